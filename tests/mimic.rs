//! Generated code for a model with mimic joints, in its independent coordinates
//! (`kanegen_dynamics::mimic`; traced as `kanegen_trace`'s coupled functions): Panda, whose
//! second finger follows the first (`q_f2 = q_f1`), fixed and free-floating, against Pinocchio
//! 4.1 with `mimic=True` (`tests/data/erd_all/panda.json`, `tools/reference/erd_all.py`), and its
//! forward dynamics, inverse dynamics and frames against the same URDF generated with every
//! joint independent (`ignore_mimic = true`) and reduced by the coupling `G` by hand.

mod common;

use common::nums;
use kanegen::dynamics::metrics::rel_err;
use serde_json::Value;
use std::path::Path;

kanegen::dynamics!(
    Panda,
    "tests/data/erd_all/panda.urdf",
    gravity = [0.0, 0.0, -9.81]
);
kanegen::dynamics!(
    PandaFree,
    "tests/data/erd_all/panda.urdf",
    base = "free-floating"
);
kanegen::dynamics!(
    PandaFull,
    "tests/data/erd_all/panda.urdf",
    ignore_mimic = true,
    gravity = [0.0, 0.0, -9.81]
);

fn reference() -> Value {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/erd_all/panda.json");
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn arr<const K: usize>(v: &[f64]) -> [f64; K] {
    v.try_into().unwrap()
}

/// `x_full = G x` of Panda (`o = 0`, multiplier 1): the second finger (the last joint) follows
/// the first.
fn full(x: &[f64; 8]) -> [f64; 9] {
    core::array::from_fn(|j| x[j.min(7)])
}

/// The types name the independent coordinates, Pinocchio's `mimic=True` joints, in its order.
#[test]
fn joints_are_the_independent_coordinates() {
    let r = reference();
    let names: Vec<&str> = r["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    assert_eq!(Panda::JOINTS.as_slice(), names.as_slice());
    assert_eq!((Panda::N, PandaFull::N, PandaFree::NV), (8, 9, 14));
    assert_eq!(Panda::UPPER_POSITION_LIMIT[7], 0.04);
}

/// `M` and `c` against Pinocchio 4.1 (`mimic=True`) at its random states, fixed base with
/// gravity and free-flyer (the reference's without gravity), to 1e-9 relative.
#[test]
fn mass_matrix_and_nonlinear_effects_match_pinocchio() {
    let r = reference();
    let mut worst = 0.0_f64;
    for s in r["fixed"]["states"].as_array().unwrap() {
        let (q, qd) = (arr::<8>(&nums(&s["q"])), arr::<8>(&nums(&s["qd"])));
        let (m, c) = Panda::mass_matrix_and_nonlinear_effects(&q, &qd);
        let minus_b: Vec<f64> = nums(&s["b"]).iter().map(|x| -x).collect();
        let e = rel_err(m.as_flattened(), &nums(&s["A"])).max(rel_err(&c, &minus_b));
        assert!(e < 1e-9, "fixed: {e:e}");
        worst = worst.max(e);
    }
    for s in r["free_flyer"]["states"].as_array().unwrap() {
        let b = &s["base"];
        let q: [f64; 15] =
            arr(&[nums(&b["position"]), nums(&b["quaternion"]), nums(&s["q"])].concat());
        let v: [f64; 14] = arr(&[nums(&b["v"]), nums(&b["omega"]), nums(&s["qd"])].concat());
        let (m, c) = PandaFree::mass_matrix_and_nonlinear_effects(&q, &v);
        let minus_b: Vec<f64> = nums(&s["b"]).iter().map(|x| -x).collect();
        let e = rel_err(m.as_flattened(), &nums(&s["A"])).max(rel_err(&c, &minus_b));
        assert!(e < 1e-9, "free-flyer: {e:e}");
        worst = worst.max(e);
    }
    eprintln!("worst against Pinocchio mimic=True: {worst:e}");
}

/// Forward and inverse dynamics, `g`, and the frames in the coordinates, against the model with
/// every joint independent: `τ = Gᵀ τ_full(G q + o, G q̇, G q̈)`, `g = Gᵀ g_full`,
/// `J = J_full G`, the placement at `G q + o`; and `M q̈ + c = τ` for the forward dynamics.
#[test]
fn functions_in_the_coordinates_equal_the_full_model_reduced() {
    let mut worst = 0.0_f64;
    let mut check = |what: &str, got: &[f64], want: &[f64]| {
        let e = rel_err(got, want);
        assert!(e < 1e-12, "{what}: {e:e}");
        worst = worst.max(e);
    };
    // Gᵀ x of a full vector: the fingers' entries summed.
    let reduce = |x: &[f64]| -> Vec<f64> {
        let mut r = x[..8].to_vec();
        r[7] += x[8];
        r
    };
    for k in 0..5 {
        let t = f64::from(k);
        let q: [f64; 8] = core::array::from_fn(|i| (0.7 * t + 1.3 * i as f64).sin());
        let qd: [f64; 8] = core::array::from_fn(|i| (0.4 * t - 0.9 * i as f64).cos());
        let qdd: [f64; 8] = core::array::from_fn(|i| (1.1 * t + 0.5 * i as f64).sin());
        let (qf, qdf, qddf) = (full(&q), full(&qd), full(&qdd));
        let tau = Panda::inverse_dynamics(&q, &qd, &qdd);
        check(
            "inverse dynamics",
            &tau,
            &reduce(&PandaFull::inverse_dynamics(&qf, &qdf, &qddf)),
        );
        check(
            "gravity",
            &Panda::gravity(&q),
            &reduce(&PandaFull::gravity(&qf)),
        );
        let a = Panda::forward_dynamics(&q, &qd, &tau);
        check("forward dynamics", &a, &qdd);
        let j = Panda::panda_hand_tcp_jacobian(&q);
        let jf = PandaFull::panda_hand_tcp_jacobian(&qf);
        for (row, rf) in j.iter().zip(&jf) {
            check("Jacobian", row, &reduce(rf));
        }
        let (x, r) = Panda::panda_hand_tcp_placement(&q);
        let (xf, rf) = PandaFull::panda_hand_tcp_placement(&qf);
        check(
            "placement",
            &[x.as_slice(), r.as_flattened()].concat(),
            &[xf.as_slice(), rf.as_flattened()].concat(),
        );
    }
    eprintln!("worst coordinates vs full model reduced: {worst:e}");
}

/// `kanegen count` counts in the coordinates (`n` = 8) and lists no derivatives for a model with
/// mimic joints (they are not traced in its coordinates), where it used to stop at them.
#[test]
fn count_takes_the_independent_coordinates() {
    let out = common::kanegen(&["count", "tests/data/erd_all/panda.urdf", "--json"]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["n"], 8);
    assert!(v.get("derivatives").is_none());
    assert!(!v["counts"].as_array().unwrap().is_empty());
}
