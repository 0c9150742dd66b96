//! Analytical derivatives of the dynamics as loops over the tables (fixed base): `∂τ/∂q`,
//! `∂τ/∂q̇` of inverse dynamics by J. Carpentier and N. Mansard, "Analytical Derivatives of
//! Rigid Body Dynamics Algorithms", *Robotics: Science and Systems* (RSS) 2018, Algorithm 1
//! (Pinocchio's `computeRNEADerivatives`), and from them those of forward dynamics,
//! `∂q̈/∂x = −M⁻¹ ∂τ/∂x` at `q̈ = FD(q, q̇, τ)` (eq. (3); Pinocchio's `computeABADerivatives`),
//! with `M⁻¹` by LDLᵀ ([`crate::ldlt`]) of the CRBA's `M`.
//!
//! Every spatial quantity is in base coordinates, where the compact kernels already carry the
//! bodies ([`world`]): moving joint `j` turns its whole subtree about `S_j`, so a body's
//! quantity in that subtree varies as `S_j ×` it (eq. (7)) plus what the subtree's velocity and
//! acceleration gain beyond the turn (eqs. (9)–(12)):
//!
//! - forward, joint `j` on parent `λ` (RBDA Table 5.1, `a_0 = −a_grav` = [`Tables::a0`]):
//!   `v_j = v_λ + S_j q̇_j`, `a_j = a_λ + S_j q̈_j + (v_j ×ₘ S_j) q̇_j`, `h_j = I_j v_j`,
//!   `f_j = I_j a_j + v_j ×* h_j`; `∂v/∂q_j = v_λ ×ₘ S_j`,
//!   `∂a/∂q_j = a_λ ×ₘ S_j + v_λ ×ₘ ∂v/∂q_j`, `∂a/∂q̇_j = v_j ×ₘ S_j + ∂v/∂q_j`, and the bias
//!   force's variation with the velocity `B_j δ = δ ×* h_j + v_j ×* I_j δ − I_j (v_j ×ₘ δ)
//!   = δ ×* h_j + İ_j δ`, with the rate `İ_j = v_j ×* I_j − I_j v_j ×ₘ` of the body's inertia
//!   (RBDA eq. (2.73)), of the rigid-body form without mass ([`inertia_rate`]), so `B` is never a
//!   6×6 matrix: `B^C_j δ = δ ×* H_j + İ^C_j δ` and `B^Cᵀ_j S = İ^C_j S − S ×* H_j` with the
//!   composite momentum `H_j = Σ h_k` and `İ^C_j = Σ İ_k` (9 numbers);
//! - backward, subtree composites `Y_j = Σ I_k`, `H_j`, `İ^C_j`, `F_j = Σ f_k`, and
//!   `∂F_j/∂q_j = S_j ×* F_j + Y_j ∂a/∂q_j + B^C_j ∂v/∂q_j`,
//!   `∂F_j/∂q̇_j = Y_j ∂a/∂q̇_j + B^C_j S_j`;
//! - entries (eq. (13)): for `i` in the subtree of `j`,
//!   `∂τ_i/∂q_j = (Y_i S_i)ᵀ ∂a/∂q_j + (B^C_iᵀ S_i)ᵀ ∂v/∂q_j`,
//!   `∂τ_i/∂q̇_j = (Y_i S_i)ᵀ ∂a/∂q̇_j + (B^C_iᵀ S_i)ᵀ S_j`; for `i` a strict ancestor of `j`,
//!   `∂τ_i/∂q_j = S_iᵀ ∂F_j/∂q_j`, `∂τ_i/∂q̇_j = S_iᵀ ∂F_j/∂q̇_j`; zero otherwise.
//!
//! The same equations as `kanegen_dynamics::algorithms::derivatives::rnea` (which the unrolled
//! form traces on the model's local parameters), here over [`Tables`] and slices.

use super::crba::crba;
use super::floating::{gravity_in_base, inverse_dynamics_in, mass_matrix_in, root_motion, Base};
use super::frames::supports;
use super::rnea::{rnea, Motions};
use super::spatial::{add, crf, crm, cross, dot, inertia_mul, scale, sub, transforms, world};
use super::tables::{Bodies, BodyStore, Tables};
use crate::scalar::{Ring, Scalar};

/// One joint's quantities of the passes ([module docs](self)), in base coordinates.
#[derive(Clone, Copy, Debug)]
pub struct Joint<S> {
    v: [S; 6],
    a: [S; 6],
    dvdq: [S; 6],
    dadq: [S; 6],
    dadv: [S; 6],
    /// `Y`: the subtree's composite inertia (the body's own after the forward pass).
    y: [S; 10],
    /// `H`: the subtree's momentum (the body's own `h = I v` after the forward pass).
    hc: [S; 6],
    /// `İ^C`: the subtree's inertia rate, `[ḣ; Ī̇]` ([`inertia_rate`]).
    ic: [S; 9],
    /// `F`: the subtree's force.
    f: [S; 6],
    /// `Y_i S_i`.
    ys: [S; 6],
    /// `B^Cᵀ_i S_i`.
    bs: [S; 6],
}

impl<S: Scalar + Copy> Joint<S> {
    /// Zeroed.
    #[inline(always)]
    #[must_use]
    pub fn zero() -> Self {
        let z = [S::zero(); 6];
        Joint {
            v: z,
            a: z,
            dvdq: z,
            dadq: z,
            dadv: z,
            y: [S::zero(); 10],
            hc: z,
            ic: [S::zero(); 9],
            f: z,
            ys: z,
            bs: z,
        }
    }
}

impl<S: Scalar + Copy> Joint<S> {
    /// `B^C δ = δ ×* H + İ^C δ`.
    #[inline(always)]
    fn bias_variation(&self, d: &[S; 6]) -> [S; 6] {
        add(&crf(d, &self.hc), &rate_mul(&self.ic, d))
    }

    /// `B^Cᵀ s = İ^C s − s ×* H` (`δ ↦ δ ×* H` is skew-symmetric, `İ^C` symmetric).
    #[inline(always)]
    fn bias_variation_transposed(&self, s: &[S; 6]) -> [S; 6] {
        sub(&rate_mul(&self.ic, s), &crf(s, &self.hc))
    }
}

/// The rate `İ = v ×* I − I v ×ₘ` of inertia `i` (`[m, h, Ī]`, [`inertia_mul`]'s layout) moving
/// with `v = [ω; v_O]`: `[ḣ; Ī̇]` with `ḣ = m v_O + ω × h` and the symmetric
/// `Ī̇ = A + Aᵀ + 2 (h·v_O) 1 − v_O hᵀ − h v_Oᵀ`, `A = ω̃ Ī`, stored `xx, xy, xz, yy, yz, zz`.
#[inline(always)]
fn inertia_rate<S: Scalar + Copy>(i: &[S; 10], v: &[S; 6]) -> [S; 9] {
    let (w, vo, h) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]], [i[1], i[2], i[3]]);
    // a[c] = A e_c = ω × (Ī e_c)
    let a = [
        cross(&w, &[i[4], i[5], i[6]]),
        cross(&w, &[i[5], i[7], i[8]]),
        cross(&w, &[i[6], i[8], i[9]]),
    ];
    let hv = h[0] * vo[0] + h[1] * vo[1] + h[2] * vo[2];
    let two_hv = hv + hv;
    let e = |r: usize, c: usize| a[c][r] + a[r][c] - vo[r] * h[c] - h[r] * vo[c];
    let wh = cross(&w, &h);
    [
        i[0] * vo[0] + wh[0],
        i[0] * vo[1] + wh[1],
        i[0] * vo[2] + wh[2],
        e(0, 0) + two_hv,
        e(0, 1),
        e(0, 2),
        e(1, 1) + two_hv,
        e(1, 2),
        e(2, 2) + two_hv,
    ]
}

/// `İ δ = [Ī̇ ω + ḣ × v; −ḣ × ω]` of an [`inertia_rate`].
#[inline(always)]
fn rate_mul<S: Scalar + Copy>(r: &[S; 9], d: &[S; 6]) -> [S; 6] {
    let (w, v, h) = ([d[0], d[1], d[2]], [d[3], d[4], d[5]], [r[0], r[1], r[2]]);
    let hv = cross(&h, &v);
    let hw = cross(&h, &w);
    [
        r[3] * w[0] + r[4] * w[1] + r[5] * w[2] + hv[0],
        r[4] * w[0] + r[6] * w[1] + r[7] * w[2] + hv[1],
        r[5] * w[0] + r[7] * w[1] + r[8] * w[2] + hv[2],
        -hw[0],
        -hw[1],
        -hw[2],
    ]
}

/// `(∂τ/∂q, ∂τ/∂q̇)` of `τ = M(q) q̈ + c(q, q̇)` (gravity as [`Tables::a0`]), `N × N` each, row
/// `i` = `τ_i`, column `j` = `∂/∂q_j`: [`rnea_derivatives_in`] on the bodies of `q`, on stack
/// storage of `N` joints.
#[inline]
pub fn inverse_dynamics_derivatives<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    qdd: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; N]; N], [[S; N]; N]) {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut js = [Joint::zero(); N];
    let mut out = ([[zero; N]; N], [[zero; N]; N]);
    transforms(t, q, sincos, b.x);
    world(t, inertia, &mut b);
    let (dq, dv) = (out.0.as_flattened_mut(), out.1.as_flattened_mut());
    rnea_derivatives_in(t, &b, qd, qdd, &mut js, dq, dv);
    out
}

/// The derivatives into `dq` and `dv` (`N × N`, rows first, zero on entry: only the entries
/// of joints on one path are written) on bodies carried to the base ([`world`]); `js`: scratch
/// of `N` joints ([module docs](self)).
#[inline(always)]
pub fn rnea_derivatives_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    b: &Bodies<'_, S>,
    qd: &[S],
    qdd: &[S],
    js: &mut [Joint<S>],
    dq: &mut [S],
    dv: &mut [S],
) {
    forward(t, b, qd, qdd, ([S::zero(); 6], t.a0), js);
    backward(t, b, js, None, dq, dv);
}

/// A free-floating base as the root of the passes (Carpentier–Mansard on a free-flyer, as
/// Pinocchio): body 0 with six columns, the unit motions of `ν_b = [v_b; ω_b]` (linear first) in
/// base coordinates, on the inertial frame (`v_λ = 0`, `a_λ = −a_grav`).
#[derive(Clone, Copy, Debug)]
pub struct FloatingRoot<S> {
    /// The base body: its motion `v_0 = [ω_b; v_b]`, `a_0 = [ω̇_b; v̇_b] − a_grav`, then its
    /// composites (its own inertia, bias variation and force first).
    pub body: Joint<S>,
    /// `−a_grav = [0; −R₀ᵀ g]`.
    pub a_grav: [S; 6],
}

impl<S: Scalar + Copy> FloatingRoot<S> {
    /// The base of spatial inertia `i` (`[m, h, Ī]`) in motion `(v, a)` (`a` with gravity's
    /// fictitious acceleration `a_grav` in it).
    #[inline(always)]
    #[must_use]
    pub fn new(i: &[S; 10], v: [S; 6], a: [S; 6], a_grav: [S; 6]) -> Self {
        let mut body = Joint::zero();
        (body.f, body.hc, body.ic) = body_terms(i, &v, &a);
        body.y = *i;
        body.v = v;
        body.a = a;
        FloatingRoot { body, a_grav }
    }
}

/// `(∂τ/∂q, ∂τ/∂ν)` of free-floating inverse dynamics into `dq`, `dv` (`(6 + N) × (6 + N)`,
/// rows first, zero on entry; the base's rows and columns first, its `∂/∂q` columns in the
/// tangent space), on bodies carried to the base ([`world`]); `qd`, `qdd`: the joints' rates.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn floating_rnea_derivatives_in<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    b: &Bodies<'_, S>,
    root: &mut FloatingRoot<S>,
    qd: &[S],
    qdd: &[S],
    js: &mut [Joint<S>],
    dq: &mut [S],
    dv: &mut [S],
) {
    forward(t, b, qd, qdd, (root.body.v, root.body.a), js);
    backward(t, b, js, Some(root), dq, dv);
}

/// `f = I a + v ×* h`, the momentum `h = I v` and the inertia rate `İ` ([`inertia_rate`]): what
/// the bias force's variation with the velocity is made of.
#[inline(always)]
fn body_terms<S: Scalar + Copy>(i: &[S; 10], v: &[S; 6], a: &[S; 6]) -> ([S; 6], [S; 6], [S; 9]) {
    let h = inertia_mul(i, v);
    let f = add(&inertia_mul(i, a), &crf(v, &h));
    (f, h, inertia_rate(i, v))
}

/// The unit motion of entry `k` of `[ω; v]`.
#[inline(always)]
fn unit<S: Scalar + Copy>(k: usize) -> [S; 6] {
    core::array::from_fn(|r| if r == k { S::one() } else { S::zero() })
}

/// The forward pass over the joints from the root's motion `(v, a)` ([module docs](self)).
#[inline(always)]
fn forward<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    b: &Bodies<'_, S>,
    qd: &[S],
    qdd: &[S],
    root: ([S; 6], [S; 6]),
    js: &mut [Joint<S>],
) {
    for j in 0..js.len() {
        let (vp, ap) = match t.parent.get(j).copied().flatten().and_then(|l| js.get(l)) {
            Some(p) => (p.v, p.a),
            None => root,
        };
        let (Some(s), Some(i), Some(&qdj), Some(&qddj)) =
            (b.s0.get(j), b.i0.get(j), qd.get(j), qdd.get(j))
        else {
            continue;
        };
        let v = add(&vp, &scale(qdj, s));
        let vs = crm(&v, s);
        let a = add(&add(&ap, &scale(qddj, s)), &scale(qdj, &vs));
        let dvdq = crm(&vp, s);
        let jt = &mut js[j];
        jt.dadq = add(&crm(&ap, s), &crm(&vp, &dvdq));
        jt.dadv = add(&vs, &dvdq);
        jt.dvdq = dvdq;
        (jt.f, jt.hc, jt.ic) = body_terms(i, &v, &a);
        jt.y = *i;
        jt.v = v;
        jt.a = a;
    }
}

/// The backward pass: composites, then each column's entries (eq. (13)); with a floating
/// `root`, its six rows and columns first.
#[inline(always)]
fn backward<S: Scalar + Copy>(
    t: &Tables<'_, S>,
    b: &Bodies<'_, S>,
    js: &mut [Joint<S>],
    mut root: Option<&mut FloatingRoot<S>>,
    dq: &mut [S],
    dv: &mut [S],
) {
    let n = js.len();
    let off = if root.is_some() { 6 } else { 0 };
    let nv = n + off;
    let mut put = |r: usize, c: usize, (x, y): (S, S)| {
        if let (Some(a), Some(b)) = (dq.get_mut(r * nv + c), dv.get_mut(r * nv + c)) {
            *a = x;
            *b = y;
        }
    };
    // The base's column `c` is entry `(c + 3) % 6` of `[ω; v]` (ν_b lists v_b first).
    let base_s = |c: usize| unit::<S>((c + 3) % 6);
    for j in (0..n).rev() {
        let Some(&s) = b.s0.get(j) else {
            continue;
        };
        let jt = js[j];
        js[j].ys = inertia_mul(&jt.y, &s);
        js[j].bs = jt.bias_variation_transposed(&s);
        let dfdq = add(
            &add(&crf(&s, &jt.f), &inertia_mul(&jt.y, &jt.dadq)),
            &jt.bias_variation(&jt.dvdq),
        );
        let dfdv = add(&inertia_mul(&jt.y, &jt.dadv), &jt.bias_variation(&s));
        for (r, jr) in js.iter().enumerate() {
            if supports(t, r, j) {
                // r in the subtree of j (its Y S, B^Cᵀ S are final: r ≥ j).
                put(
                    off + r,
                    off + j,
                    (
                        dot(&jr.ys, &jt.dadq) + dot(&jr.bs, &jt.dvdq),
                        dot(&jr.ys, &jt.dadv) + dot(&jr.bs, &s),
                    ),
                );
            } else if supports(t, j, r) {
                let sr = b.s0.get(r).copied().unwrap_or([S::zero(); 6]);
                put(off + r, off + j, (dot(&dfdq, &sr), dot(&dfdv, &sr)));
            }
        }
        if root.is_some() {
            // The base is an ancestor of every joint.
            for r in 0..6 {
                let sr = base_s(r);
                put(r, off + j, (dot(&dfdq, &sr), dot(&dfdv, &sr)));
            }
        }
        // Y_λ += Y_j, H_λ += H_j, İ^C_λ += İ^C_j, F_λ += F_j (the base's on a free-floating root).
        let parent = match t.parent.get(j).copied().flatten() {
            Some(l) => js.get_mut(l),
            None => root.as_deref_mut().map(|r| &mut r.body),
        };
        if let Some(p) = parent {
            for (a, x) in p.y.iter_mut().zip(jt.y) {
                *a = *a + x;
            }
            p.hc = add(&p.hc, &jt.hc);
            for (a, x) in p.ic.iter_mut().zip(jt.ic) {
                *a = *a + x;
            }
            p.f = add(&p.f, &jt.f);
        }
    }
    let Some(root) = root else {
        return;
    };
    // The base's columns: every body is in its subtree (∂v/∂q = 0 for them).
    let base = &root.body;
    let us: [([S; 6], [S; 6]); 6] = core::array::from_fn(|r| {
        let sr = base_s(r);
        (
            inertia_mul(&base.y, &sr),
            base.bias_variation_transposed(&sr),
        )
    });
    for c in 0..6 {
        let sc = base_s(c);
        let dadq = crm(&root.a_grav, &sc);
        let dadv = crm(&base.v, &sc);
        for (r, (ys, bs)) in us.iter().enumerate() {
            put(r, c, (dot(ys, &dadq), dot(ys, &dadv) + dot(bs, &sc)));
        }
        for (r, jr) in js.iter().enumerate() {
            put(
                off + r,
                c,
                (dot(&jr.ys, &dadq), dot(&jr.ys, &dadv) + dot(&jr.bs, &sc)),
            );
        }
    }
}

/// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)`, `N × N` each, rows first.
pub type ForwardDerivatives<S, const N: usize> = ([[S; N]; N], [[S; N]; N], [[S; N]; N]);

/// `M⁻¹` into `out` (`n × n`, rows first) from `M` in `m` (overwritten; `d_inv`: scratch of
/// `n`): `M = L D Lᵀ` ([`crate::ldlt`]), `W = L⁻¹` in place of `L` (unit lower triangular, row by
/// row: `W_ij = −(L_ij + Σ_{j<k<i} L_ik W_kj)`), then `M⁻¹ = Wᵀ D⁻¹ W`, whose entry `(i, j)`,
/// `i ≤ j`, is `Σ_{k ≥ j} W_ki W_kj / D_k` (`W_kk = 1`), mirrored. About `2N³/3` multiplications
/// against `7N³/6` for one solve per unit column.
#[inline(always)]
pub fn inverse_in<S: Scalar + Copy>(m: &mut [S], n: usize, d_inv: &mut [S], out: &mut [S]) {
    if crate::ldlt::factor_in_place(m, n, d_inv).is_err() || out.len() < n * n {
        return;
    }
    for i in 1..n {
        for j in 0..i {
            let mut acc = m[i * n + j];
            for k in j + 1..i {
                acc = acc + m[i * n + k] * m[k * n + j];
            }
            m[i * n + j] = -acc;
        }
    }
    for i in 0..n {
        for j in i..n {
            // k = j: W_jj = 1.
            let mut acc = if i == j {
                d_inv[j]
            } else {
                m[j * n + i] * d_inv[j]
            };
            for k in j + 1..n {
                acc = acc + m[k * n + i] * m[k * n + j] * d_inv[k];
            }
            out[i * n + j] = acc;
            out[j * n + i] = acc;
        }
    }
}

/// `out = −A B` of `n × n` matrices (rows first), row by row as `−Σ_k A_rk B_k·` so that the
/// inner loop runs along rows of `B` and `out` (contiguous: the compiler vectorizes it).
#[inline(always)]
pub fn neg_product<S: Ring>(a: &[S], b: &[S], n: usize, out: &mut [S]) {
    let n = n.max(1);
    for (orow, arow) in out.chunks_exact_mut(n).zip(a.chunks_exact(n)) {
        orow.fill(Ring::zero());
        for (&x, brow) in arow.iter().zip(b.chunks_exact(n)) {
            for (o, &y) in orow.iter_mut().zip(brow) {
                *o = *o - x * y;
            }
        }
    }
}

/// `M(q)⁻¹`, `N × N`: the CRBA's `M` ([`crba`]) inverted by LDLᵀ ([`inverse_in`]).
#[inline]
pub fn mass_matrix_inverse<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; N]; N] {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let (mut st, mut h, mut d_inv) = ([[zero; N]; 6], [[zero; N]; N], [zero; N]);
    let mut out = [[zero; N]; N];
    transforms(t, q, sincos, b.x);
    let h = h.as_flattened_mut();
    crba(t, inertia, &mut b, st.as_flattened_mut(), h);
    inverse_in(h, N, &mut d_inv, out.as_flattened_mut());
    out
}

/// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` of `q̈ = M⁻¹ (τ − c)` (gravity as [`Tables::a0`]), `N × N` each: `M⁻¹`
/// ([`mass_matrix_inverse`]'s steps), `c` by the RNEA ([`rnea`]), `q̈`, then
/// `∂q̈/∂x = −M⁻¹ ∂τ/∂x` with `∂τ/∂x` of [`rnea_derivatives_in`] at `q̈` (eq. (3)).
#[inline]
pub fn forward_dynamics_derivatives<S: Scalar + Copy, const N: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    q: &[S; N],
    qd: &[S; N],
    tau: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> ForwardDerivatives<S, N> {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut js = [Joint::zero(); N];
    let (mut st, mut h, mut d_inv) = ([[zero; N]; 6], [[zero; N]; N], [zero; N]);
    let (mut m, mut c, mut qdd) = ([[[zero; 6]; 3]; N], [zero; N], [zero; N]);
    let (mut dtq, mut dtv) = ([[zero; N]; N], [[zero; N]; N]);
    let mut out = ([[zero; N]; N], [[zero; N]; N], [[zero; N]; N]);
    transforms(t, q, sincos, b.x);
    rnea(t, b.x, inertia, Motions::velocity(qd), &mut m, &mut c);
    let h = h.as_flattened_mut();
    crba(t, inertia, &mut b, st.as_flattened_mut(), h);
    let minv = out.2.as_flattened_mut();
    inverse_in(h, N, &mut d_inv, minv);
    accelerations(minv, tau, &c, &mut qdd);
    world(t, inertia, &mut b);
    let (dtq, dtv) = (dtq.as_flattened_mut(), dtv.as_flattened_mut());
    rnea_derivatives_in(t, &b, qd, &qdd, &mut js, dtq, dtv);
    neg_product(minv, dtq, N, out.0.as_flattened_mut());
    neg_product(minv, dtv, N, out.1.as_flattened_mut());
    out
}

/// `q̈ = M⁻¹ (τ − c)` into `qdd`.
#[inline(always)]
pub fn accelerations<S: Ring>(minv: &[S], tau: &[S], c: &[S], qdd: &mut [S]) {
    let n = qdd.len();
    for (r, x) in qdd.iter_mut().enumerate() {
        let mut acc = <S as Ring>::zero();
        for (k, (t, c)) in tau.iter().zip(c).enumerate() {
            if let Some(&m) = minv.get(r * n + k) {
                acc = acc + m * (*t - *c);
            }
        }
        *x = acc;
    }
}

/// `(∂τ/∂q, ∂τ/∂ν)` of free-floating inverse dynamics `[f_b; n_b; τ] = M ν̇ + c`
/// ([`super::floating::inverse_dynamics`]'s layouts), `NV × NV` each (`NV = 6 + N`), the base's
/// `∂/∂q` columns in the tangent space (`q` moved by Pinocchio's `integrate(q, δν)`):
/// [`floating_rnea_derivatives_in`] on the bodies of `q`, on stack storage of `N` joints.
#[inline]
pub fn floating_inverse_dynamics_derivatives<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    a: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> ([[S; NV]; NV], [[S; NV]; NV]) {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut js = [Joint::zero(); N];
    let mut out = ([[zero; NV]; NV], [[zero; NV]; NV]);
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    world(t, inertia, &mut b);
    let mut root = floating_root(base, q, v, a);
    let (dq, dv) = (out.0.as_flattened_mut(), out.1.as_flattened_mut());
    let (qd, qdd) = (v.get(6..).unwrap_or(&[]), a.get(6..).unwrap_or(&[]));
    floating_rnea_derivatives_in(t, &b, &mut root, qd, qdd, &mut js, dq, dv);
    out
}

/// The base as the root of the derivatives' passes at `(q, ν, ν̇)`, gravity from `base`.
#[inline(always)]
pub fn floating_root<S: Scalar + Copy>(
    base: &Base<S>,
    q: &[S],
    v: &[S],
    a: &[S],
) -> FloatingRoot<S> {
    let root = root_motion(base, q, Some(v), Some(a));
    let mut a_grav = [S::zero(); 6];
    if let Some(g) = &base.gravity {
        let gb = gravity_in_base(q, g);
        a_grav = [S::zero(), S::zero(), S::zero(), -gb[0], -gb[1], -gb[2]];
    }
    FloatingRoot::new(&base.inertia, root.v, root.a, a_grav)
}

/// `M(q)⁻¹` on a free-floating base, `NV × NV`: [`super::floating::mass_matrix_in`] inverted by
/// LDLᵀ ([`inverse_in`]).
#[inline]
pub fn floating_mass_matrix_inverse<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    sincos: impl Fn(S) -> (S, S),
) -> [[S; NV]; NV] {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let (mut st, mut h, mut m) = ([[zero; N]; 6], [[zero; N]; N], [[zero; NV]; NV]);
    let (mut d_inv, mut out) = ([zero; NV], [[zero; NV]; NV]);
    transforms(t, q.get(7..).unwrap_or(&[]), sincos, b.x);
    let m = m.as_flattened_mut();
    let (st, h) = (st.as_flattened_mut(), h.as_flattened_mut());
    mass_matrix_in(t, inertia, base, &mut b, st, h, m);
    inverse_in(m, NV, &mut d_inv, out.as_flattened_mut());
    out
}

/// `(∂ν̇/∂q, ∂ν̇/∂ν, M⁻¹)` of free-floating forward dynamics `ν̇ = M⁻¹ ([0; τ] − c)` (the base
/// not actuated; [`super::floating::forward_dynamics`]'s layouts), `NV × NV` each: `c` by
/// [`inverse_dynamics_in`], `M⁻¹` as [`floating_mass_matrix_inverse`], `ν̇`, then
/// `∂ν̇/∂x = −M⁻¹ ∂τ/∂x` with `∂τ/∂x` of [`floating_rnea_derivatives_in`] at `ν̇`.
#[inline]
pub fn floating_forward_dynamics_derivatives<S: Scalar + Copy, const N: usize, const NV: usize>(
    t: &Tables<'_, S>,
    inertia: &[[S; 10]],
    base: &Base<S>,
    q: &[S],
    v: &[S],
    tau: &[S; N],
    sincos: impl Fn(S) -> (S, S),
) -> ForwardDerivatives<S, NV> {
    let zero = S::zero();
    let mut store = BodyStore::<S, N>::new();
    let mut b = store.bodies();
    let mut js = [Joint::zero(); N];
    let (mut st, mut h, mut m) = ([[zero; N]; 6], [[zero; N]; N], [[zero; NV]; NV]);
    let (mut d_inv, mut mm, mut c) = ([zero; NV], [[[zero; 6]; 3]; N], [zero; NV]);
    let (mut drives, mut nu_dot) = ([zero; NV], [zero; NV]);
    let (mut dtq, mut dtv) = ([[zero; NV]; NV], [[zero; NV]; NV]);
    let mut out = ([[zero; NV]; NV], [[zero; NV]; NV], [[zero; NV]; NV]);
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
        &mut mm,
        &mut c,
    );
    let m = m.as_flattened_mut();
    let (st, h) = (st.as_flattened_mut(), h.as_flattened_mut());
    mass_matrix_in(t, inertia, base, &mut b, st, h, m);
    let minv = out.2.as_flattened_mut();
    inverse_in(m, NV, &mut d_inv, minv);
    for (d, x) in drives.iter_mut().skip(6).zip(tau) {
        *d = *x;
    }
    accelerations(minv, &drives, &c, &mut nu_dot);
    world(t, inertia, &mut b);
    let mut root = floating_root(base, q, v, &nu_dot);
    let (dtq, dtv) = (dtq.as_flattened_mut(), dtv.as_flattened_mut());
    let qd = v.get(6..).unwrap_or(&[]);
    floating_rnea_derivatives_in(t, &b, &mut root, qd, &nu_dot[6..], &mut js, dtq, dtv);
    neg_product(minv, dtq, NV, out.0.as_flattened_mut());
    neg_product(minv, dtv, NV, out.1.as_flattened_mut());
    out
}
