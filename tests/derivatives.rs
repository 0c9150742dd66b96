//! The generated derivative functions (`inverse_dynamics_derivatives`,
//! `forward_dynamics_derivatives`, `mass_matrix_inverse`) through `kanegen::dynamics!` equal the
//! interpreted algorithms of `kanegen::dynamics::algorithms::derivatives` (themselves checked
//! against dual numbers in `dynamics/tests/derivatives.rs`) at random states: a chain with
//! prismatic joints, gravity and a runtime payload; a tree; a free-floating arm with gravity
//! (its base pose from the quaternion of `q`); `f32` with fused multiply-adds to `f32`
//! precision; a random 8-joint chain whose `M + c` is straight-line and whose larger derivatives
//! call the compact kernels (the size rule of `kanegen_codegen::compact`).
//!
//! Then the algorithms against Pinocchio 4.1's `computeRNEADerivatives`,
//! `computeABADerivatives` and `computeMinverse` on example-robot-data URDFs
//! (`tests/data/reference/derivatives.json`, made by `tools/reference/derivatives_reference.py`):
//! arms (UR5, xArm7, Z1) on a fixed base and the B1 quadruped carrying a Z1 arm (a kinematic
//! tree) fixed and free-floating, the free flyer's base columns of `∂/∂q` in Pinocchio's tangent
//! space, gravity on; to 1e-9 relative.

use kanegen::dynamics::algorithms::derivatives::{aba as fd, minverse, rnea as id};
use kanegen::dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen::dynamics::linalg::Vec3;
use kanegen::dynamics::Params;
use kanegen::model::io::{load_model, load_model_with};
use kanegen::model::random::{random_vec, rng};
use kanegen::model::{BaseKind, Model, Validation};
use serde_json::Value;
use std::path::Path;

kanegen::dynamics!(
    Random5Gravity,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    runtime_payload = true,
);
kanegen::dynamics!(Tree7, "tests/data/compact/tree7.toml", form = "unrolled");
// Unrolled `M + c`, its larger derivatives in loops (the compact kernels, by the size rule).
kanegen::dynamics!(
    Chain8,
    "benches/data/random_n8.toml",
    gravity = [0.3, -1.2, -9.81],
);
kanegen::dynamics!(
    FreeFloating7,
    "tests/data/reference/bmsd_7dof_free_floating.urdf",
    base = "free-floating",
    allow_nonphysical = true,
    gravity = [0.0, 0.0, -9.81],
);
kanegen::dynamics!(
    Random5F32Fma,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    scalar = f32,
    fma = true,
);
// The same chain in `f32`: its composed derivatives on `f32` lanes.
kanegen::dynamics!(
    Chain8F32,
    "benches/data/random_n8.toml",
    gravity = [0.3, -1.2, -9.81],
    scalar = f32,
);
kanegen::dynamics!(
    Tree10Compact,
    "tests/data/compact/tree10.toml",
    form = "compact"
);
// Compact under `auto`, its `mass_matrix_inverse` straight-line (within the derivatives' size
// rule) beside the compact kernels of the other two.
kanegen::dynamics!(Chain12Auto, "tests/data/compact/chain12.toml");

const G: [f64; 3] = [0.3, -1.2, -9.81];

fn load(rel: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    load_model_with(
        &path,
        Validation {
            allow_nonphysical_inertia: true,
        },
    )
    .unwrap()
}

/// `max|x − y| / max(max|y|, 1)`.
fn rel(x: &[f64], y: &[f64]) -> f64 {
    assert_eq!(x.len(), y.len());
    let scale = y.iter().fold(1.0_f64, |m, v| m.max(v.abs()));
    x.iter()
        .zip(y)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
        / scale
}

fn flat<const N: usize>(m: &[[f64; N]; N]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

fn flat_v(m: &[Vec<f64>]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

fn arr<const N: usize>(v: &[f64]) -> [f64; N] {
    core::array::from_fn(|i| v[i])
}

/// The three functions of a fixed-base type against the algorithms, at ten random states.
macro_rules! check_fixed {
    ($ty:ty, $n:literal, $model:expr, $g:expr, $($payload:expr)?) => {{
        let model: Model = $model;
        let p = Params::<f64>::new(&model);
        let g = $g.map(|g: [f64; 3]| Vec3::from_f64(g));
        let mut worst = 0.0_f64;
        for seed in 0..10 {
            let mut r = rng(seed + 7);
            let q: [f64; $n] = arr(&random_vec(&mut r, $n, 2.0));
            let qd: [f64; $n] = arr(&random_vec(&mut r, $n, 1.5));
            let x: [f64; $n] = arr(&random_vec(&mut r, $n, 4.0));
            let (dq, dv) = <$ty>::inverse_dynamics_derivatives(&q, &qd, &x $(, $payload)?);
            let (wq, wv) = id::derivatives(&p, &q, &qd, &x, g.as_ref());
            worst = worst.max(rel(&[flat(&dq), flat(&dv)].concat(), &[flat_v(&wq), flat_v(&wv)].concat()));
            let (aq, av, minv) = <$ty>::forward_dynamics_derivatives(&q, &qd, &x $(, $payload)?);
            let (bq, bv, bm) = fd::derivatives(&p, &q, &qd, &x, g.as_ref());
            worst = worst.max(rel(
                &[flat(&aq), flat(&av), flat(&minv)].concat(),
                &[flat_v(&bq), flat_v(&bv), flat_v(&bm)].concat(),
            ));
            let m = <$ty>::mass_matrix_inverse(&q $(, $payload)?);
            worst = worst.max(rel(&flat(&m), &flat_v(&minverse::mass_matrix_inverse(&p, &q))));
        }
        worst
    }};
}

#[test]
fn generated_fixed_base_derivatives_equal_the_algorithms() {
    let payload = Random5GravityPayload::NOMINAL;
    let e = check_fixed!(
        Random5Gravity,
        5,
        load("tests/data/codegen/random5.toml"),
        Some(G),
        &payload
    );
    println!("random5, gravity, payload: {e:.1e}");
    assert!(e < 1e-11, "random5: {e:e}");
    let e = check_fixed!(
        Tree7,
        7,
        load("tests/data/compact/tree7.toml"),
        None::<[f64; 3]>,
    );
    println!("tree7: {e:.1e}");
    assert!(e < 1e-11, "tree7: {e:e}");
    let e = check_fixed!(Chain8, 8, load("benches/data/random_n8.toml"), Some(G),);
    println!("random_n8 (derivatives in loops), gravity: {e:.1e}");
    assert!(e < 1e-11, "random_n8: {e:e}");
}

#[test]
fn generated_f32_fma_derivatives_agree_to_f32_precision() {
    let model = load("tests/data/codegen/random5.toml");
    let p = Params::<f64>::new(&model);
    let g = Vec3::from_f64(G);
    let mut worst = 0.0_f64;
    for seed in 0..10 {
        let mut r = rng(seed + 70);
        let x32 = |v: Vec<f64>| -> [f32; 5] { core::array::from_fn(|i| v[i] as f32) };
        let (q, qd, qdd) = (
            x32(random_vec(&mut r, 5, 2.0)),
            x32(random_vec(&mut r, 5, 1.5)),
            x32(random_vec(&mut r, 5, 4.0)),
        );
        let wide = |v: &[f32; 5]| -> Vec<f64> { v.iter().map(|&x| f64::from(x)).collect() };
        let (dq, dv) = Random5F32Fma::inverse_dynamics_derivatives(&q, &qd, &qdd);
        let (wq, wv) = id::derivatives(&p, &wide(&q), &wide(&qd), &wide(&qdd), Some(&g));
        let got: Vec<f64> = dq
            .iter()
            .chain(&dv)
            .flatten()
            .map(|&x| f64::from(x))
            .collect();
        worst = worst.max(rel(&got, &[flat_v(&wq), flat_v(&wv)].concat()));
    }
    println!("f32 + fma: {worst:.1e}");
    assert!(worst < 1e-4, "{worst:e}");
}

#[test]
fn generated_free_floating_derivatives_equal_the_algorithms() {
    let model = load("tests/data/reference/bmsd_7dof_free_floating.urdf");
    let p = Params::<f64>::new(&model);
    let base = FloatingBase::<f64>::from_inertial(model.base_inertial().unwrap());
    let g = Vec3::new(0.0, 0.0, -9.81);
    let mut worst = 0.0_f64;
    for seed in 0..10 {
        let mut r = rng(seed + 700);
        let mut q: [f64; 14] = arr(&random_vec(&mut r, 14, 1.5));
        let norm = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        for x in &mut q[3..7] {
            *x /= norm;
        }
        let v: [f64; 13] = arr(&random_vec(&mut r, 13, 1.0));
        let a: [f64; 13] = arr(&random_vec(&mut r, 13, 3.0));
        let tau: [f64; 7] = arr(&a[6..]);
        let state = FloatingState {
            position: Vec3::new(q[0], q[1], q[2]),
            rotation: quat_to_matrix(&[q[3], q[4], q[5], q[6]]),
            v_b: Vec3::new(v[0], v[1], v[2]),
            omega_b: Vec3::new(v[3], v[4], v[5]),
        };
        let (qj, vj) = (&q[7..], &v[6..]);
        let acc: [f64; 6] = arr(&a);
        let (dq, dv) = FreeFloating7::inverse_dynamics_derivatives(&q, &v, &a);
        let (wq, wv) = id::floating_derivatives(&p, &base, &state, qj, vj, &acc, &a[6..], Some(&g));
        worst = worst.max(rel(
            &[flat(&dq), flat(&dv)].concat(),
            &[flat_v(&wq), flat_v(&wv)].concat(),
        ));
        let (aq, av, minv) = FreeFloating7::forward_dynamics_derivatives(&q, &v, &tau);
        let (bq, bv, bm) = fd::floating_derivatives(&p, &base, &state, qj, vj, &tau, Some(&g));
        worst = worst.max(rel(
            &[flat(&aq), flat(&av), flat(&minv)].concat(),
            &[flat_v(&bq), flat_v(&bv), flat_v(&bm)].concat(),
        ));
        let m = FreeFloating7::mass_matrix_inverse(&q);
        let want = minverse::floating_mass_matrix_inverse(&p, &base, qj);
        worst = worst.max(rel(&flat(&m), &flat_v(&want)));
    }
    println!("free-floating 7-dof: {worst:.1e}");
    assert!(worst < 1e-11, "{worst:e}");
}

/// A compact type's derivatives (`kanegen_runtime::compact::derivatives`) against the
/// algorithms, as the unrolled types' above; and an auto-compact type's, whose `M⁻¹` is
/// straight-line.
#[test]
fn compact_derivatives_equal_the_algorithms() {
    let e = check_fixed!(
        Tree10Compact,
        10,
        load("tests/data/compact/tree10.toml"),
        None::<[f64; 3]>,
    );
    println!("tree10, compact: {e:.1e}");
    assert!(e < 1e-11, "tree10 compact: {e:e}");
    let e = check_fixed!(
        Chain12Auto,
        12,
        load("tests/data/compact/chain12.toml"),
        None::<[f64; 3]>,
    );
    println!("chain12, auto (M⁻¹ straight-line): {e:.1e}");
    assert!(e < 1e-11, "chain12 auto: {e:e}");
    // `CANDIDATES` lists the straight-line functions only.
    let straight = |f: &str| Chain12Auto::CANDIDATES.iter().any(|c| c.function == f);
    assert!(straight("mass_matrix_inverse") && !straight("inverse_dynamics_derivatives"));
}

/// Against Pinocchio.
const PIN_TOL: f64 = 1e-9;

fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(xs) => xs.iter().flat_map(nums).collect(),
        x => vec![x.as_f64().unwrap()],
    }
}

/// `perm[k]` = Pinocchio's index of kanegen's joint `k`.
fn permutation(pin: &[String], model: &Model) -> Vec<usize> {
    model
        .joints()
        .iter()
        .map(|j| {
            pin.iter()
                .position(|p| *p == j.name)
                .expect("joint in both")
        })
        .collect()
}

/// A Pinocchio-order matrix (`n × n`, `offset` base speeds first) in kanegen's order.
fn permute_matrix(a: &[f64], perm: &[usize], offset: usize) -> Vec<f64> {
    let idx: Vec<usize> = (0..offset).chain(perm.iter().map(|p| p + offset)).collect();
    let n = idx.len();
    (0..n)
        .flat_map(|i| idx.iter().map(move |&j| (i, j)))
        .map(|(i, j)| a[idx[i] * n + j])
        .collect()
}

fn permute(x: &[f64], perm: &[usize], offset: usize) -> Vec<f64> {
    (0..offset)
        .chain(perm.iter().map(|p| p + offset))
        .map(|i| x[i])
        .collect()
}

/// Our five matrices at one reference state, in the reference's key order:
/// `dtau_dq, dtau_dv, ddq_dq, ddq_dv, Minv (aba), Minv (minv)`.
fn ours_at(model: &Model, s: &Value, perm: &[usize], floating: bool) -> Vec<Vec<f64>> {
    let p = Params::<f64>::new(model);
    let nb = if floating { 6 } else { 0 };
    let g = Vec3::new(0.0, 0.0, -9.81);
    let q = permute(&nums(&s["q"]), perm, 0);
    let v = permute(&nums(&s["v"]), perm, nb);
    let a = permute(&nums(&s["a"]), perm, nb);
    let tau = permute(&nums(&s["tau"]), perm, 0);
    let (dq, dv, fq, fv, fm, mi) = if floating {
        let base = FloatingBase::<f64>::from_inertial(model.base_inertial().unwrap());
        let quat = nums(&s["base"]["quaternion_xyzw"]);
        let state = FloatingState {
            position: Vec3::zero(),
            rotation: quat_to_matrix(&[quat[0], quat[1], quat[2], quat[3]]),
            v_b: Vec3::new(v[0], v[1], v[2]),
            omega_b: Vec3::new(v[3], v[4], v[5]),
        };
        let acc: [f64; 6] = core::array::from_fn(|k| a[k]);
        let (dq, dv) =
            id::floating_derivatives(&p, &base, &state, &q, &v[6..], &acc, &a[6..], Some(&g));
        let (fq, fv, fm) = fd::floating_derivatives(&p, &base, &state, &q, &v[6..], &tau, Some(&g));
        let mi = minverse::floating_mass_matrix_inverse(&p, &base, &q);
        (dq, dv, fq, fv, fm, mi)
    } else {
        let (dq, dv) = id::derivatives(&p, &q, &v, &a, Some(&g));
        let (fq, fv, fm) = fd::derivatives(&p, &q, &v, &tau, Some(&g));
        (dq, dv, fq, fv, fm, minverse::mass_matrix_inverse(&p, &q))
    };
    [dq, dv, fq, fv, fm, mi].iter().map(|m| flat_v(m)).collect()
}

#[test]
fn derivatives_match_pinocchio() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/reference/derivatives.json");
    let r: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut checked = 0;
    let mut worst = 0.0_f64;
    for (name, entry) in r["models"].as_object().unwrap() {
        let fixed = load_model(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/erd/{name}.urdf")),
        )
        .unwrap();
        let pin: Vec<String> = entry["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap().to_string())
            .collect();
        let perm = permutation(&pin, &fixed);
        for (key, floating) in [("fixed", false), ("free_flyer", true)] {
            let Some(states) = entry[key].as_array() else {
                continue;
            };
            let model = if floating {
                fixed
                    .clone()
                    .with_base_kind(BaseKind::FreeFloating)
                    .unwrap()
            } else {
                fixed.clone().with_base_kind(BaseKind::Fixed).unwrap()
            };
            let nb = if floating { 6 } else { 0 };
            for (k, s) in states.iter().enumerate() {
                let got = ours_at(&model, s, &perm, floating);
                let want = [
                    &s["rnea"]["dtau_dq"],
                    &s["rnea"]["dtau_dv"],
                    &s["aba"]["ddq_dq"],
                    &s["aba"]["ddq_dv"],
                    &s["aba"]["Minv"],
                    &s["minv"],
                ];
                for (g, w) in got.iter().zip(want) {
                    let e = rel(g, &permute_matrix(&nums(w), &perm, nb));
                    worst = worst.max(e);
                    assert!(e < PIN_TOL, "{name} {key} state {k}: {e:.2e}");
                    checked += 1;
                }
            }
        }
    }
    println!("{checked} matrices against Pinocchio, worst {worst:.2e}");
    assert!(checked >= 6 * 2 * 5);
}

/// `forward_dynamics_derivatives_lanes` of a composed function (its parts' lane forms, the two
/// loops on the lane type) at `S::LANES` random states against the scalar function at each:
/// every lane the same bits (checked through `{:?}`, which shows the sign of zero).
macro_rules! composed_lanes_equal_scalar {
    ($ty:ty, $s:ty, $nq:literal, $nv:literal, $n:literal, $seed:expr) => {
        composed_lanes_equal_scalar!($ty, $s, f64, $nq, $nv, $n, $seed)
    };
    ($ty:ty, $s:ty, $f:ty, $nq:literal, $nv:literal, $n:literal, $seed:expr) => {{
        use kanegen::runtime::lanes::{lane, Lanes};
        const L: usize = <$s as Lanes<$f>>::LANES;
        type D = ([[$f; $nv]; $nv], [[$f; $nv]; $nv], [[$f; $nv]; $nv]);
        let mut r = rng($seed);
        let f = |v: Vec<f64>| -> Vec<$f> { v.into_iter().map(|x| x as $f).collect() };
        let states: Vec<([$f; $nq], [$f; $nv], [$f; $n])> = (0..L)
            .map(|_| {
                let q = f(random_vec(&mut r, $nq, 2.0)).try_into().unwrap();
                (
                    q,
                    f(random_vec(&mut r, $nv, 1.5)).try_into().unwrap(),
                    f(random_vec(&mut r, $n, 4.0)).try_into().unwrap(),
                )
            })
            .collect();
        let q: [$s; $nq] = core::array::from_fn(|j| <$s>::from_fn(|i| states[i].0[j]));
        let v: [$s; $nv] = core::array::from_fn(|j| <$s>::from_fn(|i| states[i].1[j]));
        let tau: [$s; $n] = core::array::from_fn(|j| <$s>::from_fn(|i| states[i].2[j]));
        let lanes = <$ty>::forward_dynamics_derivatives_lanes::<$s>(&q, &v, &tau);
        for (i, (q, v, tau)) in states.iter().enumerate() {
            let have: D = lane::<$f, $s, D>(&lanes, i);
            let want = <$ty>::forward_dynamics_derivatives(q, v, tau);
            assert_eq!(format!("{have:?}"), format!("{want:?}"), "lane {i}");
        }
    }};
}

/// A composed `forward_dynamics_derivatives` (past the size rule: `q̈ = M⁻¹ (τ − c)`, then
/// `−M⁻¹ ∂τ/∂x`) on lanes: the random 8-joint chain (its `∂τ` in the compact kernels, on lanes)
/// and the free-floating 7-dof arm, on `f64x2`, `f64x4` and `f64x8`, and the chain in `f32` on
/// `f32x8` and `f32x16`.
#[test]
fn composed_lanes_are_the_scalar_function() {
    use kanegen::runtime::lanes::{f32x16, f32x8, f64x2, f64x4, f64x8};
    for seed in 0..4 {
        composed_lanes_equal_scalar!(Chain8, f64x4, 8, 8, 8, 40 + seed);
        composed_lanes_equal_scalar!(Chain8, f64x2, 8, 8, 8, 50 + seed);
        composed_lanes_equal_scalar!(Chain8, f64x8, 8, 8, 8, 70 + seed);
        composed_lanes_equal_scalar!(FreeFloating7, f64x4, 14, 13, 7, 60 + seed);
        composed_lanes_equal_scalar!(FreeFloating7, f64x8, 14, 13, 7, 80 + seed);
        composed_lanes_equal_scalar!(Chain8F32, f32x8, f32, 8, 8, 8, 90 + seed);
        composed_lanes_equal_scalar!(Chain8F32, f32x16, f32, 8, 8, 8, 100 + seed);
    }
}
