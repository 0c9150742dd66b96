//! The scalar abstraction every algorithm and kernel is written against.
//!
//! An algorithm (of `kanegen-dynamics`, or a kernel of this crate) is written once, generic over `S: Scalar`, and runs on
//! `f64`, `f32`, wider or exact types, and on the symbolic tracer `Sym` of `kanegen-trace`, which
//! records the expression graph and counts operations.
//!
//! The trait deliberately has **no comparison**: a traced value cannot be compared, so a fixed model
//! gives a branch-free trace. Algorithms branch only on model structure (joint kinds, which loads are
//! present), never on values.
//!
//! ```
//! use kanegen_runtime::scalar::Scalar;
//! fn norm2<S: Scalar>(x: &[S; 3]) -> S {
//!     // The paper's convention: a k-term sum of products accumulates from zero.
//!     S::zero() + x[0].clone() * x[0].clone() + x[1].clone() * x[1].clone() + x[2].clone() * x[2].clone()
//! }
//! assert_eq!(norm2(&[1.0_f64, 2.0, 2.0]), 9.0);
//! ```

use core::fmt::Debug;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// A real scalar type the dynamics algorithms can run on.
///
/// Every arithmetic operation an algorithm performs goes through these operators, so a counting
/// implementation sees all of them. Sign changes (`Neg`) are free under the paper's convention.
pub trait Scalar:
    Clone
    + Debug
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// The constant `x` (a model parameter folded into the computation, or a literal).
    fn constant(x: f64) -> Self;
    /// Zero.
    fn zero() -> Self {
        Self::constant(0.0)
    }
    /// One.
    fn one() -> Self {
        Self::constant(1.0)
    }
    /// Sine.
    #[must_use]
    fn sin(self) -> Self;
    /// Cosine.
    #[must_use]
    fn cos(self) -> Self;
    /// Square root (of a value the caller knows to be non-negative).
    #[must_use]
    fn sqrt(self) -> Self;
    /// Sine and cosine of the same angle; a tracer records them as one `sincos`.
    fn sin_cos(self) -> (Self, Self) {
        (self.clone().sin(), self.cos())
    }
    /// Marks the start of a section of the computation (an equation of the paper, e.g. `"(14b)"`).
    /// The tracer attributes the following operations to it; numeric types ignore it.
    fn section(_label: &'static str) {}
}

macro_rules! impl_float_scalar {
    ($t:ty, $sin:ident, $cos:ident, $sqrt:ident, $sincos:ident) => {
        impl Scalar for $t {
            #[inline]
            fn constant(x: f64) -> Self {
                x as $t
            }
            #[inline]
            fn sin(self) -> Self {
                #[cfg(feature = "std")]
                return <$t>::sin(self);
                #[cfg(not(feature = "std"))]
                return libm::$sin(self);
            }
            #[inline]
            fn cos(self) -> Self {
                #[cfg(feature = "std")]
                return <$t>::cos(self);
                #[cfg(not(feature = "std"))]
                return libm::$cos(self);
            }
            #[inline]
            fn sqrt(self) -> Self {
                #[cfg(feature = "std")]
                return <$t>::sqrt(self);
                #[cfg(not(feature = "std"))]
                return libm::$sqrt(self);
            }
            #[inline]
            fn sin_cos(self) -> (Self, Self) {
                #[cfg(feature = "std")]
                return <$t>::sin_cos(self);
                #[cfg(not(feature = "std"))]
                return libm::$sincos(self);
            }
        }
    };
}
impl_float_scalar!(f64, sin, cos, sqrt, sincos);
impl_float_scalar!(f32, sinf, cosf, sqrtf, sincosf);

/// What a matrix product needs of its numbers: `+ − ×` and zero. Every [`Scalar`] is one, and so
/// is each SIMD vector of [`crate::lanes`] (`f64x4`: four numbers side by side, each operation
/// IEEE lane by lane), so the loops written over it ([`crate::composed`], the products of
/// [`crate::compact::derivatives`]) run one state or `LANES` states, bit for bit alike.
pub trait Ring: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    /// Zero.
    fn zero() -> Self;
}

impl<S: Scalar + Copy> Ring for S {
    #[inline(always)]
    fn zero() -> Self {
        Scalar::zero()
    }
}

/// A scalar that records operations instead of computing them (the tracer `Sym` of
/// `kanegen-trace`). Functions that only make sense for op-count bookkeeping — not as dynamics
/// algorithms — take `S: Symbolic`, so they cannot be evaluated numerically by mistake.
pub trait Symbolic: Scalar {}

/// A numeric scalar whose values can be read back as `f64` (every [`Scalar`] except the tracer).
pub trait Real: Scalar {
    /// The nearest `f64` (for `f64` itself, the value; for wider types, rounded).
    fn to_f64(&self) -> f64;
}

impl Real for f64 {
    fn to_f64(&self) -> f64 {
        *self
    }
}

impl Real for f32 {
    fn to_f64(&self) -> f64 {
        f64::from(*self)
    }
}
