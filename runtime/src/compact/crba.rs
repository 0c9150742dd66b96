//! The joint-space inertia matrix by the composite-rigid-body algorithm (RBDA Table 6.2), and
//! the mass matrix with the nonlinear effects on one set of joint transforms.

use super::rnea::{rnea, Motions};
use super::spatial::{inertia_mul, transforms, world};
use super::tables::{Bodies, BodyStore, Tables};
use crate::scalar::Scalar;

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
    let mut h = [[zero; N]; N];
    transforms(t, q, sincos, b.x);
    crba(
        t,
        inertia,
        &mut b,
        st.as_flattened_mut(),
        h.as_flattened_mut(),
    );
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
    let mut h = [[zero; N]; N];
    let mut m = [[[zero; 6]; 3]; N];
    let mut c = [zero; N];
    transforms(t, q, sincos, b.x);
    crba(
        t,
        inertia,
        &mut b,
        st.as_flattened_mut(),
        h.as_flattened_mut(),
    );
    rnea(t, b.x, inertia, Motions::velocity(qd), &mut m, &mut c);
    (h, c)
}

/// The composite-rigid-body algorithm (RBDA Table 6.2) in base coordinates (as Pinocchio's), on
/// the joint transforms `b.x`: the bodies carried to the base ([`world`]), composite inertias
/// `IC_λ(i) += IC_i` leaves first (one frame, no transform), then `F = IC_i S_i` and
/// `H_ij = H_ji = S_jᵀ F` for `j = i` and each ancestor `j` of `i` ([`fill`]) into `h` (`N × N`,
/// rows first). `st`: scratch of `6 N`.
#[inline(always)]
pub fn crba<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    b: &mut Bodies<'_, S>,
    st: &mut [S],
    h: &mut [S],
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
    fill(t, b.s0, b.i0, st, h);
}

/// RBDA Table 6.2's `F = I^c_i S_i`, `H_ij = H_ji = S_jᵀ F` (base coordinates). Row `i`'s
/// entries are taken for every `j ≤ i` at once, a loop over `j` with the six coordinates of the
/// `S_j` side by side (`st[k N + j]`) that the compiler vectorizes; on a tree, the entries of
/// joints that are not ancestors of `i` (zero, RBDA §6.2) are then set to zero
/// ([`Tables::ancestor`]); the upper triangle is the lower one mirrored.
#[inline(always)]
fn fill<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    s0: &[[S; 6]],
    ic: &[[S; 10]],
    st: &mut [S],
    h: &mut [S],
) {
    let n = s0.len();
    if n == 0 {
        return;
    }
    for (k, row) in st.chunks_exact_mut(n).enumerate() {
        for (x, s) in row.iter_mut().zip(s0) {
            *x = s.get(k).copied().unwrap_or_else(S::zero);
        }
    }
    let mut st = st.chunks_exact(n);
    let (Some(s0r), Some(s1r), Some(s2r), Some(s3r), Some(s4r), Some(s5r)) = (
        st.next(),
        st.next(),
        st.next(),
        st.next(),
        st.next(),
        st.next(),
    ) else {
        return;
    };
    for (i, (hrow, (ici, si))) in h.chunks_exact_mut(n).zip(ic.iter().zip(s0)).enumerate() {
        let f = inertia_mul(ici, si);
        let k = i + 1;
        let (Some(row), Some(a0), Some(a1), Some(a2), Some(a3), Some(a4), Some(a5)) = (
            hrow.get_mut(..k),
            s0r.get(..k),
            s1r.get(..k),
            s2r.get(..k),
            s3r.get(..k),
            s4r.get(..k),
            s5r.get(..k),
        ) else {
            continue;
        };
        let cols = a0.iter().zip(a1).zip(a2).zip(a3).zip(a4).zip(a5);
        for (hij, (((((a0, a1), a2), a3), a4), a5)) in row.iter_mut().zip(cols) {
            *hij = *a0 * f[0] + *a1 * f[1] + *a2 * f[2] + *a3 * f[3] + *a4 * f[4] + *a5 * f[5];
        }
        if let Some(keep) = t.ancestor.and_then(|a| a.get(i * n..(i + 1) * n)) {
            for (hij, keep) in hrow.iter_mut().zip(keep) {
                if !keep {
                    *hij = S::zero();
                }
            }
        }
    }
    // The upper triangle: `h[j][i]` for `j < i` reads across rows.
    for i in 1..n {
        for j in 0..i {
            if let Some(&hij) = h.get(i * n + j) {
                if let Some(hji) = h.get_mut(j * n + i) {
                    *hji = hij;
                }
            }
        }
    }
}
