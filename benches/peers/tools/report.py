#!/usr/bin/env python3
"""Collate timings, compile times, op counts and validation into OUT/results.md and results.json.

usage: report.py --out out --gen gen --models build/models/models.json [--total-seconds S]

Reads OUT/times.csv (pass,side,label,model,func,median_ns,min_ns,calls,checksum; one row per
pass), OUT/compile_times.csv (side,build,model,step,seconds,status), GEN/MODEL/VARIANT/counts.json
(CasADi's SX instruction counts), OUT/dumps/kanegen.default.MODEL.json (kanegen's OP_COUNTS),
OUT/dumps/validation.json and OUT/versions.txt.

Per row: the MEDIAN over passes of the per-pass medians (each pass median is over ROUNDS timed
rounds); spread = max/min - 1 of the pass medians. Ratio = peer ns / kanegen ns: "kanegen is
X times faster" (X < 1: slower, by 1/X).
"""
import argparse
import collections
import csv
import json
import os
import statistics

p = argparse.ArgumentParser()
p.add_argument("--out", default="out")
p.add_argument("--gen", default="gen")
p.add_argument("--models", default="build/models/models.json")
p.add_argument("--total-seconds", type=float, default=None)
p.add_argument("--timing-only", action="store_true", help="the run reused earlier builds (TIMING_ONLY=1)")
a = p.parse_args()

MODELS = json.load(open(a.models))
models = list(MODELS)

# ------------------------------------------------------------------ timings
T = collections.defaultdict(list)
TW = collections.defaultdict(list)  # wall-clock medians
calls = collections.defaultdict(int)
tp = os.path.join(a.out, "times.csv")
if os.path.exists(tp):
    for r in csv.DictReader(open(tp)):
        k = (r["side"], r["label"], r["model"], r["func"])
        T[k].append(float(r["median_ns"]))
        if r.get("wall_median_ns"):
            TW[k].append(float(r["wall_median_ns"]))
        calls[k] += int(r["calls"])
npass = max((len(v) for v in T.values()), default=0)
med = {k: statistics.median(v) for k, v in T.items()}
spread = {k: max(v) / min(v) - 1 for k, v in T.items()}


def ns(side, label, model, func):
    return med.get((side, label, model, func))


def ct(side, build, model, step):
    v = C.get((side, build, model, step))
    if v is None:
        return "–"
    s, st = v
    if st == "ok-cached":
        return f"{s:.1f}*"
    return f"{s:.1f}" if st == "ok" else f"{st} ({s:.0f})"


# ------------------------------------------------------------------ compile times
C = {}
cp = os.path.join(a.out, "compile_times.csv")
if os.path.exists(cp):
    for r in csv.DictReader(open(cp)):
        C[(r["side"], r["build"], r["model"], r["step"])] = (float(r["seconds"]), r["status"])

# ------------------------------------------------------------------ op counts
cas = {}  # (model, variant) -> {func: counts}
for model in models:
    gdir = os.path.join(a.gen, model)
    if not os.path.isdir(gdir):
        continue
    for var in sorted(os.listdir(gdir)):
        cj = os.path.join(gdir, var, "counts.json")
        if os.path.exists(cj):
            cas[(model, var)] = json.load(open(cj))["functions"]

KG_FUNC = {"M": "mass_matrix", "nle": "nonlinear_effects", "M_nle": "mass_matrix_and_nonlinear_effects",
           "rnea": "inverse_dynamics", "aba": "forward_dynamics",
           "rnea_derivs": "inverse_dynamics_derivatives", "aba_derivs": "forward_dynamics_derivatives",
           "minv": "mass_matrix_inverse"}
kg = {}  # model(+sfx) -> {kanegen function: op count dict}
for kind in ("default", "clean", "native"):
    for model in models:
        f = os.path.join(a.out, "dumps", f"kanegen.{kind}.{model}.json")
        if not os.path.exists(f):
            continue
        for key, m in json.load(open(f))["models"].items():
            kg.setdefault(key, {o["function"]: o for o in m["op_counts"]})


def kg_ops(key, func):
    o = kg.get(key, {}).get(KG_FUNC.get(func))
    return None if o is None else o["mul"] + o["add"]


def cas_ops(model, var, func):
    c = cas.get((model, var), {}).get(func)
    return None if c is None else c["mul_total"] + c["add_total"]


# ------------------------------------------------------------------ formatting
def fmt_ns(x):
    if x is None:
        return "–"
    return f"{x:.0f}" if x >= 100 else f"{x:.1f}"


TIE = 0.995  # ratios from TIE to 1 print as 1.00 and count as a tie, not as slower


def fmt_ratio(r):
    if r is None:
        return "–"
    return f"{r:.2f}" if r >= TIE else f"**{r:.2f}** ({1 / r:.2f}× slower)"


def ratio(peer, mine):
    return peer / mine if peer and mine else None


def best(side, label, model, funcs):
    """The fastest of the peer's conventions (LOCAL, WORLD) for one function."""
    vals = [(ns(side, label, model, f), f) for f in funcs]
    vals = [v for v in vals if v[0] is not None]
    return min(vals) if vals else (None, None)


FUNCS = [  # (row name, common key, peer keys (LOCAL first))
    ("M(q)", "M", ["M", "M_world"]),
    ("c(q, v)", "nle", ["nle"]),
    ("(M, c) one call", "M_nle", ["M_nle"]),
    ("inverse dynamics", "rnea", ["rnea"]),
    ("forward dynamics", "aba", ["aba", "aba_world"]),
]
DFUNCS = [  # (row name, common key, CasADi's SX-jacobian variant or None)
    ("∂τ/∂q, ∂τ/∂v", "rnea_derivs", "rnea_jac"),
    ("∂q̈/∂q, ∂q̈/∂v, M⁻¹", "aba_derivs", "aba_jac"),
    ("M⁻¹", "minv", None),
]

L = []
R = {"passes": npass, "total_seconds": a.total_seconds, "timing_only": a.timing_only, "models": MODELS, "headline": [], "clean": [],
     "native": [], "compile": [], "medians": [], "validation": None, "versions": None}
L.append("# kanegen vs CasADi-generated C vs numeric Pinocchio\n")
L.append("`bash benches/peers/run.sh` (benches/peers/README.md). Gravity zero, 20 states per model, the "
         "same states on every side; every function validated against numeric Pinocchio first. "
         f"ns per call: median over {npass} passes of the per-pass median round, in thread CPU time "
         "(CLOCK_THREAD_CPUTIME_ID: time slices lost to other processes on the shared machine do not count; "
         "the wall-clock medians are in results.json). "
         "**Ratio = peer ns / kanegen ns: kanegen is that many times faster** (below 1, in bold: slower).\n")
if a.total_seconds and a.timing_only:
    L.append(f"Run time: {a.total_seconds / 60:.1f} min ({a.total_seconds:.0f} s): TIMING_ONLY=1, validation, timing and "
             "report on the builds (and compile times) of an earlier complete run.\n")
elif a.total_seconds:
    L.append(f"Run time: {a.total_seconds / 60:.1f} min ({a.total_seconds:.0f} s), from scratch except the pip cache.\n")

# ------------------------------------------------------------------ headline
L.append("## Headline: kanegen (default RUSTFLAGS) vs CasADi C (`cse`, gcc -O3 -march=native) vs "
         "numeric Pinocchio (C++, header-only, g++ -O3 -march=native)\n")
L.append("Peers: the faster of their LOCAL and WORLD conventions (W marks WORLD). Ops = mul + add "
         "(kanegen: `OP_COUNTS` of the emitted function; CasADi: SX instructions of the `cse` Function, "
         "mul + sq, add + sub + twice); sin/cos, div, neg not included.\n")
L.append("| model | n | function | kanegen ns | CasADi ns | Pinocchio ns | vs CasADi | vs Pinocchio | kanegen ops | CasADi ops |")
L.append("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|")
slower = []
for model in models:
    n = MODELS[model]["n"]
    for name, key, pk in FUNCS:
        k = ns("kanegen", "default", model, key)
        c, cf = best("casadi", "cse", model, pk)
        pn, pf = best("pinocchio", "hdr", model, pk)
        rc, rp = ratio(c, k), ratio(pn, k)
        co = cas_ops(model, "cse", cf) if cf else None
        ko = kg_ops(model, key)
        L.append(f"| {model} | {n} | {name} | {fmt_ns(k)} | {fmt_ns(c)}{' W' if cf and cf.endswith('world') else ''} | "
                 f"{fmt_ns(pn)}{' W' if pf and pf.endswith('world') else ''} | {fmt_ratio(rc)} | {fmt_ratio(rp)} | "
                 f"{ko if ko is not None else '–'} | {co if co is not None else '–'} |")
        R["headline"].append({"model": model, "n": n, "function": key, "kanegen_ns": k, "casadi_ns": c,
                              "casadi_function": cf, "pinocchio_ns": pn, "pinocchio_function": pf,
                              "kanegen_faster_than_casadi": rc, "kanegen_faster_than_pinocchio": rp,
                              "kanegen_ops": ko, "casadi_ops": co})
        for peer, r in (("CasADi", rc), ("Pinocchio", rp)):
            if r is not None and r < TIE:
                slower.append(f"{model} {name}: {1 / r:.2f}× slower than {peer} ({fmt_ns(k)} ns vs "
                              f"{fmt_ns(c if peer == 'CasADi' else pn)} ns)")
L.append("")
L.append("### Where kanegen is slower\n")
L.extend([f"- {s}" for s in slower] or ["- nowhere in the headline table."])
L.append("\n(Ties, within 0.5 %, are not listed. CasADi and Pinocchio at their faster convention.)")
L.append("")

# ------------------------------------------------------------------ kanegen C beside CasADi C
R["kanegen_c"] = []
if any(k[0] == "kanegen" and k[1] == "c" for k in T):
    L.append("## kanegen C beside CasADi C: one compiler\n")
    L.append("kanegen's functions printed as C99 (`kanegen generate --lang c`: the same plan, graphs and "
             "operations as its Rust) behind CasADi's entry points (`src/kanegen_c`), compiled alone with "
             "the same gcc and flags as CasADi's `cse` C and timed by the same driver in the same passes: "
             "the generators compared under one compiler. **C ratio = CasADi C ns / kanegen C ns**; "
             "Rust / C = kanegen Rust (default build) ns / kanegen C ns. LOCAL convention.\n")
    L.append("| model | n | function | CasADi C ns | kanegen C ns | kanegen Rust ns | C ratio | Rust / C | gcc s: CasADi / kanegen |")
    L.append("|---|---:|---|---:|---:|---:|---:|---:|---|")
    for model in models:
        n = MODELS[model]["n"]
        for name, key, pk in FUNCS:
            c, kc, kr = ns("casadi", "cse", model, pk[0]), ns("kanegen", "c", model, key), ns("kanegen", "default", model, key)
            if kc is None:
                continue
            L.append(f"| {model} | {n} | {name} | {fmt_ns(c)} | {fmt_ns(kc)} | {fmt_ns(kr)} | {fmt_ratio(ratio(c, kc))} | "
                     f"{f'{kr / kc:.2f}' if kr and kc else '–'} | {ct('casadi', 'cse', model, 'cc')} / {ct('kanegen', 'c', model, 'cc')} |")
            R["kanegen_c"].append({"model": model, "n": n, "function": key, "casadi_c_ns": c, "kanegen_c_ns": kc,
                                   "kanegen_rust_ns": kr, "kanegen_c_faster_than_casadi_c": ratio(c, kc)})
    L.append("")

# ------------------------------------------------------------------ derivatives
R["derivatives"] = []
if any(ns(s_, l_, m, f) for m in models for _, f, _ in DFUNCS
       for s_, l_ in (("kanegen", "default"), ("casadi", "cse"), ("pinocchio", "hdr"))):
    L.append("## Derivatives of the dynamics\n")
    L.append("Pinocchio's layouts (row i = output i, column j = ∂/∂ input j). kanegen: "
             "`inverse_dynamics_derivatives`, `forward_dynamics_derivatives` (with M⁻¹), `mass_matrix_inverse`. "
             "CasADi: Pinocchio's `computeRNEADerivatives`, `computeABADerivatives`, `computeMinverse` traced on SX "
             "(`derivs`), and CasADi's own `SX::jacobian` of the traced `rnea` and `aba` (`jac`; for `aba` also "
             "w.r.t. τ, which is M⁻¹). Numeric Pinocchio: the same three algorithms on double (`computeMinverse` "
             "+ mirror of its upper triangle). Ratios against CasADi use its faster variant. **Like for like** "
             "(`native`): kanegen's `-C target-cpu=native` build with fused products (`native+fma`, NATIVE=1) "
             "against the C and C++ built `-march=native`; the default build's ratios beside it.\n")
    L.append("| model | n | function | kanegen ns | kanegen native ns | CasADi derivs ns | CasADi jac ns | Pinocchio ns "
             "| vs CasADi (native) | vs Pinocchio (native) | vs CasADi (default) | vs Pinocchio (default) "
             "| kanegen ops | CasADi derivs ops | CasADi jac ops |")
    L.append("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for model in models:
        n = MODELS[model]["n"]
        for name, key, jac in DFUNCS:
            c_ns = {v: ns("casadi", "cse", model, f) for v, f in (("derivs", key), ("jac", jac)) if f}
            r = {"model": model, "n": n, "function": key, "kanegen_ns": ns("kanegen", "default", model, key),
                 "casadi_derivs_ns": c_ns.get("derivs"), "casadi_jac_ns": c_ns.get("jac"),
                 "pinocchio_ns": ns("pinocchio", "hdr", model, key), "kanegen_ops": kg_ops(model, key),
                 "casadi_derivs_ops": cas_ops(model, "cse", key),
                 "casadi_jac_ops": cas_ops(model, "cse", jac) if jac else None}
            c_best = min((x for x in c_ns.values() if x is not None), default=None)
            r["kanegen_native_ns"] = ns("kanegen", "native+fma", model, key)
            r["kanegen_faster_than_casadi"] = ratio(c_best, r["kanegen_ns"])
            r["kanegen_faster_than_pinocchio"] = ratio(r["pinocchio_ns"], r["kanegen_ns"])
            r["native_faster_than_casadi"] = ratio(c_best, r["kanegen_native_ns"])
            r["native_faster_than_pinocchio"] = ratio(r["pinocchio_ns"], r["kanegen_native_ns"])
            R["derivatives"].append(r)
            cells = [fmt_ns(r[x]) for x in ("kanegen_ns", "kanegen_native_ns", "casadi_derivs_ns", "casadi_jac_ns",
                                             "pinocchio_ns")]
            cells += [fmt_ratio(r[x]) for x in ("native_faster_than_casadi", "native_faster_than_pinocchio",
                                                 "kanegen_faster_than_casadi", "kanegen_faster_than_pinocchio")]
            cells += ["–" if r[x] is None else str(r[x]) for x in ("kanegen_ops", "casadi_derivs_ops", "casadi_jac_ops")]
            L.append(f"| {model} | {n} | {name} | " + " | ".join(cells) + " |")
    L.append("")

# ------------------------------------------------------------------ run-time path
R["runtime"] = []
if any(ns("kanegen", "default", m, "aba_runtime") for m in models):
    L.append("## Run-time path (no compilation): forward dynamics vs numeric Pinocchio `aba`\n")
    L.append("kanegen run-time = `aba_runtime`: the model read from its URDF when the bench starts, "
             "`kanegen_dynamics::kernels::forward_dynamics` (the compact form's articulated-body kernel on tables built then, scratch allocated once) "
             "(what `kanegen simulate` evaluates per right-hand side; no code generated or compiled), checked "
             "against the generated `forward_dynamics` at every state before timing. Pinocchio: numeric "
             "`pinocchio::aba` (LOCAL and WORLD conventions). Generated: kanegen's `dynamics!` "
             "`forward_dynamics`. Run-time native: the same in the `-C target-cpu=native` build (NATIVE=1), as "
             "Pinocchio is compiled with -march=native. **Ratio = Pinocchio ns / run-time ns** (at least 1: the "
             "run-time path is at most as slow as Pinocchio's aba).\n")
    L.append("| model | n | kanegen run-time ns | run-time native ns "
             "| Pinocchio aba ns | Pinocchio aba WORLD ns "
             "| generated kanegen ns | Pinocchio (faster) / run-time | Pinocchio (faster) / run-time native "
             "| run-time / generated |")
    L.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for model in models:
        n = MODELS[model]["n"]
        rt = ns("kanegen", "default", model, "aba_runtime")
        if rt is None:
            continue
        rtn = ns("kanegen", "native", model, "aba_runtime")
        pl, pw = ns("pinocchio", "hdr", model, "aba"), ns("pinocchio", "hdr", model, "aba_world")
        pb = min(x for x in (pl, pw) if x is not None) if (pl or pw) else None
        gen = ns("kanegen", "default", model, "aba")
        rg = ratio(rt, gen)
        L.append(f"| {model} | {n} | {fmt_ns(rt)} | {fmt_ns(rtn)} | "
                 f"{fmt_ns(pl)} | {fmt_ns(pw)} | {fmt_ns(gen)} | "
                 f"{fmt_ratio(ratio(pb, rt))} | {fmt_ratio(ratio(pb, rtn))} | "
                 f"{f'{rg:.1f}×' if rg else '–'} |")
        R["runtime"].append({"model": model, "n": n, "kanegen_runtime_ns": rt, "kanegen_runtime_native_ns": rtn,
                             "pinocchio_aba_ns": pl, "pinocchio_aba_world_ns": pw, "generated_ns": gen,
                             "pinocchio_over_runtime": ratio(pb, rt),
                             "pinocchio_over_runtime_native": ratio(pb, rtn),
                             "spread": spread.get(("kanegen", "default", model, "aba_runtime"))})
    L.append("")

# ------------------------------------------------------------------ compile times
L.append("## Compile times (s, wall)\n")
L.append("kanegen: `cargo build --release` of the bench crate with **one** `dynamics!` (its model), the "
         "dependencies already built: macro expansion (the generator runs inside the proc-macro, at "
         "cargo's default build-override opt-level 0) + rustc/LLVM of the emitted code used by the bench "
         "(forward_dynamics_with_wrenches is generated but not compiled: unused). `check` = `cargo check "
         "--release` of the same crate (expansion + type check, no LLVM). native = `-C target-cpu=native` "
         "build with two `dynamics!` (plain and fma). CasADi: tracing + codegen (`pin_casadi_gen`, all "
         "functions of one model) and gcc -O3 -march=native of the generated `.c`. Targets for one "
         "`dynamics!`: ≤ 15 s at N = 32, ≤ 40 s at N = 64.\n")
L.append("| model | n | kanegen build | kanegen check | kanegen clean | kanegen native (2×) | CasADi trace+codegen | gcc cse | gcc cse_nocontract |")
L.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|")



for model in models:
    L.append(f"| {model} | {MODELS[model]['n']} | {ct('kanegen', 'default', model, 'build')} | "
             f"{ct('kanegen', 'default', model, 'check')} | {ct('kanegen', 'clean', model, 'build')} | "
             f"{ct('kanegen', 'native', model, 'build')} | {ct('casadi', 'cse', model, 'trace+codegen')} | "
             f"{ct('casadi', 'cse', model, 'cc')} | {ct('casadi', 'cse_nocontract', model, 'cc')} |")
if any(v[1] == "ok-cached" for v in C.values()):
    L.append("")
    L.append("\\* the object or program was reused from an earlier run (same source text and flags); the "
             "time is that of the run that compiled it.")
others = [(k, v) for k, v in C.items() if k[2] in ("all", "deps")]
if others:
    L.append("")
    L.append("Once per run: " + "; ".join(f"{k[0]} {k[1]} {'dependencies ' if k[2] == 'deps' else ''}{k[3]} {v[0]:.0f} s{'' if v[1] == 'ok' else '*' if v[1] == 'ok-cached' else ' (' + v[1] + ')'}"
                                         for k, v in others) + ".")
L.append("")
R["compile"] = [{"side": k[0], "build": k[1], "model": k[2], "step": k[3], "seconds": v[0], "status": v[1]}
                for k, v in C.items()]

# ------------------------------------------------------------------ clean models
clean_models = [m for m in models if MODELS[m]["snapped"]]
if clean_models:
    L.append("## Clean models: float noise snapped on both generated sides\n")
    L.append("CasADi `cse_clean` and kanegen `default+clean` (the same snapped model as kanegen TOML); "
             "models whose URDF leaves numbers within 1e-9 of 0 / ±1 in joint rotations (models.json "
             "`snapped`). Peers LOCAL convention.\n")
    L.append("| model | function | kanegen ns | CasADi ns | vs CasADi | kanegen ops | CasADi ops |")
    L.append("|---|---|---:|---:|---:|---:|---:|")
    for model in clean_models:
        for name, key, pk in FUNCS:
            k = ns("kanegen", "default+clean", model, key)
            c = ns("casadi", "cse_clean", model, key)
            L.append(f"| {model} | {name} | {fmt_ns(k)} | {fmt_ns(c)} | {fmt_ratio(ratio(c, k))} | "
                     f"{kg_ops(model + '+clean', key) or '–'} | {cas_ops(model, 'cse_clean', key) or '–'} |")
            R["clean"].append({"model": model, "function": key, "kanegen_ns": k, "casadi_ns": c,
                               "kanegen_faster_than_casadi": ratio(c, k)})
    L.append("")

# ------------------------------------------------------------------ native / fma
if any(k[1] == "native" for k in T):
    L.append("## Like for like on FMA: kanegen with `-C target-cpu=native`\n")
    L.append("gcc's `-O3 -march=native` contracts a·b + c into FMA by default (GNU C: -ffp-contract=fast); "
             "`cse_nocontract` is the same C with -ffp-contract=off. rustc never contracts on its own; "
             "kanegen's default (target FMA: `Name::mul_add`, one vfmadd with -C target-cpu=native) emits the fused operations, `target_fma = false` none. Ratios: no FMA = "
             "CasADi `cse_nocontract` / kanegen `native`; FMA = CasADi `cse` / kanegen `native+fma`. LOCAL "
             "convention.\n")
    L.append("| model | function | CasADi cse | CasADi nocontract | kanegen default | kanegen native | kanegen native+fma | no FMA ratio | FMA ratio |")
    L.append("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for model in models:
        for name, key, pk in FUNCS:
            c1, c0 = ns("casadi", "cse", model, key), ns("casadi", "cse_nocontract", model, key)
            kd, kn, kf = (ns("kanegen", l, model, key) for l in ("default", "native", "native+fma"))
            L.append(f"| {model} | {name} | {fmt_ns(c1)} | {fmt_ns(c0)} | {fmt_ns(kd)} | {fmt_ns(kn)} | {fmt_ns(kf)} | "
                     f"{fmt_ratio(ratio(c0, kn))} | {fmt_ratio(ratio(c1, kf))} |")
            R["native"].append({"model": model, "function": key, "casadi_cse_ns": c1, "casadi_nocontract_ns": c0,
                                "kanegen_default_ns": kd, "kanegen_native_ns": kn, "kanegen_native_fma_ns": kf})
    L.append("")

# ------------------------------------------------------------------ every variant
L.append("## Every side and label (median ns per call; spread = max/min − 1 over the pass medians, worst of the row)\n")
L.append("`sincos_n`: n sincos calls on q alone (C: glibc `sincos`, which gcc also makes of the generated "
         "sin/cos pairs; Rust: `libm::sincos`, which kanegen's code calls). Pinocchio `M_nle` = crba + "
         "nonLinearEffects (two calls); `M`, `M_world`: crba + mirror of the upper triangle.\n")
cols = ["M", "M_world", "nle", "M_nle", "rnea", "aba", "aba_world", "aba_runtime", "sincos_n"]
cols += [c for c in ("rnea_derivs", "rnea_jac", "aba_derivs", "aba_jac", "minv") if any(k[3] == c for k in T)]
L.append("| model | side / label | " + " | ".join(cols) + " | spread |")
L.append("|---|---|" + "---:|" * (len(cols) + 1))
for model in models:
    labels = sorted({(k[0], k[1]) for k in T if k[2] == model},
                    key=lambda x: (["kanegen", "casadi", "pinocchio"].index(x[0]), x[1]))
    for side, lab in labels:
        vals = [ns(side, lab, model, f) for f in cols]
        sp = max((spread.get((side, lab, model, f), 0) for f in cols if (side, lab, model, f) in spread), default=0)
        L.append(f"| {model} | {side} / {lab} | " + " | ".join(fmt_ns(v) for v in vals) + f" | {sp * 100:.0f} % |")
L.append("")
R["medians"] = [{"side": k[0], "label": k[1], "model": k[2], "function": k[3], "ns": v, "spread": spread[k],
                 "min_over_passes_ns": min(T[k]),
                 "wall_ns": statistics.median(TW[k]) if TW.get(k) else None,
                 "passes": len(T[k]), "timed_calls": calls[k]} for k, v in sorted(med.items())]

# ------------------------------------------------------------------ op counts
L.append("## Operation counts\n")
L.append("kanegen: `Name::OP_COUNTS` of each emitted function (the cheapest candidate in mul + add; "
         "methods chosen per function). CasADi: SX instructions of the `cse` Function (mul = OP_MUL + "
         "OP_SQ, add = OP_ADD + OP_SUB + OP_TWICE; `n_instr` includes inputs, outputs, constants).\n")
L.append("| model | function | kanegen method (M / bias) | kanegen mul | add | div | sincos | CasADi mul | add | sin+cos | n_instr | ops ratio CasADi / kanegen |")
L.append("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
OP_KEYS = [f[1] for f in FUNCS] + ["rnea_derivs", "rnea_jac", "aba_derivs", "aba_jac", "minv"]
for model in models:
    for key in OP_KEYS:
        o = kg.get(model, {}).get(KG_FUNC.get(key))
        c = cas.get((model, "cse"), {}).get(key)
        ko, co = kg_ops(model, key), cas_ops(model, "cse", key)
        if o is None and c is None:
            continue
        meth = "–" if o is None else f"{o['mass_matrix_method'] or '–'} / {o['nonlinear_effects_method'] or '–'}"
        L.append(f"| {model} | {key} | {meth} | " + (" | ".join(str(o[x]) for x in ("mul", "add", "div", "sincos")) if o else "– | – | – | –")
                 + " | " + (f"{c['mul_total']} | {c['add_total']} | {c['sin'] + c['cos']} | {c['n_instructions']}" if c else "– | – | – | –")
                 + (f" | {co / ko:.2f} |" if ko and co else " | – |"))
L.append("")
R["op_counts"] = {"kanegen": kg, "casadi": {f"{m}/{v}": d for (m, v), d in cas.items()}}

# ------------------------------------------------------------------ validation
vj = os.path.join(a.out, "dumps", "validation.json")
if os.path.exists(vj):
    v = json.load(open(vj))
    R["validation"] = v
    L.append(f"## Validation against numeric Pinocchio (Python pin; crba, nonLinearEffects, rnea, aba and, with DERIVS, computeRNEADerivatives, computeABADerivatives, computeMinverse), rtol {v['rtol']:g}\n")
    L.append("Worst normwise relative error max|x − x_ref| / max|x_ref| over the 20 states and all functions "
             "of a (side, label), per model.\n")
    sl = sorted({(r["side"], r["label"]) for r in v["rows"]})
    L.append("| model | " + " | ".join(f"{s} {l}" for s, l in sl) + " |")
    L.append("|---|" + "---:|" * len(sl))
    worst = collections.defaultdict(float)
    for r in v["rows"]:
        k = (r["model"], r["side"], r["label"])
        worst[k] = max(worst[k], r["max_rel_err"])
    for model in models:
        L.append(f"| {model} | " + " | ".join(f"{worst[(model, s, l)]:.1e}" if (model, s, l) in worst else "–"
                                             for s, l in sl) + " |")
    L.append("")
    L.append("FAILED: " + ", ".join(v["failed"]) + "\n" if v["failed"] else "All checks pass.\n")

# ------------------------------------------------------------------ missing pieces
missing = [f"{k[0]} {k[1]} {k[2]} {k[3]}: {v[1]} after {v[0]:.0f} s" for k, v in C.items() if not v[1].startswith("ok")]
if missing:
    L.append("## Did not build\n")
    L.extend(f"- {m}" for m in missing)
    L.append("")

vt = os.path.join(a.out, "versions.txt")
if os.path.exists(vt):
    R["versions"] = open(vt).read()
    L.append("## Machine and versions\n")
    L.append("```\n" + R["versions"].rstrip() + "\n```\n")

text = "\n".join(L)
open(os.path.join(a.out, "results.md"), "w").write(text + "\n")
json.dump(R, open(os.path.join(a.out, "results.json"), "w"), indent=1)
print(text)
