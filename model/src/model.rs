//! The validated model of a robot: a kinematic tree of bodies on a base, plain data, no behaviour
//! (Pinocchio's model/data split).
//!
//! Conventions (URDF's): joint `j` (0-based here, `j+1` in the paper) moves body `j` and sits in
//! its parent body `λ(j)` ([`Joint::parent`], Featherstone's λ; `None` is the base) at `origin` —
//! translation `l` and rotation `Υ` of the paper's eq. (1)–(2). Joints are in topological order:
//! `λ(j) < j`. A serial chain is the tree with `λ(j) = j − 1` ([`Model::is_chain`]). The child
//! body's frame is the joint frame moved by the joint: rotated by `q` about `axis` (revolute,
//! `Θ_j`), or translated by `q · axis` (prismatic, `t^rel`). The child body's inertial is given by
//! its mass, the centre of mass in the body frame and the inertia tensor about the centre of mass
//! in body-frame axes. Named [`Frame`]s (tool flanges, sensors) are massless frames fixed to a
//! body; they are never bodies.
//!
//! The base is fixed, or free-floating ([`BaseKind`]) with the base body's inertial.
//!
//! A `Model` can only be built through [`Model::new`], which validates every number; readers for
//! URDF and kanegen's TOML format live in [`crate::io`].

use crate::bounds::{normalize, LENGTH};
use crate::inertial::{bounded, finite, validate_inertial_with};
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
    /// Joint name (unique in the model).
    pub name: String,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// The parent body `λ(j)`: the body of joint `λ(j) < j`, or `None` for the base.
    pub parent: Option<usize>,
    /// Placement of the joint frame in the parent body frame (`l`, `Υ` of eq. (1)–(2)).
    pub origin: Placement,
    /// Unit joint axis in the joint frame.
    pub axis: [f64; 3],
    /// Name of the child body.
    pub body: String,
    /// Mass properties of the child body.
    pub inertial: Inertial,
}

/// A joint's limits as a URDF `<limit>` gives them (Pinocchio's `lowerPositionLimit`,
/// `upperPositionLimit`, `velocityLimit`, `effortLimit`); absent values are `None`. Read and
/// reported, never enforced by the dynamics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Limits {
    /// Lowest position, rad or m.
    pub lower: Option<f64>,
    /// Highest position, rad or m.
    pub upper: Option<f64>,
    /// Largest speed, rad/s or m/s.
    pub velocity: Option<f64>,
    /// Largest drive torque or force, N·m or N.
    pub effort: Option<f64>,
}

/// A mimic joint's coupling to its primary (URDF `<mimic>`, Pinocchio's mimic joints):
/// `q_j = multiplier · q_primary + offset`, so `q̇_j = multiplier · q̇_primary`. The primary is
/// resolved through chains of mimics: it is never a mimic itself.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Mimic {
    /// The joint it follows (index into [`Model::joints`]; not a mimic joint).
    pub primary: usize,
    /// Factor on the primary's position.
    pub multiplier: f64,
    /// Added to the position, rad or m.
    pub offset: f64,
}

/// A named frame fixed to a body (a tool flange, a camera): massless, never a body.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Frame {
    /// Frame name (unique among frames).
    pub name: String,
    /// The body it is fixed to: the body of joint `j`, or `None` for the base.
    pub parent: Option<usize>,
    /// Its placement in that body's frame.
    pub placement: Placement,
}

/// How the base moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BaseKind {
    /// Fixed to the inertial frame: `N` degrees of freedom.
    #[default]
    Fixed,
    /// Free-floating (a spacecraft): `6 + N` degrees of freedom; needs the base inertial.
    FreeFloating,
}

impl BaseKind {
    /// `fixed` or `free-floating`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BaseKind::Fixed => "fixed",
            BaseKind::FreeFloating => "free-floating",
        }
    }

    /// The kind called `name` ([`BaseKind::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "fixed" => Some(BaseKind::Fixed),
            "free-floating" => Some(BaseKind::FreeFloating),
            _ => None,
        }
    }
}

/// A validated kinematic tree of `N` bodies, each moved by a 1-dof joint, on a base.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Model {
    name: String,
    base: String,
    base_inertial: Option<Inertial>,
    base_kind: BaseKind,
    joints: Vec<Joint>,
    frames: Vec<Frame>,
    limits: Vec<Limits>,
    mimics: Vec<Option<Mimic>>,
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
    /// The file could not be parsed; the message names the key or element.
    #[error("{0}")]
    Parse(String),
    /// Some joints move no mass, so `M` is singular and forward dynamics is undefined.
    #[error(
        "model `{model}`: these joints move no mass (no body with mass beyond them): {}; the mass \
         matrix M is singular, so forward dynamics (q̈ = M⁻¹(τ − c)) is undefined; M, c and \
         inverse dynamics are (`kanegen eval`); give a link beyond each of them mass, or make \
         them fixed joints",
        .joints.iter().map(|j| format!("joint `{j}`")).collect::<Vec<_>>().join(", ")
    )]
    Singular {
        /// The model.
        model: String,
        /// The joints that move no mass (or `base` for a massless free-floating system).
        joints: Vec<String>,
    },
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
    /// Accept inertia tensors that are not physically realisable beyond
    /// [`crate::inertial::PHYSICAL_TOLERANCE`]: a negative principal moment (not positive
    /// semidefinite), the triangle inequality violated, or rotational inertia without mass
    /// ([`crate::inertial::nonphysical`]); present in some published parameter sets. Every other
    /// check stays (finite, bounded, mass ≥ 0, symmetric). Off by default.
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

    /// Builds and validates a model on a fixed base, without named frames ([`Model::with_frames`],
    /// [`Model::with_base_kind`] add them). Checks, each reported with the joint and field:
    /// finite numbers; mass ≥ 0 (a massless body has no inertia either); inertia symmetric,
    /// physical ([`crate::inertial::nonphysical`]: positive semidefinite and satisfying the
    /// triangle inequality, to a tolerance relative to its magnitude); non-zero axis (normalized here); orthonormal right-handed origin rotation;
    /// parents before children (`λ(j) < j`); unique joint and body names; at least one joint.
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
        for (k, j) in joints.iter_mut().enumerate() {
            if let Some(p) = j.parent {
                if p >= k {
                    return Err(ModelError::invalid(
                        &j.name,
                        "parent",
                        format!(
                            "joint #{p} comes at or after this joint (#{k}): joints must be \
                             listed parents first"
                        ),
                    ));
                }
            }
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
        let n = joints.len();
        Ok(Model {
            name,
            base,
            base_inertial,
            base_kind: BaseKind::Fixed,
            joints,
            frames: Vec::new(),
            limits: vec![Limits::default(); n],
            mimics: vec![None; n],
        })
    }

    /// The model with these named frames (replacing any it had). Checks: unique names, an
    /// existing parent body, a valid placement.
    ///
    /// # Errors
    /// The first frame that fails a check, naming it and the field.
    pub fn with_frames(mut self, frames: Vec<Frame>) -> Result<Self, ModelError> {
        let mut names = std::collections::HashSet::new();
        for f in &frames {
            if !names.insert(f.name.clone()) {
                return Err(ModelError::Duplicate {
                    name: f.name.clone(),
                    what: "frame".into(),
                });
            }
            if let Some(p) = f.parent {
                if p >= self.joints.len() {
                    return Err(ModelError::invalid(
                        &f.name,
                        "frame.parent",
                        format!("no body #{p} (N = {})", self.joints.len()),
                    ));
                }
            }
            validate_placement(&f.name, "frame.placement", &f.placement)?;
        }
        self.frames = frames;
        Ok(self)
    }

    /// The model with these base mass properties (replacing any it had), e.g. a stand-in for a
    /// URDF whose root link is massless, before [`Model::with_base_kind`] makes the base
    /// free-floating.
    ///
    /// # Errors
    /// The inertial fails the strict checks of [`crate::validate_inertial`] (finite, mass ≥ 0,
    /// inertia symmetric and physical: [`crate::inertial::nonphysical`]).
    pub fn with_base_inertial(mut self, inertial: Inertial) -> Result<Self, ModelError> {
        validate_inertial_with(
            &self.base,
            "base.inertial",
            &inertial,
            Validation::default(),
        )?;
        self.base_inertial = Some(inertial);
        Ok(self)
    }

    /// The model on a base of this kind.
    ///
    /// # Errors
    /// A free-floating base without mass properties.
    pub fn with_base_kind(mut self, kind: BaseKind) -> Result<Self, ModelError> {
        if kind == BaseKind::FreeFloating && self.base_inertial.is_none() {
            return Err(ModelError::invalid(
                &self.base,
                "base.mass",
                "a free-floating base needs its mass properties (mass, com, inertia)",
            ));
        }
        self.base_kind = kind;
        Ok(self)
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
    /// Fixed or free-floating.
    #[must_use]
    pub fn base_kind(&self) -> BaseKind {
        self.base_kind
    }
    /// The named frames.
    #[must_use]
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }
    /// Whether the tree is a serial chain (`λ(j) = j − 1`), as the paper's algorithms need.
    #[must_use]
    pub fn is_chain(&self) -> bool {
        self.joints
            .iter()
            .enumerate()
            .all(|(j, jt)| jt.parent == j.checked_sub(1))
    }
    /// The first joint, in order, whose parent body has another child joint before it (where
    /// the tree branches), or `None` for a chain.
    #[must_use]
    pub fn first_branch(&self) -> Option<&Joint> {
        self.joints
            .iter()
            .enumerate()
            .find(|(j, jt)| jt.parent != j.checked_sub(1))
            .map(|(_, jt)| jt)
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
    /// Number of joints `N` (bodies); with mimic joints more than the independent coordinates
    /// ([`Model::coordinates`]).
    #[must_use]
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// The limits of each joint (in the order of [`Model::joints`]).
    #[must_use]
    pub fn limits(&self) -> &[Limits] {
        &self.limits
    }

    /// The model with these joint limits (one per joint).
    ///
    /// # Errors
    /// A wrong count, a limit that is NaN or negative (velocity, effort), or `lower > upper`.
    pub fn with_limits(mut self, limits: Vec<Limits>) -> Result<Self, ModelError> {
        if limits.len() != self.joints.len() {
            return Err(ModelError::Parse(format!(
                "model `{}`: {} limits for {} joints",
                self.name,
                limits.len(),
                self.joints.len()
            )));
        }
        for (j, l) in self.joints.iter().zip(&limits) {
            let all = [l.lower, l.upper, l.velocity, l.effort];
            if all.iter().flatten().any(|x| x.is_nan()) {
                return Err(ModelError::invalid(&j.name, "limit", "a limit is NaN"));
            }
            if l.velocity.is_some_and(|v| v < 0.0) || l.effort.is_some_and(|e| e < 0.0) {
                return Err(ModelError::invalid(
                    &j.name,
                    "limit",
                    "velocity and effort limits must be ≥ 0",
                ));
            }
            if let (Some(lo), Some(hi)) = (l.lower, l.upper) {
                if lo > hi {
                    return Err(ModelError::invalid(
                        &j.name,
                        "limit",
                        format!("lower {lo} > upper {hi}"),
                    ));
                }
            }
        }
        self.limits = limits;
        Ok(self)
    }

    /// Each joint's mimic coupling (`None`: an independent coordinate).
    #[must_use]
    pub fn mimics(&self) -> &[Option<Mimic>] {
        &self.mimics
    }

    /// Whether some joint mimics another.
    #[must_use]
    pub fn has_mimics(&self) -> bool {
        self.mimics.iter().any(Option::is_some)
    }

    /// The independent coordinates: the indices of the joints that mimic none, in order; `q`
    /// has one entry per coordinate.
    #[must_use]
    pub fn coordinates(&self) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&j| self.mimics[j].is_none())
            .collect()
    }

    /// The number of independent coordinates (the joints that mimic none): the length of `q`'s
    /// joint part.
    #[must_use]
    pub fn coordinate_count(&self) -> usize {
        self.mimics.iter().filter(|m| m.is_none()).count()
    }

    /// The model with these mimic couplings (one per joint), already resolved to primaries.
    ///
    /// # Errors
    /// A wrong count, a primary out of range, itself a mimic or the joint itself, or a
    /// multiplier or offset that is not finite.
    pub fn with_mimics(mut self, mimics: Vec<Option<Mimic>>) -> Result<Self, ModelError> {
        if mimics.len() != self.joints.len() {
            return Err(ModelError::Parse(format!(
                "model `{}`: {} mimic entries for {} joints",
                self.name,
                mimics.len(),
                self.joints.len()
            )));
        }
        for (k, m) in mimics.iter().enumerate() {
            let Some(m) = m else { continue };
            let name = &self.joints[k].name;
            if m.primary >= mimics.len() || m.primary == k || mimics[m.primary].is_some() {
                return Err(ModelError::invalid(
                    name,
                    "mimic.joint",
                    format!("joint #{} is not an independent joint", m.primary),
                ));
            }
            finite(name, "mimic", &[m.multiplier, m.offset])?;
        }
        self.mimics = mimics;
        Ok(self)
    }

    /// The same model with every mimic joint an independent joint (URDF `<mimic>` ignored, as
    /// Pinocchio's `mimic=False` reads it).
    #[must_use]
    pub fn without_mimics(mut self) -> Self {
        self.mimics = vec![None; self.joints.len()];
        self
    }

    /// The joints that move no mass: no body beyond them (their own included) has mass, so
    /// their rows of `M` are zero. Decided from the structure: a joint whose subtree holds mass
    /// only on its own axis (a point mass on a revolute axis) moves no inertia either, and is
    /// not listed.
    #[must_use]
    pub fn massless_joints(&self) -> Vec<&str> {
        let mut mass: Vec<f64> = self.joints.iter().map(|j| j.inertial.mass).collect();
        for k in (0..self.joints.len()).rev() {
            if let Some(p) = self.joints[k].parent {
                mass[p] += mass[k];
            }
        }
        self.joints
            .iter()
            .zip(mass)
            .filter(|(_, m)| *m == 0.0)
            .map(|(j, _)| j.name.as_str())
            .collect()
    }

    /// Whether forward dynamics is defined structurally: every joint moves mass
    /// ([`Model::massless_joints`]) and a free-floating system has mass.
    ///
    /// # Errors
    /// [`ModelError::Singular`], naming the joints that move no mass.
    pub fn check_forward_dynamics(&self) -> Result<(), ModelError> {
        let mut joints: Vec<String> = self
            .massless_joints()
            .into_iter()
            .map(str::to_string)
            .collect();
        let total = self.base_inertial.as_ref().map_or(0.0, |b| b.mass)
            + self.joints.iter().map(|j| j.inertial.mass).sum::<f64>();
        if self.base_kind == BaseKind::FreeFloating && total == 0.0 {
            joints.insert(0, self.base.clone());
        }
        if joints.is_empty() {
            Ok(())
        } else {
            Err(ModelError::Singular {
                model: self.name.clone(),
                joints,
            })
        }
    }
}

fn validate_placement(joint: &str, field: &str, p: &Placement) -> Result<(), ModelError> {
    bounded(
        joint,
        &format!("{field}.translation"),
        &p.translation,
        LENGTH,
    )?;
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
    // Normalized by the largest component first, so no square overflows or underflows.
    normalize(a, 1e-9).ok_or_else(|| {
        ModelError::invalid(
            joint,
            "axis",
            "zero axis: a joint axis must have non-zero length",
        )
    })
}
