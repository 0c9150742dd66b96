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
    base = "free-floating",
    derivatives = false
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

/// `kanegen count` counts in the coordinates (`n` = 8), derivatives included.
#[test]
fn count_takes_the_independent_coordinates() {
    let out = common::kanegen(&["count", "tests/data/erd_all/panda.urdf", "--json"]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["n"], 8);
    let mut functions: Vec<&str> = v["derivatives"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["function"].as_str().unwrap())
        .collect();
    functions.dedup();
    assert_eq!(
        functions,
        [
            "inverse_dynamics_derivatives",
            "forward_dynamics_derivatives",
            "mass_matrix_inverse"
        ]
    );
    assert!(!v["counts"].as_array().unwrap().is_empty());
}

/// `Gᵀ D G` of a full `(offset + 9)²` matrix (row-major) of Panda: the second finger's row and
/// column added to the first's.
fn reduce_matrix(d: &[f64], offset: usize) -> Vec<Vec<f64>> {
    let (nf, n) = (offset + 9, offset + 8);
    let mut r = vec![vec![0.0; n]; n];
    for (i, row) in d.chunks(nf).enumerate() {
        for (j, x) in row.iter().enumerate() {
            r[i.min(n - 1)][j.min(n - 1)] += x;
        }
    }
    r
}

/// `A B` of square matrices.
fn product(a: &[Vec<f64>], b: &[Vec<f64>]) -> Vec<Vec<f64>> {
    a.iter()
        .map(|row| {
            (0..b[0].len())
                .map(|j| row.iter().zip(b).map(|(x, br)| x * br[j]).sum())
                .collect()
        })
        .collect()
}

fn rows<const K: usize>(m: &[[f64; K]]) -> Vec<Vec<f64>> {
    m.iter().map(|r| r.to_vec()).collect()
}

fn flat(m: &[Vec<f64>]) -> Vec<f64> {
    m.concat()
}

/// The generated derivatives in the coordinates, fixed base with gravity: `∂τ/∂x = Gᵀ D_full G`
/// against the full model's (checked against Pinocchio and dual numbers in
/// `tests/derivatives.rs`) reduced by hand; `M⁻¹ M = I`; `∂q̈/∂x = −M⁻¹ ∂τ/∂x` at
/// `q̈ = FD(q, q̇, τ)`; and `∂q̈/∂q`, `∂q̈/∂q̇` against central differences of
/// `forward_dynamics` (step 1e-5: truncation about 1e-10 of the entries, rounding about 1e-11).
#[test]
fn derivatives_in_the_coordinates_equal_the_full_model_reduced() {
    let mut worst = [0.0_f64; 4];
    for k in 0..4 {
        let t = f64::from(k);
        let q: [f64; 8] = core::array::from_fn(|i| (0.3 * t + 1.1 * i as f64).sin());
        let qd: [f64; 8] = core::array::from_fn(|i| (0.6 * t - 0.7 * i as f64).cos());
        let qdd: [f64; 8] = core::array::from_fn(|i| (0.9 * t + 0.4 * i as f64).sin());
        let (dq, dv) = Panda::inverse_dynamics_derivatives(&q, &qd, &qdd);
        let (dqf, dvf) =
            PandaFull::inverse_dynamics_derivatives(&full(&q), &full(&qd), &full(&qdd));
        let e = rel_err(
            dq.as_flattened(),
            &flat(&reduce_matrix(dqf.as_flattened(), 0)),
        )
        .max(rel_err(
            dv.as_flattened(),
            &flat(&reduce_matrix(dvf.as_flattened(), 0)),
        ));
        assert!(e < 1e-12, "∂τ against the full model reduced: {e:e}");
        worst[0] = worst[0].max(e);

        let tau = Panda::inverse_dynamics(&q, &qd, &qdd);
        let (aq, av, minv) = Panda::forward_dynamics_derivatives(&q, &qd, &tau);
        let identity: Vec<Vec<f64>> = (0..8)
            .map(|i| (0..8).map(|j| f64::from(u8::from(i == j))).collect())
            .collect();
        let e = rel_err(
            &flat(&product(&rows(&minv), &rows(&Panda::mass_matrix(&q)))),
            &flat(&identity),
        );
        assert!(e < 1e-11, "M⁻¹ M = I: {e:e}");
        worst[1] = worst[1].max(e);
        let neg = |m: Vec<Vec<f64>>| -> Vec<f64> { m.concat().iter().map(|x| -x).collect() };
        let e = rel_err(aq.as_flattened(), &neg(product(&rows(&minv), &rows(&dq)))).max(rel_err(
            av.as_flattened(),
            &neg(product(&rows(&minv), &rows(&dv))),
        ));
        assert!(e < 1e-11, "∂q̈/∂x = −M⁻¹ ∂τ/∂x: {e:e}");
        worst[2] = worst[2].max(e);

        let h = 1e-5;
        let column = |x: &[f64; 8], j: usize, at: &dyn Fn(&[f64; 8]) -> [f64; 8]| -> Vec<f64> {
            let (mut up, mut down) = (*x, *x);
            up[j] += h;
            down[j] -= h;
            let (u, d) = (at(&up), at(&down));
            u.iter().zip(&d).map(|(u, d)| (u - d) / (2.0 * h)).collect()
        };
        for j in 0..8 {
            let by_q = column(&q, j, &|q| Panda::forward_dynamics(q, &qd, &tau));
            let by_v = column(&qd, j, &|qd| Panda::forward_dynamics(&q, qd, &tau));
            let col = |m: &[[f64; 8]; 8]| -> Vec<f64> { m.iter().map(|r| r[j]).collect() };
            let scale = aq
                .as_flattened()
                .iter()
                .chain(av.as_flattened())
                .fold(0.0_f64, |m, x| m.max(x.abs()));
            let e = by_q
                .iter()
                .zip(col(&aq))
                .chain(by_v.iter().zip(col(&av)))
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
                / scale;
            assert!(e < 1e-7, "central differences, column {j}: {e:e}");
            worst[3] = worst[3].max(e);
        }
    }
    eprintln!(
        "worst: ∂τ vs full reduced {:e}, M⁻¹ M − I {:e}, ∂q̈ vs −M⁻¹ ∂τ {:e}, vs central differences {:e}",
        worst[0], worst[1], worst[2], worst[3]
    );
}

/// The traced derivatives on a free-floating base (tangent space, base speeds first and kept):
/// `∂τ/∂x` against the full model's traced derivatives reduced by hand, and the forward-dynamics
/// derivatives and `M⁻¹` against `−M⁻¹ ∂τ/∂x` and `M⁻¹ M = I` with the traced reduced `M`.
#[test]
fn free_floating_derivatives_in_the_coordinates() {
    use kanegen::dynamics::Methods;
    use kanegen::model::BaseKind;
    use kanegen::trace::{trace, Base, Function, Spec, Subject};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/erd_all/panda.urdf");
    let model = kanegen::model::io::load_model(&path)
        .unwrap()
        .with_base_kind(BaseKind::FreeFloating)
        .unwrap();
    let full_model = model.clone().without_mimics();
    let spec = Spec {
        base: Base::FreeFloating(model.base_inertial().unwrap().clone()),
        ..Spec::default()
    };
    let eval = |m: &kanegen::model::Model, f: Function, inputs: &[f64]| -> Vec<f64> {
        trace(Subject::Model(m), f, Methods::SPATIAL, &spec)
            .unwrap()
            .trace
            .eval(inputs)
    };
    let base_q = [0.1, -0.2, 0.3, 0.2, -0.1, 0.3, (1.0_f64 - 0.14).sqrt()];
    let q: Vec<f64> = (0..8).map(|i| (1.1 * f64::from(i)).sin()).collect();
    let v: Vec<f64> = (0..14).map(|i| (0.7 * f64::from(i)).cos()).collect();
    let a: Vec<f64> = (0..14).map(|i| (0.4 * f64::from(i)).sin()).collect();
    // G x: the second finger (last) follows the first (the last coordinate).
    let expand = |x: &[f64]| -> Vec<f64> { [x, &x[x.len() - 1..]].concat() };
    let (qf, vf, af) = ([&base_q[..], &expand(&q)].concat(), expand(&v), expand(&a));
    let id = eval(
        &model,
        Function::InverseDynamicsDerivatives,
        &[&base_q[..], &q, &v, &a].concat(),
    );
    let idf = eval(
        &full_model,
        Function::InverseDynamicsDerivatives,
        &[&qf[..], &vf, &af].concat(),
    );
    let (dq, dv) = id.split_at(14 * 14);
    let (dqf, dvf) = idf.split_at(15 * 15);
    let e =
        rel_err(dq, &flat(&reduce_matrix(dqf, 6))).max(rel_err(dv, &flat(&reduce_matrix(dvf, 6))));
    assert!(
        e < 1e-12,
        "free-floating ∂τ against the full model reduced: {e:e}"
    );

    // τ = ID(q, v, a) has the base's wrench first; forward dynamics takes the joints' drives with
    // an unactuated base, so drive it at the accelerations FD returns at these drives.
    let tau = &eval(
        &model,
        Function::InverseDynamics,
        &[&base_q[..], &q, &v, &a].concat(),
    )[6..];
    let fd = eval(
        &model,
        Function::ForwardDynamicsDerivatives,
        &[&base_q[..], &q, &v, tau].concat(),
    );
    let square = |x: &[f64]| -> Vec<Vec<f64>> { x.chunks(14).map(<[f64]>::to_vec).collect() };
    let (aq, rest) = fd.split_at(14 * 14);
    let (av, minv) = rest.split_at(14 * 14);
    let nu_dot = eval(
        &model,
        Function::ForwardDynamics,
        &[&base_q[..], &q, &v, tau].concat(),
    );
    let at = eval(
        &model,
        Function::InverseDynamicsDerivatives,
        &[&base_q[..], &q, &v, &nu_dot].concat(),
    );
    let (dq, dv) = at.split_at(14 * 14);
    let neg = |m: Vec<Vec<f64>>| -> Vec<f64> { m.concat().iter().map(|x| -x).collect() };
    let e = rel_err(aq, &neg(product(&square(minv), &square(dq))))
        .max(rel_err(av, &neg(product(&square(minv), &square(dv)))));
    assert!(e < 1e-11, "free-floating ∂ν̇/∂x = −M⁻¹ ∂τ/∂x: {e:e}");
    let upper = eval(
        &model,
        Function::MassMatrix,
        &base_q.iter().chain(&q).copied().collect::<Vec<_>>(),
    );
    let mut m = vec![vec![0.0; 14]; 14];
    let upper_pairs = (0..14).flat_map(|i| (i..14).map(move |j| (i, j)));
    for ((i, j), &value) in upper_pairs.zip(&upper) {
        (m[i][j], m[j][i]) = (value, value);
    }
    let identity: Vec<Vec<f64>> = (0..14)
        .map(|i| (0..14).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    let e = rel_err(&flat(&product(&square(minv), &m)), &flat(&identity));
    assert!(e < 1e-11, "free-floating M⁻¹ M = I: {e:e}");
    let upper_inv = eval(
        &model,
        Function::MassMatrixInverse,
        &base_q.iter().chain(&q).copied().collect::<Vec<_>>(),
    );
    let mut k = 0;
    let mut e = 0.0_f64;
    for i in 0..14 {
        for j in i..14 {
            e = e.max((upper_inv[k] - minv[i * 14 + j]).abs());
            k += 1;
        }
    }
    assert!(
        e < 1e-12,
        "mass_matrix_inverse against forward_dynamics_derivatives' M⁻¹: {e:e}"
    );
}

/// Damping per independent coordinate, traced in the coordinates: `c` with damping `d` is `c`
/// without it plus `d ∘ q̇` (the coordinate of the coupled fingers included), and `kanegen count`
/// counts a mimic scene with damping.
#[test]
fn damping_in_the_coordinates_is_traced() {
    use kanegen::trace::{trace, Function, Spec, Subject};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/erd_all/panda.urdf");
    let model = kanegen::model::io::load_model(&path).unwrap();
    let d: Vec<f64> = (0..8).map(|k| 0.1 + 0.3 * k as f64).collect();
    let c_of = |damping: Option<Vec<f64>>| {
        let spec = Spec {
            gravity: Some([0.0, 0.0, -9.81]),
            damping,
            ..Spec::default()
        };
        let f = Function::NonlinearEffects;
        let methods = kanegen::dynamics::Methods::SPATIAL;
        trace(Subject::Model(&model), f, methods, &spec).unwrap()
    };
    let (plain, damped) = (c_of(None), c_of(Some(d.clone())));
    let x: Vec<f64> = (0..16).map(|i| 0.3 * (i as f64 * 0.7).sin()).collect();
    let (c0, c1) = (plain.trace.eval(&x), damped.trace.eval(&x));
    let worst = (0..8).fold(0.0_f64, |m, k| {
        m.max((c1[k] - c0[k] - d[k] * x[8 + k]).abs())
    });
    assert!(worst < 1e-12, "{worst:e}");
    let short = Spec {
        damping: Some(vec![0.5; 9]),
        ..Spec::default()
    };
    let spatial = kanegen::dynamics::Methods::SPATIAL;
    let err = trace(
        Subject::Model(&model),
        Function::NonlinearEffects,
        spatial,
        &short,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("damping has 9 entries for 8 coordinates"),
        "{err}"
    );
    let out = common::kanegen(&["count", "tests/data/scenes/panda_mimic_pd.toml"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
