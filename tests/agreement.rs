//! The five algorithms agree on A and b to 1e-12 relative (max |x − y| / max |y|) on random chains
//! N = 1..32 with prismatic joints, external loads in both frames, joint drives and gravity; and
//! forward / inverse dynamics are consistent.

use kanegen::dynamics::linalg::Vec3;
use kanegen::dynamics::metrics::{flatten as flat, rel_err};
use kanegen::dynamics::Params;
use kanegen::dynamics::{ExternalWrench, LoadFrame, Loads, Methods};
use kanegen::model::random::{random_chain, random_vec, rng, ChainSpec};
use proptest::prelude::*;

fn random_loads(n: usize, seed: u64, with_gravity: bool) -> Loads<f64> {
    let mut r = rng(seed ^ 0x5eed);
    let mut external = Vec::new();
    for body in 0..n {
        if body % 3 == seed as usize % 3 {
            let v = random_vec(&mut r, 6, 50.0);
            external.push(ExternalWrench {
                body,
                frame: if body % 2 == 0 {
                    LoadFrame::Body
                } else {
                    LoadFrame::Base
                },
                force: Vec3([v[0], v[1], v[2]]),
                moment: Vec3([v[3], v[4], v[5]]),
            });
        }
    }
    Loads {
        tau: Some(random_vec(&mut r, n, 20.0)),
        gravity: with_gravity.then(|| Vec3([0.3, -1.2, -9.81])),
        external,
    }
}

fn check(n: usize, seed: u64, prismatic: f64, with_gravity: bool) -> Result<(), TestCaseError> {
    let chain = random_chain(
        &ChainSpec {
            n,
            prismatic_fraction: prismatic,
            ..Default::default()
        },
        seed,
    );
    let p = Params::<f64>::new(&chain);
    let mut r = rng(seed);
    let q = random_vec(&mut r, n, 3.0);
    let qd = random_vec(&mut r, n, 2.0);
    let loads = random_loads(n, seed, with_gravity);
    let reference = Methods::SPATIAL.dynamics(&p, &q, &qd, &loads);
    for alg in Methods::ALL {
        let d = alg.dynamics(&p, &q, &qd, &loads);
        let ea = rel_err(&flat(&d.mass_matrix), &flat(&reference.mass_matrix));
        let eb = rel_err(&d.tau_minus_c, &reference.tau_minus_c);
        prop_assert!(
            ea < 1e-12,
            "{alg} vs spatial: A rel. error {ea:.3e} (N = {n}, seed {seed})"
        );
        prop_assert!(
            eb < 1e-12,
            "{alg} vs spatial: b rel. error {eb:.3e} (N = {n}, seed {seed})"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn all_algorithms_agree(n in 1usize..=32, seed in any::<u64>(), prismatic in 0.0f64..0.5, g in any::<bool>()) {
        check(n, seed, prismatic, g)?;
    }

    #[test]
    fn forward_and_inverse_dynamics_are_consistent(n in 1usize..=16, seed in any::<u64>()) {
        let chain = random_chain(&ChainSpec { n, prismatic_fraction: 0.2, ..Default::default() }, seed);
        let p = Params::<f64>::new(&chain);
        let mut r = rng(seed);
        let q = random_vec(&mut r, n, 3.0);
        let qd = random_vec(&mut r, n, 2.0);
        let loads = random_loads(n, seed, true);
        let qdd = Methods::RECURRENT.forward_dynamics(&p, &q, &qd, &loads);
        let tau = Methods::SPATIAL.inverse_dynamics(&p, &q, &qd, &qdd, &loads);
        let e = rel_err(&tau, loads.tau.as_ref().unwrap());
        prop_assert!(e < 1e-8, "inverse(forward(τ)) ≠ τ: rel. error {e:.3e}");
    }
}

#[test]
fn every_small_chain_agrees() {
    // Deterministic sweep of the smallest chains, where index edge cases live (N = 1, 2, 3).
    for n in 1..=4 {
        for seed in 0..8 {
            check(
                n,
                seed,
                if seed % 2 == 0 { 0.0 } else { 0.5 },
                seed % 3 == 0,
            )
            .unwrap();
        }
    }
}

#[test]
fn algorithms_run_on_f32() {
    // The same source on f32: agreement with f64 to single-precision accuracy.
    for seed in 0..6 {
        let n = 7;
        let chain = random_chain(
            &ChainSpec {
                n,
                prismatic_fraction: 0.2,
                ..Default::default()
            },
            seed,
        );
        let mut r = rng(seed);
        let q = random_vec(&mut r, n, 3.0);
        let qd = random_vec(&mut r, n, 2.0);
        let p64 = Params::<f64>::new(&chain);
        let p32 = Params::<f32>::new(&chain);
        let q32: Vec<f32> = q.iter().map(|&x| x as f32).collect();
        let qd32: Vec<f32> = qd.iter().map(|&x| x as f32).collect();
        for alg in Methods::ALL {
            let d64 = alg.dynamics(&p64, &q, &qd, &Loads::default());
            let d32 = alg.dynamics(&p32, &q32, &qd32, &Loads::default());
            let a32: Vec<f64> = d32
                .mass_matrix
                .iter()
                .flatten()
                .map(|&x| x as f64)
                .collect();
            let b32: Vec<f64> = d32.tau_minus_c.iter().map(|&x| x as f64).collect();
            let (ea, eb) = (
                rel_err(&a32, &flat(&d64.mass_matrix)),
                rel_err(&b32, &d64.tau_minus_c),
            );
            assert!(ea < 1e-4 && eb < 1e-3, "{alg} f32: A {ea:.2e}, b {eb:.2e}");
        }
    }
}
