//! Generated inverse dynamics is one O(N) Newton–Euler pass: its emitted operation count grows
//! linearly in N, where the mass matrix grows quadratically.

use kanegen_codegen::choose::choose;
use kanegen_codegen::Options;
use kanegen_dynamics::{MassMatrixMethod, Methods};
use kanegen_model::random::{random_chain, ChainSpec};
use kanegen_trace::{trace, Convention, Function, Spec, Subject};

/// `mul + add` of the code emitted for `f` on a random chain with general geometry.
fn emitted(f: Function, n: usize) -> u64 {
    let model = random_chain(
        &ChainSpec {
            n,
            ..Default::default()
        },
        n as u64,
    );
    let (choice, _) = choose(&model, f, MassMatrixMethod::Crba, &Options::new("Arm")).unwrap();
    choice.counts().total()
}

#[test]
fn generated_inverse_dynamics_grows_linearly_from_8_to_32() {
    let ns = [8, 16, 24, 32];
    let id: Vec<u64> = ns
        .iter()
        .map(|&n| emitted(Function::InverseDynamics, n))
        .collect();
    let m: Vec<u64> = ns
        .iter()
        .map(|&n| emitted(Function::MassMatrix, n))
        .collect();
    eprintln!("N {ns:?}: inverse dynamics {id:?}, mass matrix {m:?}");
    // Equal steps of 8 joints add about the same: the per-joint cost stays put (within 5 %).
    let steps: Vec<f64> = id.windows(2).map(|w| (w[1] - w[0]) as f64).collect();
    for s in &steps {
        assert!((s / steps[0] - 1.0).abs() < 0.05, "steps {steps:?}");
    }
    // The mass matrix's cost per joint grows (quadratic): at least 10 % more per joint with every
    // 8 joints (1286, 4974, 10914, 16782 from N = 8 to 32: 161, 311, 455, 524 per joint; its
    // steps are not monotone, as the cheapest method changes from the local CRBA to `crba-inertial`
    // at N = 24).
    let per_joint: Vec<f64> = m
        .iter()
        .zip(ns)
        .map(|(&m, n)| m as f64 / n as f64)
        .collect();
    assert!(
        per_joint.windows(2).all(|w| w[1] > 1.1 * w[0]),
        "M per joint {per_joint:?}"
    );
}

/// With every parameter symbolic (no model's zeros), each joint adds exactly the same
/// operations: the count is an exact affine function of N.
#[test]
fn symbolic_inverse_dynamics_is_exactly_affine_in_n() {
    let count = |n| {
        trace(
            Subject::Generic { n },
            Function::InverseDynamics,
            Methods::SPATIAL,
            &Spec::default(),
        )
        .unwrap()
        .trace
        .counts(Convention::Emitted)
        .total()
    };
    let c: Vec<u64> = (8..=12).map(count).collect();
    let d: Vec<u64> = c.windows(2).map(|w| w[1] - w[0]).collect();
    eprintln!("symbolic ID, N = 8..12: {c:?}, per joint {d:?}");
    assert!(d.windows(2).all(|w| w[0] == w[1]), "{d:?}");
}
