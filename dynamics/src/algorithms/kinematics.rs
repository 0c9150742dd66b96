//! Base-frame kinematics of the paper, eq. (1)–(7) and the resultants (11).
//!
//! Shared by the base-frame algorithms (`recurrent`, `kane-direct`, `crba-base`), which are
//! **serial-chain only**: [`base_frame`] and [`floating_base_frame`] panic on a kinematic tree
//! ([`Params::assert_chain`]). Indices here are 0-based: body `j` is moved by joint `j`, its
//! predecessor is `j − 1` and "body −1" is the base, whose frame is the inertial frame (fixed
//! base: zero velocity and acceleration).
//!
//! | paper | here |
//! |---|---|
//! | `τ_j` | [`BodyKinematics::orientation`] |
//! | `r_{j-1,j}` | [`BodyKinematics::r`] |
//! | `R^rel_j` non-zero column / `T^rel_j` non-zero column | [`BodyKinematics::axis`] (joint axis, base frame) |
//! | `m_j`, `c_j`, `I_j` (eq. 6, about `O_j`) | `m`, `c`, `inertia` |
//! | `ω_j`, `v_j`, `ε_j`, `w_j` (eq. 3–5) | [`BodyMotion`] |

use crate::base::{FloatingBase, FloatingState, FLOATING_BASE_DOF};
use crate::joint::joint_sin_cos;
use crate::linalg::{axis_rotation, Mat3, Vec3};
use crate::loads::{LoadFrame, Loads};
use crate::params::Params;
use crate::scalar::Scalar;
use kanegen_model::JointKind;
use kanegen_runtime::inertia::parallel_axis;

/// Position-level quantities of one body in the base frame.
#[derive(Clone, Debug)]
pub struct BodyKinematics<S> {
    /// Kind of the joint that moves this body.
    pub kind: JointKind,
    /// `τ_j`: orientation of the body frame in the base frame (eq. (1)).
    pub orientation: Mat3<S>,
    /// `r_{j-1,j}`: from `O_{j-1}` (the base origin for `j = 0`) to `O_j` (eq. (2)).
    pub r: Vec3<S>,
    /// Unit joint axis in the base frame: the non-zero column of `R^rel_j` (revolute) or
    /// `T^rel_j` (prismatic).
    pub axis: Vec3<S>,
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
    let inertia = parallel_axis(m, &d.0, &inertia_com.0);
    (c, Mat3(inertia))
}

/// Eq. (1), (2), (6): orientations, joint-to-joint vectors, axes and inertial quantities of every
/// body in the base frame.
pub fn base_frame<S: Scalar>(p: &Params<S>, q: &[S]) -> Vec<BodyKinematics<S>> {
    base_frame_from(p, q, None)
}

/// [`base_frame`] with the base body's orientation `τ_{-1}` given: `None` is the fixed base
/// (`τ_{-1} = 1`, the base frame is the reference frame); `Some(R₀)` expresses every quantity in
/// the frame in which the base frame has orientation `R₀` (the inertial frame of a free-floating
/// base, see [`crate::algorithms::floating`]). Vectors `r_{j-1,j}` stay relative, so `r_{-1,0}`
/// starts at the base-frame origin.
pub fn base_frame_from<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    tau_base: Option<&Mat3<S>>,
) -> Vec<BodyKinematics<S>> {
    p.assert_chain("base-frame kinematics (1)-(7)");
    assert_eq!(q.len(), p.dof(), "q has the wrong length");
    let mut out: Vec<BodyKinematics<S>> = Vec::with_capacity(p.dof());
    let mut tau_prev = tau_base.cloned().unwrap_or_else(Mat3::identity);
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
                let (s, c) = joint_sin_cos(jp, qj);
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
            orientation: tau.clone(),
            r,
            axis: a,
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

/// Eq. (3)–(5): velocities and the velocity-product accelerations, fixed base
/// (`motion_from(kin, qd, None)`).
pub fn motion<S: Scalar>(kin: &[BodyKinematics<S>], qd: &[S]) -> Vec<BodyMotion<S>> {
    motion_from(kin, qd, None)
}

/// Eq. (3)–(5) starting from the motion of the base body ("body −1"): `None` is the fixed base
/// (`ω_{-1} = v_{-1} = ε_{-1} = w_{-1} = 0`, not traced at all, so the fixed-base operation count
/// is unchanged); `Some(m)` a moving base whose `m.v` is the velocity of the base-frame origin,
/// `m.eps`, `m.w` the parts of its angular and linear acceleration not proportional to the
/// generalized accelerations (for a free-floating base: [`floating_base_motion`]).
pub fn motion_from<S: Scalar>(
    kin: &[BodyKinematics<S>],
    qd: &[S],
    initial: Option<&BodyMotion<S>>,
) -> Vec<BodyMotion<S>> {
    assert_eq!(qd.len(), kin.len(), "qd has the wrong length");
    S::section("(3)-(5)");
    let mut out: Vec<BodyMotion<S>> = Vec::with_capacity(kin.len());
    for (j, (k, qdj)) in kin.iter().zip(qd).enumerate() {
        let prev = if j == 0 { initial } else { Some(&out[j - 1]) };
        let rel = k.axis.scale(qdj);
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
                    LoadFrame::Body => (
                        k.orientation.mul_vec(&ext.force),
                        k.orientation.mul_vec(&ext.moment),
                    ),
                    LoadFrame::Base => (ext.force.clone(), ext.moment.clone()),
                };
                f = f + fe;
                n = n + me;
            }
            (f, n)
        })
        .collect()
}

/// Eq. (1), (2), (6) for a free-floating base, in the inertial frame: the base as six virtual
/// joints in front of the arm, then the arm's bodies (indices `6..6+N`).
///
/// The base's generalized speeds `ν_b = [v_b; ω_b]` (base coordinates) give every body `k` the
/// partial velocities (linear `T`, angular `R` columns, inertial frame, `e_m` the unit vectors):
/// for `v_b,m`: `T = R₀e_m`, `R = 0` — a prismatic joint with axis `R₀e_m`; for `ω_b,m`:
/// `R = R₀e_m`, `T = (R₀e_m) × r_{base,k}` — a revolute joint with axis `R₀e_m` through the base
/// origin `p₀`. Virtual joints `0..3` are those prismatic joints, `3..6` those revolute joints,
/// all at `q = 0` with `r = 0` between them (virtual body 0 stores `r = p₀`, its position from
/// the inertial origin, which no recursion reads). All six virtual bodies have the base's
/// orientation `τ = R₀`; bodies `0..5` are massless and body 5 carries the base body's inertia,
/// so the base-frame algorithms' prismatic/revolute formulas give the `(6+N)×(6+N)` matrix `A`
/// with no change. Because each virtual axis is `R₀e_m`, a row `a·F` of an inertial-frame
/// vector `F` is directly its base-coordinate component `(R₀ᵀF)_m`.
pub fn floating_base_frame<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
) -> Vec<BodyKinematics<S>> {
    S::section("floating:base");
    let r0 = &state.rotation;
    let mut out: Vec<BodyKinematics<S>> = Vec::with_capacity(FLOATING_BASE_DOF + p.dof());
    let (c_local, i_local) = body_inertia_about_origin(&base.mass, &base.com, &base.inertia_com);
    for m in 0..FLOATING_BASE_DOF {
        let carries = m == FLOATING_BASE_DOF - 1;
        out.push(BodyKinematics {
            kind: if m < 3 {
                JointKind::Prismatic
            } else {
                JointKind::Revolute
            },
            orientation: r0.clone(),
            r: if m == 0 {
                state.position.clone()
            } else {
                Vec3::zero()
            },
            axis: r0.col(m % 3),
            m: if carries {
                base.mass.clone()
            } else {
                S::zero()
            },
            c: if carries {
                r0.mul_vec(&c_local)
            } else {
                Vec3::zero()
            },
            inertia: if carries {
                r0.congruence(&i_local)
            } else {
                Mat3::zero()
            },
        });
    }
    out.extend(base_frame_from(p, q, Some(r0)));
    out
}

/// The true motion of a free-floating base body, inertial frame: `ω₀ = R₀ω_b`, `v₀ = R₀v_b`,
/// `ε₀ = 0` (because `d/dt(R₀ω_b) = R₀ω̇_b + R₀(ω_b × ω_b) = R₀ω̇_b`) and `w₀ = ω₀ × v₀`
/// (because `d/dt(R₀v_b) = R₀v̇_b + ω₀ × v₀`). This — not the composition of the virtual joints'
/// rates, which would add spurious `ω × ω^rel` terms — starts the recursion (3)–(5) of the arm.
pub fn floating_base_motion<S: Scalar>(state: &FloatingState<S>) -> BodyMotion<S> {
    let omega = state.rotation.mul_vec(&state.omega_b);
    let v = state.rotation.mul_vec(&state.v_b);
    let w = omega.cross(&v);
    BodyMotion {
        omega,
        v,
        eps: Vec3::zero(),
        w,
    }
}

/// Eq. (3)–(5) for the extended bodies of [`floating_base_frame`]: the six virtual bodies move
/// with the base body ([`floating_base_motion`]), the arm's bodies follow by [`motion_from`].
pub fn floating_motion<S: Scalar>(
    kin: &[BodyKinematics<S>],
    state: &FloatingState<S>,
    qd: &[S],
) -> Vec<BodyMotion<S>> {
    assert!(
        kin.len() >= FLOATING_BASE_DOF,
        "not a floating-base body list"
    );
    let m0 = floating_base_motion(state);
    let mut out = vec![m0.clone(); FLOATING_BASE_DOF];
    out.extend(motion_from(&kin[FLOATING_BASE_DOF..], qd, Some(&m0)));
    out
}
