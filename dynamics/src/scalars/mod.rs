//! Research scalars: numbers that measure what precision costs. Nothing in the algorithms uses
//! them; they implement [`crate::Scalar`] so every algorithm runs on them unchanged.
//!
//! | module | scalar | what |
//! |---|---|---|
//! | [`dual`] | `Dual` | forward-mode derivatives (`x + ε ẋ`) |
//! | [`compensated`] | `Compensated` | f64 carrying its own rounding error (TwoSum/TwoProduct) |
//! | [`wide`] | `Wide` | double-double (about 32 digits) |
//! | [`exact`] | `Exact` | exact rationals with Pythagorean angles, loss of exactness flagged |

pub mod compensated;
pub mod dual;
pub mod exact;
pub mod wide;
