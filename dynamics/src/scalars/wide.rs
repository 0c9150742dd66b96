//! `Wide`: double-double arithmetic (about 32 significant digits) as a [`Scalar`], the reference
//! that `f64` and `f32` results are measured against for general joint angles.
//!
//! Arithmetic is the [`qd`] crate's (Bailey's QD algorithms: `+` and `−` are its *accurate*
//! sums, `×` by fused multiply-add, `÷` by two correction steps; relative error about 10⁻³²).
//! `qd` has no trigonometry, and the other double-double crate, `twofloat` 0.8, is not good
//! enough for a reference: its sine is off by about 10⁻²¹ (`sin 0.7`: 1.3·10⁻²¹ relative) and
//! its division by about 10⁻¹⁷ (`3·(1/3) − 1 = −5.6·10⁻¹⁷`: the remainder in its Algorithm 18
//! is computed without a fused multiply-add). So sine and cosine are computed here: reduction by
//! `π/2` held as three doubles, then Taylor series on `|r| ≤ π/4` to below 10⁻³³, every step in
//! double-double. The tests check identities with no shared code path (`sin² + cos² = 1`,
//! double angle, addition theorem, `sin(π/6) = 1/2`) at 10⁻³¹.
//!
//! [`crate::scalars::exact`] checks whole algorithms on `Wide` against exact rational arithmetic.
//!
//! ```
//! use kanegen_dynamics::scalar::{Real, Scalar};
//! use kanegen_dynamics::scalars::wide::Wide;
//! let x = Wide::constant(0.1);        // the double nearest 0.1, exactly
//! let y = x.clone() * Wide::constant(3.0) - Wide::constant(0.3);
//! // In f64 this is 5.55e-17; in double-double it is the exact 3·fl(0.1) − fl(0.3).
//! assert!((y.to_f64() - 2.7755575615628914e-17).abs() < 1e-31);
//! let (s, c) = Wide::constant(0.7).sin_cos();
//! let one = s.clone() * s + c.clone() * c - Wide::one();
//! assert!(one.to_f64().abs() < 1e-31);
//! ```

use crate::scalar::{Real, Scalar};
use core::ops::{Add, Div, Mul, Neg, Sub};
use qd::Quad;

/// A double-double number: an unevaluated sum `hi + lo` of two `f64` with `|lo| ≤ ulp(hi)/2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wide(pub Quad);

impl Wide {
    /// The double-double `hi + lo` (renormalized).
    #[must_use]
    pub fn new(hi: f64, lo: f64) -> Self {
        Wide(Quad(hi, 0.0).add_accurate(Quad(lo, 0.0)))
    }
    /// The leading part.
    #[must_use]
    pub fn hi(&self) -> f64 {
        self.0 .0
    }
    /// The trailing part.
    #[must_use]
    pub fn lo(&self) -> f64 {
        self.0 .1
    }
    /// The angle whose sine and cosine are `(s, c)` (`s² + c² = 1`), to double-double accuracy:
    /// `atan2` in `f64`, then one Newton step `θ ← θ + (s cos θ − c sin θ)` (the error
    /// `δ` becomes `δ³/6`, below 10⁻⁴⁶). Used to feed an angle with exact rational sine and
    /// cosine to the double-double algorithms.
    #[must_use]
    pub fn angle(s: Wide, c: Wide) -> Wide {
        let theta = Wide::constant(s.hi().atan2(c.hi()));
        let (st, ct) = theta.sin_cos();
        theta + (s * ct - c * st)
    }
}

// π/2 = P1 + P2 + P3 to about 160 bits (fdlibm's pio2_1, pio2_2, pio2_3 are shorter; these are
// the leading three doubles of the binary expansion).
const PIO2_1: f64 = core::f64::consts::FRAC_PI_2;
const PIO2_2: f64 = 6.123_233_995_736_766e-17;
const PIO2_3: f64 = -1.497_384_904_859_169_8e-33;

/// `sin r` and `cos r` for `|r| ≤ π/4 + ε` by Taylor series to 10⁻³⁴.
fn sin_cos_kernel(r: Wide) -> (Wide, Wide) {
    let r2 = r * r;
    // sin r = r − r³/3! + …, cos r = 1 − r²/2! + …; |r|^29/29! < 10⁻³⁵ at |r| = 0.8.
    let mut term_s = r;
    let mut term_c = Wide::one();
    let mut s = r;
    let mut c = Wide::one();
    let mut k = 1.0_f64;
    while k < 29.0 {
        term_c = -(term_c * r2) / Wide::constant(k * (k + 1.0));
        c = c + term_c;
        term_s = -(term_s * r2) / Wide::constant((k + 1.0) * (k + 2.0));
        s = s + term_s;
        k += 2.0;
    }
    (s, c)
}

impl Wide {
    /// Sine and cosine to double-double accuracy (about 10⁻³² relative; see the module docs).
    fn sin_cos_dd(self) -> (Self, Self) {
        let k = (self.hi() / PIO2_1).round();
        if !k.is_finite() {
            return (Wide(Quad::NAN), Wide(Quad::NAN));
        }
        // r = x − k π/2: each k·Pᵢ is exact as a double-double (two-product).
        let kw = Wide::constant(k);
        let r = self
            - kw * Wide::constant(PIO2_1)
            - kw * Wide::constant(PIO2_2)
            - kw * Wide::constant(PIO2_3);
        let (s, c) = sin_cos_kernel(r);
        // k mod 4, for any integer-valued k representable in f64.
        let quadrant = k.rem_euclid(4.0) as u8;
        let (s, c) = match quadrant {
            0 => (s, c),
            1 => (c, -s),
            2 => (-s, -c),
            _ => (-c, s),
        };
        (s, c)
    }
}

impl Add for Wide {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Wide(self.0.add_accurate(o.0))
    }
}
impl Sub for Wide {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Wide(self.0.sub_accurate(o.0))
    }
}
impl Mul for Wide {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Wide(self.0 * o.0)
    }
}
impl Div for Wide {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        Wide(self.0 / o.0)
    }
}
impl Neg for Wide {
    type Output = Self;
    fn neg(self) -> Self {
        Wide(-self.0)
    }
}

impl Scalar for Wide {
    fn constant(x: f64) -> Self {
        Wide(Quad::from_f64(x))
    }
    fn sin(self) -> Self {
        self.sin_cos_dd().0
    }
    fn cos(self) -> Self {
        self.sin_cos_dd().1
    }
    fn sqrt(self) -> Self {
        Wide(self.0.sqrt())
    }
    fn sin_cos(self) -> (Self, Self) {
        self.sin_cos_dd()
    }
}

impl Real for Wide {
    fn to_f64(&self) -> f64 {
        self.hi() + self.lo()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kanegen_model::random::{random_vec, rng};

    fn abs(x: Wide) -> f64 {
        x.to_f64().abs()
    }

    fn w(x: f64) -> Wide {
        Wide::constant(x)
    }

    /// A double-double with a non-trivial low part: `x + y·2⁻⁶⁰`.
    fn wide_random(x: f64, y: f64) -> Wide {
        Wide::new(x, y * x * 2f64.powi(-60))
    }

    #[test]
    fn pythagoras_to_1e_31() {
        let mut r = rng(11);
        let xs = random_vec(&mut r, 400, 40.0);
        let ys = random_vec(&mut r, 400, 1.0);
        for (&x, &y) in xs.iter().zip(&ys) {
            let (s, c) = wide_random(x, y).sin_cos();
            let e = abs(s * s + c * c - w(1.0));
            assert!(e < 1e-31, "x = {x}: s² + c² − 1 = {e:e}");
        }
    }

    #[test]
    fn double_angle_and_addition_theorems() {
        let mut r = rng(12);
        let xs = random_vec(&mut r, 300, 4.0);
        let ys = random_vec(&mut r, 300, 4.0);
        for (&x, &y) in xs.iter().zip(&ys) {
            let (a, b) = (wide_random(x, 0.37), wide_random(y, -0.81));
            let (sa, ca) = a.sin_cos();
            let (sb, cb) = b.sin_cos();
            // 2a is exact in double-double.
            let (s2, c2) = (a + a).sin_cos();
            assert!(abs(s2 - w(2.0) * sa * ca) < 4e-31, "sin 2x, x = {x}");
            assert!(abs(c2 - (ca * ca - sa * sa)) < 4e-31, "cos 2x, x = {x}");
            let (sab, cab) = (a + b).sin_cos();
            assert!(abs(sab - (sa * cb + ca * sb)) < 4e-31, "sin(x + y)");
            assert!(abs(cab - (ca * cb - sa * sb)) < 4e-31, "cos(x + y)");
        }
    }

    #[test]
    fn known_values() {
        // π in double-double is 2 (P1 + P2) to 10⁻³³ relative.
        let pi = w(2.0) * (w(PIO2_1) + w(PIO2_2) + w(PIO2_3));
        let half = w(0.5);
        assert!(abs((pi / w(6.0)).sin() - half) < 1e-31);
        assert!(abs((pi / w(3.0)).cos() - half) < 1e-31);
        let r2 = w(2.0).sqrt() / w(2.0);
        assert!(abs((pi / w(4.0)).sin() - r2) < 1e-31);
        assert!(abs((pi / w(4.0)).cos() - r2) < 1e-31);
        assert!(abs(pi.sin()) < 1e-32 && abs(pi.cos() + w(1.0)) < 1e-31);
        assert_eq!(w(0.0).sin_cos(), (w(0.0), w(1.0)));
    }

    #[test]
    fn agrees_with_f64_libm() {
        for k in -300..300 {
            let x = f64::from(k) * 0.0123;
            let (s, c) = w(x).sin_cos();
            assert!((s.to_f64() - x.sin()).abs() < 2e-16 && (c.to_f64() - x.cos()).abs() < 2e-16);
        }
    }

    #[test]
    fn division_and_square_root_to_1e_31() {
        let mut r = rng(13);
        let xs = random_vec(&mut r, 200, 10.0);
        let ys = random_vec(&mut r, 200, 10.0);
        for (&x, &y) in xs.iter().zip(&ys) {
            let (a, b) = (wide_random(x, 0.3), wide_random(y, -0.7));
            assert!(abs((a / b) * b - a) < 1e-31 * x.abs(), "{x} / {y}");
            let r = (a * a).sqrt();
            assert!(abs(r * r - a * a) < 1e-31 * x * x, "sqrt");
        }
        assert!(abs(w(1.0) / w(3.0) * w(3.0) - w(1.0)) < 1e-32);
    }

    #[test]
    fn angle_inverts_sin_cos() {
        for &(a, b, c) in &[
            (3.0, 4.0, 5.0),
            (5.0, 12.0, 13.0),
            (-20.0, 21.0, 29.0),
            (-8.0, -15.0, 17.0),
        ] {
            let (s, co) = (w(a) / w(c), w(b) / w(c));
            let (s1, c1) = Wide::angle(s, co).sin_cos();
            assert!(abs(s1 - s) < 1e-31 && abs(c1 - co) < 1e-31);
        }
    }

    #[test]
    fn non_finite_input_gives_nan_not_a_panic() {
        let (s, c) = w(f64::INFINITY).sin_cos();
        assert!(s.to_f64().is_nan() && c.to_f64().is_nan());
    }
}
