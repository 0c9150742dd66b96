#!/usr/bin/env python3
"""Every example-robot-data URDF kanegen can read, with Pinocchio reference values: tests/data/erd_all/.

Usage (from the repository root, in the environment of tools/reference/README.md):

    python tools/reference/erd_all.py

For every URDF of the installed example-robot-data package whose joints are revolute,
continuous, prismatic or fixed (mimic joints included) it writes

* tests/data/erd_all/<name>.urdf: the file with every <visual> and <collision> element cut out
  (import_erd.strip_text; Pinocchio builds the same model from both, checked);
* tests/data/erd_all/<name>.json: Pinocchio's values at a few seeded states
  (numpy default_rng(2026), drawn per model):
  - "joints": the independent joints in the order of Pinocchio's velocity vector (mimic joints,
    read with mimic=True where the file has <mimic> on a moving joint, have no entry);
  - "fixed": root link fixed; per state q, qd (one angle or displacement per independent joint;
    continuous joints as angles), A = crba(q), b = -nonLinearEffects(q, qd) with gravity
    (0, 0, -9.81) in the root frame;
  - "free_flyer" (only where the root link with the links fixed to it has mass): the same URDF
    under JointModelFreeFlyer; per state base (position, quaternion [x, y, z, w], v and omega in
    base coordinates), q, qd, A (6+N)², b = -nonLinearEffects with gravity zero;

and tests/data/erd_all/index.json: the models (source, mimic, dof) and every file not copied,
with the reason (no moving joint, an unsupported joint type, Pinocchio cannot read it, or the
same model as a file of tests/data/erd/, which tests/erd.rs checks already).

Checks: A symmetric; A equals crba of the mimic=False model reduced by the coupling G (Gᵀ A G),
and b equals Gᵀ b of that model at the expanded state (so Pinocchio's mimic support agrees with
the definition kanegen implements).
"""
import importlib.metadata as md
import json
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))
from import_erd import canon, robots_dir, strip_text  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
OUT = REPO / "tests" / "data" / "erd_all"
OLD = REPO / "tests" / "data" / "erd"
SEED = 2026
FIXED_STATES = 2
FREE_STATES = 1
GRAVITY = np.array([0.0, 0.0, -9.81])


def fl(x):
    return float(f"{float(x):.17g}")


def mat(m):
    return [[fl(x) for x in row] for row in np.asarray(m)]


def vec(v):
    return [fl(x) for x in np.asarray(v).ravel()]


def full_matrix(M):
    return np.triu(M) + np.triu(M, 1).T


def structure(path):
    """(reason not to copy or None, has mimic on a moving joint)."""
    root = ET.parse(path).getroot()
    joints = root.findall("joint")
    if not root.findall("link"):
        return "empty robot: no links", False
    types = {j.get("type") for j in joints}
    bad = types - {"revolute", "continuous", "prismatic", "fixed"}
    if bad:
        return f"unsupported joint types: {sorted(bad)}", False
    if not types - {"fixed"}:
        return "no moving joint", False
    mimic = any(j.find("mimic") is not None and j.get("type") != "fixed" for j in joints)
    return None, mimic


def independent(model):
    """[(joint index, name)] of the joints with a velocity of their own, in velocity order."""
    js = [(model.joints[i].idx_v, i, model.names[i]) for i in range(1, model.njoints)
          if model.joints[i].shortname() != "JointModelMimic" and model.joints[i].nv > 0]
    return [(i, n) for (_, i, n) in sorted(js)]


def pin_q(model, joints, angles, base=None):
    q = pin.neutral(model)
    if base is not None:
        q[:7] = base
    for (i, _), a in zip(joints, angles):
        j = model.joints[i]
        if j.nq == 2:
            q[j.idx_q:j.idx_q + 2] = [math.cos(a), math.sin(a)]
        else:
            q[j.idx_q] = a
    return q


def draw_angles(model, joints, rng):
    out = []
    for i, _ in joints:
        j = model.joints[i]
        lo, hi = model.lowerPositionLimit[j.idx_q], model.upperPositionLimit[j.idx_q]
        if j.nq == 1 and np.isfinite(lo) and np.isfinite(hi) and lo < hi and hi - lo < 10:
            out.append(rng.uniform(lo, hi))
        else:
            out.append(rng.uniform(-math.pi, math.pi))
    return np.array(out)


def mimic_map(path):
    """{mimic joint: (primary, multiplier, offset)} from the URDF text (moving joints)."""
    root = ET.parse(path).getroot()
    out = {}
    for j in root.findall("joint"):
        m = j.find("mimic")
        if m is not None and j.get("type") != "fixed":
            out[j.get("name")] = (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))
    return out


def resolve(mim, name):
    """(primary, multiplier, offset) of `name` through chains of mimics."""
    mult, off, prim = 1.0, 0.0, name
    while prim in mim:
        p, k, o = mim[prim]
        off += mult * o
        mult *= k
        prim = p
    return prim, mult, off


def expand(path, model, full, q, v):
    """The mimic=False state of the mimic=True state (q, v), and G (full nv × nv)."""
    mim = mimic_map(path)
    qf = pin.neutral(full)
    vf = np.zeros(full.nv)
    G = np.zeros((full.nv, model.nv))
    nbase = 6 if full.joints[1].shortname() == "JointModelFreeFlyer" else 0
    if nbase:
        qf[:7] = q[:7]
        vf[:6] = v[:6]
        G[:6, :6] = np.eye(6)

    def angle(name):
        jm = model.joints[model.getJointId(name)]
        if jm.nq == 2:
            return math.atan2(q[jm.idx_q + 1], q[jm.idx_q]), jm
        return q[jm.idx_q], jm

    for i in range(1 + (1 if nbase else 0), full.njoints):
        name = full.names[i]
        jf = full.joints[i]
        prim, mult, off = resolve(mim, name)
        a, jm = angle(prim)
        a = mult * a + off
        if jf.nq == 2:
            qf[jf.idx_q:jf.idx_q + 2] = [math.cos(a), math.sin(a)]
        else:
            qf[jf.idx_q] = a
        vf[jf.idx_v] = mult * v[jm.idx_v]
        G[jf.idx_v, jm.idx_v] = mult
    return qf, vf, G


def check(path, model, full, q, v, A, b, gravity):
    if full is None:
        return
    qf, vf, G = expand(path, model, full, q, v)
    full.gravity.linear = gravity
    d = full.createData()
    Af = full_matrix(pin.crba(full, d, qf))
    bf = -pin.nonLinearEffects(full, d, qf, vf)
    ea = np.abs(G.T @ Af @ G - A).max() / max(1.0, np.abs(A).max())
    eb = np.abs(G.T @ bf - b).max() / max(1.0, np.abs(b).max())
    if ea > 1e-10 or eb > 1e-10:
        raise SystemExit(f"{path}: mimic=True differs from Gᵀ(mimic=False)G: A {ea:.2e}, b {eb:.2e}")


def states(path, mimic, rng, free):
    root = pin.JointModelFreeFlyer() if free else None
    build = (lambda m: pin.buildModelFromUrdf(str(path), root, m)) if free else (
        lambda m: pin.buildModelFromUrdf(str(path), m))
    by_g = False
    try:
        model = build(mimic)
    except Exception:  # noqa: BLE001 (Pinocchio refuses some mimic layouts)
        model, by_g = build(False), True
    full = build(False) if mimic and not by_g else None
    if free and model.inertias[1].mass <= 0:
        return None
    mim = mimic_map(path) if by_g else {}
    joints = [(i, n) for (i, n) in independent(model) if not (free and i == 1) and n not in mim]
    data = model.createData()
    gravity = np.zeros(3) if free else GRAVITY
    model.gravity.linear = gravity
    out = []
    n_states = FREE_STATES if free else (FIXED_STATES if len(joints) <= 40 else 1)
    for _ in range(n_states):
        base = None
        st = {}
        if free:
            pos = rng.uniform(-1, 1, 3)
            quat = rng.normal(size=4)
            quat /= np.linalg.norm(quat)
            base = np.concatenate([pos, quat])
            bv, bw = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
            st["base"] = {"position": vec(pos), "quaternion": vec(quat), "v": vec(bv), "omega": vec(bw)}
        angles = draw_angles(model, joints, rng)
        qd = rng.uniform(-1, 1, len(joints))
        if by_g:
            A, b = g_reduced(path, model, joints, angles, qd, base, (bv, bw) if free else None)
        else:
            q = pin_q(model, joints, angles, base)
            v = np.concatenate([bv, bw, qd]) if free else qd
            A = full_matrix(pin.crba(model, data, q))
            b = -pin.nonLinearEffects(model, data, q, v)
            check(path, model, full, q, v, A, b, gravity)
        if np.abs(A - A.T).max() > 1e-12 * max(1.0, np.abs(A).max()):
            raise SystemExit(f"{path}: A not symmetric")
        st.update({"q": vec(angles), "qd": vec(qd), "A": mat(A), "b": vec(b)})
        out.append(st)
    return {"joints": [n for (_, n) in joints], "states": out, "by_g": by_g}


def g_reduced(path, full, joints, angles, qd, base, twist):
    """Gᵀ A G and Gᵀ b of the mimic=False model `full` (gravity already set) at the state of
    the independent joints `joints` (full model indices and names)."""
    mim = mimic_map(path)
    nbase = 6 if twist is not None else 0
    col = {n: nbase + k for k, (_, n) in enumerate(joints)}
    value = {n: a for (_, n), a in zip(joints, angles)}
    rate = {n: r for (_, n), r in zip(joints, qd)}
    qf = pin.neutral(full)
    vf = np.zeros(full.nv)
    G = np.zeros((full.nv, nbase + len(joints)))
    if nbase:
        qf[:7] = base
        vf[:6] = np.concatenate(twist)
        G[:6, :6] = np.eye(6)
    for i in range(2 if nbase else 1, full.njoints):
        name, jf = full.names[i], full.joints[i]
        prim, mult, off = resolve(mim, name)
        a = mult * value[prim] + off
        if jf.nq == 2:
            qf[jf.idx_q:jf.idx_q + 2] = [math.cos(a), math.sin(a)]
        else:
            qf[jf.idx_q] = a
        vf[jf.idx_v] = mult * rate[prim]
        G[jf.idx_v, col[prim]] = mult
    d = full.createData()
    A = full_matrix(pin.crba(full, d, qf))
    b = -pin.nonLinearEffects(full, d, qf, vf)
    return G.T @ A @ G, G.T @ b


def main():
    src = robots_dir()
    old = {canon(ET.parse(p).getroot()): p.stem for p in OLD.glob("*.urdf")}
    OUT.mkdir(parents=True, exist_ok=True)
    models, skipped, seen, names = [], [], {}, set()
    for path in sorted(src.rglob("*.urdf")):
        rel = str(path.relative_to(src))
        reason, mimic = structure(path)
        if reason is None:
            try:
                pin.buildModelFromUrdf(str(path), False)
                mimic_refs = mimic_map(path)
                names_in = {j.get("name") for j in ET.parse(path).getroot().findall("joint")}
                missing = sorted({p for (p, _, _) in mimic_refs.values()} - names_in)
                if missing:
                    reason = f"a <mimic> names joints that do not exist: {missing}"
            except Exception as e:  # noqa: BLE001 (Pinocchio raises plain exceptions)
                reason = f"Pinocchio cannot read it: {str(e).splitlines()[0]}"
        stripped = strip_text(path.read_text(encoding="utf-8")) if reason is None else None
        key = canon(ET.fromstring(stripped.encode())) if stripped else None
        if reason is None and key in old and not mimic:
            reason = f"the same model as tests/data/erd/{old[key]}.urdf (tests/erd.rs checks it)"
        if reason is None and key in seen:
            reason = f"the same XML as {seen[key]} without visual/collision"
        if reason:
            print(f"skip {rel}: {reason}")
            skipped.append({"source": rel, "reason": reason})
            continue
        seen[key] = rel
        name = path.stem if path.stem not in names else f"{path.parts[-3].removesuffix('_description')}-{path.stem}"
        names.add(name)
        dst = OUT / f"{name}.urdf"
        dst.write_text(stripped, encoding="utf-8")
        rng = np.random.default_rng(SEED)
        fixed = states(dst, mimic, rng, False)
        free = states(dst, mimic, rng, True)
        ref = {
            "source": f"share/example-robot-data/robots/{rel}",
            "pinocchio": pin.__version__,
            "mimic": mimic,
            "mimic_reference": None if not mimic else (
                "G^T A G, G^T b of the mimic=False model (Pinocchio's mimic=True reader refuses the file)"
                if fixed["by_g"] else "Pinocchio mimic=True (checked equal to G^T A G of mimic=False)"),
            "joints": fixed["joints"],
            "fixed": {"gravity": vec(GRAVITY), "states": fixed["states"]},
            "free_flyer": free and {"gravity": [0.0, 0.0, 0.0], "states": free["states"]},
        }
        (OUT / f"{name}.json").write_text(json.dumps(ref, separators=(",", ":")) + "\n", encoding="utf-8")
        models.append({"name": name, "source": rel, "mimic": mimic, "dof": len(fixed["joints"]),
                       "free_flyer": free is not None})
        print(f"{rel} -> {name}: {len(fixed['joints'])} coordinates, mimic={mimic}, free={free is not None}")
    index = {
        "description": "every example-robot-data URDF with revolute, continuous, prismatic, fixed "
                       "and mimic joints, stripped of <visual>/<collision>, with Pinocchio values "
                       "(tools/reference/erd_all.py)",
        "package": {"name": "example-robot-data", "version": md.version("example-robot-data")},
        "pinocchio": pin.__version__,
        "models": models,
        "not_copied": skipped,
    }
    (OUT / "index.json").write_text(json.dumps(index, indent=1) + "\n", encoding="utf-8")
    print(f"{len(models)} models, {len(skipped)} not copied")


if __name__ == "__main__":
    main()
