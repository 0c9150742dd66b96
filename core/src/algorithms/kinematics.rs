//! Base-frame kinematics of the paper, eq. (1)–(7) and the resultants (11).
//!
//! Shared by the base-frame algorithms (`recurrent`, `kane-direct`, `crba-base`). Indices here are
//! 0-based: body `j` is moved by joint `j`, its predecessor is `j − 1` and "body −1" is the base,
//! whose frame is the inertial frame (fixed base: zero velocity and acceleration).
//!
//! | paper | here |
//! |---|---|
//! | `τ_j` | [`BodyKinematics::tau`] |
//! | `r_{j-1,j}` | [`BodyKinematics::r`] |
//! | `R^rel_j` non-zero column / `T^rel_j` non-zero column | [`BodyKinematics::a`] (joint axis, base frame) |
//! | `m_j`, `c_j`, `I_j` (eq. 6, about `O_j`) | `m`, `c`, `inertia` |
//! | `ω_j`, `v_j`, `ε_j`, `w_j` (eq. 3–5) | [`BodyMotion`] |

use crate::algorithms::{LoadFrame, Loads};
use crate::linalg::{axis_rotation, Mat3, Vec3};
use crate::model::{ChainParams, JointKind};
use crate::scalar::Scalar;

/// Position-level quantities of one body in the base frame.
#[derive(Clone, Debug)]
pub struct BodyKinematics<S> {
    /// Kind of the joint that moves this body.
    pub kind: JointKind,
    /// `τ_j`: orientation of the body frame in the base frame (eq. (1)).
    pub tau: Mat3<S>,
    /// `r_{j-1,j}`: from `O_{j-1}` (the base origin for `j = 0`) to `O_j` (eq. (2)).
    pub r: Vec3<S>,
    /// Unit joint axis in the base frame: the non-zero column of `R^rel_j` (revolute) or
    /// `T^rel_j` (prismatic).
    pub a: Vec3<S>,
    /// `m_j`.
    pub m: S,
    /// `c_j = τ_j m_j d_j`: first moment of mass about `O_j` (eq. (6)).
    pub c: Vec3<S>,
    /// `I_j = τ_j I^{(j)}_j τ_jᵀ`: inertia about `O_j` (eq. (6)).
    pub inertia: Mat3<S>,
}

/// Velocity-level quantities of one body in the base frame (eq. (3)–(5)).
#[derive(Clone, Debug)]
pub struct BodyMotion<S> {
    /// `ω_j`: angular velocity.
    pub omega: Vec3<S>,
    /// `v_j`: velocity of `O_j`.
    pub v: Vec3<S>,
    /// `ε_j`: velocity-product part of the angular acceleration, `ω̇_j = R_j q̈ + ε_j`.
    pub eps: Vec3<S>,
    /// `w_j`: velocity-product part of the acceleration of `O_j`, `v̇_j = T_j q̈ + w_j`.
    pub w: Vec3<S>,
}

/// The body's inertia about its frame origin in its own axes: `I^{(j)}_j = I_C + m(|d|²1 − d dᵀ)`,
/// and its first moment `c^{(j)}_j = m d` (computed once before integration, §2).
pub fn body_inertia_about_origin<S: Scalar>(
    m: &S,
    d: &Vec3<S>,
    inertia_com: &Mat3<S>,
) -> (Vec3<S>, Mat3<S>) {
    let c = d.scale(m);
    // m(|d|²1 − d dᵀ) = m d̃ d̃ᵀ (parallel-axis theorem).
    let sd = Mat3::skew(d);
    let shift = sd.mul_mat(&sd.transpose()).scale(m);
    (c, inertia_com.clone() + shift)
}

/// Eq. (1), (2), (6): orientations, joint-to-joint vectors, axes and inertial quantities of every
/// body in the base frame.
pub fn base_frame<S: Scalar>(p: &ChainParams<S>, q: &[S]) -> Vec<BodyKinematics<S>> {
    assert_eq!(q.len(), p.dof(), "q has the wrong length");
    let mut out: Vec<BodyKinematics<S>> = Vec::with_capacity(p.dof());
    let mut tau_prev = Mat3::identity();
    S::section("(1)-(2)");
    for (jp, qj) in p.joints.iter().zip(q) {
        // (1) τ̂_j = τ_{j-1} Υ_{j-1}
        let tau_hat = tau_prev.mul_mat(&jp.upsilon);
        let a = tau_hat.mul_vec(&jp.axis);
        // (2) r_{j-1,j} = τ_{j-1} l + τ̂_j t^rel
        let r0 = tau_prev.mul_vec(&jp.l);
        let (tau, r) = match jp.kind {
            JointKind::Revolute => {
                // (1) τ_j = τ̂_j Θ_j, Θ_j the rotation about the axis by q_j.
                let (s, c) = qj.clone().sin_cos();
                (tau_hat.mul_mat(&axis_rotation(&jp.axis, &s, &c)), r0)
            }
            JointKind::Prismatic => (tau_hat, r0 + a.scale(qj)),
        };
        // (6) c_j = τ_j c^{(j)}, I_j = τ_j I^{(j)} τ_jᵀ
        let (c_local, i_local) = body_inertia_about_origin(&jp.mass, &jp.com, &jp.inertia_com);
        let c = tau.mul_vec(&c_local);
        let inertia = tau.congruence(&i_local);
        out.push(BodyKinematics {
            kind: jp.kind,
            tau: tau.clone(),
            r,
            a,
            m: jp.mass.clone(),
            c,
            inertia,
        });
        tau_prev = tau;
    }
    out
}

/// `E_j = ε̃_j + ω̃_j ω̃_j` (defined after eq. (5)).
pub fn e_matrix<S: Scalar>(m: &BodyMotion<S>) -> Mat3<S> {
    let wt = Mat3::skew(&m.omega);
    Mat3::skew(&m.eps) + wt.mul_mat(&wt)
}

/// Eq. (3)–(5): velocities and the velocity-product accelerations, fixed base.
pub fn motion<S: Scalar>(kin: &[BodyKinematics<S>], qd: &[S]) -> Vec<BodyMotion<S>> {
    assert_eq!(qd.len(), kin.len(), "qd has the wrong length");
    S::section("(3)-(5)");
    let mut out: Vec<BodyMotion<S>> = Vec::with_capacity(kin.len());
    for (j, (k, qdj)) in kin.iter().zip(qd).enumerate() {
        let prev = if j == 0 { None } else { Some(&out[j - 1]) };
        let rel = k.a.scale(qdj);
        let (w_rel, v_rel) = match k.kind {
            JointKind::Revolute => (Some(rel), None),
            JointKind::Prismatic => (None, Some(rel)),
        };
        let m = match prev {
            // Body 0 on a fixed base: ω_{-1} = v_{-1} = ε_{-1} = w_{-1} = 0.
            None => BodyMotion {
                omega: w_rel.clone().unwrap_or_else(Vec3::zero),
                v: v_rel.clone().unwrap_or_else(Vec3::zero),
                eps: Vec3::zero(),
                w: Vec3::zero(),
            },
            Some(pm) => {
                // (3) ω_j = ω_{j-1} + ω^rel_j; v_j = v_{j-1} + ω_{j-1} × r_{j-1,j} + v^rel_j
                let mut omega = pm.omega.clone();
                let mut v = &pm.v + &pm.omega.cross(&k.r);
                // (4) ε_j = ε_{j-1} + ω_{j-1} × ω^rel_j
                let mut eps = pm.eps.clone();
                // (5) w_j = w_{j-1} + E_{j-1} r_{j-1,j} + 2 ω_{j-1} × v^rel_j
                let mut w = &pm.w + &e_matrix(pm).mul_vec(&k.r);
                if let Some(wr) = &w_rel {
                    omega = omega + wr.clone();
                    eps = eps + pm.omega.cross(wr);
                }
                if let Some(vr) = &v_rel {
                    v = v + vr.clone();
                    let two = S::constant(2.0);
                    w = w + pm.omega.cross(vr).scale(&two);
                }
                BodyMotion { omega, v, eps, w }
            }
        };
        out.push(m);
    }
    out
}

/// Eq. (7) and (11): resultant inertial plus external force `f^IE_j` (at `O_j`) and moment
/// `m^IE_j` (about `O_j`) of every body, in the base frame. Gravity `g` acts at the centre of mass:
/// force `m_j g`, moment `c_j × g`. Only the loads present in `loads` are traced.
pub fn inertial_external<S: Scalar>(
    kin: &[BodyKinematics<S>],
    mot: &[BodyMotion<S>],
    loads: &Loads<S>,
) -> Vec<(Vec3<S>, Vec3<S>)> {
    S::section("(7),(11)");
    kin.iter()
        .zip(mot)
        .enumerate()
        .map(|(j, (k, m))| {
            // (11) f^IE = f^E − m w − E c;  m^IE = m^E − c̃ w − I ε − ω̃ I ω
            let e = e_matrix(m);
            let mut f = -(m.w.scale(&k.m) + e.mul_vec(&k.c));
            let mut n = -(k.c.cross(&m.w)
                + k.inertia.mul_vec(&m.eps)
                + m.omega.cross(&k.inertia.mul_vec(&m.omega)));
            if let Some(g) = &loads.gravity {
                f = f + g.scale(&k.m);
                n = n + k.c.cross(g);
            }
            for ext in loads.external.iter().filter(|e| e.body == j) {
                // (7) f^E_j = τ_j f^{E(j)}_j, m^E_j = τ_j m^{E(j)}_j
                let (fe, me) = match ext.frame {
                    LoadFrame::Body => (k.tau.mul_vec(&ext.force), k.tau.mul_vec(&ext.moment)),
                    LoadFrame::Base => (ext.force.clone(), ext.moment.clone()),
                };
                f = f + fe;
                n = n + me;
            }
            (f, n)
        })
        .collect()
}
