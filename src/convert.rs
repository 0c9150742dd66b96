//! nalgebra views of the fixed-size arrays that generated code returns.
//!
//! ```
//! use kanegen::convert::{to_smatrix, to_svector};
//! let a = to_smatrix([[4.0, 1.0], [1.0, 3.0]]);
//! let b = to_svector([1.0, 2.0]);
//! let x = a.cholesky().unwrap().solve(&b);
//! assert!((a * x - b).norm() < 1e-15);
//! ```

use nalgebra::{SMatrix, SVector};

/// `A` as returned by `Name::mass_matrix` (row-major `[[f64; N]; N]`) as an nalgebra matrix.
#[must_use]
pub fn to_smatrix<const N: usize>(a: [[f64; N]; N]) -> SMatrix<f64, N, N> {
    SMatrix::from_fn(|r, c| a[r][c])
}

/// A vector such as `b`, `τ` or `q̈` (`[f64; N]`) as an nalgebra vector.
#[must_use]
pub fn to_svector<const N: usize>(v: [f64; N]) -> SVector<f64, N> {
    SVector::from(v)
}

/// An nalgebra vector back into the array the generated functions take.
#[must_use]
pub fn from_svector<const N: usize>(v: &SVector<f64, N>) -> [f64; N] {
    core::array::from_fn(|i| v[i])
}

#[cfg(test)]
mod tests {
    use super::*;
    use kanegen_generated::ssrms::Ssrms;

    #[test]
    fn generated_forward_dynamics_agrees_with_an_nalgebra_solve() {
        let q = [0.1, -0.2, 0.3, -0.4, 0.5, -0.6, 0.7];
        let qd = [0.05, -0.04, 0.03, -0.02, 0.01, 0.02, -0.03];
        let tau = [10.0, -5.0, 3.0, 0.0, 1.0, -2.0, 0.5];
        let a = to_smatrix(Ssrms::mass_matrix(&q));
        assert_eq!(a[(1, 3)], Ssrms::mass_matrix(&q)[1][3]);
        let b = to_svector(Ssrms::bias(&q, &qd, &tau));
        let qdd = a.cholesky().expect("A is SPD").solve(&b);
        let gen = Ssrms::forward_dynamics(&q, &qd, &tau);
        let err = (to_svector(gen) - qdd).amax() / qdd.amax();
        assert!(err < 1e-10, "{err:e}");
        assert_eq!(from_svector(&qdd).len(), 7);
    }
}
