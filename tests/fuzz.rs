//! Fuzzing: random and adversarial models, states and scenes fed to every command's entry
//! point (`kanegen::cli::app::run_args`, the binary's own code, in process). No run may panic,
//! and a run that succeeds may print no non-finite number (`NaN`, `inf`, JSON `null` where a
//! number belongs, a non-finite constant in generated code).
//!
//! A short run (64 cases per property) is part of `cargo test`; a long run:
//!
//! ```sh
//! PROPTEST_CASES=5000 cargo test --release --test fuzz
//! ```
//!
//! (5000 cases per property: about 5 minutes on 2 cores, no failure.) `FUZZ_DEBUG=1` prints each command's
//! outcome. Adversarial values replace up to three numbers of an otherwise valid input, so that
//! most cases get past the readers and into the algorithms.

use proptest::prelude::*;
use std::path::PathBuf;

/// Numbers that break naive code: zeros, signs, the extremes of `f64`, non-finite values, and
/// ordinary ones. TOML spells `nan` and `inf` directly.
fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -2.0..2.0f64,
        1 => Just(0.0),
        1 => Just(-0.0),
        1 => Just(1e-300),
        1 => Just(5e-324),
        1 => Just(1e6),
        1 => Just(-1e6),
        1 => Just(1e7),
        1 => Just(1e12),
        1 => Just(1e18),
        1 => Just(1e200),
        1 => Just(-1e308),
        1 => Just(f64::MAX),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
    ]
}

fn toml_num(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        }
    } else {
        format!("{x:?}")
    }
}

/// A JSON number; non-finite values become numbers too large for `f64` (`1e999`), which the
/// reader must refuse.
fn json_num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else {
        "1e999".into()
    }
}

fn v3(v: &[f64]) -> String {
    format!(
        "[{}, {}, {}]",
        toml_num(v[0]),
        toml_num(v[1]),
        toml_num(v[2])
    )
}

/// `n` ordinary numbers of which up to three (at random places) are replaced by adversarial
/// ones: a mostly valid input reaches deep into the pipeline before the bad number bites.
fn numbers(n: usize) -> impl Strategy<Value = Vec<f64>> {
    (
        proptest::collection::vec(-2.0..2.0f64, n),
        proptest::collection::vec((0..n, number()), 0..=3),
    )
        .prop_map(|(mut x, bad)| {
            for (i, v) in bad {
                x[i] = v;
            }
            x
        })
}

/// A model of 1 to 3 joints, some of whose numbers may be adversarial.
fn model() -> impl Strategy<Value = (usize, String)> {
    (1usize..=3).prop_flat_map(|n| {
        (
            Just(n),
            numbers(n * 14),
            proptest::collection::vec(any::<bool>(), n),
        )
            .prop_map(|(n, x, prismatic)| {
                let mut s = String::from("name = \"fuzz\"\n");
                for j in 0..n {
                    let x = &x[j * 14..(j + 1) * 14];
                    let ty = if prismatic[j] { "prismatic" } else { "revolute" };
                    s += &format!(
                        "\n[[joint]]\nname = \"j{j}\"\ntype = \"{ty}\"\nxyz = {}\nrpy = {}\naxis = {}\n\
                         [joint.body]\nmass = {}\ncom = {}\ninertia = {{ ixx = {}, iyy = {}, izz = {} }}\n",
                        v3(&x[0..3]),
                        v3(&x[3..6]),
                        v3(&x[6..9]),
                        toml_num(x[9].abs()),
                        v3(&x[10..13]),
                        toml_num(x[13].abs() + 0.5),
                        toml_num(x[13].abs() + 0.6),
                        toml_num(x[13].abs() + 0.7),
                    );
                }
                (n, s)
            })
    })
}

/// A plain model of `n` joints (valid numbers), for state and scene fuzzing.
fn plain_model(n: usize) -> String {
    let mut s = String::from("name = \"plain\"\n");
    for j in 0..n {
        s += &format!(
            "\n[[joint]]\nname = \"j{j}\"\ntype = \"revolute\"\nxyz = [0.5, 0.1, 0.0]\n\
             axis = [0.0, 0.3, 1.0]\n[joint.body]\nmass = 2.0\ncom = [0.2, 0.0, 0.1]\n\
             inertia = {{ ixx = 0.1, iyy = 0.2, izz = 0.25 }}\n"
        );
    }
    s
}

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("kanegen-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A unique file in the fuzz directory.
fn file(name: &str, text: &str) -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static K: AtomicUsize = AtomicUsize::new(0);
    let p = dir().join(format!("{}-{name}", K.fetch_add(1, Ordering::Relaxed)));
    std::fs::write(&p, text).unwrap();
    p
}

/// Runs the command in process: no panic; on success no non-finite number in the output.
fn check(args: &[String]) -> Result<(), TestCaseError> {
    let mut out: Vec<u8> = Vec::new();
    let argv: Vec<String> = std::iter::once("kanegen".to_string())
        .chain(args.iter().cloned())
        .collect();
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        kanegen::cli::app::run_args(argv.clone(), &mut out)
    }));
    let r = match r {
        Ok(r) => r,
        Err(_) => return Err(TestCaseError::fail(format!("panic: {argv:?}"))),
    };
    if std::env::var_os("FUZZ_DEBUG").is_some() {
        eprintln!(
            "{} {:?}",
            argv[1],
            r.as_ref().map(|_| ()).map_err(|e| format!("{e:#}"))
        );
    }
    if r.is_ok() {
        let text = String::from_utf8_lossy(&out);
        for word in outside_limit_tables(&text)
            .split(|c: char| !(c.is_alphanumeric() || c == ':' || c == '_'))
        {
            let bad = matches!(word, "NaN" | "nan" | "inf" | "null")
                || word.ends_with("::NAN")
                || word.ends_with("::INFINITY")
                || word.ends_with("::NEG_INFINITY");
            prop_assert!(!bad, "{argv:?} printed `{word}`:\n{text}");
        }
    }
    Ok(())
}

/// `text` without the generated joint-limit tables (`pub const …_LIMIT: [..] = [..];`), where
/// `±∞` marks an absent limit by design.
fn outside_limit_tables(text: &str) -> String {
    let mut in_table = false;
    let mut kept = String::new();
    for line in text.lines() {
        if !in_table && line.trim_start().starts_with("pub const ") && line.contains("_LIMIT: [") {
            in_table = true;
        }
        if in_table {
            in_table = !line.trim_end().ends_with(';');
        } else {
            kept.push_str(line);
            kept.push('\n');
        }
    }
    kept
}

/// Cases per property: `PROPTEST_CASES`, default 64.
fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

fn s(x: &str) -> String {
    x.to_string()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    /// Adversarial models through eval (text and JSON), count, generate and accuracy.
    #[test]
    fn adversarial_models(m in model(), q in proptest::collection::vec(-3.0..3.0f64, 3),
                          g in numbers(3)) {
        let (n, text) = m;
        let model = file("model.toml", &text);
        let q: Vec<String> = q[..n].iter().map(|x| format!("{x:?}")).collect();
        let states = file(
            "states.json",
            &format!(r#"{{"states":[{{"q":[{0}],"qd":[{0}],"tau":[{0}]}}]}}"#, q.join(",")),
        );
        let m = model.display().to_string();
        let st = states.display().to_string();
        let grav = format!("{},{},{}", g[0], g[1], g[2]);
        check(&[s("eval"), m.clone(), s("--states"), st.clone()])?;
        check(&[s("eval"), m.clone(), s("--states"), st.clone(), s("--json"), s("--gravity"), grav.clone()])?;
        check(&[s("count"), m.clone(), s("--algorithm"), s("spatial")])?;
        check(&[s("generate"), m.clone(), s("--gravity"), grav])?;
        check(&[s("generate"), m.clone(), s("--lock"), format!("0={}", toml_num(g[1]))])?;
        // The Markdown report (its JSON uses `null` for "not measured").
        check(&[s("accuracy"), m])?;
    }

    /// Adversarial states on a plain model.
    #[test]
    fn adversarial_states(n in 1usize..=3, x in numbers(9)) {
        let model = file("model.toml", &plain_model(n));
        let v = |k: usize| x[k * 3..k * 3 + n].iter().map(|y| json_num(*y)).collect::<Vec<_>>().join(",");
        let states = file(
            "states.json",
            &format!(r#"{{"states":[{{"q":[{}],"qd":[{}],"tau":[{}]}}]}}"#, v(0), v(1), v(2)),
        );
        for algorithm in ["recurrent", "kane-direct", "spatial"] {
            check(&[s("eval"), model.display().to_string(), s("--states"),
                    states.display().to_string(), s("--algorithm"), s(algorithm)])?;
        }
    }

    /// Adversarial scenes: initial state, gravity, durations, steps, tolerances, integrators.
    #[test]
    fn adversarial_scenes(n in 1usize..=3, x in numbers(9),
                          duration in prop_oneof![Just(1e-300), Just(0.05), Just(0.3), Just(1e300), Just(f64::NAN), Just(-1.0), Just(0.0)],
                          step in prop_oneof![Just(1e-300), Just(1e-3), Just(0.05), Just(1e300), Just(f64::INFINITY), Just(0.0)],
                          tolerance in prop_oneof![Just(1e-300), Just(1e-14), Just(1e-6), Just(1.0), Just(1e300)],
                          integrator in prop_oneof![Just("rk4"), Just("dopri5"), Just("midpoint")]) {
        let model = file("model.toml", &plain_model(n));
        let v = |k: usize| v3(&x[k * 3..k * 3 + 3]);
        let take = |t: String| {
            let inner = t.trim_matches(['[', ']']);
            let parts: Vec<&str> = inner.split(", ").take(n).collect();
            format!("[{}]", parts.join(", "))
        };
        let tol = if integrator == "dopri5" { format!("tolerance = {}\n", toml_num(tolerance)) } else { String::new() };
        let scene = format!(
            "model = \"{}\"\n[effects]\ngravity = {}\n[initial]\nq = {}\nqd = {}\n[simulation]\n\
             duration = {}\nstep = {}\nintegrator = \"{integrator}\"\n{tol}",
            model.file_name().unwrap().to_string_lossy(),
            v(0),
            take(v(1)),
            take(v(2)),
            toml_num(duration),
            toml_num(step),
        );
        let scene = file("scene.toml", &scene);
        check(&[s("simulate"), scene.display().to_string()])?;
        check(&[s("count"), scene.display().to_string(), s("--algorithm"), s("spatial")])?;
    }
}

/// Empty and garbage inputs to every command that reads files.
#[test]
fn empty_and_garbage_files() {
    for text in [
        "",
        "\0\0\0",
        "name = \"x\"",
        "<robot/>",
        "{\"states\":[]}",
        "[[[[",
        "model = 3",
    ] {
        for ext in ["toml", "urdf", "json"] {
            let p = file(&format!("junk.{ext}"), text).display().to_string();
            for args in [
                vec![s("eval"), p.clone(), s("--states"), p.clone()],
                vec![s("count"), p.clone()],
                vec![s("generate"), p.clone()],
                vec![s("simulate"), p.clone()],
                vec![s("accuracy"), p.clone()],
                vec![s("sweep"), p.clone()],
                vec![s("merge"), p.clone(), s("--out"), p.clone() + ".merged"],
            ] {
                check(&args).unwrap();
            }
        }
    }
}

/// A case proptest found (`adversarial_models`): a prismatic joint of mass 5e-324, whose q̈
/// overflows `f64`. `accuracy` printed `inf` in its reference-check sentence; it says
/// `overflow`, as its tables do.
#[test]
fn accuracy_of_a_denormal_mass_prints_no_inf() {
    let model = file(
        "model.toml",
        "name = \"fuzz\"\n\n[[joint]]\nname = \"j0\"\ntype = \"prismatic\"\nxyz = [0.1, 0.2, 0.3]\n\
         axis = [0.0, 0.0, 1.0]\n[joint.body]\nmass = 5e-324\ncom = [0.1, 0.0, 0.0]\n\
         inertia = { ixx = 0.5, iyy = 0.6, izz = 0.7 }\n",
    );
    check(&[s("accuracy"), model.display().to_string()]).unwrap();
}
