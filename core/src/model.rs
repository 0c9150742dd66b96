//! The validated model of a serial chain: plain data, no behaviour (Pinocchio's model/data split).
//!
//! Conventions (URDF's): joint `j` (0-based here, `j+1` in the paper) sits in its parent body
//! (body `j-1`, or the base for `j = 0`) at `origin` — translation `l` and rotation `Υ` of the paper's
//! eq. (1)–(2). The child body's frame is the joint frame moved by the joint: rotated by `q` about
//! `axis` (revolute, `Θ_j`), or translated by `q · axis` (prismatic, `t^rel`). The child body's
//! inertial is given by its mass, the centre of mass in the body frame and the inertia tensor about
//! the centre of mass in body-frame axes.
//!
//! A `Chain` can only be built through [`Chain::new`], which validates every number; readers for
//! URDF and kanegen's TOML format live in [`crate::io`].

use crate::linalg::{Mat3, Vec3};
use crate::scalar::Scalar;
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

/// A rigid placement of one frame in another: `x_parent = rotation · x_child + translation`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// Translation, in the parent frame.
    pub translation: [f64; 3],
    /// Rotation matrix (row-major), orthonormal with determinant +1.
    pub rotation: [[f64; 3]; 3],
}

impl Placement {
    /// The identity placement.
    pub fn identity() -> Self {
        Placement {
            translation: [0.0; 3],
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }
}

/// Mass properties of a rigid body.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Inertial {
    /// Mass, kg (> 0).
    pub mass: f64,
    /// Centre of mass in the body frame, m.
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass, in body-frame axes, kg·m² (symmetric positive
    /// definite, satisfying the triangle inequality).
    pub inertia: [[f64; 3]; 3],
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
pub struct Chain {
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

/// How strictly [`Chain::new_with`] validates mass properties.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Validation {
    /// Accept inertia tensors that are positive definite but violate the triangle inequality
    /// (not physically realisable, yet present in some published parameter sets). Off by default.
    pub allow_nonphysical_inertia: bool,
}

impl Chain {
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
        Ok(Chain {
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
    /// The chain with joint `index` locked at `value` (rad or m): the joint becomes a fixed
    /// placement and its body is merged into its parent (the previous body, or the base when
    /// `index == 0`), mass, centre of mass and inertia combined; the next joint's origin is
    /// re-expressed in the parent frame. The result has `N − 1` joints and the same dynamics as
    /// the original with `q[index] = value` and `q̇[index] = 0` (rows and columns of the locked
    /// joint removed). The merged inertia is not re-checked for the triangle inequality (it holds
    /// when it held for the parts).
    ///
    /// # Errors
    /// If `index` is out of range or the chain would become empty.
    pub fn lock_joint(&self, index: usize, value: f64) -> Result<Chain, ModelError> {
        use crate::linalg::axis_rotation;
        let n = self.joints.len();
        if index >= n {
            return Err(ModelError::invalid(
                &format!("#{index}"),
                "lock_joint",
                format!("joint index {index} out of range (N = {n})"),
            ));
        }
        let j = &self.joints[index];
        // Placement of body `index` in its parent frame at q = value.
        let ups = Mat3::from_f64(j.origin.rotation);
        let axis = Vec3::from_f64(j.axis);
        let (rot, trans) = match j.kind {
            JointKind::Revolute => {
                let (s, c) = value.sin_cos();
                (
                    ups.mul_mat(&axis_rotation(&axis, &s, &c)),
                    Vec3::from_f64(j.origin.translation),
                )
            }
            JointKind::Prismatic => (
                ups.clone(),
                Vec3::from_f64(j.origin.translation) + ups.mul_vec(&axis.scale(&value)),
            ),
        };
        // The locked body's mass properties in the parent frame.
        let moved = Inertial {
            mass: j.inertial.mass,
            com: (&trans + &rot.mul_vec(&Vec3::from_f64(j.inertial.com))).into_array(),
            inertia: rot
                .mul_mat(&Mat3::from_f64(j.inertial.inertia))
                .mul_mat(&rot.transpose())
                .into_array(),
        };
        let mut joints = self.joints.clone();
        let mut base_inertial = self.base_inertial.clone();
        if index == 0 {
            base_inertial = base_inertial.map(|b| merge_inertials(&b, &moved));
        } else {
            let parent = &mut joints[index - 1].inertial;
            *parent = merge_inertials(parent, &moved);
        }
        if let Some(next) = joints.get_mut(index + 1) {
            let l = Vec3::from_f64(next.origin.translation);
            next.origin = Placement {
                translation: (&trans + &rot.mul_vec(&l)).into_array(),
                rotation: rot
                    .mul_mat(&Mat3::from_f64(next.origin.rotation))
                    .into_array(),
            };
        }
        joints.remove(index);
        Chain::new_with(
            self.name.clone(),
            self.base.clone(),
            base_inertial,
            joints,
            Validation {
                allow_nonphysical_inertia: true,
            },
        )
    }

    /// The model's numbers as constants of the scalar type `S` (see [`ChainParams`]).
    pub fn params<S: Scalar>(&self) -> ChainParams<S> {
        ChainParams {
            joints: self
                .joints
                .iter()
                .map(|j| JointParams {
                    kind: j.kind,
                    l: Vec3::from_f64(j.origin.translation),
                    upsilon: Mat3::from_f64(j.origin.rotation),
                    axis: Vec3::from_f64(j.axis),
                    mass: S::constant(j.inertial.mass),
                    com: Vec3::from_f64(j.inertial.com),
                    inertia_com: Mat3::from_f64(j.inertial.inertia),
                })
                .collect(),
        }
    }
}

/// One joint and its child body, with every number in the scalar type `S`.
#[derive(Clone, Debug)]
pub struct JointParams<S> {
    /// Revolute or prismatic.
    pub kind: JointKind,
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

/// The chain's numbers in the scalar type `S`: constants by default ([`Chain::params`]); a code
/// generator may replace some of them by runtime inputs (e.g. a payload's mass).
#[derive(Clone, Debug)]
pub struct ChainParams<S> {
    /// Joints in order from the base.
    pub joints: Vec<JointParams<S>>,
}

impl<S> ChainParams<S> {
    /// Number of degrees of freedom.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.joints.len()
    }
}

fn finite(joint: &str, field: &str, xs: &[f64]) -> Result<(), ModelError> {
    if let Some(x) = xs.iter().find(|x| !x.is_finite()) {
        return Err(ModelError::invalid(
            joint,
            field,
            format!("value {x} is not finite"),
        ));
    }
    Ok(())
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

/// Checks a body's mass properties strictly; `owner` names the joint (or body) in the message.
pub fn validate_inertial(owner: &str, field: &str, b: &Inertial) -> Result<(), ModelError> {
    validate_inertial_with(owner, field, b, Validation::default())
}

/// Checks a body's mass properties under the given [`Validation`].
pub fn validate_inertial_with(
    owner: &str,
    field: &str,
    b: &Inertial,
    validation: Validation,
) -> Result<(), ModelError> {
    finite(owner, &format!("{field}.mass"), &[b.mass])?;
    if b.mass <= 0.0 {
        return Err(ModelError::invalid(
            owner,
            &format!("{field}.mass"),
            format!("mass must be > 0, got {}", b.mass),
        ));
    }
    finite(owner, &format!("{field}.com"), &b.com)?;
    let i = &b.inertia;
    let flat: Vec<f64> = i.iter().flatten().copied().collect();
    finite(owner, &format!("{field}.inertia"), &flat)?;
    let scale = flat
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()))
        .max(f64::MIN_POSITIVE);
    for (r, c) in [(0, 1), (0, 2), (1, 2)] {
        if (i[r][c] - i[c][r]).abs() > 1e-9 * scale {
            return Err(ModelError::invalid(
                owner,
                &format!("{field}.inertia"),
                format!(
                    "not symmetric: I[{r}][{c}] = {} but I[{c}][{r}] = {}",
                    i[r][c], i[c][r]
                ),
            ));
        }
    }
    // Positive definiteness by Sylvester's criterion (leading principal minors).
    let m1 = i[0][0];
    let m2 = i[0][0] * i[1][1] - i[0][1] * i[1][0];
    let m3 = i[0][0] * (i[1][1] * i[2][2] - i[1][2] * i[2][1])
        - i[0][1] * (i[1][0] * i[2][2] - i[1][2] * i[2][0])
        + i[0][2] * (i[1][0] * i[2][1] - i[1][1] * i[2][0]);
    if !(m1 > 0.0 && m2 > 0.0 && m3 > 0.0) {
        return Err(ModelError::invalid(
            owner,
            &format!("{field}.inertia"),
            format!(
                "not positive definite (leading minors {m1:.6e}, {m2:.6e}, {m3:.6e}); the inertia tensor about the centre of mass must be SPD"
            ),
        ));
    }
    // Triangle inequality on the principal moments: each ≤ the sum of the other two.
    let ev = sym3_eigenvalues(i);
    let tol = 1e-9 * (ev[0] + ev[1] + ev[2]);
    for k in 0..3 {
        let (a, b2, c) = (ev[k], ev[(k + 1) % 3], ev[(k + 2) % 3]);
        if a > b2 + c + tol && !validation.allow_nonphysical_inertia {
            return Err(ModelError::invalid(
                owner,
                &format!("{field}.inertia"),
                format!(
                    "violates the triangle inequality: principal moments {:.6e}, {:.6e}, {:.6e} (not physically realisable; --allow-nonphysical accepts it)",
                    ev[0], ev[1], ev[2]
                ),
            ));
        }
    }
    Ok(())
}

/// Two bodies' mass properties, given in the same frame, combined into one (parallel-axis theorem).
fn merge_inertials(a: &Inertial, b: &Inertial) -> Inertial {
    let m = a.mass + b.mass;
    let c: [f64; 3] = core::array::from_fn(|k| (a.mass * a.com[k] + b.mass * b.com[k]) / m);
    let mut inertia = [[0.0; 3]; 3];
    for part in [a, b] {
        let d: [f64; 3] = core::array::from_fn(|k| part.com[k] - c[k]);
        let d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        for r in 0..3 {
            for s in 0..3 {
                let e = if r == s { d2 } else { 0.0 };
                inertia[r][s] += part.inertia[r][s] + part.mass * (e - d[r] * d[s]);
            }
        }
    }
    Inertial {
        mass: m,
        com: c,
        inertia,
    }
}

/// Eigenvalues of a symmetric 3×3 matrix.
fn sym3_eigenvalues(m: &[[f64; 3]; 3]) -> [f64; 3] {
    let mat = nalgebra::Matrix3::from_fn(|r, c| m[r][c]);
    let e = mat.symmetric_eigenvalues();
    [e[0], e[1], e[2]]
}
