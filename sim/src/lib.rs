//! # kanegen-sim
//!
//! The evaluate stage for motion: scene files (a model, its base, the effects it names, drives,
//! initial state and integrator settings, [`scene`]: the `kanegen-scene` crate, re-exported),
//! the integrators ([`integrate`]: RK4, Dormand–Prince 5(4), the Lie-group implicit midpoint rule,
//! the stiff Rodas4, those of `kanegen_runtime::ode` with heap scratch),
//! flexible joints ([`flexible`], Spong 1987), and the simulation loop with its energy and
//! momentum monitors ([`simulate`]), payload capture and release ([`events`]), and a watch of the
//! generalized Jacobian's dynamic singularities ([`singularity`]), and sweeps: a scene run many
//! times over drawn or gridded numbers, in shards that merge exactly ([`sweep`]). Only the effects a scene names
//! enter the equations. Plots and files are the CLI's.
#![warn(missing_docs)]

pub mod events;
pub use kanegen_scene::flexible;
pub mod integrate;
pub mod linearize;
pub mod monitors;
pub mod provider;
pub use kanegen_scene as scene;
pub mod simulate;
pub mod singularity;
pub mod sinks;
pub mod sweep;
pub mod system;
