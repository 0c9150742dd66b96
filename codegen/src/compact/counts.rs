//! The operation counts of a compact type's functions: the runtime kernels
//! (`kanegen_runtime::compact`) run on the tracer [`Sym`], with every number of the tables, the
//! payload and the arguments a symbolic *input* (so no constant folding hides a multiplication
//! that the loops really do), counted under [`Convention::Paper`]: every operation the kernel
//! executes, which is what the compiled loops execute (their tables are read from memory). The
//! derivative kernels, O(N³), run on the counting scalar [`Tally`] instead (no graph).
//!
//! The kernels' cores take slices of any length with caller-provided scratch, so one instance on
//! `Sym` traces a model of any number of joints, its storage in `Vec`s. Each function is traced
//! as its const-`N` entry point composes it: the joint transforms
//! (`kanegen_runtime::compact::spatial::transforms`), then the CRBA, the RNEA or the ABA
//! (`codegen/tests/compact_kernels.rs` counts the entry points themselves with a counting `f64`
//! and compares).

use crate::compact::tables::KernelTables;
use crate::compact::tally::{self, Tally};
use kanegen_dynamics::kernels::{ArticulatedVecs, BodyVecs};
use kanegen_runtime::compact::{self as k, Bodies, Motions, Rates, Tables, Transform};
use kanegen_runtime::Scalar;
use kanegen_trace::sym::{Convention, Counts, Sym, Tracer};
use kanegen_trace::Function;

/// The traced counts of the kernel that the compact body of `f` calls on a model with tables
/// `t` (`payload`: the last body's inertia built from a runtime payload per call), or `None`
/// for a function without a compact body.
#[must_use]
pub fn counts(t: &KernelTables, f: Function, payload: bool) -> Option<Counts> {
    if f.is_derivative() {
        return Some(derivative_counts(t, f, payload));
    }
    let tr = Tracer::new();
    let n = t.parent.len();
    let x = || tr.input("x");
    let v3 = || -> [Sym; 3] { core::array::from_fn(|_| x()) };
    let m3 = || -> [[Sym; 3]; 3] { core::array::from_fn(|_| v3()) };
    let each = |make: &dyn Fn() -> [[Sym; 3]; 3]| (0..n).map(|_| make()).collect::<Vec<_>>();
    let (a, b, c) = (each(&m3), each(&m3), each(&m3));
    let (l, slide): (Vec<_>, Vec<_>) = (0..n).map(|_| (v3(), v3())).unzip();
    let s: Vec<[Sym; 6]> = (0..n).map(|_| core::array::from_fn(|_| x())).collect();
    let mut inertia: Vec<[Sym; 10]> = (0..n).map(|_| core::array::from_fn(|_| x())).collect();
    if payload {
        if let Some(last) = inertia.last_mut() {
            *last = k::payload_inertia(x(), &v3(), &m3());
        }
    }
    let ancestor: Option<Vec<bool>> = t.ancestor.clone();
    let tables = Tables {
        parent: &t.parent,
        revolute: &t.revolute,
        a: &a,
        b: &b,
        c: &c,
        l: &l,
        slide: &slide,
        s: &s,
        inertia: &inertia,
        ancestor: ancestor.as_deref(),
        a0: core::array::from_fn(|_| x()),
    };
    let joints = || -> Vec<Sym> { (0..n).map(|_| x()).collect() };
    let q = joints();
    let out = match f {
        Function::FramePlacement(k) | Function::FrameJacobian(k) if t.base.is_none() => {
            let fr = t.frames.get(k)?;
            let frame = k::Frame {
                body: fr.body,
                translation: v3(),
                rotation: m3(),
            };
            trace_frame(&tables, f, &frame, &q)
        }
        _ => match &t.base {
            Some(base) => {
                let base = k::floating::Base {
                    inertia: core::array::from_fn(|_| x()),
                    gravity: base.gravity.map(|_| v3()),
                };
                let frame = f.frame().and_then(|k| t.frames.get(k)).map(|fr| k::Frame {
                    body: fr.body,
                    translation: v3(),
                    rotation: m3(),
                });
                trace_floating(&tables, f, &base, frame.as_ref(), n, &x)?
            }
            None => trace_kernel(&tables, f, &q, &mut || joints(), &x)?,
        },
    };
    Some(tr.finish(&out).counts(Convention::Paper))
}

/// The outputs of `f`'s kernel on `tables` at `q`, as its entry point computes them
/// (`arg`: a fresh vector of joint inputs, `x`: a fresh input), its scratch in `Vec`s.
fn trace_kernel(
    tables: &Tables<'_, Sym>,
    f: Function,
    q: &[Sym],
    arg: &mut dyn FnMut() -> Vec<Sym>,
    x: &dyn Fn() -> Sym,
) -> Option<Vec<Sym>> {
    let n = q.len();
    let zero = Sym::zero();
    let mut store = BodyVecs::<Sym>::new(n);
    let mut b = store.bodies();
    let inertia = tables.inertia;
    let mut m = vec![[[zero; 6]; 3]; n];
    let mut out = vec![zero; n];
    let mut rnea = |b: &Bodies<'_, Sym>, motions: Motions<'_, Sym>| {
        k::rnea::rnea(tables, b.x, inertia, motions, &mut m, &mut out);
        out.clone()
    };
    let sincos = |a: Sym| a.sin_cos();
    if !crate::compact::has_body(f, false) {
        return None;
    }
    k::spatial::transforms(tables, q, sincos, b.x);
    let (qd, qdd) = (arg(), arg());
    let (velocity, rates) = (
        Motions::velocity(&qd),
        Motions {
            qd: Some(&qd),
            qdd: Some(&qdd),
            f_ext: None,
        },
    );
    let rest = Motions {
        qd: None,
        qdd: None,
        f_ext: None,
    };
    Some(match f {
        Function::MassMatrix => crba(tables, &mut b),
        Function::NonlinearEffects => rnea(&b, velocity),
        Function::Gravity => rnea(&b, rest),
        Function::InverseDynamics => rnea(&b, rates),
        Function::MassMatrixAndNonlinearEffects => {
            let h = crba(tables, &mut b);
            [h, rnea(&b, velocity)].concat()
        }
        _ => {
            let f_ext: Option<Vec<[Sym; 6]>> = (f == Function::ForwardDynamicsWithWrenches)
                .then(|| (0..n).map(|_| core::array::from_fn(|_| x())).collect());
            let tau = arg();
            let rates = Rates {
                qd: &qd,
                tau: &tau,
                f_ext: f_ext.as_deref(),
                armature: None,
            };
            let mut store = ArticulatedVecs::<Sym>::new(n);
            let mut ab = store.articulated();
            let mut qdd = vec![zero; n];
            k::aba::aba(tables, inertia, rates, &mut b, &mut ab, &mut qdd);
            qdd
        }
    })
}

/// The outputs of a frame function's kernel on `tables` at `q`, as its entry point computes them:
/// the joint transforms and placements of the frame body's support path, then the placement
/// `[x_f; R_f rows]` or the Jacobian's rows.
fn trace_frame(
    tables: &Tables<'_, Sym>,
    f: Function,
    frame: &k::Frame<Sym>,
    q: &[Sym],
) -> Vec<Sym> {
    let zero = Sym::zero();
    let n = q.len();
    let x0 = support_path(tables, frame, q);
    if let Function::FramePlacement(_) = f {
        let (p, r) = k::frames::pose(frame, &x0);
        return p.into_iter().chain(r.into_iter().flatten()).collect();
    }
    let xf = k::frames::origin(frame, &x0);
    let mut cols = vec![[zero; 6]; n];
    k::frames::jacobian_columns(tables, frame, &x0, &xf, &mut cols);
    (0..6)
        .flat_map(|r| cols.iter().map(move |c| c[r]))
        .collect()
}

/// The outputs of a free-floating function's kernel (`kanegen_runtime::compact::floating` and
/// `::floating_frames`) on `tables` of `n` joints, as its entry point computes them, every
/// argument a fresh input (`x`), the scratch in `Vec`s; `frame`: a frame function's frame.
fn trace_floating(
    tables: &Tables<'_, Sym>,
    f: Function,
    base: &k::floating::Base<Sym>,
    frame: Option<&k::Frame<Sym>>,
    n: usize,
    x: &dyn Fn() -> Sym,
) -> Option<Vec<Sym>> {
    use k::floating::{forward_dynamics_in, inverse_dynamics_in, mass_matrix_in};
    if !crate::compact::has_body(f, true) {
        return None;
    }
    let zero = Sym::zero();
    let args = |len: usize| -> Vec<Sym> { (0..len).map(|_| x()).collect() };
    if let Some(frame) = frame {
        return Some(trace_floating_frame(tables, f, base, frame, &args(7 + n)));
    }
    let (q, v, a, tau) = (args(7 + n), args(6 + n), args(6 + n), args(n));
    let mut store = BodyVecs::<Sym>::new(n);
    let mut b = store.bodies();
    k::spatial::transforms(tables, &q[7..], |s: Sym| s.sin_cos(), b.x);
    let inertia = tables.inertia;
    let nv = n + 6;
    let mass = |b: &mut Bodies<'_, Sym>| {
        let (mut st, mut h, mut out) = (vec![zero; 6 * n], vec![zero; n * n], vec![zero; nv * nv]);
        mass_matrix_in(tables, inertia, base, b, &mut st, &mut h, &mut out);
        out
    };
    let id_at = |b: &Bodies<'_, Sym>, vel: Option<&[Sym]>, acc: Option<&[Sym]>| {
        let (mut m, mut out) = (vec![[[zero; 6]; 3]; n], vec![zero; nv]);
        let x = &*b.x;
        inverse_dynamics_in(
            tables, x, inertia, base, &q, vel, acc, None, &mut m, &mut out,
        );
        out
    };
    Some(match f {
        Function::MassMatrix => mass(&mut b),
        Function::Momentum => {
            let mut vw = vec![[zero; 6]; n];
            k::floating::momentum_in(tables, inertia, base, &q, &v, &mut b, &mut vw).to_vec()
        }
        Function::BaseReaction => {
            let mut m = vec![[[zero; 6]; 3]; n];
            k::floating::base_reaction_in(tables, b.x, inertia, base, &q, &v, &a, &mut m).to_vec()
        }
        Function::NonlinearEffects => id_at(&b, Some(&v), None),
        Function::Gravity => id_at(&b, None, None),
        Function::InverseDynamics => id_at(&b, Some(&v), Some(&a)),
        Function::MassMatrixAndNonlinearEffects => {
            let c = id_at(&b, Some(&v), None);
            [mass(&mut b), c].concat()
        }
        _ => {
            let f_ext: Option<Vec<[Sym; 6]>> = (f == Function::ForwardDynamicsWithWrenches)
                .then(|| (0..=n).map(|_| core::array::from_fn(|_| x())).collect());
            let mut store = ArticulatedVecs::<Sym>::new(n);
            let mut ab = store.articulated();
            let mut out = vec![zero; nv];
            let f_ext = f_ext.as_deref();
            forward_dynamics_in(
                tables, inertia, base, &q, &v, &tau, f_ext, &mut b, &mut ab, &mut out,
            );
            out
        }
    })
}

/// The placements of the support path of `frame`'s body at the joint positions `q`, as the
/// frame kernels' entry points compute them (the joint transforms up to the body first).
fn support_path(tables: &Tables<'_, Sym>, frame: &k::Frame<Sym>, q: &[Sym]) -> Vec<Transform<Sym>> {
    let zero = Sym::zero();
    let id = Transform {
        e: [[zero; 3]; 3],
        r: [zero; 3],
    };
    let n = q.len();
    let (mut x, mut x0) = (vec![id; n], vec![id; n]);
    if let Some(i) = frame.body {
        let upto = (i + 1).min(n);
        k::spatial::transforms(tables, &q[..upto], |a: Sym| a.sin_cos(), &mut x[..upto]);
        k::frames::support_placements(tables, i, &x, &mut x0);
    }
    x0
}

/// The outputs of a frame function's kernel on a free-floating base (`q`: the `7 + N`
/// positions), as its entry point computes them: the placement `[x; R rows]`, the Jacobian's
/// rows, or the generalized Jacobian's rows.
fn trace_floating_frame(
    tables: &Tables<'_, Sym>,
    f: Function,
    base: &k::floating::Base<Sym>,
    frame: &k::Frame<Sym>,
    q: &[Sym],
) -> Vec<Sym> {
    use k::floating_frames as ff;
    let zero = Sym::zero();
    let n = q.len() - 7;
    let sincos = |a: Sym| a.sin_cos();
    let mut cols = vec![[zero; 6]; n];
    if let Function::GeneralizedJacobian(_) = f {
        let mut store = BodyVecs::<Sym>::new(n);
        let mut b = store.bodies();
        k::spatial::transforms(tables, &q[7..], sincos, b.x);
        let mut out = vec![zero; 6 * n];
        let i = tables.inertia;
        ff::generalized_jacobian_in(tables, i, base, frame, q, &mut b, &mut cols, &mut out);
        return out;
    }
    let x0 = support_path(tables, frame, &q[7..]);
    if let Function::FramePlacement(_) = f {
        let (p, r) = ff::placement_in(frame, q, &x0);
        return p.into_iter().chain(r.into_iter().flatten()).collect();
    }
    let mut out = vec![zero; 6 * (6 + n)];
    ff::jacobian_in(tables, frame, q, &x0, &mut cols, &mut out);
    out
}

/// The counts of a derivative kernel (`kanegen_runtime::compact::derivatives`): run on
/// [`Tally`], from the payload's inertia and the joint transforms on, as its entry point
/// composes it. Its O(N³) operations (`M⁻¹`, two `N × N` products) are counted without a graph.
fn derivative_counts(t: &KernelTables, f: Function, payload: bool) -> Counts {
    let n = t.parent.len();
    let z = Tally;
    let _ = tally::take();
    let m3 = vec![[[z; 3]; 3]; n];
    let v3 = vec![[z; 3]; n];
    let s = vec![[z; 6]; n];
    let mut inertia = vec![[z; 10]; n];
    if payload {
        if let Some(last) = inertia.last_mut() {
            *last = k::payload_inertia(z, &[z; 3], &[[z; 3]; 3]);
        }
    }
    let tables = Tables {
        parent: &t.parent,
        revolute: &t.revolute,
        a: &m3,
        b: &m3,
        c: &m3,
        l: &v3,
        slide: &v3,
        s: &s,
        inertia: &inertia,
        ancestor: t.ancestor.as_deref(),
        a0: [z; 6],
    };
    let joints = vec![z; n];
    let mut store = BodyVecs::<Tally>::new(n);
    let mut b = store.bodies();
    let sincos = |a: Tally| a.sin_cos();
    match &t.base {
        None => {
            k::spatial::transforms(&tables, &joints, sincos, b.x);
            trace_derivatives(&tables, f, &mut b, &joints, &joints, &joints);
        }
        Some(base) => {
            let base = k::floating::Base {
                inertia: [z; 10],
                gravity: base.gravity.map(|_| [z; 3]),
            };
            let (q, v) = (vec![z; 7 + n], vec![z; 6 + n]);
            k::spatial::transforms(&tables, &joints, sincos, b.x);
            trace_floating_derivatives(&tables, f, &base, &mut b, &q, &v, &v, &joints);
        }
    }
    tally::take()
}

/// The outputs of a derivative kernel (`kanegen_runtime::compact::derivatives`) on the joint
/// transforms of `b`, as its entry point composes it: `(∂τ/∂q, ∂τ/∂q̇)` at `(q̇, q̈)`; `M⁻¹`; or
/// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` under the drives `tau`.
fn trace_derivatives<S: Scalar + Copy>(
    tables: &Tables<'_, S>,
    f: Function,
    b: &mut Bodies<'_, S>,
    qd: &[S],
    qdd: &[S],
    tau: &[S],
) -> Vec<S> {
    use k::derivatives as dk;
    let n = qd.len();
    let zero = S::zero();
    let mut js = vec![dk::Joint::zero(); n];
    let (mut dtq, mut dtv) = (vec![zero; n * n], vec![zero; n * n]);
    if f == Function::InverseDynamicsDerivatives {
        k::spatial::world(tables, tables.inertia, b);
        dk::rnea_derivatives_in(tables, b, qd, qdd, &mut js, &mut dtq, &mut dtv);
        return [dtq, dtv].concat();
    }
    let (mut m, mut c, mut a) = (vec![[[zero; 6]; 3]; n], vec![zero; n], vec![zero; n]);
    if f == Function::ForwardDynamicsDerivatives {
        k::rnea::rnea(
            tables,
            b.x,
            tables.inertia,
            Motions::velocity(qd),
            &mut m,
            &mut c,
        );
    }
    let mut h = crba(tables, b);
    let (mut d_inv, mut minv) = (vec![zero; n], vec![zero; n * n]);
    dk::inverse_in(&mut h, n, &mut d_inv, &mut minv);
    if f == Function::MassMatrixInverse {
        return minv;
    }
    dk::accelerations(&minv, tau, &c, &mut a);
    k::spatial::world(tables, tables.inertia, b);
    dk::rnea_derivatives_in(tables, b, qd, &a, &mut js, &mut dtq, &mut dtv);
    let (mut aq, mut av) = (vec![zero; n * n], vec![zero; n * n]);
    dk::neg_product(&minv, &dtq, n, &mut aq);
    dk::neg_product(&minv, &dtv, n, &mut av);
    [aq, av, minv].concat()
}

/// The outputs of a free-floating derivative kernel (`kanegen_runtime::compact::derivatives`) on
/// the joint transforms of `b`, as its entry point composes it: `(∂τ/∂q, ∂τ/∂ν)` at `(ν, ν̇)`;
/// `M⁻¹`; or `(∂ν̇/∂q, ∂ν̇/∂ν, M⁻¹)` under the joint drives `tau`.
#[allow(clippy::too_many_arguments)]
fn trace_floating_derivatives<S: Scalar + Copy>(
    tables: &Tables<'_, S>,
    f: Function,
    base: &k::floating::Base<S>,
    b: &mut Bodies<'_, S>,
    q: &[S],
    v: &[S],
    a: &[S],
    tau: &[S],
) -> Vec<S> {
    use k::derivatives as dk;
    let n = tau.len();
    let nv = n + 6;
    let zero = S::zero();
    let inertia = tables.inertia;
    let mut js = vec![dk::Joint::zero(); n];
    let (mut dtq, mut dtv) = (vec![zero; nv * nv], vec![zero; nv * nv]);
    if f == Function::InverseDynamicsDerivatives {
        k::spatial::world(tables, inertia, b);
        let mut root = dk::floating_root(base, q, v, a);
        let (qd, qdd) = (&v[6..], &a[6..]);
        dk::floating_rnea_derivatives_in(
            tables, b, &mut root, qd, qdd, &mut js, &mut dtq, &mut dtv,
        );
        return [dtq, dtv].concat();
    }
    let (mut mm, mut c) = (vec![[[zero; 6]; 3]; n], vec![zero; nv]);
    if f == Function::ForwardDynamicsDerivatives {
        let x = &*b.x;
        k::floating::inverse_dynamics_in(
            tables,
            x,
            inertia,
            base,
            q,
            Some(v),
            None,
            None,
            &mut mm,
            &mut c,
        );
    }
    let (mut st, mut h, mut m) = (vec![zero; 6 * n], vec![zero; n * n], vec![zero; nv * nv]);
    k::floating::mass_matrix_in(tables, inertia, base, b, &mut st, &mut h, &mut m);
    let (mut d_inv, mut minv) = (vec![zero; nv], vec![zero; nv * nv]);
    dk::inverse_in(&mut m, nv, &mut d_inv, &mut minv);
    if f == Function::MassMatrixInverse {
        return minv;
    }
    let drives: Vec<S> = [vec![zero; 6], tau.to_vec()].concat();
    let mut nu_dot = vec![zero; nv];
    dk::accelerations(&minv, &drives, &c, &mut nu_dot);
    k::spatial::world(tables, inertia, b);
    let mut root = dk::floating_root(base, q, v, &nu_dot);
    let qdd = &nu_dot[6..];
    dk::floating_rnea_derivatives_in(
        tables,
        b,
        &mut root,
        &v[6..],
        qdd,
        &mut js,
        &mut dtq,
        &mut dtv,
    );
    let (mut aq, mut av) = (vec![zero; nv * nv], vec![zero; nv * nv]);
    dk::neg_product(&minv, &dtq, nv, &mut aq);
    dk::neg_product(&minv, &dtv, nv, &mut av);
    [aq, av, minv].concat()
}

/// The CRBA's `H` (rows first) on the joint transforms of `b`.
fn crba<S: Scalar + Copy>(tables: &Tables<'_, S>, b: &mut Bodies<'_, S>) -> Vec<S> {
    let n = b.x.len();
    let zero = S::zero();
    let (mut st, mut h) = (vec![zero; 6 * n], vec![zero; n * n]);
    k::crba::crba(tables, tables.inertia, b, &mut st, &mut h);
    h
}

/// The counts of the compact body of `f` on a model with mimic joints
/// (`kanegen_runtime::compact::coupled`): the full-tree kernels it calls (`full`: the counts
/// of a function's kernel on the full tables, [`counts`]), plus its own steps run on [`Tally`]:
/// the state expanded by the coupling `c`, the results reduced, and for forward dynamics, its
/// derivatives and `M⁻¹` the right-hand side, the LDLᵀ solve or inverse of the reduced `M`
/// and the products with it. `floating`: on a free-floating base. `None`: no compact body.
pub fn coupled_counts(
    c: &kanegen_runtime::coupling::Coupling<'_>,
    f: Function,
    floating: bool,
    full: impl Fn(Function) -> Option<Counts>,
) -> Option<Counts> {
    let z = Tally;
    let (n, r) = (c.full(), c.reduced);
    let o = if floating { 6 } else { 0 };
    let (nf, rf) = (n + o, r + o);
    let _ = tally::take();
    let mut full_vec = vec![z; nf];
    let mut red_vec = vec![z; rf];
    let expand_q = |out: &mut Vec<Tally>| c.expand_positions(&vec![z; r], &mut out[..n]);
    let expand_rates = |out: &mut Vec<Tally>| c.expand_rates(&vec![z; r], &mut out[..n]);
    let reduce_matrix = || {
        let (m, mut scratch, mut out) = (vec![z; nf * nf], vec![z; nf * rf], vec![z; rf * rf]);
        c.reduce_matrix(&m, o, &mut scratch, &mut out);
    };
    let mut reduce_vector = || c.reduce_vector(&vec![z; nf], o, &mut red_vec);
    // The right-hand side `τ_full − c_full` of forward dynamics, reduced with `M`.
    let rhs = |full_vec: &mut Vec<Tally>| {
        c.expand_drives(&vec![z; r], &mut full_vec[..n]);
        for x in full_vec.iter_mut() {
            *x = *x - z;
        }
    };
    let kernels: &[Function] = match f {
        Function::MassMatrix | Function::MassMatrixInverse => {
            expand_q(&mut full_vec);
            reduce_matrix();
            if f == Function::MassMatrixInverse {
                let (mut m, mut d_inv, mut out) = (vec![z; rf * rf], vec![z; rf], vec![z; rf * rf]);
                k::derivatives::inverse_in(&mut m, rf, &mut d_inv, &mut out);
            }
            &[Function::MassMatrix]
        }
        Function::NonlinearEffects | Function::Gravity | Function::InverseDynamics => {
            expand_q(&mut full_vec);
            let rates = match f {
                Function::NonlinearEffects => 1,
                Function::Gravity => 0,
                _ => 2,
            };
            for _ in 0..rates {
                expand_rates(&mut full_vec);
            }
            reduce_vector();
            &[f]
        }
        Function::MassMatrixAndNonlinearEffects => {
            expand_q(&mut full_vec);
            expand_rates(&mut full_vec);
            reduce_matrix();
            reduce_vector();
            &[f]
        }
        Function::ForwardDynamics | Function::ForwardDynamicsWithWrenches => {
            expand_q(&mut full_vec);
            expand_rates(&mut full_vec);
            rhs(&mut full_vec);
            if f == Function::ForwardDynamicsWithWrenches {
                // One wrench subtracted per body (and the base).
                let mut fe = vec![[z; 6]; n + usize::from(floating)];
                for w in &mut fe {
                    *w = core::array::from_fn(|k| w[k] - z);
                }
            }
            reduce_matrix();
            reduce_vector();
            let (mut m, mut d_inv, mut x) = (vec![z; rf * rf], vec![z; rf], vec![z; rf]);
            if kanegen_runtime::ldlt::factor_in_place(&mut m, rf, &mut d_inv).is_ok() {
                let _ = kanegen_runtime::ldlt::solve_in_place(&m, rf, &d_inv, &mut x);
            }
            &[Function::MassMatrixAndNonlinearEffects]
        }
        Function::FramePlacement(_)
        | Function::Momentum
        | Function::BaseReaction
        | Function::FrameJacobian(_)
        | Function::GeneralizedJacobian(_) => {
            expand_q(&mut full_vec);
            let rates = match f {
                Function::Momentum => 1,
                Function::BaseReaction => 2,
                _ => 0,
            };
            for _ in 0..rates {
                expand_rates(&mut full_vec);
            }
            let offset = match f {
                Function::FrameJacobian(_) => Some(o),
                Function::GeneralizedJacobian(_) => Some(0),
                _ => None,
            };
            if let Some(offset) = offset {
                let (m, mut out) = (vec![z; 6 * (offset + n)], vec![z; 6 * (offset + r)]);
                c.reduce_rows(&m, offset, &mut out);
            }
            &[f]
        }
        Function::InverseDynamicsDerivatives => {
            expand_q(&mut full_vec);
            expand_rates(&mut full_vec);
            expand_rates(&mut full_vec);
            reduce_matrix();
            reduce_matrix();
            &[f]
        }
        Function::ForwardDynamicsDerivatives => {
            expand_q(&mut full_vec);
            expand_rates(&mut full_vec);
            rhs(&mut full_vec);
            reduce_matrix();
            reduce_vector();
            let (mut m, mut d_inv, mut minv) = (vec![z; rf * rf], vec![z; rf], vec![z; rf * rf]);
            k::derivatives::inverse_in(&mut m, rf, &mut d_inv, &mut minv);
            let mut qdd = vec![z; rf];
            k::coupled::product(&minv, &vec![z; rf], &mut qdd);
            expand_rates(&mut full_vec);
            reduce_matrix();
            reduce_matrix();
            let (d, mut out) = (vec![z; rf * rf], vec![z; rf * rf]);
            k::derivatives::neg_product(&minv, &d, rf, &mut out);
            k::derivatives::neg_product(&minv, &d, rf, &mut out);
            &[
                Function::MassMatrixAndNonlinearEffects,
                Function::InverseDynamicsDerivatives,
            ]
        }
        _ => return None,
    };
    // The own steps' tally first: a derivative kernel's counts reset it.
    let own = tally::take();
    kernels.iter().try_fold(own, |acc, &g| Some(acc + full(g)?))
}
