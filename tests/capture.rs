//! Payload capture and release on a free-floating base (`[[events]]`), and rotor inertia (the
//! armature model) on a free-floating base, interpreted (`kanegen_sim::events`,
//! `SceneSystem`) and compiled (`kanegen::scene!`).
//!
//! Scenes: `scenes/capture_free_floating.toml` (the 7-dof arm catches an 80 kg tumbling payload
//! at t = 2 s and releases it at t = 6 s, dopri5 at 1e-10), `tests/data/scenes/capture_rotor_rk4.toml`
//! (capture on link_5 between two RK4 steps and release, with rotor inertia),
//! `tests/data/scenes/floating_rotor.toml` (rotor inertia on the drifting, unactuated arm).
//!
//! Measured (release build) and bounds:
//!
//! | check | measured | bound |
//! |---|---|---|
//! | momentum of system + payload through each event (rel., summary `events`) | ≤ 2.7e-15 (capture), ≤ 1.5e-16 (release) | 1e-12 |
//! | the same from the samples at `t_e⁻`, `t_e⁺` and an independent `h_p` | ≤ 2.7e-15 | 1e-12 |
//! | total momentum over the capture scene's run (rel., summary drift, dopri5 at 1e-11) | 1.1e-11 lin, 6.0e-11 ang | 1e-9 (17× margin) |
//! | capture of a payload moving with the body: `max |ν⁺ − ν⁻|`; energy gained − payload KE | 6.4e-16; < 1e-12 rel. | 1e-12 |
//! | floating rotor: `(H + diag(0, I_m n²)) ν̇ = b` with spatial `H`, `b` | ≤ 1e-10 of `max \|b\|` | 1e-10 |
//! | floating rotor: drift of energy (bodies + rotors), body momentum | 2.7e-10, 1.7e-10 lin, 3.3e-10 ang | 1e-8 |
//! | floating rotor vs none: final `q` | differs by 0.46 | > 1e-2 |
//!
//! The checks fail on a wrong impulse: dropping `J_pᵀ h_p` moves the momentum by the payload's
//! (≈ 10 % of the total here), leaving out the armature in `H` or `H'` moves `ν⁺` of the
//! comoving capture with rotors.

use kanegen::dynamics::algorithms::{floating, frames};
use kanegen::dynamics::linalg::{Mat3, Vec3};
use kanegen::dynamics::{FrameParams, Methods, Params};
use kanegen::sim::scene::{Event, EventKind, Scene};
use kanegen::sim::simulate::{simulate, Run, SceneSystem};

mod common;
use common::{load, max_abs_diff, root};

fn run(scene: &Scene) -> Run {
    simulate(scene, None).unwrap()
}

fn rel3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    d / b.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-300)
}

/// The payload's momentum `(m v, x_c × m v + R I Rᵀ ω)` at the capture state, from the
/// placement of its centre of mass (independent of the impulse code's Jacobian).
fn payload_momentum(sys: &SceneSystem<'_>, e: &Event, x: &[f64]) -> ([f64; 3], [f64; 3]) {
    let EventKind::Capture { payload, v, omega } = &e.kind else {
        panic!("a capture")
    };
    let (q, _, st) = sys.split(x);
    let frame = FrameParams {
        parent: Some(e.body),
        translation: Vec3::from_f64(payload.com),
        rotation: Mat3::identity(),
    };
    let (xc, r) = frames::floating_placement(sys.params(), &st.unwrap(), q, &frame);
    let lin = Vec3::from_f64(*v).scale(&payload.mass);
    let i_in = r
        .mul_mat(&Mat3::from_f64(payload.inertia))
        .mul_mat(&r.transpose());
    let ang = xc.cross(&lin) + i_in.mul_vec(&Vec3::from_f64(*omega));
    (lin.into_array(), ang.into_array())
}

#[test]
fn capture_conserves_momentum_through_the_events() {
    for file in [
        "scenes/capture_free_floating.toml",
        "tests/data/scenes/capture_rotor_rk4.toml",
    ] {
        let scene = load(file);
        let r = run(&scene);
        assert_eq!(r.summary.events.len(), 2, "{file}");
        for ev in &r.summary.events {
            eprintln!(
                "{file}: {} at {}: momentum error {:.1e} lin {:.1e} ang, energy change {:.3e} J",
                ev.kind,
                ev.t,
                ev.linear_momentum_error_rel,
                ev.angular_momentum_error_rel,
                ev.energy_change
            );
            assert!(ev.linear_momentum_error_rel <= 1e-12, "{file}: {ev:?}");
            assert!(ev.angular_momentum_error_rel <= 1e-12, "{file}: {ev:?}");
        }
        // A plastic capture loses kinetic energy; a release takes the payload's away.
        assert!(r.summary.events[0].energy_change < 0.0);
        assert!(r.summary.events[1].energy_change < 0.0);
        // From the samples: the system's momentum just after the capture is the system's just
        // before plus the payload's, computed here from its placement; a release keeps ν.
        let mut sys = SceneSystem::new(&scene);
        let e = &scene.events[0];
        let at: Vec<_> = r.samples.iter().filter(|s| s.t == e.time).collect();
        assert_eq!(at.len(), 2, "{file}: samples at t_e⁻ and t_e⁺");
        let before = sys.momentum(&at[0].x).unwrap();
        let pay = payload_momentum(&sys, e, &at[0].x);
        sys.set_params(Params::new(&e.model));
        let after = sys.momentum(&at[1].x).unwrap();
        let expect = (
            [0, 1, 2].map(|i| before.0[i] + pay.0[i]),
            [0, 1, 2].map(|i| before.1[i] + pay.1[i]),
        );
        let (el, ea) = (rel3(&after.0, &expect.0), rel3(&after.1, &expect.1));
        eprintln!("{file}: samples around the capture: {el:.1e} lin, {ea:.1e} ang");
        assert!(el <= 1e-12 && ea <= 1e-12);
        // The payload matters: ≥ 1 % of the momentum.
        assert!(rel3(&before.0, &expect.0) > 1e-2 || rel3(&before.1, &expect.1) > 1e-2);
        let rel_at: Vec<_> = r
            .samples
            .iter()
            .filter(|s| s.t == scene.events[1].time)
            .collect();
        assert_eq!(rel_at.len(), 2);
        assert_eq!(rel_at[0].x, rel_at[1].x, "a release keeps the state");
    }
    let r = run(&load("scenes/capture_free_floating.toml"));
    let (l, a) = (
        r.summary.max_linear_momentum_drift_rel.unwrap(),
        r.summary.max_angular_momentum_drift_rel.unwrap(),
    );
    eprintln!("capture scene, whole run: momentum drift {l:.2e} lin, {a:.2e} ang");
    assert!(l <= 1e-9 && a <= 1e-9);
}

/// A payload already moving with the capturing body is caught without an impulse: `ν⁺ = ν⁻`
/// in all `6 + N` rows (the joint rows of `J_pᵀ h_p` and of the armature included), and the
/// system gains exactly the payload's kinetic energy.
#[test]
fn capturing_a_comoving_payload_changes_no_velocity() {
    let scene = load("tests/data/scenes/capture_rotor_rk4.toml");
    let mut sys = SceneSystem::new(&scene);
    let mut x = sys.initial_state();
    let n = scene.model.dof();
    for (i, v) in x[7 + n..].iter_mut().enumerate() {
        *v += 0.1 * (i as f64 + 1.0).sin();
    }
    let e = &scene.events[0];
    let EventKind::Capture { payload, .. } = &e.kind else {
        panic!()
    };
    let (q, _, st) = sys.split(&x);
    let st = st.unwrap();
    let frame = FrameParams {
        parent: Some(e.body),
        translation: Vec3::from_f64(payload.com),
        rotation: Mat3::identity(),
    };
    let j = frames::floating_jacobian(sys.params(), &st, q, &frame);
    let twist: Vec<f64> = j
        .iter()
        .map(|row| row.iter().zip(&x[7 + n..]).map(|(a, b)| a * b).sum())
        .collect();
    let comoving = Event {
        kind: EventKind::Capture {
            payload: payload.clone(),
            v: [twist[0], twist[1], twist[2]],
            omega: [twist[3], twist[4], twist[5]],
        },
        ..e.clone()
    };
    let before = x.clone();
    let t0 = sys.kinetic_energy(&x);
    let report = sys.apply_event(&comoving, &mut x);
    let dv = before
        .iter()
        .zip(&x)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    // The payload's kinetic energy ½ (m |v|² + ω·R I Rᵀ ω).
    let (_, r) = frames::floating_placement(sys.params(), &st, &before[7..7 + n], &frame);
    let w = Vec3::new(twist[3], twist[4], twist[5]);
    let i_in = r
        .mul_mat(&Mat3::from_f64(payload.inertia))
        .mul_mat(&r.transpose());
    let ke = 0.5
        * (payload.mass * (0..3).map(|i| twist[i] * twist[i]).sum::<f64>()
            + w.dot(&i_in.mul_vec(&w)));
    eprintln!(
        "comoving capture: |Δν| = {dv:.1e}, energy change {:.6e} vs payload KE {ke:.6e} (T = {t0:.3e})",
        report.energy_change
    );
    assert!(dv <= 1e-12, "{dv:e}");
    assert!((report.energy_change - ke).abs() <= 1e-12 * (t0 + ke));
}

/// Rotor inertia on a free-floating base: `(H + diag(0, I_m n²)) ν̇ = b` with `H`, `b` of the
/// spatial algorithms (the scene runs the recurrent ones); the run conserves kinetic energy of
/// bodies and rotors and the bodies' momentum (the armature model's Noether momenta), and the
/// rotors change the motion.
#[test]
fn floating_rotor_is_the_armature_model() {
    let scene = load("tests/data/scenes/floating_rotor.toml");
    let mut sys = SceneSystem::new(&scene);
    let n = scene.model.dof();
    let x = sys.initial_state();
    let mut dx = vec![0.0; x.len()];
    kanegen::sim::integrate::System::deriv(&mut sys, 0.0, &x, &mut dx);
    let (q, qd, st) = sys.split(&x);
    let st = st.unwrap();
    let p = Params::new(&scene.model);
    let d = floating::dynamics(
        Methods::SPATIAL,
        &p,
        sys.floating_base().unwrap(),
        &st,
        q,
        qd,
        &kanegen::dynamics::Loads::default(),
    );
    let r = scene.rotor.as_ref().unwrap();
    let nu_dot = &dx[7 + n..];
    let scale = d.tau_minus_c.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for i in 0..6 + n {
        let mut lhs: f64 = (0..6 + n).map(|j| d.mass_matrix[i][j] * nu_dot[j]).sum();
        if i >= 6 {
            lhs += r.reflected[i - 6] * nu_dot[i];
        }
        assert!(
            (lhs - d.tau_minus_c[i]).abs() <= 1e-10 * scale,
            "row {i}: {lhs} vs {}",
            d.tau_minus_c[i]
        );
    }
    let run_r = run(&scene);
    let s = &run_r.summary;
    let (e, l, a) = (
        s.max_energy_drift_rel.unwrap(),
        s.max_linear_momentum_drift_rel.unwrap(),
        s.max_angular_momentum_drift_rel.unwrap(),
    );
    eprintln!("floating rotor: drift energy {e:.2e}, momentum {l:.2e} lin {a:.2e} ang");
    assert!(e <= 1e-8 && l <= 1e-8 && a <= 1e-8);
    let free = Scene {
        rotor: None,
        ..scene.clone()
    };
    let run_f = run(&free);
    let (a, b) = (&run_r.summary.final_state.q, &run_f.summary.final_state.q);
    let diff = max_abs_diff(a, b);
    eprintln!("rotor vs none: final q differs by {diff:.2e}");
    assert!(diff > 1e-2);
}

fn parse_err(extra: &str) -> String {
    let text = format!(
        "model = \"../tests/data/reference/bmsd_7dof_free_floating.urdf\"\n\
         allow_nonphysical = true\n\
         [base]\ntype = \"free-floating\"\n\
         [simulation]\nduration = 1.0\n{extra}"
    );
    format!(
        "{:#}",
        Scene::parse(&text, &root().join("scenes")).unwrap_err()
    )
}

#[test]
fn bad_events_are_errors_naming_the_key() {
    let capture = |fields: &str| {
        format!("[[events]]\ntype = \"capture\"\ninertia = {{ ixx = 1.0, iyy = 1.0, izz = 1.0 }}\n{fields}")
    };
    for (extra, want) in [
        (capture("time = 2.0\nmass = 1.0"), "events[0].time"),
        (capture("time = 0.0\nmass = 1.0"), "events[0].time"),
        (capture("time = 0.5\nmass = 0.0"), "events[0].mass"),
        (capture("time = 0.5"), "events[0].mass"),
        (
            capture("time = 0.5\nmass = 1.0\nbody = \"nope\""),
            "events[0].body (line 7): unknown body `nope`",
        ),
        (
            // The scene allows non-physical inertias (the bMSd arm needs it), so the payload's
            // must fail a check the override keeps: the magnitude bound.
            "[[events]]\ntype = \"capture\"\ntime = 0.5\nmass = 1.0\ninertia = { ixx = 1e30, iyy = 1.0, izz = 1.0 }".into(),
            "events[0].inertia",
        ),
        (
            "[[events]]\ntype = \"release\"\ntime = 0.5".into(),
            "events[0].body (line 7): no payload held",
        ),
        (
            "[[events]]\ntype = \"release\"\ntime = 0.5\nmass = 2.0".into(),
            "events[0].mass",
        ),
        (
            "[[events]]\ntype = \"grab\"\ntime = 0.5".into(),
            "events[0].type",
        ),
        (
            format!("{}\n{}", capture("time = 0.5\nmass = 1.0"), capture("time = 0.4\nmass = 1.0")),
            "events[1].time",
        ),
    ] {
        let e = parse_err(&extra);
        assert!(e.contains(want), "{extra}\n→ {e}");
    }
    // A fixed base rejects events.
    let text = "model = \"../models/two_link.toml\"\n[simulation]\nduration = 1.0\n\
                [[events]]\ntype = \"release\"\ntime = 0.5\n";
    let e = format!(
        "{:#}",
        Scene::parse(text, &root().join("scenes")).unwrap_err()
    );
    assert!(
        e.contains("events[0]") && e.contains("free-floating"),
        "{e}"
    );
}

fn count_json(scene: &str) -> serde_json::Value {
    let out = common::kanegen(&["count", "--json", "--algorithm", "recurrent", scene]);
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `count SCENE` lists a capture's one-time cost: two `A` evaluations (the table's line) plus
/// the impulse algebra on `n_v = 13` speeds, counted here by hand: `H ν` 169 mul 156 add,
/// `h_p` 30 mul 18 add, `J_pᵀ h_p` 78 and 78, LDLᵀ factor `C(14, 3) = 364` mul and add and 78
/// div, solve 156 mul and add and 13 div — 797 mul, 772 add, 91 div (+14 add of armature with
/// rotors); a release costs nothing; a scene without events has no `events` lines.
#[test]
fn count_lists_the_capture_cost() {
    for (scene, armature) in [
        ("scenes/capture_free_floating.toml", 0),
        ("tests/data/scenes/capture_rotor_rk4.toml", 14),
    ] {
        let r = count_json(scene);
        let a = r["counts"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["function"] == "mass_matrix" && c["convention"] == "emitted")
            .unwrap()
            .clone();
        let ev = r["events"].as_array().unwrap();
        let cap = ev
            .iter()
            .find(|e| e["effect"] == "capture" && e["convention"] == "emitted")
            .unwrap();
        let int = |v: &serde_json::Value| v.as_i64().unwrap();
        assert_eq!(int(&cap["mul"]), 2 * int(&a["mul"]) + 797, "{scene}");
        assert_eq!(
            int(&cap["add"]),
            2 * int(&a["add"]) + 772 + armature,
            "{scene}"
        );
        assert_eq!(int(&cap["div"]), 91, "{scene}");
        let rel = ev.iter().find(|e| e["effect"] == "release").unwrap();
        assert_eq!((int(&rel["mul"]), int(&rel["add"])), (0, 0));
    }
    let r = count_json("scenes/free_floating_7dof.toml");
    assert!(r.get("events").is_none());
    let r = count_json("tests/data/scenes/floating_rotor.toml");
    assert!(r["effects"]
        .as_array()
        .unwrap()
        .iter()
        .any(|e| e["effect"] == "rotor"));
}

/// A base quaternion with entries near f64's range normalizes (its squares would overflow) and
/// one of zeros is an error naming the key.
#[test]
fn base_quaternion_normalizes_at_any_scale() {
    let scene = |quat: &str| {
        let text = format!(
            "model = \"../tests/data/reference/bmsd_7dof_free_floating.urdf\"\n\
             allow_nonphysical = true\n\
             [base]\ntype = \"free-floating\"\nquaternion = {quat}\n\
             [simulation]\nduration = 1.0\n"
        );
        Scene::parse(&text, &root().join("scenes"))
    };
    for (quat, want) in [
        (
            "[1e200, 1e200, 0.0, 0.0]",
            [0.5f64.sqrt(), 0.5f64.sqrt(), 0.0, 0.0],
        ),
        ("[0.0, 0.0, -3e150, 4e150]", [0.0, 0.0, -0.6, 0.8]),
        ("[0.0, 0.0, 0.0, 2.0]", [0.0, 0.0, 0.0, 1.0]),
    ] {
        let s = scene(quat).unwrap();
        let kanegen::sim::scene::BaseSpec::FreeFloating { quaternion, .. } = s.base else {
            panic!("{quat}: the base is free-floating");
        };
        assert!(
            max_abs_diff(&quaternion, &want) < 1e-15,
            "{quat}: {quaternion:?}"
        );
    }
    let e = format!("{:#}", scene("[0.0, 0.0, 0.0, 0.0]").unwrap_err());
    assert!(e.contains("base.quaternion"), "{e}");
}
