//! # kanegen-core
//!
//! The core of kanegen: validated chain models ([`model`], read by [`io`]), the scalar abstraction
//! ([`scalar`]) with the counting symbolic tracer ([`sym`]), generic 3-vector algebra ([`linalg`]),
//! and the dynamics algorithms ([`algorithms`]), each written once and generic over the scalar.
//!
//! The specification is the seed paper as rendered in `paper_en.md`; algorithm files cite its
//! equation numbers.
#![warn(missing_docs)]

pub mod algorithms;
pub mod compensated;
pub mod dual;
pub mod exact;
pub mod io;
pub mod ldlt;
pub mod linalg;
pub mod metrics;
pub mod model;
pub mod random;
pub mod scalar;
pub mod sym;
pub mod wide;

pub use algorithms::{Algorithm, Dynamics, ExternalWrench, LoadFrame, Loads};
pub use model::{
    Chain, ChainParams, Inertial, Joint, JointKind, ModelError, Placement, Validation,
};
pub use scalar::{Real, Scalar};
