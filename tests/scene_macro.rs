//! `kanegen::scene!` against the interpreted simulator (`kanegen::sim`). Both integrate the one
//! right-hand side of `kanegen::runtime::scene` (`deriv`: drives, damping, Coulomb friction,
//! wrench profiles, armature, flexible joints, the free-floating kinematics) over the same
//! `SceneEffects`; what differs, and what these tests check, is its provider: the generated
//! dynamics of the scene's model (forward dynamics with the wrenches as `f_ext` rows, the
//! generated frame placements rotating inertial-frame wrenches, the generated mass matrix
//! under the armature's LDLᵀ, the generated frame Jacobians compensating a computed-torque
//! drive, one dynamics type a model phase and the capture impulse) against the run-time
//! algorithms over the model's numbers (the articulated-body algorithm with the armature in it).
//!
//! Scenes: every example scene of `scenes/` with rigid joints (`ssrms_flexible.toml`, with
//! flexible joints and the stiff integrator, is compared in `tests/flexible.rs`) and seven test
//! scenes with what the examples lack (`tests/data/scenes/`: `gravity_wrench.toml`, fixed base,
//! constant and tabulated body-frame wrenches on one body, constant drives;
//! `floating_wrenches.toml`, free-floating under gravity, wrenches on the base in both frames
//! and on two links, constant drives, damping; `floating_midpoint.toml`, a tumbling
//! free-floating base under PD drives, implicit midpoint; `computed_torque_wrench.toml`,
//! constant wrenches in both frames compensated by a computed-torque drive;
//! `computed_torque_tabulated.toml`, tabulated wrenches compensated at each time by a
//! computed-torque drive; `rotor_wrench.toml`, rotor inertia and Coulomb friction with gravity,
//! an inertial-frame and a tabulated wrench, dopri5; `floating_friction.toml`, drive friction
//! on the tumbling free-floating arm), and the capture and rotor scenes
//! (`scenes/capture_free_floating.toml`: a payload captured and released on the free-floating
//! 7-dof arm, dopri5; `tests/data/scenes/capture_rotor_rk4.toml`: capture and release with
//! rotor inertia, RK4; `tests/data/scenes/floating_rotor.toml`: rotor inertia on a
//! free-floating base):
//!
//! - the compiled run samples at the same times as the interpreted one, and every state
//!   component agrees to `|x_c − x_i| ≤ 1e-9 (1 + |x_i|)` at every sample — the same integrator
//!   and step (RK4, midpoint) or tolerance (dopri5) on right-hand sides equal to rounding;
//!   measured (release build, `-C target-cpu=native`) worst 3.9e-14 (`gravity_wrench`), 3.4e-14
//!   (rotor with wrenches), Dextre 9.1e-15, `free_floating_7dof` 3.7e-15 (dopri5 at tolerance
//!   1e-10), floating rotor 2.8e-15, capture 1.5e-15, capture with rotors 7.0e-16, the other
//!   scenes ≤ 8.2e-16 (`ssrms_drives`, rotor inertia and friction, 1.9e-16);
//! - on the free-floating 7-dof scene, the compiled run conserves linear and angular momentum
//!   (`NameDynamics::momentum`) as the interpreted one does (its summary's drift): measured
//!   drifts 5.6e-11 (linear) and 3.49e-10 (angular) relative, interpreted the same;
//! - the compiled capture impulse is the interpreted one (1e-12) and conserves the generated
//!   `momentum` of the phases before and after (measured 4.5e-16 linear, 2.9e-15 angular,
//!   bound 1e-12);
//! - the compiled right-hand side and one RK4 step ([`SsrmsEffects::step`]) off the equilibrium
//!   are the interpreted ones; ten midpoint steps ([`FloatingMidpoint::step`]) are the run's
//!   state at its first output sample;
//! - scene types named `f64` and `Option`, and scenes in a module that names structs like every
//!   primitive type and prelude item (`common::shadowing_items!`), compile and simulate what
//!   their plainly named twins do, bit for bit.
//!
//! The checks see a wrong provider: the SSRMS wrist wrench rotated by `R` instead of `Rᵀ` moves
//! the SSRMS effects scene by 3.1e-2 (relative) and fails the first and last; the base's
//! inertial-frame wrench left unrotated moves `floating_wrenches` by 2.4e-2; the wrench
//! compensation of the computed-torque drive with the wrong sign moves its scene by 9.6e-2.
//! The effects' arithmetic is shared by both runs, so a wrong effect there (Coulomb friction
//! added instead of subtracted, half the rotor inertia) moves both alike and is not seen here:
//! `tests/drive_effects.rs` (the energy with rotor inertia and friction) and
//! `tests/flexible.rs` check it against independent oracles.

use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate, Run};
use std::path::Path;

mod common;

kanegen::scene!(SsrmsEffects, "scenes/ssrms_effects.toml");
kanegen::scene!(SsrmsPayload, "scenes/ssrms_payload_fixed.toml");
kanegen::scene!(Srms, "scenes/srms.toml");
kanegen::scene!(Ur5TorqueInput, "scenes/ur5_torque_input.toml");
kanegen::scene!(FreeFloating7, "scenes/free_floating_7dof.toml");
kanegen::scene!(Dextre, "scenes/dextre_free_floating.toml");
kanegen::scene!(GravityWrench, "tests/data/scenes/gravity_wrench.toml");
kanegen::scene!(FrameClash, "tests/data/scenes/frame_name_clash.toml");
kanegen::scene!(FloatingWrenches, "tests/data/scenes/floating_wrenches.toml");
kanegen::scene!(FloatingMidpoint, "tests/data/scenes/floating_midpoint.toml");
kanegen::scene!(CtWrench, "tests/data/scenes/computed_torque_wrench.toml");
kanegen::scene!(
    CtTabulated,
    "tests/data/scenes/computed_torque_tabulated.toml"
);
kanegen::scene!(SsrmsDrives, "scenes/ssrms_drives.toml");
kanegen::scene!(RotorWrench, "tests/data/scenes/rotor_wrench.toml");
kanegen::scene!(FloatingFriction, "tests/data/scenes/floating_friction.toml");
kanegen::scene!(Capture, "scenes/capture_free_floating.toml");
kanegen::scene!(CaptureRotor, "tests/data/scenes/capture_rotor_rk4.toml");
kanegen::scene!(FloatingRotor, "tests/data/scenes/floating_rotor.toml");

fn interpreted(file: &str) -> (Scene, Run) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let scene = Scene::load(&path).unwrap();
    let run = simulate(&scene, None).unwrap();
    (scene, run)
}

/// The compiled samples `(t, [q, v])` of a run.
fn compiled<const D: usize>(
    run: impl FnOnce(&mut dyn FnMut(f64, [f64; D])) -> kanegen::ode::Stats,
) -> Vec<(f64, [f64; D])> {
    let mut out = Vec::new();
    let stats = run(&mut |t, x| out.push((t, x)));
    assert!(stats.steps > 0);
    out
}

/// Worst `|x_c − x_i| / (1 + |x_i|)` over the samples ([`common::worst`]), printed.
fn worst<const D: usize>(name: &str, c: &[(f64, [f64; D])], i: &Run) -> f64 {
    let w = common::worst(name, c, i);
    eprintln!(
        "{name}: {} samples, worst relative difference {w:.2e}",
        c.len()
    );
    w
}

macro_rules! agree {
    ($test:ident, $ty:ident, $file:literal) => {
        #[test]
        fn $test() {
            let (_, run) = interpreted($file);
            let c = compiled(|obs| $ty::run(|t, s| obs(t, s.to_array())).unwrap());
            let w = worst(stringify!($ty), &c, &run);
            assert!(w <= 1e-9, "{}: worst {w:e}", $file);
        }
    };
}

agree!(
    ssrms_effects_agrees,
    SsrmsEffects,
    "scenes/ssrms_effects.toml"
);
agree!(
    ssrms_payload_agrees,
    SsrmsPayload,
    "scenes/ssrms_payload_fixed.toml"
);
agree!(srms_agrees, Srms, "scenes/srms.toml");
agree!(
    ur5_torque_input_agrees,
    Ur5TorqueInput,
    "scenes/ur5_torque_input.toml"
);
agree!(
    free_floating_7dof_agrees,
    FreeFloating7,
    "scenes/free_floating_7dof.toml"
);
agree!(dextre_agrees, Dextre, "scenes/dextre_free_floating.toml");
agree!(
    gravity_wrench_agrees,
    GravityWrench,
    "tests/data/scenes/gravity_wrench.toml"
);
agree!(
    frame_name_clash_agrees,
    FrameClash,
    "tests/data/scenes/frame_name_clash.toml"
);
agree!(
    floating_wrenches_agrees,
    FloatingWrenches,
    "tests/data/scenes/floating_wrenches.toml"
);
agree!(
    floating_midpoint_agrees,
    FloatingMidpoint,
    "tests/data/scenes/floating_midpoint.toml"
);
agree!(ssrms_drives_agrees, SsrmsDrives, "scenes/ssrms_drives.toml");
agree!(
    rotor_wrench_agrees,
    RotorWrench,
    "tests/data/scenes/rotor_wrench.toml"
);
agree!(
    floating_friction_agrees,
    FloatingFriction,
    "tests/data/scenes/floating_friction.toml"
);
agree!(
    computed_torque_wrench_agrees,
    CtWrench,
    "tests/data/scenes/computed_torque_wrench.toml"
);

agree!(
    computed_torque_tabulated_agrees,
    CtTabulated,
    "tests/data/scenes/computed_torque_tabulated.toml"
);

/// A computed-torque drive with an exact model compensates the tabulated wrenches at each time:
/// from a start on its reference, the arm follows the quintic to the integrator's error, compiled
/// and interpreted. Measured worst `|q − q_d(t)|` 6.9e-10 rad (both; bound 1e-8). With the
/// wrenches compensated at their `t = 0` values (zero), as the interpreted controller did before,
/// the same scene leaves the quintic by 0.77 rad.
#[test]
fn computed_torque_tracks_through_tabulated_wrenches() {
    let file = "tests/data/scenes/computed_torque_tabulated.toml";
    let (scene, run) = interpreted(file);
    let kanegen::sim::scene::Drives::ComputedTorque {
        target, duration, ..
    } = &scene.drives
    else {
        panic!("{file}: a computed-torque drive")
    };
    let n = scene.model.dof();
    let off = |t: f64, q: &[f64]| {
        let (qd, _, _) = kanegen::sim::simulate::quintic_reference(&scene.q0, target, *duration, t);
        q.iter()
            .zip(&qd)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
    };
    let wi = run
        .samples
        .iter()
        .fold(0.0_f64, |m, s| m.max(off(s.t, &s.x[..n])));
    let mut wc = 0.0_f64;
    CtTabulated::run(|t, s| wc = wc.max(off(t, &s.q))).unwrap();
    eprintln!("off the quintic: interpreted {wi:.2e}, compiled {wc:.2e}");
    assert!(
        wi <= 1e-8 && wc <= 1e-8,
        "interpreted {wi:e}, compiled {wc:e}"
    );
}

agree!(capture_agrees, Capture, "scenes/capture_free_floating.toml");
agree!(
    capture_rotor_agrees,
    CaptureRotor,
    "tests/data/scenes/capture_rotor_rk4.toml"
);
agree!(
    floating_rotor_agrees,
    FloatingRotor,
    "tests/data/scenes/floating_rotor.toml"
);

/// The compiled capture conserves the total momentum through the capture: the generated
/// `momentum` of the phase after equals that of the phase before plus the payload's (from the
/// interpreted event's report).
#[test]
fn compiled_capture_conserves_momentum() {
    use kanegen::sim::simulate::SceneSystem;
    let mut st = Capture::initial_state();
    let (mut t, h) = (0.0, 0.01);
    while t + h <= Capture::EVENT_TIMES[0] + 1e-12 {
        Capture::step(t, &mut st, h).unwrap();
        t += h;
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/capture_free_floating.toml");
    let scene = Scene::load(&path).unwrap();
    let mut x = st.to_array().to_vec();
    let report = SceneSystem::new(&scene).apply_event(&scene.events[0], &mut x);
    let before = CaptureDynamics::momentum(&st.q, &st.v);
    Capture::apply_event(0, &mut st);
    let after = CaptureDynamicsPhase1::momentum(&st.q, &st.v);
    let (pl, pa) = (
        report.payload_linear_momentum,
        report.payload_angular_momentum,
    );
    let err = |k: usize, p: [f64; 3]| {
        let want: Vec<f64> = (0..3).map(|i| before[k + i] + p[i]).collect();
        let d = (0..3)
            .map(|i| (after[k + i] - want[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        d / want.iter().map(|w| w * w).sum::<f64>().sqrt()
    };
    let (el, ea) = (err(0, pl), err(3, pa));
    eprintln!("compiled capture: momentum error {el:.1e} lin, {ea:.1e} ang");
    assert!(el <= 1e-12 && ea <= 1e-12);
    // The compiled jump is the interpreted one.
    for (a, b) in st.to_array().iter().zip(&x) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

/// The compiled free-floating run conserves momentum as the interpreted one does.
#[test]
fn free_floating_momentum_is_conserved() {
    let (_, run) = interpreted("scenes/free_floating_7dof.toml");
    let s = &run.summary;
    let (il, ia) = (
        s.max_linear_momentum_drift_rel.unwrap(),
        s.max_angular_momentum_drift_rel.unwrap(),
    );
    let x0 = FreeFloating7::initial_state();
    let p0 = FreeFloating7Dynamics::momentum(&x0.q, &x0.v);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (l0, a0) = (norm(&p0[..3]), norm(&p0[3..]));
    assert!(l0 > 0.0 && a0 > 0.0);
    let (mut dl, mut da) = (0.0_f64, 0.0_f64);
    FreeFloating7::run(|_, st| {
        let p = FreeFloating7Dynamics::momentum(&st.q, &st.v);
        let d: Vec<f64> = (0..6).map(|i| p[i] - p0[i]).collect();
        dl = dl.max(norm(&d[..3]) / l0);
        da = da.max(norm(&d[3..]) / a0);
    })
    .unwrap();
    eprintln!("momentum drift: compiled {dl:.2e} {da:.2e}, interpreted {il:.2e} {ia:.2e}");
    assert!(dl <= 1e-9 && da <= 1e-9, "compiled drift {dl:e} {da:e}");
    assert!((dl - il).abs() <= 0.05 * il + 1e-13 && (da - ia).abs() <= 0.05 * ia + 1e-13);
}

/// One compiled RK4 step is the interpreted integrator's first step (SSRMS effects scene, the
/// wrench ramping up at `t = 0.5`).
#[test]
fn one_step_matches_interpreted_rk4() {
    use kanegen::sim::integrate::{rk4, System};
    use kanegen::sim::simulate::SceneSystem;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ssrms_effects.toml");
    let scene = Scene::load(&path).unwrap();
    let mut sys = SceneSystem::new(&scene);
    let (t, h) = (0.5, 0.01);
    // A state off the equilibrium, so every effect matters.
    let mut x = sys.initial_state();
    for (i, v) in x.iter_mut().enumerate() {
        *v += 0.05 * (i as f64 + 1.0).sin();
    }
    let mut st = SsrmsEffectsState::from_array(&x.clone().try_into().unwrap());
    let d = SsrmsEffects::rhs(t, &st).to_array();
    let mut di = vec![0.0; sys.dim()];
    sys.deriv(t, &x, &mut di);
    for (a, b) in d.iter().zip(&di) {
        assert!((a - b).abs() <= 1e-10 * (1.0 + b.abs()), "rhs {a} vs {b}");
    }
    SsrmsEffects::step(t, &mut st, h).unwrap();
    rk4(&mut sys, t, t + h, h, &mut x, |_, _, _| ()).unwrap();
    for (a, b) in st.to_array().iter().zip(&x) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "step {a} vs {b}");
    }
}

/// `step` of a midpoint scene is the run's step: ten of them reach the first output sample.
#[test]
fn midpoint_steps_are_the_run() {
    let mut st = FloatingMidpoint::initial_state();
    for k in 0..10 {
        FloatingMidpoint::step(f64::from(k) * 0.01, &mut st, 0.01).unwrap();
    }
    let mut first = None;
    FloatingMidpoint::run(|t, s| {
        if first.is_none() && t > 0.0 {
            first = Some(*s);
        }
    })
    .unwrap();
    assert_eq!(first.unwrap(), st);
    let norm: f64 = st.q[3..7].iter().map(|x| x * x).sum();
    assert!((norm - 1.0).abs() < 1e-14, "|quat|² − 1 = {}", norm - 1.0);
}

// ---------------------------------------------------------------------------------------------
// Scene types named like primitive types and prelude items: the expansion names those by full
// paths, so each simulates what its normally named twin above does.

// The flexible-joint scene (Rosenbrock) beside its twin `crowded::shadowed::Flexible`.
kanegen::scene!(Flexible, "tests/data/scenes/flex_k1e3.toml");

/// A scene type called `f64` (dopri5, step Jacobians): inside `impl f64` every `f64` of the
/// expansion would be the scene type if it were not named by its full path.
#[allow(non_camel_case_types, dead_code)]
mod named_f64 {
    kanegen::scene!(f64, "scenes/srms.toml");
}

/// A scene type called `Option` (events: a capture and a release, free-floating, dopri5).
#[allow(dead_code)]
mod named_option {
    kanegen::scene!(Option, "scenes/capture_free_floating.toml");
}

/// Scenes in a module that gives every primitive type, prelude item and built-in macro the
/// expansion could name, and `core`, a meaning of its own: computed torque with its inverse
/// dynamics and step Jacobians, wrenches compensated through the generated frames, capture
/// with rotor inertia (RK4), flexible joints.
#[allow(non_camel_case_types, dead_code, clippy::upper_case_acronyms)]
mod crowded {
    pub mod shadowed {
        crate::common::shadowing_items!();

        kanegen::scene!(SsrmsPayload, "scenes/ssrms_payload_fixed.toml");
        kanegen::scene!(CtWrench, "tests/data/scenes/computed_torque_wrench.toml");
        kanegen::scene!(CaptureRotor, "tests/data/scenes/capture_rotor_rk4.toml");
        kanegen::scene!(Flexible, "tests/data/scenes/flex_k1e3.toml");
    }
}

/// Asserts that the scene type `shadowed` simulates what `plain` does, bit for bit: the samples
/// and counts of `run`, `rhs` and one `step` off the initial state, and the step Jacobians when
/// the scene has them (`jacobians` after `;`).
macro_rules! same_trajectory {
    ($shadowed:path, $plain:ident $(; $jacobians:ident)?) => {{
        type Shadowed = $shadowed;
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let stats_a = Shadowed::run(|t, s| a.push((t, s.to_array()))).unwrap();
        let stats_b = $plain::run(|t, s| b.push((t, s.to_array()))).unwrap();
        assert!(b.len() > 1, "{}", $plain::SCENE);
        assert_eq!((stats_a, a), (stats_b, b), "{}", $plain::SCENE);
        let (mut sa, mut sb) = (Shadowed::initial_state(), $plain::initial_state());
        assert_eq!(sa.to_array(), sb.to_array());
        // Off the initial state, so that every effect matters.
        for (i, (qa, qb)) in sa.q.iter_mut().zip(&mut sb.q).enumerate() {
            *qa += 1e-3 * (i as f64).sin();
            *qb += 1e-3 * (i as f64).sin();
        }
        assert_eq!(
            Shadowed::rhs(0.1, &sa).to_array(),
            $plain::rhs(0.1, &sb).to_array()
        );
        Shadowed::step(0.1, &mut sa, $plain::STEP).unwrap();
        $plain::step(0.1, &mut sb, $plain::STEP).unwrap();
        assert_eq!(sa.to_array(), sb.to_array());
        $(
            let $jacobians = [0.1; $plain::N];
            let (s1, a1, b1) = Shadowed::step_jacobians(0.1, &sa, &$jacobians, $plain::STEP).unwrap();
            let (s2, a2, b2) = $plain::step_jacobians(0.1, &sb, &$jacobians, $plain::STEP).unwrap();
            assert_eq!((s1.to_array(), a1, b1), (s2.to_array(), a2, b2));
        )?
    }};
}

#[test]
fn scene_types_named_like_primitives_and_prelude_items_simulate_what_plain_ones_do() {
    same_trajectory!(named_f64::f64, Srms; u);
    same_trajectory!(named_option::Option, Capture);
    same_trajectory!(crowded::shadowed::SsrmsPayload, SsrmsPayload; u);
    same_trajectory!(crowded::shadowed::CtWrench, CtWrench);
    same_trajectory!(crowded::shadowed::CaptureRotor, CaptureRotor);
    same_trajectory!(crowded::shadowed::Flexible, Flexible);
}

/// Step Jacobians with external wrenches on a fixed base, from the generated derivatives and
/// the generated Jacobians of the wrenches' bodies: against central differences of the step
/// (`common::linearize`) and the interpreted Jacobians (which `tests/linearize.rs` checks
/// against differences too), at a time inside the tabulated wrenches' ramp.
macro_rules! wrench_jacobians {
    ($name:ident, $ty:ident, $st:ident, $file:literal) => {
        #[test]
        fn $name() {
            use common::linearize::{
                against_differences, assert_matches_differences, interpreted, interpreted_step,
                scale, worst_between,
            };
            let t = 0.4;
            let x0 = $ty::initial_state().to_array();
            let x = core::array::from_fn(|i| x0[i] + 0.05 * ((i as f64) * 0.7).sin());
            let u = core::array::from_fn(|i| 20.0 * (1.0 + i as f64));
            let step = |x: &[f64; $ty::DIM], u: &[f64; $ty::N]| {
                let (s, a, b) = $ty::step_jacobians(t, &$st::from_array(x), u, $ty::STEP).unwrap();
                (s.to_array(), a, b)
            };
            assert_matches_differences(stringify!($ty), against_differences(step, x, u));
            let g = step(&x, &u);
            let i = interpreted_step(&interpreted($file), t, &x, &u, $ty::STEP);
            let w = worst_between(&g, &i);
            eprintln!("{}: generated vs interpreted {w:.2e}", stringify!($ty));
            assert!(w <= 1e-10 * scale(&g).max(1.0), "{w:e}");
        }
    };
}

common::linearize::floating_tests!(
    floating_wrenches_step_jacobians,
    FloatingWrenches,
    FloatingWrenchesState,
    "tests/data/scenes/floating_wrenches.toml"
);

wrench_jacobians!(
    wrenches_in_the_body_frame_step_jacobians,
    GravityWrench,
    GravityWrenchState,
    "tests/data/scenes/gravity_wrench.toml"
);
wrench_jacobians!(
    wrenches_with_rotor_inertia_step_jacobians,
    RotorWrench,
    RotorWrenchState,
    "tests/data/scenes/rotor_wrench.toml"
);
