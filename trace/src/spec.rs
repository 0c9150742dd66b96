//! What a trace sees besides the function: whose parameters ([`Subject`]), and which effects
//! ([`Spec`]): the base, gravity, external wrenches, joint damping, a runtime payload. Only the
//! effects a spec names enter the graph, so an effect costs exactly the operations it adds.

use kanegen_dynamics::LoadFrame;
use kanegen_model::{Inertial, Model};

/// Whose parameters are traced.
#[derive(Clone, Copy, Debug)]
pub enum Subject<'a> {
    /// A model: its numbers are constants, folded into the graph (with
    /// [`Spec::runtime_payload`], the last body's mass properties are inputs instead).
    Model(&'a Model),
    /// `n` revolute joints whose every parameter (placement, axis, mass properties) is an input:
    /// counts for general geometry and inertia, independent of any model's zeros.
    Generic {
        /// Degrees of freedom.
        n: usize,
    },
    /// `n` revolute bodies starting from the inertial-frame quantities of the paper's eq. (1), (2),
    /// (6) as inputs (`r_{j−1,j}`, `a_j`, `m_j`, `c_j`, `I_j`): where the paper's Table 1 starts
    /// counting. Only for the inertial-frame mass-matrix methods.
    InertialFrame {
        /// Degrees of freedom.
        n: usize,
    },
}

impl Subject<'_> {
    /// Degrees of freedom.
    #[must_use]
    pub fn dof(&self) -> usize {
        match self {
            Subject::Model(m) => m.dof(),
            Subject::Generic { n } | Subject::InertialFrame { n } => *n,
        }
    }
}

/// The base of the traced system.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Base {
    /// Fixed: `N` speeds.
    #[default]
    Fixed,
    /// Free-floating with this base inertial: `6 + N` speeds, the base state as inputs
    /// (conventions of `kanegen_dynamics::base`).
    FreeFloating(Inertial),
}

/// The value of an external wrench.
#[derive(Clone, Debug, PartialEq)]
pub enum WrenchValue {
    /// Constant: folded into the graph.
    Constant {
        /// Force at the body origin.
        force: [f64; 3],
        /// Moment about the body origin.
        moment: [f64; 3],
    },
    /// Six runtime inputs (force, then moment).
    Runtime,
}

/// An external wrench on one body.
#[derive(Clone, Debug, PartialEq)]
pub struct Wrench {
    /// The body (`kanegen_dynamics::ExternalWrench::body`).
    pub body: usize,
    /// The frame of its components.
    pub frame: LoadFrame,
    /// Constant or runtime.
    pub value: WrenchValue,
}

/// The effects a trace includes; the default is none (space, fixed base, constant model).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Spec {
    /// Fixed or free-floating base.
    pub base: Base,
    /// Uniform gravity (base frame; inertial frame for a free-floating base), m/s².
    pub gravity: Option<[f64; 3]>,
    /// External wrenches.
    pub wrenches: Vec<Wrench>,
    /// Joint viscous damping `τ_d = −d q̇`, coefficients per independent coordinate (per joint;
    /// with mimic joints, per coordinate, acting at its joint of the full tree).
    pub damping: Option<Vec<f64>>,
    /// The last body's mass properties are runtime inputs ([`crate::PayloadField`]).
    pub runtime_payload: bool,
    /// The local-frame algorithms read regrouped inertial parameters
    /// (`kanegen_dynamics::regroup`): fewer operations, the same joint-space results. Only for a
    /// model, and not for the base reaction (a per-body wrench regrouping changes).
    pub regroup: bool,
    /// Evaluate (14b) as printed, without the exact correction: the paper's Table 1 bookkeeping,
    /// **inexact for N ≥ 3**; only with [`Subject::InertialFrame`] and the `recurrent-r1` mass-matrix
    /// method.
    pub paper_14b: bool,
    /// Joint placements within this of a signed permutation, entry by entry, carry inertias in
    /// two steps (`kanegen_dynamics::params::JointParams::placement_permutation`), as do (when
    /// it is not 0) placements that turn about one coordinate axis
    /// (`kanegen_dynamics::params::axis_turn`); only for a model. 0 (default): exact
    /// permutations only. The same results, other operation counts.
    pub two_step_placement: f64,
}

/// One effect of a [`Spec`], for reports of what each effect costs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Effect {
    /// Uniform gravity.
    Gravity,
    /// The i-th external wrench.
    Wrench(usize),
    /// Joint viscous damping.
    Damping,
}

impl Effect {
    /// `gravity`, `wrench[i]`, `damping`.
    #[must_use]
    pub fn name(self) -> String {
        match self {
            Effect::Gravity => "gravity".into(),
            Effect::Wrench(i) => format!("wrench[{i}]"),
            Effect::Damping => "damping".into(),
        }
    }
}

impl Spec {
    /// Only gravity.
    #[must_use]
    pub fn with_gravity(gravity: Option<[f64; 3]>) -> Self {
        Spec {
            gravity,
            ..Spec::default()
        }
    }

    /// The effects this spec names, in the order gravity, wrenches, damping.
    #[must_use]
    pub fn effects(&self) -> Vec<Effect> {
        let mut v = Vec::new();
        if self.gravity.is_some() {
            v.push(Effect::Gravity);
        }
        v.extend((0..self.wrenches.len()).map(Effect::Wrench));
        if self.damping.is_some() {
            v.push(Effect::Damping);
        }
        v
    }

    /// The spec with only the effects in `keep` (the base, payload and form are kept). A dropped
    /// wrench is removed, so the runtime inputs of the others are renumbered.
    #[must_use]
    pub fn only(&self, keep: &[Effect]) -> Spec {
        Spec {
            gravity: self.gravity.filter(|_| keep.contains(&Effect::Gravity)),
            wrenches: self
                .wrenches
                .iter()
                .enumerate()
                .filter(|(i, _)| keep.contains(&Effect::Wrench(*i)))
                .map(|(_, w)| w.clone())
                .collect(),
            damping: self
                .damping
                .clone()
                .filter(|_| keep.contains(&Effect::Damping)),
            ..self.clone()
        }
    }
}
