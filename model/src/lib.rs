//! # kanegen-model
//!
//! The first stage of kanegen's pipeline (model → trace → emit / evaluate → report): the
//! validated description of a robot as plain data (Pinocchio's model/data split), its readers
//! and writer, and the few edits a model supports.
//!
//! - [`Model`]: the base and the joints, each moving one body ([`Joint`], [`Inertial`],
//!   [`Placement`]); built only through [`Model::new`], which validates every number.
//! - [`io`]: URDF and kanegen's TOML format in, TOML out.
//! - [`Inertial::merge`]: the one parallel-axis merge (fixed links, locked joints, payloads).
//! - `random` (feature `random`): seeded random chains, trees and states for tests, benchmarks
//!   and traces.
//! - [`bounds`]: the magnitude bounds every reader checks, so products stay finite.
//! - [`canonical`]: the same robot in frames that make its dynamics cheap (every axis `z`).
//!
//! ```
//! let model = kanegen_model::io::parse_toml(r#"
//!     name = "pendulum"
//!     [[joint]]
//!     type = "revolute"
//!     axis = [0.0, 0.0, 1.0]
//!     [joint.body]
//!     mass = 1.0
//!     inertia = { ixx = 0.01, iyy = 0.01, izz = 0.01 }
//! "#).unwrap();
//! assert_eq!(model.dof(), 1);
//! let locked_free = model.lock_joint(0, 0.3);
//! assert!(locked_free.is_err(), "a model needs at least one joint");
//! ```
#![warn(missing_docs)]

pub mod bounds;
pub mod canonical;
pub mod inertial;
pub mod io;
mod lock;
mod model;
pub mod placement;
#[cfg(feature = "random")]
pub mod random;

pub use inertial::{validate_inertial, validate_inertial_with, Inertial};
pub use model::{BaseKind, Frame, Joint, JointKind, Model, ModelError, Validation};
pub use placement::Placement;
