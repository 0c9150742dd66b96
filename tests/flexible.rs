//! Flexible joints (Spong 1987, `[effects] flexible`) and the stiff integrator (Rodas4,
//! `integrator = "rosenbrock"`). Measured values (release build, this machine) are in
//! each test's doc; run with `--nocapture` to see them.

use kanegen::dynamics::{Loads, Params};
use kanegen::sim::scene::{Integrator, Scene};
use kanegen::sim::simulate::{simulate, Run, SceneSystem};

mod common;
use common::{load, max_abs_diff, scene, scene_err, worst};

kanegen::scene!(SsrmsFlexible, "scenes/ssrms_flexible.toml");
kanegen::scene!(FlexK1e3, "tests/data/scenes/flex_k1e3.toml");
kanegen::scene!(FlexK1e4, "tests/data/scenes/flex_k1e4.toml");
kanegen::scene!(FlexK1e5, "tests/data/scenes/flex_k1e5.toml");
kanegen::scene!(FlexK1e6, "tests/data/scenes/flex_k1e6.toml");
kanegen::scene!(FlexK1e7, "tests/data/scenes/flex_k1e7.toml");
kanegen::scene!(FlexK1e8, "tests/data/scenes/flex_k1e8.toml");

fn final_state(s: &Scene) -> (Vec<f64>, Run) {
    let run = simulate(s, None).unwrap_or_else(|e| panic!("{e:#}"));
    (run.samples.last().unwrap().x.clone(), run)
}

/// Bad `[effects] flexible` values and combinations are errors naming the key.
#[test]
fn bad_flexible_values_name_the_key() {
    let two = |effects: &str, extra: &str| {
        format!(
            "model = \"models/two_link.toml\"\n{extra}\n[effects]\n{effects}\n\
             [simulation]\nduration = 1.0\n"
        )
    };
    let cases = [
        (two("flexible = { stiffness = 0.0, motor_inertia = 1.0 }", ""), "effects.flexible.stiffness"),
        (two("flexible = { stiffness = -1e4, motor_inertia = 1.0 }", ""), "must be > 0"),
        (two("flexible = { stiffness = [1e4], motor_inertia = 1.0 }", ""), "expected 2 values"),
        (two("flexible = { stiffness = 1e4, motor_inertia = 0.0 }", ""), "effects.flexible.motor_inertia"),
        (two("flexible = { stiffness = 1e4, motor_inertia = 1.0, damping = -1.0 }", ""), "effects.flexible.damping"),
        (two("flexible = { stiffness = 1e4, motor_inertia = 1.0, gear_ratio = 0.0 }", ""), "effects.flexible.gear_ratio"),
        (two("flexible = { stiffness = 1e400, motor_inertia = 1.0 }", ""), "stiffness"),
        (two("flexible = { stiffness = 1e4 }", ""), "motor_inertia"),
        (two("flexible = { stiffness = 1e4, motor_inertia = 1.0, spring = 2.0 }", ""), "spring"),
        (
            two(
                "flexible = { stiffness = 1e4, motor_inertia = 1.0 }\n\
                 rotor = { inertia = [1.0, 1.0], gear_ratio = [1.0, 1.0] }",
                "",
            ),
            "effects.rotor",
        ),
        (
            two(
                "flexible = { stiffness = 1e4, motor_inertia = 1.0 }",
                "[base]\ntype = \"free-floating\"\nmass = 10.0\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }",
            ),
            "fixed base only",
        ),
        (
            format!(
                "{}integrator = \"rosenbrok\"\n",
                two("flexible = { stiffness = 1e4, motor_inertia = 1.0 }", "")
            ),
            "rosenbrock",
        ),
    ];
    for (text, want) in cases {
        let e = scene_err(&text);
        assert!(e.contains(want), "want `{want}` in: {e}");
    }
}

/// With no drives and no damping anywhere, the total energy — link kinetic, motor kinetic
/// `½ Σ B θ̇²` and spring potential `½ Σ K (θ − q)²` — is conserved: SSRMS with K = 1e5 N·m/rad,
/// moving from rest-length springs, 2 s under Rodas4 at tolerance 1e-11 keeps it to a measured
/// 3.8e-15 relative (bound 1e-8), while the motor-plus-spring part alone swings by a measured
/// 3.2e-3 of the total (bound: at least 1e4 × the drift) — energy flows through the springs and
/// back, and the monitor sees it.
#[test]
fn energy_is_conserved_without_drives_or_damping() {
    let s = scene(
        r#"
model = "tests/data/reference/ssrms_nguyen_hughes_1994.urdf"
[effects]
flexible = { stiffness = 1e5, motor_inertia = [1e-3, 1e-3, 1e-3, 1e-3, 5e-4, 5e-4, 5e-4], gear_ratio = [1000.0, 1000.0, 1000.0, 1000.0, 500.0, 500.0, 500.0] }
[initial]
q = [0.0, 0.2, -0.8, 0.5, 0.0, 0.3, 0.0]
qd = [0.05, -0.04, 0.06, 0.03, -0.08, 0.05, 0.07]
[simulation]
duration = 2.0
integrator = "rosenbrock"
tolerance = 1e-11
step = 0.001
output_every = 10
"#,
    );
    let run = simulate(&s, None).unwrap();
    let sys = SceneSystem::new(&s);
    let f = s.flexible.as_ref().unwrap();
    let e: Vec<f64> = run
        .samples
        .iter()
        .map(|x| sys.energy(&x.x).unwrap())
        .collect();
    let inner: Vec<f64> = run
        .samples
        .iter()
        .map(|x| f.energy(&x.x[..7], &x.x[14..21], &x.x[21..]))
        .collect();
    let e0 = e[0];
    let drift = e.iter().fold(0.0_f64, |m, v| m.max((v - e0).abs())) / e0;
    let (lo, hi) = inner
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(*v), b.max(*v)));
    let swing = (hi - lo) / e0;
    eprintln!(
        "energy drift {drift:.2e}, motor+spring swing {swing:.2e}, {} steps",
        run.summary.steps
    );
    assert!(drift < 1e-8, "energy drift {drift:e}");
    assert!(swing > 1e4 * drift, "motor+spring energy swing {swing:e}");
    assert!(run.summary.max_energy_drift_rel.is_some());
}

/// `scenes/ssrms_flexible.toml` (K = 1e8 N·m/rad): Rodas4 at tolerance 1e-8 reaches the final
/// state within a measured 1.8e-10 (bound 1e-7) of Rodas4 at 1e-12 — checked against an
/// independent method over the first 2 s, RK4 at h = 1e-4 (agreement measured 5.7e-12, bound
/// 1e-8) — with an average step of 5.7e-2 s (527 steps over 30 s); RK4 at a step 100× smaller
/// than that average diverges within the first second (its largest stable step, measured by
/// bisection over 2 s, is between 2.5e-4 and 3e-4 s: about 200× below the Rodas4 average).
#[test]
fn stiff_integrator_beats_rk4_by_100x() {
    let base = load("scenes/ssrms_flexible.toml");
    assert_eq!(base.simulation.integrator, Integrator::Rosenbrock);
    assert_eq!(base.simulation.tolerance, 1e-8);
    let (x, run) = final_state(&base);
    let mut tight = base.clone();
    tight.simulation.tolerance = 1e-12;
    let (xr, _) = final_state(&tight);
    let err = max_abs_diff(&x, &xr);
    let avg = base.simulation.duration / run.summary.steps as f64;
    eprintln!(
        "rosenbrock 1e-8: error {err:.2e} vs 1e-12, {} steps, average step {avg:.3e}",
        run.summary.steps
    );
    assert!(err < 1e-7, "final-state error {err:e}");

    // The tight reference against RK4 over 2 s.
    let mut short = tight.clone();
    short.simulation.duration = 2.0;
    short.simulation.max_step = 2.0;
    let (xs, _) = final_state(&short);
    let mut rk = short.clone();
    rk.simulation.integrator = Integrator::Rk4;
    rk.simulation.step = 1e-4;
    let (xk, _) = final_state(&rk);
    let agree = max_abs_diff(&xs, &xk);
    eprintln!("rosenbrock 1e-12 vs rk4 h = 1e-4 over 2 s: {agree:.2e}");
    assert!(agree < 1e-8, "{agree:e}");

    // RK4 at avg / 100 blows up (or leaves any physical range) within 1 s.
    let mut rk = base.clone();
    rk.simulation.integrator = Integrator::Rk4;
    rk.simulation.duration = 1.0;
    rk.simulation.step = avg / 100.0;
    let blew = match simulate(&rk, None) {
        Err(_) => true,
        Ok(r) => r.samples.last().unwrap().x.iter().any(|v| v.abs() > 1e3),
    };
    eprintln!("rk4 at h = {:.3e}: diverged {blew}", avg / 100.0);
    assert!(
        blew,
        "RK4 at a step 100× below the Rodas4 average stayed bounded"
    );
}

/// The compiled scene (`scene!`, `kanegen::ode::rosenbrock`) samples at the interpreted run's
/// times and agrees with it to within the integrator tolerance: measured 9.8e-11 relative
/// (bound 1e-7). The step sequences are the same method's but not identical (528 compiled
/// steps, 527 interpreted): the right-hand sides differ by rounding, which the difference
/// quotients of the Jacobian amplify (to ~1e-11 relative in `J`), enough to move a step-size
/// decision; each run still meets the tolerance.
#[test]
fn compiled_ssrms_flexible_matches_interpreted() {
    let s = load("scenes/ssrms_flexible.toml");
    let run = simulate(&s, None).unwrap();
    let mut c = Vec::new();
    let stats = SsrmsFlexible::run(|t, st| c.push((t, st.to_array()))).unwrap();
    let w = worst("ssrms_flexible", &c, &run);
    eprintln!(
        "ssrms_flexible: compiled vs interpreted {w:.2e}; steps {} vs {}",
        stats.steps, run.summary.steps
    );
    assert!(w < 1e-7, "{w:e}");
}

/// Hard case: stiffness 1e3 … 1e8 N·m/rad on the two-link arm under gravity (PD drives on the
/// motors, 10 s, Rodas4 at 1e-8), interpreted and compiled:
///
/// - every run completes (251–279 steps), bounded (|x| ≤ 10), compiled and interpreted
///   agreeing to a measured ≤ 5.6e-13 relative (bound 1e-6);
/// - the run settles to the static deflection `θ − q = G(q) / K` (`G` the gravity torque, the
///   inverse dynamics at rest): measured ≤ 3e-11 relative to `|G|/K` (bound 1e-3);
/// - infinite-stiffness limit: the link coordinates tend to the rigid arm with rotor inertia `B`
///   on `M`'s diagonal (`[effects] rotor`, same drives, dopri5 at 1e-11): `|q_K − q_rigid|` at
///   the end is measured 1.0e-1 at K = 1e3 and 1.1e-6 at 1e8, `K · gap` constant to 7 %
///   (bound: within a factor 2 of K = 1e4's at every K ≥ 1e4, and < 2e-6 at K = 1e8).
#[test]
fn stiffness_ladder_interpreted_and_compiled() {
    fn compiled_final<const D: usize>(
        run: impl FnOnce(&mut dyn FnMut(f64, [f64; D])) -> kanegen::ode::Stats,
    ) -> Vec<(f64, [f64; D])> {
        let mut out = Vec::new();
        run(&mut |t, x| out.push((t, x)));
        out
    }
    let compiled: [Vec<(f64, [f64; 8])>; 6] = [
        compiled_final(|o| FlexK1e3::run(|t, s| o(t, s.to_array())).unwrap()),
        compiled_final(|o| FlexK1e4::run(|t, s| o(t, s.to_array())).unwrap()),
        compiled_final(|o| FlexK1e5::run(|t, s| o(t, s.to_array())).unwrap()),
        compiled_final(|o| FlexK1e6::run(|t, s| o(t, s.to_array())).unwrap()),
        compiled_final(|o| FlexK1e7::run(|t, s| o(t, s.to_array())).unwrap()),
        compiled_final(|o| FlexK1e8::run(|t, s| o(t, s.to_array())).unwrap()),
    ];
    let rigid = scene(
        r#"
model = "models/two_link.toml"
[effects]
gravity = [0.0, -9.81, 0.0]
rotor = { inertia = [0.01, 0.01], gear_ratio = [10.0, 10.0] }
[drives]
type = "pd"
kp = 200.0
kd = 100.0
target = [0.5, -0.3]
[simulation]
duration = 10.0
integrator = "dopri5"
tolerance = 1e-11
step = 0.01
output_every = 100
"#,
    );
    let (xr, _) = final_state(&rigid);
    let mut k_gap_1e4 = f64::NAN;
    let mut last_gap = f64::INFINITY;
    for (e, c) in (3..=8).zip(&compiled) {
        let s = load(&format!("tests/data/scenes/flex_k1e{e}.toml"));
        let k = 10f64.powi(e);
        let (x, run) = final_state(&s);
        assert!(x.iter().all(|v| v.abs() <= 10.0), "K = 1e{e}: {x:?}");
        let w = worst(&format!("K = 1e{e}"), c, &run);
        assert!(w < 1e-6, "K = 1e{e}: compiled vs interpreted {w:e}");
        // Static deflection: G(q) = ID(q, 0, 0) with gravity.
        let params = Params::new(&s.model);
        let loads = Loads {
            tau: None,
            gravity: s.gravity.map(kanegen::dynamics::linalg::Vec3::from_f64),
            external: Vec::new(),
        };
        let g =
            s.simulation
                .algorithm
                .inverse_dynamics(&params, &x[..2], &[0.0; 2], &[0.0; 2], &loads);
        let gn = g.iter().map(|v| v.abs()).fold(0.0, f64::max);
        let defl: Vec<f64> = (0..2).map(|i| x[4 + i] - x[i]).collect();
        let want: Vec<f64> = g.iter().map(|v| v / k).collect();
        let rel = max_abs_diff(&defl, &want) / (gn / k);
        let gap = max_abs_diff(&x[..2], &xr[..2]);
        eprintln!(
            "K = 1e{e}: {} steps, compiled vs interpreted {w:.1e}, deflection vs G/K {rel:.1e}, \
             |q − q_rigid| {gap:.1e}",
            run.summary.steps
        );
        assert!(rel < 1e-3, "K = 1e{e}: deflection {defl:?} vs G/K {want:?}");
        assert!(gap < last_gap, "K = 1e{e}: gap to the rigid arm grew");
        if e == 4 {
            k_gap_1e4 = k * gap;
        }
        if e > 4 {
            let r = k * gap / k_gap_1e4;
            assert!(
                (0.5..2.0).contains(&r),
                "K = 1e{e}: K·gap / (K·gap at 1e4) = {r}"
            );
        }
        last_gap = gap;
    }
    assert!(
        last_gap < 2e-6,
        "K = 1e8: gap to the rigid arm {last_gap:e}"
    );
}

/// `count SCENE` lists `flexible` with its formula cost (7 joints, all damped: per joint 2 mul,
/// 4 add, 1 div), and the drive effects' golden counts are unchanged
/// (`tests/drive_effects.rs::scenes_without_the_effects_are_unchanged`).
#[test]
fn count_lists_flexible() {
    let out = common::kanegen(&["count", "scenes/ssrms_flexible.toml", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let lines: Vec<_> = v["effects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["effect"] == "flexible")
        .collect();
    assert_eq!(lines.len(), 3 * 2, "3 bias methods × 2 conventions");
    for l in lines {
        assert_eq!(
            (l["mul"].as_i64(), l["add"].as_i64(), l["div"].as_i64()),
            (Some(14), Some(28), Some(7)),
            "{l}"
        );
    }
}

/// The work–precision report gives a flexible scene the stiff integrator's ladder beside RK4,
/// midpoint and dopri5 (two-link arm, K = 1e6, first 2 s): every rosenbrock row completes and
/// its error stays within 10× of the tolerance (measured 4.0e-5, 5.6e-7, 6.6e-9, 6.5e-11, 1.5e-12
/// relative at 1e-4 … 1e-12, in 23, 68, 213, 693, 2937 steps; bound 10 × max(tol, 1e-11)). At
/// 1e-8 it takes fewer steps than dopri5 (measured 213 against 3233).
#[test]
fn accuracy_report_has_the_stiff_ladder() {
    use kanegen::cli::reports::accuracy::integration::{integration_report, TOLERANCES};
    let mut s = load("tests/data/scenes/flex_k1e6.toml");
    s.simulation.duration = 2.0;
    s.simulation.max_step = 2.0;
    let r = integration_report(&s, 1).unwrap();
    let rows = |name: &str| -> Vec<_> { r.rows.iter().filter(|x| x.integrator == name).collect() };
    for name in ["rk4", "midpoint", "dopri5"] {
        assert_eq!(rows(name).len(), 5, "{name}");
    }
    let ros = rows("rosenbrock");
    assert_eq!(ros.len(), TOLERANCES.len());
    for (row, tol) in ros.iter().zip(TOLERANCES) {
        let e = row.final_error.unwrap_or_else(|| panic!("{row:?}"));
        eprintln!("rosenbrock tol {tol:e}: error {e:.2e}, {} steps", row.steps);
        assert!(e < 10.0 * tol.max(1e-11), "tol {tol:e}: error {e:e}");
    }
    let dopri = rows("dopri5");
    let (rs, ds) = (ros[2].steps, dopri[2].steps);
    eprintln!("tol 1e-8: rosenbrock {rs} steps, dopri5 {ds}");
    assert!(rs < ds, "rosenbrock {rs} steps, dopri5 {ds}");
}
