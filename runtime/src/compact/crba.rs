//! The joint-space inertia matrix by the composite-rigid-body algorithm (RBDA Table 6.2), and
//! the mass matrix with the nonlinear effects on one set of joint transforms.

use super::rnea::rnea;
use super::spatial::{inertia_mul, transforms, world, Transform};
use super::tables::Tables;
use crate::scalar::Scalar;

/// The joint-space inertia matrix `H(q)` (RBDA Table 6.2): [`crba`] on the joint transforms of
/// `q` ([`transforms`]); `inertia` is [`Tables::inertia`] or [`with_payload`](super::with_payload)'s.
#[inline(always)]
pub fn mass_matrix<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; N]; N] {
    crba(t, &transforms(t, q, sincos), inertia)
}

/// `(H(q), c(q, q̇))` on one set of joint transforms: [`crba`] and the recursive Newton–Euler
/// algorithm at `q̈ = 0` ([`rnea`], RBDA Table 5.1).
#[inline(always)]
pub fn mass_matrix_and_nonlinear_effects<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    qd: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; N]; N], [S; N]) {
    let x = transforms(t, q, sincos);
    (crba(t, &x, inertia), rnea(t, &x, inertia, Some(qd), None))
}

/// The composite-rigid-body algorithm (RBDA Table 6.2) in base coordinates (as Pinocchio's):
/// composite inertias `IC_λ(i) += IC_i` leaves first (one frame, no transform), then
/// `F = IC_i S_i` and `H_ij = H_ji = S_jᵀ F` for `j = i` and each ancestor `j` of `i`
/// ([`fill`]).
#[inline]
pub fn crba<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    x: &[Transform<S>; N],
    inertia: &[[S; 10]; N],
) -> [[S; N]; N] {
    let w = world(t, x, inertia);
    let mut ic = w.i0;
    // RBDA Table 6.2, `I^c_λ(i) = I^c_λ(i) + ^λ(i)X_i* I^c_i ^iX_λ(i)` (one frame: a sum).
    for i in (0..N).rev() {
        if let Some(l) = t.parent[i] {
            let child = ic[i];
            if let Some(icl) = ic.get_mut(l) {
                for (a, b) in icl.iter_mut().zip(child) {
                    *a = *a + b;
                }
            }
        }
    }
    fill(t, &w.s0, &ic)
}

/// RBDA Table 6.2's `F = I^c_i S_i`, `H_ij = H_ji = S_jᵀ F` (base coordinates). Row `i`'s
/// entries are taken for every `j ≤ i` at once, a loop over `j` with the six coordinates of the
/// `S_j` side by side (`st[k][j]`) that the compiler vectorizes; on a tree, the entries of joints
/// that are not ancestors of `i` (zero, RBDA §6.2) are then set to zero
/// ([`Tables::ancestor`]); the upper triangle is the lower one mirrored.
#[inline(always)]
fn fill<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    s0: &[[S; 6]; N],
    ic: &[[S; 10]; N],
) -> [[S; N]; N] {
    let zero = S::zero();
    let mut st = [[zero; N]; 6];
    for (j, s) in s0.iter().enumerate() {
        for (k, sk) in s.iter().enumerate() {
            st[k][j] = *sk;
        }
    }
    let mut h = [[zero; N]; N];
    for i in 0..N {
        let f = inertia_mul(&ic[i], &s0[i]);
        for j in 0..i + 1 {
            h[i][j] = st[0][j] * f[0]
                + st[1][j] * f[1]
                + st[2][j] * f[2]
                + st[3][j] * f[3]
                + st[4][j] * f[4]
                + st[5][j] * f[5];
        }
        if let Some(ancestor) = &t.ancestor {
            for (hij, keep) in h[i].iter_mut().zip(ancestor[i]) {
                if !keep {
                    *hij = zero;
                }
            }
        }
    }
    // The upper triangle: `h[j][i]` for `j < i` reads across rows.
    #[allow(clippy::needless_range_loop)]
    for i in 0..N {
        for j in 0..i {
            h[j][i] = h[i][j];
        }
    }
    h
}
