//! Exact polynomials in `N` with rational coefficients, fitted to traced operation counts.
//!
//! ```
//! use kanegen_trace::poly::{fit_exact, Poly};
//! // 1.5N² − 4.5N + 3 through N = 2..=9
//! let pts: Vec<(i64, i64)> = (2..=9).map(|n| (n, (3 * n * n - 9 * n + 6) / 2)).collect();
//! let fit = fit_exact(&pts, 3).unwrap();
//! assert_eq!(fit.poly.to_string(), "1.5N² − 4.5N + 3");
//! assert_eq!(fit.valid_from, 2);
//! ```

use num_rational::Ratio;
use num_traits::{ToPrimitive, Zero};
use std::fmt;

/// A rational coefficient.
pub type Q = Ratio<i128>;

/// A polynomial `c₀ + c₁N + c₂N² + …`, coefficients lowest degree first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Poly(pub Vec<Q>);

impl Poly {
    /// From decimal coefficients (exact for the halves and integers of Table 1).
    pub fn from_f64(c: &[f64]) -> Poly {
        Poly(
            c.iter()
                .map(|&x| {
                    let scaled = (x * 6.0).round() as i128;
                    assert!(
                        ((scaled as f64) / 6.0 - x).abs() < 1e-12,
                        "coefficient {x} is not a multiple of 1/6"
                    );
                    Q::new(scaled, 6)
                })
                .collect(),
        )
        .trimmed()
    }
    /// The zero polynomial.
    pub fn zero() -> Poly {
        Poly(vec![])
    }
    fn trimmed(mut self) -> Poly {
        while self.0.last().is_some_and(|c| c.is_zero()) {
            self.0.pop();
        }
        self
    }
    /// Value at `n`.
    pub fn eval(&self, n: i64) -> Q {
        self.0
            .iter()
            .rev()
            .fold(Q::zero(), |acc, c| acc * Q::from(n as i128) + c)
    }
    /// Value at a real `x`.
    pub fn eval_f64(&self, x: f64) -> f64 {
        self.0
            .iter()
            .rev()
            .fold(0.0, |acc, c| acc * x + c.to_f64().unwrap_or(f64::NAN))
    }
    /// Coefficients as decimals, lowest degree first (the JSON contract).
    pub fn coeffs_f64(&self) -> Vec<f64> {
        if self.0.is_empty() {
            return vec![0.0];
        }
        self.0
            .iter()
            .map(|c| c.to_f64().unwrap_or(f64::NAN))
            .collect()
    }
    /// Sum.
    pub fn add(&self, o: &Poly) -> Poly {
        let n = self.0.len().max(o.0.len());
        Poly(
            (0..n)
                .map(|i| {
                    self.0.get(i).copied().unwrap_or_else(Q::zero)
                        + o.0.get(i).copied().unwrap_or_else(Q::zero)
                })
                .collect(),
        )
        .trimmed()
    }
    /// Difference `self − o`.
    pub fn sub(&self, o: &Poly) -> Poly {
        self.add(&Poly(o.0.iter().map(|c| -c).collect()))
    }
    /// Degree (−1 for zero, as `None`).
    pub fn degree(&self) -> Option<usize> {
        self.0.len().checked_sub(1)
    }
    /// Real roots in `(lo, hi)` of `self`, found by sign changes on a fine grid and bisection.
    pub fn real_roots(&self, lo: f64, hi: f64) -> Vec<f64> {
        let steps = 20_000;
        let h = (hi - lo) / steps as f64;
        let mut roots = Vec::new();
        let mut x0 = lo;
        let mut f0 = self.eval_f64(x0);
        for k in 1..=steps {
            let x1 = lo + h * k as f64;
            let f1 = self.eval_f64(x1);
            if f0 == 0.0 {
                roots.push(x0);
            } else if f0 * f1 < 0.0 {
                let (mut a, mut b) = (x0, x1);
                for _ in 0..100 {
                    let m = 0.5 * (a + b);
                    if self.eval_f64(a) * self.eval_f64(m) <= 0.0 {
                        b = m;
                    } else {
                        a = m;
                    }
                }
                roots.push(0.5 * (a + b));
            }
            x0 = x1;
            f0 = f1;
        }
        roots
    }
}

fn fmt_q(c: &Q) -> String {
    if c.is_integer() {
        c.to_integer().to_string()
    } else {
        let x = c.to_f64().unwrap_or(f64::NAN);
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
        if (s.parse::<f64>().unwrap_or(f64::NAN) - x).abs() < 1e-12 {
            s
        } else {
            format!("({}/{})", c.numer(), c.denom())
        }
    }
}

impl fmt::Display for Poly {
    /// Written highest degree first with the paper's notation: `18N² − 27N + 9`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str("0");
        }
        let mut first = true;
        for (d, c) in self.0.iter().enumerate().rev() {
            if c.is_zero() {
                continue;
            }
            let neg = *c < Q::zero();
            let mag = if neg { -c } else { *c };
            let var = match d {
                0 => String::new(),
                1 => "N".into(),
                2 => "N²".into(),
                3 => "N³".into(),
                _ => format!("N^{d}"),
            };
            let num = if d > 0 && mag == Q::from(1) {
                String::new()
            } else {
                fmt_q(&mag)
            };
            match (first, neg) {
                (true, true) => write!(f, "−{num}{var}")?,
                (true, false) => write!(f, "{num}{var}")?,
                (false, true) => write!(f, " − {num}{var}")?,
                (false, false) => write!(f, " + {num}{var}")?,
            }
            first = false;
        }
        Ok(())
    }
}

/// The result of fitting counts: the polynomial, the smallest `N` from which it matches every
/// traced value, and the points used to fit and to check it.
#[derive(Clone, Debug)]
pub struct Fit {
    /// The exact polynomial.
    pub poly: Poly,
    /// It matches every traced point with `N ≥ valid_from`.
    pub valid_from: i64,
    /// `N` values the polynomial was interpolated through.
    pub fit_points: Vec<i64>,
    /// `N` values not used to fit, at which it was checked.
    pub check_points: Vec<i64>,
}

/// Lagrange interpolation through `pts` (exact).
fn interpolate(pts: &[(i64, i64)]) -> Poly {
    let mut acc = Poly::zero();
    for (i, &(xi, yi)) in pts.iter().enumerate() {
        // basis_i = Π_{j≠i} (N − x_j)/(x_i − x_j)
        let mut basis = Poly(vec![Q::from(1)]);
        for (j, &(xj, _)) in pts.iter().enumerate() {
            if i == j {
                continue;
            }
            let d = Q::from((xi - xj) as i128);
            let lin = Poly(vec![Q::from(-(xj as i128)) / d, Q::from(1) / d]);
            basis = mul(&basis, &lin);
        }
        acc = acc.add(&Poly(
            basis.0.iter().map(|c| c * Q::from(yi as i128)).collect(),
        ));
    }
    acc.trimmed()
}

fn mul(a: &Poly, b: &Poly) -> Poly {
    if a.0.is_empty() || b.0.is_empty() {
        return Poly::zero();
    }
    let mut out = vec![Q::zero(); a.0.len() + b.0.len() - 1];
    for (i, x) in a.0.iter().enumerate() {
        for (j, y) in b.0.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    Poly(out).trimmed()
}

/// Fits the exact polynomial of degree ≤ `max_degree` to `(N, count)` points (sorted by N).
/// The fit uses the `max_degree + 1` largest N; it is then checked on every other point, and the
/// range of validity is extended downwards while points keep matching. Returns `None` when the
/// largest points do not lie on one polynomial (at least two check points are required).
pub fn fit_exact(pts: &[(i64, i64)], max_degree: usize) -> Option<Fit> {
    let k = max_degree + 1;
    if pts.len() < k + 2 {
        return None;
    }
    let fit_pts = &pts[pts.len() - k - 2..pts.len() - 2];
    let poly = interpolate(fit_pts);
    let matches = |&(n, y): &(i64, i64)| poly.eval(n) == Q::from(y as i128);
    // The two largest points were not used: they must match.
    if !pts[pts.len() - 2..].iter().all(matches) {
        return None;
    }
    let mut valid_from = fit_pts[0].0;
    for p in pts[..pts.len() - k - 2].iter().rev() {
        if matches(p) {
            valid_from = p.0;
        } else {
            break;
        }
    }
    let fit_points: Vec<i64> = fit_pts.iter().map(|p| p.0).collect();
    let check_points = pts
        .iter()
        .map(|p| p.0)
        .filter(|n| *n >= valid_from && !fit_points.contains(n))
        .collect();
    Some(Fit {
        poly,
        valid_from,
        fit_points,
        check_points,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_cubic_and_reports_irregular_start() {
        // (14/3)N³ + 37N² − (5/3)N + 3 for N ≥ 3, something else below.
        let f = |n: i64| (14 * n * n * n + 111 * n * n - 5 * n + 9) / 3;
        let mut pts: Vec<(i64, i64)> = (1..=12).map(|n| (n, f(n))).collect();
        pts[0].1 += 1;
        pts[1].1 -= 2;
        let fit = fit_exact(&pts, 3).unwrap();
        assert_eq!(fit.valid_from, 3);
        assert_eq!(fit.poly.to_string(), "(14/3)N³ + 37N² − (5/3)N + 3");
        assert!(fit.check_points.contains(&12) && fit.check_points.contains(&3));
        assert_eq!(fit.poly.eval(7), Q::from(f(7) as i128));
    }

    #[test]
    fn rejects_non_polynomial_data() {
        let pts: Vec<(i64, i64)> = (1..=10).map(|n| (n, 1 << n)).collect();
        assert!(fit_exact(&pts, 3).is_none());
    }

    #[test]
    fn formats_like_the_paper() {
        assert_eq!(
            Poly::from_f64(&[39.0, -136.5, 91.5]).to_string(),
            "91.5N² − 136.5N + 39"
        );
        assert_eq!(Poly::from_f64(&[0.0, 0.0]).to_string(), "0");
        assert_eq!(Poly::from_f64(&[-9.0, 9.0]).to_string(), "9N − 9");
        let r = Poly::from_f64(&[39.0, -136.5, 91.5]).sub(&Poly::from_f64(&[0.0, 69.0, 69.0]));
        let roots = r.real_roots(1.0, 20.0);
        assert_eq!(roots.len(), 1);
        assert!((roots[0] - 8.94).abs() < 0.01, "{roots:?}");
    }
}
