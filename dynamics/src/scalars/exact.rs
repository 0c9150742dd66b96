//! `Exact`: arbitrary-precision rational arithmetic as a [`Scalar`], the exact oracle.
//!
//! Model parameters enter as the exact binary values of their `f64`s, so an algorithm run on
//! `Exact` computes the dynamics of the model *as stored*, with no rounding at all. Sine and
//! cosine are not rational in general; they are exact for angles built by
//! [`Exact::pythagorean`]: `θ = 2 atan t` with rational `t`, whose
//! `sin θ = 2t/(1 + t²)` and `cos θ = (1 − t²)/(1 + t²)` are rational (the Pythagorean triples
//! `(2mn, n² − m², n² + m²)` for `t = m/n`).
//!
//! Nothing here panics and nothing is silently approximated: an operation that cannot be exact
//! (the sine of an angle without rational trigonometry, the square root of a non-square, a
//! division by zero) returns an `f64`-based stand-in and clears [`Exact::is_exact`], which
//! propagates to everything computed from it. Oracles assert `is_exact()` on their results.
//!
//! ```
//! use kanegen_dynamics::scalars::exact::Exact;
//! use kanegen_dynamics::scalar::{Real, Scalar};
//! let (s, c) = Exact::pythagorean(1, 2).sin_cos(); // t = 1/2: sin = 4/5, cos = 3/5
//! let one = s.clone() * s + c.clone() * c;
//! assert!(one.is_exact() && one.to_f64() == 1.0);
//! let third = Exact::constant(1.0) / Exact::constant(3.0);
//! assert!((third.clone() * Exact::constant(3.0) - Exact::one()).is_zero());
//! assert!(!Exact::constant(2.0).sqrt().is_exact());
//! ```

use crate::scalar::{Real, Scalar};
use crate::scalars::wide::Wide;
use core::ops::{Add, Div, Mul, Neg, Sub};
use kanegen_model::{JointKind, Model};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, ToPrimitive, Zero};

/// An exact rational value, or a flagged stand-in where exactness was lost.
#[derive(Clone, Debug, PartialEq)]
pub struct Exact {
    value: BigRational,
    /// Exact `(sin, cos)` of this value when it is an angle made by [`Exact::pythagorean`].
    trig: Option<Box<(BigRational, BigRational)>>,
    exact: bool,
}

impl Exact {
    /// The rational `r`, exact.
    #[must_use]
    pub fn rational(r: BigRational) -> Self {
        Exact {
            value: r,
            trig: None,
            exact: true,
        }
    }

    /// The angle `θ = 2 atan(m/n)` (`n ≠ 0`), carrying its exact rational sine and cosine. Its
    /// own value is the `f64` nearest `θ` and is flagged inexact: only its sine and cosine are
    /// exact, which is all a revolute joint uses. `n = 0` gives the angle π (`t = ∞`).
    #[must_use]
    pub fn pythagorean(m: i64, n: i64) -> Self {
        let (m, n) = (BigInt::from(m), BigInt::from(n));
        let (mm, nn) = (&m * &m, &n * &n);
        let den = &mm + &nn;
        let (s, c) = if den.is_zero() {
            (BigRational::zero(), BigRational::from_integer(1.into()))
        } else {
            (
                BigRational::new(BigInt::from(2) * &m * &n, den.clone()),
                BigRational::new(&nn - &mm, den),
            )
        };
        let theta = s.to_f64().unwrap_or(0.0).atan2(c.to_f64().unwrap_or(1.0));
        Exact {
            value: BigRational::from_float(theta).unwrap_or_default(),
            trig: Some(Box::new((s, c))),
            exact: false,
        }
    }

    /// `true` when the value is exact: no operation on the way lost exactness.
    #[must_use]
    pub fn is_exact(&self) -> bool {
        self.exact
    }

    /// `true` for an exact zero.
    #[must_use]
    pub fn is_zero(&self) -> bool {
        self.exact && self.value.is_zero()
    }

    /// The rational value (a stand-in when not [`Exact::is_exact`]).
    #[must_use]
    pub fn value(&self) -> &BigRational {
        &self.value
    }

    /// Bits in the numerator and denominator: how large exact arithmetic has grown.
    #[must_use]
    pub fn bits(&self) -> u64 {
        self.value.numer().bits() + self.value.denom().bits()
    }

    /// The nearest double-double (`hi` the nearest double, `lo` the nearest double to the rest).
    #[must_use]
    pub fn to_wide(&self) -> Wide {
        if let Some(t) = &self.trig {
            // An angle: the double-double angle with these sine and cosine.
            let (s, c) = (rational_to_wide(&t.0), rational_to_wide(&t.1));
            return Wide::angle(s, c);
        }
        rational_to_wide(&self.value)
    }

    fn inexact(x: f64) -> Self {
        Exact {
            value: BigRational::from_float(x).unwrap_or_default(),
            trig: None,
            exact: false,
        }
    }

    fn binary(self, o: Self, f: impl FnOnce(BigRational, BigRational) -> BigRational) -> Self {
        Exact {
            exact: self.exact && o.exact,
            value: f(self.value, o.value),
            trig: None,
        }
    }
}

/// The `k`-th exact test state of `chain` (`q`, `q̇`, `τ`): revolute angles `2 atan(m/n)` with
/// small integers (rational sine and cosine), prismatic positions, rates and torques dyadic, so
/// the state is exact in every scalar type. Used by the exact oracles and `kanegen accuracy`.
#[must_use]
pub fn rational_state(chain: &Model, k: i64) -> (Vec<Exact>, Vec<Exact>, Vec<Exact>) {
    let n = chain.dof() as i64;
    let q = chain
        .joints()
        .iter()
        .zip(0..n)
        .map(|(joint, j)| match joint.kind {
            JointKind::Revolute => Exact::pythagorean((j * 7 + k) % 11 - 5, 3 + (j + k) % 4),
            JointKind::Prismatic => Exact::constant(((j + k) % 5) as f64 * 0.125 - 0.25),
        })
        .collect();
    let dyadic = |j: i64, a: i64, m: i64, scale: f64| {
        Exact::constant(((j * a + k) % m - m / 2) as f64 * scale)
    };
    let qd = (0..n).map(|j| dyadic(j, 3, 9, 0.125)).collect();
    let tau = (0..n).map(|j| dyadic(j, 5, 7, 12.5)).collect();
    (q, qd, tau)
}

fn rational_to_wide(r: &BigRational) -> Wide {
    let hi = r.to_f64().unwrap_or(f64::NAN);
    let rest = r - BigRational::from_float(hi).unwrap_or_default();
    Wide::new(hi, rest.to_f64().unwrap_or(0.0))
}

impl Add for Exact {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        self.binary(o, |a, b| a + b)
    }
}
impl Sub for Exact {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self.binary(o, |a, b| a - b)
    }
}
impl Mul for Exact {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        self.binary(o, |a, b| a * b)
    }
}
impl Div for Exact {
    type Output = Self;
    /// Exact unless the divisor is zero: then the result is a flagged zero (no panic).
    fn div(self, o: Self) -> Self {
        if o.value.is_zero() {
            return Exact::inexact(0.0);
        }
        self.binary(o, |a, b| a / b)
    }
}
impl Neg for Exact {
    type Output = Self;
    fn neg(self) -> Self {
        Exact {
            value: -self.value,
            trig: self.trig.map(|t| Box::new((-t.0, t.1))),
            exact: self.exact,
        }
    }
}

impl Scalar for Exact {
    /// The exact binary value of `x`; a non-finite `x` gives a flagged zero.
    fn constant(x: f64) -> Self {
        match BigRational::from_float(x) {
            Some(value) => Exact::rational(value),
            None => Exact::inexact(0.0),
        }
    }
    fn sin(self) -> Self {
        self.sin_cos().0
    }
    fn cos(self) -> Self {
        self.sin_cos().1
    }
    /// Exact for a non-negative square of a rational; otherwise the `f64` root, flagged.
    fn sqrt(self) -> Self {
        if self.exact && !self.value.is_negative() {
            let (n, d) = (self.value.numer().sqrt(), self.value.denom().sqrt());
            if &(&n * &n) == self.value.numer() && &(&d * &d) == self.value.denom() {
                return Exact::rational(BigRational::new(n, d));
            }
        }
        Exact::inexact(self.to_f64().sqrt())
    }
    /// Exact for a [`Exact::pythagorean`] angle (or its negation) and for an exact zero;
    /// otherwise `f64` values, flagged.
    fn sin_cos(self) -> (Self, Self) {
        if let Some(t) = self.trig {
            let (s, c) = *t;
            return (Exact::rational(s), Exact::rational(c));
        }
        if self.is_zero() {
            return (Exact::zero(), Exact::one());
        }
        let (s, c) = self.to_f64().sin_cos();
        (Exact::inexact(s), Exact::inexact(c))
    }
}

impl Real for Exact {
    /// The nearest `f64` (correctly rounded by `num-rational`).
    fn to_f64(&self) -> f64 {
        self.value.to_f64().unwrap_or(f64::NAN)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pythagorean_angles_have_exact_unit_trig() {
        for (m, n) in [(1, 2), (2, 3), (-3, 7), (5, 1), (1, 0), (0, 1)] {
            let a = Exact::pythagorean(m, n);
            assert!(!a.is_exact(), "the angle itself is irrational");
            let (s, c) = a.clone().sin_cos();
            let one = s.clone() * s.clone() + c.clone() * c.clone();
            assert!(one.is_exact() && (one - Exact::one()).is_zero(), "{m}/{n}");
            // The f64 stand-in of the angle has (nearly) these sine and cosine.
            let th = a.to_f64();
            assert!((th.sin() - s.to_f64()).abs() < 1e-15 && (th.cos() - c.to_f64()).abs() < 1e-15);
            // Negation keeps the trigonometry exact: sin(−θ) = −sin θ.
            let (sn, cn) = (-a.clone()).sin_cos();
            assert!((sn + s).is_zero() && (cn - c).is_zero());
            // Its double-double is the same angle to double-double accuracy.
            let (sw, cw) = a.to_wide().sin_cos();
            let (se, ce) = a.sin_cos();
            assert!((sw - se.to_wide()).to_f64().abs() < 1e-31);
            assert!((cw - ce.to_wide()).to_f64().abs() < 1e-31);
        }
    }

    #[test]
    fn exactness_is_lost_visibly_never_silently() {
        assert!(Exact::constant(4.0).sqrt().is_exact());
        assert_eq!(Exact::constant(2.25).sqrt().to_f64(), 1.5);
        let r2 = Exact::constant(2.0).sqrt();
        assert!(!r2.is_exact() && (r2.to_f64() - 2f64.sqrt()).abs() == 0.0);
        assert!(!Exact::constant(-4.0).sqrt().is_exact());
        let d = Exact::one() / Exact::zero();
        assert!(!d.is_exact());
        assert!(!Exact::constant(f64::NAN).is_exact());
        let (s, _) = Exact::constant(0.5).sin_cos();
        assert!(!s.is_exact() && (s.to_f64() - 0.5f64.sin()).abs() == 0.0);
        // …and the flag propagates.
        assert!(!(s * Exact::constant(0.0) + Exact::one()).is_exact());
        assert!(Exact::zero().sin_cos().1.is_exact());
    }

    #[test]
    fn constants_are_the_exact_binary_values() {
        let x = Exact::constant(0.1);
        // fl(0.1) = 3602879701896397 / 2^55.
        let want = BigRational::new(3_602_879_701_896_397_i64.into(), BigInt::from(1) << 55);
        assert_eq!(x.value(), &want);
        // 3·fl(0.1) − fl(0.3) is 2^−55 exactly, not 0 and not f64's 5.55e-17.
        let y = x * Exact::constant(3.0) - Exact::constant(0.3);
        assert_eq!(
            y.value(),
            &BigRational::new(1.into(), BigInt::from(1) << 55)
        );
    }
}
