//! nalgebra views of the fixed-size arrays that generated code takes and returns, for `f64` and
//! `f32` code alike.
//!
//! ```
//! use kanegen::nalgebra::{to_smatrix, to_svector};
//! let a = to_smatrix([[4.0, 1.0], [1.0, 3.0]]);
//! let b = to_svector([1.0, 2.0]);
//! let x = a.cholesky().unwrap().solve(&b);
//! assert!((a * x - b).norm() < 1e-15);
//! let a32 = to_smatrix([[4.0f32, 1.0], [1.0, 3.0]]);
//! assert_eq!(a32[(0, 1)], 1.0f32);
//! ```

use nalgebra::{SMatrix, SVector, Scalar};

/// `M` as returned by `Name::mass_matrix` (row-major `[[T; N]; N]`) as an nalgebra matrix.
#[must_use]
pub fn to_smatrix<T: Scalar + Copy, const N: usize>(a: [[T; N]; N]) -> SMatrix<T, N, N> {
    SMatrix::from_fn(|r, c| a[r][c])
}

/// A joint-space vector such as `c`, `τ` or `q̈` (`[T; N]`) as an nalgebra vector.
#[must_use]
pub fn to_svector<T: Scalar + Copy, const N: usize>(v: [T; N]) -> SVector<T, N> {
    SVector::from(v)
}

/// An nalgebra vector back into the array the generated functions take.
#[must_use]
pub fn from_svector<T: Scalar + Copy, const N: usize>(v: &SVector<T, N>) -> [T; N] {
    core::array::from_fn(|i| v[i])
}
