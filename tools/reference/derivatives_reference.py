#!/usr/bin/env python3
"""Pinocchio reference values of the derivatives of the dynamics, for tests/derivatives.rs.

Usage (from the repository root; the same Python environment as pinocchio_reference.py, see
tools/reference/README.md):

    python tools/reference/derivatives_reference.py

For a few example-robot-data URDFs of tests/data/erd/ (arms and a legged robot carrying an arm,
i.e. a kinematic tree), fixed base (the root link is the world) and free flyer
(pin.JointModelFreeFlyer(), only where the root link has mass, so that the URDF says the base's
inertial), at seeded random states (numpy default_rng(2026)), it writes
tests/data/reference/derivatives.json with:

* "rnea": computeRNEADerivatives(q, v, a) -> dtau_dq, dtau_dv;
* "aba": computeABADerivatives(q, v, tau) -> ddq_dq, ddq_dv, Minv;
* "minv": computeMinverse(q) (upper triangle filled, symmetrized);

gravity (0, 0, -9.81) in the root frame (fixed) or the world frame (free flyer).  Matrices are
lists of rows: row i = output i, column j = derivative along speed j in Pinocchio's velocity
order ("joints"); on the free flyer the base columns of d/dq are along integrate(q, dv), i.e.
M_base exp(dv).  Continuous joints are angles here ("q"), Pinocchio's (cos, sin) in
"q_pinocchio".  The script checks itself: Minv M = 1, computeMinverse = the Minv of
computeABADerivatives, ddq_dq = -Minv dtau_dq at a = aba(q, v, tau), and dtau_dq against
central differences along integrate (tolerance 1e-5 relative).
"""
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))
from pinocchio_reference import (  # noqa: E402
    GRAVITY, ERD, REPO, SEED, check_close, dumps, fail, fl, mat, q_range, set_gravity, to_pin_q,
    urdf_info,
)

MODELS = ["ur5_robot", "xarm7", "z1", "b1-z1"]
STATES = 2
OUT = REPO / "tests" / "data" / "reference" / "derivatives.json"


def derivatives(model, data, q, v, a, tau):
    """The three results at one state, checked against each other."""
    dq, dv, _ = pin.computeRNEADerivatives(model, data, q, v, a)
    dq, dv = np.array(dq), np.array(dv)
    fq, fv, minv = pin.computeABADerivatives(model, data, q, v, tau)
    fq, fv, minv = np.array(fq), np.array(fv), np.array(minv)
    mi = np.array(pin.computeMinverse(model, data, q))
    mi = np.triu(mi) + np.triu(mi, 1).T
    m = np.array(pin.crba(model, data, q))
    m = np.triu(m) + np.triu(m, 1).T
    check_close(mi @ m, np.eye(model.nv), 1e-9, "Minv M = 1")
    check_close(mi, minv, 1e-9, "computeMinverse = ABA derivatives' Minv")
    ddq = np.array(pin.aba(model, data, q, v, tau))
    rq, _, _ = pin.computeRNEADerivatives(model, data, q, v, ddq)
    check_close(fq, -minv @ np.array(rq), 1e-8, "ddq_dq = -Minv dtau_dq")
    h = 1e-6
    cols = []
    for j in range(model.nv):
        e = np.zeros(model.nv)
        e[j] = h
        plus = pin.rnea(model, data, pin.integrate(model, q, e), v, a)
        minus = pin.rnea(model, data, pin.integrate(model, q, -e), v, a)
        cols.append((plus - minus) / (2 * h))
    check_close(np.array(cols).T, dq, 1e-5, "dtau_dq against central differences")
    return {"rnea": {"dtau_dq": mat(dq), "dtau_dv": mat(dv)},
            "aba": {"ddq_dq": mat(fq), "ddq_dv": mat(fv), "Minv": mat(minv)},
            "minv": mat(mi)}


def states(model, first, uj, rng, floating):
    n = model.nv - (6 if floating else 0)
    out = []
    for _ in range(STATES):
        th = [rng.uniform(*q_range(u)) for u in uj]
        prefix = ()
        base = None
        if floating:
            pos = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            quat /= np.linalg.norm(quat)
            prefix = list(pos) + list(quat)
            base = {"position": fl(pos), "quaternion_xyzw": fl(quat)}
        q = to_pin_q(model, first, th, prefix=prefix)
        v = rng.uniform(-1.0, 1.0, model.nv)
        a = rng.uniform(-2.0, 2.0, model.nv)
        tau = np.concatenate([np.zeros(model.nv - n), rng.uniform(-5.0, 5.0, n)])
        data = model.createData()
        s = {"q": fl(th), "q_pinocchio": fl(q), "v": fl(v), "a": fl(a), "tau": fl(tau[model.nv - n:])}
        if base is not None:
            s["base"] = base
        s.update(derivatives(model, data, q, v, a, tau))
        out.append(s)
    return out


def main():
    rng = np.random.default_rng(SEED)
    result = {"generated_by": "tools/reference/derivatives_reference.py",
              "pin": pin.__version__, "gravity": fl(GRAVITY), "models": {}}
    for name in MODELS:
        urdf = ERD / f"{name}.urdf"
        ui = urdf_info(urdf)
        model = pin.buildModelFromUrdf(str(urdf), False)
        set_gravity(model, GRAVITY)
        names = [model.names[i] for i in range(1, model.njoints)]
        uj = [ui["joints"][n] for n in names]
        entry = {"joints": names, "fixed": states(model, 1, uj, rng, False)}
        ri = ui["root_inertial"]
        if ri is not None and ri["mass"] > 0.0:
            mff = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer(), False)
            set_gravity(mff, GRAVITY)
            if [mff.names[i] for i in range(2, mff.njoints)] != names:
                fail(f"{name}: free-flyer joint order differs")
            entry["free_flyer"] = states(mff, 2, uj, rng, True)
        result["models"][name] = entry
        print(f"{name}: nv {model.nv}, free flyer {'free_flyer' in entry}")
    OUT.write_text(dumps(result) + "\n")
    print(f"wrote {OUT.relative_to(REPO)}")


if __name__ == "__main__":
    main()
