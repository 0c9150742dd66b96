//! # kanegen-dynamics
//!
//! The second stage of kanegen's pipeline: the dynamics algorithms, each written once and
//! generic over the scalar, so the same source runs on `f64`, `f32`, the research scalars and the
//! counting tracer `Sym` of `kanegen-trace`.
//!
//! - [`scalar`]: the [`Scalar`] trait (no comparison: a fixed model gives a branch-free trace).
//! - [`linalg`] and [`spatial`]: 3-vector and spatial-vector algebra with the paper's counting
//!   conventions.
//! - [`params`]: a model's numbers in a scalar type; [`loads`]: drives, gravity, wrenches;
//!   [`base`]: the fixed or free-floating base and its conventions.
//! - [`algorithms`]: one file per algorithm; [`Methods`] chooses the mass-matrix method, the
//!   nonlinear-effects method and the forward-dynamics method ([`ForwardMethod`]: LDLᵀ or the
//!   articulated-body algorithm) separately.
//! - [`ldlt`]: the branch-free LDLᵀ of forward dynamics; [`metrics`]: error measures.
//! - [`kernels`]: a model's numbers and scratch for the runtime kernels (`kanegen_runtime::compact`),
//!   which the run-time path and the compact form call.
//! - `scalars` (feature `research`): research scalars (dual, compensated, double-double, exact
//!   rationals), a leaf.
//!
//! The specification is the seed paper as written out in `docs/paper.md`; algorithm files cite
//! its equation numbers, or RBDA's.
//!
//! ```
//! use kanegen_dynamics::{Loads, Methods, Params};
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let model = random_chain(&ChainSpec { n: 4, ..Default::default() }, 2);
//! let p = Params::<f64>::new(&model);
//! let (q, qd) = ([0.1, 0.2, 0.3, 0.4], [0.0; 4]);
//! let paper = Methods::RECURRENT.dynamics(&p, &q, &qd, &Loads::default());
//! let spatial = Methods::SPATIAL.dynamics(&p, &q, &qd, &Loads::default());
//! assert!((paper.mass_matrix[1][3] - spatial.mass_matrix[1][3]).abs() < 1e-9);
//! ```
#![warn(missing_docs)]

pub mod algorithms;
pub mod base;
pub mod joint;
pub mod kernels;
pub mod ldlt;
pub mod linalg;
pub mod loads;
pub mod metrics;
pub mod mimic;
pub mod params;
pub mod regroup;
pub mod scalar;
#[cfg(feature = "research")]
pub mod scalars;
pub mod spatial;

pub use algorithms::methods::{
    Dynamics, ForwardMethod, MassMatrixMethod, Methods, NonlinearEffectsMethod,
};
pub use base::{FloatingBase, FloatingState};
pub use loads::{ExternalWrench, LoadFrame, Loads};
pub use params::{FrameParams, JointParams, MethodError, Params};
pub use scalar::{Real, Scalar, Symbolic};
