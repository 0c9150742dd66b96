//! Branch-free LDLᵀ factorization and solve of a symmetric positive definite matrix, in place over
//! slices, allocating nothing, generic over the scalar (so forward dynamics `q̈ = A⁻¹ b` can be
//! traced and unrolled like the rest).
//!
//! No pivoting (A is SPD, so none is needed) and no comparisons of values: a fixed `n` gives a
//! straight-line trace. Each pivot is inverted once (`n` divisions); everything else is
//! multiplication. `kanegen_dynamics::ldlt` wraps these in `Vec` conveniences.
//!
//! ```
//! use kanegen_runtime::ldlt::{factor_in_place, solve_in_place};
//! let mut a: [f64; 4] = [4.0, 2.0, 2.0, 3.0];
//! let mut d_inv = [0.0_f64; 2];
//! factor_in_place(&mut a, 2, &mut d_inv).unwrap();
//! let mut x = [2.0, 1.0];
//! solve_in_place(&a, 2, &d_inv, &mut x).unwrap();
//! assert!((4.0 * x[0] + 2.0 * x[1] - 2.0).abs() < 1e-15 && (2.0 * x[0] + 3.0 * x[1] - 1.0).abs() < 1e-15);
//! ```

// Index loops mirror the formulas (L_ik, y_k) and keep the trace order explicit.
#![allow(clippy::needless_range_loop)]

use crate::scalar::Scalar;

/// A buffer shorter than the `n` it was given with (the only way these functions fail).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShortBuffer;

impl core::fmt::Display for ShortBuffer {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("ldlt: buffers too short")
    }
}

/// `A = L D Lᵀ` in place: `a` is the row-major `n × n` matrix (lower triangle read). On return
/// its strict lower triangle holds `L`, its diagonal the pivots `D_j`, its strict upper triangle
/// the products `L_ik D_k` (at `(k, i)`), and `d_inv` the `1 / D_j`.
///
/// # Errors
/// [`ShortBuffer`] if `a` has fewer than `n²` entries or `d_inv` fewer than `n` (nothing written).
pub fn factor_in_place<S: Scalar>(
    a: &mut [S],
    n: usize,
    d_inv: &mut [S],
) -> Result<(), ShortBuffer> {
    if a.len() < n * n || d_inv.len() < n {
        return Err(ShortBuffer);
    }
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
    Ok(())
}

/// Solves `A x = b` in place with the factorization [`factor_in_place`] left in `l` and `d_inv`
/// (only the strict lower triangle of `l` is read): `x` holds `b` on entry and `A⁻¹ b` on return.
/// Forward substitution `L y = b`, the scaling `D z = y`, back substitution `Lᵀ x = z`.
///
/// # Errors
/// [`ShortBuffer`] if `l` has fewer than `n²` entries, `d_inv` fewer than `n`, or `x` is not `n`
/// long (nothing written).
pub fn solve_in_place<S: Scalar>(
    l: &[S],
    n: usize,
    d_inv: &[S],
    x: &mut [S],
) -> Result<(), ShortBuffer> {
    if l.len() < n * n || d_inv.len() < n || x.len() != n {
        return Err(ShortBuffer);
    }
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
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×3 SPD system against its known solution, and short buffers refused untouched.
    #[test]
    fn solves_and_refuses_short_buffers() {
        // A = [[4, 2, 0], [2, 5, 1], [0, 1, 3]], x = [1, -1, 2], b = A x.
        let mut a = [4.0, 2.0, 0.0, 2.0, 5.0, 1.0, 0.0, 1.0, 3.0];
        let mut d_inv = [0.0; 3];
        factor_in_place(&mut a, 3, &mut d_inv).unwrap();
        let mut x: [f64; 3] = [2.0, -1.0, 5.0];
        solve_in_place(&a, 3, &d_inv, &mut x).unwrap();
        for (got, want) in x.iter().zip([1.0, -1.0, 2.0]) {
            assert!((got - want).abs() < 1e-15, "{x:?}");
        }
        let mut short = [1.0; 3];
        assert_eq!(factor_in_place(&mut short, 2, &mut d_inv), Err(ShortBuffer));
        assert_eq!(short, [1.0; 3]);
        assert_eq!(
            solve_in_place(&a, 3, &d_inv, &mut [0.0; 2]),
            Err(ShortBuffer)
        );
    }
}
