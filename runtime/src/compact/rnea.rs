//! Inverse dynamics, nonlinear effects and gravity by the recursive Newton–Euler algorithm
//! (RBDA Table 5.1).

use super::spatial::{add, axpy, crf, crm, dot, inertia_mul, scale, sub, transforms, Transform};
use super::tables::{BodyStore, Tables};
use crate::scalar::Scalar;

/// The joint rates the recursive Newton–Euler algorithm runs at: `q̇` and `q̈`, each `None` for
/// zero (and nothing computed for it).
#[derive(Clone, Copy, Debug)]
pub struct Motions<'a, S> {
    /// `q̇`.
    pub qd: Option<&'a [S]>,
    /// `q̈`.
    pub qdd: Option<&'a [S]>,
    /// External wrenches, `f_ext[i] = [force; moment]` on body `i` in its frame at its origin
    /// (`None`: none): the RNEA gives `M q̈ + c − Jᵀ f_ext`.
    pub f_ext: Option<&'a [[S; 6]]>,
}

impl<'a, S> Motions<'a, S> {
    /// `q̇` alone (`q̈ = 0`).
    #[inline(always)]
    #[must_use]
    pub fn velocity(qd: &'a [S]) -> Self {
        Motions {
            qd: Some(qd),
            qdd: None,
            f_ext: None,
        }
    }
}

/// [`rnea`] on the joint transforms of `q` at `motions`, on stack storage of `N` joints.
#[inline]
fn newton_euler<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    motions: Motions<'_, S>,
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let b = store.bodies();
    let mut m = [[[zero; 6]; 3]; N];
    let mut tau = [zero; N];
    transforms(t, q, sincos, b.x);
    rnea(t, b.x, inertia, motions, &mut m, &mut tau);
    tau
}

/// `c(q, q̇)`, the nonlinear effects (Coriolis, centrifugal and gravity): [`rnea`] at `q̈ = 0`.
#[inline(always)]
pub fn nonlinear_effects<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    newton_euler(t, inertia, q, Motions::velocity(qd), sincos)
}

/// `g(q)`, the gravity torques: [`rnea`] at `q̇ = 0`, `q̈ = 0`.
#[inline(always)]
pub fn gravity<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    let motions = Motions {
        qd: None,
        qdd: None,
        f_ext: None,
    };
    newton_euler(t, inertia, q, motions, sincos)
}

/// `τ = M(q) q̈ + c(q, q̇)`: [`rnea`].
#[inline(always)]
pub fn inverse_dynamics<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    qdd: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    let motions = Motions {
        qd: Some(qd),
        qdd: Some(qdd),
        f_ext: None,
    };
    newton_euler(t, inertia, q, motions, sincos)
}

/// The recursive Newton–Euler algorithm (RBDA Table 5.1) on the joint transforms `x`, into
/// `tau`: forward `v_i = Xup_i v_λ(i) + S_i q̇_i`, `a_i = Xup_i a_λ(i) + S_i q̈_i + v_i ×ₘ S_i q̇_i`,
/// `f_i = I_i a_i + v_i ×* I_i v_i`, from `a₀` ([`Tables::a0`], RBDA §5.3); backward
/// `τ_i = S_iᵀ f_i`, `f_λ(i) += Xup_iᵀ f_i`. `m`: scratch of `[v_i, a_i, f_i]` per joint.
#[inline(always)]
pub fn rnea<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    x: &[Transform<S>],
    inertia: &[[S; 10]],
    motions: Motions<'_, S>,
    m: &mut [[[S; 6]; 3]],
    tau: &mut [S],
) {
    let root = Root {
        v: [S::zero(); 6],
        a: t.a0,
    };
    rnea_rooted(t, x, inertia, motions, &root, m, tau, None);
}

/// The motion of the body the joints without a parent hang on: the fixed base (`v = 0`,
/// `a = a₀`) or a free-floating base.
#[derive(Clone, Copy, Debug)]
pub struct Root<S> {
    /// Its spatial velocity in its own coordinates.
    pub v: [S; 6],
    /// Its spatial acceleration (gravity's fictitious one included, RBDA §5.3).
    pub a: [S; 6],
}

/// [`rnea`] from the root's motion `root`, the forces the joints on it carry there summed into
/// `root_force` (`None`: not wanted).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn rnea_rooted<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    x: &[Transform<S>],
    inertia: &[[S; 10]],
    motions: Motions<'_, S>,
    root: &Root<S>,
    m: &mut [[[S; 6]; 3]],
    tau: &mut [S],
    mut root_force: Option<&mut [S; 6]>,
) {
    let n = x.len().min(m.len());
    for i in 0..n {
        let (vp, ap) = match t.parent.get(i).copied().flatten().and_then(|l| m.get(l)) {
            Some([vp, ap, _]) => (*vp, *ap),
            None => (root.v, root.a),
        };
        let (Some(s), Some(ii)) = (t.s.get(i), inertia.get(i)) else {
            continue;
        };
        // RBDA Table 5.1: a_i = Xup_i a_λ(i) + S_i q̈_i + v_i ×ₘ S_i q̇_i.
        let mut ai = x[i].apply(&ap);
        if let Some(&qdd) = motions.qdd.and_then(|qdd| qdd.get(i)) {
            ai = axpy(&ai, qdd, s);
        }
        let [v, a, f] = &mut m[i];
        if let Some(&qd) = motions.qd.and_then(|qd| qd.get(i)) {
            let vj = scale(qd, s);
            *v = add(&x[i].apply(&vp), &vj);
            ai = add(&ai, &crm(v, &vj));
        }
        *a = ai;
        // f_i = I_i a_i + v_i ×* I_i v_i.
        *f = inertia_mul(ii, a);
        if motions.qd.is_some() {
            let iv = inertia_mul(ii, v);
            *f = add(f, &crf(v, &iv));
        }
        if let Some(e) = motions.f_ext.and_then(|f| f.get(i)) {
            *f = sub(f, &[e[3], e[4], e[5], e[0], e[1], e[2]]);
        }
    }
    for i in (0..n).rev() {
        let fi = m[i][2];
        if let (Some(s), Some(taui)) = (t.s.get(i), tau.get_mut(i)) {
            *taui = dot(s, &fi);
        }
        let carried = || x[i].apply_tr(&fi);
        match t.parent.get(i).copied().flatten() {
            Some(l) => {
                let c = carried();
                if let Some([_, _, fl]) = m.get_mut(l) {
                    *fl = add(fl, &c);
                }
            }
            None => {
                if let Some(f0) = root_force.as_deref_mut() {
                    *f0 = add(f0, &carried());
                }
            }
        }
    }
}
