//! Dense linear solves without allocation or panics: LU with partial pivoting on a row-major
//! `d × d` slice (the iteration matrix of [`rosenbrock`](super::rosenbrock())), and the solve of
//! a fixed-size symmetric positive definite system by the runtime's one LDLᵀ
//! ([`crate::ldlt`]; [`solve_spd`], `scene!`'s `(M + diag(I_m n²)) q̈ = τ − c`).

// Index loops over matrix entries, in the order of Golub & Van Loan, Alg. 3.4.1.
#![allow(clippy::needless_range_loop)]

use crate::ldlt::{factor_in_place, solve_in_place};

/// Factors `a` (row-major `d × d`) in place into `P a = L U` by Gaussian elimination with
/// partial pivoting (Golub & Van Loan, *Matrix Computations*, Alg. 3.4.1; `piv[k]`: the row
/// swapped with row `k`). `false` when a pivot is zero or not finite, or `a` (`piv`) is
/// shorter than `d²` (`d`).
pub fn lu_factor(a: &mut [f64], piv: &mut [usize], d: usize) -> bool {
    if a.len() < d * d || piv.len() < d {
        return false;
    }
    for k in 0..d {
        let mut p = k;
        for i in k + 1..d {
            if libm::fabs(a[i * d + k]) > libm::fabs(a[p * d + k]) {
                p = i;
            }
        }
        piv[k] = p;
        let pv = a[p * d + k];
        if pv == 0.0 || !pv.is_finite() {
            return false;
        }
        if p != k {
            for j in 0..d {
                a.swap(k * d + j, p * d + j);
            }
        }
        for i in k + 1..d {
            let l = a[i * d + k] / pv;
            a[i * d + k] = l;
            for j in k + 1..d {
                a[i * d + j] -= l * a[k * d + j];
            }
        }
    }
    true
}

/// Solves `a x = b` in place (`b` becomes `x`) with the factors of a successful [`lu_factor`]
/// of the same `d`; `b` is left alone when a length is short.
pub fn lu_solve(a: &[f64], piv: &[usize], b: &mut [f64], d: usize) {
    if a.len() < d * d || piv.len() < d || b.len() < d || piv[..d].iter().any(|&p| p >= d) {
        return;
    }
    // The factorization swapped whole rows: all the swaps first, then `L`.
    for k in 0..d {
        b.swap(k, piv[k]);
    }
    for k in 0..d {
        for i in k + 1..d {
            b[i] -= a[i * d + k] * b[k];
        }
    }
    for k in (0..d).rev() {
        let mut s = b[k];
        for j in k + 1..d {
            s -= a[k * d + j] * b[j];
        }
        b[k] = s / a[k * d + k];
    }
}

/// Solves `A x = b` for a symmetric positive definite `A` of fixed size by the runtime's LDLᵀ
/// ([`factor_in_place`], [`solve_in_place`]: Golub & Van Loan, Alg. 4.1.2; only the lower
/// triangle is read). `None` when a pivot is not positive (or not finite): `A` is not positive
/// definite.
#[must_use]
pub fn solve_spd<const N: usize>(a: &[[f64; N]; N], b: &[f64; N]) -> Option<[f64; N]> {
    let mut l = *a;
    let mut d_inv = [0.0f64; N];
    factor_in_place(l.as_flattened_mut(), N, &mut d_inv).ok()?;
    // The pivots `D_j` are left on the diagonal; `!(D_j > 0)` also catches NaN.
    if l.iter()
        .enumerate()
        .any(|(j, row)| !(row[j] > 0.0 && row[j].is_finite()))
    {
        return None;
    }
    let mut x = *b;
    solve_in_place(l.as_flattened(), N, &d_inv, &mut x).ok()?;
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `lu_factor` + `lu_solve` against a known solution on a 5×5 system that needs pivoting at
    /// every column (a wrong order of the row swaps fails this).
    #[test]
    fn lu_solves_with_pivoting() {
        const D: usize = 5;
        let mut a: [f64; D * D] = core::array::from_fn(|k| {
            let (i, j) = (k / D, k % D);
            (((i * 7 + j * 3) % 11) as f64 - 5.0) + if (i + j) % 4 == 0 { 9.0 } else { 0.0 }
        });
        let x: [f64; D] = core::array::from_fn(|i| 1.0 + i as f64 * 0.5);
        let mut b: [f64; D] = core::array::from_fn(|i| (0..D).map(|j| a[i * D + j] * x[j]).sum());
        let mut piv = [0; D];
        assert!(lu_factor(&mut a, &mut piv, D));
        lu_solve(&a, &piv, &mut b, D);
        for i in 0..D {
            assert!(libm::fabs(b[i] - x[i]) < 1e-12, "{b:?}");
        }
        assert!(!lu_factor(&mut [0.0; 4], &mut [0; 2], 2), "singular");
        assert!(!lu_factor(&mut [1.0; 3], &mut [0; 2], 2), "short");
    }

    #[test]
    fn solve_spd_solves_and_refuses_indefinite() {
        let a = [[4.0, 2.0], [2.0, 3.0]];
        let x = solve_spd(&a, &[2.0, 1.0]).unwrap();
        assert!(libm::fabs(4.0 * x[0] + 2.0 * x[1] - 2.0) < 1e-15);
        assert!(libm::fabs(2.0 * x[0] + 3.0 * x[1] - 1.0) < 1e-15);
        assert!(solve_spd(&[[1.0, 2.0], [2.0, 1.0]], &[1.0, 1.0]).is_none());
        assert!(solve_spd(&[[f64::NAN]], &[1.0]).is_none());
    }
}
