//! The scalar abstraction every algorithm is written against: [`Scalar`], defined in
//! `kanegen-runtime` (the bottom of the crate graph, so the runtime's kernels are generic over
//! it too) and re-exported here.

pub use kanegen_runtime::scalar::{Real, Scalar, Symbolic};

/// Converts a slice of `f64` into scalars by [`Scalar::constant`].
pub fn constants<S: Scalar>(xs: &[f64]) -> Vec<S> {
    xs.iter().map(|&x| S::constant(x)).collect()
}
