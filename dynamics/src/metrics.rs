//! Error measures shared by tests, reports and benchmarks.
//!
//! ```
//! use kanegen_dynamics::metrics::rel_err;
//! assert_eq!(rel_err(&[1.0, 2.5], &[1.0, 2.0]), 0.25);
//! assert_eq!(rel_err(&[f64::NAN, 2.0], &[1.0, 2.0]), f64::INFINITY);
//! ```

#[cfg(feature = "research")]
use crate::{scalar::Real, scalars::wide::Wide};

/// `max |x − y| / max |y|` over all entries (the project's "relative error"); when `y` is all
/// zero, the absolute error `max |x − y|`. A non-finite entry in `x` or `y` gives `∞` (a
/// plain `f64::max` fold would drop a NaN and report a broken result as perfect).
#[must_use]
pub fn rel_err(x: &[f64], y: &[f64]) -> f64 {
    assert_eq!(x.len(), y.len(), "rel_err: lengths differ");
    if !x.iter().chain(y).all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    let num = x
        .iter()
        .zip(y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let den = y.iter().map(|b| b.abs()).fold(0.0, f64::max);
    if den == 0.0 {
        num
    } else {
        num / den
    }
}

/// [`rel_err`] over the entries of two matrices given as rows.
#[must_use]
pub fn rel_err_mat(x: &[Vec<f64>], y: &[Vec<f64>]) -> f64 {
    assert_eq!(x.len(), y.len(), "rel_err_mat: row counts differ");
    rel_err(&flatten(x), &flatten(y))
}

/// The entries of a matrix given as rows, row by row.
#[must_use]
pub fn flatten(a: &[Vec<f64>]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

/// [`rel_err`] of double-double values, the difference taken in double-double so that errors
/// far below `f64` resolution stay visible (how the reference itself is checked).
#[cfg(feature = "research")]
#[must_use]
pub fn rel_err_wide(x: &[Wide], y: &[Wide]) -> f64 {
    assert_eq!(x.len(), y.len(), "rel_err_wide: lengths differ");
    let (hi, lo): (Vec<f64>, Vec<f64>) = x.iter().chain(y).map(|w| (w.hi(), w.lo())).unzip();
    if !hi.iter().chain(&lo).all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    let num = x
        .iter()
        .zip(y)
        .map(|(a, b)| (*a - *b).to_f64().abs())
        .fold(0.0, f64::max);
    let den = y.iter().map(|b| b.to_f64().abs()).fold(0.0, f64::max);
    if den == 0.0 {
        num
    } else {
        num / den
    }
}
