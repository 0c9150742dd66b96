//! The spatial algebra of the compact kernels on plain arrays: Plücker transforms as a rotation
//! and a translation, motion and force 6-vectors `[angular; linear]`, spatial inertias as
//! 10-vectors, and the joint transforms and base-coordinate quantities of [`Tables`].

use super::tables::{Bodies, Tables};
use crate::scalar::Scalar;

/// A Plücker transform `X = [E 0; −E r̃ E]` as its rotation `E` and translation `r`
/// (RBDA eq. (2.24)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform<S> {
    /// The rotation `E` (from the parent's to the child's coordinates).
    pub e: [[S; 3]; 3],
    /// The translation `r` (the child's origin in the parent's coordinates).
    pub r: [S; 3],
}

impl<S: Scalar + Copy> Transform<S> {
    /// `X m = [E ω; E (v − r × ω)]` for a motion `m = [ω; v]` (RBDA eq. (2.24)).
    #[inline(always)]
    #[must_use]
    pub fn apply(&self, m: &[S; 6]) -> [S; 6] {
        let w = [m[0], m[1], m[2]];
        let rw = cross(&self.r, &w);
        let a = rot(&self.e, &w);
        let l = rot(&self.e, &[m[3] - rw[0], m[4] - rw[1], m[5] - rw[2]]);
        [a[0], a[1], a[2], l[0], l[1], l[2]]
    }

    /// `Xᵀ f = [Eᵀ n + r × Eᵀ f; Eᵀ f]` for a force `f = [n; f]` (RBDA Table 2.5).
    #[inline(always)]
    #[must_use]
    pub fn apply_tr(&self, f: &[S; 6]) -> [S; 6] {
        let l = rot_tr(&self.e, &[f[3], f[4], f[5]]);
        let a = rot_tr(&self.e, &[f[0], f[1], f[2]]);
        let rl = cross(&self.r, &l);
        [a[0] + rl[0], a[1] + rl[1], a[2] + rl[2], l[0], l[1], l[2]]
    }

    /// `X⁻¹ m = [Eᵀ ω; Eᵀ v + r × Eᵀ ω]` for a motion `m = [ω; v]` (RBDA Table 2.5): a body's
    /// `S_i` in base coordinates when `X` is its placement `(E_0i, p_0i)`.
    #[inline(always)]
    #[must_use]
    pub fn apply_tr_motion(&self, s: &[S; 6]) -> [S; 6] {
        let ws = rot_tr(&self.e, &[s[0], s[1], s[2]]);
        let vs = rot_tr(&self.e, &[s[3], s[4], s[5]]);
        let pw = cross(&self.r, &ws);
        [
            ws[0],
            ws[1],
            ws[2],
            vs[0] + pw[0],
            vs[1] + pw[1],
            vs[2] + pw[2],
        ]
    }

    /// `Xᵀ I X` of a spatial inertia `I` (RBDA Table 2.5): `h' = Eᵀh + m r`,
    /// `Ī' = Eᵀ Ī E − (Eᵀh) rᵀ − r h'ᵀ + (r·Eᵀh + r·h') 1`.
    #[inline(always)]
    #[must_use]
    pub fn inertia_tr(&self, i: &[S; 10]) -> [S; 10] {
        let (e, r, m) = (&self.e, &self.r, i[0]);
        let ib = [[i[4], i[5], i[6]], [i[5], i[7], i[8]], [i[6], i[8], i[9]]];
        let hr = rot_tr(e, &[i[1], i[2], i[3]]);
        let h = [hr[0] + m * r[0], hr[1] + m * r[1], hr[2] + m * r[2]];
        // Ī E, then the upper triangle of Eᵀ (Ī E).
        let ie_row = |a: usize| {
            let ie = |b: usize| ib[a][0] * e[0][b] + ib[a][1] * e[1][b] + ib[a][2] * e[2][b];
            [ie(0), ie(1), ie(2)]
        };
        let ie = [ie_row(0), ie_row(1), ie_row(2)];
        let d = r[0] * (hr[0] + h[0]) + r[1] * (hr[1] + h[1]) + r[2] * (hr[2] + h[2]);
        let entry = |a: usize, b: usize| {
            let eie = e[0][a] * ie[0][b] + e[1][a] * ie[1][b] + e[2][a] * ie[2][b];
            eie - hr[a] * r[b] - r[a] * h[b]
        };
        [
            m,
            h[0],
            h[1],
            h[2],
            entry(0, 0) + d,
            entry(0, 1),
            entry(0, 2),
            entry(1, 1) + d,
            entry(1, 2),
            entry(2, 2) + d,
        ]
    }
}

/// `a × b`.
#[inline(always)]
#[must_use]
pub fn cross<S: Scalar + Copy>(a: &[S; 3], b: &[S; 3]) -> [S; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `E v`.
#[inline(always)]
#[must_use]
pub fn rot<S: Scalar + Copy>(e: &[[S; 3]; 3], v: &[S; 3]) -> [S; 3] {
    let row = |r: usize| e[r][0] * v[0] + e[r][1] * v[1] + e[r][2] * v[2];
    [row(0), row(1), row(2)]
}

/// `Eᵀ v`.
#[inline(always)]
#[must_use]
pub fn rot_tr<S: Scalar + Copy>(e: &[[S; 3]; 3], v: &[S; 3]) -> [S; 3] {
    let col = |c: usize| e[0][c] * v[0] + e[1][c] * v[1] + e[2][c] * v[2];
    [col(0), col(1), col(2)]
}

/// `a ×ₘ b = [ω_a × ω_b; ω_a × v_b + v_a × ω_b]` (RBDA eq. (2.31)).
#[inline(always)]
#[must_use]
pub fn crm<S: Scalar + Copy>(a: &[S; 6], b: &[S; 6]) -> [S; 6] {
    let (wa, va, wb, vb) = (
        [a[0], a[1], a[2]],
        [a[3], a[4], a[5]],
        [b[0], b[1], b[2]],
        [b[3], b[4], b[5]],
    );
    let x = cross(&wa, &wb);
    let y = cross(&wa, &vb);
    let z = cross(&va, &wb);
    [x[0], x[1], x[2], y[0] + z[0], y[1] + z[1], y[2] + z[2]]
}

/// `v ×* f = [ω × n + v × f; ω × f]` (RBDA eq. (2.32)).
#[inline(always)]
#[must_use]
pub fn crf<S: Scalar + Copy>(v: &[S; 6], f: &[S; 6]) -> [S; 6] {
    let (w, vl, n, fl) = (
        [v[0], v[1], v[2]],
        [v[3], v[4], v[5]],
        [f[0], f[1], f[2]],
        [f[3], f[4], f[5]],
    );
    let x = cross(&w, &n);
    let y = cross(&vl, &fl);
    let z = cross(&w, &fl);
    [x[0] + y[0], x[1] + y[1], x[2] + y[2], z[0], z[1], z[2]]
}

/// `I m = [Ī ω + h × v; m v − h × ω]` (RBDA eq. (2.63)).
#[inline(always)]
#[must_use]
pub fn inertia_mul<S: Scalar + Copy>(i: &[S; 10], m: &[S; 6]) -> [S; 6] {
    let (w, v, h) = ([m[0], m[1], m[2]], [m[3], m[4], m[5]], [i[1], i[2], i[3]]);
    let hv = cross(&h, &v);
    let hw = cross(&h, &w);
    [
        i[4] * w[0] + i[5] * w[1] + i[6] * w[2] + hv[0],
        i[5] * w[0] + i[7] * w[1] + i[8] * w[2] + hv[1],
        i[6] * w[0] + i[8] * w[1] + i[9] * w[2] + hv[2],
        i[0] * v[0] - hw[0],
        i[0] * v[1] - hw[1],
        i[0] * v[2] - hw[2],
    ]
}

/// `a · b` of two 6-vectors (`S_jᵀ f`).
#[inline(always)]
#[must_use]
pub fn dot<S: Scalar + Copy>(a: &[S; 6], b: &[S; 6]) -> S {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}

/// `a + k b`.
#[inline(always)]
#[must_use]
pub fn axpy<S: Scalar + Copy>(a: &[S; 6], k: S, b: &[S; 6]) -> [S; 6] {
    let f = |r: usize| a[r] + k * b[r];
    [f(0), f(1), f(2), f(3), f(4), f(5)]
}

/// `k b`.
#[inline(always)]
#[must_use]
pub fn scale<S: Scalar + Copy>(k: S, b: &[S; 6]) -> [S; 6] {
    let f = |r: usize| k * b[r];
    [f(0), f(1), f(2), f(3), f(4), f(5)]
}

/// `a + b`.
#[inline(always)]
#[must_use]
pub fn add<S: Scalar + Copy>(a: &[S; 6], b: &[S; 6]) -> [S; 6] {
    let f = |r: usize| a[r] + b[r];
    [f(0), f(1), f(2), f(3), f(4), f(5)]
}

/// `a − b`.
#[inline(always)]
#[must_use]
pub fn sub<S: Scalar + Copy>(a: &[S; 6], b: &[S; 6]) -> [S; 6] {
    let f = |r: usize| a[r] - b[r];
    [f(0), f(1), f(2), f(3), f(4), f(5)]
}

/// `Xup_j = XJ(q_j) Xtree_j` for every joint, as `E_j = A_j + cos q_j B_j + sin q_j C_j` and
/// `r_j = l_j + q_j Υ_j u_j` (RBDA §4.4, Table 4.1; the module docs of [`super`]), into `x`.
/// `sincos` is called once per revolute joint.
#[inline(always)]
pub fn transforms<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
    x: &mut [Transform<S>],
) {
    let zero = S::zero();
    let kinds = x.iter_mut().zip(q).zip(t.revolute);
    let joints = kinds
        .zip(t.a)
        .zip(t.b)
        .zip(t.c)
        .zip(t.l.iter().zip(t.slide));
    for ((((((xj, &qj), &revolute), a), b), cc), (l, slide)) in joints {
        let (s, c, d) = if revolute {
            let (s, c) = sincos(qj);
            (s, c, zero)
        } else {
            (zero, zero, qj)
        };
        for r in 0..3 {
            for k in 0..3 {
                xj.e[r][k] = a[r][k] + c * b[r][k] + s * cc[r][k];
            }
            xj.r[r] = l[r] + d * slide[r];
        }
    }
}

/// The base-coordinate fields of [`Bodies`] from its joint transforms `x`:
/// `E_0i = E_i E_0λ(i)`, `p_0i = p_0λ(i) + E_0λ(i)ᵀ r_i` (RBDA §2.8, composition of Plücker
/// transforms), then `S_i` and `I_i` carried to the base (RBDA eq. (2.66)).
#[inline(always)]
pub fn world<S: Scalar + Copy>(t: &Tables<'_, S>, inertia: &[[S; 10]], w: &mut Bodies<'_, S>) {
    for i in 0..w.x.len().min(w.x0.len()) {
        let x = w.x[i];
        let parent = t.parent.get(i).copied().flatten();
        w.x0[i] = match parent.and_then(|l| w.x0.get(l)) {
            Some(p) => compose(&x, p),
            None => x,
        };
        let x0 = &w.x0[i];
        if let (Some(s), Some(s0)) = (t.s.get(i), w.s0.get_mut(i)) {
            *s0 = x0.apply_tr_motion(s);
        }
        if let (Some(ii), Some(i0)) = (inertia.get(i), w.i0.get_mut(i)) {
            *i0 = x0.inertia_tr(ii);
        }
    }
}

/// `(E_0i, p_0i)` of a body from its joint transform `x` and its parent's `p`:
/// `E_0i = E_i E_0λ`, `p_0i = p_0λ + E_0λᵀ r_i` (RBDA §2.8).
#[inline(always)]
#[must_use]
pub fn compose<S: Scalar + Copy>(x: &Transform<S>, p: &Transform<S>) -> Transform<S> {
    let (e, r, el) = (&x.e, &x.r, &p.e);
    let row = |a: usize| {
        let e0 = |b: usize| e[a][0] * el[0][b] + e[a][1] * el[1][b] + e[a][2] * el[2][b];
        [e0(0), e0(1), e0(2)]
    };
    let e0 = [row(0), row(1), row(2)];
    let d = rot_tr(el, r);
    Transform {
        e: e0,
        r: [p.r[0] + d[0], p.r[1] + d[1], p.r[2] + d[2]],
    }
}
