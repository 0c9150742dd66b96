//! The compact form of the generated functions: fixed-size loops over `const` tables of the
//! model's numbers instead of straight-line code, for models where straight-line code loses.
//!
//! Same API as the unrolled form ([`crate::api`]), same parameters (the joints' placements and
//! axes of [`kanegen_dynamics::Params`], the spatial inertias of
//! [`kanegen_dynamics::regroup::regrouped`] when [`Options::regroup`] is on), and the
//! local-frame algorithms of `kanegen_dynamics` written once as loops over the tables:
//!
//! - `mass_matrix`: the composite-rigid-body algorithm (RBDA Table 6.2);
//! - `nonlinear_effects`, `gravity`, `inverse_dynamics`: the recursive Newton–Euler algorithm
//!   (RBDA Table 5.1; gravity as the base's fictitious acceleration `a₀ = −a_g`, RBDA §5.3);
//! - `forward_dynamics`, `forward_dynamics_with_wrenches`: the articulated-body algorithm
//!   (RBDA Table 7.1), O(N) instead of the unrolled form's CRBA + RNEA + LDLᵀ;
//! - `mass_matrix_and_nonlinear_effects`: CRBA and RNEA on one set of joint transforms.
//!
//! Trees are handled through the parent table (`λ(i) < i`). Arrays live on the stack
//! (`[[f64; 6]; N]`, …), nothing allocates, no function panics (parent indices are read with
//! `get`, loops run over arrays of size `N`), sines and cosines go through the configured libm
//! path, and `f32` works as `f64`. The frame functions (`<frame>_placement`, `<frame>_jacobian`)
//! stay straight-line code: their cost grows with one path of the tree, not with its size.
//!
//! Supported: a fixed base, chains and trees, `f64` and `f32`, gravity, a runtime payload (the
//! last body's inertia built from it at each call), with or without regrouping. Not supported
//! (the generator keeps the unrolled form, and `form = "compact"` is an error): a free-floating
//! base.
//!
//! # The joint transform in three constant matrices
//!
//! `Xup_j = XJ(q_j) Xtree_j` has rotation `E_j = (Υ_j Θ(q_j))ᵀ` (RBDA §4.4, Table 4.1) with
//! Rodrigues' `Θ = u uᵀ + c (1 − u uᵀ) + s ũ` for the unit axis `u`, so
//! `E_j = A_j + c B_j + s C_j` with the constants `A = (Υ u uᵀ)ᵀ`, `B = (Υ (1 − u uᵀ))ᵀ`,
//! `C = (Υ ũ)ᵀ`; a prismatic joint has `A = Υᵀ`, `B = C = 0` and `r_j = l_j + q_j Υ u`. One
//! table serves both kinds without a branch on the kind in the transforms.
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

use crate::options::{Error, Float, Form, Options};
use kanegen_dynamics::{ForwardMethod, MassMatrixMethod, Methods, NonlinearEffectsMethod};
use kanegen_model::{BaseKind, JointKind, Model};
use kanegen_trace::Function;
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
/// [`Form::Auto`], an O(N) Newton–Euler function (then it does when its unrolled body has at
/// most [`LINEAR_AUTO_LIMIT`] emitted operations, [`keeps_unrolled`]).
#[must_use]
pub fn may_keep_unrolled(opts: &Options, f: Function) -> bool {
    opts.form == Form::Auto
        && matches!(
            f,
            Function::NonlinearEffects | Function::Gravity | Function::InverseDynamics
        )
}

/// Whether `f` keeps its unrolled body in a model that [`decide`] made compact: it
/// [`may_keep_unrolled`] and its unrolled body, traced as far as `size`, has at most
/// [`LINEAR_AUTO_LIMIT`] emitted operations.
#[must_use]
pub fn keeps_unrolled(opts: &Options, f: Function, size: Size) -> bool {
    may_keep_unrolled(opts, f) && !size.above(LINEAR_AUTO_LIMIT)
}

/// Why the compact form cannot be emitted for `model` under `opts`, or `None` when it can.
#[must_use]
pub fn unsupported(model: &Model, opts: &Options) -> Option<&'static str> {
    if opts.algorithm.is_some() {
        // The compact form has its own algorithms (CRBA, RNEA, ABA).
        return Some("a forced algorithm");
    }
    (model.base_kind() == BaseKind::FreeFloating).then_some("a free-floating base")
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
            "Form: compact: loops over constant tables (CRBA, RNEA, ABA; frame functions \
             straight-line) ({why}). The functions in loops are not traced: their `OP_COUNTS` \
             entries name the loops' methods with 0 operations (unknown), and `CANDIDATES` and \
             the table below hold the straight-line functions only."
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

/// Whether the compact form has its own body for `f` (the frame functions stay straight-line).
#[must_use]
pub fn has_body(f: Function) -> bool {
    matches!(
        f,
        Function::MassMatrix
            | Function::NonlinearEffects
            | Function::Gravity
            | Function::InverseDynamics
            | Function::ForwardDynamics
            | Function::ForwardDynamicsWithWrenches
            | Function::MassMatrixAndNonlinearEffects
    )
}

type M3 = [[f64; 3]; 3];

fn mat(float: Float, m: &M3) -> TokenStream {
    let rows = m.iter().map(|r| {
        let r = r.map(|x| float.suffixed(x));
        quote!([#(#r),*])
    });
    quote!([#(#rows),*])
}

fn vector<const K: usize>(float: Float, v: &[f64; K]) -> TokenStream {
    let v = v.map(|x| float.suffixed(x));
    quote!([#(#v),*])
}

fn transpose(m: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| m[j][i]))
}

fn mul(a: &M3, b: &M3) -> M3 {
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// The private constant tables and helper functions of the compact form (items of the
/// generated `impl`).
///
/// # Errors
/// A libm path that is not a Rust path.
#[allow(clippy::too_many_lines)]
pub fn items(model: &Model, opts: &Options) -> Result<TokenStream, Error> {
    let fl = opts.float.ty();
    let float = opts.float;
    let libm = opts.libm()?;
    let sincos = if opts.table_sincos() {
        quote!(Self::sincos)
    } else {
        let f = float.libm_fn("sincos");
        quote!(#libm::#f)
    };
    let n = model.dof();
    let nl = Literal::usize_unsuffixed(n);
    // The payload body neither gives nor receives (its inertia is a runtime input).
    let keep: &[usize] = if opts.runtime_payload { &[n - 1] } else { &[] };
    let p = if opts.regroup {
        kanegen_dynamics::regroup::regrouped::<f64>(model, None, keep).params
    } else {
        kanegen_dynamics::Params::<f64>::new(model)
    };
    let (mut ta, mut tb, mut tc, mut tl, mut tslide, mut ts, mut ti, mut par, mut rev) = (
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
        vec![],
    );
    for jp in &p.joints {
        let u = jp.axis.0;
        let ups = jp.upsilon.0;
        let uu: M3 = core::array::from_fn(|i| core::array::from_fn(|j| u[i] * u[j]));
        let one_minus: M3 = core::array::from_fn(|i| {
            core::array::from_fn(|j| f64::from(u8::from(i == j)) - uu[i][j])
        });
        let skew: M3 = [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]];
        let zero = [[0.0; 3]; 3];
        let (a, b, c, slide, s) = match jp.kind {
            JointKind::Revolute => (
                transpose(&mul(&ups, &uu)),
                transpose(&mul(&ups, &one_minus)),
                transpose(&mul(&ups, &skew)),
                [0.0; 3],
                [u[0], u[1], u[2], 0.0, 0.0, 0.0],
            ),
            JointKind::Prismatic => (
                transpose(&ups),
                zero,
                zero,
                core::array::from_fn(|i| (0..3).map(|k| ups[i][k] * u[k]).sum()),
                [0.0, 0.0, 0.0, u[0], u[1], u[2]],
            ),
        };
        ta.push(mat(float, &a));
        tb.push(mat(float, &b));
        tc.push(mat(float, &c));
        tl.push(vector(float, &jp.l.0));
        tslide.push(vector(float, &slide));
        ts.push(vector(float, &s));
        let i = &jp.inertia;
        let ib = i.ibar.0;
        ti.push(vector(
            float,
            &[
                i.m, i.h.0[0], i.h.0[1], i.h.0[2], ib[0][0], ib[0][1], ib[0][2], ib[1][1],
                ib[1][2], ib[2][2],
            ],
        ));
        par.push(match jp.parent {
            Some(l) => {
                let l = Literal::usize_unsuffixed(l);
                quote!(Some(#l))
            }
            None => quote!(None),
        });
        rev.push(jp.kind == JointKind::Revolute);
    }
    let a0 = match opts.gravity {
        Some(g) => {
            let g = g.map(|x| float.suffixed(-x));
            quote!([0.0, 0.0, 0.0, #(#g),*])
        }
        None => quote!([0.0; 6]),
    };
    let payload_fn = if opts.runtime_payload {
        let ty = syn::parse_str::<syn::Ident>(&opts.payload_name)
            .map_err(|e| Error(format!("payload name `{}`: {e}", opts.payload_name)))?;
        quote! {
            /// Compact form: the inertia table with the payload's spatial inertia as the last
            /// body's, `h = m c`, `Ī = I_c + m (|c|² 1 − c cᵀ)` (RBDA eq. (2.63), parallel axes).
            #[inline(always)]
            fn cx_inertia(payload: &#ty) -> [[#fl; 10]; #nl] {
                let mut t = Self::CX_INERTIA;
                let (m, c, ic) = (payload.mass, &payload.com, &payload.inertia);
                let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
                if let Some(last) = t.last_mut() {
                    *last = [
                        m,
                        m * c[0],
                        m * c[1],
                        m * c[2],
                        ic[0][0] + m * (cc - c[0] * c[0]),
                        ic[0][1] - m * c[0] * c[1],
                        ic[0][2] - m * c[0] * c[2],
                        ic[1][1] + m * (cc - c[1] * c[1]),
                        ic[1][2] - m * c[1] * c[2],
                        ic[2][2] + m * (cc - c[2] * c[2]),
                    ];
                }
                t
            }
        }
    } else {
        quote!()
    };
    // On a tree, row `i` of `H` keeps the entries of `i`'s ancestors (RBDA §6.2: the others
    // are zero); a chain's every `j < i` is one.
    let (mask, ancestor_table) = if model.is_chain() {
        (quote!(), quote!())
    } else {
        let rows = (0..n).map(|i| {
            let mut anc = vec![false; n];
            let mut j = Some(i);
            while let Some(k) = j {
                anc[k] = true;
                j = p.joints[k].parent;
            }
            quote!([#(#anc),*])
        });
        (
            quote! {
                for (hij, keep) in h[i].iter_mut().zip(Self::CX_ANCESTOR[i]) {
                    if !keep {
                        *hij = 0.0;
                    }
                }
            },
            quote! {
                /// Compact form: whether joint `j` is joint `i` or one of its ancestors
                /// (`[i][j]`).
                const CX_ANCESTOR: [[bool; #nl]; #nl] = [#(#rows),*];
            },
        )
    };
    let (sym_times_s, sym_minus_outer, sym_p) = packed_symmetric();
    Ok(quote! {
        #ancestor_table
        /// Compact form: each joint's parent body `λ(j) < j` (`None`: the base).
        const CX_PARENT: [Option<usize>; #nl] = [#(#par),*];
        /// Compact form: whether joint `j` is revolute (else prismatic).
        const CX_REVOLUTE: [bool; #nl] = [#(#rev),*];
        /// Compact form: `E_j = A_j + cos q_j B_j + sin q_j C_j` (module docs): `A_j`.
        const CX_A: [[[#fl; 3]; 3]; #nl] = [#(#ta),*];
        /// Compact form: `B_j`.
        const CX_B: [[[#fl; 3]; 3]; #nl] = [#(#tb),*];
        /// Compact form: `C_j`.
        const CX_C: [[[#fl; 3]; 3]; #nl] = [#(#tc),*];
        /// Compact form: joint origin `l_j` in the parent body frame.
        const CX_L: [[#fl; 3]; #nl] = [#(#tl),*];
        /// Compact form: `Υ_j u_j` of a prismatic joint (zero for a revolute one).
        const CX_SLIDE: [[#fl; 3]; #nl] = [#(#tslide),*];
        /// Compact form: motion subspace `S_j` (`[u; 0]` revolute, `[0; u]` prismatic).
        const CX_S: [[#fl; 6]; #nl] = [#(#ts),*];
        /// Compact form: spatial inertia of body `j` about its origin, `[m, h (3), Ī_xx, Ī_xy,
        /// Ī_xz, Ī_yy, Ī_yz, Ī_zz]` (RBDA eq. (2.63)).
        const CX_INERTIA: [[#fl; 10]; #nl] = [#(#ti),*];
        /// Compact form: the base's spatial acceleration `a₀ = [0; −g]` (RBDA §5.3).
        const CX_A0: [#fl; 6] = #a0;

        #payload_fn

        /// Compact form: `(E_j, r_j)` of `Xup_j = XJ(q_j) Xtree_j` for every joint (RBDA §4.4).
        #[inline(always)]
        fn cx_transforms(q: &[#fl; #nl]) -> [([[#fl; 3]; 3], [#fl; 3]); #nl] {
            let mut x = [([[0.0; 3]; 3], [0.0; 3]); #nl];
            for (j, xj) in x.iter_mut().enumerate() {
                let (s, c, d) = if Self::CX_REVOLUTE[j] {
                    let (s, c) = #sincos(q[j]);
                    (s, c, 0.0)
                } else {
                    (0.0, 0.0, q[j])
                };
                let (a, b, cc) = (&Self::CX_A[j], &Self::CX_B[j], &Self::CX_C[j]);
                for r in 0..3 {
                    for k in 0..3 {
                        xj.0[r][k] = a[r][k] + c * b[r][k] + s * cc[r][k];
                    }
                    xj.1[r] = Self::CX_L[j][r] + d * Self::CX_SLIDE[j][r];
                }
            }
            x
        }

        /// `a × b`.
        #[inline(always)]
        fn cx_cross(a: &[#fl; 3], b: &[#fl; 3]) -> [#fl; 3] {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        }

        /// `E v`.
        #[inline(always)]
        fn cx_rot(e: &[[#fl; 3]; 3], v: &[#fl; 3]) -> [#fl; 3] {
            [
                e[0][0] * v[0] + e[0][1] * v[1] + e[0][2] * v[2],
                e[1][0] * v[0] + e[1][1] * v[1] + e[1][2] * v[2],
                e[2][0] * v[0] + e[2][1] * v[1] + e[2][2] * v[2],
            ]
        }

        /// `Eᵀ v`.
        #[inline(always)]
        fn cx_rot_tr(e: &[[#fl; 3]; 3], v: &[#fl; 3]) -> [#fl; 3] {
            [
                e[0][0] * v[0] + e[1][0] * v[1] + e[2][0] * v[2],
                e[0][1] * v[0] + e[1][1] * v[1] + e[2][1] * v[2],
                e[0][2] * v[0] + e[1][2] * v[1] + e[2][2] * v[2],
            ]
        }

        /// `X m = [E ω; E (v − r × ω)]` for a motion `m = [ω; v]` (RBDA eq. (2.24)).
        #[inline(always)]
        fn cx_apply(x: &([[#fl; 3]; 3], [#fl; 3]), m: &[#fl; 6]) -> [#fl; 6] {
            let w = [m[0], m[1], m[2]];
            let rw = Self::cx_cross(&x.1, &w);
            let a = Self::cx_rot(&x.0, &w);
            let l = Self::cx_rot(&x.0, &[m[3] - rw[0], m[4] - rw[1], m[5] - rw[2]]);
            [a[0], a[1], a[2], l[0], l[1], l[2]]
        }

        /// `Xᵀ f = [Eᵀ n + r × Eᵀ f; Eᵀ f]` for a force `f = [n; f]` (RBDA Table 2.5).
        #[inline(always)]
        fn cx_apply_tr(x: &([[#fl; 3]; 3], [#fl; 3]), f: &[#fl; 6]) -> [#fl; 6] {
            let l = Self::cx_rot_tr(&x.0, &[f[3], f[4], f[5]]);
            let a = Self::cx_rot_tr(&x.0, &[f[0], f[1], f[2]]);
            let rl = Self::cx_cross(&x.1, &l);
            [a[0] + rl[0], a[1] + rl[1], a[2] + rl[2], l[0], l[1], l[2]]
        }

        /// `a ×ₘ b = [ω_a × ω_b; ω_a × v_b + v_a × ω_b]` (RBDA eq. (2.31)).
        #[inline(always)]
        fn cx_crm(a: &[#fl; 6], b: &[#fl; 6]) -> [#fl; 6] {
            let (wa, va, wb, vb) = (
                [a[0], a[1], a[2]],
                [a[3], a[4], a[5]],
                [b[0], b[1], b[2]],
                [b[3], b[4], b[5]],
            );
            let x = Self::cx_cross(&wa, &wb);
            let y = Self::cx_cross(&wa, &vb);
            let z = Self::cx_cross(&va, &wb);
            [x[0], x[1], x[2], y[0] + z[0], y[1] + z[1], y[2] + z[2]]
        }

        /// `v ×* f = [ω × n + v × f; ω × f]` (RBDA eq. (2.32)).
        #[inline(always)]
        fn cx_crf(v: &[#fl; 6], f: &[#fl; 6]) -> [#fl; 6] {
            let (w, vl, n, fl) = (
                [v[0], v[1], v[2]],
                [v[3], v[4], v[5]],
                [f[0], f[1], f[2]],
                [f[3], f[4], f[5]],
            );
            let x = Self::cx_cross(&w, &n);
            let y = Self::cx_cross(&vl, &fl);
            let z = Self::cx_cross(&w, &fl);
            [x[0] + y[0], x[1] + y[1], x[2] + y[2], z[0], z[1], z[2]]
        }

        /// `I m = [Ī ω + h × v; m v − h × ω]` (RBDA eq. (2.63)).
        #[inline(always)]
        fn cx_inertia_mul(i: &[#fl; 10], m: &[#fl; 6]) -> [#fl; 6] {
            let (w, v, h) = ([m[0], m[1], m[2]], [m[3], m[4], m[5]], [i[1], i[2], i[3]]);
            let hv = Self::cx_cross(&h, &v);
            let hw = Self::cx_cross(&h, &w);
            [
                i[4] * w[0] + i[5] * w[1] + i[6] * w[2] + hv[0],
                i[5] * w[0] + i[7] * w[1] + i[8] * w[2] + hv[1],
                i[6] * w[0] + i[8] * w[1] + i[9] * w[2] + hv[2],
                i[0] * v[0] - hw[0],
                i[0] * v[1] - hw[1],
                i[0] * v[2] - hw[2],
            ]
        }

        /// `Xᵀ I X` (RBDA Table 2.5): `h' = Eᵀh + m r`,
        /// `Ī' = Eᵀ Ī E − (Eᵀh) rᵀ − r h'ᵀ + (r·Eᵀh + r·h') 1`.
        #[inline(always)]
        fn cx_inertia_tr(x: &([[#fl; 3]; 3], [#fl; 3]), i: &[#fl; 10]) -> [#fl; 10] {
            let (e, r, m) = (&x.0, &x.1, i[0]);
            let ib = [[i[4], i[5], i[6]], [i[5], i[7], i[8]], [i[6], i[8], i[9]]];
            let hr = Self::cx_rot_tr(e, &[i[1], i[2], i[3]]);
            let h = [hr[0] + m * r[0], hr[1] + m * r[1], hr[2] + m * r[2]];
            // Ī E, then Eᵀ (Ī E): upper triangle.
            let mut ie = [[0.0; 3]; 3];
            for a in 0..3 {
                for b in 0..3 {
                    ie[a][b] = ib[a][0] * e[0][b] + ib[a][1] * e[1][b] + ib[a][2] * e[2][b];
                }
            }
            let d = r[0] * (hr[0] + h[0]) + r[1] * (hr[1] + h[1]) + r[2] * (hr[2] + h[2]);
            let entry = |a: usize, b: usize| {
                let eie = e[0][a] * ie[0][b] + e[1][a] * ie[1][b] + e[2][a] * ie[2][b];
                let diag = if a == b { d } else { 0.0 };
                eie - hr[a] * r[b] - r[a] * h[b] + diag
            };
            [
                m,
                h[0],
                h[1],
                h[2],
                entry(0, 0),
                entry(0, 1),
                entry(0, 2),
                entry(1, 1),
                entry(1, 2),
                entry(2, 2),
            ]
        }

        /// `a · b` of two 6-vectors (`S_jᵀ f`).
        #[inline(always)]
        fn cx_dot(a: &[#fl; 6], b: &[#fl; 6]) -> #fl {
            a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
        }

        /// `a + k b`.
        #[inline(always)]
        fn cx_axpy(a: &[#fl; 6], k: #fl, b: &[#fl; 6]) -> [#fl; 6] {
            [
                a[0] + k * b[0],
                a[1] + k * b[1],
                a[2] + k * b[2],
                a[3] + k * b[3],
                a[4] + k * b[4],
                a[5] + k * b[5],
            ]
        }

        /// `a + b`.
        #[inline(always)]
        fn cx_add(a: &[#fl; 6], b: &[#fl; 6]) -> [#fl; 6] {
            [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4], a[5] + b[5]]
        }

        /// Each body's placement in base coordinates, `(E_0i, p_0i)`: `E_0i = E_i E_0λ(i)`
        /// rotates base to body coordinates, `p_0i = p_0λ(i) + E_0λ(i)ᵀ r_i` is the body
        /// origin (RBDA §2.8, composition of Plücker transforms); with each joint's motion
        /// subspace `S_i` and each body's spatial inertia `I_i` (about the base origin) in base
        /// coordinates, `ᴼX_i S_i` and `ᴼX_i* I_i ⁱX_O` (RBDA eq. (2.66)).
        #[inline(always)]
        fn cx_world(
            x: &[([[#fl; 3]; 3], [#fl; 3]); #nl],
            inertia: &[[#fl; 10]; #nl],
        ) -> (
            [([[#fl; 3]; 3], [#fl; 3]); #nl],
            [[#fl; 6]; #nl],
            [[#fl; 10]; #nl],
        ) {
            let mut x0 = [([[0.0; 3]; 3], [0.0; 3]); #nl];
            let mut s0 = [[0.0; 6]; #nl];
            let mut i0 = [[0.0; 10]; #nl];
            for i in 0..#nl {
                let (e, r) = &x[i];
                x0[i] = match Self::CX_PARENT[i].and_then(|l| x0.get(l)) {
                    Some((el, pl)) => {
                        let mut e0 = [[0.0; 3]; 3];
                        for a in 0..3 {
                            for b in 0..3 {
                                e0[a][b] = e[a][0] * el[0][b] + e[a][1] * el[1][b] + e[a][2] * el[2][b];
                            }
                        }
                        let d = Self::cx_rot_tr(el, r);
                        (e0, [pl[0] + d[0], pl[1] + d[1], pl[2] + d[2]])
                    }
                    None => (*e, *r),
                };
                let (e0, p0) = &x0[i];
                let s = &Self::CX_S[i];
                let w = Self::cx_rot_tr(e0, &[s[0], s[1], s[2]]);
                let v = Self::cx_rot_tr(e0, &[s[3], s[4], s[5]]);
                let pw = Self::cx_cross(p0, &w);
                s0[i] = [w[0], w[1], w[2], v[0] + pw[0], v[1] + pw[1], v[2] + pw[2]];
                i0[i] = Self::cx_inertia_tr(&x0[i], &inertia[i]);
            }
            (x0, s0, i0)
        }

        /// The joint-space inertia matrix by the composite-rigid-body algorithm (RBDA Table
        /// 6.2) in base coordinates (as Pinocchio's): composite inertias `IC_λ(i) += IC_i`
        /// leaves first (one frame, no transform), then `F = IC_i S_i` and
        /// `H_ij = H_ji = S_jᵀ F` for `j = i` and each ancestor `j` of `i`. The ancestors'
        /// entries of row `i` are taken for every `j ≤ i` at once, a loop over `j` with the
        /// six coordinates of the `S_j` side by side (`st[k][j]`) that the compiler
        /// vectorizes (on a tree, the entries of joints that are not ancestors of `i` are then
        /// set to zero, `CX_ANCESTOR`); the upper triangle is the lower one mirrored.
        #[inline]
        fn cx_crba(
            x: &[([[#fl; 3]; 3], [#fl; 3]); #nl],
            inertia: &[[#fl; 10]; #nl],
        ) -> [[#fl; #nl]; #nl] {
            let (_, s0, mut ic) = Self::cx_world(x, inertia);
            for i in (0..#nl).rev() {
                if let Some(l) = Self::CX_PARENT[i] {
                    let child = ic[i];
                    if let Some(icl) = ic.get_mut(l) {
                        for (a, b) in icl.iter_mut().zip(child) {
                            *a += b;
                        }
                    }
                }
            }
            let mut st = [[0.0; #nl]; 6];
            for (j, s) in s0.iter().enumerate() {
                for (k, sk) in s.iter().enumerate() {
                    st[k][j] = *sk;
                }
            }
            let mut h = [[0.0; #nl]; #nl];
            for i in 0..#nl {
                let f = Self::cx_inertia_mul(&ic[i], &s0[i]);
                for j in 0..i + 1 {
                    h[i][j] = st[0][j] * f[0]
                        + st[1][j] * f[1]
                        + st[2][j] * f[2]
                        + st[3][j] * f[3]
                        + st[4][j] * f[4]
                        + st[5][j] * f[5];
                }
                #mask
            }
            for i in 0..#nl {
                for j in 0..i {
                    h[j][i] = h[i][j];
                }
            }
            h
        }

        /// Inverse dynamics by the recursive Newton–Euler algorithm (RBDA Table 5.1): forward
        /// `v_i = Xup_i v_λ(i) + S_i q̇_i`, `a_i = Xup_i a_λ(i) + S_i q̈_i + v_i ×ₘ S_i q̇_i`,
        /// `f_i = I_i a_i + v_i ×* I_i v_i − f^x_i`; backward `τ_i = S_iᵀ f_i`,
        /// `f_λ(i) += Xup_iᵀ f_i`. `a0`: the base's acceleration (`[0; −g]` for gravity);
        /// `f_ext[i] = [force; moment]` in body `i`'s frame.
        #[inline]
        fn cx_rnea(
            x: &[([[#fl; 3]; 3], [#fl; 3]); #nl],
            inertia: &[[#fl; 10]; #nl],
            qd: &[#fl; #nl],
            qdd: &[#fl; #nl],
            a0: &[#fl; 6],
            f_ext: &[[#fl; 6]; #nl],
        ) -> [#fl; #nl] {
            let mut v = [[0.0; 6]; #nl];
            let mut a = [[0.0; 6]; #nl];
            let mut f = [[0.0; 6]; #nl];
            for i in 0..#nl {
                let (vp, ap) = match Self::CX_PARENT[i].and_then(|l| v.get(l).zip(a.get(l))) {
                    Some((vp, ap)) => (*vp, *ap),
                    None => ([0.0; 6], *a0),
                };
                let vj = Self::cx_axpy(&[0.0; 6], qd[i], &Self::CX_S[i]);
                v[i] = Self::cx_add(&Self::cx_apply(&x[i], &vp), &vj);
                let ai = Self::cx_axpy(&Self::cx_apply(&x[i], &ap), qdd[i], &Self::CX_S[i]);
                a[i] = Self::cx_add(&ai, &Self::cx_crm(&v[i], &vj));
                let iv = Self::cx_inertia_mul(&inertia[i], &v[i]);
                let fi = Self::cx_add(
                    &Self::cx_inertia_mul(&inertia[i], &a[i]),
                    &Self::cx_crf(&v[i], &iv),
                );
                let e = &f_ext[i];
                f[i] = [
                    fi[0] - e[3],
                    fi[1] - e[4],
                    fi[2] - e[5],
                    fi[3] - e[0],
                    fi[4] - e[1],
                    fi[5] - e[2],
                ];
            }
            let mut tau = [0.0; #nl];
            for i in (0..#nl).rev() {
                tau[i] = Self::cx_dot(&Self::CX_S[i], &f[i]);
                if let Some(l) = Self::CX_PARENT[i] {
                    let carried = Self::cx_apply_tr(&x[i], &f[i]);
                    if let Some(fl) = f.get_mut(l) {
                        *fl = Self::cx_add(fl, &carried);
                    }
                }
            }
            tau
        }

        /// Forward dynamics by the articulated-body algorithm (RBDA Table 7.1) in base
        /// coordinates (RBDA §7.3's "any coordinate system", as Pinocchio's), so that no
        /// transform is needed between bodies: `v_i = v_λ + S_i q̇_i`, `c_i = v_i ×ₘ S_i q̇_i`,
        /// `p_i = v_i ×* I_i v_i − f^x_i` outwards; inwards `U_i = I^A_i S_i`,
        /// `D_i = S_iᵀ U_i`, `u_i = τ_i − S_iᵀ p^A_i`, `I^A_λ += I^A_i − U_i U_iᵀ / D_i`,
        /// `p^A_λ += p^A_i + (I^A_i − U_i U_iᵀ / D_i) c_i + U_i u_i / D_i`; outwards
        /// `a' = a_λ + c_i`, `q̈_i = (u_i − U_iᵀ a') / D_i`, `a_i = a' + S_i q̈_i`, from
        /// `a₀ = [0; −g]`. `f_ext[i] = [force; moment]` in body `i`'s frame at its origin
        /// (`None`: no wrenches, nothing computed for them). The articulated inertias are
        /// symmetric and kept as their 21 upper-triangle entries, by rows.
        #[inline]
        fn cx_aba(
            inertia: &[[#fl; 10]; #nl],
            q: &[#fl; #nl],
            qd: &[#fl; #nl],
            tau: &[#fl; #nl],
            f_ext: Option<&[[#fl; 6]; #nl]>,
        ) -> [#fl; #nl] {
            let x = Self::cx_transforms(q);
            let (x0, s0, i0) = Self::cx_world(&x, inertia);
            let mut v = [[0.0; 6]; #nl];
            let mut c = [[0.0; 6]; #nl];
            let mut ia = [[0.0; 21]; #nl];
            let mut pa = [[0.0; 6]; #nl];
            for i in 0..#nl {
                let vp = match Self::CX_PARENT[i].and_then(|l| v.get(l)) {
                    Some(vp) => *vp,
                    None => [0.0; 6],
                };
                let vj = Self::cx_axpy(&[0.0; 6], qd[i], &s0[i]);
                v[i] = Self::cx_add(&vp, &vj);
                c[i] = Self::cx_crm(&v[i], &vj);
                let k = &i0[i];
                // I = [Ī h̃; h̃ᵀ m1] (RBDA eq. (2.63)), upper triangle by rows.
                ia[i] = [
                    k[4], k[5], k[6], 0.0, -k[3], k[2],
                    k[7], k[8], k[3], 0.0, -k[1],
                    k[9], -k[2], k[1], 0.0,
                    k[0], 0.0, 0.0,
                    k[0], 0.0,
                    k[0],
                ];
                let iv = Self::cx_inertia_mul(k, &v[i]);
                let p = Self::cx_crf(&v[i], &iv);
                pa[i] = match f_ext {
                    Some(f_ext) => {
                        let e = &f_ext[i];
                        let fx = Self::cx_apply_tr(&x0[i], &[e[3], e[4], e[5], e[0], e[1], e[2]]);
                        [
                            p[0] - fx[0],
                            p[1] - fx[1],
                            p[2] - fx[2],
                            p[3] - fx[3],
                            p[4] - fx[4],
                            p[5] - fx[5],
                        ]
                    }
                    None => p,
                };
            }
            let mut u = [[0.0; 6]; #nl];
            let mut d = [1.0; #nl];
            let mut uu = [0.0; #nl];
            for i in (0..#nl).rev() {
                let s = &s0[i];
                let iai = &ia[i];
                let ui = #sym_times_s;
                d[i] = Self::cx_dot(s, &ui);
                uu[i] = tau[i] - Self::cx_dot(s, &pa[i]);
                u[i] = ui;
                if let Some(l) = Self::CX_PARENT[i] {
                    let dinv = 1.0 / d[i];
                    let w = [
                        ui[0] * dinv,
                        ui[1] * dinv,
                        ui[2] * dinv,
                        ui[3] * dinv,
                        ui[4] * dinv,
                        ui[5] * dinv,
                    ];
                    let m = #sym_minus_outer;
                    let p = Self::cx_axpy(&pa[i], uu[i], &w);
                    let ci = &c[i];
                    let p = #sym_p;
                    if let (Some(ial), Some(pal)) = (ia.get_mut(l), pa.get_mut(l)) {
                        for (a, b) in ial.iter_mut().zip(m) {
                            *a += b;
                        }
                        *pal = Self::cx_add(pal, &p);
                    }
                }
            }
            let mut acc = [[0.0; 6]; #nl];
            let mut qdd = [0.0; #nl];
            for i in 0..#nl {
                let ap = match Self::CX_PARENT[i].and_then(|l| acc.get(l)) {
                    Some(ap) => *ap,
                    None => Self::CX_A0,
                };
                let a = Self::cx_add(&ap, &c[i]);
                qdd[i] = (uu[i] - Self::cx_dot(&u[i], &a)) / d[i];
                acc[i] = Self::cx_axpy(&a, qdd[i], &s0[i]);
            }
            qdd
        }
    })
}

/// Where entry `(r, c)` of a symmetric 6×6 matrix is kept among its 21 upper-triangle entries,
/// by rows.
fn sym_index(r: usize, c: usize) -> usize {
    let (r, c) = (r.min(c), r.max(c));
    r * 6 - r * (r + 1) / 2 + c
}

/// The expressions of `cx_aba`'s packed articulated inertias, each `[…]` of literal indices:
/// `U = I^A S` (from `iai`, `s`), `I^A − W Uᵀ` (from `iai`, `w`, `ui`), and `p + (I^A − W Uᵀ) c`
/// (from `p`, `m`, `ci`).
fn packed_symmetric() -> (TokenStream, TokenStream, TokenStream) {
    let lit = Literal::usize_unsuffixed;
    let times = |m: &str, v: &str, r: usize| {
        let (m, v) = (quote::format_ident!("{m}"), quote::format_ident!("{v}"));
        let terms = (0..6).map(|c| {
            let (k, c) = (lit(sym_index(r, c)), lit(c));
            quote!(#m[#k] * #v[#c])
        });
        quote!(#(#terms)+*)
    };
    let u = (0..6).map(|r| times("iai", "s", r));
    let m = (0..6)
        .flat_map(|r| (r..6).map(move |c| (r, c)))
        .map(|(r, c)| {
            let (k, r, c) = (lit(sym_index(r, c)), lit(r), lit(c));
            quote!(iai[#k] - w[#r] * ui[#c])
        });
    let p = (0..6).map(|r| {
        let sum = times("m", "ci", r);
        let r = lit(r);
        quote!(p[#r] + (#sum))
    });
    (quote!([#(#u),*]), quote!([#(#m),*]), quote!([#(#p),*]))
}

/// The body of `f` in the compact form (`None`: `f` stays straight-line, [`has_body`]).
#[must_use]
pub fn body(f: Function, opts: &Options, n: usize) -> Option<TokenStream> {
    let nl = Literal::usize_unsuffixed(n);
    let gravity = opts.gravity.is_some();
    let a0 = if gravity {
        quote!(&Self::CX_A0)
    } else {
        quote!(&[0.0; 6])
    };
    let zero = quote!(&[0.0; #nl]);
    let no_ext = quote!(&[[0.0; 6]; #nl]);
    let i = if opts.runtime_payload {
        quote!(&Self::cx_inertia(payload))
    } else {
        quote!(&Self::CX_INERTIA)
    };
    Some(match f {
        Function::MassMatrix => quote! {
            Self::cx_crba(&Self::cx_transforms(q), #i)
        },
        Function::NonlinearEffects => quote! {
            Self::cx_rnea(&Self::cx_transforms(q), #i, qd, #zero, #a0, #no_ext)
        },
        Function::Gravity => quote! {
            Self::cx_rnea(&Self::cx_transforms(q), #i, #zero, #zero, &Self::CX_A0, #no_ext)
        },
        Function::InverseDynamics => quote! {
            Self::cx_rnea(&Self::cx_transforms(q), #i, qd, qdd, #a0, #no_ext)
        },
        Function::MassMatrixAndNonlinearEffects => quote! {
            let x = Self::cx_transforms(q);
            let inertia = #i;
            (Self::cx_crba(&x, inertia), Self::cx_rnea(&x, inertia, qd, #zero, #a0, #no_ext))
        },
        Function::ForwardDynamics => quote! {
            Self::cx_aba(#i, q, qd, tau, None)
        },
        Function::ForwardDynamicsWithWrenches => quote! {
            Self::cx_aba(#i, q, qd, tau, Some(f_ext))
        },
        _ => return None,
    })
}
