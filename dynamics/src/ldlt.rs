//! Branch-free LDLᵀ factorization and solve of a symmetric positive definite matrix, generic over
//! the scalar, so that forward dynamics `q̈ = A⁻¹ b` can be traced and unrolled like the rest:
//! `Vec` conveniences around the allocation-free [`factor_in_place`] and [`solve_in_place`] of
//! `kanegen_runtime::ldlt`, which do every operation.
//!
//! No pivoting (A is SPD, so none is needed) and no comparisons: a fixed `N` gives a straight-line
//! trace. Each pivot is inverted once (`N` divisions); everything else is multiplication.
//!
//! ```
//! use kanegen_dynamics::ldlt::{ldlt, solve};
//! let a: Vec<Vec<f64>> = vec![vec![4.0, 2.0], vec![2.0, 3.0]];
//! let f = ldlt(&a);
//! let x = solve(&f, &[2.0, 1.0]);
//! assert!((4.0 * x[0] + 2.0 * x[1] - 2.0).abs() < 1e-15 && (2.0 * x[0] + 3.0 * x[1] - 1.0).abs() < 1e-15);
//! ```

use crate::scalar::Scalar;
pub use kanegen_runtime::ldlt::{factor_in_place, solve_in_place, ShortBuffer};

/// `A = L D Lᵀ`: unit lower-triangular `L` (strictly-lower part stored row-wise), the pivots `D`
/// and their inverses.
#[derive(Clone, Debug)]
pub struct Ldlt<S> {
    /// `l[i][k]` for `k < i`.
    pub l: Vec<Vec<S>>,
    /// Pivots `D_j` (all positive for SPD `A`).
    pub d: Vec<S>,
    /// `1 / D_j`.
    pub d_inv: Vec<S>,
}

/// Factorizes a symmetric positive definite `a` (only the lower triangle is read) by
/// [`factor_in_place`] on a row-major copy.
pub fn ldlt<S: Scalar>(a: &[Vec<S>]) -> Ldlt<S> {
    let n = a.len();
    let mut m: Vec<S> = a.iter().flat_map(|row| row[..n].iter().cloned()).collect();
    let mut d_inv: Vec<S> = (0..n).map(|_| S::zero()).collect();
    factor_in_place(&mut m, n, &mut d_inv).expect("buffers of n² and n entries");
    Ldlt {
        l: (0..n)
            .map(|i| (0..i).map(|k| m[i * n + k].clone()).collect())
            .collect(),
        d: (0..n).map(|j| m[j * n + j].clone()).collect(),
        d_inv,
    }
}

/// Solves `A x = b` with a factorization of `A`, by [`solve_in_place`] on a copy of `b`.
pub fn solve<S: Scalar>(f: &Ldlt<S>, b: &[S]) -> Vec<S> {
    let n = f.d.len();
    assert_eq!(b.len(), n, "right-hand side has the wrong length");
    let mut m: Vec<S> = (0..n * n).map(|_| S::zero()).collect();
    for (i, row) in f.l.iter().enumerate() {
        for (k, x) in row.iter().enumerate() {
            m[i * n + k] = x.clone();
        }
    }
    let mut x = b.to_vec();
    solve_in_place(&m, n, &f.d_inv, &mut x).expect("buffers of n² and n entries");
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    #[test]
    fn solves_random_spd_systems_like_cholesky() {
        let mut rng = kanegen_model::random::rng(3);
        for n in 1..=12 {
            let m = DMatrix::from_vec(
                n,
                n,
                kanegen_model::random::random_vec(&mut rng, n * n, 1.0),
            );
            let a = &m * m.transpose() + DMatrix::identity(n, n) * 0.5;
            let b = kanegen_model::random::random_vec(&mut rng, n, 1.0);
            let rows: Vec<Vec<f64>> = (0..n)
                .map(|i| (0..n).map(|j| a[(i, j)]).collect())
                .collect();
            let f = ldlt(&rows);
            assert!(f.d.iter().all(|&d| d > 0.0));
            let x = solve(&f, &b);
            let want = a
                .clone()
                .cholesky()
                .unwrap()
                .solve(&nalgebra::DVector::from_vec(b.clone()));
            for i in 0..n {
                assert!(
                    (x[i] - want[i]).abs() < 1e-10 * (1.0 + want[i].abs()),
                    "n={n} i={i}"
                );
            }
        }
    }
}
