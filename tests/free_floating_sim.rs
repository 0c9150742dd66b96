//! A free-floating simulation on generated code conserves momentum as the interpreted one
//! does. The scene `scenes/free_floating_7dof.toml` (the bMSd 7-dof arm on its 1000 kg base,
//! joint PD drives, no gravity, an initial base twist) is integrated twice with the same RK4 of
//! `kanegen_sim::integrate` over the same state layout `[q (7 + N), v (6 + N)]` (Pinocchio's
//! free-flyer): once through the interpreted scene system, once through the generated
//! `kanegen_generated::free_floating_7dof::FreeFloating7`. The trajectories agree, and both
//! keep the total momentum (measured by the generated `momentum`).

use kanegen::sim::integrate::{rk4, System};
use kanegen::sim::scene::{Drives, Scene};
use kanegen::sim::simulate::SceneSystem;
use kanegen_generated::free_floating_7dof::FreeFloating7;
use std::path::Path;

const NQ: usize = FreeFloating7::NQ;
const NV: usize = FreeFloating7::NV;

/// The scene's dynamics on the generated code: PD drives, forward dynamics, configuration rates.
struct Generated {
    kp: Vec<f64>,
    kd: Vec<f64>,
    target: Vec<f64>,
}

impl System for Generated {
    fn dim(&self) -> usize {
        NQ + NV
    }
    fn deriv(&mut self, _t: f64, x: &[f64], dx: &mut [f64]) {
        let q: [f64; NQ] = x[..NQ].try_into().unwrap();
        let v: [f64; NV] = x[NQ..].try_into().unwrap();
        let tau: [f64; 7] = core::array::from_fn(|i| {
            self.kp[i] * (self.target[i] - q[7 + i]) - self.kd[i] * v[6 + i]
        });
        let a = FreeFloating7::forward_dynamics(&q, &v, &tau);
        let r = kanegen::dynamics::base::quat_to_matrix(&[q[3], q[4], q[5], q[6]]);
        for (d, row) in dx[..3].iter_mut().zip(&r.0) {
            *d = (0..3).map(|k| row[k] * v[k]).sum();
        }
        let (ux, uy, uz, w) = (q[3], q[4], q[5], q[6]);
        let (wx, wy, wz) = (v[3], v[4], v[5]);
        dx[3] = 0.5 * (w * wx + uy * wz - uz * wy);
        dx[4] = 0.5 * (w * wy + uz * wx - ux * wz);
        dx[5] = 0.5 * (w * wz + ux * wy - uy * wx);
        dx[6] = -0.5 * (ux * wx + uy * wy + uz * wz);
        dx[7..NQ].copy_from_slice(&v[6..]);
        dx[NQ..].copy_from_slice(&a);
    }
    fn project(&self, x: &mut [f64]) {
        let n = x[3..7].iter().map(|a| a * a).sum::<f64>().sqrt();
        for a in &mut x[3..7] {
            *a /= n;
        }
    }
}

#[test]
fn generated_free_floating_simulation_conserves_momentum_like_the_interpreted_one() {
    let scene =
        Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/free_floating_7dof.toml"))
            .unwrap();
    let Drives::Pd { kp, kd, target } = scene.drives.clone() else {
        panic!("the scene has PD drives")
    };
    let mut interp = SceneSystem::new(&scene);
    let x0 = interp.initial_state();
    assert_eq!(x0.len(), NQ + NV, "one state layout");
    let momentum = |x: &[f64]| -> [f64; 6] {
        FreeFloating7::momentum(&x[..NQ].try_into().unwrap(), &x[NQ..].try_into().unwrap())
    };
    let h0 = momentum(&x0);
    let scale = h0.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    assert!(scale > 1.0, "the scene starts with momentum: {h0:?}");
    let drift = |x: &[f64]| {
        momentum(x)
            .iter()
            .zip(&h0)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
            / scale
    };
    let (t1, h) = (5.0, 0.005);
    let (mut xi, mut xg) = (x0.clone(), x0.clone());
    let (mut di, mut dg) = (0.0_f64, 0.0_f64);
    rk4(&mut interp, 0.0, t1, h, &mut xi, |_, _, x| {
        di = di.max(drift(x))
    })
    .unwrap();
    let mut gen = Generated { kp, kd, target };
    rk4(&mut gen, 0.0, t1, h, &mut xg, |_, _, x| {
        dg = dg.max(drift(x))
    })
    .unwrap();
    let diff = xi
        .iter()
        .zip(&xg)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    eprintln!(
        "momentum drift: interpreted {di:.2e}, generated {dg:.2e}; states differ by {diff:.2e}"
    );
    assert!(diff < 1e-9, "the two simulations part: {diff:e}");
    // RK4 at h = 5 ms keeps momentum to its truncation error, both runs alike (measured
    // 1.2e-8 relative for each; bound 4× that).
    assert!(
        dg < 5e-8 && di < 5e-8,
        "drift interpreted {di:e}, generated {dg:e}"
    );
    assert!(
        dg < 10.0 * di.max(1e-15),
        "generated drifts more: {dg:e} vs {di:e}"
    );
}
