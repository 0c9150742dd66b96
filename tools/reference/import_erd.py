#!/usr/bin/env python3
"""Copy example-robot-data URDFs into tests/data/erd/, stripped of <visual> and <collision>.

Usage (from the repository root, in a Python environment that has the PyPI packages
``pin`` (Pinocchio), ``numpy`` and ``example-robot-data``; see tools/reference/README.md):

    python tools/reference/import_erd.py            # copy, check, write tests/data/erd/index.json
    python tools/reference/import_erd.py --list     # only print the candidates and their class

What it does, for every candidate URDF of the families UR, Franka/Panda, xArm, Kinova,
TALOS arm and Unitree Z1 (including the two legged robots that carry such an arm):

1. classifies it from the URDF text (see ``classify``):
   a = serial arm plus fixed frames (fixed joints in line, or fixed side branches: a link with
       several child joints where all but one subtree hold only fixed joints),
   b = moving branches (a real kinematic tree: gripper fingers, legs),
   c = something else (empty file, floating/planar joints, xacro only) -> not copied;
2. copies it to tests/data/erd/<stem>.urdf with every <visual> and <collision> element removed
   as text (the rest of the file is byte-for-byte the original);
3. checks that Pinocchio builds the same model from the original and from the copy (nq, nv,
   joint names/types/placements, inertias, frames and limits) and that, apart from
   visual/collision, the XML trees are equal;
4. writes tests/data/erd/index.json.

Mimic tags are ignored (Pinocchio is called with mimic=False, as kanegen does): a mimic joint
is an independent degree of freedom.
"""
import argparse
import collections
import importlib.metadata as md
import json
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

REPO = Path(__file__).resolve().parents[2]
OUT = REPO / "tests" / "data" / "erd"
PACKAGE = "example-robot-data"

# Candidates, as paths inside <prefix>/share/example-robot-data/robots/.
CANDIDATES = [
    "ur_description/urdf/ur3.urdf",
    "ur_description/urdf/ur3_robot.urdf",
    "ur_description/urdf/ur3_joint_limited_robot.urdf",
    "ur_description/urdf/ur3_gripper.urdf",
    "ur_description/urdf/ur5_robot.urdf",
    "ur_description/urdf/ur5_joint_limited_robot.urdf",
    "ur_description/urdf/ur5_gripper.urdf",
    "ur_description/urdf/ur10_robot.urdf",
    "ur_description/urdf/ur10_joint_limited_robot.urdf",
    "panda_description/urdf/panda.urdf",
    "panda_description/urdf/panda_collision.urdf",
    "xarm_description/urdf/xarm7.urdf",
    "kinova_description/robots/kinova.urdf",
    "talos_data/robots/talos_left_arm.urdf",
    "z1_description/urdf/z1.urdf",
    "b1_description/urdf/b1-z1.urdf",
    "anymal_b_simple_description/robots/anymal-kinova.urdf",
]


def robots_dir():
    for f in md.files(PACKAGE) or []:
        s = str(f)
        if s.endswith("robots/ur_description/urdf/ur5_robot.urdf"):
            return Path(f.locate()).parents[2]
    raise SystemExit(f"cannot find the robots/ folder of the installed {PACKAGE} package")


def strip_text(text):
    """Remove <visual>/<collision> elements; a line left blank by the removal is dropped."""
    pat = re.compile(
        r"(?P<lead>^[ \t]*)?<(?P<tag>visual|collision)\b[^>]*?"
        r"(?:/>|(?<!/)>.*?</(?P=tag)\s*>)(?P<trail>[ \t]*\n)?",
        re.S | re.M,
    )

    def repl(m):
        whole_line = m.group("lead") is not None and m.group("trail") is not None
        if whole_line:
            return ""
        return (m.group("lead") or "") + (m.group("trail") or "")

    return pat.sub(repl, text)


def canon(el, drop=("visual", "collision")):
    """Canonical form of an XML element without the given tags (for comparison)."""
    return (
        el.tag,
        tuple(sorted(el.attrib.items())),
        (el.text or "").strip(),
        tuple(canon(c, drop) for c in el if c.tag not in drop),
    )


def classify(path):
    """Return (class, info dict) from the URDF's structure."""
    root = ET.parse(path).getroot()
    links = [l.get("name") for l in root.findall("link")]
    joints = root.findall("joint")
    info = {"mimic_joints": [], "mimic_tags_on_fixed_joints": [], "notes": []}
    if not links:
        info["notes"].append("empty robot: no links (a xacro leftover; urdfdom rejects it: no robot name)")
        return "c", info
    children = collections.defaultdict(list)
    is_child = set()
    types = collections.Counter()
    for j in joints:
        jt = j.get("type")
        types[jt] += 1
        children[j.find("parent").get("link")].append((j.get("name"), jt, j.find("child").get("link")))
        is_child.add(j.find("child").get("link"))
        if j.find("mimic") is not None:
            (info["mimic_tags_on_fixed_joints"] if jt == "fixed" else info["mimic_joints"]).append(j.get("name"))
    roots = [l for l in links if l not in is_child]
    info["root_link"] = roots[0] if len(roots) == 1 else roots
    info["urdf_joint_types"] = dict(types)

    def moving(link):
        return sum((jt != "fixed") + moving(c) for (_, jt, c) in children[link])

    side, branch = [], []
    for l in links:
        ch = children[l]
        if len(ch) > 1:
            nmov = sum(1 for (_, jt, c) in ch if (jt != "fixed") + moving(c) > 0)
            (branch if nmov > 1 else side).append(l)
    info["fixed_side_branch_links"] = side
    info["moving_branch_links"] = branch
    if len(roots) != 1 or any(t in types for t in ("floating", "planar")):
        return "c", info
    if branch:
        return "b", info
    if not side:
        info["notes"].append("serial chain; fixed joints only in line (no fixed side branch)")
    return "a", info


def pin_summary(path):
    m = pin.buildModelFromUrdf(str(path), False)
    s = {"nq": m.nq, "nv": m.nv, "names": list(m.names)}
    s["joints"] = [(m.joints[i].shortname(), m.parents[i], m.jointPlacements[i].homogeneous.tolist()) for i in range(m.njoints)]
    s["inertias"] = [(m.inertias[i].mass, m.inertias[i].lever.tolist(), m.inertias[i].inertia.tolist()) for i in range(m.njoints)]
    s["frames"] = [(f.name, str(f.type), f.parentJoint, f.placement.homogeneous.tolist(), f.inertia.mass) for f in m.frames]
    s["limits"] = (m.lowerPositionLimit.tolist(), m.upperPositionLimit.tolist())
    return m, s


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--list", action="store_true", help="only print candidates and classes")
    args = ap.parse_args()
    src = robots_dir()
    version = md.version(PACKAGE)
    index = []
    skipped = []
    seen = {}
    for rel in CANDIDATES:
        path = src / rel
        cls, info = classify(path)
        name = path.stem
        print(f"{rel}: class {cls}; {info}")
        if args.list:
            continue
        if cls == "c":
            skipped.append({"source": f"share/example-robot-data/robots/{rel}", "reason": "; ".join(info["notes"]) or "class c"})
            continue
        text = path.read_text(encoding="utf-8")
        stripped = strip_text(text)
        a = ET.fromstring(text.encode())
        b = ET.fromstring(stripped.encode())
        if canon(a) != canon(b):
            raise SystemExit(f"{rel}: stripping changed more than visual/collision")
        if any(True for _ in b.iter("visual")) or any(True for _ in b.iter("collision")):
            raise SystemExit(f"{rel}: visual/collision left after stripping")
        key = canon(b)  # XML content, comments and layout aside
        if key in seen:
            print(f"  skipped: same XML as {seen[key]} once visual/collision are removed")
            skipped.append({"source": f"share/example-robot-data/robots/{rel}",
                            "reason": f"same XML as {seen[key]} without visual/collision"})
            continue
        seen[key] = rel
        dst = OUT / f"{name}.urdf"
        OUT.mkdir(parents=True, exist_ok=True)
        dst.write_text(stripped, encoding="utf-8")
        m0, s0 = pin_summary(path)
        m1, s1 = pin_summary(dst)
        if s0 != s1:
            raise SystemExit(f"{rel}: Pinocchio model differs after stripping")
        continuous = [m1.names[i] for i in range(1, m1.njoints) if m1.joints[i].nq == 2]
        fixed_frames = [f for k, f in enumerate(m1.frames) if k != 0 and f.type == pin.FrameType.FIXED_JOINT]
        index.append({
            "name": name,
            "urdf": f"{name}.urdf",
            "reference": f"{name}.reference.json",
            "source": f"share/example-robot-data/robots/{rel}",
            "package": {"name": PACKAGE, "version": version},
            "dof": m1.nv,
            "class": cls,
            "fixed_joints": info["urdf_joint_types"].get("fixed", 0),
            "fixed_frames": None,  # filled in below (same rule as the reference files)
            "continuous_joints": continuous,
            "mimic_joints": info["mimic_joints"],
            "mimic_tags_on_fixed_joints": info["mimic_tags_on_fixed_joints"],
            "root_link": info["root_link"],
            "fixed_side_branch_links": info["fixed_side_branch_links"],
            "moving_branch_links": info["moving_branch_links"],
            "notes": info["notes"],
            "bytes": {"original": len(text.encode()), "stripped": len(stripped.encode())},
        })
        # number of fixed frames: FIXED_JOINT frames + body frames of links attached by them
        index[-1]["fixed_frames"] = 2 * len(fixed_frames)
        print(f"  -> {dst.relative_to(REPO)} ({len(text)} -> {len(stripped)} bytes); Pinocchio model identical")
    if args.list:
        return
    doc = {
        "description": "example-robot-data URDFs copied with <visual>/<collision> removed "
                       "(tools/reference/import_erd.py); Pinocchio references in <name>.reference.json "
                       "(tools/reference/pinocchio_reference.py).",
        "classes": {
            "a": "serial arm plus fixed frames (fixed joints in line and/or fixed side branches)",
            "b": "moving branches (a kinematic tree)",
            "c": "something else (not copied)",
        },
        "pinocchio": pin.__version__,
        "models": index,
        "not_copied": skipped,
    }
    (OUT / "index.json").write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {(OUT / 'index.json').relative_to(REPO)} ({len(index)} models)")


if __name__ == "__main__":
    main()
