//! The base of a robot: fixed, or free-floating (a spacecraft) with its conventions, stated once
//! and used by the algorithms, the tracer, the generated code and the simulator.
//!
//! # Free-floating conventions (Pinocchio's free-flyer)
//!
//! - **Base pose**: position `p₀` of the base-frame origin in the inertial frame, and the attitude
//!   as a unit quaternion stored `[x, y, z, w]` (Pinocchio/Eigen order), i.e. the rotation `R₀`
//!   from base to inertial coordinates ([`quat_to_matrix`]). [`FloatingState`] holds `R₀` as a
//!   matrix.
//! - **Generalized velocity** `ν = [v_b (3), ω_b (3), q̇ (N)]`: `v_b` the linear velocity of the
//!   base-frame origin and `ω_b` the base's angular velocity, both in **base** coordinates.
//! - `A ν̇ = b`, `b = Q − h`, where `ν̇` is the time derivative of the components of `ν` (so `v̇_b`
//!   is the derivative of the base-coordinate components, not the base origin's acceleration).
//!   Rows `0..3` of `b` hold the external + gravity force on the system and rows `3..6` its moment
//!   about the base origin, both in base coordinates, minus the velocity-product terms; rows `6..`
//!   are the arm's rows.
//! - **Position state** for integrators: `[p₀ (3), quat (4: x, y, z, w), q (N)]`, with
//!   `ṗ₀ = R₀ v_b`, `Ṙ₀ = R₀ ω̃_b`, `q̇` as given.
//! - **Loads** ([`crate::Loads`]): `gravity` is in the **inertial** frame. An
//!   [`crate::ExternalWrench`] with `body = j < N` acts on arm body `j` (force at `O_j`, moment
//!   about `O_j`) and with `body =` [`BASE_BODY`] on the base body (force at the base origin); its
//!   frame [`crate::LoadFrame::Body`] is that body's frame and [`crate::LoadFrame::Base`] means
//!   the **inertial** frame (which is the base frame of a fixed-base chain). `tau` has `N`
//!   entries (arm drives; the base is not actuated).

use crate::linalg::{Mat3, Vec3};
use crate::scalar::Scalar;
use crate::spatial::RbInertia;
use kanegen_model::Inertial;

/// The `body` index of an [`crate::ExternalWrench`] on the base body of a free-floating chain.
pub const BASE_BODY: usize = usize::MAX;

/// Number of generalized speeds of a free-floating base (3 linear, then 3 angular).
pub const FLOATING_BASE_DOF: usize = 6;

/// Mass properties of the free-floating base body (base-frame coordinates).
#[derive(Clone, Debug)]
pub struct FloatingBase<S> {
    /// Mass.
    pub mass: S,
    /// Centre of mass in the base frame.
    pub com: Vec3<S>,
    /// Inertia about the centre of mass, base-frame axes.
    pub inertia_com: Mat3<S>,
    /// The spatial inertia about the base-frame origin, as the local-frame algorithms read it:
    /// [`RbInertia::from_com`] of the three above, unless regrouped ([`crate::regroup`]).
    pub inertia: RbInertia<S>,
}

impl<S: Scalar> FloatingBase<S> {
    /// From mass, centre of mass and inertia about it.
    pub fn new(mass: S, com: Vec3<S>, inertia_com: Mat3<S>) -> Self {
        FloatingBase {
            inertia: RbInertia::from_com(&mass, &com, &inertia_com),
            mass,
            com,
            inertia_com,
        }
    }

    /// From a model's inertial (e.g. [`kanegen_model::Model::base_inertial`]), as constants.
    pub fn from_inertial(i: &Inertial) -> Self {
        Self::new(
            S::constant(i.mass),
            Vec3::from_f64(i.com),
            Mat3::from_f64(i.inertia),
        )
    }
}

/// The base's pose and twist (see the module conventions).
#[derive(Clone, Debug)]
pub struct FloatingState<S> {
    /// `p₀`: the base-frame origin in the inertial frame.
    pub position: Vec3<S>,
    /// `R₀`: rotation from base to inertial coordinates ([`quat_to_matrix`]).
    pub rotation: Mat3<S>,
    /// `v_b`: velocity of the base-frame origin, base coordinates.
    pub v_b: Vec3<S>,
    /// `ω_b`: angular velocity of the base, base coordinates.
    pub omega_b: Vec3<S>,
}

impl<S: Scalar> FloatingState<S> {
    /// Identity pose, zero twist.
    pub fn at_rest() -> Self {
        FloatingState {
            position: Vec3::zero(),
            rotation: Mat3::identity(),
            v_b: Vec3::zero(),
            omega_b: Vec3::zero(),
        }
    }

    /// The base speeds `ν_b = [v_b; ω_b]`.
    pub fn nu_base(&self) -> [S; 6] {
        let [a, b, c] = self.v_b.0.clone();
        let [d, e, f] = self.omega_b.0.clone();
        [a, b, c, d, e, f]
    }
}

/// The rotation matrix of a unit quaternion stored `[x, y, z, w]` (Pinocchio/Eigen order):
/// `R = (w² − |u|²) 1 + 2 u uᵀ + 2 w ũ`, written for a unit quaternion as
/// `R = 1 + 2 w ũ + 2 ũ ũ` (`u = (x, y, z)`). The quaternion is not normalized here.
pub fn quat_to_matrix<S: Scalar>(quat: &[S; 4]) -> Mat3<S> {
    let u = Vec3::new(quat[0].clone(), quat[1].clone(), quat[2].clone());
    let two = S::constant(2.0);
    let su = Mat3::skew(&u);
    Mat3::identity() + su.scale(&(two.clone() * quat[3].clone())) + su.mul_mat(&su).scale(&two)
}
