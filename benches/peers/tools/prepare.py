#!/usr/bin/env python3
"""URDF -> everything the three sides need, from Pinocchio's own URDF parser (numeric pin).

Adapted from the shared harness (peers/casadi/tools/prepare.py). Differences: no link is
stripped (kanegen reads trees and fixed side frames now); joints keep their parent (trees);
`continuous` joints are rewritten as `revolute` (Pinocchio gives a continuous joint nq = 2,
(cos, sin); both readers give the same dynamics for a revolute joint); four vectors per state
(q, v, tau, a); the clean TOML has prismatic joints and parents; one Rust file per kanegen build.

usage: prepare.py --out DIR NAME=PATH.urdf [NAME=PATH.urdf ...]

For each model NAME=PATH.urdf this writes into DIR:

  NAME.urdf        the URDF all sides read (a copy; `continuous` -> `revolute` when present)
  NAME.model.txt   the Pinocchio model as built by pin.buildModelFromUrdf (joint types, parents,
                   joint placements, body inertias with fixed links merged), one joint per line,
                   17 significant digits: src/model_txt.hpp rebuilds the identical model in C++.
  NAME.clean.model.txt  the same with float noise snapped (SNAP, TINY below): CasADi `cse_clean`.
  NAME.clean.toml  the same snapped model in kanegen's TOML format (exact rotation matrices, which
                   a URDF cannot express): kanegen `+clean`. Both only matter when something was
                   snapped (models.json: `snapped`).
  NAME.states.txt  "K n", then one line per state: q, v, tau, a (n each)   [C / C++ drivers]
  NAME.ref.json    Pinocchio numeric (Python) at those states, gravity 0: M (crba, symmetrized),
                   nle = nonLinearEffects, tau = rnea(q, v, a), ddq = aba(q, v, tau),
                   dtau_dq, dtau_dv = computeRNEADerivatives(q, v, a), ddq_dq, ddq_dv =
                   computeABADerivatives(q, v, tau), Minv = computeMinverse(q) (symmetrized
                   from its upper triangle; row i = output i, column j = input j)
  NAME.states.rs   the same states as Rust constants, in Pinocchio's joint order, with the joint
                   names (the kanegen bench maps them onto `Name::JOINTS`)
  NAME.kg_default.rs / NAME.kg_clean.rs / NAME.kg_native.rs   the body of the kanegen bench's
                   src/kanegen_models.rs for one build: one `dynamics!` on the URDF; one on the
                   clean TOML; the URDF with `target_fma = false` and with the default (fused through
                   -C target-cpu=native)
and DIR/models.json (per model: n, joint types, tree or chain, where the states came from, how
many numbers the clean model snapped).

States: q, v from NAME.states.json next to the URDF when present (the project's fixed reference
states, first K), else seeded: q uniform in [-pi, pi] (revolute) or [-0.5, 0.5] m (prismatic),
v uniform in [-1, 1]. a seeded uniform in [-1, 1]^n, tau = rnea(q, v, a), so aba's answer is a.
"""
import argparse
import json
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

p = argparse.ArgumentParser()
p.add_argument("models", nargs="+", help="NAME=path/to/model.urdf")
p.add_argument("--out", default="build/models")
p.add_argument("--states", type=int, default=20)
p.add_argument("--seed", type=int, default=20261201)
args = p.parse_args()
os.makedirs(args.out, exist_ok=True)

R = lambda x: repr(float(x))
# "clean" model: a joint rotation (or axis) all of whose entries lie within SNAP of 0 or +-1 is
# replaced by that exact signed permutation; offsets below TINY m and inertia entries below
# TINY x the largest become 0. URDF rpy = pi/2 leaves cos(pi/2) = 6e-17 in a rotation (UR's
# 1.570796325 leaves 5e-12); both generators keep such numbers as real operands. A rotation that
# is really off-axis (xArm's rpy 1.5708 leaves cos = -3.7e-6) is left alone.
SNAP = 1e-9
TINY = 1e-12
REVOLUTE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned")
PRISMATIC = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned")
summary = {}

for spec in args.models:
    name, path = spec.split("=", 1)
    if not name.replace("_", "").isalnum():
        sys.exit(f"model name {name!r}: letters, digits and _ only")
    urdf = os.path.join(args.out, f"{name}.urdf")
    tree = ET.parse(path)
    root = tree.getroot()
    continuous = []
    for j in root.findall("joint"):
        if j.get("type") == "continuous":
            j.set("type", "revolute")
            lim = j.find("limit")
            if lim is None:
                lim = ET.SubElement(j, "limit", effort="1000", velocity="10")
            lim.set("lower", "-1e6")
            lim.set("upper", "1e6")
            continuous.append(j.get("name"))
    tree.write(urdf)
    model = pin.buildModelFromUrdf(urdf)
    model.gravity.setZero()
    if model.nq != model.nv:
        sys.exit(f"{name}: nq {model.nq} != nv {model.nv} (free or spherical joints are not handled here)")
    n = model.nv
    data = model.createData()
    types = [model.joints[j].shortname() for j in range(1, model.njoints)]
    parents = [int(model.parents[j]) for j in range(1, model.njoints)]
    is_tree = any(pj != j for j, pj in enumerate(parents))  # joint j+1's parent is joint j in a chain

    # ---- the model, raw and with float noise snapped ("clean")
    def snap_all(a):
        a = np.asarray(a, float)
        r = np.round(a) + 0.0  # + 0.0: no negative zeros
        return r if np.all(np.abs(a - r) < SNAP) and np.all(np.abs(r) <= 1) else a

    def joints(clean):
        out = []
        for j in range(1, model.njoints):
            jm = model.joints[j]
            t = jm.shortname()
            if t in ("JointModelRX", "JointModelPX"):
                ax = [1.0, 0.0, 0.0]
            elif t in ("JointModelRY", "JointModelPY"):
                ax = [0.0, 1.0, 0.0]
            elif t in ("JointModelRZ", "JointModelPZ"):
                ax = [0.0, 0.0, 1.0]
            elif t in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
                ax = list(jm.extract().axis)
            else:
                sys.exit(f"{name}: joint type {t} not handled")
            M = model.jointPlacements[j]
            I = model.inertias[j]
            S = np.array(I.inertia)  # 3x3 about the COM, body axes
            rot = M.rotation.copy()
            tr, lever = list(M.translation), list(I.lever)
            if clean:
                ax = list(snap_all(ax))
                rot = snap_all(rot)
                tr = [0.0 if abs(x) < TINY else x for x in tr]
                lever = [0.0 if abs(x) < TINY else x for x in lever]
                S[abs(S) < TINY * abs(S).max()] = 0.0
            out.append(dict(type=t, parent=int(model.parents[j]), name=model.names[j], rot=rot, tr=tr, ax=ax,
                            mass=I.mass, lever=lever, S=S))
        return out

    def model_txt(js):
        lines = [f"name {name}", f"njoints {len(js)}"]
        for J in js:
            S = J["S"]
            tok = ["joint", J["type"], str(J["parent"]), J["name"]]
            tok += [R(x) for x in J["rot"].reshape(-1)]  # row-major
            tok += [R(x) for x in J["tr"]] + [R(x) for x in J["ax"]]
            tok += [R(J["mass"])] + [R(x) for x in J["lever"]]
            tok += [R(S[0, 0]), R(S[0, 1]), R(S[0, 2]), R(S[1, 1]), R(S[1, 2]), R(S[2, 2])]
            lines.append(" ".join(tok))
        return "\n".join(lines) + "\n"

    def model_toml(js):
        """kanegen's TOML model: same joints and parents, exact rotation matrices."""
        v = lambda xs: "[" + ", ".join(R(x) for x in xs) + "]"
        out = [f'# {name}: Pinocchio model of {os.path.basename(path)} with float noise snapped '
               f'(benches/peers/tools/prepare.py); generated, do not edit', f'name = "{name}_clean"',
               'base = "base"', ""]
        for J in js:
            kind = "revolute" if J["type"] in REVOLUTE else "prismatic" if J["type"] in PRISMATIC else None
            if kind is None:
                sys.exit(f"{name}: TOML export handles revolute and prismatic joints only")
            par = "base" if J["parent"] == 0 else js[J["parent"] - 1]["name"]
            out += ["[[joint]]", f'name = "{J["name"]}"', f'type = "{kind}"', f'parent = "{par}"',
                    f'xyz = {v(J["tr"])}', "rotation = [" + ", ".join(v(r) for r in J["rot"]) + "]",
                    f'axis = {v(J["ax"])}', "", "[joint.body]", f'name = "{J["name"]}_body"',
                    f'mass = {R(J["mass"])}', f'com = {v(J["lever"])}',
                    "inertia = [" + ", ".join(v(r) for r in J["S"]) + "]", ""]
        return "\n".join(out)

    raw, clean = joints(False), joints(True)
    open(os.path.join(args.out, f"{name}.model.txt"), "w").write(model_txt(raw))
    open(os.path.join(args.out, f"{name}.clean.model.txt"), "w").write(model_txt(clean))
    open(os.path.join(args.out, f"{name}.clean.toml"), "w").write(model_toml(clean))
    nsnap = sum(int(np.sum(a["rot"] != b["rot"]) + np.sum(a["S"] != b["S"])
                    + sum(x != y for x, y in zip(a["tr"] + a["lever"] + a["ax"], b["tr"] + b["lever"] + b["ax"])))
                for a, b in zip(raw, clean))

    # ---- states
    rng = np.random.default_rng(args.seed + sum(map(ord, name)))
    sj = os.path.splitext(path)[0] + ".states.json"
    qs, vs = [], []
    src = "seeded random"
    if os.path.exists(sj):
        st = json.load(open(sj))["states"][: args.states]
        qs = [np.array(s["q"], float) for s in st]
        vs = [np.array(s.get("qd", s.get("v")), float) for s in st]
        src = os.path.basename(sj) + (" + seeded random" if len(qs) < args.states else "")
    lim = np.array([np.pi if t in REVOLUTE else 0.5 for t in types])
    while len(qs) < args.states:
        qs.append(rng.uniform(-1, 1, n) * lim)
        vs.append(rng.uniform(-1, 1, n))
    taus, accs, refs = [], [], []
    for q, v in zip(qs, vs):
        a = rng.uniform(-1, 1, n)
        tau = pin.rnea(model, data, q, v, a).copy()
        Mq = pin.crba(model, data, q).copy()
        Mq = np.triu(Mq) + np.triu(Mq, 1).T
        nle = pin.nonLinearEffects(model, data, q, v).copy()
        ddq = pin.aba(model, data, q, v, tau).copy()
        dtau_dq, dtau_dv, _ = (x.copy() for x in pin.computeRNEADerivatives(model, data, q, v, a))
        ddq_dq, ddq_dv, _ = (x.copy() for x in pin.computeABADerivatives(model, data, q, v, tau))
        Minv = pin.computeMinverse(model, data, q).copy()
        Minv = np.triu(Minv) + np.triu(Minv, 1).T
        taus.append(tau)
        accs.append(a)
        refs.append({"q": q.tolist(), "v": v.tolist(), "tau": tau.tolist(), "a": a.tolist(),
                     "M": Mq.tolist(), "nle": nle.tolist(), "ddq": ddq.tolist(),
                     "dtau_dq": dtau_dq.tolist(), "dtau_dv": dtau_dv.tolist(),
                     "ddq_dq": ddq_dq.tolist(), "ddq_dv": ddq_dv.tolist(), "Minv": Minv.tolist()})
    with open(os.path.join(args.out, f"{name}.states.txt"), "w") as f:
        f.write(f"{len(qs)} {n}\n")
        for q, v, t, a in zip(qs, vs, taus, accs):
            f.write(" ".join(R(x) for x in list(q) + list(v) + list(t) + list(a)) + "\n")
    jnames = [model.names[j] for j in range(1, model.njoints)]
    json.dump({"format": "kanegen-peers-ref/1", "library": f"pinocchio {pin.__version__} (numeric, Python)",
               "model": name, "urdf": os.path.basename(path), "n": n, "gravity": [0, 0, 0],
               "joints": jnames, "states_from": src, "samples": refs},
              open(os.path.join(args.out, f"{name}.ref.json"), "w"))

    # ---- Rust: states, and the dynamics! invocations of each build
    ty = "".join(w.capitalize() for w in name.split("_"))
    arr = lambda v: "[" + ", ".join(R(x) for x in v) + "]"
    K = len(qs)
    open(os.path.join(args.out, f"{name}.states.rs"), "w").write(
        f"// {name}: states in Pinocchio's joint order; generated by benches/peers/tools/prepare.py\n"
        f"#[allow(clippy::all)]\nmod {name}_states {{\n"
        f"    pub const NAMES: [&str; {n}] = [{', '.join(json.dumps(x) for x in jnames)}];\n"
        f"    pub const Q: [[f64; {n}]; {K}] = [{', '.join(arr(q) for q in qs)}];\n"
        f"    pub const V: [[f64; {n}]; {K}] = [{', '.join(arr(v) for v in vs)}];\n"
        f"    pub const TAU: [[f64; {n}]; {K}] = [{', '.join(arr(t) for t in taus)}];\n"
        f"    pub const A: [[f64; {n}]; {K}] = [{', '.join(arr(a) for a in accs)}];\n"
        f"}}\n")

    def kg(invocations, rows):
        body = [f"// {name}: one kanegen bench build; generated by benches/peers/tools/prepare.py\n",
                f'include!("{name}.states.rs");\n']
        body += invocations
        body.append("macro_rules! for_each_model {\n    ($m:ident, $($arg:expr),*) => {\n")
        body += [f"        {r}\n" for r in rows]
        body.append("    };\n}\n")
        return "".join(body)

    open(os.path.join(args.out, f"{name}.kg_default.rs"), "w").write(kg(
        [f'kanegen::dynamics!({ty}, "models/{name}.urdf", ignore_mimic = true);\n'],
        [f'$m!({ty}, "{name}", {name}_states, "", $($arg),*);']))
    open(os.path.join(args.out, f"{name}.kg_clean.rs"), "w").write(kg(
        [f'kanegen::dynamics!({ty}Clean, "models/{name}.clean.toml");\n'],
        [f'$m!({ty}Clean, "{name}", {name}_states, "+clean", $($arg),*);']))
    open(os.path.join(args.out, f"{name}.kg_native.rs"), "w").write(kg(
        ["// no fused multiply-add: every product and sum written out\n",
         f'kanegen::dynamics!({ty}, "models/{name}.urdf", target_fma = false, ignore_mimic = true);\n',
         "// the default: products fuse through Name::mul_add, one vfmadd where the target has FMA\n",
         '#[cfg(target_feature = "fma")]\n',
         f'kanegen::dynamics!({ty}Fma, "models/{name}.urdf", ignore_mimic = true);\n'],
        [f'$m!({ty}, "{name}", {name}_states, "", $($arg),*);',
         '#[cfg(target_feature = "fma")]',
         f'$m!({ty}Fma, "{name}", {name}_states, "+fma", $($arg),*);']))

    summary[name] = {"urdf": path, "n": n, "joint_types": sorted(set(types)), "tree": is_tree,
                     "states_from": src, "snapped": nsnap, "continuous_as_revolute": continuous,
                     "joints": jnames}
    print(f"{name}: n={n}, {'tree' if is_tree else 'chain'}, joints {sorted(set(types))}, states from {src}, "
          f"numbers snapped in the clean model: {nsnap}"
          + (f", continuous read as revolute: {continuous}" if continuous else ""))

json.dump(summary, open(os.path.join(args.out, "models.json"), "w"), indent=1)
