//! The compact form (`form = "compact"`: loops over constant tables) equals the unrolled form
//! and the interpreted algorithms on random chains and trees with prismatic joints, with and
//! without gravity, in f64 (1e-12 relative) and f32.

use kanegen::model::io::to_toml;
use kanegen::model::random::{random_chain, random_tree, ChainSpec};
use kanegen::model::Model;
use std::path::Path;

/// The committed test models: `(file stem, model)`.
fn models() -> Vec<(String, Model)> {
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.3,
        ..Default::default()
    };
    vec![
        ("chain3".into(), random_chain(&spec(3), 3)),
        ("chain12".into(), random_chain(&spec(12), 12)),
        ("tree7".into(), random_tree(&spec(7), 7)),
        ("tree10".into(), random_tree(&spec(10), 10)),
    ]
}

#[test]
fn compact_models_are_current() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/compact");
    let bless = std::env::var_os("KANEGEN_BLESS").is_some();
    for (stem, model) in models() {
        let text = to_toml(&model);
        let path = dir.join(format!("{stem}.toml"));
        if bless {
            std::fs::write(&path, &text).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == text,
            "{} is stale: rerun with KANEGEN_BLESS=1",
            path.display()
        );
    }
}

use kanegen::dynamics::metrics::rel_err;
use kanegen::dynamics::{linalg::Vec3, Loads, Methods, Params};
use kanegen::model::random::{random_vec, rng};

const G: [f64; 3] = [0.3, -1.2, -9.81];

kanegen::dynamics!(
    Chain3C,
    "tests/data/compact/chain3.toml",
    form = "compact",
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    Chain3U,
    "tests/data/compact/chain3.toml",
    form = "unrolled",
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    Chain12C,
    "tests/data/compact/chain12.toml",
    form = "compact"
);
kanegen::dynamics!(
    Chain12U,
    "tests/data/compact/chain12.toml",
    form = "unrolled"
);
kanegen::dynamics!(
    Chain12F32,
    "tests/data/compact/chain12.toml",
    form = "compact",
    scalar = f32
);
kanegen::dynamics!(
    Tree7C,
    "tests/data/compact/tree7.toml",
    form = "compact",
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    Tree7U,
    "tests/data/compact/tree7.toml",
    form = "unrolled",
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    Tree10C,
    "tests/data/compact/tree10.toml",
    form = "compact",
    regroup = false
);
kanegen::dynamics!(Tree10U, "tests/data/compact/tree10.toml", form = "unrolled");

kanegen::dynamics!(
    Tree7PC,
    "tests/data/compact/tree7.toml",
    form = "compact",
    runtime_payload = true,
    gravity = [0.3, -1.2, -9.81]
);
kanegen::dynamics!(
    Tree7PU,
    "tests/data/compact/tree7.toml",
    form = "unrolled",
    runtime_payload = true,
    gravity = [0.3, -1.2, -9.81]
);

/// A payload other than the nominal one, for the compact and the unrolled type.
fn payloads() -> (Tree7PCPayload, Tree7PUPayload) {
    let pc = Tree7PCPayload {
        mass: 7.5,
        com: [0.1, -0.2, 0.3],
        inertia: [[0.4, 0.01, -0.02], [0.01, 0.5, 0.03], [-0.02, 0.03, 0.6]],
    };
    let pu = Tree7PUPayload {
        mass: pc.mass,
        com: pc.com,
        inertia: pc.inertia,
    };
    (pc, pu)
}

/// A runtime payload other than the nominal one: the compact form reads it like the unrolled.
#[test]
fn compact_runtime_payload_equals_unrolled() {
    let (pc, pu) = payloads();
    let mut r = rng(9);
    let q: [f64; 7] = arr(random_vec(&mut r, 7, 2.0));
    let qd: [f64; 7] = arr(random_vec(&mut r, 7, 1.0));
    let tau: [f64; 7] = arr(random_vec(&mut r, 7, 20.0));
    close(
        "M",
        &flat(&Tree7PC::mass_matrix(&q, &pc)),
        &flat(&Tree7PU::mass_matrix(&q, &pu)),
        1e-12,
    );
    close(
        "c",
        &Tree7PC::nonlinear_effects(&q, &qd, &pc),
        &Tree7PU::nonlinear_effects(&q, &qd, &pu),
        1e-12,
    );
    close(
        "ID",
        &Tree7PC::inverse_dynamics(&q, &qd, &tau, &pc),
        &Tree7PU::inverse_dynamics(&q, &qd, &tau, &pu),
        1e-12,
    );
    close(
        "FD",
        &Tree7PC::forward_dynamics(&q, &qd, &tau, &pc),
        &Tree7PU::forward_dynamics(&q, &qd, &tau, &pu),
        1e-10,
    );
    // And the payload matters.
    let nominal = Tree7PCPayload::NOMINAL;
    assert!(
        rel_err(
            &Tree7PC::nonlinear_effects(&q, &qd, &nominal),
            &Tree7PC::nonlinear_effects(&q, &qd, &pc)
        ) > 1e-3
    );
}

/// The compact form's derivatives (`kanegen_runtime::compact::derivatives`, loops over the
/// tables) against the unrolled form's (Carpentier–Mansard traced on the model's local
/// parameters, checked against dual numbers and Pinocchio in `tests/derivatives.rs`): a tree
/// under gravity, the same tree with a runtime payload other than the nominal one, and a chain.
#[test]
fn compact_derivatives_equal_unrolled() {
    let mut r = rng(19);
    type Three = ([[f64; 7]; 7], [[f64; 7]; 7], [[f64; 7]; 7]);
    let flat3 = |m: &Three| [flat(&m.0), flat(&m.1), flat(&m.2)].concat();
    let q: [f64; 7] = arr(random_vec(&mut r, 7, 2.0));
    let qd: [f64; 7] = arr(random_vec(&mut r, 7, 1.0));
    let x: [f64; 7] = arr(random_vec(&mut r, 7, 5.0));
    let (cq, cv) = Tree7C::inverse_dynamics_derivatives(&q, &qd, &x);
    let (uq, uv) = Tree7U::inverse_dynamics_derivatives(&q, &qd, &x);
    let both = |a: &[[f64; 7]; 7], b: &[[f64; 7]; 7]| [flat(a), flat(b)].concat();
    close("ID derivatives", &both(&cq, &cv), &both(&uq, &uv), 1e-12);
    let c = Tree7C::forward_dynamics_derivatives(&q, &qd, &x);
    let u = Tree7U::forward_dynamics_derivatives(&q, &qd, &x);
    close("FD derivatives", &flat3(&c), &flat3(&u), 1e-11);
    close(
        "M⁻¹",
        &flat(&Tree7C::mass_matrix_inverse(&q)),
        &flat(&Tree7U::mass_matrix_inverse(&q)),
        1e-12,
    );
    let (pc, pu) = payloads();
    let c = Tree7PC::forward_dynamics_derivatives(&q, &qd, &x, &pc);
    let u = Tree7PU::forward_dynamics_derivatives(&q, &qd, &x, &pu);
    close(
        "FD derivatives with a payload",
        &flat3(&c),
        &flat3(&u),
        1e-11,
    );
    let q: [f64; 3] = arr(random_vec(&mut r, 3, 2.0));
    let qd: [f64; 3] = arr(random_vec(&mut r, 3, 1.0));
    let x: [f64; 3] = arr(random_vec(&mut r, 3, 5.0));
    let (cq, cv, _) = Chain3C::forward_dynamics_derivatives(&q, &qd, &x);
    let (uq, uv, _) = Chain3U::forward_dynamics_derivatives(&q, &qd, &x);
    close(
        "FD derivatives of a chain",
        &[flat(&cq), flat(&cv)].concat(),
        &[flat(&uq), flat(&uv)].concat(),
        1e-11,
    );
}

fn load(stem: &str) -> Model {
    kanegen::model::io::load_model(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/compact/{stem}.toml")),
    )
    .unwrap()
}

fn arr<const N: usize>(v: Vec<f64>) -> [f64; N] {
    core::array::from_fn(|i| v[i])
}

fn flat<const N: usize>(a: &[[f64; N]; N]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

/// `(compact, reference)` pairs must agree to `tol` relative.
fn close(what: &str, x: &[f64], y: &[f64], tol: f64) {
    let e = rel_err(x, y);
    assert!(e < tol, "{what}: relative error {e:e}\n{x:?}\n{y:?}");
}

macro_rules! compare {
    ($c:ident, $u:ident, $n:literal, $stem:literal, $gravity:expr) => {{
        let model = load($stem);
        let p = Params::<f64>::new(&model);
        let gravity: Option<[f64; 3]> = $gravity;
        let loads = Loads {
            gravity: gravity.map(|g| Vec3::new(g[0], g[1], g[2])),
            ..Loads::default()
        };
        let alg = Methods::SPATIAL;
        for seed in 0..10 {
            let mut r = rng(seed);
            let q: [f64; $n] = arr(random_vec(&mut r, $n, 2.0));
            let qd: [f64; $n] = arr(random_vec(&mut r, $n, 1.0));
            let qdd: [f64; $n] = arr(random_vec(&mut r, $n, 1.0));
            let tau: [f64; $n] = arr(random_vec(&mut r, $n, 20.0));
            let f_ext: [[f64; 6]; $n] = core::array::from_fn(|_| arr(random_vec(&mut r, 6, 3.0)));
            let m = $c::mass_matrix(&q);
            close(
                "M vs unrolled",
                &flat(&m),
                &flat(&$u::mass_matrix(&q)),
                1e-12,
            );
            let mi: Vec<f64> = alg
                .mass_matrix
                .mass_matrix(&p, &q)
                .into_iter()
                .flatten()
                .collect();
            close("M vs interpreted", &flat(&m), &mi, 1e-12);
            let c = $c::nonlinear_effects(&q, &qd);
            close("c vs unrolled", &c, &$u::nonlinear_effects(&q, &qd), 1e-12);
            let ci: Vec<f64> = alg
                .nonlinear_effects
                .tau_minus_c(&p, &q, &qd, &loads)
                .iter()
                .map(|b| -b)
                .collect();
            close("c vs interpreted", &c, &ci, 1e-12);
            let (m2, c2) = $c::mass_matrix_and_nonlinear_effects(&q, &qd);
            assert_eq!((m2, c2), (m, c), "M + c in one call");
            let id = $c::inverse_dynamics(&q, &qd, &qdd);
            close(
                "ID vs unrolled",
                &id,
                &$u::inverse_dynamics(&q, &qd, &qdd),
                1e-12,
            );
            let idi = alg.inverse_dynamics(&p, &q, &qd, &qdd, &loads);
            close("ID vs interpreted", &id, &idi, 1e-12);
            let fd = $c::forward_dynamics(&q, &qd, &tau);
            close(
                "FD vs unrolled",
                &fd,
                &$u::forward_dynamics(&q, &qd, &tau),
                1e-10,
            );
            let with_tau = Loads {
                tau: Some(tau.to_vec()),
                ..loads.clone()
            };
            close(
                "FD vs interpreted",
                &fd,
                &alg.forward_dynamics(&p, &q, &qd, &with_tau),
                1e-10,
            );
            // M q̈ + c = τ at the ABA's q̈.
            let back: Vec<f64> = (0..$n)
                .map(|i| (0..$n).map(|j| m[i][j] * fd[j]).sum::<f64>() + c[i])
                .collect();
            close("M FD + c = τ", &back, &tau, 1e-10);
            let fw = $c::forward_dynamics_with_wrenches(&q, &qd, &tau, &f_ext);
            let fwu = $u::forward_dynamics_with_wrenches(&q, &qd, &tau, &f_ext);
            close("FD with wrenches vs unrolled", &fw, &fwu, 1e-10);
        }
    }};
}

#[test]
fn compact_chain_with_gravity_equals_unrolled_and_interpreted() {
    compare!(Chain3C, Chain3U, 3, "chain3", Some(G));
    let q = [0.3, -0.2, 1.1];
    close(
        "gravity",
        &Chain3C::gravity(&q),
        &Chain3U::gravity(&q),
        1e-12,
    );
    close(
        "gravity = c(q̇ = 0)",
        &Chain3C::gravity(&q),
        &Chain3C::nonlinear_effects(&q, &[0.0; 3]),
        1e-15,
    );
}

#[test]
fn compact_chain_in_space_equals_unrolled_and_interpreted() {
    compare!(Chain12C, Chain12U, 12, "chain12", None);
}

#[test]
fn compact_trees_equal_unrolled_and_interpreted() {
    compare!(Tree7C, Tree7U, 7, "tree7", Some(G));
    compare!(Tree10C, Tree10U, 10, "tree10", None);
}

#[test]
fn compact_f32_is_close_to_f64() {
    let mut r = rng(5);
    let q: [f64; 12] = arr(random_vec(&mut r, 12, 2.0));
    let qd: [f64; 12] = arr(random_vec(&mut r, 12, 1.0));
    let tau: [f64; 12] = arr(random_vec(&mut r, 12, 20.0));
    let (q32, qd32, tau32) = (
        q.map(|x| x as f32),
        qd.map(|x| x as f32),
        tau.map(|x| x as f32),
    );
    let up = |v: &[f32]| v.iter().map(|x| f64::from(*x)).collect::<Vec<_>>();
    let m: Vec<f64> = Chain12F32::mass_matrix(&q32)
        .iter()
        .flat_map(|r| up(r))
        .collect();
    close("M f32", &m, &flat(&Chain12C::mass_matrix(&q)), 1e-4);
    close(
        "c f32",
        &up(&Chain12F32::nonlinear_effects(&q32, &qd32)),
        &Chain12C::nonlinear_effects(&q, &qd),
        1e-4,
    );
    close(
        "FD f32",
        &up(&Chain12F32::forward_dynamics(&q32, &qd32, &tau32)),
        &Chain12C::forward_dynamics(&q, &qd, &tau),
        1e-3,
    );
}

kanegen::dynamics!(
    Ur5C,
    "tests/data/erd/ur5_robot.urdf",
    form = "compact",
    gravity = [0.0, 0.0, -9.81]
);
kanegen::dynamics!(
    Ur5U,
    "tests/data/erd/ur5_robot.urdf",
    form = "unrolled",
    gravity = [0.0, 0.0, -9.81]
);

/// The compact frame functions (loops over the support path, `kanegen_runtime::compact::frames`)
/// equal the unrolled ones on UR5's frames: two on the wrist, two on the base.
#[test]
fn compact_frames_equal_unrolled() {
    let placement = |(x, r): ([f64; 3], [[f64; 3]; 3])| -> Vec<f64> {
        x.into_iter().chain(r.into_iter().flatten()).collect()
    };
    let jac = |j: [[f64; 6]; 6]| -> Vec<f64> { j.into_iter().flatten().collect() };
    let mut r = rng(17);
    for _ in 0..20 {
        let q: [f64; 6] = arr(random_vec(&mut r, 6, 3.0));
        close(
            "ee_link placement",
            &placement(Ur5C::ee_link_placement(&q)),
            &placement(Ur5U::ee_link_placement(&q)),
            1e-14,
        );
        close(
            "tool0 placement",
            &placement(Ur5C::tool0_placement(&q)),
            &placement(Ur5U::tool0_placement(&q)),
            1e-14,
        );
        close(
            "base_link placement",
            &placement(Ur5C::base_link_placement(&q)),
            &placement(Ur5U::base_link_placement(&q)),
            1e-15,
        );
        close(
            "ee_link jacobian",
            &jac(Ur5C::ee_link_jacobian(&q)),
            &jac(Ur5U::ee_link_jacobian(&q)),
            1e-14,
        );
        close(
            "tool0 jacobian",
            &jac(Ur5C::tool0_jacobian(&q)),
            &jac(Ur5U::tool0_jacobian(&q)),
            1e-14,
        );
        assert_eq!(Ur5C::base_jacobian(&q), [[0.0; 6]; 6]);
        close(
            "M",
            &flat(&Ur5C::mass_matrix(&q)),
            &flat(&Ur5U::mass_matrix(&q)),
            1e-13,
        );
    }
}

kanegen::dynamics!(
    B1Z1C,
    "tests/data/erd/b1-z1.urdf",
    base = "free-floating",
    form = "compact",
    gravity = [0.0, 0.0, -9.81]
);

/// The compact form on a free-floating base (B1 + Z1, a 19-joint tree; the kernels of
/// `kanegen_runtime::compact::floating` and `::floating_frames`) against the interpreted
/// local-frame algorithms: `M`, `c`, inverse dynamics, forward dynamics with and without
/// wrenches, `(M, c)`, the momentum, the base reaction, the derivatives and `M⁻¹`, and the
/// placement, Jacobian and generalized Jacobian of a foot, a frame on the base and the arm's
/// gripper.
#[test]
fn compact_free_floating_equals_interpreted() {
    use kanegen::dynamics::algorithms::{aba, derivatives, floating, frames, momentum, rnea};
    use kanegen::dynamics::base::{quat_to_matrix, FloatingBase, FloatingState, BASE_BODY};
    use kanegen::dynamics::{ExternalWrench, LoadFrame, MassMatrixMethod};
    const N: usize = 19;
    let mut model = kanegen::model::io::load_model(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/erd/b1-z1.urdf"
    )))
    .unwrap();
    model = model
        .with_base_kind(kanegen::model::BaseKind::FreeFloating)
        .unwrap();
    let p = Params::<f64>::new(&model);
    let fb = FloatingBase::<f64>::from_inertial(model.base_inertial().unwrap());
    let mut r = rng(23);
    for _ in 0..5 {
        let w = random_vec(&mut r, 4, 1.0);
        let norm = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        let quat = [w[0] / norm, w[1] / norm, w[2] / norm, w[3] / norm];
        let qj = random_vec(&mut r, N, 1.5);
        let q: [f64; N + 7] = arr([0.2, -0.1, 0.4]
            .into_iter()
            .chain(quat)
            .chain(qj.iter().copied())
            .collect());
        let v: [f64; N + 6] = arr(random_vec(&mut r, N + 6, 1.0));
        let a: [f64; N + 6] = arr(random_vec(&mut r, N + 6, 1.0));
        let tau: [f64; N] = arr(random_vec(&mut r, N, 10.0));
        let f_ext: [[f64; 6]; N + 1] =
            core::array::from_fn(|k| core::array::from_fn(|i| ((6 * k + i) as f64).sin()));
        let st = FloatingState {
            position: Vec3::new(q[0], q[1], q[2]),
            rotation: quat_to_matrix(&quat),
            v_b: Vec3::new(v[0], v[1], v[2]),
            omega_b: Vec3::new(v[3], v[4], v[5]),
        };
        let loads = Loads {
            tau: Some(tau.to_vec()),
            gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
            external: vec![],
        };
        let passive = Loads {
            tau: None,
            ..loads.clone()
        };
        let m = floating::mass_matrix(MassMatrixMethod::Crba, &p, &fb, &st, &qj);
        close("M", &flat(&B1Z1C::mass_matrix(&q)), &m.concat(), 1e-12);
        let c: Vec<f64> = rnea::floating_tau_minus_c(&p, &fb, &st, &qj, &v[6..], &passive)
            .iter()
            .map(|x| -x)
            .collect();
        close("c", &B1Z1C::nonlinear_effects(&q, &v), &c, 1e-12);
        let (mm, cc) = B1Z1C::mass_matrix_and_nonlinear_effects(&q, &v);
        close(
            "(M, c)",
            &[flat(&mm), cc.to_vec()].concat(),
            &[m.concat(), c].concat(),
            1e-12,
        );
        let acc: [f64; 6] = core::array::from_fn(|i| a[i]);
        let id =
            rnea::floating_inverse_dynamics(&p, &fb, &st, &qj, &v[6..], &acc, &a[6..], &passive);
        close(
            "inverse dynamics",
            &B1Z1C::inverse_dynamics(&q, &v, &a),
            &id,
            1e-12,
        );
        let fd = aba::floating(&p, &fb, &st, &qj, &v[6..], &loads);
        close(
            "forward dynamics",
            &B1Z1C::forward_dynamics(&q, &v, &tau),
            &fd,
            1e-11,
        );
        let mut with = loads.clone();
        with.external = f_ext
            .iter()
            .enumerate()
            .map(|(k, f)| ExternalWrench {
                body: if k == 0 { BASE_BODY } else { k - 1 },
                frame: LoadFrame::Body,
                force: Vec3::new(f[0], f[1], f[2]),
                moment: Vec3::new(f[3], f[4], f[5]),
            })
            .collect();
        let fdw = aba::floating(&p, &fb, &st, &qj, &v[6..], &with);
        close(
            "forward dynamics with wrenches",
            &B1Z1C::forward_dynamics_with_wrenches(&q, &v, &tau, &f_ext),
            &fdw,
            1e-11,
        );
        let (lin, ang) = momentum::momentum(&p, &fb, &st, &qj, &v[6..]);
        let h = [lin.0, ang.0].concat();
        close("momentum", &B1Z1C::momentum(&q, &v), &h, 1e-12);
        let reaction = rnea::base_reaction(&p, &st, &qj, &v[6..], &acc, &a[6..], &passive);
        close(
            "base reaction",
            &B1Z1C::base_reaction(&q, &v, &a),
            &reaction,
            1e-12,
        );
        type Placement = ([f64; 3], [[f64; 3]; 3]);
        type Frame = (
            &'static str,
            fn(&[f64; N + 7]) -> Placement,
            fn(&[f64; N + 7]) -> [[f64; N + 6]; 6],
            fn(&[f64; N + 7]) -> [[f64; N]; 6],
        );
        let frames: [Frame; 3] = [
            (
                "FR_foot",
                B1Z1C::fr_foot_placement,
                B1Z1C::fr_foot_jacobian,
                B1Z1C::fr_foot_generalized_jacobian,
            ),
            (
                "trunk",
                B1Z1C::trunk_placement,
                B1Z1C::trunk_jacobian,
                B1Z1C::trunk_generalized_jacobian,
            ),
            (
                "gripperStator",
                B1Z1C::gripperstator_placement,
                B1Z1C::gripperstator_jacobian,
                B1Z1C::gripperstator_generalized_jacobian,
            ),
        ];
        let g = Vec3::new(0.0, 0.0, -9.81);
        let (dq, dv) = B1Z1C::inverse_dynamics_derivatives(&q, &v, &a);
        let (wq, wv) = derivatives::rnea::floating_derivatives(
            &p,
            &fb,
            &st,
            &qj,
            &v[6..],
            &acc,
            &a[6..],
            Some(&g),
        );
        close(
            "(∂τ/∂q, ∂τ/∂v)",
            &[dq.as_flattened(), dv.as_flattened()].concat(),
            &[wq.concat(), wv.concat()].concat(),
            1e-12,
        );
        let (aq, av, minv) = B1Z1C::forward_dynamics_derivatives(&q, &v, &tau);
        let (wq, wv, winv) =
            derivatives::aba::floating_derivatives(&p, &fb, &st, &qj, &v[6..], &tau, Some(&g));
        close(
            "(∂v̇/∂q, ∂v̇/∂v, M⁻¹)",
            &[aq.as_flattened(), av.as_flattened(), minv.as_flattened()].concat(),
            &[wq.concat(), wv.concat(), winv.concat()].concat(),
            1e-10,
        );
        close(
            "M⁻¹",
            B1Z1C::mass_matrix_inverse(&q).as_flattened(),
            &winv.concat(),
            1e-10,
        );
        for (name, placement, jacobian, generalized) in frames {
            let k = model.frames().iter().position(|f| f.name == name).unwrap();
            let fp = &p.frames[k];
            let (x, rot) = placement(&q);
            let (want_x, want_r) = frames::floating_placement(&p, &st, &qj, fp);
            close(
                name,
                &[x.as_slice(), rot.as_flattened()].concat(),
                &[want_x.0.as_slice(), want_r.0.as_flattened()].concat(),
                1e-13,
            );
            let want = frames::floating_jacobian(&p, &st, &qj, fp).concat();
            close(name, jacobian(&q).as_flattened(), &want, 1e-13);
            let want = frames::generalized_jacobian(&p, &fb, &st, &qj, fp).concat();
            close(name, generalized(&q).as_flattened(), &want, 1e-12);
        }
    }
}
