//! Forward dynamics by the articulated-body algorithm (RBDA Table 7.1), with and without
//! external wrenches.

use super::spatial::{add, axpy, crf, crm, dot, inertia_mul, scale, sub, transforms, world};
use super::tables::Tables;
use crate::scalar::Scalar;

/// `q̈ = M(q)⁻¹ (τ − c(q, q̇))`: [`aba`] without external wrenches.
#[inline(always)]
pub fn forward_dynamics<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    qd: &[S; N],
    tau: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    aba(t, inertia, q, qd, tau, None, sincos)
}

/// [`forward_dynamics`] with `f_ext[i] = [force; moment]` on body `i`, in its frame at its
/// origin: [`aba`].
#[inline(always)]
pub fn forward_dynamics_with_wrenches<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    qd: &[S; N],
    tau: &[S; N],
    f_ext: &[[S; 6]; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    aba(t, inertia, q, qd, tau, Some(f_ext), sincos)
}

/// Where entry `(r, c)` of a symmetric 6×6 matrix is kept among its 21 upper-triangle entries,
/// by rows.
const SYM: [[usize; 6]; 6] = {
    let mut k = [[0; 6]; 6];
    let mut r = 0;
    while r < 6 {
        let mut c = 0;
        while c < 6 {
            let (a, b) = if r < c { (r, c) } else { (c, r) };
            k[r][c] = a * 6 - a * (a + 1) / 2 + b;
            c += 1;
        }
        r += 1;
    }
    k
};

/// `M v` of a symmetric 6×6 `M` kept as its 21 upper-triangle entries ([`SYM`]).
#[inline(always)]
fn sym_times<S: Scalar + Copy>(m: &[S; 21], v: &[S; 6]) -> [S; 6] {
    core::array::from_fn(|r| {
        let row = &SYM[r];
        m[row[0]] * v[0]
            + m[row[1]] * v[1]
            + m[row[2]] * v[2]
            + m[row[3]] * v[3]
            + m[row[4]] * v[4]
            + m[row[5]] * v[5]
    })
}

/// `M − w uᵀ` of a packed symmetric `M` (for `w uᵀ` symmetric: `w = u / D`).
#[inline(always)]
fn sym_minus_outer<S: Scalar + Copy>(m: &[S; 21], w: &[S; 6], u: &[S; 6]) -> [S; 21] {
    let mut out = *m;
    let mut k = 0;
    for (r, wr) in w.iter().enumerate() {
        for uc in &u[r..] {
            out[k] = m[k] - *wr * *uc;
            k += 1;
        }
    }
    out
}

/// The articulated-body algorithm (RBDA Table 7.1) in base coordinates (RBDA §7.3's "any
/// coordinate system", as Pinocchio's), so that no transform is needed between bodies:
/// velocities and bias terms outwards ([`outward`]), articulated inertias inwards ([`inward`]),
/// accelerations outwards from `a₀` ([`Tables::a0`]). `f_ext[i] = [force; moment]` in body
/// `i`'s frame at its origin (`None`: no wrenches, nothing computed for them).
#[inline]
pub fn aba<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    inertia: &[[S; 10]; N],
    q: &[S; N],
    qd: &[S; N],
    tau: &[S; N],
    f_ext: Option<&[[S; 6]; N]>,
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    let x = transforms(t, q, sincos);
    let w = world(t, &x, inertia);
    let mut o = outward(t, &w, qd, f_ext);
    let s = inward(t, &w.s0, tau, &mut o);
    // RBDA Table 7.1, third pass: a' = a_λ + c_i, q̈_i = (u_i − U_iᵀ a') / D_i,
    // a_i = a' + S_i q̈_i.
    let zero = S::zero();
    let mut acc = [[zero; 6]; N];
    let mut qdd = [zero; N];
    for i in 0..N {
        let ap = match t.parent[i].and_then(|l| acc.get(l)) {
            Some(ap) => *ap,
            None => t.a0,
        };
        let a = add(&ap, &o.c[i]);
        qdd[i] = (s.u[i] - dot(&s.ui[i], &a)) / s.d[i];
        acc[i] = axpy(&a, qdd[i], &w.s0[i]);
    }
    qdd
}

/// The ABA's first pass: velocities `v_i`, bias accelerations `c_i`, and the articulated
/// inertias and bias forces before the second pass.
struct Outward<S, const N: usize> {
    /// `c_i = v_i ×ₘ S_i q̇_i`.
    c: [[S; 6]; N],
    /// `I^A_i`, 21 upper-triangle entries by rows ([`SYM`]).
    ia: [[S; 21]; N],
    /// `p^A_i`.
    pa: [[S; 6]; N],
}

/// RBDA Table 7.1, first pass (base coordinates): `v_i = v_λ + S_i q̇_i`,
/// `c_i = v_i ×ₘ S_i q̇_i`, `I^A_i = I_i`, `p^A_i = v_i ×* I_i v_i − f^x_i`.
#[inline(always)]
fn outward<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    w: &super::spatial::World<S, N>,
    qd: &[S; N],
    f_ext: Option<&[[S; 6]; N]>,
) -> Outward<S, N> {
    let zero = S::zero();
    let mut v = [[zero; 6]; N];
    let mut o = Outward {
        c: [[zero; 6]; N],
        ia: [[zero; 21]; N],
        pa: [[zero; 6]; N],
    };
    for i in 0..N {
        let vp = match t.parent[i].and_then(|l| v.get(l)) {
            Some(vp) => *vp,
            None => [zero; 6],
        };
        let vj = scale(qd[i], &w.s0[i]);
        v[i] = add(&vp, &vj);
        o.c[i] = crm(&v[i], &vj);
        let k = &w.i0[i];
        // I = [Ī h̃; h̃ᵀ m1] (RBDA eq. (2.63)), upper triangle by rows.
        #[rustfmt::skip]
        let ia = [
            k[4], k[5], k[6], zero, -k[3], k[2],
            k[7], k[8], k[3], zero, -k[1],
            k[9], -k[2], k[1], zero,
            k[0], zero, zero,
            k[0], zero,
            k[0],
        ];
        o.ia[i] = ia;
        let iv = inertia_mul(k, &v[i]);
        let p = crf(&v[i], &iv);
        o.pa[i] = match f_ext {
            Some(f_ext) => {
                let e = &f_ext[i];
                sub(&p, &w.x0[i].apply_tr(&[e[3], e[4], e[5], e[0], e[1], e[2]]))
            }
            None => p,
        };
    }
    o
}

/// The ABA's second-pass results per joint.
struct Inward<S, const N: usize> {
    /// `U_i = I^A_i S_i`.
    ui: [[S; 6]; N],
    /// `D_i = S_iᵀ U_i`.
    d: [S; N],
    /// `u_i = τ_i − S_iᵀ p^A_i`.
    u: [S; N],
}

/// RBDA Table 7.1, second pass (base coordinates, leaves first): `U_i = I^A_i S_i`,
/// `D_i = S_iᵀ U_i`, `u_i = τ_i − S_iᵀ p^A_i`, `I^A_λ += I^A_i − U_i U_iᵀ / D_i`,
/// `p^A_λ += p^A_i + (I^A_i − U_i U_iᵀ / D_i) c_i + U_i u_i / D_i`.
#[inline(always)]
fn inward<S: Scalar + Copy, const N: usize>(
    t: &Tables<S, N>,
    s0: &[[S; 6]; N],
    tau: &[S; N],
    o: &mut Outward<S, N>,
) -> Inward<S, N> {
    let zero = S::zero();
    let mut r = Inward {
        ui: [[zero; 6]; N],
        d: [S::one(); N],
        u: [zero; N],
    };
    for i in (0..N).rev() {
        let s = &s0[i];
        let ui = sym_times(&o.ia[i], s);
        r.d[i] = dot(s, &ui);
        r.u[i] = tau[i] - dot(s, &o.pa[i]);
        r.ui[i] = ui;
        if let Some(l) = t.parent[i] {
            let dinv = S::one() / r.d[i];
            let w = scale(dinv, &ui);
            let m = sym_minus_outer(&o.ia[i], &w, &ui);
            let p = axpy(&o.pa[i], r.u[i], &w);
            let p = add(&p, &sym_times(&m, &o.c[i]));
            if let (Some(ial), Some(pal)) = (o.ia.get_mut(l), o.pa.get_mut(l)) {
                for (a, b) in ial.iter_mut().zip(m) {
                    *a = *a + b;
                }
                *pal = add(pal, &p);
            }
        }
    }
    r
}
