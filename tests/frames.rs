//! Generated named-frame kinematics and free-floating identities.
//!
//! - Fixed base, UR5 (example-robot-data; its tool flange `tool0`, `ee_link`, `base_link`,
//!   `base` are fixed links kept as named frames): every `<frame>_placement` against
//!   Pinocchio's frame placements at ten states, and every `<frame>_jacobian` against central
//!   differences of the placement.
//! - Free-floating Panda (a tree): the frame Jacobian against differences of the placement
//!   along `v`; the generalized Jacobian against the frame's motion when the base moves so that
//!   the momentum stays zero; inverse dynamics, forward dynamics (with and without wrenches) and
//!   the base reaction against each other and the interpreted algorithms.

use kanegen::dynamics::algorithms::{floating, rnea};
use kanegen::dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen::dynamics::linalg::Vec3;
use kanegen::dynamics::metrics::rel_err;
use kanegen::dynamics::{ExternalWrench, LoadFrame, Loads, Methods, Params};
use kanegen::model::random::{random_vec, rng};
use kanegen::model::BaseKind;
use serde_json::Value;
use std::path::Path;

kanegen::dynamics!(Ur5, "tests/data/erd/ur5_robot.urdf");
kanegen::dynamics!(
    PandaFree,
    "tests/data/erd/panda.urdf",
    base = "free-floating",
    ignore_mimic = true
);

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(xs) => xs.iter().flat_map(nums).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        other => panic!("not a number: {other}"),
    }
}

type Placement = ([f64; 3], [[f64; 3]; 3]);
/// A frame's name, placement function and Jacobian function (UR5: 6 joints).
type FrameFns = (
    &'static str,
    fn(&[f64; 6]) -> Placement,
    fn(&[f64; 6]) -> [[f64; 6]; 6],
);

/// A frame's placement as 12 numbers (origin, then rotation rows).
fn flat(p: &Placement) -> Vec<f64> {
    p.0.iter().chain(p.1.iter().flatten()).copied().collect()
}

/// The velocity `[v; ω]` of a frame from central differences of its placement along `dq`
/// (`ω̃ = Ṙ Rᵀ`).
fn velocity(f: impl Fn(f64) -> Placement, h: f64) -> [f64; 6] {
    let (p1, p0, r) = (f(h), f(-h), f(0.0).1);
    let v: [f64; 3] = core::array::from_fn(|i| (p1.0[i] - p0.0[i]) / (2.0 * h));
    let rd: [[f64; 3]; 3] =
        core::array::from_fn(|i| core::array::from_fn(|j| (p1.1[i][j] - p0.1[i][j]) / (2.0 * h)));
    let w = |i: usize, j: usize| (0..3).map(|k| rd[i][k] * r[j][k]).sum::<f64>();
    [v[0], v[1], v[2], w(2, 1), w(0, 2), w(1, 0)]
}

#[test]
fn fixed_base_frames_match_pinocchio_and_their_jacobians_match_differences() {
    let r: Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("tests/data/erd/ur5_robot.reference.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(Ur5::FRAMES, ["base_link", "ee_link", "tool0", "base"]);
    let pin_frames = r["frames"].as_array().unwrap();
    let index = |name: &str| {
        pin_frames
            .iter()
            .position(|f| f["name"] == name && f["kind"] == "body")
            .unwrap_or_else(|| panic!("frame {name}"))
    };
    let fns: [FrameFns; 4] = [
        (
            "base_link",
            Ur5::base_link_placement,
            Ur5::base_link_jacobian,
        ),
        ("ee_link", Ur5::ee_link_placement, Ur5::ee_link_jacobian),
        ("tool0", Ur5::tool0_placement, Ur5::tool0_jacobian),
        ("base", Ur5::base_placement, Ur5::base_jacobian),
    ];
    let mut worst: (f64, f64) = (0.0, 0.0);
    for s in r["fixed"]["states"].as_array().unwrap() {
        // UR5 is a chain: Pinocchio's joint order is the file's.
        let q: [f64; 6] = nums(&s["q"]).try_into().unwrap();
        for (name, placement, jacobian) in fns {
            let want = &s["frames"][index(name)];
            let mut w = nums(&want["translation"]);
            w.extend(nums(&want["rotation"]));
            let e = rel_err(&flat(&placement(&q)), &w);
            worst.0 = worst.0.max(e);
            assert!(e < 1e-9, "{name}: placement {e:.2e}");
            let j = jacobian(&q);
            for k in 0..6 {
                let col: Vec<f64> = (0..6).map(|r| j[r][k]).collect();
                let fd = velocity(
                    |t| {
                        let mut qq = q;
                        qq[k] += t;
                        placement(&qq)
                    },
                    1e-6,
                );
                let e = col
                    .iter()
                    .zip(&fd)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                worst.1 = worst.1.max(e);
                assert!(e < 1e-7, "{name}: Jacobian column {k} off by {e:.2e}");
            }
        }
    }
    eprintln!(
        "UR5 frames: placement vs Pinocchio {:.2e}, Jacobian vs differences {:.2e}",
        worst.0, worst.1
    );
}

const N: usize = PandaFree::N;
const NQ: usize = PandaFree::NQ;
const NV: usize = PandaFree::NV;

/// A random free-floating Panda state: `q` (unit quaternion), `v`.
fn floating_state(seed: u64) -> ([f64; NQ], [f64; NV]) {
    let mut g = rng(seed);
    let mut q: [f64; NQ] = random_vec(&mut g, NQ, 1.0).try_into().unwrap();
    let norm = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
    for x in &mut q[3..7] {
        *x /= norm;
    }
    (q, random_vec(&mut g, NV, 0.5).try_into().unwrap())
}

/// The interpreted model, base state and joint parts of `(q, v)`.
fn interpreted(
    q: &[f64; NQ],
    v: &[f64; NV],
) -> (Params<f64>, FloatingBase<f64>, FloatingState<f64>) {
    let m = kanegen::model::io::load_model(&root().join("tests/data/erd/panda.urdf"))
        .unwrap()
        .without_mimics()
        .with_base_kind(BaseKind::FreeFloating)
        .unwrap();
    let state = FloatingState {
        position: Vec3([q[0], q[1], q[2]]),
        rotation: quat_to_matrix(&[q[3], q[4], q[5], q[6]]),
        v_b: Vec3([v[0], v[1], v[2]]),
        omega_b: Vec3([v[3], v[4], v[5]]),
    };
    (
        Params::new(&m),
        FloatingBase::from_inertial(m.base_inertial().unwrap()),
        state,
    )
}

#[test]
fn free_floating_frame_jacobians_follow_the_motion() {
    for seed in 0..5 {
        let (q, v) = floating_state(40 + seed);
        // q̇ of the configuration from v: ṗ = R₀ v_b, quaternion rate ½ q ⊗ (ω_b, 0).
        let step = |t: f64| -> [f64; NQ] {
            let r = quat_to_matrix(&[q[3], q[4], q[5], q[6]]);
            let pd = r.mul_vec(&Vec3([v[0], v[1], v[2]]));
            let (x, y, z, w) = (q[3], q[4], q[5], q[6]);
            let (a, b, c) = (v[3], v[4], v[5]);
            let qd = [
                0.5 * (w * a + y * c - z * b),
                0.5 * (w * b + z * a - x * c),
                0.5 * (w * c + x * b - y * a),
                -0.5 * (x * a + y * b + z * c),
            ];
            let mut out = q;
            for (o, p) in out[..3].iter_mut().zip(&pd.0) {
                *o += t * p;
            }
            for i in 0..4 {
                out[3 + i] += t * qd[i];
            }
            for i in 0..N {
                out[7 + i] += t * v[6 + i];
            }
            out
        };
        let j = PandaFree::panda_hand_tcp_jacobian(&q);
        let jv: Vec<f64> = (0..6)
            .map(|r| (0..NV).map(|k| j[r][k] * v[k]).sum())
            .collect();
        let fd = velocity(|t| PandaFree::panda_hand_tcp_placement(&step(t)), 1e-6);
        let e = jv
            .iter()
            .zip(&fd)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(e < 1e-6, "seed {seed}: J v vs differences {e:.2e}");

        // Zero momentum: ν_b = −A_bb⁻¹ A_bm q̇, then J* q̇ = J [ν_b; q̇].
        let m = PandaFree::mass_matrix(&q);
        let abb = nalgebra::Matrix6::from_fn(|r, c| m[r][c]);
        let qd = &v[6..];
        let rhs =
            nalgebra::Vector6::from_fn(|r, _| -(0..N).map(|k| m[r][6 + k] * qd[k]).sum::<f64>());
        let nub = abb.cholesky().unwrap().solve(&rhs);
        let mut nu = [0.0; NV];
        nu[..6].copy_from_slice(nub.as_slice());
        nu[6..].copy_from_slice(qd);
        let p = PandaFree::momentum(&q, &nu);
        let scale = PandaFree::momentum(&q, &v)
            .iter()
            .fold(1.0_f64, |a, x| a.max(x.abs()));
        assert!(p.iter().all(|x| x.abs() < 1e-12 * scale), "momentum {p:?}");
        let want: Vec<f64> = (0..6)
            .map(|r| (0..NV).map(|k| j[r][k] * nu[k]).sum())
            .collect();
        let gj = PandaFree::panda_hand_tcp_generalized_jacobian(&q);
        let have: Vec<f64> = (0..6)
            .map(|r| (0..N).map(|k| gj[r][k] * qd[k]).sum())
            .collect();
        let e = rel_err(&have, &want);
        assert!(
            e < 1e-10,
            "seed {seed}: J* q̇ vs zero-momentum motion {e:.2e}"
        );
    }
}

#[test]
fn free_floating_inverse_and_forward_dynamics_and_base_reaction_agree() {
    for seed in 0..5 {
        let (q, v) = floating_state(60 + seed);
        let tau: [f64; N] = random_vec(&mut rng(70 + seed), N, 5.0).try_into().unwrap();
        // Forward then inverse dynamics: no wrench on the base, the drives back.
        let a = PandaFree::forward_dynamics(&q, &v, &tau);
        let id = PandaFree::inverse_dynamics(&q, &v, &a);
        let mut want = [0.0; NV];
        want[6..].copy_from_slice(&tau);
        let scale = tau.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        let e = id
            .iter()
            .zip(&want)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
            / scale;
        assert!(e < 1e-10, "seed {seed}: ID(FD(τ)) {e:.2e}");
        // M a + c = [0; τ].
        let (m, c) = PandaFree::mass_matrix_and_nonlinear_effects(&q, &v);
        let lhs: Vec<f64> = (0..NV)
            .map(|i| (0..NV).map(|k| m[i][k] * a[k]).sum::<f64>() + c[i])
            .collect();
        assert!(rel_err(&lhs, &want) < 1e-10);
        // Wrenches: zero ones change nothing; others equal the interpreted algorithm.
        let zero = [[0.0; 6]; N + 1];
        // To rounding: `forward_dynamics` may be traced in canonical body frames, the wrench
        // variant (body-frame wrenches) always in the model's own.
        let e = rel_err(
            &PandaFree::forward_dynamics_with_wrenches(&q, &v, &tau, &zero),
            &a,
        );
        assert!(e < 1e-13, "zero wrenches: {e:.2e}");
        let mut g = rng(80 + seed);
        let f_ext: [[f64; 6]; N + 1] =
            core::array::from_fn(|_| random_vec(&mut g, 6, 3.0).try_into().unwrap());
        let (p, base, state) = interpreted(&q, &v);
        let external: Vec<ExternalWrench<f64>> = f_ext
            .iter()
            .enumerate()
            .map(|(r, w)| ExternalWrench {
                body: if r == 0 {
                    kanegen::dynamics::base::BASE_BODY
                } else {
                    r - 1
                },
                frame: LoadFrame::Body,
                force: Vec3([w[0], w[1], w[2]]),
                moment: Vec3([w[3], w[4], w[5]]),
            })
            .collect();
        let loads = Loads {
            tau: Some(tau.to_vec()),
            gravity: None,
            external,
        };
        let interp = floating::forward_dynamics(
            Methods::SPATIAL,
            &p,
            &base,
            &state,
            &q[7..],
            &v[6..],
            &loads,
        );
        let gen = PandaFree::forward_dynamics_with_wrenches(&q, &v, &tau, &f_ext);
        let e = rel_err(&gen, &interp);
        assert!(e < 1e-10, "seed {seed}: FD with wrenches {e:.2e}");
        // With no external wrench on the base, the arm's reaction is all that moves it: the
        // reaction equals the isolated base's inertial wrench I_b a_b + v_b ×* I_b v_b.
        let reaction = PandaFree::base_reaction(&q, &v, &a);
        let base_acc: [f64; 6] = core::array::from_fn(|k| a[k]);
        let no_loads = Loads::default();
        let needed = rnea::floating_inverse_dynamics(
            &p,
            &base,
            &state,
            &q[7..],
            &v[6..],
            &base_acc,
            &a[6..],
            &no_loads,
        );
        assert!(
            needed[..6].iter().all(|x| x.abs() < 1e-9 * scale),
            "{needed:?}"
        );
        let isolated = kanegen::dynamics::spatial::RbInertia::from_com(
            &base.mass,
            &base.com,
            &base.inertia_com,
        );
        let vb = kanegen::dynamics::spatial::Motion {
            ang: Vec3([v[3], v[4], v[5]]),
            lin: Vec3([v[0], v[1], v[2]]),
        };
        let ab = kanegen::dynamics::spatial::Motion {
            ang: Vec3([a[3], a[4], a[5]]),
            lin: Vec3([a[0], a[1], a[2]]),
        };
        let f = isolated.mul(&ab) + vb.crf(&isolated.mul(&vb));
        let want = kanegen::dynamics::spatial::base_rows(&f);
        let e = rel_err(&reaction, &want);
        assert!(
            e < 1e-9,
            "seed {seed}: base reaction {e:.2e} ({reaction:?} vs {want:?})"
        );
    }
}
