//! The 1-dof joints in spatial algebra ([`crate::spatial`]; RBDA §4.4, spatial_v2 `jcalc`).
//!
//! Joint `j` (URDF convention): `Xtree_j` places the joint frame in the parent (`E = Υᵀ`,
//! `r = l`); `XJ_j` is the joint motion (revolute: `E = Θ(q)ᵀ`, `r = 0`; prismatic: `E = 1`,
//! `r = q·axis`); `Xup_j = XJ_j Xtree_j`; the motion subspace is `S_j = [axis; 0]` (revolute) or
//! `[0; axis]` (prismatic), the axis having the same coordinates in the joint and child frames.
//! Each revolute `q_j` costs one `sin_cos` per call of [`xup`].

use crate::linalg::{axis_rotation, Mat3, Vec3};
use crate::params::JointParams;
use crate::scalar::Scalar;
use crate::spatial::{Force, Motion, RbInertia, Xform};
use kanegen_model::JointKind;

/// `Xup_j = XJ(q_j) Xtree_j` (RBDA §4.4; spatial_v2 `jcalc` and `Xtree`).
pub fn xup<S: Scalar>(jp: &JointParams<S>, q: &S) -> Xform<S> {
    xup_trig(jp, q).0
}

/// `Xup_j` with `(sin q_j, cos q_j)` for a revolute joint ([`joint_sin_cos`]: of `q_j` plus its
/// angle offset where it has one; `None` for a prismatic one).
pub type XupTrig<S> = (Xform<S>, Option<(S, S)>);

/// `(sin q_j, cos q_j)` of a revolute joint, of `q_j` plus its
/// [`JointParams::angle_offset`] where it has one.
pub fn joint_sin_cos<S: Scalar>(jp: &JointParams<S>, q: &S) -> (S, S) {
    match &jp.angle_offset {
        Some(offset) => (q.clone() + offset.clone()).sin_cos(),
        None => q.clone().sin_cos(),
    }
}

/// [`xup`], and `(sin q_j, cos q_j)` for a revolute joint (`None` for a prismatic one), for
/// callers that use them again ([`carry_inertia`]) without a second `sin_cos`.
pub fn xup_trig<S: Scalar>(jp: &JointParams<S>, q: &S) -> XupTrig<S> {
    match jp.kind {
        JointKind::Revolute => {
            let (s, c) = joint_sin_cos(jp, q);
            // E = Θᵀ Υᵀ = (Υ Θ)ᵀ, r = l.
            let e = jp
                .upsilon
                .mul_mat(&axis_rotation(&jp.axis, &s, &c))
                .transpose();
            (Xform { e, r: jp.l.clone() }, Some((s, c)))
        }
        // E = Υᵀ, r = l + Υ (q axis).
        JointKind::Prismatic => (
            Xform {
                e: jp.upsilon.transpose(),
                r: &jp.l + &jp.upsilon.mul_vec(&jp.axis.scale(q)),
            },
            None,
        ),
    }
}

/// `Xup_jᵀ I Xup_j`: the inertia `i` of body `j` (its frame) carried to its parent's frame
/// (RBDA Table 2.5, the backward loop of Table 6.2). `(x, trig)` is [`xup_trig`] of `q_j`. A
/// revolute joint about a coordinate axis ([`JointParams::coordinate_axis`]) placed by a signed
/// permutation, or within [`crate::params::NEAR_PERMUTATION`] of one
/// ([`JointParams::placement_permutation`]), goes in two steps, `Xtreeᵀ (XJᵀ I XJ) Xtree`: the
/// joint's own turn in double-angle form ([`RbInertia::turned_about_axis`], sharing `q`'s sine
/// and cosine with `x`), then the placement (its true rotation: in the same double-angle form
/// when it turns about one coordinate axis, [`JointParams::placement_turn`]; the tracer also takes
/// the two steps through such placements where that is cheaper); any other joint through `x` at
/// once (measured: after a dense placement the two steps cost more, as the products of the
/// double-angle terms with the placement's numbers are not shared).
pub fn carry_inertia<S: Scalar>(
    jp: &JointParams<S>,
    (x, trig): &XupTrig<S>,
    i: &RbInertia<S>,
) -> RbInertia<S> {
    match (trig, jp.coordinate_axis) {
        (Some((s, c)), Some(k)) if jp.placement_permutation => {
            // The axis is ±e_k exactly: s·u_k is ±s.
            let turned = i.turned_about_axis(k, &(s.clone() * jp.axis.at(k)), c);
            match &jp.placement_turn {
                // Υ = Θ_kp(α): Υ Ī Υᵀ is the turn about e_kp, then the shift by `l`.
                Some((kp, sp, cp)) => Xform {
                    e: Mat3::identity(),
                    r: jp.l.clone(),
                }
                .tr_inertia(&turned.turned_about_axis(*kp, sp, cp)),
                None => Xform {
                    e: jp.upsilon.transpose(),
                    r: jp.l.clone(),
                }
                .tr_inertia(&turned),
            }
        }
        _ => x.tr_inertia(i),
    }
}

/// `E v` for `Xup_j = (E, r)`: a vector of the parent's coordinates in body `j`'s. Where the
/// inertia carry goes in two steps ([`carry_inertia`]) through a placement that turns about one
/// axis ([`JointParams::placement_turn`]), so does the vector: `E = Θᵀ Υᵀ`, the placement's turn
/// by `−α`, then the joint's by `−q_j`, eight products where `E` at once takes up to nine and the
/// four of `E`'s own entries (a signed permutation `Υ` folds either way, and goes at once).
pub fn rotate_up<S: Scalar>(jp: &JointParams<S>, (x, trig): &XupTrig<S>, v: &Vec3<S>) -> Vec3<S> {
    match (trig, jp.coordinate_axis, &jp.placement_turn) {
        (Some((s, c)), Some(k), Some((kp, sp, cp))) if jp.placement_permutation => v
            .turned_about_axis(*kp, &-sp.clone(), cp)
            .turned_about_axis(k, &-(s.clone() * jp.axis.at(k)), c),
        _ => x.e.mul_vec(v),
    }
}

/// `Eᵀ v` for `Xup_j = (E, r)`: a vector of body `j`'s coordinates in its parent's, in two steps
/// where [`rotate_up`] takes two (`Eᵀ = Υ Θ`).
pub fn rotate_down<S: Scalar>(jp: &JointParams<S>, (x, trig): &XupTrig<S>, v: &Vec3<S>) -> Vec3<S> {
    match (trig, jp.coordinate_axis, &jp.placement_turn) {
        (Some((s, c)), Some(k), Some((kp, sp, cp))) if jp.placement_permutation => v
            .turned_about_axis(k, &(s.clone() * jp.axis.at(k)), c)
            .turned_about_axis(*kp, sp, cp),
        _ => x.e.tr_mul_vec(v),
    }
}

/// `Xup_jᵀ f`: a force of body `j` carried to its parent ([`Xform::tr_apply`]), its rotations by
/// [`rotate_down`].
pub fn carry_force<S: Scalar>(jp: &JointParams<S>, xt: &XupTrig<S>, f: &Force<S>) -> Force<S> {
    let lin = rotate_down(jp, xt, &f.lin);
    Force {
        ang: rotate_down(jp, xt, &f.ang) + xt.0.r.cross(&lin),
        lin,
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
