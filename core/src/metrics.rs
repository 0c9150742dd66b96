//! Error measures shared by tests, reports and benchmarks.
//!
//! ```
//! use kanegen_core::metrics::rel_err;
//! assert_eq!(rel_err(&[1.0, 2.5], &[1.0, 2.0]), 0.25);
//! ```

/// `max |x − y| / max |y|` over all entries (the project's "relative error"); when `y` is all
/// zero, the absolute error `max |x − y|`.
#[must_use]
pub fn rel_err(x: &[f64], y: &[f64]) -> f64 {
    assert_eq!(x.len(), y.len(), "rel_err: lengths differ");
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
