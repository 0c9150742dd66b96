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
use super::spatial::{add, crf, inertia_mul, transforms, world};
use super::tables::{BodyStore, Tables};
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

/// `R₀ᵀ g` for the quaternion `[x, y, z, w]` of `q[3..7]`: gravity in base coordinates.
#[inline(always)]
fn gravity_in_base<S: Scalar + Copy>(q: &[S], g: &[S; 3]) -> [S; 3] {
    let zero = S::zero();
    let at = |k: usize| q.get(k).copied().unwrap_or(zero);
    let (x, y, z, w) = (at(3), at(4), at(5), at(6));
    let two = S::constant(2.0);
    let one = S::one();
    let r = [
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
    ];
    core::array::from_fn(|i| r[0][i] * g[0] + r[1][i] * g[1] + r[2][i] * g[2])
}

/// The joints' entries of a free-floating vector (`skip` = 7 for positions, 6 for speeds).
#[inline(always)]
fn joints<S: Copy, const N: usize>(x: &[S], skip: usize, zero: S) -> [S; N] {
    core::array::from_fn(|i| x.get(skip + i).copied().unwrap_or(zero))
}

/// `[ω_b; v_b]` of `ν = [v_b; ω_b; …]`.
#[inline(always)]
fn spatial<S: Copy>(nu: &[S], zero: S) -> [S; 6] {
    let at = |k: usize| nu.get(k).copied().unwrap_or(zero);
    [at(3), at(4), at(5), at(0), at(1), at(2)]
}

/// `M(q)`, `(6 + N) × (6 + N)` (`NV = 6 + N`): the joints' block by the composite-rigid-body
/// algorithm ([`crba`]); the base's column of joint `j` is `F_j = I^c_j S_j` and the base's block
/// the composite inertia of the whole system `I^c_0 = I_0 + Σ I^c_root` (RBDA §9.2), both
/// written in the order `[v_b; ω_b]` (force rows first).
#[inline]
pub fn mass_matrix<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; NV]; NV] {
    let zero = S::zero();
    let qj: [S; N] = joints(q, 7, zero);
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut st = [[zero; N]; 6];
    let mut h = [[zero; N]; N];
    transforms(t, &qj, sincos, b.x);
    crba(
        t,
        inertia,
        &mut b,
        st.as_flattened_mut(),
        h.as_flattened_mut(),
    );
    let mut out = [[zero; NV]; NV];
    let mut ic0 = base.inertia;
    for (i, ici) in b.i0.iter().enumerate() {
        if t.parent.get(i).copied().flatten().is_none() {
            for (a, c) in ic0.iter_mut().zip(ici) {
                *a = *a + *c;
            }
        }
        let (Some(s), Some(row)) = (b.s0.get(i), h.get(i)) else {
            continue;
        };
        let f = inertia_mul(ici, s);
        let col = [f[3], f[4], f[5], f[0], f[1], f[2]];
        for (r, x) in col.into_iter().enumerate() {
            out[r][6 + i] = x;
            out[6 + i][r] = x;
        }
        for (j, x) in row.iter().enumerate() {
            out[6 + i][6 + j] = *x;
        }
    }
    // I^c_0 = [Ī h̃; h̃ᵀ m1] in [ω; v] order, written in [v; ω] order: [m1 h̃ᵀ; h̃ Ī].
    let (m, h3) = (ic0[0], [ic0[1], ic0[2], ic0[3]]);
    let ib = [
        [ic0[4], ic0[5], ic0[6]],
        [ic0[5], ic0[7], ic0[8]],
        [ic0[6], ic0[8], ic0[9]],
    ];
    // h̃ (rows of the ω block against v): h̃ v = h × v.
    let ht = [
        [zero, -h3[2], h3[1]],
        [h3[2], zero, -h3[0]],
        [-h3[1], h3[0], zero],
    ];
    for r in 0..3 {
        out[r][r] = m;
        for c in 0..3 {
            out[3 + r][3 + c] = ib[r][c];
            out[3 + r][c] = ht[r][c];
            out[c][3 + r] = ht[r][c];
        }
    }
    out
}

/// Inverse dynamics `[f_b; n_b; τ] = M ν̇ + c` (`NV = 6 + N` entries) by the recursive
/// Newton–Euler algorithm from the base's motion (RBDA §9.5): `v_0 = [ω_b; v_b]`,
/// `a_0 = [ω̇_b; v̇_b − R₀ᵀ g]`, the joints as [`rnea_rooted`], then
/// `f_0 = I_0 a_0 + v_0 ×* I_0 v_0 + Σ_{λ(i) = base} Xup_iᵀ f_i`. `a = None`: `ν̇ = 0` (then the
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
    let qj: [S; N] = joints(q, 7, zero);
    let mut store = BodyStore::<S, N>::new();
    let b = store.bodies();
    transforms(t, &qj, sincos, b.x);
    let v0 = v.map_or([zero; 6], |v| spatial(v, zero));
    let mut a0 = a.map_or([zero; 6], |a| spatial(a, zero));
    if let Some(g) = &base.gravity {
        let gb = gravity_in_base(q, g);
        a0 = [
            a0[0],
            a0[1],
            a0[2],
            a0[3] - gb[0],
            a0[4] - gb[1],
            a0[5] - gb[2],
        ];
    }
    let (qd, qdd): ([S; N], [S; N]) = (
        v.map_or([zero; N], |v| joints(v, 6, zero)),
        a.map_or([zero; N], |a| joints(a, 6, zero)),
    );
    let motions = Motions {
        qd: v.map(|_| &qd[..]),
        qdd: a.map(|_| &qdd[..]),
    };
    let k = &base.inertia;
    let mut f0 = inertia_mul(k, &a0);
    if v.is_some() {
        f0 = add(&f0, &crf(&v0, &inertia_mul(k, &v0)));
    }
    let mut m = [[[zero; 6]; 3]; N];
    let mut tau = [zero; N];
    let root = Root { v: v0, a: a0 };
    rnea_rooted(
        t,
        b.x,
        inertia,
        motions,
        &root,
        &mut m,
        &mut tau,
        Some(&mut f0),
    );
    let mut out = [zero; NV];
    let head = [f0[3], f0[4], f0[5], f0[0], f0[1], f0[2]];
    for (o, x) in out.iter_mut().zip(head.into_iter().chain(tau)) {
        *o = x;
    }
    out
}

/// Forward dynamics `ν̇` (`NV = 6 + N` entries) under the joint drives `tau` and, with `f_ext`,
/// the wrenches `f_ext[0]` on the base and `f_ext[1 + i]` on body `i` (`[force; moment]` in the
/// body's frame at its origin): the articulated-body algorithm with the base as its root
/// ([`aba_floating_on_world`]).
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
    let zero = S::zero();
    let qj: [S; N] = joints(q, 7, zero);
    let qd: [S; N] = joints(v, 6, zero);
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    transforms(t, &qj, sincos, b.x);
    world(t, inertia, &mut b);
    let rates = Rates {
        qd: &qd,
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
    let mut scratch = ArticulatedStore::<S, N>::new();
    let mut ab: Articulated<'_, S> = scratch.articulated();
    let mut out = [zero; NV];
    aba_floating_on_world(t, rates, &root, &b, &mut ab, &mut out);
    out
}
