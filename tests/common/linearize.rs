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
