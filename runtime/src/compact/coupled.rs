//! The compact kernels of a model with mimic joints ([`crate::coupling`]): the arguments are
//! the independent coordinates (`R` of them), the kernels run on the full joint list (`N`
//! joints, the tables' rows) and their results are reduced.
//!
//! Each function expands the state (`q_full = G q + o`, `q̇_full = G q̇`, `q̈_full = G q̈`, the
//! drives on the independent joints, zero on mimic joints), runs the full kernel of this
//! module's parent, and reduces: `M = Gᵀ M_full G`, `c = Gᵀ c_full`, a Jacobian `J G`, the
//! inverse-dynamics derivatives `Gᵀ D G`. Forward dynamics is not the full articulated-body
//! algorithm (the tree's joints are not free): it solves `M q̈ = Gᵀ (τ_full − c_full + Jᵀ f_ext)`
//! with the reduced `M` by LDLᵀ ([`crate::ldlt`]); its derivatives are
//! `−M⁻¹ Gᵀ (∂τ_full/∂x_full) G` at `q̈_full = G q̈`, and `M⁻¹` that of the reduced `M`
//! (Carpentier & Mansard, RSS 2018, eq. (3), in the reduced coordinates). External wrenches
//! take one row per body of the full tree (after the base's on a free-floating base).
//!
//! On a free-floating base (`NV = N + 6` full speeds, `RV = R + 6` reduced, `NQ = N + 7` full
//! positions), the base's six speeds and seven positions map to themselves.
//!
//! The reduced results live on the stack (arrays of `R`, `RV`), the full ones too (arrays of
//! `N`, `NV`): nothing allocates, nothing panics.

use super::crba::crba;
use super::derivatives::{self as d, ForwardDerivatives};
use super::floating::{self as fl, Base};
use super::frames::Frame;
use super::rnea::{rnea, Motions};
use super::spatial::transforms;
use super::tables::{BodyStore, Tables};
use crate::coupling::Coupling;
use crate::ldlt::{factor_in_place, solve_in_place};
use crate::scalar::Scalar;

/// `q_full` of the coordinates `q` (`R`).
#[inline(always)]
fn positions<S: Scalar + Copy, const N: usize>(c: &Coupling<'_>, q: &[S]) -> [S; N] {
    let mut out = [S::zero(); N];
    c.expand_positions(q, &mut out);
    out
}

/// `x_full = G x` of the coordinates' rates or accelerations `x`.
#[inline(always)]
fn rates<S: Scalar + Copy, const N: usize>(c: &Coupling<'_>, x: &[S]) -> [S; N] {
    let mut out = [S::zero(); N];
    c.expand_rates(x, &mut out);
    out
}

/// `τ_full` of the coordinates' drives `tau`.
#[inline(always)]
fn drives<S: Scalar + Copy, const N: usize>(c: &Coupling<'_>, tau: &[S]) -> [S; N] {
    let mut out = [S::zero(); N];
    c.expand_drives(tau, &mut out);
    out
}

/// `[x[..head]; expand(x[head..])]`: a free-floating base's entries (`head` of them) kept, the
/// joints' expanded to the full tree (`K` entries in all).
#[inline(always)]
fn with_base<S: Scalar + Copy, const K: usize>(
    x: &[S],
    head: usize,
    expand: impl FnOnce(&[S], &mut [S]),
) -> [S; K] {
    let mut out = [S::zero(); K];
    for (o, v) in out.iter_mut().zip(x.iter().take(head)) {
        *o = *v;
    }
    if let (Some(joints), Some(rest)) = (x.get(head..), out.get_mut(head..)) {
        expand(joints, rest);
    }
    out
}

/// A free-floating base's full positions `[p₀; quat; q_full]` (`NQ = N + 7`) of `[p₀; quat; q]`.
#[inline(always)]
fn floating_positions<S: Scalar + Copy, const NQ: usize>(c: &Coupling<'_>, q: &[S]) -> [S; NQ] {
    with_base(q, 7, |joints, out| c.expand_positions(joints, out))
}

/// A free-floating base's full speeds or accelerations `[base (6); G x]` (`NV`).
#[inline(always)]
fn floating_rates<S: Scalar + Copy, const NV: usize>(c: &Coupling<'_>, v: &[S]) -> [S; NV] {
    with_base(v, 6, |joints, out| c.expand_rates(joints, out))
}

/// `Gᵀ v` (`offset` base entries kept) of a full vector.
#[inline(always)]
fn vector<S: Scalar + Copy, const R: usize>(c: &Coupling<'_>, v: &[S], offset: usize) -> [S; R] {
    let mut out = [S::zero(); R];
    c.reduce_vector(v, offset, &mut out);
    out
}

/// `Gᵀ M G` (`offset` base rows and columns kept) of a full `NF × NF` matrix.
#[inline(always)]
fn matrix<S: Scalar + Copy, const NF: usize, const R: usize>(
    c: &Coupling<'_>,
    m: &[[S; NF]; NF],
    offset: usize,
) -> [[S; R]; R] {
    let mut scratch = [[S::zero(); R]; NF];
    let mut out = [[S::zero(); R]; R];
    c.reduce_matrix(
        m.as_flattened(),
        offset,
        scratch.as_flattened_mut(),
        out.as_flattened_mut(),
    );
    out
}

/// `J G` (`offset` base columns kept) of a full `6 × NF` Jacobian.
#[inline(always)]
fn columns<S: Scalar + Copy, const NF: usize, const R: usize>(
    c: &Coupling<'_>,
    j: &[[S; NF]; 6],
    offset: usize,
) -> [[S; R]; 6] {
    let mut out = [[S::zero(); R]; 6];
    c.reduce_rows(j.as_flattened(), offset, out.as_flattened_mut());
    out
}

/// `M⁻¹ b` of the reduced `M` and right-hand side by LDLᵀ (`m` overwritten).
#[inline(always)]
fn solve<S: Scalar + Copy, const R: usize>(mut m: [[S; R]; R], b: [S; R]) -> [S; R] {
    let mut d_inv = [S::zero(); R];
    let mut x = b;
    let l = m.as_flattened_mut();
    if factor_in_place(l, R, &mut d_inv).is_ok() {
        let _ = solve_in_place(l, R, &d_inv, &mut x);
    }
    x
}

/// `M⁻¹` of the reduced `M` ([`d::inverse_in`]).
#[inline(always)]
fn inverse<S: Scalar + Copy, const R: usize>(mut m: [[S; R]; R]) -> [[S; R]; R] {
    let (mut d_inv, mut out) = ([S::zero(); R], [[S::zero(); R]; R]);
    d::inverse_in(m.as_flattened_mut(), R, &mut d_inv, out.as_flattened_mut());
    out
}

/// `out = A x` of a square matrix `A` (rows first, one row per entry of `out`).
#[inline(always)]
pub fn product<S: Scalar + Copy>(a: &[S], x: &[S], out: &mut [S]) {
    let n = out.len();
    for (o, row) in out.iter_mut().zip(a.chunks(n.max(1))) {
        let mut acc = S::zero();
        for (a, x) in row.iter().zip(x) {
            acc = acc + *a * *x;
        }
        *o = acc;
    }
}

/// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` in the coordinates: `M⁻¹` of the reduced `m`, `q̈ = M⁻¹ b`, the full
/// inverse-dynamics derivatives `id(q̈)` (of the full accelerations at `q̈`) reduced, then
/// `−M⁻¹ ∂τ/∂x`.
#[inline(always)]
fn forward_derivatives<S: Scalar + Copy, const R: usize>(
    m: [[S; R]; R],
    b: &[S; R],
    id: impl FnOnce(&[S; R]) -> ([[S; R]; R], [[S; R]; R]),
) -> ForwardDerivatives<S, R> {
    let minv = inverse(m);
    let mut qdd = [S::zero(); R];
    product(minv.as_flattened(), b, &mut qdd);
    let (dq, dv) = id(&qdd);
    let mut out = ([[S::zero(); R]; R], [[S::zero(); R]; R], minv);
    let minv = out.2.as_flattened();
    d::neg_product(minv, dq.as_flattened(), R, out.0.as_flattened_mut());
    d::neg_product(minv, dv.as_flattened(), R, out.1.as_flattened_mut());
    out
}

/// The full `M` and `τ_full − c_full + Jᵀ f_ext` (fixed base) at the full state.
#[inline(always)]
fn full_system<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    tau: &[S; N],
    f_ext: Option<&[[S; 6]]>,
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; N]; N], [S; N]) {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let (mut st, mut h) = ([[zero; N]; 6], [[zero; N]; N]);
    let (mut m, mut c) = ([[[zero; 6]; 3]; N], [zero; N]);
    transforms(t, q, sincos, b.x);
    let motions = Motions {
        qd: Some(qd),
        qdd: None,
        f_ext,
    };
    rnea(t, b.x, inertia, motions, &mut m, &mut c);
    crba(
        t,
        inertia,
        &mut b,
        st.as_flattened_mut(),
        h.as_flattened_mut(),
    );
    (h, core::array::from_fn(|i| tau[i] - c[i]))
}

/// `M = Gᵀ M_full G`, `R × R`.
#[inline]
pub fn mass_matrix<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; R]; R] {
    let m = super::mass_matrix::<S, N>(t, inertia, &positions(c, q), sincos);
    matrix(c, &m, 0)
}

/// `c = Gᵀ c_full(q_full, G q̇)`.
#[inline]
pub fn nonlinear_effects<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> [S; R] {
    let (q, qd) = (positions::<S, N>(c, q), rates::<S, N>(c, qd));
    vector(c, &super::nonlinear_effects(t, inertia, &q, &qd, sincos), 0)
}

/// `g = Gᵀ g_full(q_full)`.
#[inline]
pub fn gravity<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> [S; R] {
    let q = positions::<S, N>(c, q);
    vector(c, &super::gravity(t, inertia, &q, sincos), 0)
}

/// `τ = Gᵀ τ_full(q_full, G q̇, G q̈) = M q̈ + c`.
#[inline]
pub fn inverse_dynamics<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    qdd: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> [S; R] {
    let (q, qd) = (positions::<S, N>(c, q), rates::<S, N>(c, qd));
    let qdd = rates::<S, N>(c, qdd);
    vector(
        c,
        &super::inverse_dynamics(t, inertia, &q, &qd, &qdd, sincos),
        0,
    )
}

/// `(M, c)` on one set of joint transforms.
#[inline]
pub fn mass_matrix_and_nonlinear_effects<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; R]; R], [S; R]) {
    let (q, qd) = (positions::<S, N>(c, q), rates::<S, N>(c, qd));
    let (m, nle) = super::mass_matrix_and_nonlinear_effects(t, inertia, &q, &qd, sincos);
    (matrix(c, &m, 0), vector(c, &nle, 0))
}

/// `q̈ = M⁻¹ Gᵀ (τ_full − c_full)` ([module docs](self)).
#[inline]
pub fn forward_dynamics<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    tau: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> [S; R] {
    forward::<S, N, R>(t, c, inertia, q, qd, tau, None, sincos)
}

/// [`forward_dynamics`] with `f_ext[i] = [force; moment]` on body `i` of the full tree, in its
/// frame at its origin.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics_with_wrenches<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    tau: &[S; R],
    f_ext: &[[S; 6]; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; R] {
    forward::<S, N, R>(t, c, inertia, q, qd, tau, Some(f_ext), sincos)
}

/// Forward dynamics on a fixed base, with or without wrenches.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn forward<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    tau: &[S; R],
    f_ext: Option<&[[S; 6]]>,
    sincos: impl Fn(S) -> (S, S),
) -> [S; R] {
    let (q, qd) = (positions::<S, N>(c, q), rates::<S, N>(c, qd));
    let tau = drives::<S, N>(c, tau);
    let (m, b) = full_system(t, inertia, &q, &qd, &tau, f_ext, sincos);
    solve(matrix(c, &m, 0), vector(c, &b, 0))
}

/// A named frame's placement at `q_full`.
#[inline]
pub fn frame_placement<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    frame: &Frame<S>,
    q: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> ([S; 3], [[S; 3]; 3]) {
    super::frame_placement(t, frame, &positions::<S, N>(c, q), sincos)
}

/// A named frame's Jacobian `J_full G`, `6 × R`.
#[inline]
pub fn frame_jacobian<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    frame: &Frame<S>,
    q: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; R]; 6] {
    let j = super::frame_jacobian(t, frame, &positions::<S, N>(c, q), sincos);
    columns(c, &j, 0)
}

/// `(∂τ/∂q, ∂τ/∂q̇) = Gᵀ (∂τ_full/∂x_full) G`, `R × R` each.
#[inline]
pub fn inverse_dynamics_derivatives<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    qdd: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; R]; R], [[S; R]; R]) {
    let (q, qd) = (positions::<S, N>(c, q), rates::<S, N>(c, qd));
    let qdd = rates::<S, N>(c, qdd);
    let (dq, dv) = d::inverse_dynamics_derivatives(t, inertia, &q, &qd, &qdd, sincos);
    (matrix(c, &dq, 0), matrix(c, &dv, 0))
}

/// `M⁻¹` of the reduced `M`, `R × R`.
#[inline]
pub fn mass_matrix_inverse<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; R]; R] {
    inverse(mass_matrix::<S, N, R>(t, c, inertia, q, sincos))
}

/// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` in the coordinates ([module docs](self)).
#[inline]
pub fn forward_dynamics_derivatives<S: Scalar + Copy, const N: usize, const R: usize>(
    t: &Tables<'_, S>,
    c: &Coupling<'_>,
    inertia: &[[S; 10]],
    q: &[S; R],
    qd: &[S; R],
    tau: &[S; R],
    sincos: impl Fn(S) -> (S, S),
) -> ForwardDerivatives<S, R> {
    let (qf, qdf) = (positions::<S, N>(c, q), rates::<S, N>(c, qd));
    let tau = drives::<S, N>(c, tau);
    let (m, b) = full_system(t, inertia, &qf, &qdf, &tau, None, &sincos);
    forward_derivatives(matrix(c, &m, 0), &vector(c, &b, 0), |qdd| {
        let qddf = rates::<S, N>(c, qdd);
        let (dq, dv) = d::inverse_dynamics_derivatives(t, inertia, &qf, &qdf, &qddf, &sincos);
        (matrix(c, &dq, 0), matrix(c, &dv, 0))
    })
}

/// The free-floating base's kernels ([`super::floating`], [`super::floating_frames`], the
/// derivatives) in the coordinates: `q = [p₀; quat; q (R)]`, `ν = [v_b; ω_b; q̇ (R)]`.
pub mod floating {
    use super::*;

    /// The full `M` and `[0; τ_full] − c_full + Jᵀ f_ext` (`f_ext[0]` on the base).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn full_system<S: Scalar + Copy, const N: usize, const NV: usize>(
        t: &Tables<'_, S>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: &[S],
        tau: &[S; N],
        f_ext: Option<&[[S; 6]]>,
        sincos: impl Fn(S) -> (S, S),
    ) -> ([[S; NV]; NV], [S; NV]) {
        let zero = S::zero();
        let mut store = BodyStore::<S, N>::new();
        let mut b = store.bodies();
        let (mut st, mut h, mut m) = ([[zero; N]; 6], [[zero; N]; N], [[zero; NV]; NV]);
        let (mut mm, mut c) = ([[[zero; 6]; 3]; N], [zero; NV]);
        transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
        fl::inverse_dynamics_in(
            t,
            b.x,
            inertia,
            base,
            q,
            Some(v),
            None,
            f_ext,
            &mut mm,
            &mut c,
        );
        let (stf, hf) = (st.as_flattened_mut(), h.as_flattened_mut());
        fl::mass_matrix_in(t, inertia, base, &mut b, stf, hf, m.as_flattened_mut());
        let rhs = core::array::from_fn(|i| match i.checked_sub(6).and_then(|j| tau.get(j)) {
            Some(&x) => x - c[i],
            None => -c[i],
        });
        (m, rhs)
    }

    /// `M = Gᵀ M_full G`, `RV × RV`.
    #[inline]
    pub fn mass_matrix<S, const N: usize, const NV: usize, const NQ: usize, const RV: usize>(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> [[S; RV]; RV]
    where
        S: Scalar + Copy,
    {
        let q = floating_positions::<S, NQ>(c, q);
        matrix(
            c,
            &fl::mass_matrix::<S, N, NV>(t, inertia, base, &q, sincos),
            6,
        )
    }

    /// Inverse dynamics `Gᵀ [f_b; n_b; τ_full]` (`a = None`: `ν̇ = 0`; `v = None`: `ν = 0`).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn inverse_dynamics<S, const N: usize, const NV: usize, const NQ: usize, const RV: usize>(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: Option<&[S]>,
        a: Option<&[S]>,
        sincos: impl Fn(S) -> (S, S),
    ) -> [S; RV]
    where
        S: Scalar + Copy,
    {
        let q = floating_positions::<S, NQ>(c, q);
        let v = v.map(|v| floating_rates::<S, NV>(c, v));
        let a = a.map(|a| floating_rates::<S, NV>(c, a));
        let (v, a) = (v.as_ref().map(|v| &v[..]), a.as_ref().map(|a| &a[..]));
        let tau = fl::inverse_dynamics::<S, N, NV>(t, inertia, base, &q, v, a, sincos);
        vector(c, &tau, 6)
    }

    /// `(M, c)` on one set of joint transforms.
    #[inline]
    pub fn mass_matrix_and_nonlinear_effects<
        S,
        const N: usize,
        const NV: usize,
        const NQ: usize,
        const RV: usize,
    >(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> ([[S; RV]; RV], [S; RV])
    where
        S: Scalar + Copy,
    {
        let (q, v) = (
            floating_positions::<S, NQ>(c, q),
            floating_rates::<S, NV>(c, v),
        );
        let (m, nle) =
            fl::mass_matrix_and_nonlinear_effects::<S, N, NV>(t, inertia, base, &q, &v, sincos);
        (matrix(c, &m, 6), vector(c, &nle, 6))
    }

    /// Forward dynamics `ν̇ = M⁻¹ Gᵀ ([0; τ_full] − c_full + Jᵀ f_ext)` (`RV` entries) with
    /// `f_ext[0]` on the base and `f_ext[1 + i]` on body `i` of the full tree.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn forward_dynamics<
        S,
        const N: usize,
        const NV: usize,
        const NQ: usize,
        const R: usize,
        const RV: usize,
    >(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: &[S],
        tau: &[S; R],
        f_ext: Option<&[[S; 6]]>,
        sincos: impl Fn(S) -> (S, S),
    ) -> [S; RV]
    where
        S: Scalar + Copy,
    {
        let (q, v) = (
            floating_positions::<S, NQ>(c, q),
            floating_rates::<S, NV>(c, v),
        );
        let tau = drives::<S, N>(c, tau);
        let (m, b) = full_system::<S, N, NV>(t, inertia, base, &q, &v, &tau, f_ext, sincos);
        solve(matrix(c, &m, 6), vector(c, &b, 6))
    }

    /// The momentum of the base and the arm at `(q_full, ν_full)` ([`fl::momentum`]).
    #[inline]
    pub fn momentum<S, const N: usize, const NV: usize, const NQ: usize>(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> [S; 6]
    where
        S: Scalar + Copy,
    {
        let (q, v) = (
            floating_positions::<S, NQ>(c, q),
            floating_rates::<S, NV>(c, v),
        );
        fl::momentum::<S, N>(t, inertia, base, &q, &v, sincos)
    }

    /// The wrench the arm exerts on the base at `(q_full, ν_full, ν̇_full)`.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn base_reaction<S, const N: usize, const NV: usize, const NQ: usize>(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: &[S],
        a: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> [S; 6]
    where
        S: Scalar + Copy,
    {
        let q = floating_positions::<S, NQ>(c, q);
        let (v, a) = (floating_rates::<S, NV>(c, v), floating_rates::<S, NV>(c, a));
        fl::base_reaction::<S, N>(t, inertia, base, &q, &v, &a, sincos)
    }

    /// A named frame's placement in the inertial frame at `q_full`.
    #[inline]
    pub fn frame_placement<S, const N: usize, const NQ: usize>(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        frame: &Frame<S>,
        q: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> ([S; 3], [[S; 3]; 3])
    where
        S: Scalar + Copy,
    {
        let q = floating_positions::<S, NQ>(c, q);
        super::super::floating_frames::frame_placement::<S, N>(t, frame, &q, sincos)
    }

    /// A named frame's Jacobian `J_full G`, `6 × RV` (the base's six columns kept).
    #[inline]
    pub fn frame_jacobian<S, const N: usize, const NV: usize, const NQ: usize, const RV: usize>(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        frame: &Frame<S>,
        q: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> [[S; RV]; 6]
    where
        S: Scalar + Copy,
    {
        let q = floating_positions::<S, NQ>(c, q);
        let j = super::super::floating_frames::frame_jacobian::<S, N, NV>(t, frame, &q, sincos);
        columns(c, &j, 6)
    }

    /// A named frame's generalized Jacobian `J* G`, `6 × R`.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn generalized_jacobian<S, const N: usize, const NQ: usize, const R: usize>(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        frame: &Frame<S>,
        q: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> [[S; R]; 6]
    where
        S: Scalar + Copy,
    {
        let q = floating_positions::<S, NQ>(c, q);
        let j = super::super::floating_frames::generalized_jacobian::<S, N>(
            t, inertia, base, frame, &q, sincos,
        );
        columns(c, &j, 0)
    }

    /// `(∂τ/∂q, ∂τ/∂ν) = Gᵀ D G`, `RV × RV` each (the base's columns in the tangent space).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn inverse_dynamics_derivatives<
        S,
        const N: usize,
        const NV: usize,
        const NQ: usize,
        const RV: usize,
    >(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: &[S],
        a: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> ([[S; RV]; RV], [[S; RV]; RV])
    where
        S: Scalar + Copy,
    {
        let q = floating_positions::<S, NQ>(c, q);
        let (v, a) = (floating_rates::<S, NV>(c, v), floating_rates::<S, NV>(c, a));
        let (dq, dv) = d::floating_inverse_dynamics_derivatives::<S, N, NV>(
            t, inertia, base, &q, &v, &a, sincos,
        );
        (matrix(c, &dq, 6), matrix(c, &dv, 6))
    }

    /// `M⁻¹` of the reduced `M`, `RV × RV`.
    #[inline]
    pub fn mass_matrix_inverse<
        S,
        const N: usize,
        const NV: usize,
        const NQ: usize,
        const RV: usize,
    >(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        sincos: impl Fn(S) -> (S, S),
    ) -> [[S; RV]; RV]
    where
        S: Scalar + Copy,
    {
        inverse(mass_matrix::<S, N, NV, NQ, RV>(
            t, c, inertia, base, q, sincos,
        ))
    }

    /// `(∂ν̇/∂q, ∂ν̇/∂ν, M⁻¹)` in the coordinates, `RV × RV` each.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn forward_dynamics_derivatives<
        S,
        const N: usize,
        const NV: usize,
        const NQ: usize,
        const R: usize,
        const RV: usize,
    >(
        t: &Tables<'_, S>,
        c: &Coupling<'_>,
        inertia: &[[S; 10]],
        base: &Base<S>,
        q: &[S],
        v: &[S],
        tau: &[S; R],
        sincos: impl Fn(S) -> (S, S),
    ) -> ForwardDerivatives<S, RV>
    where
        S: Scalar + Copy,
    {
        let (qf, vf) = (
            floating_positions::<S, NQ>(c, q),
            floating_rates::<S, NV>(c, v),
        );
        let tau = drives::<S, N>(c, tau);
        let (m, b) = full_system::<S, N, NV>(t, inertia, base, &qf, &vf, &tau, None, &sincos);
        forward_derivatives(matrix(c, &m, 6), &vector(c, &b, 6), |a| {
            let af = floating_rates::<S, NV>(c, a);
            let (dq, dv) = d::floating_inverse_dynamics_derivatives::<S, N, NV>(
                t, inertia, base, &qf, &vf, &af, &sincos,
            );
            (matrix(c, &dq, 6), matrix(c, &dv, 6))
        })
    }
}
