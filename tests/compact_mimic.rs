//! The compact form of a model with mimic joints (`kanegen_runtime::compact::coupled`: the
//! state expanded to the full joint list, the full kernels, the results reduced, forward
//! dynamics by LDLᵀ of the reduced `M`) against the unrolled form, traced in the independent
//! coordinates: Panda, whose second finger follows the first, fixed and free-floating, every
//! function, 1e-12 relative.

use kanegen::dynamics::metrics::rel_err;
use kanegen::model::random::{random_vec, rng};

kanegen::dynamics!(
    PandaC,
    "tests/data/erd_all/panda.urdf",
    form = "compact",
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    PandaU,
    "tests/data/erd_all/panda.urdf",
    form = "unrolled",
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    PandaFreeC,
    "tests/data/erd_all/panda.urdf",
    base = "free-floating",
    form = "compact",
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    PandaFreeU,
    "tests/data/erd_all/panda.urdf",
    base = "free-floating",
    form = "unrolled",
    gravity = [0.3, -1.2, -9.81]
);

const TOL: f64 = 1e-12;

fn arr<const K: usize>(v: Vec<f64>) -> [f64; K] {
    core::array::from_fn(|i| v[i])
}

fn flat<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

fn placement((x, r): ([f64; 3], [[f64; 3]; 3])) -> Vec<f64> {
    x.into_iter().chain(r.into_iter().flatten()).collect()
}

/// The compact result `x` against the unrolled `y`, relative; returns the error.
fn close(what: &str, x: &[f64], y: &[f64]) -> f64 {
    let e = rel_err(x, y);
    assert!(e <= TOL, "{what}: relative error {e:e}\n{x:?}\n{y:?}");
    e
}

#[test]
fn the_arguments_are_the_independent_coordinates() {
    assert_eq!((PandaC::N, PandaFreeC::N, PandaFreeC::NV), (8, 8, 14));
    assert_eq!(PandaC::JOINTS, PandaU::JOINTS);
}

#[test]
fn compact_fixed_base_equals_unrolled() {
    let mut worst = 0.0_f64;
    for seed in 0..10 {
        let mut r = rng(seed);
        let q: [f64; 8] = arr(random_vec(&mut r, 8, 2.0));
        let qd: [f64; 8] = arr(random_vec(&mut r, 8, 1.0));
        let qdd: [f64; 8] = arr(random_vec(&mut r, 8, 1.0));
        let tau: [f64; 8] = arr(random_vec(&mut r, 8, 20.0));
        // One wrench per body of the full tree (9 joints).
        let f_ext: [[f64; 6]; 9] = core::array::from_fn(|_| arr(random_vec(&mut r, 6, 3.0)));
        let mut each = |what: &str, x: &[f64], y: &[f64]| worst = worst.max(close(what, x, y));
        each(
            "M",
            &flat(&PandaC::mass_matrix(&q)),
            &flat(&PandaU::mass_matrix(&q)),
        );
        each(
            "c",
            &PandaC::nonlinear_effects(&q, &qd),
            &PandaU::nonlinear_effects(&q, &qd),
        );
        each("g", &PandaC::gravity(&q), &PandaU::gravity(&q));
        each(
            "ID",
            &PandaC::inverse_dynamics(&q, &qd, &qdd),
            &PandaU::inverse_dynamics(&q, &qd, &qdd),
        );
        let (mc, cc) = PandaC::mass_matrix_and_nonlinear_effects(&q, &qd);
        let (mu, cu) = PandaU::mass_matrix_and_nonlinear_effects(&q, &qd);
        each(
            "(M, c)",
            &[flat(&mc), cc.to_vec()].concat(),
            &[flat(&mu), cu.to_vec()].concat(),
        );
        each(
            "FD",
            &PandaC::forward_dynamics(&q, &qd, &tau),
            &PandaU::forward_dynamics(&q, &qd, &tau),
        );
        each(
            "FD with wrenches",
            &PandaC::forward_dynamics_with_wrenches(&q, &qd, &tau, &f_ext),
            &PandaU::forward_dynamics_with_wrenches(&q, &qd, &tau, &f_ext),
        );
        each(
            "hand TCP placement",
            &placement(PandaC::panda_hand_tcp_placement(&q)),
            &placement(PandaU::panda_hand_tcp_placement(&q)),
        );
        each(
            "hand TCP Jacobian",
            &flat(&PandaC::panda_hand_tcp_jacobian(&q)),
            &flat(&PandaU::panda_hand_tcp_jacobian(&q)),
        );
        let (cq, cv) = PandaC::inverse_dynamics_derivatives(&q, &qd, &qdd);
        let (uq, uv) = PandaU::inverse_dynamics_derivatives(&q, &qd, &qdd);
        each(
            "∂τ",
            &[flat(&cq), flat(&cv)].concat(),
            &[flat(&uq), flat(&uv)].concat(),
        );
        let (cq, cv, ci) = PandaC::forward_dynamics_derivatives(&q, &qd, &tau);
        let (uq, uv, ui) = PandaU::forward_dynamics_derivatives(&q, &qd, &tau);
        each(
            "∂q̈",
            &[flat(&cq), flat(&cv), flat(&ci)].concat(),
            &[flat(&uq), flat(&uv), flat(&ui)].concat(),
        );
        each(
            "M⁻¹",
            &flat(&PandaC::mass_matrix_inverse(&q)),
            &flat(&PandaU::mass_matrix_inverse(&q)),
        );
    }
    println!("fixed base: largest relative error {worst:e}");
}

#[test]
fn compact_free_floating_equals_unrolled() {
    let mut worst = 0.0_f64;
    for seed in 0..10 {
        let mut r = rng(100 + seed);
        let w = random_vec(&mut r, 4, 1.0);
        let norm = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        let qj = random_vec(&mut r, 8, 2.0);
        let q: [f64; 15] = arr([0.2, -0.1, 0.4]
            .into_iter()
            .chain(w.iter().map(|x| x / norm))
            .chain(qj)
            .collect());
        let v: [f64; 14] = arr(random_vec(&mut r, 14, 1.0));
        let a: [f64; 14] = arr(random_vec(&mut r, 14, 1.0));
        let tau: [f64; 8] = arr(random_vec(&mut r, 8, 20.0));
        // The base's wrench, then one per body of the full tree (9 joints).
        let f_ext: [[f64; 6]; 10] = core::array::from_fn(|_| arr(random_vec(&mut r, 6, 3.0)));
        let mut each = |what: &str, x: &[f64], y: &[f64]| worst = worst.max(close(what, x, y));
        each(
            "M",
            &flat(&PandaFreeC::mass_matrix(&q)),
            &flat(&PandaFreeU::mass_matrix(&q)),
        );
        each(
            "c",
            &PandaFreeC::nonlinear_effects(&q, &v),
            &PandaFreeU::nonlinear_effects(&q, &v),
        );
        each("g", &PandaFreeC::gravity(&q), &PandaFreeU::gravity(&q));
        each(
            "ID",
            &PandaFreeC::inverse_dynamics(&q, &v, &a),
            &PandaFreeU::inverse_dynamics(&q, &v, &a),
        );
        let (mc, cc) = PandaFreeC::mass_matrix_and_nonlinear_effects(&q, &v);
        let (mu, cu) = PandaFreeU::mass_matrix_and_nonlinear_effects(&q, &v);
        each(
            "(M, c)",
            &[flat(&mc), cc.to_vec()].concat(),
            &[flat(&mu), cu.to_vec()].concat(),
        );
        each(
            "FD",
            &PandaFreeC::forward_dynamics(&q, &v, &tau),
            &PandaFreeU::forward_dynamics(&q, &v, &tau),
        );
        each(
            "FD with wrenches",
            &PandaFreeC::forward_dynamics_with_wrenches(&q, &v, &tau, &f_ext),
            &PandaFreeU::forward_dynamics_with_wrenches(&q, &v, &tau, &f_ext),
        );
        each(
            "momentum",
            &PandaFreeC::momentum(&q, &v),
            &PandaFreeU::momentum(&q, &v),
        );
        each(
            "base reaction",
            &PandaFreeC::base_reaction(&q, &v, &a),
            &PandaFreeU::base_reaction(&q, &v, &a),
        );
        each(
            "hand TCP placement",
            &placement(PandaFreeC::panda_hand_tcp_placement(&q)),
            &placement(PandaFreeU::panda_hand_tcp_placement(&q)),
        );
        each(
            "hand TCP Jacobian",
            &flat(&PandaFreeC::panda_hand_tcp_jacobian(&q)),
            &flat(&PandaFreeU::panda_hand_tcp_jacobian(&q)),
        );
        each(
            "hand TCP generalized Jacobian",
            &flat(&PandaFreeC::panda_hand_tcp_generalized_jacobian(&q)),
            &flat(&PandaFreeU::panda_hand_tcp_generalized_jacobian(&q)),
        );
        let (cq, cv) = PandaFreeC::inverse_dynamics_derivatives(&q, &v, &a);
        let (uq, uv) = PandaFreeU::inverse_dynamics_derivatives(&q, &v, &a);
        each(
            "∂τ",
            &[flat(&cq), flat(&cv)].concat(),
            &[flat(&uq), flat(&uv)].concat(),
        );
        let (cq, cv, ci) = PandaFreeC::forward_dynamics_derivatives(&q, &v, &tau);
        let (uq, uv, ui) = PandaFreeU::forward_dynamics_derivatives(&q, &v, &tau);
        each(
            "∂ν̇",
            &[flat(&cq), flat(&cv), flat(&ci)].concat(),
            &[flat(&uq), flat(&uv), flat(&ui)].concat(),
        );
        each(
            "M⁻¹",
            &flat(&PandaFreeC::mass_matrix_inverse(&q)),
            &flat(&PandaFreeU::mass_matrix_inverse(&q)),
        );
    }
    println!("free-floating: largest relative error {worst:e}");
}
