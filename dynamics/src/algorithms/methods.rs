//! Which algorithm computes what: the mass-matrix method and the bias method are chosen
//! separately ([`Methods`]), and every fixed-base entry point dispatches here.
//!
//! | mass-matrix method | file | what |
//! |---|---|---|
//! | `recurrent` | `recurrent.rs` | the paper's O(N²) recursion (12)–(16), (20), (14b) exact as R2 |
//! | `recurrent-r1` | `recurrent.rs` | the same with (14b) as R1 (the paper's per-matrix cost + O(N)) |
//! | `kane-direct` | `kane_direct.rs` | the direct Kane sum (9), O(N³) |
//! | `crba-base` | `crba_base.rs` | composite rigid bodies in the paper's base-frame notation |
//! | `crba` | `crba.rs` | Featherstone's composite-rigid-body algorithm in local frames |
//!
//! | bias method | file | what |
//! |---|---|---|
//! | `recurrent` | `recurrent.rs` | the paper's backward recursion (17)–(19), (21) |
//! | `kane-direct` | `kane_direct.rs` | the direct Kane sum (10) |
//! | `rnea` | `rnea.rs` | Featherstone's recursive Newton–Euler algorithm in local frames |
//! | `newton-euler` | `newton_euler.rs` | the classical Newton–Euler algorithm in local frames (3-vectors) |
//!
//! | forward method | file | what |
//! |---|---|---|
//! | `ldlt` | `ldlt.rs` | `q̈ = A⁻¹ b` by a branch-free LDLᵀ of the mass-matrix method's `A` |
//! | `aba` | `aba.rs` | Featherstone's articulated-body algorithm, O(N), no `A` at all |
//!
//! The CLI's `--algorithm` names are presets of the first two ([`Methods::PRESETS`]), all with
//! `ldlt`; [`Methods::ABA`] is the articulated-body algorithm.
//!
//! **Trees.** Only the local-frame methods (`crba`, `rnea`, `newton-euler`, and `aba`) take a
//! kinematic tree; the paper's base-frame methods are serial-chain only
//! ([`MassMatrixMethod::supports_trees`], [`BiasMethod::supports_trees`]). [`Methods::check`]
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
//! ```

use crate::algorithms::kinematics::{self, BodyKinematics};
use crate::algorithms::{aba, crba, crba_base, kane_direct, newton_euler, recurrent, rnea};
use crate::loads::Loads;
pub use crate::params::MethodError;
use crate::params::Params;
use crate::scalar::Scalar;

/// `A` (full symmetric, row-major `a[i][j]`) and `b` of `A q̈ = b`.
#[derive(Clone, Debug)]
pub struct Dynamics<S> {
    /// Generalized inertia matrix, N×N, both triangles filled.
    pub a: Vec<Vec<S>>,
    /// Generalized forces `b = Q − h`.
    pub b: Vec<S>,
}

/// How the generalized inertia matrix `A(q)` is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MassMatrixMethod {
    /// The paper's recurrent algorithm, (14b) as R2 (exact).
    Recurrent,
    /// The paper's recurrent algorithm, (14b) as R1 (the paper's per-matrix cost plus an O(N)
    /// correction).
    RecurrentR1,
    /// The direct Kane sum (9), O(N³).
    KaneDirect,
    /// Composite rigid bodies in the paper's base-frame notation (Stepanenko's baseline).
    CrbaBase,
    /// Featherstone's composite-rigid-body algorithm in local frames (RBDA Table 6.2).
    Crba,
}

impl MassMatrixMethod {
    /// All methods, in report order.
    pub const ALL: [MassMatrixMethod; 5] = [
        MassMatrixMethod::Recurrent,
        MassMatrixMethod::RecurrentR1,
        MassMatrixMethod::KaneDirect,
        MassMatrixMethod::CrbaBase,
        MassMatrixMethod::Crba,
    ];

    /// Its name in reports and generated headers.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MassMatrixMethod::Recurrent => "recurrent",
            MassMatrixMethod::RecurrentR1 => "recurrent-r1",
            MassMatrixMethod::KaneDirect => "kane-direct",
            MassMatrixMethod::CrbaBase => "crba-base",
            MassMatrixMethod::Crba => "crba",
        }
    }

    /// The method called `name` ([`MassMatrixMethod::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Whether the method takes a kinematic tree: only the local-frame [`MassMatrixMethod::Crba`];
    /// the paper's base-frame methods are serial-chain only.
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

    /// `A` from the base-frame quantities of eq. (1), (2), (6) (fixed base, or the free-floating
    /// base's virtual-joint extension); `None` for [`MassMatrixMethod::Crba`], which works in
    /// local frames from `q`.
    pub fn from_base_frame<S: Scalar>(self, kin: &[BodyKinematics<S>]) -> Option<Vec<Vec<S>>> {
        match self {
            MassMatrixMethod::Recurrent => {
                Some(recurrent::mass_matrix_base(kin, recurrent::Variant::R2))
            }
            MassMatrixMethod::RecurrentR1 => {
                Some(recurrent::mass_matrix_base(kin, recurrent::Variant::R1))
            }
            MassMatrixMethod::KaneDirect => Some(kane_direct::mass_matrix_base(kin)),
            MassMatrixMethod::CrbaBase => Some(crba_base::mass_matrix_base(kin)),
            MassMatrixMethod::Crba => None,
        }
    }

    /// The generalized inertia matrix `A(q)`, fixed base.
    ///
    /// # Panics
    /// A serial-chain-only method on a tree ([`MassMatrixMethod::check`]).
    pub fn mass_matrix<S: Scalar>(self, p: &Params<S>, q: &[S]) -> Vec<Vec<S>> {
        match self {
            MassMatrixMethod::Crba => crba::mass_matrix(p, q),
            base_frame => {
                p.assert_chain(base_frame.name());
                base_frame
                    .from_base_frame(&kinematics::base_frame(p, q))
                    .expect("every method but the CRBA starts from base-frame quantities")
            }
        }
    }
}

/// How the generalized forces `b = Q − h` (and so the nonlinear effects `c = −b(τ = 0)`) are
/// computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BiasMethod {
    /// The paper's base-frame backward recursion (17)–(19), (21).
    Recurrent,
    /// The direct Kane sum (10).
    KaneDirect,
    /// Featherstone's recursive Newton–Euler algorithm in local frames (RBDA Table 5.1).
    Rnea,
    /// The classical Newton–Euler algorithm in local frames with 3-vectors (Luh–Walker–Paul, in
    /// Khalil's customized form): no linear velocities.
    NewtonEuler,
}

impl BiasMethod {
    /// All methods, in report order.
    pub const ALL: [BiasMethod; 4] = [
        BiasMethod::Recurrent,
        BiasMethod::KaneDirect,
        BiasMethod::Rnea,
        BiasMethod::NewtonEuler,
    ];

    /// Its name in reports and generated headers.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            BiasMethod::Recurrent => "recurrent",
            BiasMethod::KaneDirect => "kane-direct",
            BiasMethod::Rnea => "rnea",
            BiasMethod::NewtonEuler => "newton-euler",
        }
    }

    /// The method called `name` ([`BiasMethod::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Whether the method takes a kinematic tree: the local-frame [`BiasMethod::Rnea`] and
    /// [`BiasMethod::NewtonEuler`]; the paper's base-frame methods are serial-chain only.
    #[must_use]
    pub fn supports_trees(self) -> bool {
        matches!(self, BiasMethod::Rnea | BiasMethod::NewtonEuler)
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

    /// The generalized forces `b(q, q̇, loads) = Q − h`, fixed base.
    ///
    /// # Panics
    /// A serial-chain-only method on a tree ([`BiasMethod::check`]).
    pub fn bias<S: Scalar>(self, p: &Params<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
        match self {
            BiasMethod::Recurrent => recurrent::bias(p, q, qd, loads),
            BiasMethod::KaneDirect => kane_direct::bias(p, q, qd, loads),
            BiasMethod::Rnea => rnea::bias(p, q, qd, loads),
            BiasMethod::NewtonEuler => newton_euler::bias(p, q, qd, loads),
        }
    }
}

/// How forward dynamics `q̈ = A⁻¹ b` is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ForwardMethod {
    /// `A` and `b` by the mass-matrix and bias methods, then the branch-free LDLᵀ of
    /// [`crate::ldlt`].
    Ldlt,
    /// Featherstone's articulated-body algorithm ([`aba`], RBDA Table 7.1): O(N), reads neither
    /// the mass-matrix nor the bias method; any kinematic tree.
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

/// A mass-matrix method, a bias method and a forward-dynamics method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Methods {
    /// How `A` is computed.
    pub mass_matrix: MassMatrixMethod,
    /// How `b` is computed.
    pub bias: BiasMethod,
    /// How forward dynamics is computed ([`ForwardMethod::Ldlt`] in every preset).
    pub forward: ForwardMethod,
}

impl Methods {
    /// `recurrent`: the paper's recurrent algorithm for both.
    pub const RECURRENT: Methods = Methods {
        mass_matrix: MassMatrixMethod::Recurrent,
        bias: BiasMethod::Recurrent,
        forward: ForwardMethod::Ldlt,
    };
    /// `recurrent-r1`: (14b) as R1, with the paper's bias recursion.
    pub const RECURRENT_R1: Methods = Methods {
        mass_matrix: MassMatrixMethod::RecurrentR1,
        bias: BiasMethod::Recurrent,
        forward: ForwardMethod::Ldlt,
    };
    /// `kane-direct`: the direct sums (9) and (10).
    pub const KANE_DIRECT: Methods = Methods {
        mass_matrix: MassMatrixMethod::KaneDirect,
        bias: BiasMethod::KaneDirect,
        forward: ForwardMethod::Ldlt,
    };
    /// `crba-base`: base-frame composite rigid bodies, with the paper's bias recursion.
    pub const CRBA_BASE: Methods = Methods {
        mass_matrix: MassMatrixMethod::CrbaBase,
        bias: BiasMethod::Recurrent,
        forward: ForwardMethod::Ldlt,
    };
    /// `spatial`: Featherstone's CRBA and RNEA in local frames.
    pub const SPATIAL: Methods = Methods {
        mass_matrix: MassMatrixMethod::Crba,
        bias: BiasMethod::Rnea,
        forward: ForwardMethod::Ldlt,
    };

    /// `aba`: forward dynamics by the articulated-body algorithm; `A` and `b`, when asked for,
    /// by the CRBA and the RNEA (as [`Methods::SPATIAL`]). Not a preset.
    pub const ABA: Methods = Methods {
        mass_matrix: MassMatrixMethod::Crba,
        bias: BiasMethod::Rnea,
        forward: ForwardMethod::Aba,
    };

    /// The presets, by the CLI's `--algorithm` names, in report order.
    pub const PRESETS: [(&'static str, Methods); 5] = [
        ("recurrent", Methods::RECURRENT),
        ("recurrent-r1", Methods::RECURRENT_R1),
        ("kane-direct", Methods::KANE_DIRECT),
        ("crba-base", Methods::CRBA_BASE),
        ("spatial", Methods::SPATIAL),
    ];

    /// The presets' methods ([`Methods::PRESETS`] without the names).
    pub const ALL: [Methods; 5] = [
        Methods::RECURRENT,
        Methods::RECURRENT_R1,
        Methods::KANE_DIRECT,
        Methods::CRBA_BASE,
        Methods::SPATIAL,
    ];

    /// The preset called `name` ([`Methods::PRESETS`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Methods> {
        Self::PRESETS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, m)| *m)
    }

    /// Whether both methods take a kinematic tree (of the presets, [`Methods::SPATIAL`] only).
    #[must_use]
    pub fn supports_trees(self) -> bool {
        self.mass_matrix.supports_trees() && self.bias.supports_trees()
    }

    /// `Ok` when both methods can run on `p`: call it before running a model that may be a tree.
    ///
    /// # Errors
    /// The first serial-chain-only method (mass matrix, then bias) on a tree; the message names
    /// it and the first branching joint.
    pub fn check<S>(self, p: &Params<S>) -> Result<(), MethodError> {
        self.mass_matrix.check(p)?;
        self.bias.check(p)
    }

    /// The preset's name, or `mass+bias` for a combination that is no preset; `aba` for
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
            || format!("{}+{}", self.mass_matrix.name(), self.bias.name()),
            |(n, _)| (*n).to_string(),
        );
        match self.forward {
            ForwardMethod::Ldlt => name,
            ForwardMethod::Aba => format!("{name}+{}", ForwardMethod::Aba.name()),
        }
    }

    /// `A` and `b` together, fixed base.
    pub fn dynamics<S: Scalar>(
        self,
        p: &Params<S>,
        q: &[S],
        qd: &[S],
        loads: &Loads<S>,
    ) -> Dynamics<S> {
        Dynamics {
            a: self.mass_matrix.mass_matrix(p, q),
            b: self.bias.bias(p, q, qd, loads),
        }
    }

    /// Forward dynamics `q̈ = A⁻¹ b`, fixed base: by the branch-free LDLᵀ of [`crate::ldlt`] on
    /// this pair's `A` and `b` ([`ForwardMethod::Ldlt`]), or by the articulated-body algorithm
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
                crate::ldlt::solve(&crate::ldlt::ldlt(&d.a), &d.b)
            }
            ForwardMethod::Aba => aba::forward_dynamics(p, q, qd, loads),
        }
    }

    /// Inverse dynamics: the joint drives `τ` for which `A q̈ = b(q, q̇, τ)` holds (`loads.tau` is
    /// ignored). With a local-frame bias method, one O(N) pass ([`rnea::inverse_dynamics`],
    /// [`newton_euler::inverse_dynamics`]); otherwise `τ = A q̈ − b(q, q̇, τ = 0)` from this pair's own `A` and `b`.
    pub fn inverse_dynamics<S: Scalar>(
        self,
        p: &Params<S>,
        q: &[S],
        qd: &[S],
        qdd: &[S],
        loads: &Loads<S>,
    ) -> Vec<S> {
        let passive = loads.passive();
        match self.bias {
            BiasMethod::Rnea => return rnea::inverse_dynamics(p, q, qd, qdd, &passive),
            BiasMethod::NewtonEuler => {
                return newton_euler::inverse_dynamics(p, q, qd, qdd, &passive)
            }
            BiasMethod::Recurrent | BiasMethod::KaneDirect => {}
        }
        let d = self.dynamics(p, q, qd, &passive);
        d.a.iter()
            .zip(d.b)
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
