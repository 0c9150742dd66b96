//! Spatial-vector algebra in local body coordinates (R. Featherstone, *Rigid Body Dynamics
//! Algorithms*, Springer 2008, "RBDA", ch. 2; spatial_v2's names in brackets), shared by the
//! local-frame algorithms [`crate::algorithms::crba`] and [`crate::algorithms::rnea`].
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
//! Each revolute `q_j` costs one `sin_cos` per call of [`xup`].

use crate::linalg::{axis_rotation, Mat3, Vec3};
use crate::params::JointParams;
use crate::scalar::Scalar;
use kanegen_model::JointKind;

/// A spatial motion vector `[ω; v]` (RBDA §2.2).
#[derive(Clone, Debug)]
pub struct Motion<S> {
    /// Angular part `ω`.
    pub ang: Vec3<S>,
    /// Linear part `v` (velocity of the frame origin).
    pub lin: Vec3<S>,
}

/// A spatial force vector `[n; f]`, `n` about the frame origin (RBDA §2.3).
#[derive(Clone, Debug)]
pub struct Force<S> {
    /// Moment `n` about the frame origin.
    pub ang: Vec3<S>,
    /// Force `f`.
    pub lin: Vec3<S>,
}

impl<S: Scalar> Motion<S> {
    /// The zero motion.
    pub fn zero() -> Self {
        Motion {
            ang: Vec3::zero(),
            lin: Vec3::zero(),
        }
    }
    /// `self ×ₘ m = [ω × ω₂; ω × v₂ + v × ω₂]` (RBDA eq. (2.31), spatial_v2 `crm`).
    pub fn crm(&self, m: &Motion<S>) -> Motion<S> {
        Motion {
            ang: self.ang.cross(&m.ang),
            lin: self.ang.cross(&m.lin) + self.lin.cross(&m.ang),
        }
    }
    /// `self ×* f = [ω × n + v × f; ω × f]` (RBDA eq. (2.32), spatial_v2 `crf`).
    pub fn crf(&self, f: &Force<S>) -> Force<S> {
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
pub struct Xform<S> {
    /// `E`: rotation from A to B coordinates.
    pub e: Mat3<S>,
    /// `r`: B's origin in A coordinates.
    pub r: Vec3<S>,
}

impl<S: Scalar> Xform<S> {
    /// `X m = [E ω; E (v − r × ω)]`.
    pub fn apply(&self, m: &Motion<S>) -> Motion<S> {
        Motion {
            ang: self.e.mul_vec(&m.ang),
            lin: self.e.mul_vec(&(&m.lin - &self.r.cross(&m.ang))),
        }
    }
    /// `Xᵀ f = [Eᵀ n + r × Eᵀ f; Eᵀ f]`: a force from frame B coordinates back to frame A
    /// (`ᴬX_B* = Xᵀ`, spatial_v2's `Xup' * f`).
    pub fn tr_apply(&self, f: &Force<S>) -> Force<S> {
        let lin = self.e.tr_mul_vec(&f.lin);
        Force {
            ang: self.e.tr_mul_vec(&f.ang) + self.r.cross(&lin),
            lin,
        }
    }
    /// `Xᵀ I X`: a rigid-body inertia from frame B coordinates to frame A coordinates
    /// (RBDA Table 2.5): `(m, Eᵀh + m r, EᵀĪE − r̃ (Eᵀh)~ − (Eᵀh + m r)~ r̃)`.
    pub fn tr_inertia(&self, i: &RbInertia<S>) -> RbInertia<S> {
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
pub struct RbInertia<S> {
    /// Mass.
    pub m: S,
    /// First moment `m c` about the frame origin.
    pub h: Vec3<S>,
    /// Rotational inertia about the frame origin.
    pub ibar: Mat3<S>,
}

impl<S: Scalar> RbInertia<S> {
    /// spatial_v2 `mcI(m, c, I_c)`: `h = m c`, `Ī = I_c + m c̃ c̃ᵀ` (parallel axes).
    pub fn from_com(m: &S, c: &Vec3<S>, inertia_com: &Mat3<S>) -> Self {
        let ct = Mat3::skew(c);
        RbInertia {
            m: m.clone(),
            h: c.scale(m),
            ibar: inertia_com.clone() + ct.mul_mat(&ct.transpose()).scale(m),
        }
    }
    /// The inertia of joint `jp`'s body in its own frame ([`RbInertia::from_com`]).
    pub fn mci(jp: &JointParams<S>) -> Self {
        Self::from_com(&jp.mass, &jp.com, &jp.inertia_com)
    }
    /// `I [ω; v] = [Ī ω + h × v; m v − h × ω]`.
    pub fn mul(&self, v: &Motion<S>) -> Force<S> {
        Force {
            ang: self.ibar.mul_vec(&v.ang) + self.h.cross(&v.lin),
            lin: v.lin.scale(&self.m) - self.h.cross(&v.ang),
        }
    }
}

/// `Xup_j = XJ(q_j) Xtree_j` (RBDA §4.4; spatial_v2 `jcalc` and `Xtree`).
pub fn xup<S: Scalar>(jp: &JointParams<S>, q: &S) -> Xform<S> {
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
pub fn s_times<S: Scalar>(jp: &JointParams<S>, x: &S) -> Motion<S> {
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
pub fn s_tr<S: Scalar>(jp: &JointParams<S>, f: &Force<S>) -> S {
    match jp.kind {
        JointKind::Revolute => jp.axis.dot(&f.ang),
        JointKind::Prismatic => jp.axis.dot(&f.lin),
    }
}

/// `I S_j` for a rigid-body inertia (only the non-zero half of `S_j` is multiplied).
pub fn inertia_s<S: Scalar>(ic: &RbInertia<S>, jp: &JointParams<S>) -> Force<S> {
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

/// The rows `[f; n]` of a force (linear part first: the base rows of `ν = [v_b; ω_b; q̇]`).
pub fn base_rows<S: Scalar>(f: &Force<S>) -> [S; 6] {
    [
        f.lin.at(0),
        f.lin.at(1),
        f.lin.at(2),
        f.ang.at(0),
        f.ang.at(1),
        f.ang.at(2),
    ]
}

/// Two bodies' inertias in the same frame, welded together.
impl<S: Scalar> core::ops::Add for RbInertia<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        RbInertia {
            m: self.m + o.m,
            h: self.h + o.h,
            ibar: self.ibar + o.ibar,
        }
    }
}
