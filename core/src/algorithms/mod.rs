//! The dynamics algorithms, one per file, each generic over the scalar.
//!
//! Every algorithm computes the generalized inertia matrix `A(q)` and the generalized force vector
//! `b(q, q̇, loads) = Q − h` of `A q̈ = b` (paper eq. (8)): `Q` the joint drives plus the generalized
//! external loads and gravity, `h` the velocity-product terms.
//!
//! | name (CLI)      | file               | what                                                      |
//! |-----------------|--------------------|-----------------------------------------------------------|
//! | `recurrent`     | `recurrent.rs`     | the paper's O(N²) recursion (1)–(21), (14b) exact as R2    |
//! | `recurrent-r1`  | `recurrent.rs`     | the same with (14b) as R1 (paper's per-matrix cost + O(N)) |
//! | `kane-direct`   | `kane_direct.rs`   | the direct sums (9)–(11), O(N³)                           |
//! | `crba-base`     | `crba_base.rs`     | composite-rigid-body algorithm in base-frame notation     |
//! | `spatial`       | `spatial.rs`       | Featherstone's local-frame spatial CRBA + RNEA            |
//!
//! A free-floating base (6 + N speeds, issue #5) is in [`floating`]: the first four algorithms run
//! on the base-as-six-virtual-joints extension of their base-frame inputs, `spatial` has its own
//! floating-base CRBA + RNEA ([`spatial::floating_dynamics`]).

use crate::linalg::Vec3;
use crate::model::ChainParams;
use crate::scalar::Scalar;

/// Which frame an external wrench is expressed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadFrame {
    /// The frame of the body it acts on.
    Body,
    /// The base (inertial) frame.
    Base,
}

/// An external wrench on one body: a force applied at the body frame origin `O_j` and a moment,
/// both expressed in `frame` (paper eq. (7): `f^E_j`, `m^E_j`).
#[derive(Clone, Debug)]
pub struct ExternalWrench<S> {
    /// Index of the body (0-based; body `j` is moved by joint `j`).
    pub body: usize,
    /// The frame of `force` and `moment`.
    pub frame: LoadFrame,
    /// Force at `O_j`.
    pub force: Vec3<S>,
    /// Moment (about `O_j`).
    pub moment: Vec3<S>,
}

/// The applied loads of a call: each effect is present only when given, so a traced scene without
/// gravity or loads has no term for them.
#[derive(Clone, Debug)]
pub struct Loads<S> {
    /// Joint drive torques (revolute) or forces (prismatic), `m^J`, `f^J` of eq. (10).
    pub tau: Option<Vec<S>>,
    /// Uniform gravitational acceleration in the base frame.
    pub gravity: Option<Vec3<S>>,
    /// External wrenches on bodies.
    pub external: Vec<ExternalWrench<S>>,
}

impl<S> Default for Loads<S> {
    fn default() -> Self {
        Loads {
            tau: None,
            gravity: None,
            external: Vec::new(),
        }
    }
}

/// `A` (full symmetric, row-major `a[i][j]`) and `b` of `A q̈ = b`.
#[derive(Clone, Debug)]
pub struct Dynamics<S> {
    /// Generalized inertia matrix, N×N, both triangles filled.
    pub a: Vec<Vec<S>>,
    /// Generalized forces `b = Q − h`.
    pub b: Vec<S>,
}

/// The algorithms kanegen implements, by their CLI names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Algorithm {
    /// The paper's recurrent algorithm, (14b) as R2 (exact).
    Recurrent,
    /// The paper's recurrent algorithm, (14b) as R1 (paper's per-matrix cost plus an O(N) correction).
    RecurrentR1,
    /// The direct Kane sums (9)–(11), O(N³).
    KaneDirect,
    /// Composite-rigid-body algorithm in the paper's base-frame notation (Stepanenko's baseline).
    CrbaBase,
    /// Featherstone's spatial-vector CRBA + RNEA in local frames.
    Spatial,
}

impl Algorithm {
    /// All algorithms, in report order.
    pub const ALL: [Algorithm; 5] = [
        Algorithm::Recurrent,
        Algorithm::RecurrentR1,
        Algorithm::KaneDirect,
        Algorithm::CrbaBase,
        Algorithm::Spatial,
    ];

    /// The CLI name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Recurrent => "recurrent",
            Algorithm::RecurrentR1 => "recurrent-r1",
            Algorithm::KaneDirect => "kane-direct",
            Algorithm::CrbaBase => "crba-base",
            Algorithm::Spatial => "spatial",
        }
    }

    /// Parses a CLI name.
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == s)
    }

    /// The generalized inertia matrix `A(q)`.
    pub fn mass_matrix<S: Scalar>(self, p: &ChainParams<S>, q: &[S]) -> Vec<Vec<S>> {
        match self {
            Algorithm::Recurrent => recurrent::mass_matrix(p, q, recurrent::Variant::R2),
            Algorithm::RecurrentR1 => recurrent::mass_matrix(p, q, recurrent::Variant::R1),
            Algorithm::KaneDirect => kane_direct::mass_matrix(p, q),
            Algorithm::CrbaBase => crba_base::mass_matrix(p, q),
            Algorithm::Spatial => spatial::mass_matrix(p, q),
        }
    }

    /// The generalized forces `b(q, q̇, loads) = Q − h`.
    pub fn bias<S: Scalar>(
        self,
        p: &ChainParams<S>,
        q: &[S],
        qd: &[S],
        loads: &Loads<S>,
    ) -> Vec<S> {
        match self {
            Algorithm::Recurrent | Algorithm::RecurrentR1 => recurrent::bias(p, q, qd, loads),
            Algorithm::KaneDirect => kane_direct::bias(p, q, qd, loads),
            Algorithm::CrbaBase => crba_base::bias(p, q, qd, loads),
            Algorithm::Spatial => spatial::bias(p, q, qd, loads),
        }
    }

    /// `A` and `b` together.
    pub fn dynamics<S: Scalar>(
        self,
        p: &ChainParams<S>,
        q: &[S],
        qd: &[S],
        loads: &Loads<S>,
    ) -> Dynamics<S> {
        Dynamics {
            a: self.mass_matrix(p, q),
            b: self.bias(p, q, qd, loads),
        }
    }
}

impl Algorithm {
    /// Forward dynamics `q̈ = A⁻¹ b`, by the branch-free LDLᵀ of [`crate::ldlt`].
    pub fn forward_dynamics<S: Scalar>(
        self,
        p: &ChainParams<S>,
        q: &[S],
        qd: &[S],
        loads: &Loads<S>,
    ) -> Vec<S> {
        let d = self.dynamics(p, q, qd, loads);
        crate::ldlt::solve(&crate::ldlt::ldlt(&d.a), &d.b)
    }

    /// Inverse dynamics: the joint drives `τ` for which `A q̈ = b(q, q̇, τ)` holds, i.e.
    /// `τ = A q̈ − b(q, q̇, τ = 0)`; `loads.tau` is ignored.
    pub fn inverse_dynamics<S: Scalar>(
        self,
        p: &ChainParams<S>,
        q: &[S],
        qd: &[S],
        qdd: &[S],
        loads: &Loads<S>,
    ) -> Vec<S> {
        let passive = Loads {
            tau: None,
            ..loads.clone()
        };
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

impl core::fmt::Display for Algorithm {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

pub mod crba_base;
pub mod floating;
pub mod kane_direct;
pub mod kinematics;
pub mod recurrent;
pub mod spatial;
