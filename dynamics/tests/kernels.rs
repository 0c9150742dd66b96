//! The run-time path's forward dynamics ([`kernels::forward_dynamics`]: the compact form's
//! articulated-body kernel in base coordinates on tables built at run time) against this crate's
//! local-frame articulated-body algorithm ([`aba`]), on random trees and chains with prismatic
//! joints, fixed and free-floating bases, drives, gravity, wrenches in the body and the base
//! frame, and armature; and both against the same algorithm in double-double ([`Wide`]) on the
//! two space arms, to say which rounds less.

mod common;

use common::{base_inertial, base_state, loads, models};
use kanegen_dynamics::algorithms::aba::{self, Workspace};
use kanegen_dynamics::base::{FloatingBase, FloatingState, BASE_BODY};
use kanegen_dynamics::kernels::{self, KernelData, KernelTables};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::metrics::rel_err;
use kanegen_dynamics::scalars::wide::Wide;
use kanegen_dynamics::{Loads, Params, Real, Scalar};
use kanegen_model::random::{random_vec, rng};

/// The kernel against the local-frame ABA, fixed base: every load variant, with and without
/// armature (which the kernel puts into `D_i` as the workspace ABA does).
#[test]
fn fixed_base_kernel_matches_the_local_frame_aba() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        for variant in 0..3 {
            let mut g = rng(500 + 10 * k as u64 + variant as u64);
            let (q, qd) = (random_vec(&mut g, n, 2.5), random_vec(&mut g, n, 1.5));
            let armature: Vec<f64> = random_vec(&mut g, n, 0.5).iter().map(|a| a.abs()).collect();
            let l = loads(n, 3 * k as u64 + variant as u64, false, variant);
            // The kernel reads gravity from its tables on a fixed base.
            let t = KernelTables::new(&p, l.gravity.as_ref().map(|g| g.0));
            let mut data = KernelData::new(n);
            for arm in [None, Some(armature.as_slice())] {
                let mut want = vec![0.0; n];
                aba::forward_dynamics_in(&p, &mut Workspace::new(&p), &q, &qd, &l, arm, &mut want);
                let mut got = vec![0.0; n];
                kernels::forward_dynamics(&t, &mut data, None, &q, &qd, &l, arm, &mut got);
                let e = rel_err(&got, &want);
                assert!(e < 1e-12, "{} variant {variant}: {e:e}", m.name());
                worst = worst.max(e);
            }
        }
    }
    eprintln!("worst kernel vs local-frame ABA, fixed base: {worst:e}");
}

/// The kernel on a free-floating base against the local-frame ABA's (`aba::floating`): the
/// base's acceleration and the joints', every load variant (wrenches on the base in both
/// frames), with and without armature.
#[test]
fn floating_base_kernel_matches_the_local_frame_aba() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        let base = FloatingBase::from_inertial(&base_inertial(k as u64));
        for variant in 0..3 {
            let mut g = rng(900 + 10 * k as u64 + variant as u64);
            let (q, qd) = (random_vec(&mut g, n, 2.5), random_vec(&mut g, n, 1.5));
            let armature: Vec<f64> = random_vec(&mut g, n, 0.5).iter().map(|a| a.abs()).collect();
            let st = base_state(77 + k as u64);
            let l = loads(n, 5 * k as u64 + variant as u64, true, variant);
            // Gravity is the loads', not the tables'.
            let t = KernelTables::new(&p, None);
            let mut data = KernelData::new(n);
            for arm in [None, Some(armature.as_slice())] {
                let mut want = vec![0.0; 6 + n];
                let mut ws = Workspace::new(&p);
                aba::floating_in(&p, &mut ws, &base, &st, &q, &qd, &l, arm, &mut want);
                let mut got = vec![0.0; 6 + n];
                let fb = Some((&base, &st));
                kernels::forward_dynamics(&t, &mut data, fb, &q, &qd, &l, arm, &mut got);
                let e = rel_err(&got, &want);
                assert!(e < 1e-12, "{} variant {variant}: {e:e}", m.name());
                worst = worst.max(e);
            }
        }
    }
    eprintln!("worst kernel vs local-frame ABA, free-floating base: {worst:e}");
}

/// Both f64 paths against the local-frame ABA in double-double on the space arms (15–17 m long,
/// where base coordinates meet large lever arms): each stays within 1e-12 of the reference, and
/// the measured errors are printed. The kernel's, in base coordinates, is the larger.
#[test]
fn both_paths_against_double_double_on_the_space_arms() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/reference");
    for name in ["ssrms_nguyen_hughes_1994", "srms_nguyen_hughes_1994"] {
        let m = kanegen_model::io::load_model(&dir.join(format!("{name}.urdf"))).unwrap();
        let p = Params::<f64>::new(&m);
        let pw = Params::<Wide>::new(&m);
        let n = p.dof();
        let t = KernelTables::new(&p, Some([0.0, 0.0, -9.81]));
        let mut data = KernelData::new(n);
        let (mut kernel, mut local) = (0.0_f64, 0.0_f64);
        for seed in 0..20 {
            let mut g = rng(seed);
            let (q, qd) = (random_vec(&mut g, n, 3.0), random_vec(&mut g, n, 0.3));
            let tau = random_vec(&mut g, n, 50.0);
            let l = Loads {
                tau: Some(tau.clone()),
                gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
                external: vec![],
            };
            let wide = |x: &[f64]| x.iter().map(|&v| Wide::constant(v)).collect::<Vec<_>>();
            let lw = Loads {
                tau: Some(wide(&tau)),
                gravity: Some(Vec3::new(Wide::zero(), Wide::zero(), Wide::constant(-9.81))),
                external: vec![],
            };
            let reference: Vec<f64> = aba::forward_dynamics(&pw, &wide(&q), &wide(&qd), &lw)
                .iter()
                .map(Real::to_f64)
                .collect();
            let mut got = vec![0.0; n];
            kernels::forward_dynamics(&t, &mut data, None, &q, &qd, &l, None, &mut got);
            kernel = kernel.max(rel_err(&got, &reference));
            local = local.max(rel_err(&aba::forward_dynamics(&p, &q, &qd, &l), &reference));
        }
        eprintln!("{name}: worst relative error against double-double: kernel {kernel:e}, local-frame ABA {local:e}");
        assert!(
            kernel < 1e-12 && local < 1e-12,
            "{name}: {kernel:e} {local:e}"
        );
    }
}

/// A frame at a random offset and orientation on `body`, as this crate and the kernels hold it.
fn random_frame(
    g: &mut rand_chacha::ChaCha8Rng,
    body: Option<usize>,
) -> (
    kanegen_dynamics::FrameParams<f64>,
    kanegen_runtime::compact::Frame<f64>,
) {
    use kanegen_dynamics::linalg::{axis_rotation, Mat3};
    let w = random_vec(g, 7, 1.0);
    let norm = (w[3] * w[3] + w[4] * w[4] + w[5] * w[5]).sqrt();
    let axis = Vec3::new(w[3] / norm, w[4] / norm, w[5] / norm);
    let rotation: Mat3<f64> = axis_rotation(&axis, &w[6].sin(), &w[6].cos());
    let fp = kanegen_dynamics::FrameParams {
        parent: body,
        translation: Vec3::new(w[0], w[1], w[2]),
        rotation: rotation.clone(),
    };
    let frame = kanegen_runtime::compact::Frame {
        body,
        translation: [w[0], w[1], w[2]],
        rotation: rotation.0,
    };
    (fp, frame)
}

/// The frame kernels (`kanegen_runtime::compact::frames`, over the support path in base
/// coordinates) against this crate's local-frame kinematics (`algorithms::frames`): placement and
/// Jacobian of frames at random offsets and orientations on every body of random trees and
/// chains, and on the base.
#[test]
fn frame_kernels_match_the_local_frame_kinematics() {
    use kanegen_dynamics::algorithms::frames;
    use kanegen_runtime::compact::frames::{jacobian_columns, origin, pose, support_placements};
    use kanegen_runtime::compact::spatial::transforms;
    use kanegen_runtime::compact::Transform;
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        let t = KernelTables::new(&p, None);
        let tables = t.tables();
        let mut g = rng(1300 + k as u64);
        let q = random_vec(&mut g, n, 2.5);
        let id = Transform {
            e: [[0.0; 3]; 3],
            r: [0.0; 3],
        };
        let mut x = vec![id; n];
        transforms(&tables, &q, f64::sin_cos, &mut x);
        for body in std::iter::once(None).chain((0..n).map(Some)) {
            let (fp, frame) = random_frame(&mut g, body);
            let mut x0 = vec![id; n];
            if let Some(i) = body {
                support_placements(&tables, i, &x, &mut x0);
            }
            let (xf, rf) = pose(&frame, &x0);
            assert_eq!(xf, origin(&frame, &x0));
            let mut cols = vec![[0.0; 6]; n];
            jacobian_columns(&tables, &frame, &x0, &xf, &mut cols);
            let (want_x, want_r) = frames::placement(&p, &q, &fp);
            let want_j = frames::jacobian(&p, &q, &fp);
            let got: Vec<f64> = xf
                .into_iter()
                .chain(rf.into_iter().flatten())
                .chain((0..6).flat_map(|r| cols.iter().map(move |c| c[r])))
                .collect();
            let want: Vec<f64> = want_x
                .0
                .into_iter()
                .chain(want_r.0.into_iter().flatten())
                .chain(want_j.iter().flatten().copied())
                .collect();
            let e = rel_err(&got, &want);
            assert!(e < 1e-13, "{} frame on {body:?}: {e:e}", m.name());
            worst = worst.max(e);
        }
    }
    eprintln!("worst frame kernel vs local-frame kinematics: {worst:e}");
}

/// The free-floating kernels (`kanegen_runtime::compact::floating`: `M`, `c`, inverse and
/// forward dynamics with the base as the root, wrenches on the base and the bodies, the
/// momentum, the base reaction, the frames; `::derivatives`: the derivatives and `M⁻¹`) against
/// this crate's local-frame algorithms on random trees and chains with random base inertias, poses
/// and twists, with gravity.
#[test]
fn floating_kernels_match_the_local_frame_algorithms() {
    use kanegen_dynamics::algorithms::{derivatives, floating, frames, momentum, rnea};
    use kanegen_dynamics::base::quat_to_matrix;
    use kanegen_dynamics::kernels::inertia_row;
    use kanegen_dynamics::{LoadFrame, MassMatrixMethod};
    use kanegen_model::random::{random_chain, random_tree, ChainSpec};
    use kanegen_runtime::compact::derivatives as dk;
    use kanegen_runtime::compact::floating::{self as fk, Base};
    use kanegen_runtime::compact::floating_frames as ff;

    fn check<const N: usize, const NV: usize>(m: &kanegen_model::Model, seed: u64) -> f64 {
        let p = Params::<f64>::new(m);
        let t = KernelTables::new(&p, None);
        let tables = t.tables();
        let inertia = &t.numbers.inertia[..];
        let fb = FloatingBase::from_inertial(&base_inertial(seed));
        let g = [0.4, -0.7, -9.81];
        let base = Base {
            inertia: inertia_row(&fb.inertia),
            gravity: Some(g),
        };
        let mut r = rng(seed);
        let w = random_vec(&mut r, 4, 1.0);
        let norm = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        let quat = [w[0] / norm, w[1] / norm, w[2] / norm, w[3] / norm];
        let qj = random_vec(&mut r, N, 2.5);
        let q: Vec<f64> = [0.3, -0.2, 1.1]
            .into_iter()
            .chain(quat)
            .chain(qj.clone())
            .collect();
        let nu = random_vec(&mut r, NV, 1.0);
        let nu_dot = random_vec(&mut r, NV, 1.0);
        let tau: [f64; N] = core::array::from_fn(|i| 5.0 * (i as f64 + 1.0).sin());
        let f_ext: Vec<[f64; 6]> = (0..=N)
            .map(|k| core::array::from_fn(|i| ((k * 6 + i) as f64).cos()))
            .collect();
        let st = FloatingState {
            position: Vec3::new(q[0], q[1], q[2]),
            rotation: quat_to_matrix(&quat),
            v_b: Vec3::new(nu[0], nu[1], nu[2]),
            omega_b: Vec3::new(nu[3], nu[4], nu[5]),
        };
        let gravity = Some(Vec3::new(g[0], g[1], g[2]));
        let loads = Loads {
            tau: Some(tau.to_vec()),
            gravity,
            external: vec![],
        };
        let passive = Loads {
            tau: None,
            ..loads.clone()
        };
        let sc = f64::sin_cos;
        let mut worst = 0.0_f64;
        let mut agree = |what: &str, got: &[f64], want: &[f64]| {
            let e = rel_err(got, want);
            assert!(e < 1e-12, "{} {what}: {e:e}", m.name());
            worst = worst.max(e);
        };
        let mm = fk::mass_matrix::<f64, N, NV>(&tables, inertia, &base, &q, sc);
        let want = floating::mass_matrix(MassMatrixMethod::Crba, &p, &fb, &st, &qj);
        agree("M", mm.as_flattened(), &want.concat());
        let c =
            fk::inverse_dynamics::<f64, N, NV>(&tables, inertia, &base, &q, Some(&nu), None, sc);
        let minus_c = rnea::floating_tau_minus_c(&p, &fb, &st, &qj, &nu[6..], &passive);
        agree("c", &c, &minus_c.iter().map(|x| -x).collect::<Vec<_>>());
        let id = fk::inverse_dynamics::<f64, N, NV>(
            &tables,
            inertia,
            &base,
            &q,
            Some(&nu),
            Some(&nu_dot),
            sc,
        );
        let acc: [f64; 6] = core::array::from_fn(|i| nu_dot[i]);
        let want = rnea::floating_inverse_dynamics(
            &p,
            &fb,
            &st,
            &qj,
            &nu[6..],
            &acc,
            &nu_dot[6..],
            &passive,
        );
        agree("inverse dynamics", &id, &want);
        let fd =
            fk::forward_dynamics::<f64, N, NV>(&tables, inertia, &base, &q, &nu, &tau, None, sc);
        let want = aba::floating(&p, &fb, &st, &qj, &nu[6..], &loads);
        agree("forward dynamics", &fd, &want);
        let fdw = fk::forward_dynamics::<f64, N, NV>(
            &tables,
            inertia,
            &base,
            &q,
            &nu,
            &tau,
            Some(&f_ext),
            sc,
        );
        let mut with = loads.clone();
        with.external = f_ext
            .iter()
            .enumerate()
            .map(|(k, f)| kanegen_dynamics::ExternalWrench {
                body: if k == 0 { BASE_BODY } else { k - 1 },
                frame: LoadFrame::Body,
                force: Vec3::new(f[0], f[1], f[2]),
                moment: Vec3::new(f[3], f[4], f[5]),
            })
            .collect();
        let want = aba::floating(&p, &fb, &st, &qj, &nu[6..], &with);
        agree("forward dynamics with wrenches", &fdw, &want);
        let h = fk::momentum::<f64, N>(&tables, inertia, &base, &q, &nu, sc);
        let (lin, ang) = momentum::momentum(&p, &fb, &st, &qj, &nu[6..]);
        agree("momentum", &h, &[lin.0, ang.0].concat());
        let reaction = fk::base_reaction::<f64, N>(&tables, inertia, &base, &q, &nu, &nu_dot, sc);
        let want = rnea::base_reaction(&p, &st, &qj, &nu[6..], &acc, &nu_dot[6..], &passive);
        agree("base reaction", &reaction, &want);
        for body in std::iter::once(None).chain((0..N).map(Some)) {
            let (fp, frame) = random_frame(&mut r, body);
            let (x, rot) = ff::frame_placement::<f64, N>(&tables, &frame, &q, sc);
            let (want_x, want_r) = frames::floating_placement(&p, &st, &qj, &fp);
            let got = [x.as_slice(), rot.as_flattened()].concat();
            agree(
                "frame placement",
                &got,
                &[want_x.0.as_slice(), want_r.0.as_flattened()].concat(),
            );
            let j = ff::frame_jacobian::<f64, N, NV>(&tables, &frame, &q, sc);
            let want = frames::floating_jacobian(&p, &st, &qj, &fp);
            agree("frame Jacobian", j.as_flattened(), &want.concat());
            let gj = ff::generalized_jacobian::<f64, N>(&tables, inertia, &base, &frame, &q, sc);
            let want = frames::generalized_jacobian(&p, &fb, &st, &qj, &fp);
            agree("generalized Jacobian", gj.as_flattened(), &want.concat());
        }
        let (dq, dv) = dk::floating_inverse_dynamics_derivatives::<f64, N, NV>(
            &tables, inertia, &base, &q, &nu, &nu_dot, sc,
        );
        let gv = Vec3::new(g[0], g[1], g[2]);
        let (wq, wv) = derivatives::rnea::floating_derivatives(
            &p,
            &fb,
            &st,
            &qj,
            &nu[6..],
            &acc,
            &nu_dot[6..],
            Some(&gv),
        );
        let got = [dq.as_flattened(), dv.as_flattened()].concat();
        agree("(∂τ/∂q, ∂τ/∂ν)", &got, &[wq.concat(), wv.concat()].concat());
        let minv = dk::floating_mass_matrix_inverse::<f64, N, NV>(&tables, inertia, &base, &q, sc);
        let want = derivatives::minverse::floating_mass_matrix_inverse(&p, &fb, &qj);
        agree("M⁻¹", minv.as_flattened(), &want.concat());
        let (aq, av, ainv) = dk::floating_forward_dynamics_derivatives::<f64, N, NV>(
            &tables, inertia, &base, &q, &nu, &tau, sc,
        );
        let (wq, wv, winv) =
            derivatives::aba::floating_derivatives(&p, &fb, &st, &qj, &nu[6..], &tau, Some(&gv));
        let got = [aq.as_flattened(), av.as_flattened(), ainv.as_flattened()].concat();
        let want = [wq.concat(), wv.concat(), winv.concat()].concat();
        agree("(∂ν̇/∂q, ∂ν̇/∂ν, M⁻¹)", &got, &want);
        worst
    }
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.3,
        ..Default::default()
    };
    let worst = [
        check::<1, 7>(&random_chain(&spec(1), 1), 11),
        check::<5, 11>(&random_chain(&spec(5), 2), 12),
        check::<7, 13>(&random_tree(&spec(7), 3), 13),
        check::<12, 18>(&random_tree(&spec(12), 4), 14),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    eprintln!("worst floating kernel vs local-frame algorithms: {worst:e}");
}

/// The compact derivative kernels (`kanegen_runtime::compact::derivatives`: Carpentier–Mansard
/// over the tables, `M⁻¹` by LDLᵀ) against this crate's local-parameter derivatives
/// (`algorithms::derivatives`, themselves checked against dual numbers and Pinocchio), on random
/// chains and trees with prismatic joints, under gravity.
#[test]
fn derivative_kernels_match_the_local_frame_derivatives() {
    use kanegen_dynamics::algorithms::derivatives::{aba as fd, minverse, rnea as id};
    use kanegen_model::random::{random_chain, random_tree, ChainSpec};
    use kanegen_runtime::compact::derivatives as dk;

    fn check<const N: usize>(m: &kanegen_model::Model, seed: u64) -> f64 {
        let p = Params::<f64>::new(m);
        let g = [0.4, -0.7, -9.81];
        let t = KernelTables::new(&p, Some(g));
        let tables = t.tables();
        let inertia = &t.numbers.inertia[..];
        let gravity = Vec3::new(g[0], g[1], g[2]);
        let mut r = rng(seed);
        let v = |r: &mut _, s| -> [f64; N] { random_vec(r, N, s).try_into().unwrap() };
        let (q, qd, qdd, tau) = (
            v(&mut r, 2.5),
            v(&mut r, 1.0),
            v(&mut r, 1.0),
            v(&mut r, 5.0),
        );
        let sc = f64::sin_cos;
        let mut worst = 0.0_f64;
        // The matrices of one function against their common scale (∂τ/∂q̇ of one joint is
        // zero up to rounding).
        let mut agree = |what: &str, got: &[&[[f64; N]; N]], want: &[&[Vec<f64>]]| {
            let got: Vec<f64> = got.iter().flat_map(|m| m.as_flattened().to_vec()).collect();
            let want: Vec<f64> = want.iter().flat_map(|m| m.concat()).collect();
            let e = rel_err(&got, &want);
            assert!(e < 1e-12, "{} {what}: {e:e}", m.name());
            worst = worst.max(e);
        };
        let (dq, dv) = dk::inverse_dynamics_derivatives(&tables, inertia, &q, &qd, &qdd, sc);
        let (wq, wv) = id::derivatives(&p, &q, &qd, &qdd, Some(&gravity));
        agree("(∂τ/∂q, ∂τ/∂q̇)", &[&dq, &dv], &[&wq, &wv]);
        let minv = dk::mass_matrix_inverse(&tables, inertia, &q, sc);
        agree("M⁻¹", &[&minv], &[&minverse::mass_matrix_inverse(&p, &q)]);
        let (aq, av, ainv) = dk::forward_dynamics_derivatives(&tables, inertia, &q, &qd, &tau, sc);
        let (wq, wv, winv) = fd::derivatives(&p, &q, &qd, &tau, Some(&gravity));
        agree(
            "(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)",
            &[&aq, &av, &ainv],
            &[&wq, &wv, &winv],
        );
        worst
    }
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.3,
        ..Default::default()
    };
    let worst = [
        check::<1>(&random_chain(&spec(1), 21), 31),
        check::<6>(&random_chain(&spec(6), 22), 32),
        check::<7>(&random_tree(&spec(7), 23), 33),
        check::<12>(&random_tree(&spec(12), 24), 34),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    eprintln!("worst derivative kernel vs local-frame derivatives: {worst:e}");
}
