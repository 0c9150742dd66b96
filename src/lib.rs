//! # kanegen
//!
//! Equations of motion of space manipulators `A(q) q̈ = b(q, q̇)`: the paper's recurrent O(N²)
//! algorithm and its baselines, generic over the scalar; a counting symbolic tracer; and (later)
//! code generation and simulation. This crate is the user-facing facade and the `kanegen` CLI.
#![warn(missing_docs)]

// `::kanegen::…` paths emitted by `dynamics!` resolve inside this crate too (src/accuracy/generated.rs).
extern crate self as kanegen;

pub mod accuracy;
pub mod commands;
pub mod convert;
pub mod integrate;
pub mod poly;
pub mod scene;
pub mod simulate;
pub mod simulate_plot;
pub mod states;
pub mod table1;

pub use kanegen_core::*;

/// Unrolled, allocation-free dynamics of a fixed model, generated at compile time; see
/// [`kanegen_macros::dynamics!`] and the README section "Code generation".
///
/// ```
/// kanegen::dynamics!(TwoLink, "models/two_link.toml");
/// let a = TwoLink::mass_matrix(&[0.1, 0.2]);
/// assert_eq!(TwoLink::N, 2);
/// assert_eq!(a[0][1], a[1][0]);
/// ```
pub use kanegen_macros::dynamics;

/// Support for the code emitted by [`dynamics!`]; not a public API.
#[doc(hidden)]
pub mod __private {
    pub use libm;
}
