//! The Jacobians `(A, B)` of one step of a scene, `x⁺ = Φ(t, x, u)` with `u` the joint torques
//! added to the scene's drive: `scene!`'s `step_jacobians` (from the generated derivatives)
//! and the interpreted `kanegen::sim::linearize::step_jacobians` (from the run-time ones).
//!
//! Oracles:
//! - central differences of the step itself (the state `step_jacobians` returns, which with
//!   `u = 0` is [`Srms::step`]'s bit for bit), at steps `e` and `2e`: the Jacobians agree with
//!   the differences at `e` within four times the differences' own error `|D(e) − D(2e)|` plus
//!   a rounding floor of `1e-9 · max|J|`;
//! - the interpreted and generated Jacobians, two independent derivative codes (run-time
//!   Carpentier–Mansard over the model's numbers, generated straight-line code), agree to
//!   `1e-10 · max|J|`.
//!
//! Scenes: `scenes/srms.toml` (dopri5, so its step is RK4; PD drives and damping, fixed base),
//! `tests/data/scenes/linearize_ct_midpoint.toml` (UR5 under gravity, a computed-torque drive
//! along a quintic, viscous and Coulomb friction, a wrench fixed in a body and one fixed in the
//! base frame, implicit midpoint), `tests/data/scenes/rotor_wrench.toml` (interpreted: rotor
//! inertia, a tabulated body-frame wrench and a base-frame one, RK4) and
//! `scenes/ur5_torque_input.toml` (UR5 under gravity, damping, no drive, RK4) and
//! `scenes/ssrms_drives.toml` (rotor inertia, stiff PD, viscous and Coulomb friction, RK4),
//! `tests/data/scenes/linearize_flexible.toml` (Spong's flexible joints under gravity, PD and
//! friction on the motors, RK4) and, in the tangent space, `tests/data/scenes/linearize_floating.toml`
//! `tests/data/scenes/linearize_floating_rotor.toml` and
//! `tests/data/scenes/linearize_floating_midpoint.toml` (a free-floating base under gravity,
//! RK4 without and with rotor inertia, and the Lie-group implicit midpoint rule; module
//! [`tangent`]).

use common::linearize::{
    against_differences, assert_matches_differences, floating_tests, interpreted, interpreted_step,
    scale, worst_between, Jac,
};
use kanegen::sim::linearize::scheme;
use kanegen::sim::system::SceneSystem;

mod common;

kanegen::scene!(Srms, "scenes/srms.toml");
kanegen::scene!(CtMidpoint, "tests/data/scenes/linearize_ct_midpoint.toml");
kanegen::scene!(FreeUr5, "scenes/ur5_torque_input.toml");
kanegen::scene!(SsrmsDrives, "scenes/ssrms_drives.toml");

macro_rules! scene_tests {
    ($mod:ident, $ty:ident, $st:ident, $file:literal, $t:expr, $du:expr) => {
        mod $mod {
            use super::*;

            /// A state off the initial one (speeds and a displacement) and an input.
            fn point() -> (f64, [f64; $ty::DIM], [f64; $ty::N]) {
                let x0 = $ty::initial_state().to_array();
                let x = core::array::from_fn(|i| {
                    x0[i] + 0.05 * ((i as f64) * 0.7).sin() + 0.1 * (i % 3) as f64
                });
                let u = core::array::from_fn(|i| $du * (1.0 + i as f64) * 0.3);
                ($t, x, u)
            }

            fn step(x: &[f64; $ty::DIM], u: &[f64; $ty::N]) -> Jac<{ $ty::DIM }, { $ty::N }> {
                let s = $st::from_array(x);
                let (s, a, b) = $ty::step_jacobians(point().0, &s, u, $ty::STEP).unwrap();
                (s.to_array(), a, b)
            }

            #[test]
            fn generated_jacobians_match_central_differences() {
                let (_, x, u) = point();
                assert_matches_differences(stringify!($ty), against_differences(step, x, u));
            }

            #[test]
            fn interpreted_jacobians_match_central_differences() {
                let scene = interpreted($file);
                let (t, x, u) = point();
                let f = |x: &[f64; $ty::DIM], u: &[f64; $ty::N]| {
                    interpreted_step(&scene, t, x, u, $ty::STEP)
                };
                assert_matches_differences(
                    concat!(stringify!($ty), " (interpreted)"),
                    against_differences(f, x, u),
                );
            }

            #[test]
            fn interpreted_and_generated_agree() {
                let scene = interpreted($file);
                let (t, x, u) = point();
                let g = step(&x, &u);
                let i = interpreted_step(&scene, t, &x, &u, $ty::STEP);
                let w = worst_between(&g, &i);
                eprintln!(
                    "{}: generated vs interpreted {w:.2e} (max|J| {:.2e})",
                    stringify!($ty),
                    scale(&g)
                );
                assert!(w <= 1e-10 * scale(&g).max(1.0), "{w:e}");
            }

            /// With no input, the new state is `step`'s, bit for bit.
            #[test]
            fn with_no_input_the_state_is_the_step() {
                let (t, x, _) = point();
                let s = $st::from_array(&x);
                let (with, _, _) = $ty::step_jacobians(t, &s, &[0.0; $ty::N], $ty::STEP).unwrap();
                let mut plain = s;
                $ty::step(t, &mut plain, $ty::STEP).unwrap();
                assert_eq!(with.to_array(), plain.to_array());
            }
        }
    };
}

scene_tests!(srms, Srms, SrmsState, "scenes/srms.toml", 0.0, 20.0);
scene_tests!(
    computed_torque_midpoint,
    CtMidpoint,
    CtMidpointState,
    "tests/data/scenes/linearize_ct_midpoint.toml",
    0.4,
    1.5
);
scene_tests!(
    free_ur5,
    FreeUr5,
    FreeUr5State,
    "scenes/ur5_torque_input.toml",
    0.0,
    2.0
);

scene_tests!(
    rotor_inertia,
    SsrmsDrives,
    SsrmsDrivesState,
    "scenes/ssrms_drives.toml",
    0.0,
    50.0
);

/// External wrenches on the RK4 path with rotor inertia: `tests/data/scenes/rotor_wrench.toml`
/// (SSRMS under gravity, a wrench fixed in the base frame and a tabulated one fixed in a body,
/// Coulomb friction; dopri5, so its step is RK4), interpreted, inside the table's ramp.
#[test]
fn wrenches_with_rotor_inertia_match_central_differences() {
    let scene = interpreted("tests/data/scenes/rotor_wrench.toml");
    let q = [0.1, 0.3, -0.7, 0.4, 0.1, 0.2, 0.0];
    let x: [f64; 14] = core::array::from_fn(|i| {
        if i < 7 {
            q[i] + 0.05 * ((i as f64) * 0.7).sin()
        } else {
            0.03 * ((i as f64) * 1.3).cos()
        }
    });
    let u: [f64; 7] = core::array::from_fn(|i| 20.0 * (1.0 + i as f64));
    let f = |x: &[f64; 14], u: &[f64; 7]| interpreted_step(&scene, 0.4, x, u, 0.01);
    assert_matches_differences("rotor_wrench (interpreted)", against_differences(f, x, u));
}

kanegen::scene!(Flexible, "tests/data/scenes/linearize_flexible.toml");

scene_tests!(
    flexible_joints,
    Flexible,
    FlexibleState,
    "tests/data/scenes/linearize_flexible.toml",
    0.1,
    3.0
);

kanegen::scene!(Floating, "tests/data/scenes/linearize_floating.toml");
kanegen::scene!(
    FloatingRotor,
    "tests/data/scenes/linearize_floating_rotor.toml"
);
kanegen::scene!(
    FloatingMidpoint,
    "tests/data/scenes/linearize_floating_midpoint.toml"
);

floating_tests!(
    floating,
    Floating,
    FloatingState,
    "tests/data/scenes/linearize_floating.toml"
);
floating_tests!(
    floating_midpoint,
    FloatingMidpoint,
    FloatingMidpointState,
    "tests/data/scenes/linearize_floating_midpoint.toml"
);
floating_tests!(
    floating_rotor,
    FloatingRotor,
    FloatingRotorState,
    "tests/data/scenes/linearize_floating_rotor.toml"
);

/// What the step Jacobians do not cover is refused, named.
#[test]
fn uncovered_scenes_are_refused_by_name() {
    for (file, words) in [
        ("tests/data/scenes/panda_mimic_pd.toml", "mimic joints"),
        ("scenes/ssrms_flexible.toml", "rosenbrock (Rodas4)"),
    ] {
        let scene = interpreted(file);
        let sys = SceneSystem::new(&scene);
        let err = scheme(&sys).unwrap_err().to_string();
        assert!(err.contains(words), "{file}: {err}");
    }
}

/// `kanegen simulate SCENE --linearize` with its arguments, from the project root.
fn cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .args(["simulate"])
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

/// The CLI prints the generated type's Jacobians at the scene's initial state (JSON), and
/// refuses an uncovered scene naming what it has.
#[test]
fn cli_linearize_prints_the_step_jacobians() {
    let o = cli(&["scenes/srms.toml", "--linearize", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["scheme"], "rk4");
    let s = Srms::initial_state();
    let (next, a, b) = Srms::step_jacobians(0.0, &s, &[0.0; Srms::N], Srms::STEP).unwrap();
    let rows =
        |m: &serde_json::Value| -> Vec<Vec<f64>> { serde_json::from_value(m.clone()).unwrap() };
    let (ca, cb) = (rows(&v["A"]), rows(&v["B"]));
    let x: Vec<f64> = serde_json::from_value(v["x_next"].clone()).unwrap();
    let mut worst = 0.0_f64;
    for i in 0..Srms::DIM {
        worst = worst.max((x[i] - next.to_array()[i]).abs());
        for j in 0..Srms::DIM {
            worst = worst.max((ca[i][j] - a[i][j]).abs());
        }
        for j in 0..Srms::N {
            worst = worst.max((cb[i][j] - b[i][j]).abs());
        }
    }
    assert!(worst <= 1e-12, "{worst:e}");
    let text = cli(&["scenes/srms.toml", "--linearize"]);
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(
        text.contains("A = ∂x⁺/∂x (12 × 12") && text.contains("qd_wrist_roll"),
        "{text}"
    );
    // A free-floating scene: `A` in the tangent space, rows named by their directions.
    let file = "tests/data/scenes/linearize_floating.toml";
    let o = cli(&[file, "--linearize", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let s = Floating::initial_state();
    let (_, a, _) = Floating::step_jacobians(0.0, &s, &[0.0; Floating::N], Floating::STEP).unwrap();
    let ca = rows(&v["A"]);
    assert_eq!(
        (ca.len(), ca[0].len()),
        (Floating::DIM - 1, Floating::DIM - 1)
    );
    let worst = (0..Floating::DIM - 1)
        .flat_map(|i| (0..Floating::DIM - 1).map(move |j| (i, j)))
        .fold(0.0_f64, |m, (i, j)| m.max((ca[i][j] - a[i][j]).abs()));
    assert!(worst <= 1e-10, "{worst:e}");
    let names: Vec<String> = serde_json::from_value(v["tangent"].clone()).unwrap();
    assert_eq!(
        names[..6],
        ["dp0_x", "dp0_y", "dp0_z", "dtheta_x", "dtheta_y", "dtheta_z"]
    );
    let err = cli(&["tests/data/scenes/panda_mimic_pd.toml", "--linearize"]);
    let msg = String::from_utf8_lossy(&err.stderr);
    assert!(
        !err.status.success() && msg.contains("mimic joints"),
        "{msg}"
    );
    // A fixed-base scene with wrenches in both frames (the SSRMS effects scene).
    let ok = cli(&["scenes/ssrms_effects.toml", "--linearize"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}
