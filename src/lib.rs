//! # kanegen
//!
//! Equations of motion of space manipulators `A(q) q̈ = b(q, q̇)`: the paper's recurrent O(N²)
//! algorithm and its baselines, generic over the scalar; a counting symbolic tracer; and (later)
//! code generation and simulation. This crate is the user-facing facade and the `kanegen` CLI.
#![warn(missing_docs)]

pub mod commands;
pub mod integrate;
pub mod poly;
pub mod scene;
pub mod simulate;
pub mod simulate_plot;
pub mod states;
pub mod table1;

pub use kanegen_core::*;
