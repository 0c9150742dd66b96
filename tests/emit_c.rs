//! The C output (`kanegen generate --lang c`, `kanegen_codegen::c`): for every example model
//! (SSRMS, SRMS, UR5 with gravity, Panda with its mimic finger, xArm7, a random 16-joint chain, the
//! free-floating 7-dof arm) the emitted header compiles with the system's `cc -std=c99 -Wall
//! -Wextra -Werror`, and a driver calling every function at random states prints what the Rust
//! side computes from the same plan's graphs (each node once, in order, sines and cosines by the
//! runtime's `sincos_n_unfused`, as the Rust functions compute them) within 1e-15 relative to the
//! largest entry of the function's result (bit for bit on a target without FMA). SSRMS's header,
//! plain and with `--fma`, is checked against the checked-in Rust functions (`kanegen_generated`)
//! themselves; the `float`, payload and libm variants compile warning-free.

mod common;
mod precondition;

use kanegen::codegen::c;
use kanegen::codegen::plan::Plan;
use kanegen::codegen::{Form, Options, Shape};
use kanegen::model::{BaseKind, Model};
use kanegen::trace::{Arg, Input, Traced};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The system's C compiler (`$CC`, else `cc`), or `None` after reporting it absent.
fn compiler() -> Option<String> {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    match Command::new(&cc).arg("--version").output() {
        Ok(o) if o.status.success() => Some(cc),
        _ => {
            precondition::absent("cc", &format!("no C compiler `{cc}` on PATH"));
            None
        }
    }
}

/// A scratch directory of its own under `target/`.
fn scratch(name: &str) -> PathBuf {
    let d = root().join("target/emit_c").join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small deterministic generator (xorshift64*): uniform in `[lo, hi)`.
struct Rng(u64);

impl Rng {
    fn next(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

/// One state: the values of every argument, by name, flattened row-major.
type State = HashMap<&'static str, Vec<f64>>;

/// Random states for `model` (a free-floating base's quaternion normalized).
fn states(model: &Model, count: usize, seed: u64) -> Vec<State> {
    let floating = model.base_kind() == BaseKind::FreeFloating;
    let (n, dof) = (model.coordinate_count(), model.dof());
    let mut rng = Rng(seed | 1);
    (0..count)
        .map(|_| {
            let mut s = State::new();
            for a in [
                Arg::Q,
                Arg::Qd,
                Arg::Qdd,
                Arg::Tau,
                Arg::V,
                Arg::A,
                Arg::FExt,
            ] {
                let len = match a {
                    Arg::FExt => 6 * a.len(dof, floating),
                    _ => a.len(n, floating),
                };
                let mut v: Vec<f64> = (0..len).map(|_| rng.next(-2.0, 2.0)).collect();
                if a == Arg::Q && floating {
                    let norm = v[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
                    v[3..7].iter_mut().for_each(|x| *x /= norm);
                }
                s.insert(a.name(), v);
            }
            s
        })
        .collect()
}

/// The graph evaluated in order, each node once ([`kanegen::trace::Trace::eval_with`]): sines and
/// cosines by the runtime's `sincos_n_unfused` (what the functions call without fused products).
fn eval(t: &Traced, state: &State) -> Vec<f64> {
    let inputs: Vec<f64> = t
        .inputs
        .iter()
        .map(|i| match i {
            Input::Joint(a, k) => state[a.name()][*k],
            Input::Row(a, r, c) => state[a.name()][6 * r + c],
            other => panic!("unexpected input {other}"),
        })
        .collect();
    let sc = |a: f64| kanegen::runtime::sincos::sincos_n_unfused([a])[0];
    t.trace.eval_with(&inputs, |a| sc(a).0, |a| sc(a).1)
}

/// The trace's outputs as the C function writes its out-parameters, flattened in order: a
/// symmetric matrix whole.
fn flattened(out: &[f64], shape: Shape) -> Vec<f64> {
    let sym = |o: &[f64], n: usize| {
        let idx = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
        (0..n * n)
            .map(|k| o[idx((k / n).min(k % n), (k / n).max(k % n))])
            .collect::<Vec<_>>()
    };
    match shape {
        Shape::SymMatrix(n) => sym(out, n),
        Shape::SymMatrixAndVector(n) => {
            let t = n * (n + 1) / 2;
            let mut v = sym(&out[..t], n);
            v.extend_from_slice(&out[t..]);
            v
        }
        _ => out.to_vec(),
    }
}

/// The out-parameters of `shape`: the C array suffix of each.
fn out_params(shape: Shape) -> Vec<String> {
    match shape {
        Shape::Vector(n) => vec![format!("[{n}]")],
        Shape::SymMatrix(n) => vec![format!("[{n}][{n}]")],
        Shape::SymMatrixAndVector(n) => vec![format!("[{n}][{n}]"), format!("[{n}]")],
        Shape::Matrix(r, c) => vec![format!("[{r}][{c}]")],
        Shape::Matrices(k, n) => vec![format!("[{n}][{n}]"); k],
        Shape::Placement => vec!["[3]".into(), "[3][3]".into()],
    }
}

/// A C driver that calls every function of `plan` (prefix `p`) at each of `states` and prints
/// every entry of its results, `%.17g` one per line.
fn driver(plan: &Plan, p: &str, header: &str, states: &[State]) -> String {
    let mut s = format!("#include <stdio.h>\n#include \"{header}\"\n\n");
    let args: Vec<(Arg, usize)> = {
        let mut all: Vec<(Arg, usize)> = plan
            .functions
            .iter()
            .flat_map(|fp| fp.args.iter().copied())
            .collect();
        all.sort_by_key(|(a, _)| a.name());
        all.dedup();
        all
    };
    for (a, len) in &args {
        let dims = if *a == Arg::FExt {
            format!("[{len}][6]")
        } else {
            format!("[{len}]")
        };
        let _ = writeln!(
            s,
            "static const double in_{}[{}]{dims} = {{",
            a.name(),
            states.len()
        );
        for st in states {
            let v: Vec<String> = st[a.name()][..len * if *a == Arg::FExt { 6 } else { 1 }]
                .iter()
                .map(|x| format!("{x:?}"))
                .collect();
            if *a == Arg::FExt {
                let rows: Vec<String> = v
                    .chunks(6)
                    .map(|r| format!("{{{}}}", r.join(", ")))
                    .collect();
                let _ = writeln!(s, "    {{{}}},", rows.join(", "));
            } else {
                let _ = writeln!(s, "    {{{}}},", v.join(", "));
            }
        }
        s.push_str("};\n");
    }
    s.push_str(
        "\nstatic void print(const double *x, int n) {\n    int i;\n    for (i = 0; i < n; i++) \
         {\n        printf(\"%.17g\\n\", x[i]);\n    }\n}\n\nint main(void) {\n    int k;\n    \
         for (k = 0; k < ",
    );
    let _ = writeln!(s, "{}; k++) {{", states.len());
    for fp in &plan.functions {
        s.push_str("        {\n");
        let outs = out_params(fp.shape);
        for (i, dims) in outs.iter().enumerate() {
            let _ = writeln!(s, "            double o{i}{dims};");
        }
        let mut call: Vec<String> = fp
            .args
            .iter()
            .map(|(a, _)| format!("in_{}[k]", a.name()))
            .collect();
        call.extend((0..outs.len()).map(|i| format!("o{i}")));
        let _ = writeln!(s, "            {p}_{}({});", fp.name, call.join(", "));
        for i in 0..outs.len() {
            let _ = writeln!(
                s,
                "            print((const double *)o{i}, (int)(sizeof o{i} / sizeof(double)));"
            );
        }
        s.push_str("        }\n");
    }
    s.push_str("    }\n    return 0;\n}\n");
    s
}

/// Runs `cc -std=c99 -Wall -Wextra -Werror` with `args`, checking that it succeeds (its stderr
/// is the failure message).
fn cc_checked<A: AsRef<std::ffi::OsStr>>(cc: &str, args: impl IntoIterator<Item = A>) {
    common::succeeded(
        Command::new(cc)
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror"])
            .args(args),
    );
}

/// Compiles `driver.c` in `dir` (beside its header) with [`cc_checked`] and `flags`, runs it and
/// returns the numbers it printed.
fn compile_and_run(cc: &str, dir: &Path, flags: &[&str]) -> Vec<f64> {
    let exe = dir.join("driver");
    let mut args: Vec<std::ffi::OsString> = flags.iter().map(Into::into).collect();
    args.extend([
        dir.join("driver.c").into(),
        "-o".into(),
        exe.clone().into(),
        "-lm".into(),
    ]);
    cc_checked(cc, args);
    let run = Command::new(&exe).output().unwrap();
    assert!(run.status.success(), "{} failed", exe.display());
    String::from_utf8(run.stdout)
        .unwrap()
        .lines()
        .map(|l| l.trim().parse::<f64>().unwrap())
        .collect()
}

/// One model of the check.
struct Case {
    name: &'static str,
    file: &'static str,
    gravity: Option<[f64; 3]>,
    base: Option<BaseKind>,
    allow_nonphysical: bool,
    /// Optimization level: `-O2` for two arms, `-O0` for the rest to keep the test short (the
    /// 16-joint chain's derivatives take over a minute at `-O2`).
    opt: &'static str,
}

const CASES: [Case; 7] = [
    Case {
        name: "Ssrms",
        file: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        gravity: None,
        base: None,
        allow_nonphysical: false,
        // At `-O2` in `c_output_matches_the_checked_in_rust_functions`.
        opt: "-O0",
    },
    Case {
        name: "Srms",
        file: "tests/data/reference/srms_nguyen_hughes_1994.urdf",
        gravity: None,
        base: None,
        allow_nonphysical: false,
        opt: "-O2",
    },
    Case {
        name: "Ur5",
        file: "tests/data/erd/ur5_robot.urdf",
        gravity: Some([0.0, 0.0, -9.81]),
        base: None,
        allow_nonphysical: false,
        opt: "-O2",
    },
    Case {
        name: "Panda",
        file: "tests/data/erd/panda.urdf",
        gravity: Some([0.0, 0.0, -9.81]),
        base: None,
        allow_nonphysical: false,
        opt: "-O0",
    },
    Case {
        name: "Xarm7",
        file: "tests/data/erd/xarm7.urdf",
        gravity: Some([0.0, 0.0, -9.81]),
        base: None,
        allow_nonphysical: false,
        opt: "-O0",
    },
    Case {
        name: "RandomN16",
        file: "benches/data/random_n16.toml",
        gravity: None,
        base: None,
        allow_nonphysical: false,
        opt: "-O0",
    },
    Case {
        name: "FreeFloating7",
        file: "tests/data/reference/bmsd_7dof_free_floating.urdf",
        gravity: None,
        base: Some(BaseKind::FreeFloating),
        allow_nonphysical: true,
        opt: "-O0",
    },
];

/// Relative error of `have` against `want`, relative to the largest entry of `want`.
fn check(case: &str, function: &str, have: &[f64], want: &[f64]) -> f64 {
    assert_eq!(have.len(), want.len(), "{case} {function}");
    let scale = want.iter().fold(f64::MIN_POSITIVE, |m, x| m.max(x.abs()));
    let mut worst: f64 = 0.0;
    for (k, (h, w)) in have.iter().zip(want).enumerate() {
        let e = (h - w).abs() / scale;
        assert!(
            e <= 1e-15,
            "{case} `{function}` entry {k}: C {h:e}, Rust {w:e} (relative {e:e})"
        );
        worst = worst.max(e);
    }
    worst
}

/// Every model: the header compiles warning-free, and every function matches the Rust side.
fn check_case(cc: &str, case: &Case) {
    let v = kanegen::model::Validation {
        allow_nonphysical_inertia: case.allow_nonphysical,
    };
    let model = kanegen::model::io::load_model_with(&root().join(case.file), v).unwrap();
    let mut opts = Options::new(case.name);
    opts.gravity = case.gravity;
    opts.base = case.base;
    let p = c::prefix(case.name);
    let text = c::generate(&model, &opts, &p).unwrap();
    // The Rust side: the plan the C output is printed from (C is straight-line).
    opts.form = Form::Unrolled;
    let (plan, graphs) = Plan::new(&model, &opts).unwrap();
    let dir = scratch(&p);
    let header = format!("{p}.h");
    std::fs::write(dir.join(&header), &text).unwrap();
    let states = states(&plan.model, 3, 0x5EED ^ p.len() as u64);
    std::fs::write(dir.join("driver.c"), driver(&plan, &p, &header, &states)).unwrap();
    let printed = compile_and_run(cc, &dir, &[case.opt]);
    let mut at = 0;
    let mut worst: f64 = 0.0;
    for st in &states {
        for (fp, g) in plan.functions.iter().zip(&graphs) {
            let g = g.as_ref().expect("a straight-line plan");
            let want = flattened(&eval(g, st), fp.shape);
            let have = &printed[at..at + want.len()];
            at += want.len();
            worst = worst.max(check(case.name, &fp.name, have, &want));
        }
    }
    assert_eq!(
        at,
        printed.len(),
        "{}: every printed number read",
        case.name
    );
    eprintln!(
        "{}: {} functions, largest relative difference {worst:e}",
        case.name,
        plan.functions.len()
    );
}

#[test]
fn c_output_compiles_and_matches_rust_for_every_example_model() {
    let Some(cc) = compiler() else { return };
    std::thread::scope(|s| {
        let (cc, cases) = (&cc, &CASES);
        let handles: Vec<_> = (0..2)
            .map(|w| {
                s.spawn(move || {
                    for case in cases.iter().skip(w).step_by(2) {
                        check_case(cc, case);
                    }
                })
            })
            .collect();
        for h in handles {
            h.join().unwrap();
        }
    });
}

/// The results of the checked-in Rust functions of one `kanegen_generated` type at one state,
/// in the order the C driver prints them (the plan's functions, out-parameters flattened).
type RustFns = fn(&State) -> Vec<(&'static str, Vec<f64>)>;

/// [`RustFns`] of a fixed-base `kanegen_generated` type of 7 joints with every function of
/// the default options (no gravity, no frames).
macro_rules! rust_fns {
    ($ty:ty) => {
        |st: &State| -> Vec<(&'static str, Vec<f64>)> {
            let arr = |name: &str| -> [f64; 7] { st[name][..7].try_into().unwrap() };
            let (q, qd, qdd, tau) = (arr("q"), arr("qd"), arr("qdd"), arr("tau"));
            let f_ext: [[f64; 6]; 7] =
                core::array::from_fn(|r| st["f_ext"][6 * r..6 * r + 6].try_into().unwrap());
            let flat = |m: [[f64; 7]; 7]| m.concat();
            let (m, c) = <$ty>::mass_matrix_and_nonlinear_effects(&q, &qd);
            let (dq, dv) = <$ty>::inverse_dynamics_derivatives(&q, &qd, &qdd);
            let (fq, fv, minv) = <$ty>::forward_dynamics_derivatives(&q, &qd, &tau);
            vec![
                ("mass_matrix", flat(<$ty>::mass_matrix(&q))),
                (
                    "nonlinear_effects",
                    <$ty>::nonlinear_effects(&q, &qd).to_vec(),
                ),
                (
                    "inverse_dynamics",
                    <$ty>::inverse_dynamics(&q, &qd, &qdd).to_vec(),
                ),
                (
                    "forward_dynamics",
                    <$ty>::forward_dynamics(&q, &qd, &tau).to_vec(),
                ),
                (
                    "mass_matrix_and_nonlinear_effects",
                    [flat(m), c.to_vec()].concat(),
                ),
                (
                    "forward_dynamics_with_wrenches",
                    <$ty>::forward_dynamics_with_wrenches(&q, &qd, &tau, &f_ext).to_vec(),
                ),
                (
                    "inverse_dynamics_derivatives",
                    [flat(dq), flat(dv)].concat(),
                ),
                (
                    "forward_dynamics_derivatives",
                    [flat(fq), flat(fv), flat(minv)].concat(),
                ),
                ("mass_matrix_inverse", flat(<$ty>::mass_matrix_inverse(&q))),
            ]
        }
    };
}

/// SSRMS's header, plain and with `--fma` (`fma` of `<math.h>` against the Rust `libm::fma`),
/// from the options of the checked-in files, against the checked-in Rust functions
/// (`kanegen_generated::ssrms`, `ssrms_fma`) themselves, every function at random states. The C
/// fuses the products the Rust fuses: with `-march=native` where the Rust is built for FMA
/// (`S::mul_add` fused there, `PREFIX_mul_add` where `FP_FAST_FMA`).
#[test]
fn c_output_matches_the_checked_in_rust_functions() {
    use kanegen::cli::commands::generate::GENERATED;
    let Some(cc) = compiler() else { return };
    let cases: [(&str, RustFns); 2] = [
        ("Ssrms", rust_fns!(kanegen_generated::ssrms::Ssrms)),
        (
            "SsrmsFma",
            rust_fns!(kanegen_generated::ssrms_fma::SsrmsFma),
        ),
    ];
    let flags: &[&str] = if cfg!(target_feature = "fma") {
        &["-O2", "-march=native"]
    } else {
        &["-O2"]
    };
    for (name, rust) in cases {
        let g = GENERATED.iter().find(|g| g.type_name == name).unwrap();
        let model = g.model(root()).unwrap();
        let opts = g.options();
        let p = c::prefix(name);
        let text = c::generate(&model, &opts, &p).unwrap();
        let mut unrolled = opts.clone();
        unrolled.form = Form::Unrolled;
        let (plan, _) = Plan::new(&model, &unrolled).unwrap();
        let dir = scratch(&format!("{p}_rust"));
        let header = format!("{p}.h");
        std::fs::write(dir.join(&header), &text).unwrap();
        let states = states(&plan.model, 3, 0xC0DE);
        std::fs::write(dir.join("driver.c"), driver(&plan, &p, &header, &states)).unwrap();
        let printed = compile_and_run(&cc, &dir, flags);
        let mut at = 0;
        for st in &states {
            let want = rust(st);
            assert_eq!(
                want.iter().map(|w| w.0).collect::<Vec<_>>(),
                plan.functions
                    .iter()
                    .map(|fp| fp.name.as_str())
                    .collect::<Vec<_>>(),
                "{name}: the functions in the order of the plan"
            );
            for (function, want) in want {
                let have = &printed[at..at + want.len()];
                at += want.len();
                check(name, function, have, &want);
            }
        }
        assert_eq!(at, printed.len(), "{name}: every printed number read");
    }
}

/// A variant of the options: its prefix and what it sets.
type Variant = (&'static str, fn(&mut Options));

/// The other variants compile warning-free too, every function emitted (its address taken):
/// `float` code with a runtime payload and gravity; `--fma` with a payload; libm's sine and
/// cosine. A bad prefix, the compact form and a model past `c::MAX_JOINTS` are errors, not
/// panics.
#[test]
fn c_output_variants_compile() {
    let Some(cc) = compiler() else { return };
    let model = kanegen::model::io::load_model(&root().join("models/two_link.toml")).unwrap();
    let variants: [Variant; 3] = [
        ("arm_f32", |o| {
            o.float = kanegen::codegen::Float::F32;
            o.runtime_payload = true;
            o.gravity = Some([0.0, 0.0, -9.81]);
        }),
        ("arm_fma", |o| {
            o.fma = true;
            o.runtime_payload = true;
        }),
        ("arm_libm", |o| o.libm_trig = true),
    ];
    for (p, set) in variants {
        let mut opts = Options::new("Arm");
        set(&mut opts);
        let text = c::generate(&model, &opts, p).unwrap();
        opts.form = Form::Unrolled;
        let (plan, _) = Plan::new(&model, &opts).unwrap();
        let dir = scratch(p);
        std::fs::write(dir.join("arm.h"), &text).unwrap();
        let kept: Vec<String> = plan
            .functions
            .iter()
            .map(|fp| format!("    (void (*)(void)){p}_{},", fp.name))
            .collect();
        let tu = format!(
            "#include \"arm.h\"\nvoid (*const kept[])(void) = {{\n{}\n}};\n",
            kept.join("\n")
        );
        std::fs::write(dir.join("kept.c"), tu).unwrap();
        let (src, obj) = (dir.join("kept.c"), dir.join("kept.o"));
        cc_checked(
            &cc,
            [
                "-O2".as_ref(),
                "-c".as_ref(),
                src.as_os_str(),
                "-o".as_ref(),
                obj.as_os_str(),
            ],
        );
    }
    let opts = Options::new("Arm");
    let err = c::generate(&model, &opts, "1arm").unwrap_err();
    assert!(err.0.contains("not a C identifier"), "{err}");
    let mut compact = Options::new("Arm");
    compact.form = Form::Compact;
    let err = c::generate(&model, &compact, "arm").unwrap_err();
    assert!(err.0.contains("does not support the compact form"), "{err}");
    use kanegen::model::random::{random_chain, ChainSpec};
    let n = c::MAX_JOINTS + 1;
    let large = random_chain(
        &ChainSpec {
            n,
            ..Default::default()
        },
        1,
    );
    let err = c::generate(&large, &opts, "arm").unwrap_err();
    assert!(err.0.contains(&format!("N = {n} is past the")), "{err}");
}

/// `kanegen generate --lang c`: the header on stdout, its names from the model's; an unknown
/// language and a name C cannot take are one-line errors.
#[test]
fn the_cli_writes_c() {
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_kanegen"))
            .args(args)
            .current_dir(root())
            .output()
            .unwrap()
    };
    let out = run(&["generate", "models/two_link.toml", "--lang", "c"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.starts_with("// Dynamics of `two_link` (N = 2)"),
        "{text}"
    );
    for f in [
        "mass_matrix(const double q[2], double m[2][2])",
        "forward_dynamics(",
    ] {
        assert!(
            text.contains(&format!("static inline void two_link_{f}")),
            "{f}"
        );
    }
    for (args, want) in [
        (
            &["generate", "models/two_link.toml", "--lang", "fortran"][..],
            "unknown language `fortran`: rust or c",
        ),
        (
            &[
                "generate",
                "models/two_link.toml",
                "--lang",
                "c",
                "--name",
                "9arm",
            ][..],
            "C prefix `9arm` is not a C identifier",
        ),
    ] {
        let out = run(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(want),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}
