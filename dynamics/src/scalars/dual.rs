//! Forward-mode dual numbers `a + b ε` (`ε² = 0`), generic over any [`Scalar`].
//!
//! `Dual<S>` is itself a [`Scalar`], so derivatives nest: `Dual<f64>` gives first derivatives,
//! `Dual<Dual<f64>>` mixed second derivatives, and so on, each exact to rounding (no step size).
//! The test oracles use them to differentiate the kinetic energy of a chain (Lagrange's equations)
//! without any Newton–Euler recursion.
//!
//! ```
//! use kanegen_dynamics::scalars::dual::Dual;
//! use kanegen_dynamics::scalar::Scalar;
//! // f(x) = x sin x, f'(x) = sin x + x cos x
//! let f = |x: Dual<f64>| x.clone() * x.sin();
//! let x = 0.7_f64;
//! let d = f(Dual::variable(x));
//! assert!((d.re - x * x.sin()).abs() < 1e-15);
//! assert!((d.eps - (x.sin() + x * x.cos())).abs() < 1e-15);
//!
//! // Second derivative by nesting: f''(x) = 2 cos x − x sin x.
//! let g = |x: Dual<Dual<f64>>| x.clone() * x.sin();
//! let y = g(Dual::new(Dual::variable(x), Dual::constant(1.0)));
//! assert!((y.eps.eps - (2.0 * x.cos() - x * x.sin())).abs() < 1e-14);
//! ```

use crate::scalar::Scalar;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// A dual number `re + eps·ε` with `ε² = 0`: a value and its derivative along one direction.
#[derive(Clone, Debug, PartialEq)]
pub struct Dual<S> {
    /// The value.
    pub re: S,
    /// The derivative (the coefficient of `ε`).
    pub eps: S,
}

impl<S: Scalar> Dual<S> {
    /// The dual number `re + eps·ε`.
    pub fn new(re: S, eps: S) -> Self {
        Dual { re, eps }
    }
    /// The independent variable at `re`: derivative one.
    pub fn variable(re: S) -> Self {
        Dual { re, eps: S::one() }
    }
    /// A constant lifted from `S`: derivative zero.
    pub fn lift(re: S) -> Self {
        Dual { re, eps: S::zero() }
    }
}

impl<S: Scalar> Add for Dual<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Dual::new(self.re + o.re, self.eps + o.eps)
    }
}

impl<S: Scalar> Sub for Dual<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Dual::new(self.re - o.re, self.eps - o.eps)
    }
}

impl<S: Scalar> Mul for Dual<S> {
    type Output = Self;
    /// `(a + a'ε)(b + b'ε) = ab + (a'b + ab')ε`.
    fn mul(self, o: Self) -> Self {
        let eps = self.eps * o.re.clone() + self.re.clone() * o.eps;
        Dual::new(self.re * o.re, eps)
    }
}

impl<S: Scalar> Div for Dual<S> {
    type Output = Self;
    /// `(a + a'ε)/(b + b'ε) = a/b + (a' − (a/b) b')/b ε`.
    fn div(self, o: Self) -> Self {
        let q = self.re / o.re.clone();
        let eps = (self.eps - q.clone() * o.eps) / o.re;
        Dual::new(q, eps)
    }
}

impl<S: Scalar> Neg for Dual<S> {
    type Output = Self;
    fn neg(self) -> Self {
        Dual::new(-self.re, -self.eps)
    }
}

impl<S: Scalar> Scalar for Dual<S> {
    fn constant(x: f64) -> Self {
        Dual::lift(S::constant(x))
    }
    fn sin(self) -> Self {
        self.sin_cos().0
    }
    fn cos(self) -> Self {
        self.sin_cos().1
    }
    /// `√(a + a'ε) = √a + a'/(2√a) ε` (requires `a > 0` for a finite derivative).
    fn sqrt(self) -> Self {
        let r = self.re.sqrt();
        let eps = self.eps / (S::constant(2.0) * r.clone());
        Dual::new(r, eps)
    }
    /// One `sin_cos` of the value: `sin → (s, c a')`, `cos → (c, −s a')`.
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.re.sin_cos();
        let ds = c.clone() * self.eps.clone();
        let dc = -(s.clone() * self.eps);
        (Dual::new(s, ds), Dual::new(c, dc))
    }
    fn section(label: &'static str) {
        S::section(label);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-13 * (1.0 + b.abs())
    }

    #[test]
    fn arithmetic_rules() {
        let x = Dual::new(1.5_f64, 2.0);
        let y = Dual::new(-0.5_f64, 3.0);
        let p = x.clone() * y.clone();
        assert!(close(p.re, -0.75) && close(p.eps, 2.0 * -0.5 + 1.5 * 3.0));
        let q = x.clone() / y.clone();
        assert!(close(q.re, -3.0) && close(q.eps, (2.0 * -0.5 - 1.5 * 3.0) / 0.25));
        let s = x.clone() - y.clone();
        assert!(close(s.re, 2.0) && close(s.eps, -1.0));
        let n = -x;
        assert!(close(n.re, -1.5) && close(n.eps, -2.0));
    }

    #[test]
    fn elementary_functions_first_derivatives() {
        for &x in &[0.3_f64, 1.2, 2.9] {
            let d = Dual::variable(x);
            assert!(close(d.clone().sin().eps, x.cos()));
            assert!(close(d.clone().cos().eps, -x.sin()));
            assert!(close(d.clone().sqrt().eps, 0.5 / x.sqrt()));
            let (s, c) = d.sin_cos();
            assert!(close(s.re, x.sin()) && close(c.re, x.cos()));
        }
    }

    #[test]
    fn nested_duals_give_mixed_second_derivatives() {
        // f(x, y) = sin(x y) / (1 + x²); ∂²f/∂x∂y against a closed form.
        let (x0, y0) = (0.4_f64, -1.3_f64);
        let f = |x: Dual<Dual<f64>>, y: Dual<Dual<f64>>| {
            (x.clone() * y).sin() / (Dual::constant(1.0) + x.clone() * x)
        };
        // x varies with the outer ε, y with the inner one.
        let x = Dual::new(Dual::lift(x0), Dual::constant(1.0));
        let y = Dual::lift(Dual::variable(y0));
        let v = f(x, y);
        let u = x0 * y0;
        let den = 1.0 + x0 * x0;
        // ∂f/∂y = x cos(xy)/den; ∂/∂x of that:
        let fxy = (u.cos() - x0 * y0 * u.sin()) / den - x0 * u.cos() * 2.0 * x0 / (den * den);
        assert!(close(v.eps.eps, fxy), "{} vs {}", v.eps.eps, fxy);
        assert!(close(v.re.re, u.sin() / den));
    }

    #[test]
    fn triple_nesting_third_derivative() {
        // d³/dx³ x⁴ = 24 x.
        type D3 = Dual<Dual<Dual<f64>>>;
        let x0 = 0.8_f64;
        let one = || Dual::constant(1.0);
        let x: D3 = Dual::new(
            Dual::new(Dual::variable(x0), one()),
            Dual::new(one(), Dual::constant(0.0)),
        );
        let y = x.clone() * x.clone() * x.clone() * x;
        assert!(close(y.eps.eps.eps, 24.0 * x0));
    }
}
