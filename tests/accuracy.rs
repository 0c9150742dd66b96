//! `kanegen accuracy`: the committed docs/accuracy.md is the rendering of the
//! committed docs/accuracy.json, and that JSON's deterministic parts (errors, steps, operation
//! counts, trajectory changes) agree with a fresh run; the rows say what they should (f32 loses
//! digits that f64 keeps, fixed-step errors fall with the step at the integrator's order,
//! leaving an effect out moves the trajectory).
//!
//! Times are not compared: they come from a shared, noisy machine.

use kanegen::cli::commands::accuracy::{figure_name, render_markdown, run, Cost, DEFAULT_INPUTS};
use kanegen::cli::reports::accuracy::integration::IntegrationRow;
use kanegen::cli::reports::accuracy::{AccuracyReport, Options};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn committed() -> Vec<AccuracyReport> {
    let text = std::fs::read_to_string(root().join("docs/accuracy.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    serde_json::from_value(v["subjects"].clone()).unwrap()
}

fn fresh() -> Vec<AccuracyReport> {
    let inputs: Vec<PathBuf> = DEFAULT_INPUTS.iter().map(|p| root().join(p)).collect();
    let mut r = run(&inputs, false, Options { timing: false }).unwrap();
    for (x, name) in r.iter_mut().zip(DEFAULT_INPUTS) {
        x.subject = name.into();
    }
    r
}

/// `a` and `b` agree to a factor `f` (both finite and positive), or are both zero / both NaN.
fn close(a: f64, b: f64, f: f64) -> bool {
    (a.is_nan() && b.is_nan()) || a == b || (a > 0.0 && b > 0.0 && a / b < f && b / a < f)
}

#[test]
fn docs_accuracy_md_renders_docs_accuracy_json() {
    let reports = committed();
    let md = std::fs::read_to_string(root().join("docs/accuracy.md")).unwrap();
    assert!(
        md == render_markdown(&reports, true).unwrap(),
        "docs/accuracy.md is not the rendering of docs/accuracy.json: run \
         `cargo run --release -- accuracy --out docs --force`"
    );
    for r in &reports {
        if !r.integration.is_empty() {
            for cost in [Cost::Wall, Cost::Evals] {
                let svg = root().join("docs").join(figure_name(r, cost));
                assert!(svg.exists(), "{} missing", svg.display());
            }
        }
    }
}

const STALE: &str =
    "docs/accuracy.json is stale: run `cargo run --release -- accuracy --out docs --force`";

/// A committed integration run `a` and a fresh one `b` agree: same setting, final errors within
/// a factor 2 (or both below 1e-12), steps within 2 %.
fn same_run(subject: &str, a: &IntegrationRow, b: &IntegrationRow) {
    assert_eq!(
        (&a.integrator, &a.setting),
        (&b.integrator, &b.setting),
        "{STALE}"
    );
    match (a.final_error, b.final_error) {
        (Some(x), Some(y)) => assert!(
            close(x, y, 2.0) || x.max(y) < 1e-12,
            "{subject} {} {}: {x:e} vs {y:e}; {STALE}",
            a.integrator,
            a.setting
        ),
        (x, y) => assert_eq!(x.is_none(), y.is_none(), "{STALE}"),
    }
    let (s, t) = (a.steps as f64, b.steps as f64);
    assert!(
        (s - t).abs() <= 0.02 * s.max(t) + 2.0,
        "{subject} {} steps {s} vs {t}; {STALE}",
        a.setting
    );
}

/// Committed and fresh errors of one row agree: round-off errors may move a little with the
/// machine's libm; a factor 2 is a change.
fn same_errors(label: &str, committed: [f64; 3], fresh: [f64; 3]) {
    for (x, y) in committed.into_iter().zip(fresh) {
        assert!(close(x, y, 2.0), "{label}: {x:e} vs {y:e}; {STALE}");
    }
}

#[test]
fn docs_accuracy_json_is_fresh() {
    let (old, new) = (committed(), fresh());
    let stale = STALE;
    assert_eq!(old.len(), new.len(), "{stale}");
    for (o, n) in old.iter().zip(&new) {
        assert_eq!(
            (&o.subject, o.n, &o.base),
            (&n.subject, n.n, &n.base),
            "{stale}"
        );
        assert!(
            close(o.cond_a, n.cond_a, 1.001),
            "{}: cond {} vs {}; {stale}",
            o.subject,
            o.cond_a,
            n.cond_a
        );
        assert_eq!(o.evaluation.len(), n.evaluation.len(), "{stale}");
        for (a, b) in o.evaluation.iter().zip(&n.evaluation) {
            let label = format!("{} {} {}", o.subject, a.precision, a.path);
            same_errors(
                &label,
                [a.rel_err_a, a.rel_err_b, a.rel_err_qdd],
                [b.rel_err_a, b.rel_err_b, b.rel_err_qdd],
            );
        }
        assert_eq!(o.derivatives.len(), n.derivatives.len(), "{stale}");
        for (a, b) in o.derivatives.iter().zip(&n.derivatives) {
            assert_eq!((&a.precision, &a.path), (&b.precision, &b.path), "{stale}");
            let label = format!("{} derivatives {} {}", o.subject, a.precision, a.path);
            same_errors(
                &label,
                [a.rel_err_dtau, a.rel_err_dqdd, a.rel_err_minv],
                [b.rel_err_dtau, b.rel_err_dqdd, b.rel_err_minv],
            );
        }
        assert_eq!(o.integration.len(), n.integration.len(), "{stale}");
        for (a, b) in o.integration.iter().zip(&n.integration) {
            same_run(&o.subject, a, b);
        }
        assert_eq!(o.friction.len(), n.friction.len(), "{STALE}");
        for (a, b) in o.friction.iter().zip(&n.friction) {
            assert_eq!((a.v_s, a.scene), (b.v_s, b.scene), "{STALE}");
            same_run(&o.subject, &a.run, &b.run);
        }
        assert_eq!(o.effects.len(), n.effects.len(), "{stale}");
        for (a, b) in o.effects.iter().zip(&n.effects) {
            assert_eq!((&a.effect, a.ops), (&b.effect, b.ops), "{stale}");
            assert!(
                close(a.trajectory_change, b.trajectory_change, 1.01),
                "{stale}"
            );
        }
    }
}

#[test]
fn the_rows_say_what_they_should() {
    for r in committed() {
        let row = |p: &str, path: &str| {
            r.evaluation
                .iter()
                .find(|e| e.precision == p && e.path == path)
                .unwrap_or_else(|| panic!("{}: no {p} {path} row", r.subject))
        };
        let (f32r, f64r) = (row("f32", "interpreted"), row("f64", "interpreted"));
        // f64 keeps about 16 − log10 cond(A) digits of q̈, f32 about 7 − log10 cond(A): at least
        // 6 digits apart, and f64 within 10·cond(A)·ε of the reference.
        assert!(f32r.rel_err_qdd > 1e6 * f64r.rel_err_qdd, "{}", r.subject);
        assert!(
            f64r.rel_err_qdd < 10.0 * r.cond_a * f64::EPSILON,
            "{}: {:e}",
            r.subject,
            f64r.rel_err_qdd
        );
        assert!(
            f64r.rel_err_a < 1e-14 && f64r.rel_err_b < 1e-13,
            "{}",
            r.subject
        );
        // Compensated f64 is as good as computing in twice the precision: delivered in f64 it
        // is within an ulp or two of the reference; double-double is itself within 1e-28 of
        // exact rationals (measured ≤ 7.1e-30 for the 116 t payload, cond 1.2e5).
        let comp = row("compensated", "interpreted");
        assert!(
            comp.rel_err_qdd <= 2.0 * f64::EPSILON,
            "{}: {:e}",
            r.subject,
            comp.rel_err_qdd
        );
        let wide = row("wide", "interpreted");
        assert!(
            wide.rel_err_qdd < 1e-28 && wide.rel_err_a < 1e-30,
            "{}",
            r.subject
        );
        // Generated code, where there is any: f64 (plain and fused) as good as interpreted f64,
        // f32 six digits worse.
        let generated: Vec<_> = r
            .evaluation
            .iter()
            .filter(|e| e.path == "generated")
            .collect();
        for g in &generated {
            let bound = if g.precision == "f32" {
                10.0 * r.cond_a * f64::from(f32::EPSILON)
            } else {
                10.0 * r.cond_a * f64::EPSILON
            };
            assert!(
                g.rel_err_qdd < bound,
                "{} generated {}: {:e}",
                r.subject,
                g.precision,
                g.rel_err_qdd
            );
        }
        if let (Some(g32), Some(g64)) = (
            generated.iter().find(|g| g.precision == "f32"),
            generated.iter().find(|g| g.precision == "f64"),
        ) {
            assert!(g32.rel_err_qdd > 1e6 * g64.rel_err_qdd, "{}", r.subject);
        }
        derivative_rows_say_what_they_should(&r);
        // Fixed-step integrators: halving the step divides the error by about 2^p while above
        // the reference's floor (RK4 p = 4, midpoint p = 2); checked on the two finest steps.
        // With Coulomb friction the steps of the ladder are not yet in the asymptotic range
        // (the slope τ_c / v_s of tanh is 2e5 N·m·s on ssrms_drives: RK4 measured 8.7 there),
        // so the error must fall at least at the order, not at exactly it.
        for (name, p) in [("rk4", 4.0), ("midpoint", 2.0)] {
            let errs: Vec<f64> = r
                .integration
                .iter()
                .filter(|i| i.integrator == name)
                .filter_map(|i| i.final_error)
                .collect();
            if let [.., a, b] = errs[..] {
                if b > 1e3 * r.integration_reference_error.unwrap() {
                    let order = (a / b).log2();
                    let ok = if r.friction.is_empty() {
                        (order - p).abs() < 0.5
                    } else {
                        order > p - 0.5
                    };
                    assert!(ok, "{} {name}: order {order:.2}", r.subject);
                }
            }
        }
        // Coulomb regularization: a finer v_s comes closer to the finest (the error falls,
        // measured 2.4e-2, 2.2e-2, 8.2e-3, 1.2e-3 on ssrms_drives), and costs more steps
        // (229, 413, 886, 4010, 37424).
        for w in r.friction.windows(2) {
            assert!(
                w[0].v_s > w[1].v_s,
                "{}: ladder not coarse to fine",
                r.subject
            );
            assert!(
                w[1].run.steps > w[0].run.steps,
                "{}: v_s {:e} no dearer",
                r.subject,
                w[1].v_s
            );
            if let (Some(a), Some(b)) = (w[0].run.final_error, w[1].run.final_error) {
                assert!(b < a, "{}: v_s {:e} no closer", r.subject, w[1].v_s);
            }
        }
        if let Some(last) = r.friction.last() {
            assert_eq!(last.run.final_error, Some(0.0), "{}", r.subject);
            assert!(
                r.friction.iter().filter(|f| f.scene).count() == 1,
                "{}",
                r.subject
            );
        }
        for e in &r.effects {
            assert!(e.ops > 0, "{}: {} costs nothing", r.subject, e.effect);
            assert!(
                e.trajectory_change > 1e-8,
                "{}: {} changes nothing",
                r.subject,
                e.effect
            );
        }
    }
}

/// Max-norm of `a − b`, relative to `max(1, |b|∞)`.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// The fixed-step integrators' orders on a fresh run (not the committed JSON): the SRMS scene
/// (PD drives, damping) over 2 s, RK4 at h = 0.04, 0.02, 0.01 and the implicit midpoint rule at
/// h = 0.02, 0.01, 0.005, each final state against a reference whose own error is measured —
/// dopri5 at its tightest tolerance (1e-14) against an independent Richardson-extrapolated RK4
/// (h = 2.5e-3 and 1.25e-3, `x(h/2) + (x(h/2) − x(h))/15`): every error must be 1000× the
/// reference's, and halving the step must divide it by 2^p (RK4 p = 4, midpoint p = 2) within
/// ±0.3 in p.
#[test]
fn fixed_step_orders_on_a_fresh_run_against_a_measured_reference() {
    use kanegen::sim::integrate::{dopri5, midpoint, rk4, Dopri5Options};
    use kanegen::sim::scene::Scene;
    use kanegen::sim::simulate::SceneSystem;
    let mut scene = Scene::load(&root().join("scenes/srms.toml")).unwrap();
    let t1 = 2.0;
    scene.simulation.duration = t1;
    let run = |method: &str, h: f64| -> Vec<f64> {
        let mut sys = SceneSystem::new(&scene);
        let mut x = sys.initial_state();
        match method {
            "rk4" => {
                rk4(&mut sys, 0.0, t1, h, &mut x, |_, _, _| {}).unwrap();
            }
            "midpoint" => {
                midpoint(&mut sys, 0.0, t1, h, &mut x, |_, _, _| {}).unwrap();
            }
            _ => {
                let opts = Dopri5Options {
                    tolerance: h,
                    max_step: 0.05,
                    initial_step: 1e-3,
                    output_interval: t1,
                };
                dopri5(&mut sys, 0.0, t1, &opts, &mut x, |_, _| {}).unwrap();
            }
        }
        x
    };
    let reference = run("dopri5", kanegen::sim::scene::MIN_TOLERANCE);
    let (coarse, fine) = (run("rk4", 2.5e-3), run("rk4", 1.25e-3));
    let richardson: Vec<f64> = coarse
        .iter()
        .zip(&fine)
        .map(|(c, f)| f + (f - c) / 15.0)
        .collect();
    let ref_error = rel_diff(&reference, &richardson);
    println!("reference (dopri5 1e-14) against Richardson RK4: {ref_error:.2e}");
    assert!(ref_error < 1e-11, "reference error {ref_error:.2e}");
    for (method, p, steps) in [
        ("rk4", 4.0, [0.04, 0.02, 0.01]),
        ("midpoint", 2.0, [0.02, 0.01, 0.005]),
    ] {
        let errs: Vec<f64> = steps
            .iter()
            .map(|&h| rel_diff(&run(method, h), &reference))
            .collect();
        for (h, e) in steps.iter().zip(&errs) {
            println!("{method} h = {h}: error {e:.3e}");
            assert!(
                *e > 1e3 * ref_error,
                "{method} h = {h}: {e:.2e} at the reference's floor"
            );
        }
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).log2();
            println!("{method}: observed order {order:.3}");
            assert!(
                (order - p).abs() < 0.3,
                "{method}: order {order:.3}, expected {p}"
            );
        }
    }
}

/// The derivative rows of a model: interpreted and generated `f64` within a few hundred ulps
/// of the double-double reference for `∂τ/∂x` and `M⁻¹` (products and sums of the state's
/// sines, no cancellation beyond `M`'s conditioning: measured ≤ 7e-16 on SSRMS), `∂q̈/∂x =
/// −M⁻¹ ∂τ/∂x` within `10·cond(A)·ε` like `q̈`; `f32` at least four digits worse; double-double
/// within 1e-28 of exact rationals. The generated rows are those of the checked-in SSRMS
/// variants, all generated with derivatives.
fn derivative_rows_say_what_they_should(r: &AccuracyReport) {
    if r.kind != "model" {
        assert!(r.derivatives.is_empty(), "{}", r.subject);
        return;
    }
    let row = |p: &str, path: &str| {
        r.derivatives
            .iter()
            .find(|e| e.precision == p && e.path == path)
            .unwrap_or_else(|| panic!("{}: no {p} {path} derivative row", r.subject))
    };
    let wide = row("wide", "interpreted");
    assert!(
        wide.rel_err_dtau < 1e-28 && wide.rel_err_dqdd < 1e-26 && wide.rel_err_minv < 1e-28,
        "{}: {wide:?}",
        r.subject
    );
    for path in ["interpreted", "generated"] {
        let (f32r, f64r) = (row("f32", path), row("f64", path));
        assert!(
            f64r.rel_err_dtau < 1e-14 && f64r.rel_err_minv < 1e-14,
            "{} {path}: {f64r:?}",
            r.subject
        );
        assert!(
            f64r.rel_err_dqdd < 10.0 * r.cond_a * f64::EPSILON,
            "{} {path}: {f64r:?}",
            r.subject
        );
        assert!(
            f32r.rel_err_dtau > 1e4 * f64r.rel_err_dtau,
            "{} {path}: {f32r:?}",
            r.subject
        );
    }
    let fma = row("f64-fma", "generated");
    assert!(
        fma.rel_err_dtau < 1e-14 && fma.rel_err_minv < 1e-14,
        "{}: {fma:?}",
        r.subject
    );
}
