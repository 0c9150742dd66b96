//! `Compensated`: `f64` arithmetic that carries a first-order estimate of its own rounding error
//! (compensated arithmetic, after Ogita, Rump and Oishi's `Dot2` and Graillat's compensated
//! Horner scheme), as a [`Scalar`].
//!
//! A value is `v + e`: `v` is what plain `f64` would compute, `e` accumulates the exact rounding
//! errors of every `+` and `×` (by the error-free transformations TwoSum and TwoProduct with a
//! fused multiply-add) and their first-order propagation; [`Real::to_f64`] returns `v + e`.
//! The result is as accurate as if computed in twice the working precision and then rounded
//! (`≈ ε + cond · ε²`), at a fraction of the cost of double-double ([`crate::scalars::wide::Wide`]),
//! because `v` and `e` are never renormalized. Sine and cosine of a joint angle are computed in
//! double-double and split, so the trigonometry does not cap the accuracy at `f64`.
//!
//! ```
//! use kanegen_dynamics::scalars::compensated::Compensated;
//! use kanegen_dynamics::scalar::{Real, Scalar};
//! let c = |x: f64| Compensated::constant(x);
//! // 0.1 + 0.2 − 0.3 in f64 is 5.55e-17; compensated, it is the exact fl(0.1) + fl(0.2) − fl(0.3).
//! let r = c(0.1) + c(0.2) - c(0.3);
//! assert_eq!(r.to_f64(), 2.7755575615628914e-17);
//! ```

use crate::scalar::{Real, Scalar};
use crate::scalars::wide::Wide;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// `v + e`: the `f64` result and its accumulated rounding-error correction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compensated {
    /// The plain `f64` value.
    pub v: f64,
    /// The correction: the (first-order) error of `v`.
    pub e: f64,
}

/// TwoSum (Knuth): `a + b = s + t` exactly.
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

impl Add for Compensated {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        let (s, t) = two_sum(self.v, o.v);
        Compensated {
            v: s,
            e: self.e + o.e + t,
        }
    }
}

impl Sub for Compensated {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}

impl Mul for Compensated {
    type Output = Self;
    /// TwoProduct by a fused multiply-add, plus the first-order propagation of both errors.
    #[inline]
    fn mul(self, o: Self) -> Self {
        let p = self.v * o.v;
        let t = self.v.mul_add(o.v, -p);
        Compensated {
            v: p,
            e: t + self.v * o.e + self.e * o.v,
        }
    }
}

impl Div for Compensated {
    type Output = Self;
    /// `q = a/b`; the exact remainder `a − q b` (one fused multiply-add) gives the correction.
    #[inline]
    fn div(self, o: Self) -> Self {
        let q = self.v / o.v;
        let r = (-q).mul_add(o.v, self.v);
        Compensated {
            v: q,
            e: (r + self.e - q * o.e) / o.v,
        }
    }
}

impl Neg for Compensated {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Compensated {
            v: -self.v,
            e: -self.e,
        }
    }
}

impl Compensated {
    fn from_wide(w: Wide) -> Self {
        Compensated {
            v: w.hi(),
            e: w.lo(),
        }
    }
}

impl Scalar for Compensated {
    #[inline]
    fn constant(x: f64) -> Self {
        Compensated { v: x, e: 0.0 }
    }
    fn sin(self) -> Self {
        self.sin_cos().0
    }
    fn cos(self) -> Self {
        self.sin_cos().1
    }
    /// `√v` corrected by `(v − r²)/(2r)` (exact remainder by a fused multiply-add) and `e/(2r)`.
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        let rem = (-r).mul_add(r, self.v);
        Compensated {
            v: r,
            e: (rem + self.e) / (2.0 * r),
        }
    }
    /// In double-double, then split: the sine of `v + e` to about 10⁻³².
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = Wide::new(self.v, self.e).sin_cos();
        (Compensated::from_wide(s), Compensated::from_wide(c))
    }
}

impl Real for Compensated {
    fn to_f64(&self) -> f64 {
        self.v + self.e
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ill_conditioned_sum_is_exact_where_f64_loses_everything() {
        // 1e16 + 1 − 1e16: f64 gives 0 (or 2), compensated gives 1.
        let c = Compensated::constant;
        assert_eq!((c(1e16) + c(1.0) - c(1e16)).to_f64(), 1.0);
        assert_eq!(1e16_f64 + 1.0 - 1e16, 0.0);
    }

    #[test]
    fn dot_product_like_dot2() {
        // Σ xᵢ yᵢ with heavy cancellation; compensated agrees with double-double to 1e-30
        // absolute here, while f64 is off by ~1e-16 · Σ|xᵢ yᵢ|.
        let xs = [1.0e8, 1.0 / 3.0, -1.0e8, 2.0_f64.sqrt(), 1.0e-3];
        let ys = [1.0 + 1e-8, 3.0, 1.0, -1.0 / 7.0, 1.0e5];
        let c: Compensated = xs.iter().zip(&ys).fold(Compensated::zero(), |s, (&x, &y)| {
            s + Compensated::constant(x) * Compensated::constant(y)
        });
        let w: Wide = xs.iter().zip(&ys).fold(Wide::zero(), |s, (&x, &y)| {
            s + Wide::constant(x) * Wide::constant(y)
        });
        let f: f64 = xs.iter().zip(&ys).map(|(x, y)| x * y).sum();
        let wc = (Wide::new(c.v, c.e) - w).to_f64().abs();
        let wf = (Wide::constant(f) - w).to_f64().abs();
        assert!(wc < 1e-24, "compensated off by {wc:e}");
        assert!(wf > 1e4 * wc.max(1e-30), "f64 off by only {wf:e}");
    }

    #[test]
    fn division_and_sqrt_corrections() {
        let c = Compensated::constant;
        let third = c(1.0) / c(3.0);
        let back = Wide::new(third.v, third.e) * Wide::constant(3.0) - Wide::one();
        assert!(back.to_f64().abs() < 1e-31);
        let r = c(2.0).sqrt();
        let sq = Wide::new(r.v, r.e) * Wide::new(r.v, r.e) - Wide::constant(2.0);
        assert!(sq.to_f64().abs() < 1e-31);
    }
}
