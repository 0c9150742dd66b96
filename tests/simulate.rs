//! Scenes and simulation: conservation of momentum and energy along simulated
//! trajectories, RK4's empirical order, dopri5 against a fine RK4 and an exact solution, every
//! example scene, scene validation errors, and one CLI smoke test.
//!
//! Run with `--nocapture` to see the measured numbers.

use kanegen::model::Inertial;
use kanegen::sim::integrate::{dopri5, rk4, Dopri5Options, System};
use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate, SceneSystem};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scene(text: &str) -> Scene {
    Scene::parse(text, &root()).unwrap_or_else(|e| panic!("{e:#}"))
}

fn scene_err(text: &str) -> String {
    match Scene::parse(text, &root()) {
        Ok(_) => panic!("scene accepted:\n{text}"),
        Err(e) => format!("{e:#}"),
    }
}

/// The 7-dof arm on its 1000 kg free-floating base, with a moving initial state.
fn floating(drives: &str, simulation: &str) -> String {
    format!(
        r#"
model = "tests/data/reference/bmsd_7dof_free_floating.urdf"
allow_nonphysical = true
[base]
type = "free-floating"
position = [0.5, -0.2, 1.0]
quaternion = [0.1, -0.2, 0.3, 0.9]
v = [0.05, -0.02, 0.03]
omega = [0.02, 0.05, -0.03]
{drives}
[initial]
q = [0.1, 0.3, -0.2, -0.5, 0.4, 0.2, -0.1]
qd = [0.3, -0.4, 0.5, 0.2, -0.6, 0.4, 0.7]
[simulation]
{simulation}
"#
    )
}

const PD: &str = r#"
[drives]
type = "pd"
kp = 20.0
kd = [5.0, 5.0, 5.0, 2.0, 2.0, 1.0, 1.0]
target = [0.5, -0.4, 0.3, 0.6, -0.2, 0.4, 0.1]
"#;

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn free_floating_momentum_is_conserved_with_drives_acting() {
    let s = scene(&floating(
        &format!("{PD}\n[effects]\ndamping = [1.0, 1.0, 1.0, 0.5, 0.5, 0.5, 0.5]"),
        "duration = 2.0\nintegrator = \"dopri5\"\ntolerance = 1e-10\noutput_every = 5",
    ));
    let run = simulate(&s, None).unwrap();
    let sm = &run.summary;
    let (lin, ang) = (
        sm.max_linear_momentum_drift_rel.unwrap(),
        sm.max_angular_momentum_drift_rel.unwrap(),
    );
    println!(
        "momentum drift over 2 s (dopri5 1e-10, PD + damping): linear {lin:.2e}, angular {ang:.2e}, \
         {} steps, {} rejected, {:.3} s",
        sm.steps, sm.rejected_steps, sm.wall_s
    );
    assert!(lin < 1e-9 && ang < 1e-9, "momentum drift {lin:e} {ang:e}");
    // Not conserved with drives and damping: energy is not monitored.
    assert!(sm.max_energy_drift_rel.is_none());
    // The drives really act: the joints moved far from a coasting motion.
    let q0 = &s.q0;
    let moved = max_abs_diff(&sm.final_state.q, q0);
    assert!(moved > 0.1, "the arm barely moved ({moved})");
    assert!(run.samples.len() > 10);
}

#[test]
fn momentum_is_not_conserved_under_an_external_wrench() {
    // The monitor is off (null) when a wrench acts, and the wrench really changes momentum.
    let s = scene(&floating(
        "[[effects.wrench]]\nbody = \"link_7\"\nframe = \"inertial\"\nforce = [10.0, 0.0, 0.0]",
        "duration = 0.5\nintegrator = \"rk4\"\nstep = 0.01",
    ));
    let run = simulate(&s, None).unwrap();
    assert!(run.summary.max_linear_momentum_drift_rel.is_none());
    let sys = SceneSystem::new(&s);
    let (p0, _) = sys.momentum(&run.samples[0].x).unwrap();
    let (p1, _) = sys.momentum(&run.samples.last().unwrap().x).unwrap();
    // Impulse 10 N · 0.5 s along x.
    assert!(
        ((p1[0] - p0[0]) - 5.0).abs() < 1e-6,
        "Δp_x = {}",
        p1[0] - p0[0]
    );
    assert!((p1[1] - p0[1]).abs() < 1e-6 && (p1[2] - p0[2]).abs() < 1e-6);
}

#[test]
fn a_tabulated_wrench_delivers_its_impulse() {
    // ṗ = F(t) on a free-floating system whatever the arm does, so Δp = ∫F dt: the area under
    // the piecewise-linear table, held at its last row after t = 0.5 (breakpoints on step
    // boundaries). p is not linear in the state (it depends on q through the base rows of A),
    // so RK4 does not carry the impulse exactly: measured error 5e-8 at h = 0.01, bound 1e-6
    // (the constant-wrench test's).
    let s = scene(&floating(
        r#"[[effects.wrench]]
body = "link_4"
frame = "inertial"
time = [0.0, 0.2, 0.5]
force = [[0.0, 0.0, 0.0], [20.0, 0.0, 0.0], [0.0, 5.0, 0.0]]"#,
        "duration = 0.6\nintegrator = \"rk4\"\nstep = 0.01",
    ));
    let run = simulate(&s, None).unwrap();
    let sys = SceneSystem::new(&s);
    let (p0, _) = sys.momentum(&run.samples[0].x).unwrap();
    let (p1, _) = sys.momentum(&run.samples.last().unwrap().x).unwrap();
    // x: ½·0.2·20 + ½·0.3·20 = 5; y: ½·0.3·5 + 0.1·5 = 1.25.
    let dp = [0, 1, 2].map(|i| p1[i] - p0[i]);
    println!("tabulated wrench: Δp = {dp:?}, expected [5, 1.25, 0]");
    assert!(max_abs_diff(&dp, &[5.0, 1.25, 0.0]) < 1e-6, "Δp = {dp:?}");

    // A table whose rows are all equal is the constant wrench: the same trajectory.
    let constant = scene(&floating(
        "[[effects.wrench]]\nbody = \"link_7\"\nframe = \"body\"\nforce = [1.0, -2.0, 3.0]\nmoment = [0.5, 0.0, -0.5]",
        "duration = 0.3\nintegrator = \"rk4\"\nstep = 0.01",
    ));
    let table = scene(&floating(
        "[[effects.wrench]]\nbody = \"link_7\"\nframe = \"body\"\ntime = [-1.0, 7.0]\nforce = [[1.0, -2.0, 3.0], [1.0, -2.0, 3.0]]\nmoment = [[0.5, 0.0, -0.5], [0.5, 0.0, -0.5]]",
        "duration = 0.3\nintegrator = \"rk4\"\nstep = 0.01",
    ));
    let (a, b) = (
        simulate(&constant, None).unwrap(),
        simulate(&table, None).unwrap(),
    );
    let (xa, xb) = (&a.samples.last().unwrap().x, &b.samples.last().unwrap().x);
    assert!(max_abs_diff(xa, xb) < 1e-12, "{}", max_abs_diff(xa, xb));
    // ... and differs from the motion without it.
    let free = simulate(
        &scene(&floating(
            "",
            "duration = 0.3\nintegrator = \"rk4\"\nstep = 0.01",
        )),
        None,
    )
    .unwrap();
    assert!(max_abs_diff(xa, &free.samples.last().unwrap().x) > 1e-4);
}

#[test]
fn energy_is_conserved_without_drives() {
    let s = scene(&floating(
        "",
        "duration = 2.0\nintegrator = \"dopri5\"\ntolerance = 1e-10",
    ));
    let sm = simulate(&s, None).unwrap().summary;
    let e = sm.max_energy_drift_rel.unwrap();
    println!("free-floating energy drift over 2 s (dopri5 1e-10, τ = 0): {e:.2e}");
    assert!(e < 1e-8, "energy drift {e:e}");
    assert!(sm.max_angular_momentum_drift_rel.unwrap() < 1e-9);

    // Fixed base under gravity: kinetic + potential is conserved.
    let s = scene(
        r#"
model = "tests/data/reference/srms_nguyen_hughes_1994.urdf"
[effects]
gravity = [0.0, -3.0, -9.81]
[initial]
q = [0.2, 0.4, -0.3, 0.1, 0.5, 0.0]
qd = [0.1, 0.0, 0.2, -0.3, 0.0, 0.4]
[simulation]
duration = 1.0
integrator = "dopri5"
tolerance = 1e-10
"#,
    );
    let run = simulate(&s, None).unwrap();
    let e = run.summary.max_energy_drift_rel.unwrap();
    println!("fixed-base energy (T + V) drift over 1 s under gravity: {e:.2e}");
    assert!(e < 1e-8, "energy drift {e:e}");
    // Kinetic energy alone changes a lot (the arm falls): the potential term matters.
    let sys = SceneSystem::new(&s);
    let kinetic = |x: &[f64]| {
        let mut x = x.to_vec();
        let n = s.model.dof();
        let free = Scene {
            gravity: None,
            ..s.clone()
        };
        let sys = SceneSystem::new(&free);
        x.truncate(2 * n);
        sys.energy(&x).unwrap()
    };
    let (x0, x1) = (&run.samples[0].x, &run.samples.last().unwrap().x);
    let total0 = sys.energy(x0).unwrap();
    assert!((kinetic(x1) - kinetic(x0)).abs() > 1e3 * e * total0.abs());
}

#[test]
fn rk4_has_order_four() {
    // Richardson: for order p, |x_h − x_{h/2}| / |x_{h/2} − x_{h/4}| → 2^p.
    let s = scene(&floating(PD, "duration = 1.0\nintegrator = \"rk4\""));
    let final_state = |h: f64| {
        let mut sys = SceneSystem::new(&s);
        let mut x = sys.initial_state();
        rk4(&mut sys, 0.0, 1.0, h, &mut x, |_, _, _| {}).unwrap();
        x
    };
    let h = 0.025;
    let x: Vec<Vec<f64>> = (0..4).map(|k| final_state(h / f64::from(1 << k))).collect();
    let d: Vec<f64> = (0..3).map(|k| max_abs_diff(&x[k], &x[k + 1])).collect();
    let (o1, o2) = ((d[0] / d[1]).log2(), (d[1] / d[2]).log2());
    println!(
        "RK4 |x_h − x_h/2| at h = {h}, h/2, h/4: {:.3e}, {:.3e}, {:.3e}; orders {o1:.3}, {o2:.3}",
        d[0], d[1], d[2]
    );
    assert!((o1 - 4.0).abs() < 0.2, "order {o1}");
    assert!((o2 - 4.0).abs() < 0.2, "order {o2}");
}

#[test]
fn dopri5_agrees_with_a_fine_rk4() {
    // Samples every 0.1 s: dopri5's from its dense output, RK4's at its steps.
    let fast = scene(&floating(
        PD,
        "duration = 2.0\nintegrator = \"dopri5\"\ntolerance = 1e-10\nstep = 0.01\noutput_every = 10",
    ));
    let fine = scene(&floating(
        PD,
        "duration = 2.0\nintegrator = \"rk4\"\nstep = 0.0025\noutput_every = 40",
    ));
    let a = simulate(&fast, None).unwrap();
    let b = simulate(&fine, None).unwrap();
    assert_eq!(a.samples.len(), b.samples.len());
    assert_eq!(a.samples.len(), 21);
    let mut worst = 0.0_f64;
    for (x, y) in a.samples.iter().zip(&b.samples) {
        assert!((x.t - y.t).abs() < 1e-12);
        worst = worst.max(max_abs_diff(&x.x, &y.x));
    }
    println!(
        "dopri5 (1e-10, {} steps, {} rejected) vs RK4 h = 0.0025: max |Δx| = {worst:.2e}",
        a.summary.steps, a.summary.rejected_steps
    );
    assert!(worst < 1e-8, "max difference {worst:e}");
    assert!(a.summary.steps < b.summary.steps / 3);
}

/// `ẍ = −x`: exact solution `(cos t, −sin t)`, to check dopri5's steps and dense output.
struct Oscillator;
impl System for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn deriv(&mut self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = -x[0];
    }
}

#[test]
fn dopri5_matches_an_exact_solution_and_controls_its_error() {
    let mut errs = Vec::new();
    for tol in [1e-6, 1e-9] {
        let opts = Dopri5Options {
            tolerance: tol,
            max_step: 1.0,
            initial_step: 0.01,
            output_interval: 0.05,
        };
        let mut x = vec![1.0, 0.0];
        let mut worst = 0.0_f64;
        let mut count = 0;
        let stats = dopri5(&mut Oscillator, 0.0, 10.0, &opts, &mut x, |t, x| {
            worst = worst
                .max((x[0] - t.cos()).abs())
                .max((x[1] + t.sin()).abs());
            count += 1;
        })
        .unwrap();
        assert_eq!(count, 201, "samples at 0, 0.05, …, 10");
        println!("oscillator, tol {tol:e}: max error {worst:.2e}, {stats:?}");
        assert!(worst < 200.0 * tol, "error {worst:e} at tolerance {tol:e}");
        errs.push((worst, stats.steps));
    }
    // A tighter tolerance takes more steps and is more accurate.
    assert!(errs[1].0 < errs[0].0 / 100.0 && errs[1].1 > errs[0].1);
}

#[test]
fn every_example_scene_parses_and_runs() {
    let mut n = 0;
    for entry in std::fs::read_dir(root().join("scenes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let mut s = Scene::load(&path).unwrap_or_else(|e| panic!("{e:#}"));
        s.simulation.duration = s.simulation.duration.min(1.0);
        let run = simulate(&s, None).unwrap();
        let sm = &run.summary;
        println!(
            "{}: {} steps in {:.3} s",
            path.display(),
            sm.steps,
            sm.wall_s
        );
        assert!(sm.final_state.q.iter().all(|v| v.is_finite()));
        assert!((run.samples.last().unwrap().t - s.simulation.duration).abs() < 1e-9);
        n += 1;
    }
    assert!(n >= 3, "expected at least 3 scenes, found {n}");
}

#[test]
fn computed_torque_tracks_the_quintic_with_the_payload() {
    let s = Scene::load(&root().join("scenes/ssrms_payload_fixed.toml")).unwrap();
    // The payload is merged into the last body.
    let last = s.model.joints().last().unwrap();
    assert!((last.inertial.mass - (243.66 + 116000.0)).abs() < 1e-6);
    let run = simulate(&s, None).unwrap();
    let target = [0.3, 0.4, -0.5, 0.2, 0.1, -0.2, 0.3];
    let err = max_abs_diff(&run.summary.final_state.q, &target);
    assert!(err < 1e-6, "final error {err:e}");
    // On the way, q follows q_d (the model is exact, the initial error zero).
    for sm in &run.samples {
        let (qd, _, _) = kanegen::sim::simulate::quintic_reference(&s.q0, &target, 25.0, sm.t);
        assert!(max_abs_diff(&sm.x[..7], &qd) < 1e-6, "at t = {}", sm.t);
    }
}

#[test]
fn combine_inertials_is_the_parallel_axis_theorem() {
    let point = |m: f64, x: f64| Inertial {
        mass: m,
        com: [x, 0.0, 0.0],
        inertia: [[0.0; 3]; 3],
    };
    // Two point masses 1 kg at x = 0 and 3 kg at x = 4: CoM at 3, Iyy = 1·9 + 3·1 = 12.
    let c = point(1.0, 0.0).merge(&point(3.0, 4.0));
    assert_eq!(c.mass, 4.0);
    assert!((c.com[0] - 3.0).abs() < 1e-12);
    assert!((c.inertia[1][1] - 12.0).abs() < 1e-12 && (c.inertia[2][2] - 12.0).abs() < 1e-12);
    assert!(c.inertia[0][0].abs() < 1e-12);
}

const VALID: &str = r#"
model = "tests/data/reference/srms_nguyen_hughes_1994.urdf"
[simulation]
duration = 1.0
integrator = "dopri5"
tolerance = 1e-8
"#;

#[test]
fn invalid_scenes_name_the_key() {
    scene(VALID);
    let cases = [
        (VALID.replace("duration = 1.0", "duration = 1.0\nfoo = 2"), "foo"),
        (
            VALID.replace("[simulation]", "[base]\ntype = \"fixed\"\nmas = 3.0\n[simulation]"),
            "mas",
        ),
        (
            VALID.replace("\"dopri5\"", "\"euler\""),
            "simulation.integrator",
        ),
        (
            VALID.replace("1e-8", "-1e-8"),
            "simulation.tolerance: must be > 0",
        ),
        (
            VALID.replace("[simulation]", "[initial]\nq = [0.0, 1.0]\n[simulation]"),
            "initial.q: expected 6 values",
        ),
        (
            VALID.replace("[simulation]", "[drives]\ntype = \"pid\"\n[simulation]"),
            "drives.type",
        ),
        (
            VALID.replace(
                "[simulation]",
                "[[effects.wrench]]\nbody = \"B9\"\nframe = \"body\"\n[simulation]",
            ),
            "effects.wrench[0].body",
        ),
        (
            VALID.replace(
                "[simulation]",
                "[[effects.wrench]]\nbody = \"B7\"\nframe = \"body\"\ntime = [0.0, 1.0, 1.0]\nforce = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n[simulation]",
            ),
            "effects.wrench[0].time: sample times must be strictly increasing",
        ),
        (
            VALID.replace(
                "[simulation]",
                "[[effects.wrench]]\nbody = \"B7\"\nframe = \"body\"\ntime = [0.0, 1.0]\nforce = [[1.0, 0.0, 0.0]]\n[simulation]",
            ),
            "effects.wrench[0].force: expected 2 rows",
        ),
        (
            VALID.replace(
                "[simulation]",
                "[[effects.wrench]]\nbody = \"B7\"\nframe = \"body\"\nforce = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]\n[simulation]",
            ),
            "effects.wrench[0].force: one row per sample needs `effects.wrench[0].time`",
        ),
        (
            VALID.replace(
                "[simulation]",
                "[[effects.wrench]]\nbody = \"B7\"\nframe = \"body\"\ntime = [0.0, 1.0]\nmoment = [1.0, 0.0, 0.0]\n[simulation]",
            ),
            "effects.wrench[0].moment: with `effects.wrench[0].time` give one",
        ),
        (
            VALID.replace(
                "[simulation]",
                "[base]\ntype = \"free-floating\"\n[drives]\ntype = \"computed-torque\"\nkp = 1.0\nkd = 1.0\ntarget = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\nduration_s = 1.0\n[simulation]",
            ),
            "computed-torque needs a fixed base",
        ),
    ];
    for (text, key) in cases {
        let e = scene_err(&text);
        assert!(e.contains(key), "error `{e}` does not name `{key}`");
    }
}

#[test]
fn cli_simulate_writes_trajectory_and_summary() {
    let out = std::env::temp_dir().join(format!("kanegen-sim-{}", std::process::id()));
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .args(["simulate", "scenes/srms.toml", "--json", "--out"])
        .arg(&out)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["base"], "fixed");
    assert!(v["steps"].as_u64().unwrap() > 0);
    assert!(v["max_energy_drift_rel"].is_null());
    assert_eq!(v["final"]["q"].as_array().unwrap().len(), 6);
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.starts_with("t,q_"), "{header}");
    assert_eq!(header.split(',').count(), 1 + 12);
    assert!(csv.lines().count() > 10);
    assert!(Path::new(&out.join("summary.json")).exists());
    assert!(Path::new(&out.join("joints.svg")).exists());
    std::fs::remove_dir_all(&out).ok();
}

#[test]
fn dopri5_rejects_a_too_large_first_step_and_recovers() {
    let opts = Dopri5Options {
        tolerance: 1e-10,
        max_step: 2.0,
        initial_step: 2.0,
        output_interval: 0.5,
    };
    let mut x = vec![1.0, 0.0];
    let stats = dopri5(&mut Oscillator, 0.0, 5.0, &opts, &mut x, |_, _| {}).unwrap();
    assert!(stats.rejected_steps > 0, "{stats:?}");
    assert!((x[0] - 5f64.cos()).abs() < 1e-8 && (x[1] + 5f64.sin()).abs() < 1e-8);
}

#[test]
fn payload_is_welded_to_the_named_body() {
    let text = || {
        String::from(
            r#"model = "tests/data/reference/srms_nguyen_hughes_1994.urdf"
[payload]
mass = 500.0
com = [0.2, 0.0, 0.0]
inertia = { ixx = 10.0, iyy = 12.0, izz = 14.0 }
[initial]
q = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
qd = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
[simulation]
duration = 0.1
integrator = "rk4"
step = 0.01
"#,
        )
    };
    let plain = kanegen::model::io::load_model(
        &root().join("tests/data/reference/srms_nguyen_hughes_1994.urdf"),
    )
    .unwrap();
    let third = plain.joints()[2].body.clone();
    let named = Scene::parse(
        &text().replace("[payload]", &format!("[payload]\nbody = \"{third}\"")),
        &root(),
    )
    .unwrap_or_else(|e| panic!("{e:#}"));
    let default = Scene::parse(&text(), &root()).unwrap();
    let m = |s: &Scene, j: usize| s.model.joints()[j].inertial.mass;
    assert_eq!(m(&named, 2), plain.joints()[2].inertial.mass + 500.0);
    assert_eq!(m(&named, 5), plain.joints()[5].inertial.mass);
    assert_eq!(m(&default, 5), plain.joints()[5].inertial.mass + 500.0);
    let bad = text().replace("[payload]", "[payload]\nbody = \"nope\"");
    let e = format!("{:#}", Scene::parse(&bad, &root()).unwrap_err());
    assert!(e.contains("payload.body") && e.contains("nope"), "{e}");
}
