//! The compact kernels on a free-floating base (RBDA ch. 9; Pinocchio's free-flyer layout):
//! the base is body 0, the root the joints without a parent hang on, and its frame is the base
//! coordinates of the kernels (the tables' placements are relative to it; their `a₀` is not
//! read, gravity comes as `g` in the inertial frame).
//!
//! Positions `q = [p₀ (3); quat (4: x, y, z, w); q_joints (N)]`, speeds
//! `ν = [v_b (3); ω_b (3); q̇ (N)]` (the base's velocity in its own coordinates), accelerations
//! `ν̇ = [v̇_b; ω̇_b; q̈]` (the time derivatives of those components: the base's spatial
//! acceleration in its coordinates, RBDA §9.3), generalized forces `[f_b; n_b; τ]` (force, then
//! moment about the base origin, base coordinates). `R₀` is the quaternion's rotation
//! `1 + 2w ũ + 2 ũ ũ` (not normalized), so gravity in base coordinates is `R₀ᵀ g`.

use super::aba::{aba_floating_on_world, Articulated, ArticulatedStore, FloatingRoot, Rates};
use super::crba::crba;
use super::rnea::{rnea_rooted, Motions, Root};
use super::spatial::{
    add, crf, cross, inertia_mul, rot, rot_tr, sub, transforms, world, Transform,
};
use super::tables::{Bodies, BodyStore, Tables};
use crate::scalar::Scalar;

/// The free-floating base of a compact model: its spatial inertia about its origin in its frame
/// (`[m, h, Ī]` as [`Tables::inertia`]) and gravity in the inertial frame (`None`: none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Base<S> {
    /// The base body's spatial inertia.
    pub inertia: [S; 10],
    /// Gravity `g`, inertial frame.
    pub gravity: Option<[S; 3]>,
}

/// `R₀ = 1 + 2w ũ + 2 ũ ũ` of the quaternion `[x, y, z, w]` of `q[3..7]` (written out for a unit
/// quaternion; not normalized): base to inertial coordinates.
#[inline(always)]
pub fn base_rotation<S: Scalar + Copy>(q: &[S]) -> [[S; 3]; 3] {
    let zero = S::zero();
    let at = |k: usize| q.get(k).copied().unwrap_or(zero);
    let (x, y, z, w) = (at(3), at(4), at(5), at(6));
    let two = S::constant(2.0);
    let one = S::one();
    [
        [
            one - two * (y * y + z * z),
            two * (x * y - w * z),
            two * (x * z + w * y),
        ],
        [
            two * (x * y + w * z),
            one - two * (x * x + z * z),
            two * (y * z - w * x),
        ],
        [
            two * (x * z - w * y),
            two * (y * z + w * x),
            one - two * (x * x + y * y),
        ],
    ]
}

/// `R₀ᵀ g` for the quaternion of `q[3..7]`: gravity in base coordinates.
#[inline(always)]
pub(crate) fn gravity_in_base<S: Scalar + Copy>(q: &[S], g: &[S; 3]) -> [S; 3] {
    rot_tr(&base_rotation(q), g)
}

/// The base's position `p₀ = q[0..3]` in the inertial frame.
#[inline(always)]
pub(crate) fn base_position<S: Scalar + Copy>(q: &[S]) -> [S; 3] {
    let zero = S::zero();
    core::array::from_fn(|k| q.get(k).copied().unwrap_or(zero))
}

/// `[ω_b; v_b]` of `ν = [v_b; ω_b; …]`.
#[inline(always)]
fn spatial<S: Copy>(nu: &[S], zero: S) -> [S; 6] {
    let at = |k: usize| nu.get(k).copied().unwrap_or(zero);
    [at(3), at(4), at(5), at(0), at(1), at(2)]
}

/// `M(q)`, `(6 + N) × (6 + N)` (`NV = 6 + N`): [`mass_matrix_in`] on the joint transforms of `q`,
/// on stack storage of `N` joints.
#[inline]
pub fn mass_matrix<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; NV]; NV] {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut st = [[zero; N]; 6];
    let mut h = [[zero; N]; N];
    let mut out = [[zero; NV]; NV];
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    mass_matrix_in(
        t,
        inertia,
        base,
        &mut b,
        st.as_flattened_mut(),
        h.as_flattened_mut(),
        out.as_flattened_mut(),
    );
    out
}

/// `M` into `out` (`NV × NV`, rows first, `NV = 6 + N`) on the joint transforms `b.x`: the
/// joints' block by the composite-rigid-body algorithm ([`crba`], into `h`, `N × N`; `st`:
/// its scratch of `6 N`); the base's column of joint `j` is `F_j = I^c_j S_j` and the base's
/// block the composite inertia of the whole system `I^c_0 = I_0 + Σ I^c_root` (RBDA §9.2), both
/// written in the order `[v_b; ω_b]` (force rows first).
#[inline(always)]
pub fn mass_matrix_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    b: &mut Bodies<'_, S>,
    st: &mut [S],
    h: &mut [S],
    out: &mut [S],
) {
    let zero = S::zero();
    crba(t, inertia, b, st, h);
    let n = b.s0.len();
    let nv = n + 6;
    let mut put = |r: usize, c: usize, x: S| {
        if let Some(o) = out.get_mut(r * nv + c) {
            *o = x;
        }
    };
    let mut ic0 = base.inertia;
    for (i, ici) in b.i0.iter().enumerate() {
        if t.parent.get(i).copied().flatten().is_none() {
            for (a, c) in ic0.iter_mut().zip(ici) {
                *a = *a + *c;
            }
        }
        let Some(s) = b.s0.get(i) else {
            continue;
        };
        let f = inertia_mul(ici, s);
        for (r, x) in [f[3], f[4], f[5], f[0], f[1], f[2]].into_iter().enumerate() {
            put(r, 6 + i, x);
            put(6 + i, r, x);
        }
        for j in 0..n {
            put(6 + i, 6 + j, h.get(i * n + j).copied().unwrap_or(zero));
        }
    }
    // I^c_0 = [Ī h̃; h̃ᵀ m1] in [ω; v] order, written in [v; ω] order: [m1 h̃ᵀ; h̃ Ī].
    let h3 = [ic0[1], ic0[2], ic0[3]];
    let ib = [
        [ic0[4], ic0[5], ic0[6]],
        [ic0[5], ic0[7], ic0[8]],
        [ic0[6], ic0[8], ic0[9]],
    ];
    let ht = [
        [zero, -h3[2], h3[1]],
        [h3[2], zero, -h3[0]],
        [-h3[1], h3[0], zero],
    ];
    for r in 0..3 {
        for c in 0..3 {
            put(r, c, if r == c { ic0[0] } else { zero });
            put(3 + r, 3 + c, ib[r][c]);
            put(3 + r, c, ht[r][c]);
            put(c, 3 + r, ht[r][c]);
        }
    }
}

/// `(M(q), c(q, ν))` on one set of joint transforms: [`mass_matrix_in`] and
/// [`inverse_dynamics_in`] at `ν̇ = 0`.
#[inline]
pub fn mass_matrix_and_nonlinear_effects<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; NV]; NV], [S; NV]) {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut st = [[zero; N]; 6];
    let mut h = [[zero; N]; N];
    let mut m = [[[zero; 6]; 3]; N];
    let mut out = ([[zero; NV]; NV], [zero; NV]);
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    inverse_dynamics_in(
        t,
        b.x,
        inertia,
        base,
        q,
        Some(v),
        None,
        None,
        &mut m,
        &mut out.1,
    );
    let (st, h) = (st.as_flattened_mut(), h.as_flattened_mut());
    mass_matrix_in(t, inertia, base, &mut b, st, h, out.0.as_flattened_mut());
    out
}

/// Inverse dynamics `[f_b; n_b; τ] = M ν̇ + c` (`NV = 6 + N` entries): [`inverse_dynamics_in`]
/// on the joint transforms of `q`, on stack storage of `N` joints. `a = None`: `ν̇ = 0` (then the
/// result is `c`); `v = None`: `ν = 0`.
#[inline]
pub fn inverse_dynamics<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: Option<&[S]>,
    a: Option<&[S]>,
    sincos: impl Fn(S) -> (S, S),
) -> [S; NV] {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let b = store.bodies();
    let mut m = [[[zero; 6]; 3]; N];
    let mut out = [zero; NV];
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    inverse_dynamics_in(t, b.x, inertia, base, q, v, a, None, &mut m, &mut out);
    out
}

/// Inverse dynamics into `out` (`6 + N`) by the recursive Newton–Euler algorithm from the
/// base's motion (RBDA §9.5) on the joint transforms `x`: `v_0 = [ω_b; v_b]`,
/// `a_0 = [ω̇_b; v̇_b − R₀ᵀ g]`, the joints as [`rnea_rooted`] (`m`: its scratch), then
/// `f_0 = I_0 a_0 + v_0 ×* I_0 v_0 + Σ_{λ(i) = base} Xup_iᵀ f_i`. With `f_ext` (`[force;
/// moment]` in each body's frame at its origin: `f_ext[0]` on the base, `f_ext[1 + i]` on body
/// `i`), each body's wrench is subtracted from its force: the result is `M ν̇ + c − Jᵀ f_ext`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn inverse_dynamics_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    x: &[Transform<S>],
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: Option<&[S]>,
    a: Option<&[S]>,
    f_ext: Option<&[[S; 6]]>,
    m: &mut [[[S; 6]; 3]],
    out: &mut [S],
) {
    let root = root_motion(base, q, v, a);
    let motions = Motions {
        qd: v.map(|v| v.get(6..).unwrap_or(&[])),
        qdd: a.map(|a| a.get(6..).unwrap_or(&[])),
        f_ext: f_ext.map(|f| f.get(1..).unwrap_or(&[])),
    };
    let k = &base.inertia;
    let mut f0 = inertia_mul(k, &root.a);
    if v.is_some() {
        f0 = add(&f0, &crf(&root.v, &inertia_mul(k, &root.v)));
    }
    if let Some(e) = f_ext.and_then(<[_]>::first) {
        f0 = sub(&f0, &[e[3], e[4], e[5], e[0], e[1], e[2]]);
    }
    let (head, tau) = out.split_at_mut(6.min(out.len()));
    rnea_rooted(t, x, inertia, motions, &root, m, tau, Some(&mut f0));
    for (o, x) in head
        .iter_mut()
        .zip([f0[3], f0[4], f0[5], f0[0], f0[1], f0[2]])
    {
        *o = x;
    }
}

/// The base's motion as the root of the passes (RBDA §9.5): `v_0 = [ω_b; v_b]` of `ν` (zero
/// without `v`), `a_0 = [ω̇_b; v̇_b − R₀ᵀ g]` of `ν̇` (zero without `a`; gravity as the base's
/// fictitious acceleration, RBDA §5.3).
#[inline(always)]
pub(crate) fn root_motion<S: Scalar + Copy>(
    base: &Base<S>,
    q: &[S],
    v: Option<&[S]>,
    a: Option<&[S]>,
) -> Root<S> {
    let zero = S::zero();
    let mut a0 = a.map_or([zero; 6], |a| spatial(a, zero));
    if let Some(g) = &base.gravity {
        let gb = gravity_in_base(q, g);
        for k in 0..3 {
            a0[3 + k] = a0[3 + k] - gb[k];
        }
    }
    Root {
        v: v.map_or([zero; 6], |v| spatial(v, zero)),
        a: a0,
    }
}

/// The wrench the arm exerts on the base for the motion `(q, ν, ν̇)` under gravity, `[f; n]`
/// (force, moment about the base origin, base coordinates): [`base_reaction_in`] on the joint
/// transforms of `q`, on stack storage of `N` joints.
#[inline]
pub fn base_reaction<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [S; 6] {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let b = store.bodies();
    let mut m = [[[zero; 6]; 3]; N];
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    base_reaction_in(t, b.x, inertia, base, q, v, a, &mut m)
}

/// The arm's reaction on its base on the joint transforms `x`: the recursive Newton–Euler
/// passes from the base's motion ([`rnea_rooted`], `m`: its scratch) with the base's own
/// inertia left out, `−Σ_{λ(i) = base} Xup_iᵀ f_i` (Newton's third law; the base's equation is
/// `w_b + reaction = I_0 a_0 + v_0 ×* I_0 v_0`), written `[f; n]`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn base_reaction_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    x: &[Transform<S>],
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    m: &mut [[[S; 6]; 3]],
) -> [S; 6] {
    let root = root_motion(base, q, Some(v), Some(a));
    let motions = Motions {
        qd: Some(v.get(6..).unwrap_or(&[])),
        qdd: Some(a.get(6..).unwrap_or(&[])),
        f_ext: None,
    };
    let mut f0 = [S::zero(); 6];
    rnea_rooted(t, x, inertia, motions, &root, m, &mut [], Some(&mut f0));
    [-f0[3], -f0[4], -f0[5], -f0[0], -f0[1], -f0[2]]
}

/// The total momentum of base and arm `[P; L]` (inertial frame, `L` about the inertial
/// origin): [`momentum_in`] on the joint transforms of `q`, on stack storage of `N` joints.
#[inline]
pub fn momentum<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [S; 6] {
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut vw = [[S::zero(); 6]; N];
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    momentum_in(t, inertia, base, q, v, &mut b, &mut vw)
}

/// The momentum on the joint transforms `b.x`: the bodies carried to the base ([`world`]), their
/// velocities in base coordinates `ᴼv_i = ᴼv_λ(i) + ᴼS_i q̇_i` from `ᴼv_0 = [ω_b; v_b]` (into
/// `vw`), `h = I_0 v_0 + Σ ᴼI_i ᴼv_i` about the base origin (RBDA §2.13), then
/// `P = R₀ h_f`, `L = R₀ h_n + p₀ × P`.
#[inline(always)]
pub fn momentum_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    b: &mut Bodies<'_, S>,
    vw: &mut [[S; 6]],
) -> [S; 6] {
    let zero = S::zero();
    world(t, inertia, b);
    let v0 = spatial(v, zero);
    let mut h = inertia_mul(&base.inertia, &v0);
    let qd = v.get(6..).unwrap_or(&[]);
    for i in 0..vw.len() {
        let vp = match t.parent.get(i).copied().flatten().and_then(|l| vw.get(l)) {
            Some(vp) => *vp,
            None => v0,
        };
        let (Some(s0), Some(i0), Some(&qdi)) = (b.s0.get(i), b.i0.get(i), qd.get(i)) else {
            continue;
        };
        let vi = add(&vp, &super::spatial::scale(qdi, s0));
        h = add(&h, &inertia_mul(i0, &vi));
        vw[i] = vi;
    }
    let r0 = base_rotation(q);
    let lin = rot(&r0, &[h[3], h[4], h[5]]);
    let ang = rot(&r0, &[h[0], h[1], h[2]]);
    let pl = cross(&base_position(q), &lin);
    [
        lin[0],
        lin[1],
        lin[2],
        ang[0] + pl[0],
        ang[1] + pl[1],
        ang[2] + pl[2],
    ]
}

/// Forward dynamics `ν̇` (`NV = 6 + N` entries) under the joint drives `tau` and, with `f_ext`,
/// the wrenches `f_ext[0]` on the base and `f_ext[1 + i]` on body `i` (`[force; moment]` in the
/// body's frame at its origin): [`forward_dynamics_in`] on the joint transforms of `q`, on stack
/// storage of `N` joints.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn forward_dynamics<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    tau: &[S; N],
    f_ext: Option<&[[S; 6]]>,
    sincos: impl Fn(S) -> (S, S),
) -> [S; NV] {
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut scratch = ArticulatedStore::<S, N>::new();
    let mut out = [S::zero(); NV];
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    let mut ab = scratch.articulated();
    forward_dynamics_in(
        t, inertia, base, q, v, tau, f_ext, &mut b, &mut ab, &mut out,
    );
    out
}

/// Forward dynamics into `out` (`6 + N`) on the joint transforms `b.x`: the bodies carried to
/// the base ([`world`]), then the articulated-body algorithm with the base as its root
/// ([`aba_floating_on_world`]; `ab`: its scratch).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn forward_dynamics_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    tau: &[S],
    f_ext: Option<&[[S; 6]]>,
    b: &mut Bodies<'_, S>,
    ab: &mut Articulated<'_, S>,
    out: &mut [S],
) {
    let zero = S::zero();
    world(t, inertia, b);
    let rates = Rates {
        qd: v.get(6..).unwrap_or(&[]),
        tau,
        f_ext: f_ext.map(|f| f.get(1..).unwrap_or(&[])),
        armature: None,
    };
    let root = FloatingRoot {
        inertia: base.inertia,
        v: spatial(v, zero),
        f_ext: f_ext.and_then(|f| f.first().copied()),
        gravity: base.gravity.map(|g| gravity_in_base(q, &g)),
    };
    aba_floating_on_world(t, rates, &root, b, ab, out);
}
