//! kanegen's `no_std` runtime: what every other part of kanegen runs on, written once.
//!
//! It sits at the bottom of the crate graph and depends on nothing of kanegen's (only `libm` and `wide`),
//! so the simulator (`kanegen-sim`), the run-time path (`kanegen-dynamics`), the code that
//! `dynamics!` and `scene!` emit (through the facade, `kanegen::runtime`) and the checked-in
//! generated files (`kanegen-generated`) all call the same code:
//!
//! - [`scalar`]: the [`Scalar`](scalar::Scalar) trait every algorithm is generic over (`f64`,
//!   `f32`, research scalars, and the tracer `Sym`, which counts what a kernel does).
//! - [`compact`]: the compact form's kernels (CRBA, RNEA, ABA as loops over a model's tables).
//! - [`composed`]: forward-dynamics derivatives composed from a generated type's own functions.
//! - [`coupling`]: mimic joints' constant coupling of the full joint list to the independent
//!   coordinates (expanding the state, reducing `M`, vectors and derivatives).
//! - [`ode`]: the integrators (RK4, Dormand–Prince 5(4), Rodas4, the Lie-group implicit
//!   midpoint rule) over slices with caller-provided scratch, for the simulator and `scene!`.
//! - [`sincos`]: the table sine–cosine of generated `f64` code; [`fma`]: its fused multiply-add.
//! - [`lanes`]: the [`Lanes`](lanes::Lanes) trait of generated `NAME_lanes` functions, which
//!   evaluate several states per call on SIMD vector types (`wide`'s), lane by lane bit for bit
//!   the scalar function, and [`Lane`](lanes::Lane), a lane type as the [`Scalar`](scalar::Scalar)
//!   of the compact kernels and the composed loops.
//! - [`scene`]: a scene's right-hand side (drives, damping, friction, wrenches, rotor inertia,
//!   flexible joints, a free-floating base's kinematics) over a dynamics provider, written once
//!   for the interpreted simulator and `scene!`.
//! - `par` (feature `rayon`; targets with the standard library): a batch split across threads, each thread running a
//!   generated `NAME_batch` on its chunk of the states, and `par::install` for a loop of batches.
//! - [`ldlt`]: LDLᵀ factorization and solve over slices, allocating nothing.
//! - [`inertia`]: the parallel-axis shift of a rigid body's inertia.
#![no_std]
#![warn(missing_docs)]

#[cfg(feature = "std")]
extern crate std;

pub mod compact;
pub mod composed;
pub mod coupling;
pub mod fma;
pub mod inertia;
pub mod lanes;
pub mod ldlt;
pub mod ode;
#[cfg(feature = "rayon")]
pub mod par;
pub mod scalar;
pub mod scene;
pub mod sincos;

pub use scalar::{Real, Ring, Scalar, Symbolic};
