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
    let mut m: Vec<S> = a.iter().flat_map(|row| row[..n].iter().cloned()).collect();
    let mut d_inv: Vec<S> = (0..n).map(|_| S::zero()).collect();
    factor_in_place(&mut m, n, &mut d_inv);
    Ldlt {
        l: (0..n)
            .map(|i| (0..i).map(|k| m[i * n + k].clone()).collect())
            .collect(),
        d: (0..n).map(|j| m[j * n + j].clone()).collect(),
        d_inv,
    }
}

/// [`ldlt`] in place, allocating nothing: `a` is the row-major `n × n` matrix (lower triangle
/// read). On return its strict lower triangle holds `L`, its diagonal the pivots `D_j`, its
/// strict upper triangle the products `L_ik D_k` (at `(k, i)`), and `d_inv` the `1 / D_j`.
/// The operations, in order, of [`ldlt`] (which calls it).
pub fn factor_in_place<S: Scalar>(a: &mut [S], n: usize, d_inv: &mut [S]) {
    assert!(
        a.len() >= n * n && d_inv.len() >= n,
        "ldlt: buffers too short"
    );
    for j in 0..n {
        // D_j = A_jj − Σ_{k<j} L_jk (L_jk D_k)
        let mut dj = a[j * n + j].clone();
        for k in 0..j {
            dj = dj - a[j * n + k].clone() * a[k * n + j].clone();
        }
        let inv = S::one() / dj.clone();
        for i in (j + 1)..n {
            // L_ij D_j = A_ij − Σ_{k<j} L_ik (L_jk D_k)
            let mut s = a[i * n + j].clone();
            for k in 0..j {
                s = s - a[i * n + k].clone() * a[k * n + j].clone();
            }
            a[i * n + j] = s.clone() * inv.clone();
            a[j * n + i] = s;
        }
        a[j * n + j] = dj;
        d_inv[j] = inv;
    }
}

/// Solves `A x = b` with a factorization of `A`.
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
    solve_in_place(&m, n, &f.d_inv, &mut x);
    x
}

/// [`solve`] in place, allocating nothing: `x` holds `b` on entry and `A⁻¹ b` on return; `l` and
/// `d_inv` as [`factor_in_place`] leaves them (only the strict lower triangle of `l` is read).
/// The operations, in order, of [`solve`] (which calls it).
pub fn solve_in_place<S: Scalar>(l: &[S], n: usize, d_inv: &[S], x: &mut [S]) {
    assert!(
        l.len() >= n * n && d_inv.len() >= n && x.len() == n,
        "ldlt: buffers too short"
    );
    // L y = b
    for i in 0..n {
        for k in 0..i {
            let t = l[i * n + k].clone() * x[k].clone();
            x[i] = x[i].clone() - t;
        }
    }
    // D z = y, Lᵀ x = z
    for i in 0..n {
        x[i] = x[i].clone() * d_inv[i].clone();
    }
    for i in (0..n).rev() {
        for k in (i + 1)..n {
            let t = l[k * n + i].clone() * x[k].clone();
            x[i] = x[i].clone() - t;
        }
    }
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
