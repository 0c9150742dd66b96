//! A named frame's placement, geometric Jacobian and generalized Jacobian on a free-floating
//! base, as loops ([`super::frames`] in base coordinates, then the base's pose; the layouts of
//! [`super::floating`]).
//!
//! With `R₀`, `p₀` the base's pose ([`base_rotation`], `q[0..3]`) and `(x_f, R_f)` the frame's
//! placement in base coordinates ([`frames::pose`]): the placement is `(p₀ + R₀ x_f, R₀ R_f)`.
//! The Jacobian has rows `[v; ω]` in inertial axes and `6 + N` columns for
//! `ν = [v_b; ω_b; q̇]`: `v_b,m` gives `[R₀ e_m; 0]`, `ω_b,m` gives `[R₀ (e_m × x_f); R₀ e_m]`,
//! and a joint's column is `R₀` times its fixed-base column ([`frames::jacobian_columns`]).
//! The generalized Jacobian (Umetani & Yoshida 1989) is `J* = J_m − J_b A_bb⁻¹ A_bm` (`6 × N`):
//! `A_bb = I^c_0`, the composite inertia of the whole system, and column `j` of `A_bm` is
//! `F_j = I^c_j S_j` (RBDA §9.2, as [`super::floating::mass_matrix_in`]), so column `j` of `J*`
//! is `R₀ (J_j − [v + ω × x_f; ω])` with `[ω; v] = (I^c_0)⁻¹ F_j`, the base twist that
//! cancels joint `j`'s momentum.

use super::aba::{packed_inertia, SpatialFactor};
use super::crba::composite_inertias;
use super::floating::{base_position, base_rotation, Base};
use super::frames::{self, Frame};
use super::spatial::{cross, inertia_mul, rot, transforms, Transform};
use super::tables::{Bodies, BodyStore, Tables};
use crate::scalar::Scalar;

/// The frame's placement `(x, R)` in the inertial frame at `q = [p₀; quat; q_joints]`.
#[inline]
pub fn frame_placement<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    frame: &Frame<S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> ([S; 3], [[S; 3]; 3]) {
    let x0 = frames::placements::<S, N>(t, frame, q.get(7..).unwrap_or(&[]), sincos);
    placement_in(frame, q, &x0)
}

/// The placement from the support path's placements `x0` ([`frames::support_placements`]).
#[inline(always)]
pub fn placement_in<S: Scalar + Copy>(
    frame: &Frame<S>,
    q: &[S],
    x0: &[Transform<S>],
) -> ([S; 3], [[S; 3]; 3]) {
    let (x, r) = frames::pose(frame, x0);
    let r0 = base_rotation(q);
    let (p0, d) = (base_position(q), rot(&r0, &x));
    let cols: [[S; 3]; 3] = core::array::from_fn(|c| rot(&r0, &[r[0][c], r[1][c], r[2][c]]));
    (
        [p0[0] + d[0], p0[1] + d[1], p0[2] + d[2]],
        core::array::from_fn(|i| core::array::from_fn(|c| cols[c][i])),
    )
}

/// The frame's geometric Jacobian at `q`: rows `[v; ω]` in inertial axes, `NV = 6 + N` columns.
#[inline]
pub fn frame_jacobian<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    frame: &Frame<S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; NV]; 6] {
    let x0 = frames::placements::<S, N>(t, frame, q.get(7..).unwrap_or(&[]), sincos);
    let mut cols = [[S::zero(); 6]; N];
    let mut out = [[S::zero(); NV]; 6];
    jacobian_in(t, frame, q, &x0, &mut cols, out.as_flattened_mut());
    out
}

/// The Jacobian into `out` (`6 × (6 + N)`, rows first) from the support path's placements
/// `x0`; `cols`: scratch of `N` columns.
#[inline(always)]
pub fn jacobian_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    frame: &Frame<S>,
    q: &[S],
    x0: &[Transform<S>],
    cols: &mut [[S; 6]],
    out: &mut [S],
) {
    let (zero, one) = (S::zero(), S::one());
    let xf = frames::origin(frame, x0);
    frames::jacobian_columns(t, frame, x0, &xf, cols);
    let r0 = base_rotation(q);
    let nv = 6 + cols.len();
    let mut put = |c: usize, col: &[S; 6]| {
        let (v, w) = (
            rot(&r0, &[col[0], col[1], col[2]]),
            rot(&r0, &[col[3], col[4], col[5]]),
        );
        for (r, x) in v.into_iter().chain(w).enumerate() {
            if let Some(o) = out.get_mut(r * nv + c) {
                *o = x;
            }
        }
    };
    for m in 0..3 {
        let e: [S; 3] = core::array::from_fn(|k| if k == m { one } else { zero });
        let ex = cross(&e, &xf);
        put(m, &[e[0], e[1], e[2], zero, zero, zero]);
        put(3 + m, &[ex[0], ex[1], ex[2], e[0], e[1], e[2]]);
    }
    for (j, col) in cols.iter().enumerate() {
        put(6 + j, col);
    }
}

/// The frame's generalized Jacobian `J*` at `q` (`6 × N`, rows `[v; ω]`, inertial axes):
/// [`generalized_jacobian_in`] on the joint transforms of `q`, on stack storage of `N` joints.
#[inline]
pub fn generalized_jacobian<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    frame: &Frame<S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; N]; 6] {
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut cols = [[S::zero(); 6]; N];
    let mut out = [[S::zero(); N]; 6];
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    generalized_jacobian_in(
        t,
        inertia,
        base,
        frame,
        q,
        &mut b,
        &mut cols,
        out.as_flattened_mut(),
    );
    out
}

/// `J*` into `out` (`6 × N`, rows first) on the joint transforms `b.x`: the composite inertias
/// ([`composite_inertias`]), the frame's joint columns in base coordinates (into `cols`), then
/// each column less the base twist that cancels its momentum ([module docs](self)).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn generalized_jacobian_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    frame: &Frame<S>,
    q: &[S],
    b: &mut Bodies<'_, S>,
    cols: &mut [[S; 6]],
    out: &mut [S],
) {
    composite_inertias(t, inertia, b);
    let mut ic0 = base.inertia;
    for (i, ici) in b.i0.iter().enumerate() {
        if t.parent.get(i).copied().flatten().is_none() {
            for (a, c) in ic0.iter_mut().zip(ici) {
                *a = *a + *c;
            }
        }
    }
    let factor = SpatialFactor::new(&packed_inertia(&ic0));
    let xf = frames::origin(frame, b.x0);
    frames::jacobian_columns(t, frame, b.x0, &xf, cols);
    let r0 = base_rotation(q);
    let n = cols.len();
    for (j, col) in cols.iter().enumerate() {
        let (Some(ic), Some(s)) = (b.i0.get(j), b.s0.get(j)) else {
            continue;
        };
        let mut tw = inertia_mul(ic, s);
        factor.solve(&mut tw);
        let w = [tw[0], tw[1], tw[2]];
        let wx = cross(&w, &xf);
        let v = rot(
            &r0,
            &[
                col[0] - tw[3] - wx[0],
                col[1] - tw[4] - wx[1],
                col[2] - tw[5] - wx[2],
            ],
        );
        let w = rot(&r0, &[col[3] - w[0], col[4] - w[1], col[5] - w[2]]);
        for (r, x) in v.into_iter().chain(w).enumerate() {
            if let Some(o) = out.get_mut(r * n + j) {
                *o = x;
            }
        }
    }
}
