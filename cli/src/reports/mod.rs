//! Reports computed from several library calls.

pub mod accuracy;
