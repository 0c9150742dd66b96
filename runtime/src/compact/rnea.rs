//! Inverse dynamics, nonlinear effects and gravity by the recursive Newton–Euler algorithm
//! (RBDA Table 5.1).

use super::spatial::{add, axpy, crf, crm, dot, inertia_mul, scale, transforms, Transform};
use super::tables::Tables;
use crate::scalar::Scalar;

/// `c(q, q̇)`, the nonlinear effects (Coriolis, centrifugal and gravity): [`rnea`] at `q̈ = 0`.
#[inline(always)]
pub fn nonlinear_effects<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    qd: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    rnea(t, &transforms(t, q, sincos), inertia, Some(qd), None)
}

/// `g(q)`, the gravity torques: [`rnea`] at `q̇ = 0`, `q̈ = 0`.
#[inline(always)]
pub fn gravity<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    rnea(t, &transforms(t, q, sincos), inertia, None, None)
}

/// `τ = M(q) q̈ + c(q, q̇)`: [`rnea`].
#[inline(always)]
pub fn inverse_dynamics<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    qd: &[S; N],
    qdd: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    rnea(t, &transforms(t, q, sincos), inertia, Some(qd), Some(qdd))
}

/// The recursive Newton–Euler algorithm (RBDA Table 5.1) on the joint transforms `x`: forward
/// `v_i = Xup_i v_λ(i) + S_i q̇_i`, `a_i = Xup_i a_λ(i) + S_i q̈_i + v_i ×ₘ S_i q̇_i`,
/// `f_i = I_i a_i + v_i ×* I_i v_i`, from `a₀` ([`Tables::a0`], RBDA §5.3); backward
/// `τ_i = S_iᵀ f_i`, `f_λ(i) += Xup_iᵀ f_i`. `None` for `q̇` or `q̈`: zero, and nothing
/// computed for it.
#[inline]
pub fn rnea<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    x: &[Transform<S>; N],
    inertia: &[[S; 10]; N],
    qd: Option<&[S; N]>,
    qdd: Option<&[S; N]>,
) -> [S; N] {
    let zero = S::zero();
    let mut v = [[zero; 6]; N];
    let mut a = [[zero; 6]; N];
    let mut f = [[zero; 6]; N];
    for i in 0..N {
        let (vp, ap) = match t.parent[i].and_then(|l| v.get(l).zip(a.get(l))) {
            Some((vp, ap)) => (*vp, *ap),
            None => ([zero; 6], t.a0),
        };
        // RBDA Table 5.1: a_i = Xup_i a_λ(i) + S_i q̈_i + v_i ×ₘ S_i q̇_i.
        let mut ai = x[i].apply(&ap);
        if let Some(qdd) = qdd {
            ai = axpy(&ai, qdd[i], &t.s[i]);
        }
        if let Some(qd) = qd {
            let vj = scale(qd[i], &t.s[i]);
            v[i] = add(&x[i].apply(&vp), &vj);
            ai = add(&ai, &crm(&v[i], &vj));
        }
        a[i] = ai;
        // f_i = I_i a_i + v_i ×* I_i v_i.
        f[i] = inertia_mul(&inertia[i], &a[i]);
        if qd.is_some() {
            let iv = inertia_mul(&inertia[i], &v[i]);
            f[i] = add(&f[i], &crf(&v[i], &iv));
        }
    }
    let mut tau = [zero; N];
    for i in (0..N).rev() {
        tau[i] = dot(&t.s[i], &f[i]);
        if let Some(l) = t.parent[i] {
            let carried = x[i].apply_tr(&f[i]);
            if let Some(fl) = f.get_mut(l) {
                *fl = add(fl, &carried);
            }
        }
    }
    tau
}
