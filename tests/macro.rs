//! `kanegen::dynamics!` on random-geometry models (prismatic joints, gravity, a runtime payload):
//! the emitted functions equal the interpreted f64 algorithms.

use kanegen::metrics::rel_err;
use kanegen::random::{random_vec, rng};
use kanegen::{Algorithm, Chain, Inertial, Loads};
use std::path::Path;

kanegen::dynamics!(Random3, "tests/data/codegen/random3_prismatic.toml");
kanegen::dynamics!(Random5, "tests/data/codegen/random5.toml");
kanegen::dynamics!(
    Random5Gravity,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    runtime_payload = true,
);

const G: [f64; 3] = [0.3, -1.2, -9.81];

fn load(rel: &str) -> Chain {
    kanegen::io::load_model(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

fn flat<const N: usize>(a: [[f64; N]; N]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

fn flat_v(a: Vec<Vec<f64>>) -> Vec<f64> {
    a.into_iter().flatten().collect()
}

/// Random `(q, qd, tau, qdd)`.
fn state<const N: usize>(seed: u64) -> [[f64; N]; 4] {
    let mut r = rng(seed);
    let mut v = |s| -> [f64; N] { random_vec(&mut r, N, s).try_into().unwrap() };
    [v(2.0), v(1.0), v(20.0), v(1.0)]
}

macro_rules! check_constant_model {
    ($t:ident, $n:literal, $file:literal) => {{
        let chain = load($file);
        let p = chain.params::<f64>();
        assert_eq!($t::N, $n);
        assert_eq!($t::JOINTS.len(), chain.dof());
        for seed in 0..20 {
            let [q, qd, tau, qdd] = state::<$n>(seed);
            let loads = Loads {
                tau: Some(tau.to_vec()),
                ..Loads::default()
            };
            for alg in Algorithm::ALL {
                let e = rel_err(&flat($t::mass_matrix(&q)), &flat_v(alg.mass_matrix(&p, &q)));
                assert!(e < 1e-12, "{}: A vs {alg}: {e:e}", $file);
                let e = rel_err(&$t::bias(&q, &qd, &tau), &alg.bias(&p, &q, &qd, &loads));
                assert!(e < 1e-12, "{}: b vs {alg}: {e:e}", $file);
                let h = alg.bias(&p, &q, &qd, &Loads::default());
                let e = rel_err(&$t::bias_velocity(&q, &qd), &h);
                assert!(e < 1e-12, "{}: -h vs {alg}: {e:e}", $file);
                let id = alg.inverse_dynamics(&p, &q, &qd, &qdd, &loads);
                let e = rel_err(&$t::inverse_dynamics(&q, &qd, &qdd), &id);
                assert!(e < 1e-11, "{}: ID vs {alg}: {e:e}", $file);
                let fd = alg.forward_dynamics(&p, &q, &qd, &loads);
                let e = rel_err(&$t::forward_dynamics(&q, &qd, &tau), &fd);
                assert!(e < 1e-10, "{}: FD vs {alg}: {e:e}", $file);
            }
        }
    }};
}

#[test]
fn random_models_through_the_macro_equal_interpreted() {
    check_constant_model!(Random3, 3, "tests/data/codegen/random3_prismatic.toml");
    check_constant_model!(Random5, 5, "tests/data/codegen/random5.toml");
    // The op-count table lists every algorithm for every function and names the emitted one.
    assert_eq!(Random5::OP_COUNTS.len(), 5 * Algorithm::ALL.len());
    for (f, alg) in Random5::ALGORITHMS {
        let best = Random5::OP_COUNTS
            .iter()
            .filter(|r| r.0 == *f)
            .map(|r| r.2 + r.3)
            .min()
            .unwrap();
        let chosen = Random5::OP_COUNTS
            .iter()
            .find(|r| r.0 == *f && r.1 == *alg)
            .unwrap();
        assert_eq!(chosen.2 + chosen.3, best, "{f}");
    }
}

/// The chain with its last body's mass properties replaced.
fn with_payload(chain: &Chain, p: &Random5GravityPayload) -> Chain {
    let mut joints = chain.joints().to_vec();
    joints.last_mut().unwrap().inertial = Inertial {
        mass: p.mass,
        com: p.com,
        inertia: p.inertia,
    };
    Chain::new(
        chain.name(),
        chain.base(),
        chain.base_inertial().cloned(),
        joints,
    )
    .unwrap()
}

#[test]
fn runtime_payload_and_gravity_equal_interpreted_with_modified_chain() {
    let chain = load("tests/data/codegen/random5.toml");
    let nominal = Random5GravityPayload::NOMINAL;
    assert_eq!(nominal.mass, chain.joints()[4].inertial.mass);
    let heavy = Random5GravityPayload {
        mass: 42.0,
        com: [0.3, -0.2, 0.5],
        inertia: [[2.0, 0.1, -0.2], [0.1, 1.5, 0.05], [-0.2, 0.05, 1.8]],
    };
    for payload in [nominal, heavy] {
        let modified = with_payload(&chain, &payload);
        let p = modified.params::<f64>();
        let g = Some(kanegen::linalg::Vec3(G));
        for seed in 0..10 {
            let [q, qd, tau, qdd] = state::<5>(100 + seed);
            let loads = Loads {
                tau: Some(tau.to_vec()),
                gravity: g.clone(),
                external: Vec::new(),
            };
            let alg = Algorithm::Recurrent;
            let e = rel_err(
                &flat(Random5Gravity::mass_matrix(&q, &payload)),
                &flat_v(alg.mass_matrix(&p, &q)),
            );
            assert!(e < 1e-12, "A: {e:e}");
            let e = rel_err(
                &Random5Gravity::bias(&q, &qd, &tau, &payload),
                &alg.bias(&p, &q, &qd, &loads),
            );
            assert!(e < 1e-12, "b: {e:e}");
            let grav = Loads {
                gravity: g.clone(),
                ..Loads::default()
            };
            let e = rel_err(
                &Random5Gravity::gravity(&q, &payload),
                &alg.bias(&p, &q, &[0.0; 5], &grav),
            );
            assert!(e < 1e-12, "gravity: {e:e}");
            let e = rel_err(
                &Random5Gravity::bias_velocity(&q, &qd, &payload),
                &alg.bias(&p, &q, &qd, &Loads::default()),
            );
            assert!(e < 1e-12, "-h: {e:e}");
            let e = rel_err(
                &Random5Gravity::inverse_dynamics(&q, &qd, &qdd, &payload),
                &alg.inverse_dynamics(&p, &q, &qd, &qdd, &loads),
            );
            assert!(e < 1e-11, "ID: {e:e}");
            let e = rel_err(
                &Random5Gravity::forward_dynamics(&q, &qd, &tau, &payload),
                &alg.forward_dynamics(&p, &q, &qd, &loads),
            );
            assert!(e < 1e-10, "FD: {e:e}");
        }
    }
    // The payload matters: a heavier payload changes A.
    let q = [0.1, 0.2, 0.3, 0.1, 0.5];
    assert_ne!(
        Random5Gravity::mass_matrix(&q, &nominal),
        Random5Gravity::mass_matrix(&q, &heavy)
    );
}
