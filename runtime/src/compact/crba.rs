//! The joint-space inertia matrix by the composite-rigid-body algorithm (RBDA Table 6.2), and
//! the mass matrix with the nonlinear effects on one set of joint transforms.

use super::rnea::{rnea, Motions};
use super::spatial::{dot, inertia_mul, transforms, world};
use super::tables::{Bodies, BodyStore, Tables};
use crate::scalar::Scalar;

/// [`crba`]'s `H` for `N` joints known at compile time, into the place `$h` (`[[S; N]; N]`,
/// zero): [`crba`]'s rows (as [`row`]: `F = I^c_i S_i`, `H_ij = S_jᵀ F` for `j ≤ i`, the
/// entries of non-ancestors zero) and their mirror image, from `$ic`, `$s0` and `$st`
/// ([`composite`]'s, `$st: [[S; N]; 6]`). `$h` is written by index only (never borrowed), so
/// that the compiler builds it in place of the caller's result, or of the field of it that
/// `$h` is, rather than copying it there.
macro_rules! symmetric_into {
    ($h:expr, $t:expr, $ic:expr, $s0:expr, $st:expr) => {{
        let st = $st;
        for i in 0..N {
            let (Some(ici), Some(si)) = ($ic.get(i), $s0.get(i)) else {
                continue;
            };
            let f = inertia_mul(ici, si);
            for j in 0..i + 1 {
                let s = [st[0][j], st[1][j], st[2][j], st[3][j], st[4][j], st[5][j]];
                $h[i][j] = dot(&s, &f);
            }
            if let Some(keep) = $t.ancestor.and_then(|a| a.get(i * N..i * N + i + 1)) {
                for (j, keep) in keep.iter().enumerate() {
                    if !keep {
                        $h[i][j] = S::zero();
                    }
                }
            }
        }
        for j in 0..N {
            for i in j + 1..N {
                $h[j][i] = $h[i][j];
            }
        }
    }};
}

/// The joint-space inertia matrix `H(q)` (RBDA Table 6.2): [`crba`] on the joint transforms of
/// `q` ([`transforms`]); `inertia` is [`Tables::inertia`] or [`with_payload`](super::with_payload)'s.
#[inline]
pub fn mass_matrix<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; N]; N] {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut st = [[zero; N]; 6];
    transforms(t, q, sincos, b.x);
    let mut h = [[zero; N]; N];
    composite(t, inertia, &mut b, st.as_flattened_mut());
    symmetric_into!(h, t, b.i0, b.s0, &st);
    h
}

/// `(H(q), c(q, q̇))` on one set of joint transforms: [`crba`] and the recursive Newton–Euler
/// algorithm at `q̈ = 0` ([`rnea`], RBDA Table 5.1).
#[inline]
pub fn mass_matrix_and_nonlinear_effects<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; N]; N], [S; N]) {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut st = [[zero; N]; 6];
    let mut m = [[[zero; 6]; 3]; N];
    let mut c = [zero; N];
    let mut out = ([[zero; N]; N], [zero; N]);
    transforms(t, q, sincos, b.x);
    rnea(t, b.x, inertia, Motions::velocity(qd), &mut m, &mut c);
    composite(t, inertia, &mut b, st.as_flattened_mut());
    symmetric_into!(out.0, t, b.i0, b.s0, &st);
    out.1 = c;
    out
}

/// The composite-rigid-body algorithm (RBDA Table 6.2) in base coordinates (as Pinocchio's), on
/// the joint transforms `b.x`: the bodies carried to the base and their composite inertias
/// ([`composite`]), then `F = IC_i S_i` and `H_ij = H_ji = S_jᵀ F` for `j = i` and each
/// ancestor `j` of `i` ([`row`]) into `h` (`N × N`, rows first), the upper triangle the lower
/// one mirrored. `st`: scratch of `6 N`.
#[inline(always)]
pub fn crba<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    b: &mut Bodies<'_, S>,
    st: &mut [S],
    h: &mut [S],
) {
    composite(t, inertia, b, st);
    let n = b.s0.len();
    if n == 0 {
        return;
    }
    let bodies = b.i0.iter().zip(b.s0.iter());
    for (i, (hrow, (ici, si))) in h.chunks_exact_mut(n).zip(bodies).enumerate() {
        row(t, st, i, ici, si, hrow);
    }
    for j in 0..n {
        for i in j + 1..n {
            if let Some(&hij) = h.get(i * n + j) {
                if let Some(hji) = h.get_mut(j * n + i) {
                    *hji = hij;
                }
            }
        }
    }
}

/// [`composite_inertias`], and the `S_j` side by side for [`row`]: `st[k N + j] = S_j[k]`.
#[inline(always)]
fn composite<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    b: &mut Bodies<'_, S>,
    st: &mut [S],
) {
    composite_inertias(t, inertia, b);
    let n = b.s0.len();
    if n == 0 {
        return;
    }
    for (k, row) in st.chunks_exact_mut(n).enumerate() {
        for (x, s) in row.iter_mut().zip(b.s0.iter()) {
            *x = s.get(k).copied().unwrap_or_else(S::zero);
        }
    }
}

/// The bodies carried to the base ([`world`]), then RBDA Table 6.2's composite inertias
/// `I^c_λ(i) += I^c_i` leaves first (one frame, no transform) in `b.i0`.
#[inline(always)]
pub fn composite_inertias<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    b: &mut Bodies<'_, S>,
) {
    world(t, inertia, b);
    let ic = &mut *b.i0;
    // RBDA Table 6.2, `I^c_λ(i) = I^c_λ(i) + ^λ(i)X_i* I^c_i ^iX_λ(i)` (one frame: a sum).
    for i in (0..ic.len()).rev() {
        if let Some(l) = t.parent.get(i).copied().flatten() {
            let child = ic[i];
            if let Some(icl) = ic.get_mut(l) {
                for (a, b) in icl.iter_mut().zip(child) {
                    *a = *a + b;
                }
            }
        }
    }
}

/// Row `i` of `H` up to the diagonal, into `out[..=i]`: RBDA Table 6.2's `F = I^c_i S_i`,
/// `H_ij = S_jᵀ F` (base coordinates) for every `j ≤ i` at once, a loop over `j` with the six
/// coordinates of the `S_j` side by side (`st`, [`composite`]) that the compiler vectorizes; on
/// a tree, the entries of joints that are not ancestors of `i` (zero, RBDA §6.2) are then set
/// to zero ([`Tables::ancestor`]).
#[inline(always)]
fn row<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    st: &[S],
    i: usize,
    ic: &[S; 10],
    s: &[S; 6],
    out: &mut [S],
) {
    let n = st.len() / 6;
    let f = inertia_mul(ic, s);
    let k = i + 1;
    let mut cols = st.chunks_exact(n).map(|c| c.get(..k));
    let (Some(row), Some(Some(a0)), Some(Some(a1)), Some(Some(a2))) =
        (out.get_mut(..k), cols.next(), cols.next(), cols.next())
    else {
        return;
    };
    let (Some(Some(a3)), Some(Some(a4)), Some(Some(a5))) = (cols.next(), cols.next(), cols.next())
    else {
        return;
    };
    let cols = a0.iter().zip(a1).zip(a2).zip(a3).zip(a4).zip(a5);
    for (hij, (((((a0, a1), a2), a3), a4), a5)) in row.iter_mut().zip(cols) {
        *hij = dot(&[*a0, *a1, *a2, *a3, *a4, *a5], &f);
    }
    if let Some(keep) = t.ancestor.and_then(|a| a.get(i * n..i * n + k)) {
        for (hij, keep) in row.iter_mut().zip(keep) {
            if !keep {
                *hij = S::zero();
            }
        }
    }
}
