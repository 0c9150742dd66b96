//! Regrouped inertial parameters change the bodies' spatial inertias but not the joint-space
//! dynamics. Oracle: the same local-frame algorithms on [`Params::new`] (untouched inertias),
//! and the paper's recurrent algorithms, which read the untouched centre-of-mass form and must
//! agree on regrouped parameters too. Random trees with prismatic joints, fixed and free-floating
//! base, gravity and external wrenches; the payload body of `keep` is left alone.

use kanegen_dynamics::algorithms::{crba, floating, momentum, rnea};
use kanegen_dynamics::base::{FloatingBase, FloatingState, BASE_BODY};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::metrics::{rel_err, rel_err_mat};
use kanegen_dynamics::regroup::regrouped;
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads, Methods, Params};
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
    (1..=9)
        .map(|n| random_tree(&spec(n), 300 + n as u64))
        .chain((2..=7).map(|n| random_chain(&spec(n), 500 + n as u64)))
        .collect()
}

fn loads(n: usize, seed: u64, floating: bool) -> Loads<f64> {
    let mut r = rng(seed);
    let w = random_vec(&mut r, 12, 3.0);
    Loads {
        tau: Some(random_vec(&mut r, n, 2.0)),
        gravity: Some(Vec3::new(0.4, -2.0, -9.81)),
        external: vec![
            ExternalWrench {
                body: n - 1,
                frame: LoadFrame::Body,
                force: Vec3::new(w[0], w[1], w[2]),
                moment: Vec3::new(w[3], w[4], w[5]),
            },
            ExternalWrench {
                body: if floating { BASE_BODY } else { 0 },
                frame: LoadFrame::Base,
                force: Vec3::new(w[6], w[7], w[8]),
                moment: Vec3::new(w[9], w[10], w[11]),
            },
        ],
    }
}

#[test]
fn fixed_base_joint_space_dynamics_are_unchanged() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let r = regrouped::<f64>(m, None, &[]);
        assert!(r.base.is_none());
        let n = p.dof();
        // General axes leave dense residues; never more numbers than before.
        assert!(
            r.report.nonzero_after <= r.report.nonzero_before,
            "{:?}",
            r.report
        );
        let mut g = rng(k as u64);
        let (q, qd, qdd) = (
            random_vec(&mut g, n, 2.0),
            random_vec(&mut g, n, 1.5),
            random_vec(&mut g, n, 3.0),
        );
        let l = loads(n, k as u64, false);
        let errs = [
            rel_err_mat(
                &crba::mass_matrix(&r.params, &q),
                &crba::mass_matrix(&p, &q),
            ),
            rel_err(
                &rnea::tau_minus_c(&r.params, &q, &qd, &l),
                &rnea::tau_minus_c(&p, &q, &qd, &l),
            ),
            rel_err(
                &rnea::inverse_dynamics(&r.params, &q, &qd, &qdd, &l),
                &rnea::inverse_dynamics(&p, &q, &qd, &qdd, &l),
            ),
        ];
        for (what, e) in ["M", "bias", "inverse dynamics"].iter().zip(errs) {
            assert!(e < TOL, "model {k}: {what} {e:e}");
            worst = worst.max(e);
        }
        // The paper's algorithm reads the centre-of-mass form, which regrouping leaves alone.
        if m.is_chain() {
            let rec = Methods::RECURRENT;
            let e = rel_err_mat(
                &rec.mass_matrix.mass_matrix(&r.params, &q),
                &crba::mass_matrix(&p, &q),
            );
            assert!(
                e < 1e-10,
                "model {k}: recurrent M on regrouped parameters {e:e}"
            );
        }
    }
    println!("fixed base: worst {worst:.1e}");
}

#[test]
fn what_a_fixed_base_receives_is_dropped_and_a_floating_base_keeps_it() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let bi = &random_inertial(&mut rng(900 + k as u64), 50.0, 1.0);
        let p = Params::<f64>::new(m);
        let base = FloatingBase::<f64>::from_inertial(bi);
        let r = regrouped::<f64>(m, Some(bi), &[]);
        let rb = r.base.as_ref().expect("a floating base");
        // The centre-of-mass form of the base is the original one; only `inertia` grew.
        assert_eq!(rb.mass, base.mass);
        let n = p.dof();
        let mut g = rng(50 + k as u64);
        let (q, qd) = (random_vec(&mut g, n, 2.0), random_vec(&mut g, n, 1.5));
        let w = random_vec(&mut g, 6, 0.8);
        let mut s = FloatingState::at_rest();
        s.v_b = Vec3::new(w[0], w[1], w[2]);
        s.omega_b = Vec3::new(w[3], w[4], w[5]);
        s.rotation = kanegen_dynamics::linalg::axis_rotation(
            &Vec3::new(0.6, 0.0, 0.8),
            &0.3_f64.sin(),
            &0.3_f64.cos(),
        );
        let l = loads(n, 70 + k as u64, true);
        let sp = Methods::SPATIAL;
        let errs = [
            rel_err_mat(
                &floating::mass_matrix(sp.mass_matrix, &r.params, rb, &s, &q),
                &floating::mass_matrix(sp.mass_matrix, &p, &base, &s, &q),
            ),
            rel_err(
                &floating::tau_minus_c(sp.nonlinear_effects, &r.params, rb, &s, &q, &qd, &l),
                &floating::tau_minus_c(sp.nonlinear_effects, &p, &base, &s, &q, &qd, &l),
            ),
            rel_err(
                &momentum::momentum_base(&r.params, rb, &s, &q, &qd),
                &momentum::momentum_base(&p, &base, &s, &q, &qd),
            ),
        ];
        for (what, e) in ["M", "bias", "momentum"].iter().zip(errs) {
            assert!(e < TOL, "model {k}: floating {what} {e:e}");
            worst = worst.max(e);
        }
    }
    println!("floating base: worst {worst:.1e}");
}

#[test]
fn kept_bodies_neither_give_nor_receive() {
    let m = random_chain(
        &ChainSpec {
            n: 5,
            ..Default::default()
        },
        9,
    );
    let p = Params::<f64>::new(&m);
    let r = regrouped::<f64>(&m, None, &[4]);
    let same = |a: &kanegen_dynamics::spatial::RbInertia<f64>,
                b: &kanegen_dynamics::spatial::RbInertia<f64>| {
        a.m == b.m && a.h.0 == b.h.0 && a.ibar.0 == b.ibar.0
    };
    // Body 4 kept; body 3 (its parent) gives to body 2 but receives nothing from 4.
    assert!(same(&r.params.joints[4].inertia, &p.joints[4].inertia));
    assert!(!same(&r.params.joints[3].inertia, &p.joints[3].inertia));
    assert_eq!(
        r.params.joints[3].inertia.m, 0.0,
        "a revolute body gives its axis mass"
    );
    // The centre-of-mass form is untouched everywhere.
    for (a, b) in r.params.joints.iter().zip(&p.joints) {
        assert_eq!(
            (a.mass, a.com.0, a.inertia_com.0),
            (b.mass, b.com.0, b.inertia_com.0)
        );
    }
    let _ = Mat3::<f64>::zero();
}
