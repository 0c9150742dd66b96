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
    against_differences, assert_matches_differences, interpreted, interpreted_step, scale,
    worst_between, Jac,
};
use kanegen::sim::linearize::{scheme, step_jacobians};
use kanegen::sim::scene::Scene;
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

/// A free-floating base: `A` and `B` in the tangent space of Pinocchio's `integrate` (the pose's
/// 7 numbers as `[δp; δθ]` in base coordinates). The central differences perturb the state
/// along each tangent direction (`p₀ + R₀ δp`, `quat ⊗ exp(δθ/2)`, the rest additively) and
/// read the new state in the same chart about the unperturbed new state
/// (`R⁺ᵀ (p − p⁺)`, `2 vec(quat⁺* ⊗ quat)`).
mod tangent {
    /// `a ⊗ b` of quaternions `[x, y, z, w]`.
    pub fn qmul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        let (au, aw, bu, bw) = ([a[0], a[1], a[2]], a[3], [b[0], b[1], b[2]], b[3]);
        let c = [
            au[1] * bu[2] - au[2] * bu[1],
            au[2] * bu[0] - au[0] * bu[2],
            au[0] * bu[1] - au[1] * bu[0],
        ];
        let v: [f64; 3] = core::array::from_fn(|i| aw * bu[i] + bw * au[i] + c[i]);
        [
            v[0],
            v[1],
            v[2],
            aw * bw - (au[0] * bu[0] + au[1] * bu[1] + au[2] * bu[2]),
        ]
    }

    fn quat(x: &[f64]) -> [f64; 4] {
        [x[3], x[4], x[5], x[6]]
    }

    /// `x ⊕ δ` (tangent `δ`, one number fewer than `x`).
    pub fn integrate<const D: usize>(x: &[f64; D], dt: &[f64]) -> [f64; D] {
        let r = kanegen::runtime::ode::quat_to_matrix(&quat(x));
        let mut y = *x;
        for i in 0..3 {
            y[i] += (0..3).map(|j| r[i][j] * dt[j]).sum::<f64>();
        }
        let th = [dt[3], dt[4], dt[5]];
        let a = (th[0] * th[0] + th[1] * th[1] + th[2] * th[2]).sqrt();
        let s = if a > 0.0 { (0.5 * a).sin() / a } else { 0.5 };
        let q = qmul(quat(x), [s * th[0], s * th[1], s * th[2], (0.5 * a).cos()]);
        y[3..7].copy_from_slice(&q);
        for i in 7..D {
            y[i] += dt[i - 1];
        }
        y
    }

    /// The chart of `y` about `y0`: `[R0ᵀ (p − p0); 2 vec(quat0* ⊗ quat); rest − rest0]`.
    pub fn chart(y0: &[f64], y: &[f64]) -> Vec<f64> {
        let r = kanegen::runtime::ode::quat_to_matrix(&quat(y0));
        let q0 = quat(y0);
        let rel = qmul([-q0[0], -q0[1], -q0[2], q0[3]], quat(y));
        (0..y.len() - 1)
            .map(|i| match i {
                0..=2 => (0..3).map(|j| r[j][i] * (y[j] - y0[j])).sum::<f64>(),
                3..=5 => 2.0 * rel[i - 3],
                _ => y[i + 1] - y0[i + 1],
            })
            .collect()
    }
}

macro_rules! floating_tests {
    ($mod:ident, $ty:ident, $st:ident, $file:literal) => {
        mod $mod {
            use super::tangent::{chart, integrate};
            use super::*;

            const D: usize = $ty::DIM;
            const T: usize = D - 1;
            const N: usize = $ty::N;

            /// One step with its Jacobians: the new state, `A` (`T × T`), `B` (`T × N`).
            type TJac = ([f64; D], [[f64; T]; T], [[f64; N]; T]);

            fn point() -> (f64, [f64; D], [f64; N]) {
                let x0 = $ty::initial_state().to_array();
                let x = core::array::from_fn(|i| {
                    if i < 7 {
                        x0[i]
                    } else {
                        x0[i] + 0.05 * ((i as f64) * 0.7).sin()
                    }
                });
                (0.2, x, core::array::from_fn(|i| 0.4 * (1.0 + i as f64)))
            }

            fn generated(x: &[f64; D], u: &[f64; N]) -> TJac {
                let s = $st::from_array(x);
                let (s, a, b) = $ty::step_jacobians(point().0, &s, u, $ty::STEP).unwrap();
                (s.to_array(), a, b)
            }

            fn interpreted_floating(scene: &Scene, x: &[f64; D], u: &[f64; N]) -> TJac {
                let mut sys = SceneSystem::new(scene);
                let j = step_jacobians(&mut sys, point().0, x, u, $ty::STEP).unwrap();
                assert_eq!((j.a.len(), j.b.len()), (T, T));
                (
                    j.state.try_into().unwrap(),
                    core::array::from_fn(|i| j.a[i].clone().try_into().unwrap()),
                    core::array::from_fn(|i| j.b[i].clone().try_into().unwrap()),
                )
            }

            fn against_tangent_differences(
                step: impl Fn(&[f64; D], &[f64; N]) -> TJac,
            ) -> (f64, f64, f64) {
                let (_, x, u) = point();
                let j = step(&x, &u);
                let scale = j.1.iter().flatten().chain(j.2.iter().flatten());
                let scale = scale.fold(0.0_f64, |m, v| m.max(v.abs()));
                let (mut worst, mut own) = (0.0_f64, 0.0_f64);
                for col in 0..T + N {
                    let diff = |e: f64| -> Vec<f64> {
                        let (mut dp, mut dm) = ([0.0; T], [0.0; T]);
                        let (mut up, mut um) = (u, u);
                        if col < T {
                            dp[col] = e;
                            dm[col] = -e;
                        } else {
                            up[col - T] += e;
                            um[col - T] -= e;
                        }
                        let p = chart(&j.0, &step(&integrate(&x, &dp), &up).0);
                        let m = chart(&j.0, &step(&integrate(&x, &dm), &um).0);
                        p.iter().zip(&m).map(|(p, m)| (p - m) / (2.0 * e)).collect()
                    };
                    let (d1, d2) = (diff(1e-6), diff(2e-6));
                    for i in 0..T {
                        let exact = if col < T {
                            j.1[i][col]
                        } else {
                            j.2[i][col - T]
                        };
                        worst = worst.max((exact - d1[i]).abs());
                        own = own.max((d1[i] - d2[i]).abs());
                    }
                }
                (worst, own, scale)
            }

            #[test]
            fn generated_jacobians_match_central_differences() {
                let r = against_tangent_differences(generated);
                assert_matches_differences(stringify!($ty), r);
            }

            #[test]
            fn interpreted_jacobians_match_central_differences() {
                let scene = interpreted($file);
                let f = |x: &[f64; D], u: &[f64; N]| interpreted_floating(&scene, x, u);
                assert_matches_differences(
                    concat!(stringify!($ty), " (interpreted)"),
                    against_tangent_differences(f),
                );
            }

            #[test]
            fn interpreted_and_generated_agree() {
                let scene = interpreted($file);
                let (_, x, u) = point();
                let (g, i) = (generated(&x, &u), interpreted_floating(&scene, &x, &u));
                let pairs = g.1.iter().flatten().zip(i.1.iter().flatten());
                let pairs = pairs.chain(g.2.iter().flatten().zip(i.2.iter().flatten()));
                let pairs = pairs.chain(g.0.iter().zip(i.0.iter()));
                let w = pairs.fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
                let ws =
                    g.0.iter()
                        .zip(i.0.iter())
                        .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()));
                eprintln!(
                    "{}: generated vs interpreted {w:.2e} (state {ws:.2e})",
                    stringify!($ty)
                );
                // Measured 1.4e-15 without rotors and 1.7e-10 with them (the LDLᵀ solves of
                // `M + A` and the articulated-body kernel of the interpreted step differ in
                // rounding), each within its central differences' own error.
                assert!(w <= 1e-9 && ws <= 1e-12, "{w:e} {ws:e}");
            }

            /// With no input, the new state is `step`'s (the quaternion renormalized), bit for
            /// bit.
            #[test]
            fn with_no_input_the_state_is_the_step() {
                let (t, x, _) = point();
                let s = $st::from_array(&x);
                let (with, _, _) = $ty::step_jacobians(t, &s, &[0.0; N], $ty::STEP).unwrap();
                let mut plain = s;
                $ty::step(t, &mut plain, $ty::STEP).unwrap();
                assert_eq!(with.to_array(), plain.to_array());
            }

            /// Gravity is read through the base's attitude: without its columns (`∂ν̇/∂quat`)
            /// the Jacobians would miss `[g_b]×` in the base's rotation columns. The scene's
            /// gravity is far from zero there.
            #[test]
            fn the_attitude_columns_carry_gravity() {
                let (_, x, u) = point();
                let a = generated(&x, &u).1;
                // Rows v_b (tangent 6 + N..), columns δθ (3..6): about h [g_b]×.
                let col: f64 = (0..3)
                    .map(|r| (3..6).map(|c| a[T - 6 - N + r][c].abs()).sum::<f64>())
                    .sum();
                assert!(col > 1e-3, "{col:e}");
            }
        }
    };
}

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
        (
            "tests/data/scenes/floating_wrenches.toml",
            "external wrenches on a free-floating base",
        ),
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
    let err = cli(&["tests/data/scenes/floating_wrenches.toml", "--linearize"]);
    let msg = String::from_utf8_lossy(&err.stderr);
    assert!(
        !err.status.success() && msg.contains("external wrenches on a free-floating base"),
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
