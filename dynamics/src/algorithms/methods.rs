//! Which algorithm computes what: the mass-matrix method (how `M` is computed) and the
//! nonlinear-effects method (how `c`, and with it `τ − c`, is computed) are chosen separately
//! ([`Methods`]), and every fixed-base entry point dispatches here. The convention is
//! `M q̈ + c = τ` (Pinocchio's); the paper's own files write it `A q̈ = b` with `b = τ − c`.
//!
//! | mass-matrix method | file | what |
//! |---|---|---|
//! | `recurrent` | `recurrent.rs` | the paper's O(N²) recursion (12)–(16), (20), (14b) exact as R2 |
//! | `recurrent-r1` | `recurrent.rs` | the same with (14b) as R1 (the paper's per-matrix cost + O(N)) |
//! | `kane-direct` | `kane_direct.rs` | the direct Kane sum (9), O(N³) |
//! | `crba-inertial` | `crba_inertial.rs` | composite rigid bodies in the paper's inertial-frame notation |
//! | `crba` | `crba.rs` | Featherstone's composite-rigid-body algorithm in local frames |
//!
//! | nonlinear-effects method | file | what |
//! |---|---|---|
//! | `recurrent` | `recurrent.rs` | the paper's backward recursion (17)–(19), (21) |
//! | `kane-direct` | `kane_direct.rs` | the direct Kane sum (10) |
//! | `rnea` | `rnea.rs` | Featherstone's recursive Newton–Euler algorithm in local frames |
//! | `newton-euler` | `newton_euler.rs` | the classical Newton–Euler algorithm in local frames (3-vectors) |
//!
//! | forward method | file | what |
//! |---|---|---|
//! | `ldlt` | `ldlt.rs` | `q̈ = M⁻¹ (τ − c)` by a branch-free LDLᵀ of the mass-matrix method's `M` |
//! | `aba` | `aba.rs` | Featherstone's articulated-body algorithm, O(N), no `M` at all |
//!
//! The CLI's `--algorithm` names are presets of the first two ([`Methods::PRESETS`]), all with
//! `ldlt`; [`Methods::ABA`] is the articulated-body algorithm. Every method's name of earlier
//! releases stays accepted by `from_name` ([`MassMatrixMethod::ALIASES`], [`Methods::ALIASES`]):
//! `crba-base` is `crba-inertial`.
//!
//! **Trees.** Only the local-frame methods (`crba`, `rnea`, `newton-euler`, and `aba`) take a
//! kinematic tree; the paper's inertial-frame methods are serial-chain only
//! ([`MassMatrixMethod::supports_trees`], [`NonlinearEffectsMethod::supports_trees`]). [`Methods::check`]
//! tells a caller before it runs them; the methods themselves panic with the same message.
//!
//! ```
//! use kanegen_dynamics::{Methods, Params};
//! use kanegen_model::random::{random_tree, ChainSpec};
//! let tree = random_tree(&ChainSpec { n: 5, ..Default::default() }, 4);
//! let p = Params::<f64>::new(&tree);
//! assert!(Methods::SPATIAL.check(&p).is_ok());
//! let e = Methods::RECURRENT.check(&p).unwrap_err();
//! assert!(e.to_string().contains("`recurrent` handles serial chains only"));
//! // An earlier name still names its method.
//! assert_eq!(Methods::from_name("crba-base"), Some(Methods::CRBA_INERTIAL));
//! ```

use crate::algorithms::kinematics::{self, BodyKinematics};
use crate::algorithms::{aba, crba, crba_inertial, kane_direct, newton_euler, recurrent, rnea};
use crate::loads::Loads;
pub use crate::params::MethodError;
use crate::params::Params;
use crate::scalar::Scalar;

/// `M` (full symmetric, row-major `mass_matrix[i][j]`) and `τ − c` of `M q̈ + c = τ`.
#[derive(Clone, Debug)]
pub struct Dynamics<S> {
    /// `M`: the generalized inertia (joint-space mass) matrix, N×N, both triangles filled.
    pub mass_matrix: Vec<Vec<S>>,
    /// `τ + Σ Jᵀ f_ext − c`: the joint drives plus the generalized forces of the external
    /// wrenches, minus the nonlinear effects `c` (velocity products and gravity); the paper's `b`.
    pub tau_minus_c: Vec<S>,
}

/// How the generalized inertia matrix `M(q)` is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MassMatrixMethod {
    /// The paper's recurrent algorithm, (14b) as R2 (exact).
    Recurrent,
    /// The paper's recurrent algorithm, (14b) as R1 (the paper's per-matrix cost plus an O(N)
    /// correction).
    RecurrentR1,
    /// The direct Kane sum (9), O(N³).
    KaneDirect,
    /// Composite rigid bodies in the paper's inertial-frame notation (Stepanenko's baseline).
    CrbaInertial,
    /// Featherstone's composite-rigid-body algorithm in local frames (RBDA Table 6.2).
    Crba,
}

impl MassMatrixMethod {
    /// All methods, in report order.
    pub const ALL: [MassMatrixMethod; 5] = [
        MassMatrixMethod::Recurrent,
        MassMatrixMethod::RecurrentR1,
        MassMatrixMethod::KaneDirect,
        MassMatrixMethod::CrbaInertial,
        MassMatrixMethod::Crba,
    ];

    /// Its name in reports and generated headers.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MassMatrixMethod::Recurrent => "recurrent",
            MassMatrixMethod::RecurrentR1 => "recurrent-r1",
            MassMatrixMethod::KaneDirect => "kane-direct",
            MassMatrixMethod::CrbaInertial => "crba-inertial",
            MassMatrixMethod::Crba => "crba",
        }
    }

    /// Earlier names still accepted by [`MassMatrixMethod::from_name`]: `(old, method)`.
    pub const ALIASES: [(&'static str, MassMatrixMethod); 1] =
        [("crba-base", MassMatrixMethod::CrbaInertial)];

    /// The method called `name` ([`MassMatrixMethod::name`], or an alias of
    /// [`MassMatrixMethod::ALIASES`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .or_else(|| {
                Self::ALIASES
                    .iter()
                    .find(|(old, _)| *old == name)
                    .map(|(_, m)| *m)
            })
    }

    /// Whether the method takes a kinematic tree: only the local-frame [`MassMatrixMethod::Crba`];
    /// the paper's inertial-frame methods are serial-chain only.
    #[must_use]
    pub fn supports_trees(self) -> bool {
        self == MassMatrixMethod::Crba
    }

    /// `Ok` when the method can run on `p` (any model for a tree-capable method, a serial chain
    /// otherwise).
    ///
    /// # Errors
    /// A serial-chain-only method on a tree: the error names the method and the first branching
    /// joint.
    pub fn check<S>(self, p: &Params<S>) -> Result<(), MethodError> {
        if self.supports_trees() {
            Ok(())
        } else {
            p.require_chain(self.name())
        }
    }

    /// `M` from the inertial-frame quantities of eq. (1), (2), (6) (fixed base, or the
    /// free-floating base's virtual-joint extension); `None` for [`MassMatrixMethod::Crba`], which
    /// works in local frames from `q`.
    pub fn from_inertial_frame<S: Scalar>(self, kin: &[BodyKinematics<S>]) -> Option<Vec<Vec<S>>> {
        match self {
            MassMatrixMethod::Recurrent => {
                Some(recurrent::mass_matrix_inertial(kin, recurrent::Variant::R2))
            }
            MassMatrixMethod::RecurrentR1 => {
                Some(recurrent::mass_matrix_inertial(kin, recurrent::Variant::R1))
            }
            MassMatrixMethod::KaneDirect => Some(kane_direct::mass_matrix_inertial(kin)),
            MassMatrixMethod::CrbaInertial => Some(crba_inertial::mass_matrix_inertial(kin)),
            MassMatrixMethod::Crba => None,
        }
    }

    /// The generalized inertia matrix `M(q)`, fixed base.
    ///
    /// # Panics
    /// A serial-chain-only method on a tree ([`MassMatrixMethod::check`]).
    pub fn mass_matrix<S: Scalar>(self, p: &Params<S>, q: &[S]) -> Vec<Vec<S>> {
        match self {
            MassMatrixMethod::Crba => crba::mass_matrix(p, q),
            inertial_frame => {
                p.assert_chain(inertial_frame.name());
                inertial_frame
                    .from_inertial_frame(&kinematics::inertial_frame(p, q))
                    .expect("every method but the CRBA starts from inertial-frame quantities")
            }
        }
    }
}

/// How the nonlinear effects `c(q, q̇)` (velocity products and gravity; Pinocchio's
/// `nonLinearEffects`) are computed, and with them `τ − c` (the paper's `b`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum NonlinearEffectsMethod {
    /// The paper's inertial-frame backward recursion (17)–(19), (21).
    Recurrent,
    /// The direct Kane sum (10).
    KaneDirect,
    /// Featherstone's recursive Newton–Euler algorithm in local frames (RBDA Table 5.1).
    Rnea,
    /// The classical Newton–Euler algorithm in local frames with 3-vectors (Luh–Walker–Paul, in
    /// Khalil's customized form): no linear velocities.
    NewtonEuler,
}

impl NonlinearEffectsMethod {
    /// All methods, in report order.
    pub const ALL: [NonlinearEffectsMethod; 4] = [
        NonlinearEffectsMethod::Recurrent,
        NonlinearEffectsMethod::KaneDirect,
        NonlinearEffectsMethod::Rnea,
        NonlinearEffectsMethod::NewtonEuler,
    ];

    /// Its name in reports and generated headers.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            NonlinearEffectsMethod::Recurrent => "recurrent",
            NonlinearEffectsMethod::KaneDirect => "kane-direct",
            NonlinearEffectsMethod::Rnea => "rnea",
            NonlinearEffectsMethod::NewtonEuler => "newton-euler",
        }
    }

    /// The method called `name` ([`NonlinearEffectsMethod::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Whether the method takes a kinematic tree: the local-frame [`NonlinearEffectsMethod::Rnea`] and
    /// [`NonlinearEffectsMethod::NewtonEuler`]; the paper's inertial-frame methods are serial-chain only.
    #[must_use]
    pub fn supports_trees(self) -> bool {
        matches!(
            self,
            NonlinearEffectsMethod::Rnea | NonlinearEffectsMethod::NewtonEuler
        )
    }

    /// `Ok` when the method can run on `p` ([`MassMatrixMethod::check`]).
    ///
    /// # Errors
    /// A serial-chain-only method on a tree.
    pub fn check<S>(self, p: &Params<S>) -> Result<(), MethodError> {
        if self.supports_trees() {
            Ok(())
        } else {
            p.require_chain(self.name())
        }
    }

    /// `τ − c(q, q̇)` with the applied loads (`τ = loads.tau` plus the external wrenches' generalized
    /// forces; gravity is part of `c`), fixed base.
    ///
    /// # Panics
    /// A serial-chain-only method on a tree ([`NonlinearEffectsMethod::check`]).
    pub fn tau_minus_c<S: Scalar>(
        self,
        p: &Params<S>,
        q: &[S],
        qd: &[S],
        loads: &Loads<S>,
    ) -> Vec<S> {
        match self {
            NonlinearEffectsMethod::Recurrent => recurrent::tau_minus_c(p, q, qd, loads),
            NonlinearEffectsMethod::KaneDirect => kane_direct::tau_minus_c(p, q, qd, loads),
            NonlinearEffectsMethod::Rnea => rnea::tau_minus_c(p, q, qd, loads),
            NonlinearEffectsMethod::NewtonEuler => newton_euler::tau_minus_c(p, q, qd, loads),
        }
    }
}

/// How forward dynamics `q̈ = M⁻¹ (τ − c)` is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ForwardMethod {
    /// `M` and `τ − c` by the mass-matrix and nonlinear-effects methods, then the branch-free LDLᵀ of
    /// [`crate::ldlt`].
    Ldlt,
    /// Featherstone's articulated-body algorithm ([`aba`], RBDA Table 7.1): O(N), reads neither
    /// the mass-matrix nor the nonlinear-effects method; any kinematic tree.
    Aba,
}

impl ForwardMethod {
    /// All methods, in report order.
    pub const ALL: [ForwardMethod; 2] = [ForwardMethod::Ldlt, ForwardMethod::Aba];

    /// Its name in reports and generated headers.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ForwardMethod::Ldlt => "ldlt",
            ForwardMethod::Aba => "aba",
        }
    }

    /// The method called `name` ([`ForwardMethod::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }
}

/// A mass-matrix method, a nonlinear-effects method and a forward-dynamics method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Methods {
    /// How `M` is computed.
    pub mass_matrix: MassMatrixMethod,
    /// How `c` (and so `τ − c`) is computed.
    pub nonlinear_effects: NonlinearEffectsMethod,
    /// How forward dynamics is computed ([`ForwardMethod::Ldlt`] in every preset).
    pub forward: ForwardMethod,
}

impl Methods {
    /// `recurrent`: the paper's recurrent algorithm for both.
    pub const RECURRENT: Methods = Methods {
        mass_matrix: MassMatrixMethod::Recurrent,
        nonlinear_effects: NonlinearEffectsMethod::Recurrent,
        forward: ForwardMethod::Ldlt,
    };
    /// `recurrent-r1`: (14b) as R1, with the paper's recursion for `c`.
    pub const RECURRENT_R1: Methods = Methods {
        mass_matrix: MassMatrixMethod::RecurrentR1,
        nonlinear_effects: NonlinearEffectsMethod::Recurrent,
        forward: ForwardMethod::Ldlt,
    };
    /// `kane-direct`: the direct sums (9) and (10).
    pub const KANE_DIRECT: Methods = Methods {
        mass_matrix: MassMatrixMethod::KaneDirect,
        nonlinear_effects: NonlinearEffectsMethod::KaneDirect,
        forward: ForwardMethod::Ldlt,
    };
    /// `crba-inertial`: inertial-frame composite rigid bodies, with the paper's recursion for `c`.
    pub const CRBA_INERTIAL: Methods = Methods {
        mass_matrix: MassMatrixMethod::CrbaInertial,
        nonlinear_effects: NonlinearEffectsMethod::Recurrent,
        forward: ForwardMethod::Ldlt,
    };
    /// `spatial`: Featherstone's CRBA and RNEA in local frames.
    pub const SPATIAL: Methods = Methods {
        mass_matrix: MassMatrixMethod::Crba,
        nonlinear_effects: NonlinearEffectsMethod::Rnea,
        forward: ForwardMethod::Ldlt,
    };

    /// `aba`: forward dynamics by the articulated-body algorithm; `M` and `τ − c`, when asked for,
    /// by the CRBA and the RNEA (as [`Methods::SPATIAL`]). Not a preset.
    pub const ABA: Methods = Methods {
        mass_matrix: MassMatrixMethod::Crba,
        nonlinear_effects: NonlinearEffectsMethod::Rnea,
        forward: ForwardMethod::Aba,
    };

    /// The presets, by the CLI's `--algorithm` names, in report order.
    pub const PRESETS: [(&'static str, Methods); 5] = [
        ("recurrent", Methods::RECURRENT),
        ("recurrent-r1", Methods::RECURRENT_R1),
        ("kane-direct", Methods::KANE_DIRECT),
        ("crba-inertial", Methods::CRBA_INERTIAL),
        ("spatial", Methods::SPATIAL),
    ];

    /// The presets' methods ([`Methods::PRESETS`] without the names).
    pub const ALL: [Methods; 5] = [
        Methods::RECURRENT,
        Methods::RECURRENT_R1,
        Methods::KANE_DIRECT,
        Methods::CRBA_INERTIAL,
        Methods::SPATIAL,
    ];

    /// Earlier preset names still accepted by [`Methods::from_name`]: `(old, preset)`.
    pub const ALIASES: [(&'static str, Methods); 1] = [("crba-base", Methods::CRBA_INERTIAL)];

    /// The preset called `name` ([`Methods::PRESETS`], or an alias of [`Methods::ALIASES`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Methods> {
        Self::PRESETS
            .iter()
            .chain(&Self::ALIASES)
            .find(|(n, _)| *n == name)
            .map(|(_, m)| *m)
    }

    /// Whether both methods take a kinematic tree (of the presets, [`Methods::SPATIAL`] only).
    #[must_use]
    pub fn supports_trees(self) -> bool {
        self.mass_matrix.supports_trees() && self.nonlinear_effects.supports_trees()
    }

    /// `Ok` when both methods can run on `p`: call it before running a model that may be a tree.
    ///
    /// # Errors
    /// The first serial-chain-only method (mass matrix, then nonlinear effects) on a tree; the message names
    /// it and the first branching joint.
    pub fn check<S>(self, p: &Params<S>) -> Result<(), MethodError> {
        self.mass_matrix.check(p)?;
        self.nonlinear_effects.check(p)
    }

    /// The preset's name, or `mass+nonlinear-effects` for a combination that is no preset; `aba` for
    /// [`Methods::ABA`], and `…+aba` for another pair with [`ForwardMethod::Aba`].
    #[must_use]
    pub fn name(self) -> String {
        if self == Methods::ABA {
            return ForwardMethod::Aba.name().to_string();
        }
        let pair = Methods {
            forward: ForwardMethod::Ldlt,
            ..self
        };
        let name = Self::PRESETS.iter().find(|(_, m)| *m == pair).map_or_else(
            || {
                format!(
                    "{}+{}",
                    self.mass_matrix.name(),
                    self.nonlinear_effects.name()
                )
            },
            |(n, _)| (*n).to_string(),
        );
        match self.forward {
            ForwardMethod::Ldlt => name,
            ForwardMethod::Aba => format!("{name}+{}", ForwardMethod::Aba.name()),
        }
    }

    /// `M` and `τ − c` together, fixed base.
    pub fn dynamics<S: Scalar>(
        self,
        p: &Params<S>,
        q: &[S],
        qd: &[S],
        loads: &Loads<S>,
    ) -> Dynamics<S> {
        Dynamics {
            mass_matrix: self.mass_matrix.mass_matrix(p, q),
            tau_minus_c: self.nonlinear_effects.tau_minus_c(p, q, qd, loads),
        }
    }

    /// Forward dynamics `q̈ = M⁻¹ (τ − c)`, fixed base: by the branch-free LDLᵀ of [`crate::ldlt`]
    /// on this pair's `M` and `τ − c` ([`ForwardMethod::Ldlt`]), or by the articulated-body algorithm
    /// ([`ForwardMethod::Aba`], [`aba::forward_dynamics`]).
    pub fn forward_dynamics<S: Scalar>(
        self,
        p: &Params<S>,
        q: &[S],
        qd: &[S],
        loads: &Loads<S>,
    ) -> Vec<S> {
        match self.forward {
            ForwardMethod::Ldlt => {
                let d = self.dynamics(p, q, qd, loads);
                crate::ldlt::solve(&crate::ldlt::ldlt(&d.mass_matrix), &d.tau_minus_c)
            }
            ForwardMethod::Aba => aba::forward_dynamics(p, q, qd, loads),
        }
    }

    /// Inverse dynamics: the joint drives `τ` for which `M q̈ + c = τ` holds with the other loads
    /// (`loads.tau` is ignored). With a local-frame nonlinear-effects method, one O(N) pass
    /// ([`rnea::inverse_dynamics`], [`newton_euler::inverse_dynamics`]); otherwise
    /// `τ = M q̈ − (τ − c)(τ = 0)` from this pair's own `M` and `τ − c`.
    pub fn inverse_dynamics<S: Scalar>(
        self,
        p: &Params<S>,
        q: &[S],
        qd: &[S],
        qdd: &[S],
        loads: &Loads<S>,
    ) -> Vec<S> {
        let passive = loads.passive();
        match self.nonlinear_effects {
            NonlinearEffectsMethod::Rnea => return rnea::inverse_dynamics(p, q, qd, qdd, &passive),
            NonlinearEffectsMethod::NewtonEuler => {
                return newton_euler::inverse_dynamics(p, q, qd, qdd, &passive)
            }
            NonlinearEffectsMethod::Recurrent | NonlinearEffectsMethod::KaneDirect => {}
        }
        let d = self.dynamics(p, q, qd, &passive);
        d.mass_matrix
            .iter()
            .zip(d.tau_minus_c)
            .map(|(row, bi)| {
                row.iter()
                    .zip(qdd)
                    .fold(S::zero(), |acc, (aij, x)| acc + aij.clone() * x.clone())
                    - bi
            })
            .collect()
    }
}

impl core::fmt::Display for Methods {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(&self.name())
    }
}
