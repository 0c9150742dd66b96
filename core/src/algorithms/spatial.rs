//! Featherstone's spatial-vector algorithms in local body coordinates — an independent
//! cross-check of the paper's base-frame algorithms (it does not use `kinematics.rs`).
//!
//! Solves `tau = H(q) q̈ + C(q, q̇, f_ext)` (R. Featherstone, *Rigid Body Dynamics Algorithms*,
//! Springer 2008, "RBDA") and returns kanegen's `A = H` and `b = Q − C`, where `Q` is the joint
//! drives `loads.tau`; gravity and the external wrenches are inside `C`, so the generalized
//! external forces enter `b` with a plus sign (paper eq. (8), (10): `b = Q − h`).
//!
//! - [`mass_matrix`]: the composite-rigid-body algorithm, RBDA Table 6.2 (spatial_v2 `HandC`, the
//!   `H` part): composite inertias `IC` in a backward loop, then `H_ij = S_iᵀ F` with `F = IC_i S_i`
//!   carried to the ancestors by `Xupᵀ`.
//! - [`bias`]: the recursive Newton–Euler algorithm, RBDA Table 5.1 (spatial_v2 `ID` / the `C` part
//!   of `HandC`) with `q̈ = 0`: `avp_i = Xup_i avp_{λ} + v_i ×ₘ vJ_i`,
//!   `fvp_i = I_i avp_i + v_i ×* I_i v_i − f^x_i`, `C_i = S_iᵀ fvp_i`, `fvp_λ += Xup_iᵀ fvp_i`.
//!   Gravity is the fictitious base acceleration `a_0 = −a_grav = [0; −g]` (RBDA §5.3).
//!
//! Conventions (RBDA ch. 2): motion vectors `[ω; v]` with `v` the velocity of the body-frame
//! origin; force vectors `[n; f]` with `n` the moment about the origin; the Plücker transform from
//! frame A to frame B is `X = [E 0; −E r̃ E]` (RBDA eq. (2.24)), `E` the rotation from A to B
//! coordinates and `r` the position of B's origin in A coordinates, stored as the pair `(E, r)`
//! (RBDA §2.8, Table 2.5). A rigid-body inertia is stored as `(m, h = m c, Ī)`, `Ī` about the
//! frame origin (RBDA eq. (2.62)–(2.63), spatial_v2 `mcI`).
//!
//! Joint `j` (URDF convention): `Xtree_j` places the joint frame in the parent (`E = Υᵀ`,
//! `r = l`); `XJ_j` is the joint motion (revolute: `E = Θ(q)ᵀ`, `r = 0`; prismatic: `E = 1`,
//! `r = q·axis`); `Xup_j = XJ_j Xtree_j`; the motion subspace is `S_j = [axis; 0]` (revolute) or
//! `[0; axis]` (prismatic), the axis having the same coordinates in the joint and child frames.
//! Each revolute `q_j` costs one `sin_cos` per call.
//!
//! ```
//! use kanegen_core::algorithms::{spatial, Loads};
//! use kanegen_core::random::{random_chain, ChainSpec};
//! let chain = random_chain(&ChainSpec { n: 3, ..Default::default() }, 1);
//! let p = chain.params::<f64>();
//! let q = [0.1, -0.4, 0.9];
//! let h = spatial::mass_matrix(&p, &q);
//! assert!((h[0][2] - h[2][0]).abs() < 1e-12 && h[1][1] > 0.0);
//! // At rest, without gravity or loads, b = 0.
//! let b = spatial::bias(&p, &q, &[0.0; 3], &Loads::default());
//! assert!(b.iter().all(|x| x.abs() < 1e-12));
//! ```

use crate::algorithms::{LoadFrame, Loads};
use crate::linalg::{axis_rotation, Mat3, Vec3};
use crate::model::{ChainParams, JointKind, JointParams};
use crate::scalar::Scalar;

/// A spatial motion vector `[ω; v]` (RBDA §2.2).
#[derive(Clone, Debug)]
struct Motion<S> {
    ang: Vec3<S>,
    lin: Vec3<S>,
}

/// A spatial force vector `[n; f]`, `n` about the frame origin (RBDA §2.3).
#[derive(Clone, Debug)]
struct Force<S> {
    ang: Vec3<S>,
    lin: Vec3<S>,
}

impl<S: Scalar> Motion<S> {
    fn zero() -> Self {
        Motion {
            ang: Vec3::zero(),
            lin: Vec3::zero(),
        }
    }
    /// `self ×ₘ m = [ω × ω₂; ω × v₂ + v × ω₂]` (RBDA eq. (2.31), spatial_v2 `crm`).
    fn crm(&self, m: &Motion<S>) -> Motion<S> {
        Motion {
            ang: self.ang.cross(&m.ang),
            lin: self.ang.cross(&m.lin) + self.lin.cross(&m.ang),
        }
    }
    /// `self ×* f = [ω × n + v × f; ω × f]` (RBDA eq. (2.32), spatial_v2 `crf`).
    fn crf(&self, f: &Force<S>) -> Force<S> {
        Force {
            ang: self.ang.cross(&f.ang) + self.lin.cross(&f.lin),
            lin: self.ang.cross(&f.lin),
        }
    }
}

impl<S: Scalar> core::ops::Add for Motion<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Motion {
            ang: self.ang + o.ang,
            lin: self.lin + o.lin,
        }
    }
}

impl<S: Scalar> core::ops::Add for Force<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Force {
            ang: self.ang + o.ang,
            lin: self.lin + o.lin,
        }
    }
}

impl<S: Scalar> core::ops::Sub for Force<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Force {
            ang: self.ang - o.ang,
            lin: self.lin - o.lin,
        }
    }
}

/// A Plücker transform `(E, r)` from frame A to frame B (RBDA §2.8, Table 2.5).
#[derive(Clone, Debug)]
struct Xform<S> {
    e: Mat3<S>,
    r: Vec3<S>,
}

impl<S: Scalar> Xform<S> {
    /// `X m = [E ω; E (v − r × ω)]`.
    fn apply(&self, m: &Motion<S>) -> Motion<S> {
        Motion {
            ang: self.e.mul_vec(&m.ang),
            lin: self.e.mul_vec(&(&m.lin - &self.r.cross(&m.ang))),
        }
    }
    /// `Xᵀ f = [Eᵀ n + r × Eᵀ f; Eᵀ f]`: a force from frame B coordinates back to frame A
    /// (`ᴬX_B* = Xᵀ`, spatial_v2's `Xup' * f`).
    fn tr_apply(&self, f: &Force<S>) -> Force<S> {
        let lin = self.e.tr_mul_vec(&f.lin);
        Force {
            ang: self.e.tr_mul_vec(&f.ang) + self.r.cross(&lin),
            lin,
        }
    }
    /// `Xᵀ I X`: a rigid-body inertia from frame B coordinates to frame A coordinates
    /// (RBDA Table 2.5): `(m, Eᵀh + m r, EᵀĪE − r̃ (Eᵀh)~ − (Eᵀh + m r)~ r̃)`.
    fn tr_inertia(&self, i: &RbInertia<S>) -> RbInertia<S> {
        let h_rot = self.e.tr_mul_vec(&i.h);
        let h = &h_rot + &self.r.scale(&i.m);
        let rt = Mat3::skew(&self.r);
        let ibar = self.e.transpose().congruence(&i.ibar)
            - rt.mul_mat(&Mat3::skew(&h_rot))
            - Mat3::skew(&h).mul_mat(&rt);
        RbInertia {
            m: i.m.clone(),
            h,
            ibar,
        }
    }
}

/// A rigid-body spatial inertia about the frame origin: mass `m`, first moment `h = m c` and
/// rotational inertia `Ī` about the origin (RBDA eq. (2.63)).
#[derive(Clone, Debug)]
struct RbInertia<S> {
    m: S,
    h: Vec3<S>,
    ibar: Mat3<S>,
}

impl<S: Scalar> RbInertia<S> {
    /// spatial_v2 `mcI(m, c, I_c)`: `h = m c`, `Ī = I_c + m c̃ c̃ᵀ` (parallel axes).
    fn mci(jp: &JointParams<S>) -> Self {
        let ct = Mat3::skew(&jp.com);
        RbInertia {
            m: jp.mass.clone(),
            h: jp.com.scale(&jp.mass),
            ibar: jp.inertia_com.clone() + ct.mul_mat(&ct.transpose()).scale(&jp.mass),
        }
    }
    /// `I [ω; v] = [Ī ω + h × v; m v − h × ω]`.
    fn mul(&self, v: &Motion<S>) -> Force<S> {
        Force {
            ang: self.ibar.mul_vec(&v.ang) + self.h.cross(&v.lin),
            lin: v.lin.scale(&self.m) - self.h.cross(&v.ang),
        }
    }
    fn add(self, o: Self) -> Self {
        RbInertia {
            m: self.m + o.m,
            h: self.h + o.h,
            ibar: self.ibar + o.ibar,
        }
    }
}

/// `Xup_j = XJ(q_j) Xtree_j` (RBDA §4.4; spatial_v2 `jcalc` and `Xtree`).
fn xup<S: Scalar>(jp: &JointParams<S>, q: &S) -> Xform<S> {
    match jp.kind {
        JointKind::Revolute => {
            let (s, c) = q.clone().sin_cos();
            // E = Θᵀ Υᵀ = (Υ Θ)ᵀ, r = l.
            let e = jp
                .upsilon
                .mul_mat(&axis_rotation(&jp.axis, &s, &c))
                .transpose();
            Xform { e, r: jp.l.clone() }
        }
        // E = Υᵀ, r = l + Υ (q axis).
        JointKind::Prismatic => Xform {
            e: jp.upsilon.transpose(),
            r: &jp.l + &jp.upsilon.mul_vec(&jp.axis.scale(q)),
        },
    }
}

/// `S_j q̇_j` (spatial_v2 `vJ`).
fn s_times<S: Scalar>(jp: &JointParams<S>, x: &S) -> Motion<S> {
    let ax = jp.axis.scale(x);
    match jp.kind {
        JointKind::Revolute => Motion {
            ang: ax,
            lin: Vec3::zero(),
        },
        JointKind::Prismatic => Motion {
            ang: Vec3::zero(),
            lin: ax,
        },
    }
}

/// `S_jᵀ f`: the axis component of the moment (revolute) or of the force (prismatic).
fn s_tr<S: Scalar>(jp: &JointParams<S>, f: &Force<S>) -> S {
    match jp.kind {
        JointKind::Revolute => jp.axis.dot(&f.ang),
        JointKind::Prismatic => jp.axis.dot(&f.lin),
    }
}

/// `I S_j` for a rigid-body inertia (only the non-zero half of `S_j` is multiplied).
fn inertia_s<S: Scalar>(ic: &RbInertia<S>, jp: &JointParams<S>) -> Force<S> {
    let a = &jp.axis;
    match jp.kind {
        // I [a; 0] = [Ī a; −h × a]
        JointKind::Revolute => Force {
            ang: ic.ibar.mul_vec(a),
            lin: -ic.h.cross(a),
        },
        // I [0; a] = [h × a; m a]
        JointKind::Prismatic => Force {
            ang: ic.h.cross(a),
            lin: a.scale(&ic.m),
        },
    }
}

/// The joint-space inertia matrix `H(q)` (= the paper's `A(q)`), full and symmetric, by the
/// composite-rigid-body algorithm (RBDA Table 6.2).
///
/// `p`: the chain's parameters; `q`: joint positions (rad or m), length `N`. Returns `H` as `N`
/// rows of `N` entries; the upper triangle is computed and mirrored. Section `"spatial:crba"`.
pub fn mass_matrix<S: Scalar>(p: &ChainParams<S>, q: &[S]) -> Vec<Vec<S>> {
    let n = p.dof();
    assert_eq!(q.len(), n, "q has the wrong length");
    S::section("spatial:crba");
    let xup: Vec<Xform<S>> = p.joints.iter().zip(q).map(|(jp, qj)| xup(jp, qj)).collect();
    // IC_i = I_i; backward loop: IC_λ(i) += Xup_iᵀ IC_i Xup_i.
    let mut ic: Vec<RbInertia<S>> = p.joints.iter().map(RbInertia::mci).collect();
    for i in (1..n).rev() {
        let carried = xup[i].tr_inertia(&ic[i]);
        let parent = ic[i - 1].clone();
        ic[i - 1] = parent.add(carried);
    }
    // Fill loop: F = IC_i S_i, H_ii = S_iᵀ F; up the chain F = Xup_jᵀ F, H_ij = S_jᵀ F.
    let mut h = vec![vec![S::zero(); n]; n];
    for i in 0..n {
        let mut f = inertia_s(&ic[i], &p.joints[i]);
        h[i][i] = s_tr(&p.joints[i], &f);
        let mut j = i;
        while j > 0 {
            f = xup[j].tr_apply(&f);
            j -= 1;
            let hij = s_tr(&p.joints[j], &f);
            h[j][i] = hij.clone();
            h[i][j] = hij;
        }
    }
    h
}

/// The generalized forces `b = Q − C(q, q̇, f_ext)` by the recursive Newton–Euler algorithm with
/// `q̈ = 0` (RBDA Table 5.1).
///
/// `p`: the chain's parameters; `q`, `q̇`: joint positions and velocities, length `N`; `loads`:
/// joint drives `Q = loads.tau` (added when present), gravity `g` in the base frame (entered as the
/// base acceleration `a_0 = [0; −g]`), and external wrenches (force at `O_j`, moment about `O_j`;
/// base-frame ones are rotated into body coordinates with the body's orientation), which enter
/// `C` as `−f^x_j`. Section `"spatial:rnea"`.
pub fn bias<S: Scalar>(p: &ChainParams<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
    let n = p.dof();
    assert_eq!(q.len(), n, "q has the wrong length");
    assert_eq!(qd.len(), n, "qd has the wrong length");
    if let Some(tau) = &loads.tau {
        assert_eq!(tau.len(), n, "loads.tau has the wrong length");
    }
    assert!(
        loads.external.iter().all(|e| e.body < n),
        "an external wrench names a body past the end of the chain"
    );
    S::section("spatial:rnea");
    let need_rot = loads.external.iter().any(|e| e.frame == LoadFrame::Base);
    // a_0 = −a_grav.
    let mut a_prev = match &loads.gravity {
        Some(g) => Motion {
            ang: Vec3::zero(),
            lin: -g.clone(),
        },
        None => Motion::zero(),
    };
    let mut v_prev = Motion::zero();
    // E_0j: rotation from base to body-j coordinates (only when a base-frame wrench needs it).
    let mut e0_prev = Mat3::identity();
    let mut xups = Vec::with_capacity(n);
    let mut fvp: Vec<Force<S>> = Vec::with_capacity(n);
    // Forward loop.
    for (j, (jp, (qj, qdj))) in p.joints.iter().zip(q.iter().zip(qd)).enumerate() {
        let x = xup(jp, qj);
        let vj = s_times(jp, qdj);
        // v_j = Xup_j v_λ + vJ
        let v = x.apply(&v_prev) + vj.clone();
        // avp_j = Xup_j avp_λ + v_j ×ₘ vJ   (q̈ = 0, cJ = 0)
        let avp = x.apply(&a_prev) + v.crm(&vj);
        // fvp_j = I_j avp_j + v_j ×* I_j v_j − f^x_j
        let inertia = RbInertia::mci(jp);
        let mut f = inertia.mul(&avp) + v.crf(&inertia.mul(&v));
        if need_rot {
            e0_prev = x.e.mul_mat(&e0_prev);
        }
        for ext in loads.external.iter().filter(|e| e.body == j) {
            let fx = match ext.frame {
                LoadFrame::Body => Force {
                    ang: ext.moment.clone(),
                    lin: ext.force.clone(),
                },
                LoadFrame::Base => Force {
                    ang: e0_prev.mul_vec(&ext.moment),
                    lin: e0_prev.mul_vec(&ext.force),
                },
            };
            f = f - fx;
        }
        fvp.push(f);
        v_prev = v;
        a_prev = avp;
        xups.push(x);
    }
    // Backward loop: C_j = S_jᵀ fvp_j; fvp_λ += Xup_jᵀ fvp_j; b_j = τ_j − C_j.
    let mut b = vec![S::zero(); n];
    for j in (0..n).rev() {
        let c = s_tr(&p.joints[j], &fvp[j]);
        b[j] = match &loads.tau {
            Some(tau) => tau[j].clone() - c,
            None => -c,
        };
        if j > 0 {
            let carried = xups[j].tr_apply(&fvp[j]);
            let parent = fvp[j - 1].clone();
            fvp[j - 1] = parent + carried;
        }
    }
    b
}

/// Featherstone's floating-base dynamics (RBDA §9.3, Table 9.6 / spatial_v2 `HandC` with a
/// floating base), an implementation independent of the virtual-joint extension of
/// [`crate::algorithms::floating`], with that module's conventions.
///
/// The base is body 0 with a 6-dof joint whose motion subspace is `1₆` in base coordinates: its
/// spatial velocity in base coordinates is `[ω_b; v_b]` and, as `v × v = 0`, its spatial
/// acceleration in base coordinates is the derivative of those components, `[ω̇_b; v̇_b]` — so
/// the base speeds of `ν = [v_b; ω_b; q̇]` are the base joint's speeds reordered.
///
/// - `A`: composite inertias `IC_j` of the arm (RBDA Table 6.2); the base block is the composite
///   inertia of the whole tree `IC_0 = I_base + Xup_0ᵀ IC_arm,0 Xup_0` applied to unit motions;
///   the arm columns `F = IC_i S_i` are carried down to the base, `A_bi = F` (rows `[f; n]`).
/// - `b`: RNEA with `ν̇ = 0`: base `v_0 = [ω_b; v_b]`, `a_0 = [0; −R₀ᵀ g]` (gravity as a
///   fictitious base acceleration, RBDA §5.3), `fvp_0 = I_0 a_0 + v_0 ×* I_0 v_0 − f^x_0`, the arm
///   as in [`bias`], `fvp_0 += Xup_0ᵀ fvp_arm,0`; then `b_base = −[fvp_0.f; fvp_0.n]`,
///   `b_arm,j = τ_j − S_jᵀ fvp_j`. Inertial-frame wrenches are rotated into body coordinates
///   with `E_{0j} R₀ᵀ`. Section `"spatial:floating"`.
pub fn floating_dynamics<S: Scalar>(
    p: &ChainParams<S>,
    base: &crate::algorithms::floating::FloatingBase<S>,
    state: &crate::algorithms::floating::FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
) -> crate::algorithms::Dynamics<S> {
    use crate::algorithms::floating::BASE_BODY;
    let n = p.dof();
    assert_eq!(q.len(), n, "q has the wrong length");
    assert_eq!(qd.len(), n, "qd has the wrong length");
    if let Some(tau) = &loads.tau {
        assert_eq!(tau.len(), n, "loads.tau has the wrong length");
    }
    assert!(
        loads
            .external
            .iter()
            .all(|e| e.body < n || e.body == BASE_BODY),
        "an external wrench names a body past the end of the chain"
    );
    S::section("spatial:floating");
    let nb = 6;
    let xup: Vec<Xform<S>> = p.joints.iter().zip(q).map(|(jp, qj)| xup(jp, qj)).collect();
    let ct = Mat3::skew(&base.com);
    let i_base = RbInertia {
        m: base.mass.clone(),
        h: base.com.scale(&base.mass),
        ibar: base.inertia_com.clone() + ct.mul_mat(&ct.transpose()).scale(&base.mass),
    };

    // ---- A ----
    let mut ic: Vec<RbInertia<S>> = p.joints.iter().map(RbInertia::mci).collect();
    for i in (1..n).rev() {
        let carried = xup[i].tr_inertia(&ic[i]);
        let parent = ic[i - 1].clone();
        ic[i - 1] = parent.add(carried);
    }
    let ic0 = if n > 0 {
        i_base.clone().add(xup[0].tr_inertia(&ic[0]))
    } else {
        i_base.clone()
    };
    let mut a = vec![vec![S::zero(); nb + n]; nb + n];
    // Base block: column m of ν_b is the unit motion [0; e_m] (m < 3) or [e_{m−3}; 0].
    let unit = |m: usize| {
        let mut e = Vec3::zero();
        e.0[m % 3] = S::one();
        if m < 3 {
            Motion {
                ang: Vec3::zero(),
                lin: e,
            }
        } else {
            Motion {
                ang: e,
                lin: Vec3::zero(),
            }
        }
    };
    let rows = |f: &Force<S>| -> [S; 6] {
        [
            f.lin.at(0),
            f.lin.at(1),
            f.lin.at(2),
            f.ang.at(0),
            f.ang.at(1),
            f.ang.at(2),
        ]
    };
    #[allow(clippy::needless_range_loop)] // a[i][m] and a[m][i] are both written
    for m in 0..nb {
        let col = rows(&ic0.mul(&unit(m)));
        // Upper triangle, mirrored (IC_0 is symmetric; mirroring makes A exactly so).
        for (i, x) in col.into_iter().enumerate().take(m + 1) {
            a[m][i] = x.clone();
            a[i][m] = x;
        }
    }
    for i in 0..n {
        let mut f = inertia_s(&ic[i], &p.joints[i]);
        a[nb + i][nb + i] = s_tr(&p.joints[i], &f);
        let mut j = i;
        loop {
            f = xup[j].tr_apply(&f);
            if j == 0 {
                break;
            }
            j -= 1;
            let hij = s_tr(&p.joints[j], &f);
            a[nb + j][nb + i] = hij.clone();
            a[nb + i][nb + j] = hij;
        }
        for (r, x) in rows(&f).into_iter().enumerate() {
            a[r][nb + i] = x.clone();
            a[nb + i][r] = x;
        }
    }

    // ---- b ----
    let r0t = state.rotation.transpose();
    let v0 = Motion {
        ang: state.omega_b.clone(),
        lin: state.v_b.clone(),
    };
    let a0 = match &loads.gravity {
        Some(g) => Motion {
            ang: Vec3::zero(),
            lin: -r0t.mul_vec(g),
        },
        None => Motion::zero(),
    };
    let ext_force = |body: usize, e0: &Mat3<S>| {
        let mut f: Option<Force<S>> = None;
        for ext in loads.external.iter().filter(|e| e.body == body) {
            let fx = match ext.frame {
                LoadFrame::Body => Force {
                    ang: ext.moment.clone(),
                    lin: ext.force.clone(),
                },
                LoadFrame::Base => Force {
                    ang: e0.mul_vec(&ext.moment),
                    lin: e0.mul_vec(&ext.force),
                },
            };
            f = Some(match f {
                None => fx,
                Some(acc) => acc + fx,
            });
        }
        f
    };
    let mut f0 = i_base.mul(&a0) + v0.crf(&i_base.mul(&v0));
    if let Some(fx) = ext_force(BASE_BODY, &r0t) {
        f0 = f0 - fx;
    }
    let mut v_prev = v0;
    let mut a_prev = a0;
    let mut e0_prev = r0t;
    let mut fvp: Vec<Force<S>> = Vec::with_capacity(n);
    for (j, (jp, qdj)) in p.joints.iter().zip(qd).enumerate() {
        let x = &xup[j];
        let vj = s_times(jp, qdj);
        let v = x.apply(&v_prev) + vj.clone();
        let avp = x.apply(&a_prev) + v.crm(&vj);
        let inertia = RbInertia::mci(jp);
        let mut f = inertia.mul(&avp) + v.crf(&inertia.mul(&v));
        e0_prev = x.e.mul_mat(&e0_prev);
        if let Some(fx) = ext_force(j, &e0_prev) {
            f = f - fx;
        }
        fvp.push(f);
        v_prev = v;
        a_prev = avp;
    }
    let mut b = vec![S::zero(); nb + n];
    for j in (0..n).rev() {
        let c = s_tr(&p.joints[j], &fvp[j]);
        b[nb + j] = match &loads.tau {
            Some(tau) => tau[j].clone() - c,
            None => -c,
        };
        let carried = xup[j].tr_apply(&fvp[j]);
        if j > 0 {
            let parent = fvp[j - 1].clone();
            fvp[j - 1] = parent + carried;
        } else {
            f0 = f0 + carried;
        }
    }
    for (bi, x) in b.iter_mut().zip(rows(&f0)) {
        *bi = -x;
    }
    crate::algorithms::Dynamics { a, b }
}
