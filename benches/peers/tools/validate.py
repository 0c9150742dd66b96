#!/usr/bin/env python3
"""Check every timed function of every side against Pinocchio's numeric values (gravity 0).

usage: validate.py REFDIR DUMPDIR [--rtol 1e-9]

REFDIR/NAME.ref.json            tools/prepare.py (Python pin): M (crba, symmetrized), nle,
                                tau = rnea(q, v, a), ddq = aba(q, v, tau), dtau_dq, dtau_dv
                                (computeRNEADerivatives), ddq_dq, ddq_dv (computeABADerivatives),
                                Minv (computeMinverse, symmetrized)
DUMPDIR/casadi.NAME.LABEL.json  `driver ... dump` (CasADi-generated C)
DUMPDIR/pinocchio.NAME.LABEL.json  `pin_numeric ... dump` (numeric Pinocchio in C++)
DUMPDIR/kanegen.LABEL.NAME.json `kanegen_bench LABEL dump` (one build: one model, its variants)

Every side dumps the same keys in Pinocchio's joint order: M, nle, M_nle (+ M_nle.nle), rnea,
aba, and CasADi / Pinocchio also M_world, aba_world. With the derivatives: rnea_derivs
(+ rnea_derivs.dtau_dv), aba_derivs (+ aba_derivs.ddq_dv, aba_derivs.Minv), minv; CasADi also
rnea_jac and aba_jac (SX jacobians, same keys). A key absent from a dump is not checked.

Error measure, per quantity: max over the states of  max|x - x_ref| / max|x_ref|
(normwise relative: the entries of M span many orders of magnitude, and the small ones carry
absolute errors about as large as the rounding of the big ones). Prints one line per
(side, label, model, quantity) and writes DUMPDIR/validation.json. Exits 1 when a check is
above --rtol or not finite (run.sh records that and goes on to time everything).
"""
import argparse
import glob
import json
import os
import sys

import numpy as np

p = argparse.ArgumentParser()
p.add_argument("refdir")
p.add_argument("dumpdir")
p.add_argument("--rtol", type=float, default=1e-9)
a = p.parse_args()

REF_KEY = {"M": "M", "M_world": "M", "M_nle": "M", "M_nle.nle": "nle", "nle": "nle", "rnea": "tau",
           "aba": "ddq", "aba_world": "ddq", "minv": "Minv"}
for f in ("rnea_derivs", "rnea_jac"):
    REF_KEY.update({f: "dtau_dq", f + ".dtau_dv": "dtau_dv"})
for f in ("aba_derivs", "aba_jac"):
    REF_KEY.update({f: "ddq_dq", f + ".ddq_dv": "ddq_dv", f + ".Minv": "Minv"})
ORDER = list(REF_KEY)


def err(x, ref):
    x, ref = np.asarray(x, float), np.asarray(ref, float)
    if x.shape != ref.shape:
        return float("inf")
    s = max(np.abs(ref).max(), 1e-300)
    return float(np.abs(x - ref).max() / s)


refs = {}
for f in glob.glob(os.path.join(a.refdir, "*.ref.json")):
    r = json.load(open(f))
    refs[r["model"]] = r["samples"]

rows, bad = [], []


def check(side, label, model, samples):
    ref = refs[model]
    for key in ORDER:
        if key not in samples[0]:
            continue
        e = max(err(s[key], r[REF_KEY[key]]) for s, r in zip(samples, ref))
        if len(samples) != len(ref):
            e = float("inf")
        rows.append({"side": side, "label": label, "model": model, "quantity": key, "ref": REF_KEY[key],
                     "max_rel_err": e})
        ok = e <= a.rtol and np.isfinite(e)
        print(f"{side:9s} {label:15s} {model:11s} {key:20s} vs {REF_KEY[key]:7s} max rel err {e:9.2e}"
              + ("" if ok else "   <-- FAIL"))
        if not ok:
            bad.append(f"{side}/{label}/{model}/{key}")


for side in ("casadi", "pinocchio"):
    for f in sorted(glob.glob(os.path.join(a.dumpdir, f"{side}.*.json"))):
        d = json.load(open(f))
        check(side, d["label"], d["model"], d["samples"])

for f in sorted(glob.glob(os.path.join(a.dumpdir, "kanegen_c.*.json"))):
    d = json.load(open(f))
    check(d["side"], d["label"], d["model"], d["samples"])

for f in sorted(glob.glob(os.path.join(a.dumpdir, "kanegen.*.json"))):
    d = json.load(open(f))
    for model, m in d["models"].items():
        base = model.split("+")[0]
        lab = d["label"] + model[len(base):]
        check("kanegen", lab, base, m["samples"])

json.dump({"rtol": a.rtol, "rows": rows, "failed": bad},
          open(os.path.join(a.dumpdir, "validation.json"), "w"), indent=1)
if bad:
    print(f"VALIDATION FAILED (rtol {a.rtol:g}): {', '.join(bad)}")
    sys.exit(1)
print(f"validation: all {len(rows)} checks within rtol {a.rtol:g}; "
      f"worst {max((r['max_rel_err'] for r in rows), default=0):.2e}")
