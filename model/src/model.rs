//! The validated model of a serial chain: plain data, no behaviour (Pinocchio's model/data split).
//!
//! Conventions (URDF's): joint `j` (0-based here, `j+1` in the paper) sits in its parent body
//! (body `j-1`, or the base for `j = 0`) at `origin` — translation `l` and rotation `Υ` of the paper's
//! eq. (1)–(2). The child body's frame is the joint frame moved by the joint: rotated by `q` about
//! `axis` (revolute, `Θ_j`), or translated by `q · axis` (prismatic, `t^rel`). The child body's
//! inertial is given by its mass, the centre of mass in the body frame and the inertia tensor about
//! the centre of mass in body-frame axes.
//!
//! A `Model` can only be built through [`Model::new`], which validates every number; readers for
//! URDF and kanegen's TOML format live in [`crate::io`].

use crate::inertial::{finite, validate_inertial_with};
use crate::{Inertial, Placement};
use serde::Serialize;

/// The kind of a one-degree-of-freedom joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Rotation about the axis; `q` in rad, the drive is a torque.
    Revolute,
    /// Translation along the axis; `q` in m, the drive is a force.
    Prismatic,
}

/// A joint together with the body it moves.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Joint {
    /// Joint name (unique in the chain).
    pub name: String,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Placement of the joint frame in the parent body frame (`l`, `Υ` of eq. (1)–(2)).
    pub origin: Placement,
    /// Unit joint axis in the joint frame.
    pub axis: [f64; 3],
    /// Name of the child body.
    pub body: String,
    /// Mass properties of the child body.
    pub inertial: Inertial,
}

/// A validated serial chain of `N` bodies, each moved by a 1-dof joint, on a base.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Model {
    name: String,
    base: String,
    base_inertial: Option<Inertial>,
    joints: Vec<Joint>,
}

/// An error in a model: which joint (or body, or key) and which field, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A field has a value that is not physical or not well formed.
    #[error("joint `{joint}`: field `{field}`: {reason}")]
    Invalid {
        /// Joint (or body) name, or its position when unnamed.
        joint: String,
        /// The offending field, e.g. `inertial.mass`.
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The chain has no moving joint.
    #[error("model `{0}`: the chain is empty (no revolute or prismatic joint)")]
    Empty(String),
    /// A name is used twice.
    #[error("duplicate name `{name}` ({what})")]
    Duplicate {
        /// The repeated name.
        name: String,
        /// Joint or link.
        what: String,
    },
    /// A URDF tree branches at a link.
    #[error("link `{0}` has more than one child joint: kanegen handles serial chains only")]
    Branching(String),
    /// The file could not be parsed; the message names the key or element.
    #[error("{0}")]
    Parse(String),
    /// The file could not be read.
    #[error("cannot read `{path}`: {reason}")]
    Io {
        /// The path.
        path: String,
        /// The OS error.
        reason: String,
    },
}

impl ModelError {
    /// Shorthand for [`ModelError::Invalid`].
    pub fn invalid(joint: &str, field: &str, reason: impl Into<String>) -> Self {
        ModelError::Invalid {
            joint: joint.to_string(),
            field: field.to_string(),
            reason: reason.into(),
        }
    }
}

/// How strictly [`Model::new_with`] validates mass properties.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Validation {
    /// Accept inertia tensors that are positive definite but violate the triangle inequality
    /// (not physically realisable, yet present in some published parameter sets). Off by default.
    pub allow_nonphysical_inertia: bool,
}

impl Model {
    /// Builds and validates a chain with the default (strict) [`Validation`].
    pub fn new(
        name: impl Into<String>,
        base: impl Into<String>,
        base_inertial: Option<Inertial>,
        joints: Vec<Joint>,
    ) -> Result<Self, ModelError> {
        Self::new_with(name, base, base_inertial, joints, Validation::default())
    }

    /// Builds and validates a chain. Checks, each reported with the joint and field: finite
    /// numbers; mass > 0; inertia symmetric, positive definite and satisfying the triangle
    /// inequality; non-zero axis (normalized here); orthonormal right-handed origin rotation;
    /// unique joint and body names; at least one joint.
    pub fn new_with(
        name: impl Into<String>,
        base: impl Into<String>,
        base_inertial: Option<Inertial>,
        joints: Vec<Joint>,
        validation: Validation,
    ) -> Result<Self, ModelError> {
        let name = name.into();
        let base = base.into();
        if joints.is_empty() {
            return Err(ModelError::Empty(name));
        }
        let mut joints = joints;
        let mut names = std::collections::HashSet::new();
        let mut bodies = std::collections::HashSet::from([base.clone()]);
        for j in &mut joints {
            if !names.insert(j.name.clone()) {
                return Err(ModelError::Duplicate {
                    name: j.name.clone(),
                    what: "joint".into(),
                });
            }
            if !bodies.insert(j.body.clone()) {
                return Err(ModelError::Duplicate {
                    name: j.body.clone(),
                    what: "link".into(),
                });
            }
            validate_placement(&j.name, "origin", &j.origin)?;
            j.axis = validate_axis(&j.name, &j.axis)?;
            validate_inertial_with(&j.name, "inertial", &j.inertial, validation)?;
        }
        if let Some(b) = &base_inertial {
            validate_inertial_with(&base, "base.inertial", b, validation)?;
        }
        Ok(Model {
            name,
            base,
            base_inertial,
            joints,
        })
    }

    /// Model name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Name of the base body.
    #[must_use]
    pub fn base(&self) -> &str {
        &self.base
    }
    /// Mass properties of the base body, when the model gives them.
    #[must_use]
    pub fn base_inertial(&self) -> Option<&Inertial> {
        self.base_inertial.as_ref()
    }
    /// The joints in order from the base; `joints()[j]` moves body `j`.
    #[must_use]
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }
    /// Number of degrees of freedom `N`.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.joints.len()
    }
}

fn validate_placement(joint: &str, field: &str, p: &Placement) -> Result<(), ModelError> {
    finite(joint, &format!("{field}.translation"), &p.translation)?;
    let flat: Vec<f64> = p.rotation.iter().flatten().copied().collect();
    finite(joint, &format!("{field}.rotation"), &flat)?;
    let r = &p.rotation;
    let mut worst: f64 = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            let d: f64 = (0..3).map(|k| r[k][i] * r[k][j]).sum();
            let e = if i == j { 1.0 } else { 0.0 };
            worst = worst.max((d - e).abs());
        }
    }
    let det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
    if worst > 1e-6 || det < 0.0 {
        return Err(ModelError::invalid(
            joint,
            &format!("{field}.rotation"),
            format!(
                "not a rotation: |RᵀR − 1| = {worst:.3e}, det = {det:.6} (must be orthonormal with det +1)"
            ),
        ));
    }
    Ok(())
}

fn validate_axis(joint: &str, a: &[f64; 3]) -> Result<[f64; 3], ModelError> {
    finite(joint, "axis", a)?;
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if n < 1e-9 {
        return Err(ModelError::invalid(
            joint,
            "axis",
            "zero axis: a joint axis must have non-zero length",
        ));
    }
    Ok([a[0] / n, a[1] / n, a[2] / n])
}
