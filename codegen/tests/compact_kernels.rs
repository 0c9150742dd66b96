//! The compact form's runtime kernels (`kanegen_runtime::compact`) on the tables the generator
//! emits ([`kanegen_codegen::compact::tables::numbers`]): in f64 they agree with the
//! interpreted algorithms of `kanegen_dynamics` on random chains and trees with prismatic
//! joints (regrouped or not, with and without gravity, a runtime payload, external wrenches);
//! and the operation counts a compact type reports (`OP_COUNTS`) are what the kernels execute,
//! counted independently of the tracer by a scalar that counts its own operations.

use kanegen_codegen::compact::kernel_counts;
use kanegen_codegen::compact::tables::{numbers, KernelTables};
use kanegen_codegen::{generate_items, Form, Options};
use kanegen_dynamics::kernels::TablesIn as Owned;
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::metrics::rel_err;
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads, Methods, Params};
use kanegen_model::random::{random_chain, random_tree, random_vec, rng, ChainSpec};
use kanegen_model::Model;
use kanegen_runtime::compact as k;
use kanegen_runtime::Scalar;
use kanegen_trace::Function;
use std::cell::Cell;
use std::ops::{Add, Div, Mul, Neg, Sub};

const G: [f64; 3] = [0.3, -1.2, -9.81];

fn spec(n: usize) -> ChainSpec {
    ChainSpec {
        n,
        prismatic_fraction: 0.3,
        ..Default::default()
    }
}

fn arr<const N: usize>(v: Vec<f64>) -> [f64; N] {
    core::array::from_fn(|i| v[i])
}

fn close(what: &str, x: &[f64], y: &[f64], tol: f64) {
    let e = rel_err(x, y);
    assert!(e < tol, "{what}: relative error {e:e}\n{x:?}\n{y:?}");
}

const PAYLOAD: (f64, [f64; 3], [[f64; 3]; 3]) = (
    7.5,
    [0.1, -0.2, 0.3],
    [[0.4, 0.01, -0.02], [0.01, 0.5, 0.03], [-0.02, 0.03, 0.6]],
);

/// Every kernel against the interpreted algorithms (`Methods::SPATIAL`, RBDA's CRBA and RNEA;
/// forward dynamics by LDLᵀ on them) for one model and options.
fn agree<const N: usize>(model: &Model, opts: &Options) {
    let numbers = numbers(model, opts);
    let owned = Owned::new(&numbers, |x| x);
    let t = owned.tables(&numbers);
    let inertia: [[f64; 10]; N] = if opts.runtime_payload {
        k::with_payload(t.inertia, PAYLOAD.0, &PAYLOAD.1, &PAYLOAD.2)
    } else {
        core::array::from_fn(|j| t.inertia[j])
    };
    let mut p = Params::<f64>::new(model);
    if let (true, Some(last)) = (opts.runtime_payload, p.joints.last_mut()) {
        last.set_inertial(PAYLOAD.0, Vec3(PAYLOAD.1), Mat3(PAYLOAD.2));
    }
    let alg = Methods::SPATIAL;
    let sc = |x: f64| x.sin_cos();
    for seed in 0..5 {
        let mut r = rng(seed);
        let q: [f64; N] = arr(random_vec(&mut r, N, 2.0));
        let qd: [f64; N] = arr(random_vec(&mut r, N, 1.0));
        let qdd: [f64; N] = arr(random_vec(&mut r, N, 1.0));
        let tau: [f64; N] = arr(random_vec(&mut r, N, 20.0));
        let f_ext: [[f64; 6]; N] = core::array::from_fn(|_| arr(random_vec(&mut r, 6, 3.0)));
        let loads = Loads {
            gravity: opts.gravity.map(|g| Vec3::new(g[0], g[1], g[2])),
            ..Loads::default()
        };
        let m = k::mass_matrix(&t, &inertia, &q, sc);
        let mi = alg.mass_matrix.mass_matrix(&p, &q);
        close("M", m.as_flattened(), &mi.concat(), 1e-12);
        let c = k::nonlinear_effects(&t, &inertia, &q, &qd, sc);
        let ci: Vec<f64> = alg
            .nonlinear_effects
            .tau_minus_c(&p, &q, &qd, &loads)
            .iter()
            .map(|b| -b)
            .collect();
        close("c", &c, &ci, 1e-12);
        assert_eq!(
            k::mass_matrix_and_nonlinear_effects(&t, &inertia, &q, &qd, sc),
            (m, c),
            "M + c in one call"
        );
        let g = k::gravity(&t, &inertia, &q, sc);
        let gi: Vec<f64> = alg
            .nonlinear_effects
            .tau_minus_c(&p, &q, &[0.0; N], &loads)
            .iter()
            .map(|b| -b)
            .collect();
        close("g", &g, &gi, 1e-12);
        let id = k::inverse_dynamics(&t, &inertia, &q, &qd, &qdd, sc);
        close(
            "ID",
            &id,
            &alg.inverse_dynamics(&p, &q, &qd, &qdd, &loads),
            1e-12,
        );
        let fd = k::forward_dynamics(&t, &inertia, &q, &qd, &tau, sc);
        let with_tau = Loads {
            tau: Some(tau.to_vec()),
            ..loads.clone()
        };
        close(
            "FD",
            &fd,
            &alg.forward_dynamics(&p, &q, &qd, &with_tau),
            1e-10,
        );
        let fw = k::forward_dynamics_with_wrenches(&t, &inertia, &q, &qd, &tau, &f_ext, sc);
        let wrenches = Loads {
            external: f_ext
                .iter()
                .enumerate()
                .map(|(body, e)| ExternalWrench {
                    body,
                    frame: LoadFrame::Body,
                    force: Vec3::new(e[0], e[1], e[2]),
                    moment: Vec3::new(e[3], e[4], e[5]),
                })
                .collect(),
            ..with_tau
        };
        close(
            "FD with wrenches",
            &fw,
            &alg.forward_dynamics(&p, &q, &qd, &wrenches),
            1e-10,
        );
        assert!(rel_err(&fw, &fd) > 1e-6, "the wrenches matter");
    }
}

#[test]
fn kernels_agree_with_the_interpreted_algorithms() {
    let chain = random_chain(&spec(6), 31);
    let tree = random_tree(&spec(9), 32);
    assert!(!tree.is_chain());
    for (regroup, gravity, runtime_payload) in [
        (true, Some(G), false),
        (false, None, false),
        (true, Some(G), true),
        (false, None, true),
    ] {
        let mut o = Options::new("Arm");
        o.regroup = regroup;
        o.gravity = gravity;
        o.runtime_payload = runtime_payload;
        agree::<6>(&chain, &o);
        agree::<9>(&tree, &o);
    }
}

// ---------------------------------------------------------------------------------------------
// Operation counts.

thread_local! {
    /// `[mul, add, div, sincos]` since the last [`take`].
    static OPS: Cell<[u64; 4]> = const { Cell::new([0; 4]) };
}

fn bump(k: usize) {
    OPS.with(|c| {
        let mut v = c.get();
        v[k] += 1;
        c.set(v);
    });
}

fn take() -> [u64; 4] {
    OPS.with(|c| c.replace([0; 4]))
}

/// An `f64` that counts the operations done on it (sign changes free, as in the tracer's
/// conventions).
#[derive(Clone, Copy, Debug)]
struct Counted(f64);

macro_rules! counted_op {
    ($tr:ident, $f:ident, $op:tt, $k:expr) => {
        impl $tr for Counted {
            type Output = Counted;
            fn $f(self, o: Counted) -> Counted {
                bump($k);
                Counted(self.0 $op o.0)
            }
        }
    };
}
counted_op!(Add, add, +, 1);
counted_op!(Sub, sub, -, 1);
counted_op!(Mul, mul, *, 0);
counted_op!(Div, div, /, 2);

impl Neg for Counted {
    type Output = Counted;
    fn neg(self) -> Counted {
        Counted(-self.0)
    }
}

impl Scalar for Counted {
    fn constant(x: f64) -> Self {
        Counted(x)
    }
    fn sin(self) -> Self {
        bump(3);
        Counted(self.0.sin())
    }
    fn cos(self) -> Self {
        bump(3);
        Counted(self.0.cos())
    }
    fn sqrt(self) -> Self {
        Counted(self.0.sqrt())
    }
    fn sin_cos(self) -> (Self, Self) {
        bump(3);
        let (s, c) = self.0.sin_cos();
        (Counted(s), Counted(c))
    }
}

/// The operations each compact function's kernel executes, counted by running it on
/// [`Counted`].
fn counted<const N: usize>(t: &KernelTables, f: Function, payload: bool) -> [u64; 4] {
    let t_frames = &t.frames;
    let owned = Owned::new(t, Counted);
    let t = owned.tables(t);
    let x = |k: usize| Counted(0.1 + 0.01 * k as f64);
    let v: [Counted; N] = core::array::from_fn(x);
    let sc = |a: Counted| a.sin_cos();
    take();
    let inertia: [[Counted; 10]; N] = if payload {
        k::with_payload(t.inertia, x(1), &[x(2), x(3), x(4)], &[[x(5); 3]; 3])
    } else {
        core::array::from_fn(|j| t.inertia[j])
    };
    match f {
        Function::MassMatrix => _ = k::mass_matrix(&t, &inertia, &v, sc),
        Function::NonlinearEffects => _ = k::nonlinear_effects(&t, &inertia, &v, &v, sc),
        Function::Gravity => _ = k::gravity(&t, &inertia, &v, sc),
        Function::InverseDynamics => _ = k::inverse_dynamics(&t, &inertia, &v, &v, &v, sc),
        Function::MassMatrixAndNonlinearEffects => {
            _ = k::mass_matrix_and_nonlinear_effects(&t, &inertia, &v, &v, sc);
        }
        Function::ForwardDynamics => _ = k::forward_dynamics(&t, &inertia, &v, &v, &v, sc),
        Function::ForwardDynamicsWithWrenches => {
            let f_ext = [[x(6); 6]; N];
            _ = k::forward_dynamics_with_wrenches(&t, &inertia, &v, &v, &v, &f_ext, sc);
        }
        Function::InverseDynamicsDerivatives => {
            _ = k::derivatives::inverse_dynamics_derivatives(&t, &inertia, &v, &v, &v, sc);
        }
        Function::ForwardDynamicsDerivatives => {
            _ = k::derivatives::forward_dynamics_derivatives(&t, &inertia, &v, &v, &v, sc);
        }
        Function::MassMatrixInverse => {
            _ = k::derivatives::mass_matrix_inverse(&t, &inertia, &v, sc);
        }
        Function::FramePlacement(k) | Function::FrameJacobian(k) => {
            let frame = counted_frame(&t_frames[k]);
            if let Function::FramePlacement(_) = f {
                _ = k::frame_placement(&t, &frame, &v, sc);
            } else {
                _ = k::frame_jacobian(&t, &frame, &v, sc);
            }
        }
        _ => unreachable!("{f:?} has no kernel"),
    }
    take()
}

/// A frame of the tables on [`Counted`].
fn counted_frame(fr: &k::Frame<f64>) -> k::Frame<Counted> {
    k::Frame {
        body: fr.body,
        translation: fr.translation.map(Counted),
        rotation: fr.rotation.map(|r| r.map(Counted)),
    }
}

/// The derivative kernels (fixed base).
const DERIVATIVES: [Function; 3] = [
    Function::InverseDynamicsDerivatives,
    Function::ForwardDynamicsDerivatives,
    Function::MassMatrixInverse,
];

const KERNELS: [Function; 7] = [
    Function::MassMatrix,
    Function::NonlinearEffects,
    Function::Gravity,
    Function::InverseDynamics,
    Function::MassMatrixAndNonlinearEffects,
    Function::ForwardDynamics,
    Function::ForwardDynamicsWithWrenches,
];

/// A compact type's `OP_COUNTS` entry of a kernel function is the tracer's count of that kernel
/// (`kernel_counts`), and that count is what the kernel executes ([`Counted`]); a kernel
/// changed without the counts following fails here.
fn counts_follow<const N: usize>(model: &Model, opts: &Options) {
    let t = numbers(model, opts);
    let items = generate_items(model, opts)
        .unwrap()
        .items
        .to_string()
        .replace(' ', "");
    let frames =
        (0..t.frames.len()).flat_map(|k| [Function::FramePlacement(k), Function::FrameJacobian(k)]);
    for f in KERNELS.into_iter().chain(DERIVATIVES).chain(frames) {
        if f == Function::Gravity && opts.gravity.is_none() {
            continue; // no `gravity` function in space
        }
        let c = kernel_counts(model, opts, f).expect("a kernel function");
        let ran = counted::<N>(&t, f, opts.runtime_payload);
        assert_eq!(
            [c.mul, c.add, c.div, c.sincos],
            ran,
            "{f:?} of {}",
            model.name()
        );
        // A frame on the base costs nothing; every other kernel computes.
        let on_base = match f {
            Function::FramePlacement(k) | Function::FrameJacobian(k) => t.frames[k].body.is_none(),
            _ => false,
        };
        assert_eq!(c.mul > 0 && c.add > 0, !on_base, "{f:?}");
        // The generated type reports them.
        let name = match f {
            Function::FramePlacement(k) => format!("{}_placement", model.frames()[k].name),
            Function::FrameJacobian(k) => format!("{}_jacobian", model.frames()[k].name),
            _ => f.name().to_string(),
        };
        let entry = format!(
            "function:\"{}\",mass_matrix_method:::core::option::Option::{}",
            name,
            if f.uses_mass_matrix() && !f.is_forward_dynamics() {
                "Some(\"crba\")"
            } else {
                "None"
            }
        );
        let at = items
            .find(&entry)
            .unwrap_or_else(|| panic!("no `{entry}` in OP_COUNTS"));
        let end = at + items[at..].find('}').unwrap();
        let reported = &items[at..end];
        assert!(
            reported.contains(&format!(
                "mul:{}u64,add:{}u64,div:{}u64",
                c.mul, c.add, c.div
            )),
            "{reported}"
        );
    }
}

#[test]
fn op_counts_of_compact_types_are_what_the_kernels_execute() {
    let mut o = Options::new("Arm");
    o.form = Form::Compact;
    o.gravity = Some(G);
    counts_follow::<5>(&random_chain(&spec(5), 41), &o);
    counts_follow::<7>(&random_tree(&spec(7), 42), &o);
    o.runtime_payload = true;
    o.gravity = None;
    counts_follow::<7>(&random_tree(&spec(7), 43), &o);
    // UR5's four frames (two on the base, two on the wrist) in the compact form.
    let ur5 =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/erd/ur5_robot.urdf");
    let ur5 = kanegen_model::io::load_model(&ur5).unwrap();
    assert_eq!(ur5.frames().len(), 4);
    o.runtime_payload = false;
    counts_follow::<6>(&ur5, &o);
}

/// The counts follow the kernels above 64 joints too (the kernels are traced for any number of
/// joints), on a chain and a tree.
#[test]
fn op_counts_of_large_compact_types_are_what_the_kernels_execute() {
    let mut o = Options::new("Arm");
    o.form = Form::Compact;
    o.gravity = Some(G);
    counts_follow::<70>(&random_chain(&spec(70), 44), &o);
    o.runtime_payload = true;
    counts_follow::<66>(&random_tree(&spec(66), 45), &o);
}

/// The operations a free-floating compact function's kernel executes
/// (`kanegen_runtime::compact::floating`), counted by running it on [`Counted`].
fn counted_floating<const N: usize, const NV: usize>(t: &KernelTables, f: Function) -> [u64; 4] {
    use k::derivatives as dk;
    use k::floating as fk;
    use k::floating_frames as ff;
    let frames = &t.frames;
    let base = t.base.expect("a free-floating model");
    let base = fk::Base {
        inertia: base.inertia.map(Counted),
        gravity: base.gravity.map(|g| g.map(Counted)),
    };
    let owned = Owned::new(t, Counted);
    let t = owned.tables(t);
    let x = |k: usize| Counted(0.1 + 0.01 * k as f64);
    let q: [Counted; 64] = core::array::from_fn(x);
    let (q, v) = (&q[..N + 7], &q[..NV]);
    let tau: [Counted; N] = core::array::from_fn(x);
    let f_ext = [[x(6); 6]; 64];
    let sc = |a: Counted| a.sin_cos();
    let inertia = t.inertia;
    take();
    match f {
        Function::MassMatrix => _ = fk::mass_matrix::<_, N, NV>(&t, inertia, &base, q, sc),
        Function::NonlinearEffects => {
            _ = fk::inverse_dynamics::<_, N, NV>(&t, inertia, &base, q, Some(v), None, sc);
        }
        Function::Gravity => {
            _ = fk::inverse_dynamics::<_, N, NV>(&t, inertia, &base, q, None, None, sc);
        }
        Function::InverseDynamics => {
            _ = fk::inverse_dynamics::<_, N, NV>(&t, inertia, &base, q, Some(v), Some(v), sc);
        }
        Function::MassMatrixAndNonlinearEffects => {
            _ = fk::mass_matrix_and_nonlinear_effects::<_, N, NV>(&t, inertia, &base, q, v, sc);
        }
        Function::ForwardDynamics => {
            _ = fk::forward_dynamics::<_, N, NV>(&t, inertia, &base, q, v, &tau, None, sc);
        }
        Function::ForwardDynamicsWithWrenches => {
            let w = Some(&f_ext[..=N]);
            _ = fk::forward_dynamics::<_, N, NV>(&t, inertia, &base, q, v, &tau, w, sc);
        }
        Function::Momentum => _ = fk::momentum::<_, N>(&t, inertia, &base, q, v, sc),
        Function::InverseDynamicsDerivatives => {
            _ = dk::floating_inverse_dynamics_derivatives::<_, N, NV>(
                &t, inertia, &base, q, v, v, sc,
            );
        }
        Function::ForwardDynamicsDerivatives => {
            _ = dk::floating_forward_dynamics_derivatives::<_, N, NV>(
                &t, inertia, &base, q, v, &tau, sc,
            );
        }
        Function::MassMatrixInverse => {
            _ = dk::floating_mass_matrix_inverse::<_, N, NV>(&t, inertia, &base, q, sc);
        }
        Function::BaseReaction => {
            _ = fk::base_reaction::<_, N>(&t, inertia, &base, q, v, v, sc);
        }
        Function::FramePlacement(k) => {
            _ = ff::frame_placement::<_, N>(&t, &counted_frame(&frames[k]), q, sc);
        }
        Function::FrameJacobian(k) => {
            _ = ff::frame_jacobian::<_, N, NV>(&t, &counted_frame(&frames[k]), q, sc);
        }
        Function::GeneralizedJacobian(k) => {
            let frame = counted_frame(&frames[k]);
            _ = ff::generalized_jacobian::<_, N>(&t, inertia, &base, &frame, q, sc);
        }
        _ => unreachable!("{f:?} has no floating kernel"),
    }
    take()
}

/// A free-floating compact type's `OP_COUNTS` of its kernel functions are what the floating
/// kernels execute, on SSRMS (a chain) and a two-armed tree with three frames, with gravity (so
/// `gravity` has a kernel too): the dynamics, the momentum, the base reaction and each frame's
/// placement, Jacobian and generalized Jacobian.
#[test]
fn op_counts_of_free_floating_compact_types_are_what_the_kernels_execute() {
    fn check<const N: usize, const NV: usize>(model: &Model) {
        let mut o = Options::new("Arm");
        o.form = Form::Compact;
        o.gravity = Some(G);
        let model = &model
            .clone()
            .with_base_kind(kanegen_model::BaseKind::FreeFloating)
            .unwrap();
        let t = numbers(model, &o);
        let frames = (0..t.frames.len()).flat_map(|k| {
            [
                Function::FramePlacement(k),
                Function::FrameJacobian(k),
                Function::GeneralizedJacobian(k),
            ]
        });
        let floating_only = [Function::Momentum, Function::BaseReaction];
        let all = KERNELS.into_iter().chain(DERIVATIVES).chain(floating_only);
        for f in all.chain(frames) {
            let c = kernel_counts(model, &o, f).expect("a kernel function");
            let ran = counted_floating::<N, NV>(&t, f);
            assert_eq!(
                [c.mul, c.add, c.div, c.sincos],
                ran,
                "{f:?} of {}",
                model.name()
            );
            assert!(c.mul > 0 && c.add > 0);
        }
    }
    let ssrms = kanegen_model::io::load_model(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/ssrms.toml"),
    )
    .unwrap();
    check::<7, 13>(&ssrms);
    let dextre = kanegen_model::io::load_model(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/dextre_standin.toml"),
    )
    .unwrap();
    assert!(!dextre.is_chain());
    check::<14, 20>(&dextre);
}
