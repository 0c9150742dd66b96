//! The compact form of the generated functions: fixed-size loops over `const` tables of the
//! model's numbers instead of straight-line code, for models where straight-line code loses.
//!
//! Same API as the unrolled form ([`crate::api`]), same parameters (the joints' placements and
//! axes of [`kanegen_dynamics::Params`], the spatial inertias of
//! [`kanegen_dynamics::regroup::regrouped`] when [`Options::regroup`] is on). The generator
//! emits only data and calls: one `const CX: Tables<…>` of the runtime crate
//! (`kanegen_runtime::compact::Tables`, [`tables::numbers`]) and, for each function, one call
//! of its kernel in `kanegen_runtime::compact`, where the algorithms are written once, generic
//! over the scalar:
//!
//! - `mass_matrix`: the composite-rigid-body algorithm (RBDA Table 6.2);
//! - `nonlinear_effects`, `gravity`, `inverse_dynamics`: the recursive Newton–Euler algorithm
//!   (RBDA Table 5.1; gravity as the base's fictitious acceleration `a₀ = −a_g`, RBDA §5.3);
//! - `forward_dynamics`, `forward_dynamics_with_wrenches`: the articulated-body algorithm
//!   (RBDA Table 7.1), O(N) instead of the unrolled form's CRBA + RNEA + LDLᵀ;
//! - `mass_matrix_and_nonlinear_effects`: CRBA and RNEA on one set of joint transforms;
//! - `<frame>_placement`, `<frame>_jacobian`: loops over the support path of the frame's body
//!   (`kanegen_runtime::compact::frames`, `const CX_FRAMES`);
//! - `inverse_dynamics_derivatives`, `forward_dynamics_derivatives`, `mass_matrix_inverse`:
//!   Carpentier–Mansard's derivatives over the tables (on a free-floating base, the base as body
//!   0 with six columns, its `∂/∂q` in the tangent space), `M⁻¹` by LDLᵀ
//!   (`kanegen_runtime::compact::derivatives`);
//! - on a free-floating base, the dynamics functions above with the base as the root of the
//!   passes (`kanegen_runtime::compact::floating`, `const CX_BASE`), `momentum` and
//!   `base_reaction` (one pass each), and the frames in the inertial frame with their
//!   `<frame>_generalized_jacobian` (`kanegen_runtime::compact::floating_frames`: the composite
//!   inertias, one 6×6 LDLᵀ, one solve per joint).
//!
//! The kernels take the type's sine–cosine (`Self::sincos`, or libm's per
//! [`Options::libm_trig`] and for `f32`). Nothing allocates, no function panics, `f32` works as
//! `f64`. A compact function's `OP_COUNTS` entry is the kernel traced on the tracer `Sym` with
//! the tables as symbolic inputs ([`counts`]): every operation its loops execute, for any
//! number of joints (the kernels' cores take slices, so one instance on `Sym` traces them all).
//! Under [`Form::Auto`] the O(N) functions (Newton–Euler, frames) keep their straight-line body
//! while it is small ([`LINEAR_AUTO_LIMIT`]).
//!
//! Supported: a fixed or free-floating base, chains and trees, `f64` and `f32`, gravity, a
//! runtime payload (the last body's inertia built from it at each call), with or without
//! regrouping (none on a free-floating base), with frames. Not supported (`form = "compact"` is
//! an error): a forced algorithm. The frame functions' entry points are `#[inline]`, not
//! `#[inline(always)]`: every frame of a model calls one instance, so a model with many frames
//! (pr2: 51) compiles one copy of the loops, not one per function.
//!
//! # Measured: when compact code wins
//!
//! `tools/compact/measure.sh` (one crate with one `dynamics!` per form and model, release build;
//! ns per call: the lowest of three alternating runs of the median of five rounds; rebuild: user
//! CPU seconds of `cargo build --release` of that crate; a shared 2-core machine):
//!
//! | N (random chain) | unrolled M + c ops | M + c unrolled / compact (ns) | FD unrolled / compact (ns) | rebuild, user CPU s: unrolled / compact |
//! |---:|---:|---:|---:|---:|
//! | 2 | 525 | 79 / 227 | 109 / 256 | 0.7 / 0.8 |
//! | 4 | 1,706 | 205 / 570 | 354 / 602 | 1.0 / 0.8 |
//! | 8 | 4,077 | 1,426 / 1,142 | 1,274 / 1,011 | 2.2 / 1.2 |
//! | 12 | 6,663 | 2,468 / 1,777 | 2,480 / 1,897 | 3.6 / 0.8 |
//! | 16 | 9,521 | 3,171 / 2,412 | 3,600 / 2,742 | 4.0–5.4 / 1.1–1.2 |
//! | 24 | 16,053 | 6,107 / 3,900 | 7,148 / 3,786 | 10.0 / 1.5 |
//! | 32 | 23,673 | 10,164 / 5,985 | 12,555 / 6,549 | 14.5–17.9 / 1.2–1.4 |
//! | 48 | 42,177 | 22,472 / 6,898 | 32,151 / 6,561 | 67 / 1.8 |
//! | 64 | 65,033 | 43,513 / 11,059 | 92,134 / 7,094 | 183–223 / 2.4–2.7 |
//! | SSRMS (7) | 635 | 97 / 962 | 265 / 1,048 | 0.7 / 0.9 |
//!
//! Compact code loses below a few thousand operations (its loops, table reads and branches on
//! the kind cost more than the folded constants of straight-line code: 4–10× for SSRMS) and
//! wins from random N = 8 on, by 4–13× at N = 64; it builds in seconds at any N. Hence
//! [`AUTO_LIMIT`], on the emitted operations of the unrolled `M + c`. (The table was measured
//! with the chains traced in their own frames; the generator now also traces canonical frames
//! (`crate::choose::BodyFrames`), where the unrolled `M + c` of random N = 8 emits 2,955
//! operations and stays straight-line, and N = 16 emits 8,401.) The O(N) Newton–Euler
//! functions cross over later (at about 4,300 operations of their own, random N = 16), so a
//! compact model keeps them straight-line below [`LINEAR_AUTO_LIMIT`] ([`keeps_unrolled`]).
//!
//! Two kernels were rewritten after the table: the CRBA's fill takes row `i` of `H` for every
//! `j ≤ i` in one loop over the `S_j` stored side by side (vectorized; a tree's non-ancestors
//! masked to zero after), and the ABA keeps each articulated inertia as its 21 upper-triangle
//! entries (the 6×6 products written out with literal indices) and computes nothing for absent
//! wrenches. Side by side in one process (paired rounds, median of the per-round ratios, a
//! noisy 2-core machine), old / new time: random N = 16, 32, 64: `M` 1.08, 1.27, 1.45;
//! `M + c` 1.04, 1.14, 1.29; forward dynamics 1.13, 1.14, 1.14.
//!
//! The kernels live in `kanegen_runtime::compact` (generic over the scalar; cores over slices
//! with caller-provided scratch, so that one instance on `Sym` traces any N, inlined into
//! const-`N` entry points; the tables one `const` of `'static` slices). Side by side against the
//! same algorithms pasted as tokens into each generated type (`tools/compact/side_by_side.sh`),
//! their results are bit-identical and their times no longer (`docs/performance.md`, "The
//! compact kernels against the token-template kernels").

pub mod counts;
pub mod tables;
pub mod tally;

use self::tables::{numbers, M3};
use crate::options::{Error, Float, Form, Options};
use crate::paths;
use kanegen_dynamics::{ForwardMethod, MassMatrixMethod, Methods, NonlinearEffectsMethod};
use kanegen_model::Model;
use kanegen_runtime::compact::floating::Base;
use kanegen_runtime::compact::Frame;
use kanegen_trace::{Counts, Function};
use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// [`Form::Auto`] emits compact code when the unrolled `mass_matrix_and_nonlinear_effects` would
/// have more emitted operations (`mul + add`) than this: measured ([module docs](self)), compact
/// code is slower at random N = 4 (1,706 operations) and faster from N = 8 (4,077) on.
pub const AUTO_LIMIT: u64 = 4_000;

/// Under [`Form::Auto`], a compact model keeps the unrolled body of its O(N) Newton–Euler
/// functions (`nonlinear_effects`, `gravity`, `inverse_dynamics`) while that body has at most
/// this many emitted operations. They grow like N, not N², so they cross over later than
/// `M + c`: measured side by side (`cargo bench --bench compact`, random chains), unrolled `c`
/// and inverse dynamics are 12 % and 19 % faster than compact at N = 8 (2,012 and 2,099
/// operations), tie at N = 16 (4,292 and 4,427) and are 13 % and 26 % slower at N = 32 (8,852
/// and 9,083).
pub const LINEAR_AUTO_LIMIT: u64 = 4_000;

/// Whether `f` may keep its unrolled body in a model that [`decide`] made compact: under
/// [`Form::Auto`], an O(N) Newton–Euler function or a frame function (then it does when its
/// unrolled body has at most [`LINEAR_AUTO_LIMIT`] emitted operations, [`keeps_unrolled`]).
#[must_use]
pub fn may_keep_unrolled(opts: &Options, f: Function) -> bool {
    opts.form == Form::Auto
        && matches!(
            f,
            Function::NonlinearEffects | Function::Gravity | Function::InverseDynamics
        )
}

/// Whether `f` is `mass_matrix_inverse` in a model that [`decide`] made compact under
/// [`Form::Auto`]: it keeps its straight-line body (CRBA and the LDLᵀ inverse unrolled) while
/// that has at most [`DERIVATIVES_AUTO_LIMIT`] emitted operations, sized on prefixes. Its
/// kernel runs dense `N × N` loops where the traced body drops every zero and one: measured side
/// by side on a random 12-joint chain (`DERIVS=1 tools/compact/measure.sh auto|compact`, 5,342
/// emitted operations), 611 ns against 1,250 for the kernel, for a rebuild of 25 s of CPU
/// against 3 s (what an unrolled model of six or seven joints takes).
#[must_use]
pub fn may_keep_inverse_unrolled(opts: &Options, f: Function) -> bool {
    f == Function::MassMatrixInverse && loops_derivatives(opts)
}

/// Whether `f` keeps its unrolled body in a model that [`decide`] made compact: it
/// [`may_keep_unrolled`] and its unrolled body, traced as far as `size`, has at most
/// [`LINEAR_AUTO_LIMIT`] emitted operations.
#[must_use]
pub fn keeps_unrolled(opts: &Options, f: Function, size: Size) -> bool {
    may_keep_unrolled(opts, f) && !size.above(LINEAR_AUTO_LIMIT)
}

/// Under [`Form::Auto`], an unrolled model keeps a derivative function (`∂τ`, `∂q̈` with
/// `M⁻¹`, `M⁻¹`) straight-line while its cheapest unrolled body has at most this many emitted
/// operations, or at most [`DERIVATIVES_UNROLLED_SHARE`] percent of its compact kernel's traced
/// operations; above both it is emitted in loops, the compact form's kernel
/// ([`derivative_keeps_unrolled`]).
///
/// Measured side by side (`DERIVS=1 tools/compact/measure.sh unrolled|compact`, `-C
/// target-cpu=native`, ns per call, median of 5 rounds; docs/performance.md): straight-line
/// derivatives run at 0.08–0.10 ns per emitted operation up to 6,957 operations (Panda's `∂τ`),
/// then at 0.17–0.21 past a cliff at 8,849 (a random 8-joint chain's `∂τ`: 1,838 ns unrolled
/// against 1,216 compact) as the body outgrows the instruction cache; the compact kernels run
/// at 0.12–0.16 ns per traced operation. Past the cliff, the straight-line body wins while it has
/// fewer than about 0.72× the kernel's operations (Panda's forward-dynamics derivatives: 12,100
/// against 21,280, 2,117 ns against 3,296; a random 6-joint chain's: 10,340 against 12,531,
/// 1,761 ns against 1,631).
pub const DERIVATIVES_AUTO_LIMIT: u64 = 7_000;

/// See [`DERIVATIVES_AUTO_LIMIT`]: the share (percent) of the compact kernel's traced operations
/// below which a straight-line derivative body is kept past the limit.
pub const DERIVATIVES_UNROLLED_SHARE: u64 = 72;

/// The counts of `kanegen_runtime::composed`'s loops for `nv` speeds, run on the counting
/// scalar: `q̈ = M⁻¹ (τ − c)` and the two products `−M⁻¹ ∂τ/∂x`.
#[must_use]
pub fn composed_counts(nv: usize) -> Counts {
    use kanegen_runtime::compact::derivatives::{accelerations, neg_product};
    let z = tally::Tally;
    let _ = tally::take();
    let (m, mut out) = (vec![z; nv * nv], vec![z; nv * nv]);
    let (full, c, mut qdd) = (vec![z; nv], vec![z; nv], vec![z; nv]);
    accelerations(&m, &full, &c, &mut qdd);
    neg_product(&m, &m, nv, &mut out);
    neg_product(&m, &m, nv, &mut out);
    tally::take()
}

/// Whether an unrolled model may emit its derivative functions in loops: under [`Form::Auto`],
/// when the compact form supports the options ([`unsupported`]).
#[must_use]
pub fn loops_derivatives(opts: &Options) -> bool {
    opts.form == Form::Auto && unsupported(opts).is_none()
}

/// Whether the derivative function `f` of an unrolled model keeps its straight-line body of
/// `ops` emitted operations against a compact kernel of `kernel_ops` traced operations
/// ([`DERIVATIVES_AUTO_LIMIT`]). `forward_dynamics_derivatives` past the limit is composed
/// from the type's other functions instead (`kanegen_runtime::composed`), which costs about
/// what they cost and is never slower than the kernel (which recomputes them): the share does
/// not apply to it.
#[must_use]
pub fn derivative_keeps_unrolled(f: Function, ops: u64, kernel_ops: u64) -> bool {
    ops <= DERIVATIVES_AUTO_LIMIT
        || (f != Function::ForwardDynamicsDerivatives
            && ops * 100 <= kernel_ops * DERIVATIVES_UNROLLED_SHARE)
}

/// Why the compact form cannot be emitted under `opts` (any model, fixed or free-floating), or
/// `None` when it can.
#[must_use]
pub fn unsupported(opts: &Options) -> Option<&'static str> {
    // The compact form has its own algorithms (CRBA, RNEA, ABA).
    opts.algorithm.is_some().then_some("a forced algorithm")
}

/// The traced counts of the runtime kernel that the compact body of `f` calls
/// ([`counts::counts`]; with mimic joints, [`counts::coupled_counts`]): every operation its
/// loops execute.
///
/// # Errors
/// `f` has no compact body ([`has_body`]).
pub fn kernel_counts(model: &Model, opts: &Options, f: Function) -> Result<Counts, Error> {
    let t = numbers(model, opts);
    let full = |g: Function| counts::counts(&t, g, opts.runtime_payload);
    let counts = if model.has_mimics() {
        let c = kanegen_dynamics::mimic::Coupling::new(model.mimics());
        counts::coupled_counts(&c.table(), f, t.base.is_some(), full)
    } else {
        full(f)
    };
    counts.ok_or_else(|| Error(format!("`{}` has no compact body", f.name())))
}

/// The form emitted and why, as the header says it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Decision {
    /// [`Form::Unrolled`] or [`Form::Compact`].
    pub form: Form,
    /// The header line.
    pub line: String,
}

/// The emitted operations (`mul + add`) of an unrolled function's cheapest candidate, as far
/// as they were traced: on the whole model (`joints` = its N), or on its first `joints` joints
/// alone, a prefix already above the limit it was measured against. A prefix is a lower bound:
/// every joint added to a chain or tree adds operations (rests on measurement; the decisions
/// from prefixes equal those from whole traces on random chains N = 2..64 and the test models,
/// `codegen/tests/compact.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Emitted `mul + add` traced.
    pub ops: u64,
    /// Joints of the model or prefix traced.
    pub joints: usize,
}

impl Size {
    /// Whether the traced operations are above `limit`.
    #[must_use]
    pub fn above(self, limit: u64) -> bool {
        self.ops > limit
    }

    /// `N ops` for the whole model, `over N ops (its first K joints alone)` for a prefix of a
    /// model of `n` joints.
    fn describe(self, n: usize) -> String {
        if self.joints >= n {
            format!("{} emitted operations", self.ops)
        } else {
            format!(
                "over {} emitted operations (its first {} joints alone)",
                self.ops, self.joints
            )
        }
    }
}

/// Decides the form of a model of `n` joints: `why_not` is [`unsupported`] of the model,
/// `size` the emitted `mul + add` of its cheapest unrolled `mass_matrix_and_nonlinear_effects`
/// as far as it was traced (read under [`Form::Auto`] for a supported model only; `None`
/// otherwise).
///
/// # Errors
/// [`Form::Compact`] asked for a model it does not support.
pub fn decide(
    opts: &Options,
    n: usize,
    why_not: Option<&str>,
    size: Option<Size>,
) -> Result<Decision, Error> {
    let compact = |why: String| Decision {
        form: Form::Compact,
        line: format!(
            "Form: compact: loops over constant tables (CRBA, RNEA, ABA; the frames along their \
             support paths) ({why}). `OP_COUNTS` of the functions in loops \
             are the traced counts of the runtime kernels they call (every operation their loops \
             execute); `CANDIDATES` and the table below hold the straight-line functions only."
        ),
    };
    let unrolled = |why: String| Decision {
        form: Form::Unrolled,
        line: format!("Form: unrolled straight-line code ({why})."),
    };
    Ok(match (opts.form, why_not, size) {
        (Form::Compact, Some(why), _) => {
            return Err(Error(format!(
                "form = \"compact\" does not support {why} yet (use \"unrolled\" or \"auto\")"
            )))
        }
        (Form::Compact, None, _) => compact("asked for".into()),
        (Form::Unrolled, ..) => unrolled("asked for".into()),
        (Form::Auto, Some(why), _) => {
            unrolled(format!("auto: the compact form does not support {why} yet"))
        }
        (Form::Auto, None, Some(size)) if size.above(AUTO_LIMIT) => compact(format!(
            "auto: unrolled M + c would be {}, above the {AUTO_LIMIT} limit where compact code \
             measured faster",
            size.describe(n)
        )),
        (Form::Auto, None, size) => unrolled(format!(
            "auto: {} emitted operations in M + c, within the {AUTO_LIMIT} limit",
            size.map_or(0, |s| s.ops)
        )),
    })
}

/// The methods a compact body computes `f` by: the articulated-body algorithm for forward
/// dynamics, the CRBA and the RNEA otherwise ([module docs](self)).
#[must_use]
pub fn methods(f: Function) -> Methods {
    if f.is_forward_dynamics() {
        Methods::ABA
    } else {
        Methods {
            mass_matrix: MassMatrixMethod::Crba,
            nonlinear_effects: NonlinearEffectsMethod::Rnea,
            forward: ForwardMethod::Ldlt,
        }
    }
}

/// Whether the compact form has its own body for `f` on a fixed base, or on a free-floating one
/// (`floating`: also the momentum, the base reaction and the generalized Jacobians).
#[must_use]
pub fn has_body(f: Function, floating: bool) -> bool {
    let both = matches!(
        f,
        Function::FramePlacement(_)
            | Function::FrameJacobian(_)
            | Function::MassMatrix
            | Function::NonlinearEffects
            | Function::Gravity
            | Function::InverseDynamics
            | Function::ForwardDynamics
            | Function::ForwardDynamicsWithWrenches
            | Function::MassMatrixAndNonlinearEffects
    );
    let derivatives = matches!(
        f,
        Function::InverseDynamicsDerivatives
            | Function::ForwardDynamicsDerivatives
            | Function::MassMatrixInverse
    );
    let floating_only = matches!(
        f,
        Function::Momentum | Function::BaseReaction | Function::GeneralizedJacobian(_)
    );
    both || derivatives || (floating && floating_only)
}

fn mat(float: Float, m: &M3) -> TokenStream {
    let rows = m.iter().map(|r| vector(float, r));
    quote!([#(#rows),*])
}

fn vector<const K: usize>(float: Float, v: &[f64; K]) -> TokenStream {
    let v = v.map(|x| float.suffixed(x));
    quote!([#(#v),*])
}

/// The private constant tables of the compact form (an item of the generated `impl`): one
/// `kanegen_runtime::compact::Tables`, which the functions' bodies ([`body`]) hand to the
/// runtime kernels.
///
/// # Errors
/// A runtime path that is not a Rust path.
pub fn items(model: &Model, opts: &Options) -> Result<TokenStream, Error> {
    let fl = opts.float.ty();
    let float = opts.float;
    let rt = opts.runtime()?;
    let t = numbers(model, opts);
    let mats = |m: &[M3]| {
        let m = m.iter().map(|m| mat(float, m));
        quote!(&[#(#m),*])
    };
    let vectors = |v: &[[f64; 3]]| {
        let v = v.iter().map(|v| vector(float, v));
        quote!(&[#(#v),*])
    };
    let parent = t
        .parent
        .iter()
        .map(|p| paths::option(p.map(Literal::usize_unsuffixed)));
    let x = &t.numbers;
    let (a, b, c, l, slide) = (
        mats(&x.a),
        mats(&x.b),
        mats(&x.c),
        vectors(&x.l),
        vectors(&x.slide),
    );
    let s = x.s.iter().map(|v| vector(float, v));
    let inertia = x.inertia.iter().map(|v| vector(float, v));
    let revolute = &t.revolute;
    let ancestor = paths::option(t.ancestor.as_ref().map(|flat| {
        let rows = flat.chunks(t.dof().max(1)).map(|r| quote!(#(#r,)*));
        quote!(&[#(#rows)*])
    }));
    let a0 = vector(float, &x.a0);
    let base = t.base.as_ref().map(|base| floating_base(&rt, float, base));
    let frames = frames(&rt, float, &t.frames);
    let coupling = model.has_mimics().then(|| coupling(&rt, model));
    Ok(quote! {
        /// Compact form: the model's numbers as the runtime kernels read them
        /// (`kanegen_runtime::compact::Tables`: parents, joint kinds, the joint transforms'
        /// `A`, `B`, `C`, `l`, slide, `S`, the spatial inertias, ancestors on a tree, `a₀`).
        const CX: #rt::compact::Tables<'static, #fl> = #rt::compact::Tables {
            parent: &[#(#parent),*],
            revolute: &[#(#revolute),*],
            a: #a,
            b: #b,
            c: #c,
            l: #l,
            slide: #slide,
            s: &[#(#s),*],
            inertia: &[#(#inertia),*],
            ancestor: #ancestor,
            a0: #a0,
        };
        #base
        #frames
        #coupling
    })
}

/// The mimic joints' constant of the compact form (`CX_COUPLING`): for each joint of the full
/// list, the coordinate it follows, its multiplier and offset, whether it is independent and
/// whether it is the first joint of its coordinate (`kanegen_runtime::coupling`).
fn coupling(rt: &TokenStream, model: &Model) -> TokenStream {
    let c = kanegen_dynamics::mimic::Coupling::new(model.mimics());
    let reduced = Literal::usize_unsuffixed(c.reduced());
    let joints = c.joints().iter().map(|f| {
        let coordinate = Literal::usize_unsuffixed(f.coordinate);
        let (k, o) = (
            Literal::f64_suffixed(f.multiplier),
            Literal::f64_suffixed(f.offset),
        );
        let (independent, first) = (f.independent, f.first);
        quote! {
            #rt::coupling::Follower {
                coordinate: #coordinate,
                multiplier: #k,
                offset: #o,
                independent: #independent,
                first: #first,
            }
        }
    });
    quote! {
        /// Compact form: the mimic joints' coupling of the full joint list (the tables' rows)
        /// to the independent coordinates (the arguments): `q_j = k_j q_c(j) + o_j`.
        const CX_COUPLING: #rt::coupling::Coupling<'static> = #rt::coupling::Coupling {
            joints: &[#(#joints),*],
            reduced: #reduced,
        };
    }
}

/// The body of `f` on a model with mimic joints (`n` joints in the tables, `r` coordinates):
/// one call of a kernel of `kanegen_runtime::compact::coupled` (`None`: `f` stays
/// straight-line).
fn coupled_body(
    f: Function,
    k: &TokenStream,
    i: &TokenStream,
    sincos: &TokenStream,
    (n, r): (usize, usize),
    floating: bool,
) -> Option<TokenStream> {
    let [nl, rl, nvl, rvl, nql] = [n, r, n + 6, r + 6, n + 7].map(Literal::usize_unsuffixed);
    let cx = quote!(&Self::CX, &Self::CX_COUPLING);
    let frame = |k: usize| {
        let k = Literal::usize_unsuffixed(k);
        quote!(&Self::CX_FRAMES[#k])
    };
    let none = paths::option(None::<TokenStream>);
    let [some_v, some_a, some_f_ext] = [quote!(v), quote!(a), quote!(f_ext)]
        .map(Some)
        .map(paths::option);
    if floating {
        let fk = quote!(#k::coupled::floating);
        let args = quote!(#cx, #i, &Self::CX_BASE, q);
        let sizes = quote!(_, #nl, #nvl, #nql, #rvl);
        return Some(match f {
            Function::MassMatrix => quote!(#fk::mass_matrix::<#sizes>(#args, #sincos)),
            Function::NonlinearEffects => {
                quote!(#fk::inverse_dynamics::<#sizes>(#args, #some_v, #none, #sincos))
            }
            Function::Gravity => {
                quote!(#fk::inverse_dynamics::<#sizes>(#args, #none, #none, #sincos))
            }
            Function::InverseDynamics => {
                quote!(#fk::inverse_dynamics::<#sizes>(#args, #some_v, #some_a, #sincos))
            }
            Function::MassMatrixAndNonlinearEffects => {
                quote!(#fk::mass_matrix_and_nonlinear_effects::<#sizes>(#args, v, #sincos))
            }
            Function::ForwardDynamics => quote! {
                #fk::forward_dynamics::<_, #nl, #nvl, #nql, #rl, #rvl>(#args, v, tau, #none, #sincos)
            },
            Function::ForwardDynamicsWithWrenches => quote! {
                #fk::forward_dynamics::<_, #nl, #nvl, #nql, #rl, #rvl>(
                    #args, v, tau, #some_f_ext, #sincos
                )
            },
            Function::Momentum => {
                quote!(#fk::momentum::<_, #nl, #nvl, #nql>(#args, v, #sincos))
            }
            Function::BaseReaction => {
                quote!(#fk::base_reaction::<_, #nl, #nvl, #nql>(#args, v, a, #sincos))
            }
            Function::FramePlacement(k) => {
                let fr = frame(k);
                quote!(#fk::frame_placement::<_, #nl, #nql>(#cx, #fr, q, #sincos))
            }
            Function::FrameJacobian(k) => {
                let fr = frame(k);
                quote!(#fk::frame_jacobian::<_, #nl, #nvl, #nql, #rvl>(#cx, #fr, q, #sincos))
            }
            Function::GeneralizedJacobian(k) => {
                let fr = frame(k);
                quote! {
                    #fk::generalized_jacobian::<_, #nl, #nql, #rl>(
                        #cx, #i, &Self::CX_BASE, #fr, q, #sincos
                    )
                }
            }
            Function::InverseDynamicsDerivatives => quote! {
                #fk::inverse_dynamics_derivatives::<#sizes>(#args, v, a, #sincos)
            },
            Function::ForwardDynamicsDerivatives => quote! {
                #fk::forward_dynamics_derivatives::<_, #nl, #nvl, #nql, #rl, #rvl>(
                    #args, v, tau, #sincos
                )
            },
            Function::MassMatrixInverse => {
                quote!(#fk::mass_matrix_inverse::<#sizes>(#args, #sincos))
            }
            _ => return None,
        });
    }
    let ck = quote!(#k::coupled);
    let sizes = quote!(_, #nl, #rl);
    Some(match f {
        Function::MassMatrix => quote!(#ck::mass_matrix::<#sizes>(#cx, #i, q, #sincos)),
        Function::NonlinearEffects => {
            quote!(#ck::nonlinear_effects::<#sizes>(#cx, #i, q, qd, #sincos))
        }
        Function::Gravity => quote!(#ck::gravity::<#sizes>(#cx, #i, q, #sincos)),
        Function::InverseDynamics => {
            quote!(#ck::inverse_dynamics::<#sizes>(#cx, #i, q, qd, qdd, #sincos))
        }
        Function::MassMatrixAndNonlinearEffects => {
            quote!(#ck::mass_matrix_and_nonlinear_effects::<#sizes>(#cx, #i, q, qd, #sincos))
        }
        Function::ForwardDynamics => {
            quote!(#ck::forward_dynamics::<#sizes>(#cx, #i, q, qd, tau, #sincos))
        }
        Function::ForwardDynamicsWithWrenches => quote! {
            #ck::forward_dynamics_with_wrenches::<#sizes>(#cx, #i, q, qd, tau, f_ext, #sincos)
        },
        Function::FramePlacement(k) => {
            let fr = frame(k);
            quote!(#ck::frame_placement::<#sizes>(#cx, #fr, q, #sincos))
        }
        Function::FrameJacobian(k) => {
            let fr = frame(k);
            quote!(#ck::frame_jacobian::<#sizes>(#cx, #fr, q, #sincos))
        }
        Function::InverseDynamicsDerivatives => quote! {
            #ck::inverse_dynamics_derivatives::<#sizes>(#cx, #i, q, qd, qdd, #sincos)
        },
        Function::ForwardDynamicsDerivatives => quote! {
            #ck::forward_dynamics_derivatives::<#sizes>(#cx, #i, q, qd, tau, #sincos)
        },
        Function::MassMatrixInverse => {
            quote!(#ck::mass_matrix_inverse::<#sizes>(#cx, #i, q, #sincos))
        }
        _ => return None,
    })
}

/// The body of `f` on a free-floating base of `n` joints: one call of a kernel of
/// `kanegen_runtime::compact::floating` (`None`: `f` stays straight-line).
fn floating_body(
    f: Function,
    k: &TokenStream,
    i: &TokenStream,
    sincos: &TokenStream,
    n: usize,
) -> Option<TokenStream> {
    let (nl, nvl) = (
        Literal::usize_unsuffixed(n),
        Literal::usize_unsuffixed(n + 6),
    );
    let fk = quote!(#k::floating);
    let ff = quote!(#k::floating_frames);
    let args = quote!(&Self::CX, #i, &Self::CX_BASE, q);
    let frame = |k: usize| {
        let k = Literal::usize_unsuffixed(k);
        quote!(&Self::CX_FRAMES[#k])
    };
    let none = paths::option(None::<TokenStream>);
    let [some_v, some_a, some_f_ext] = [quote!(v), quote!(a), quote!(f_ext)]
        .map(Some)
        .map(paths::option);
    let dk = quote!(#k::derivatives);
    Some(match f {
        Function::InverseDynamicsDerivatives => quote! {
            #dk::floating_inverse_dynamics_derivatives::<_, #nl, #nvl>(#args, v, a, #sincos)
        },
        Function::ForwardDynamicsDerivatives => quote! {
            #dk::floating_forward_dynamics_derivatives::<_, #nl, #nvl>(#args, v, tau, #sincos)
        },
        Function::MassMatrixInverse => {
            quote!(#dk::floating_mass_matrix_inverse::<_, #nl, #nvl>(#args, #sincos))
        }
        Function::Momentum => quote!(#fk::momentum::<_, #nl>(#args, v, #sincos)),
        Function::BaseReaction => quote!(#fk::base_reaction::<_, #nl>(#args, v, a, #sincos)),
        Function::FramePlacement(k) => {
            let fr = frame(k);
            quote!(#ff::frame_placement::<_, #nl>(&Self::CX, #fr, q, #sincos))
        }
        Function::FrameJacobian(k) => {
            let fr = frame(k);
            quote!(#ff::frame_jacobian::<_, #nl, #nvl>(&Self::CX, #fr, q, #sincos))
        }
        Function::GeneralizedJacobian(k) => {
            let fr = frame(k);
            quote! {
                #ff::generalized_jacobian::<_, #nl>(&Self::CX, #i, &Self::CX_BASE, #fr, q, #sincos)
            }
        }
        Function::MassMatrix => quote!(#fk::mass_matrix::<_, #nl, #nvl>(#args, #sincos)),
        Function::NonlinearEffects => {
            quote!(#fk::inverse_dynamics::<_, #nl, #nvl>(#args, #some_v, #none, #sincos))
        }
        Function::Gravity => {
            quote!(#fk::inverse_dynamics::<_, #nl, #nvl>(#args, #none, #none, #sincos))
        }
        Function::InverseDynamics => {
            quote!(#fk::inverse_dynamics::<_, #nl, #nvl>(#args, #some_v, #some_a, #sincos))
        }
        Function::MassMatrixAndNonlinearEffects => {
            quote!(#fk::mass_matrix_and_nonlinear_effects::<_, #nl, #nvl>(#args, v, #sincos))
        }
        Function::ForwardDynamics => {
            quote!(#fk::forward_dynamics::<_, #nl, #nvl>(#args, v, tau, #none, #sincos))
        }
        Function::ForwardDynamicsWithWrenches => {
            quote!(#fk::forward_dynamics::<_, #nl, #nvl>(#args, v, tau, #some_f_ext, #sincos))
        }
        _ => return None,
    })
}

/// The free-floating base's constant of the compact form (`CX_BASE`): its spatial inertia about
/// its origin and gravity in the inertial frame, as the floating kernels read them.
fn floating_base(rt: &TokenStream, float: Float, base: &Base<f64>) -> TokenStream {
    let fl = float.ty();
    let inertia = vector(float, &base.inertia);
    let gravity = paths::option(base.gravity.as_ref().map(|g| vector(float, g)));
    quote! {
        /// Compact form: the free-floating base's spatial inertia about its origin
        /// (`[m, h, Ī]`) and gravity in the inertial frame, as the floating kernels read them.
        const CX_BASE: #rt::compact::floating::Base<#fl> = #rt::compact::floating::Base {
            inertia: #inertia,
            gravity: #gravity,
        };
    }
}

/// The frames' constants of the compact form (`CX_FRAMES`, none without frames): each frame's
/// body, origin and orientation in the body frame, as the frame kernels read them.
fn frames(rt: &TokenStream, float: Float, frames: &[Frame<f64>]) -> TokenStream {
    if frames.is_empty() {
        return TokenStream::new();
    }
    let fl = float.ty();
    let k = Literal::usize_unsuffixed(frames.len());
    let each = frames.iter().map(|f| {
        let body = paths::option(f.body.map(Literal::usize_unsuffixed));
        let (t, r) = (vector(float, &f.translation), mat(float, &f.rotation));
        quote!(#rt::compact::Frame { body: #body, translation: #t, rotation: #r })
    });
    quote! {
        /// Compact form: the named frames (body, origin and orientation in the body frame), in
        /// the model's order, as the frame kernels read them.
        const CX_FRAMES: [#rt::compact::Frame<#fl>; #k] = [#(#each),*];
    }
}

/// The body of `f` in the compact form of `model`: one call of its runtime kernel
/// (`kanegen_runtime::compact`, `kanegen_runtime::compact::coupled` with mimic joints) on the
/// type's tables (`None`: `f` stays straight-line, [`has_body`]).
///
/// # Errors
/// A runtime or libm path that is not a Rust path.
pub fn body(
    f: Function,
    opts: &Options,
    model: &Model,
    floating: bool,
) -> Result<Option<TokenStream>, Error> {
    let n = model.dof();
    let rt = opts.runtime()?;
    let sincos = if opts.table_sincos() {
        quote!(Self::sincos)
    } else {
        let libm = opts.libm()?;
        let f = opts.float.libm_fn("sincos");
        quote!(#libm::#f)
    };
    let nl = Literal::usize_unsuffixed(n);
    let i = if opts.runtime_payload {
        quote!(&#rt::compact::with_payload::<_, #nl>(Self::CX.inertia, payload.mass, &payload.com, &payload.inertia))
    } else {
        quote!(Self::CX.inertia)
    };
    let k = quote!(#rt::compact);
    if model.has_mimics() {
        let sizes = (n, model.coordinate_count());
        return Ok(coupled_body(f, &k, &i, &sincos, sizes, floating));
    }
    if floating {
        return Ok(floating_body(f, &k, &i, &sincos, n));
    }
    let frame = |f: usize| {
        let f = Literal::usize_unsuffixed(f);
        quote!(&Self::CX_FRAMES[#f])
    };
    let cx = quote!(Self::CX);
    Ok(fixed_call(f, &k, &cx, &i, &|a| quote!(#a), &sincos, &frame))
}

/// The kernel call of function `f` on a fixed base: tables `cx`, inertias `i`, each argument
/// `a` as `arg(a)`, sines and cosines by `sincos`, named frame `j` as `frame(j)`.
fn fixed_call(
    f: Function,
    k: &TokenStream,
    cx: &TokenStream,
    i: &TokenStream,
    arg: &dyn Fn(syn::Ident) -> TokenStream,
    sincos: &TokenStream,
    frame: &dyn Fn(usize) -> TokenStream,
) -> Option<TokenStream> {
    let [q, qd, qdd, tau, f_ext] =
        ["q", "qd", "qdd", "tau", "f_ext"].map(|a| arg(quote::format_ident!("{a}")));
    Some(match f {
        Function::MassMatrix => quote!(#k::mass_matrix(&#cx, #i, #q, #sincos)),
        Function::NonlinearEffects => {
            quote!(#k::nonlinear_effects(&#cx, #i, #q, #qd, #sincos))
        }
        Function::Gravity => quote!(#k::gravity(&#cx, #i, #q, #sincos)),
        Function::InverseDynamics => {
            quote!(#k::inverse_dynamics(&#cx, #i, #q, #qd, #qdd, #sincos))
        }
        Function::MassMatrixAndNonlinearEffects => {
            quote!(#k::mass_matrix_and_nonlinear_effects(&#cx, #i, #q, #qd, #sincos))
        }
        Function::ForwardDynamics => {
            quote!(#k::forward_dynamics(&#cx, #i, #q, #qd, #tau, #sincos))
        }
        Function::ForwardDynamicsWithWrenches => quote! {
            #k::forward_dynamics_with_wrenches(&#cx, #i, #q, #qd, #tau, #f_ext, #sincos)
        },
        Function::FramePlacement(f) => {
            let f = frame(f);
            quote!(#k::frame_placement(&#cx, #f, #q, #sincos))
        }
        Function::FrameJacobian(f) => {
            let f = frame(f);
            quote!(#k::frame_jacobian(&#cx, #f, #q, #sincos))
        }
        Function::InverseDynamicsDerivatives => quote! {
            #k::derivatives::inverse_dynamics_derivatives(&#cx, #i, #q, #qd, #qdd, #sincos)
        },
        Function::ForwardDynamicsDerivatives => quote! {
            #k::derivatives::forward_dynamics_derivatives(&#cx, #i, #q, #qd, #tau, #sincos)
        },
        Function::MassMatrixInverse => {
            quote!(#k::derivatives::mass_matrix_inverse(&#cx, #i, #q, #sincos))
        }
        _ => return None,
    })
}

/// The most joints for which a compact function gets a lane body ([`lanes_body`]): at 64 the
/// tables' copy on `f64x4` lanes is 100 KB of the caller's stack (a thread of `rayon`'s pool has
/// 2 MB).
pub const LANES_BODY_MAX_DOF: usize = 64;

/// The body of `NAME_lanes` of a compact function on a fixed base: the same kernel call on the
/// tables' numbers as [`Lane`](kanegen_runtime::lanes::Lane)s of `S` (a stack copy of the
/// `f64` tables, `TablesStore`), the arguments wrapped and the result unwrapped, so each lane
/// is bit for bit the `f64` function's result for its state. `None` where the function has no
/// such body (it then evaluates the scalar function lane by lane): `f32` code, a free-floating
/// base, mimic joints, a runtime payload, more than [`LANES_BODY_MAX_DOF`] joints (the copy of
/// the tables is 49 N + 6 numbers on the caller's stack per lane), the named frames (whose
/// tables stay `f64`), and `M`
/// and `(M, c)`: the composite-rigid-body kernel's rows are vectorized across the joints
/// already, and on lanes it ran slower than the scalar function state by state (random chains,
/// `f64x4`, 256 states: 0.68× at N = 16 and 32; docs/performance.md).
pub fn lanes_body(
    f: Function,
    opts: &Options,
    model: &Model,
    floating: bool,
) -> Result<Option<TokenStream>, Error> {
    if opts.float != Float::F64
        || floating
        || model.dof() > LANES_BODY_MAX_DOF
        || model.has_mimics()
        || opts.runtime_payload
        || matches!(
            f,
            Function::FramePlacement(_)
                | Function::FrameJacobian(_)
                | Function::MassMatrix
                | Function::MassMatrixAndNonlinearEffects
        )
    {
        return Ok(None);
    }
    let rt = opts.runtime()?;
    let lane = quote!(#rt::lanes::Lane);
    let sincos = match (opts.table_sincos(), !opts.fma && opts.target_fma) {
        (true, true) => quote!(#lane::sincos_table),
        (true, false) => quote!(#lane::sincos_table_unfused),
        (false, _) => quote!(#lane::sincos_libm),
    };
    let k = quote!(#rt::compact);
    let (cx, i) = (quote!(cx), quote!(cx.inertia));
    let arg = |a: syn::Ident| {
        if a == "f_ext" {
            quote!(&#rt::lanes::wrap_rows(#a))
        } else {
            quote!(&#rt::lanes::wrap(#a))
        }
    };
    let Some(call) = fixed_call(f, &k, &cx, &i, &arg, &sincos, &|_| quote!()) else {
        return Ok(None);
    };
    let nl = Literal::usize_unsuffixed(model.dof());
    Ok(Some(quote! {
        let store = #k::TablesStore::<#lane<S>, #nl>::new(&Self::CX);
        let cx = store.tables(&Self::CX);
        #rt::lanes::Unlane::unlane(#call)
    }))
}
