//! A model's numbers in a scalar type: what the algorithms read.
//!
//! [`Params::new`] turns every number of a [`Model`] into a constant of `S`; a code generator or
//! a report may then replace some of them by runtime inputs (a payload's mass, or every parameter
//! for a generic symbolic chain).

use crate::linalg::{Mat3, Vec3};
use crate::scalar::Scalar;
use kanegen_model::{JointKind, Model};

/// One joint and its child body, with every number in the scalar type `S`.
#[derive(Clone, Debug)]
pub struct JointParams<S> {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// The parent body `λ(j) < j`, or `None` for the base.
    pub parent: Option<usize>,
    /// `l^{(j-1)}_{j-1}`: joint origin in the parent body frame (eq. (2)).
    pub l: Vec3<S>,
    /// `Υ_{j-1}`: joint frame orientation in the parent body frame (eq. (1)).
    pub upsilon: Mat3<S>,
    /// Unit joint axis in the joint frame.
    pub axis: Vec3<S>,
    /// `m_j`.
    pub mass: S,
    /// `d^{(j)}_j`: centre of mass in the body frame.
    pub com: Vec3<S>,
    /// Inertia about the centre of mass, body axes.
    pub inertia_com: Mat3<S>,
}

/// A named frame fixed to a body, in the scalar type `S`.
#[derive(Clone, Debug)]
pub struct FrameParams<S> {
    /// The body it is fixed to (`None`: the base).
    pub parent: Option<usize>,
    /// Its origin in the body frame.
    pub translation: Vec3<S>,
    /// Its orientation in the body frame.
    pub rotation: Mat3<S>,
}

/// The model's numbers in the scalar type `S`.
#[derive(Clone, Debug)]
pub struct Params<S> {
    /// Joints in topological order (parents first).
    pub joints: Vec<JointParams<S>>,
    /// The model's named frames, in its order.
    pub frames: Vec<FrameParams<S>>,
}

impl<S: Scalar> Params<S> {
    /// Every number of `model` as a constant of `S`.
    #[must_use]
    pub fn new(model: &Model) -> Self {
        Params {
            joints: model
                .joints()
                .iter()
                .map(|j| JointParams {
                    kind: j.kind,
                    parent: j.parent,
                    l: Vec3::from_f64(j.origin.translation),
                    upsilon: Mat3::from_f64(j.origin.rotation),
                    axis: Vec3::from_f64(j.axis),
                    mass: S::constant(j.inertial.mass),
                    com: Vec3::from_f64(j.inertial.com),
                    inertia_com: Mat3::from_f64(j.inertial.inertia),
                })
                .collect(),
            frames: model
                .frames()
                .iter()
                .map(|f| FrameParams {
                    parent: f.parent,
                    translation: Vec3::from_f64(f.placement.translation),
                    rotation: Mat3::from_f64(f.placement.rotation),
                })
                .collect(),
        }
    }
}

impl<S> Params<S> {
    /// Number of degrees of freedom.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Whether the tree is a serial chain (`λ(j) = j − 1`), as the paper's base-frame algorithms
    /// need.
    #[must_use]
    pub fn is_chain(&self) -> bool {
        self.joints
            .iter()
            .enumerate()
            .all(|(j, jp)| jp.parent == j.checked_sub(1))
    }
}
