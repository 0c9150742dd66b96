//! The oracles of step Jacobians (`tests/linearize.rs`, `tests/scene_macro.rs`): central
//! differences of the step with their own error, and the interpreted Jacobians
//! (`kanegen::sim::linearize::step_jacobians`) as fixed-size arrays.

use kanegen::sim::linearize::step_jacobians;
use kanegen::sim::scene::Scene;
use kanegen::sim::system::SceneSystem;
use std::path::Path;

/// One step with its Jacobians at `(x, u)`: the new state, `A` (`D × D`) and `B` (`D × N`).
pub type Jac<const D: usize, const N: usize> = ([f64; D], [[f64; D]; D], [[f64; N]; D]);

/// The largest entry of `A` and `B` in magnitude.
pub fn scale<const D: usize, const N: usize>(j: &Jac<D, N>) -> f64 {
    let a = j.1.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
    j.2.iter().flatten().fold(a, |m, v| m.max(v.abs()))
}

/// `(worst |J − D(e)|, worst |D(e) − D(2e)|)` of the central differences `D` of the step over
/// every column of `x` and `u` (`e` relative to each component).
pub fn against_differences<const D: usize, const N: usize>(
    step: impl Fn(&[f64; D], &[f64; N]) -> Jac<D, N>,
    x: [f64; D],
    u: [f64; N],
) -> (f64, f64, f64) {
    let j = step(&x, &u);
    let (mut worst, mut own) = (0.0_f64, 0.0_f64);
    for col in 0..D + N {
        let diff = |e: f64| -> [f64; D] {
            let (mut xp, mut xm, mut up, mut um) = (x, x, u, u);
            let h = if col < D {
                let h = e * (1.0 + x[col].abs());
                xp[col] += h;
                xm[col] -= h;
                h
            } else {
                let h = e * (1.0 + u[col - D].abs());
                up[col - D] += h;
                um[col - D] -= h;
                h
            };
            let (p, m) = (step(&xp, &up).0, step(&xm, &um).0);
            core::array::from_fn(|i| (p[i] - m[i]) / (2.0 * h))
        };
        let (d1, d2) = (diff(1e-6), diff(2e-6));
        for i in 0..D {
            let exact = if col < D {
                j.1[i][col]
            } else {
                j.2[i][col - D]
            };
            worst = worst.max((exact - d1[i]).abs());
            own = own.max((d1[i] - d2[i]).abs());
        }
    }
    (worst, own, scale(&j))
}

pub fn assert_matches_differences(name: &str, (worst, own, scale): (f64, f64, f64)) {
    eprintln!("{name}: worst |J − D| {worst:.2e}, the differences' own error {own:.2e}, max|J| {scale:.2e}");
    assert!(
        worst <= 4.0 * own + 1e-9 * scale,
        "{name}: {worst:e} > 4 · {own:e} + 1e-9 · {scale:e}"
    );
}

/// The interpreted system of a scene file.
pub fn interpreted(file: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).unwrap()
}

/// The interpreted Jacobians as fixed-size arrays.
pub fn interpreted_step<const D: usize, const N: usize>(
    scene: &Scene,
    t: f64,
    x: &[f64; D],
    u: &[f64; N],
    h: f64,
) -> Jac<D, N> {
    let mut sys = SceneSystem::new(scene);
    let j = step_jacobians(&mut sys, t, x, u, h).unwrap();
    (
        j.state.try_into().unwrap(),
        core::array::from_fn(|i| j.a[i].clone().try_into().unwrap()),
        core::array::from_fn(|i| j.b[i].clone().try_into().unwrap()),
    )
}

/// Worst `|J_generated − J_interpreted|` over `A`, `B` and the new state.
pub fn worst_between<const D: usize, const N: usize>(g: &Jac<D, N>, i: &Jac<D, N>) -> f64 {
    let a = g.1.iter().flatten().zip(i.1.iter().flatten());
    let b = g.2.iter().flatten().zip(i.2.iter().flatten());
    let x = g.0.iter().zip(i.0.iter());
    a.chain(b)
        .chain(x)
        .fold(0.0_f64, |m, (p, q)| m.max((p - q).abs()))
}

/// A free-floating base: `A` and `B` in the tangent space of Pinocchio's `integrate` (the pose's
/// 7 numbers as `[δp; δθ]` in base coordinates). The central differences perturb the state
/// along each tangent direction (`p₀ + R₀ δp`, `quat ⊗ exp(δθ/2)`, the rest additively) and
/// read the new state in the same chart about the unperturbed new state
/// (`R⁺ᵀ (p − p⁺)`, `2 vec(quat⁺* ⊗ quat)`).
pub mod tangent {
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

/// The tests of a free-floating scene's step Jacobians (`scene!`'s type `$ty` with state `$st`
/// of the scene file `$file`, invoked at the test crate's root): against central differences
/// along the tangent directions ([`tangent`]), generated and interpreted, and each other.
// Each test crate that takes `common` uses it or not.
#[allow(unused_macros)]
macro_rules! floating_tests {
    ($mod:ident, $ty:ident, $st:ident, $file:literal) => {
        mod $mod {
            use super::*;
            use crate::common::linearize::tangent::{chart, integrate};
            use crate::common::linearize::{assert_matches_differences, interpreted};
            use kanegen::sim::linearize::step_jacobians;
            use kanegen::sim::scene::Scene;
            use kanegen::sim::system::SceneSystem;

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

#[allow(unused_imports)]
pub(crate) use floating_tests;
