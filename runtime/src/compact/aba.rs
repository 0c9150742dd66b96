//! Forward dynamics by the articulated-body algorithm (RBDA Table 7.1), with and without
//! external wrenches.

use super::spatial::{add, axpy, crf, crm, dot, inertia_mul, scale, sub, transforms, world};
use super::tables::{Bodies, BodyStore, Tables};
use crate::scalar::Scalar;

/// `q̈ = M(q)⁻¹ (τ − c(q, q̇))`: [`aba`] without external wrenches.
#[inline(always)]
pub fn forward_dynamics<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    tau: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    articulated(
        t,
        inertia,
        q,
        Rates {
            qd,
            tau,
            f_ext: None,
            armature: None,
        },
        sincos,
    )
}

/// [`forward_dynamics`] with `f_ext[i] = [force; moment]` on body `i`, in its frame at its
/// origin: [`aba`].
#[inline(always)]
pub fn forward_dynamics_with_wrenches<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    tau: &[S; N],
    f_ext: &[[S; 6]; N],
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    let rates = Rates {
        qd,
        tau,
        f_ext: Some(f_ext),
        armature: None,
    };
    articulated(t, inertia, q, rates, sincos)
}

/// [`aba`] on the joint transforms of `q`, on stack storage of `N` joints.
#[inline]
fn articulated<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    rates: Rates<'_, S>,
    sincos: impl Fn(S) -> (S, S),
) -> [S; N] {
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut scratch = ArticulatedStore::<S, N>::new();
    let mut qdd = [S::zero(); N];
    transforms(t, q, sincos, b.x);
    aba(
        t,
        inertia,
        rates,
        &mut b,
        &mut scratch.articulated(),
        &mut qdd,
    );
    qdd
}

/// What the articulated-body algorithm runs at besides `q`: `q̇`, `τ`, the external wrenches,
/// `f_ext[i] = [force; moment]` in body `i`'s frame at its origin, and the armature `a_i ≥ 0`
/// (the reflected rotor inertia `I_m n²` of a geared motor, Pinocchio's `Model::armature`:
/// `(M + diag(a)) q̈ = τ − c`). One entry per joint; `None`: absent, nothing computed for it.
#[derive(Clone, Copy, Debug)]
pub struct Rates<'a, S> {
    /// `q̇`.
    pub qd: &'a [S],
    /// `τ`.
    pub tau: &'a [S],
    /// The external wrenches.
    pub f_ext: Option<&'a [[S; 6]]>,
    /// The armature.
    pub armature: Option<&'a [S]>,
}

/// The bodies' quantities in the articulated-body algorithm (RBDA Table 7.1), one entry per
/// joint in each slice: the kernel's scratch (see [`ArticulatedStore`]).
#[derive(Debug)]
pub struct Articulated<'a, S> {
    /// `v_i`.
    pub v: &'a mut [[S; 6]],
    /// `c_i = v_i ×ₘ S_i q̇_i`.
    pub c: &'a mut [[S; 6]],
    /// `I^A_i`, 21 upper-triangle entries by rows ([`SYM`]).
    pub ia: &'a mut [[S; 21]],
    /// `p^A_i`.
    pub pa: &'a mut [[S; 6]],
    /// `U_i = I^A_i S_i`.
    pub ui: &'a mut [[S; 6]],
    /// `D_i = S_iᵀ U_i`.
    pub d: &'a mut [S],
    /// `u_i = τ_i − S_iᵀ p^A_i`.
    pub u: &'a mut [S],
    /// `a_i`.
    pub a: &'a mut [[S; 6]],
}

/// Storage of `N` joints for [`Articulated`], on the stack: what the const-`N` entry points hand
/// to [`aba`]. All zero (every entry is written before it is read).
#[derive(Clone, Copy, Debug)]
pub struct ArticulatedStore<S, const N: usize> {
    v: [[S; 6]; N],
    c: [[S; 6]; N],
    ia: [[S; 21]; N],
    pa: [[S; 6]; N],
    ui: [[S; 6]; N],
    d: [S; N],
    u: [S; N],
    a: [[S; 6]; N],
}

impl<S: Scalar + Copy, const N: usize> ArticulatedStore<S, N> {
    /// Zeroed storage.
    #[inline(always)]
    #[must_use]
    pub fn new() -> Self {
        let zero = S::zero();
        ArticulatedStore {
            v: [[zero; 6]; N],
            c: [[zero; 6]; N],
            ia: [[zero; 21]; N],
            pa: [[zero; 6]; N],
            ui: [[zero; 6]; N],
            d: [zero; N],
            u: [zero; N],
            a: [[zero; 6]; N],
        }
    }

    /// The storage as the kernel's scratch.
    #[inline(always)]
    pub fn articulated(&mut self) -> Articulated<'_, S> {
        Articulated {
            v: &mut self.v,
            c: &mut self.c,
            ia: &mut self.ia,
            pa: &mut self.pa,
            ui: &mut self.ui,
            d: &mut self.d,
            u: &mut self.u,
            a: &mut self.a,
        }
    }
}

impl<S: Scalar + Copy, const N: usize> Default for ArticulatedStore<S, N> {
    #[inline(always)]
    fn default() -> Self {
        Self::new()
    }
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
    let row = |r: usize| {
        let row = &SYM[r];
        m[row[0]] * v[0]
            + m[row[1]] * v[1]
            + m[row[2]] * v[2]
            + m[row[3]] * v[3]
            + m[row[4]] * v[4]
            + m[row[5]] * v[5]
    };
    [row(0), row(1), row(2), row(3), row(4), row(5)]
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
/// coordinate system", as Pinocchio's), so that no transform is needed between bodies, on the
/// joint transforms `b.x`, into `qdd`: the bodies carried to the base ([`world`]), then
/// [`aba_on_world`]. `ab`: scratch, one entry per joint.
#[inline(always)]
pub fn aba<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    rates: Rates<'_, S>,
    b: &mut Bodies<'_, S>,
    ab: &mut Articulated<'_, S>,
    qdd: &mut [S],
) {
    world(t, inertia, b);
    aba_on_world(t, rates, b, ab, qdd);
}

/// [`aba`] on bodies already carried to the base ([`world`]): velocities and bias terms
/// outwards ([`outward`]), articulated inertias inwards ([`inward`]), accelerations outwards
/// from `a₀` ([`Tables::a0`], [`accelerations`]).
#[inline(always)]
pub fn aba_on_world<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    rates: Rates<'_, S>,
    b: &Bodies<'_, S>,
    ab: &mut Articulated<'_, S>,
    qdd: &mut [S],
) {
    outward(t, b, rates, &[S::zero(); 6], ab);
    inward(t, b.s0, rates, ab, None);
    accelerations(t, b.s0, ab, &t.a0, qdd);
}

/// The free-floating base of [`aba_floating_on_world`]: body 0, moved by a 6-dof joint, whose
/// frame is the base coordinates of the kernels (the tables' placements are relative to it).
#[derive(Clone, Copy, Debug)]
pub struct FloatingRoot<S> {
    /// Its spatial inertia about its origin, `[m, h (3), Ī upper triangle (6)]` as
    /// [`Tables::inertia`].
    pub inertia: [S; 10],
    /// Its spatial velocity `v_0 = [ω_b; v_b]` in its own coordinates.
    pub v: [S; 6],
    /// The external wrench on it, `[force; moment]` in its frame at its origin.
    pub f_ext: Option<[S; 6]>,
    /// Gravity in its coordinates, `R₀ᵀ g`.
    pub gravity: Option<[S; 3]>,
}

/// Forward dynamics on a free-floating base by the articulated-body algorithm (RBDA ch. 9,
/// spatial_v2's `FDfb`) on bodies already carried to the base ([`world`]), into
/// `nu_dot = [v̇_b (3); ω̇_b (3); q̈ (N)]`: the base's spatial acceleration in its own
/// coordinates, then the joints'. The base is the root of the passes: `v_0` starts the outward
/// pass, `I^A_0 = I_0`, `p^A_0 = v_0 ×* I_0 v_0 − f^x_0` gather the joints on it, and
/// `a'_0 = −(I^A_0)⁻¹ p^A_0` (a 6×6 LDLᵀ) starts the accelerations. Gravity stays out of the
/// passes (every `a'_i = a_i − a_g` obeys the same recursion; [`Tables::a0`] is not read) and is
/// put back on the base: `a_0 = a'_0 + [0; R₀ᵀ g]`.
#[inline(always)]
pub fn aba_floating_on_world<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    rates: Rates<'_, S>,
    root: &FloatingRoot<S>,
    b: &Bodies<'_, S>,
    ab: &mut Articulated<'_, S>,
    nu_dot: &mut [S],
) {
    let k = &root.inertia;
    outward(t, b, rates, &root.v, ab);
    let mut ia0 = packed_inertia(k);
    let p0 = crf(&root.v, &inertia_mul(k, &root.v));
    let mut pa0 = match &root.f_ext {
        Some(e) => sub(&p0, &[e[3], e[4], e[5], e[0], e[1], e[2]]),
        None => p0,
    };
    inward(t, b.s0, rates, ab, Some((&mut ia0, &mut pa0)));
    // I^A_0 a'_0 = −p^A_0.
    let factor = SpatialFactor::new(&ia0);
    let mut a0: [S; 6] = core::array::from_fn(|r| -pa0[r]);
    factor.solve(&mut a0);
    let (head, qdd) = nu_dot.split_at_mut(6.min(nu_dot.len()));
    accelerations(t, b.s0, ab, &a0, qdd);
    // a_0 = a'_0 + [0; R₀ᵀ g], written [linear; angular].
    let mut lin = [a0[3], a0[4], a0[5]];
    if let Some(g) = &root.gravity {
        lin = [lin[0] + g[0], lin[1] + g[1], lin[2] + g[2]];
    }
    for (o, v) in head
        .iter_mut()
        .zip(lin.into_iter().chain([a0[0], a0[1], a0[2]]))
    {
        *o = v;
    }
}

/// The LDLᵀ factors of a symmetric positive definite 6×6 matrix (a spatial inertia, articulated
/// or composite), for solving `I a = f` with it ([`crate::ldlt`]).
pub(crate) struct SpatialFactor<S> {
    l: [S; 36],
    d_inv: [S; 6],
}

impl<S: Scalar + Copy> SpatialFactor<S> {
    /// The factors of the matrix kept as its 21 upper-triangle entries ([`SYM`]).
    #[inline(always)]
    pub(crate) fn new(packed: &[S; 21]) -> Self {
        let mut f = SpatialFactor {
            l: core::array::from_fn(|k| packed[SYM[k / 6][k % 6]]),
            d_inv: [S::zero(); 6],
        };
        // 36 and 6 entries: the buffers are never short.
        let _ = crate::ldlt::factor_in_place(&mut f.l, 6, &mut f.d_inv);
        f
    }

    /// `x ← I⁻¹ x`.
    #[inline(always)]
    pub(crate) fn solve(&self, x: &mut [S; 6]) {
        let _ = crate::ldlt::solve_in_place(&self.l, 6, &self.d_inv, x);
    }
}

/// `I = [Ī h̃; h̃ᵀ m1]` (RBDA eq. (2.63)) of a spatial inertia `[m, h, Ī]`, its upper triangle by
/// rows ([`SYM`]).
#[inline(always)]
pub(crate) fn packed_inertia<S: Scalar + Copy>(k: &[S; 10]) -> [S; 21] {
    let zero = S::zero();
    #[rustfmt::skip]
    let i = [
        k[4], k[5], k[6], zero, -k[3], k[2],
        k[7], k[8], k[3], zero, -k[1],
        k[9], -k[2], k[1], zero,
        k[0], zero, zero,
        k[0], zero,
        k[0],
    ];
    i
}

/// RBDA Table 7.1, third pass (`a_root`: the root's acceleration): `a' = a_λ + c_i`, `q̈_i = (u_i − U_iᵀ a') / D_i`,
/// `a_i = a' + S_i q̈_i`.
#[inline(always)]
fn accelerations<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    s0: &[[S; 6]],
    ab: &mut Articulated<'_, S>,
    a_root: &[S; 6],
    qdd: &mut [S],
) {
    for i in 0..ab.a.len() {
        let ap = match t.parent.get(i).copied().flatten().and_then(|l| ab.a.get(l)) {
            Some(p) => *p,
            None => *a_root,
        };
        let (Some(s), Some(c), Some(ui), Some(&u), Some(&d), Some(qddi)) = (
            s0.get(i),
            ab.c.get(i),
            ab.ui.get(i),
            ab.u.get(i),
            ab.d.get(i),
            qdd.get_mut(i),
        ) else {
            continue;
        };
        let a = add(&ap, c);
        *qddi = (u - dot(ui, &a)) / d;
        if let Some(ai) = ab.a.get_mut(i) {
            *ai = axpy(&a, *qddi, s);
        }
    }
}

/// RBDA Table 7.1, first pass (base coordinates; `v_root`: the root's velocity): `v_i = v_λ + S_i q̇_i`,
/// `c_i = v_i ×ₘ S_i q̇_i`, `I^A_i = I_i`, `p^A_i = v_i ×* I_i v_i − f^x_i`.
#[inline(always)]
fn outward<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    b: &Bodies<'_, S>,
    rates: Rates<'_, S>,
    v_root: &[S; 6],
    ab: &mut Articulated<'_, S>,
) {
    for i in 0..ab.v.len() {
        let vp = match t.parent.get(i).copied().flatten().and_then(|l| ab.v.get(l)) {
            Some(p) => *p,
            None => *v_root,
        };
        let (Some(s), Some(k), Some(x0), Some(&qd)) =
            (b.s0.get(i), b.i0.get(i), b.x0.get(i), rates.qd.get(i))
        else {
            continue;
        };
        let (Some(c), Some(ia), Some(pa)) = (ab.c.get_mut(i), ab.ia.get_mut(i), ab.pa.get_mut(i))
        else {
            continue;
        };
        let vj = scale(qd, s);
        let v = add(&vp, &vj);
        *c = crm(&v, &vj);
        *ia = packed_inertia(k);
        let iv = inertia_mul(k, &v);
        let p = crf(&v, &iv);
        *pa = match rates.f_ext.and_then(|f| f.get(i)) {
            Some(e) => sub(&p, &x0.apply_tr(&[e[3], e[4], e[5], e[0], e[1], e[2]])),
            None => p,
        };
        if let Some(vi) = ab.v.get_mut(i) {
            *vi = v;
        }
    }
}

/// RBDA Table 7.1, second pass (base coordinates, leaves first): `U_i = I^A_i S_i`,
/// `D_i = S_iᵀ U_i + a_i` (armature `a_i`), `u_i = τ_i − S_iᵀ p^A_i`,
/// `I^A_λ += I^A_i − U_i U_iᵀ / D_i`, `p^A_λ += p^A_i + (I^A_i − U_i U_iᵀ / D_i) c_i + U_i u_i / D_i`;
/// a joint on the base gives to `root` when the base is floating (`None`: a fixed base, nothing
/// given).
#[inline(always)]
fn inward<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    s0: &[[S; 6]],
    rates: Rates<'_, S>,
    ab: &mut Articulated<'_, S>,
    mut root: Option<(&mut [S; 21], &mut [S; 6])>,
) {
    for i in (0..ab.ia.len()).rev() {
        let (Some(s), Some(&taui), Some(&ia), Some(&pa), Some(&c)) = (
            s0.get(i),
            rates.tau.get(i),
            ab.ia.get(i),
            ab.pa.get(i),
            ab.c.get(i),
        ) else {
            continue;
        };
        let ui = sym_times(&ia, s);
        let d = match rates.armature.and_then(|a| a.get(i)) {
            Some(&a) => dot(s, &ui) + a,
            None => dot(s, &ui),
        };
        let u = taui - dot(s, &pa);
        if let (Some(di), Some(uu), Some(uv)) = (ab.d.get_mut(i), ab.u.get_mut(i), ab.ui.get_mut(i))
        {
            (*di, *uu, *uv) = (d, u, ui);
        }
        let parent = t.parent.get(i).copied().flatten();
        let target = match parent {
            Some(l) => ab.ia.get_mut(l).zip(ab.pa.get_mut(l)),
            None => root.as_mut().map(|(ia, pa)| (&mut **ia, &mut **pa)),
        };
        if let Some((ial, pal)) = target {
            let dinv = S::one() / d;
            let w = scale(dinv, &ui);
            let m = sym_minus_outer(&ia, &w, &ui);
            let p = axpy(&pa, u, &w);
            let p = add(&p, &sym_times(&m, &c));
            for (a, b) in ial.iter_mut().zip(m) {
                *a = *a + b;
            }
            *pal = add(pal, &p);
        }
    }
}
