//! Branch-free LDLᵀ factorization and solve of a symmetric positive definite matrix, generic over
//! the scalar, so that forward dynamics `q̈ = A⁻¹ b` can be traced and unrolled like the rest.
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

// Index loops mirror the formulas (L_ik, y_k) and keep the trace order explicit.
#![allow(clippy::needless_range_loop)]

use crate::scalar::Scalar;

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

/// Factorizes a symmetric positive definite `a` (only the lower triangle is read).
pub fn ldlt<S: Scalar>(a: &[Vec<S>]) -> Ldlt<S> {
    let n = a.len();
    let mut l: Vec<Vec<S>> = (0..n).map(|i| Vec::with_capacity(i)).collect();
    let mut d: Vec<S> = Vec::with_capacity(n);
    let mut d_inv: Vec<S> = Vec::with_capacity(n);
    // Working copy of w[i][k] = L_ik D_k, to avoid recomputing products.
    let mut w: Vec<Vec<S>> = (0..n).map(|i| Vec::with_capacity(i)).collect();
    for j in 0..n {
        // D_j = A_jj − Σ_{k<j} L_jk (L_jk D_k)
        let mut dj = a[j][j].clone();
        for k in 0..j {
            dj = dj - l[j][k].clone() * w[j][k].clone();
        }
        let inv = S::one() / dj.clone();
        for i in (j + 1)..n {
            // L_ij D_j = A_ij − Σ_{k<j} L_ik (L_jk D_k)
            let mut s = a[i][j].clone();
            for k in 0..j {
                s = s - l[i][k].clone() * w[j][k].clone();
            }
            l[i].push(s.clone() * inv.clone());
            w[i].push(s);
        }
        d.push(dj);
        d_inv.push(inv);
    }
    Ldlt { l, d, d_inv }
}

/// Solves `A x = b` with a factorization of `A`.
pub fn solve<S: Scalar>(f: &Ldlt<S>, b: &[S]) -> Vec<S> {
    let n = f.d.len();
    assert_eq!(b.len(), n, "right-hand side has the wrong length");
    // L y = b
    let mut y: Vec<S> = Vec::with_capacity(n);
    for i in 0..n {
        let mut s = b[i].clone();
        for k in 0..i {
            s = s - f.l[i][k].clone() * y[k].clone();
        }
        y.push(s);
    }
    // D z = y, Lᵀ x = z
    let mut x: Vec<S> = y
        .into_iter()
        .zip(&f.d_inv)
        .map(|(yi, di)| yi * di.clone())
        .collect();
    for i in (0..n).rev() {
        for k in (i + 1)..n {
            let t = f.l[k][i].clone() * x[k].clone();
            x[i] = x[i].clone() - t;
        }
    }
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
