//! The classical Newton–Euler algorithm (3-vectors, classical accelerations) against the spatial
//! RNEA, which shares only the joint transforms with it: bias forces, inverse dynamics, fixed and
//! free-floating base, random trees and chains with prismatic joints, gravity, drives and
//! external wrenches in both frames, on the model's own and on regrouped inertias. And the
//! comparison can fail: a perturbed inertia moves the result far outside the tolerance.

use kanegen_dynamics::algorithms::{newton_euler, rnea};
use kanegen_dynamics::base::{FloatingBase, FloatingState, BASE_BODY};
use kanegen_dynamics::linalg::{axis_rotation, Vec3};
use kanegen_dynamics::metrics::rel_err;
use kanegen_dynamics::regroup::regrouped;
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads, Params};
use kanegen_model::random::{
    random_chain, random_inertial, random_tree, random_vec, rng, ChainSpec,
};
use kanegen_model::Model;

const TOL: f64 = 1e-12;

fn models() -> Vec<Model> {
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.3,
        ..Default::default()
    };
    (1..=10)
        .map(|n| random_tree(&spec(n), 700 + n as u64))
        .chain((1..=8).map(|n| random_chain(&spec(n), 800 + n as u64)))
        .collect()
}

fn loads(n: usize, seed: u64, base_body: usize) -> Loads<f64> {
    let mut r = rng(seed);
    let w = random_vec(&mut r, 18, 3.0);
    let v = |k: usize| Vec3::new(w[k], w[k + 1], w[k + 2]);
    Loads {
        tau: Some(random_vec(&mut r, n, 2.0)),
        gravity: Some(Vec3::new(0.4, -2.0, -9.81)),
        external: vec![
            ExternalWrench {
                body: n - 1,
                frame: LoadFrame::Body,
                force: v(0),
                moment: v(3),
            },
            ExternalWrench {
                body: n / 2,
                frame: LoadFrame::Base,
                force: v(6),
                moment: v(9),
            },
            ExternalWrench {
                body: base_body,
                frame: LoadFrame::Base,
                force: v(12),
                moment: v(15),
            },
        ],
    }
}

#[test]
fn fixed_base_agrees_with_the_spatial_rnea() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let n = m.dof();
        for p in [Params::<f64>::new(m), regrouped::<f64>(m, None, &[]).params] {
            let mut g = rng(k as u64);
            let (q, qd, qdd) = (
                random_vec(&mut g, n, 2.0),
                random_vec(&mut g, n, 1.5),
                random_vec(&mut g, n, 3.0),
            );
            let l = loads(n, 10 + k as u64, 0);
            let e_b = rel_err(
                &newton_euler::tau_minus_c(&p, &q, &qd, &l),
                &rnea::tau_minus_c(&p, &q, &qd, &l),
            );
            let e_id = rel_err(
                &newton_euler::inverse_dynamics(&p, &q, &qd, &qdd, &l),
                &rnea::inverse_dynamics(&p, &q, &qd, &qdd, &l),
            );
            assert!(
                e_b < TOL && e_id < TOL,
                "model {k}: bias {e_b:e}, ID {e_id:e}"
            );
            worst = worst.max(e_b).max(e_id);
        }
    }
    println!("fixed base: worst {worst:.1e}");
}

#[test]
fn floating_base_agrees_with_the_spatial_rnea() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let n = m.dof();
        let bi = random_inertial(&mut rng(60 + k as u64), 40.0, 1.0);
        let base = FloatingBase::<f64>::from_inertial(&bi);
        let p = Params::<f64>::new(m);
        let mut g = rng(90 + k as u64);
        let (q, qd, qdd) = (
            random_vec(&mut g, n, 2.0),
            random_vec(&mut g, n, 1.5),
            random_vec(&mut g, n, 3.0),
        );
        let w = random_vec(&mut g, 12, 0.8);
        let mut s = FloatingState::at_rest();
        s.position = Vec3::new(w[0], w[1], w[2]);
        s.v_b = Vec3::new(w[3], w[4], w[5]);
        s.omega_b = Vec3::new(w[6], w[7], w[8]);
        s.rotation = axis_rotation(&Vec3::new(0.0, 0.6, 0.8), &0.7_f64.sin(), &0.7_f64.cos());
        let base_acc: [f64; 6] = core::array::from_fn(|i| w[(i + 3) % 12] * 1.7);
        let l = loads(n, 30 + k as u64, BASE_BODY);
        let e_b = rel_err(
            &newton_euler::floating_tau_minus_c(&p, &base, &s, &q, &qd, &l),
            &rnea::floating_tau_minus_c(&p, &base, &s, &q, &qd, &l),
        );
        let e_id = rel_err(
            &newton_euler::floating_inverse_dynamics(&p, &base, &s, &q, &qd, &base_acc, &qdd, &l),
            &rnea::floating_inverse_dynamics(&p, &base, &s, &q, &qd, &base_acc, &qdd, &l),
        );
        assert!(
            e_b < TOL && e_id < TOL,
            "model {k}: bias {e_b:e}, ID {e_id:e}"
        );
        worst = worst.max(e_b).max(e_id);
    }
    println!("floating base: worst {worst:.1e}");
}

#[test]
fn a_perturbed_inertia_is_detected() {
    let m = &models()[12];
    let n = m.dof();
    let p = Params::<f64>::new(m);
    let mut p2 = p.clone();
    let j = p2.joints[n / 2].clone();
    p2.joints[n / 2].set_inertial(j.mass * 1.01, j.com, j.inertia_com);
    let mut g = rng(5);
    let (q, qd) = (random_vec(&mut g, n, 2.0), random_vec(&mut g, n, 1.5));
    let l = loads(n, 6, 0);
    let e = rel_err(
        &newton_euler::tau_minus_c(&p2, &q, &qd, &l),
        &rnea::tau_minus_c(&p, &q, &qd, &l),
    );
    assert!(e > 1e-6, "{e:e}");
}
