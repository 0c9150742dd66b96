//! [`Lane`]: a lane type as a [`Scalar`] of the compact kernels ([`crate::compact`]), so that one
//! call evaluates `S::LANES` states, each lane bit for bit the `f64` kernel's result for its
//! state: `+ − × ÷` are the vector operations (IEEE, lane by lane), the negation flips the sign
//! bit as the scalar `-x` does ([`Lanes::neg`]), and the sine, cosine and square root are the
//! `f64` routines on each lane. (The composed loops, [`crate::composed`], need only `+ − ×` and
//! run on the lane type itself, a [`crate::Ring`].)

use super::Lanes;
use crate::scalar::Scalar;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// `S::LANES` `f64` values side by side (`f64` itself, `f64x2`, `f64x4`, `f64x8`), a [`Scalar`]
/// for the compact kernels.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct Lane<S>(pub S);

macro_rules! binary {
    ($($tr:ident $f:ident),*) => {$(
        impl<S: Lanes<f64>> $tr for Lane<S> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                Lane(self.0.$f(o.0))
            }
        }
    )*};
}
binary!(Add add, Sub sub, Mul mul, Div div);

impl<S: Lanes<f64>> Neg for Lane<S> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Lane(Lanes::neg(self.0))
    }
}

impl<S: Lanes<f64>> Lane<S> {
    /// The scalar `f` on each lane.
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Lane(S::from_fn(|i| f(self.0.lane(i))))
    }

    /// `(sin x, cos x)` by the table sine–cosine of generated code, fused where the build targets
    /// FMA: each lane that of the generated type's `sincos` ([`Lanes::sincos_n`]).
    #[inline(always)]
    #[must_use]
    pub fn sincos_table(self) -> (Self, Self) {
        let [(s, c)] = S::sincos_n([self.0]);
        (Lane(s), Lane(c))
    }

    /// [`Lane::sincos_table`] never fused ([`Lanes::sincos_n_unfused`]).
    #[inline(always)]
    #[must_use]
    pub fn sincos_table_unfused(self) -> (Self, Self) {
        let [(s, c)] = S::sincos_n_unfused([self.0]);
        (Lane(s), Lane(c))
    }

    /// `(sin x, cos x)` by libm's `sincos` on each lane ([`Lanes::sincos`]).
    #[inline(always)]
    #[must_use]
    pub fn sincos_libm(self) -> (Self, Self) {
        let (s, c) = self.0.sincos();
        (Lane(s), Lane(c))
    }
}

impl<S: Lanes<f64>> Scalar for Lane<S> {
    #[inline(always)]
    fn constant(x: f64) -> Self {
        Lane(S::splat(x))
    }
    #[inline(always)]
    fn sin(self) -> Self {
        self.map(<f64 as Scalar>::sin)
    }
    #[inline(always)]
    fn cos(self) -> Self {
        self.map(<f64 as Scalar>::cos)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(<f64 as Scalar>::sqrt)
    }
}

/// An argument of a generated `NAME_lanes` as the compact kernels take it: each value a
/// [`Lane`].
#[inline(always)]
#[must_use]
pub fn wrap<S: Copy, const K: usize>(x: &[S; K]) -> [Lane<S>; K] {
    x.map(Lane)
}

/// [`wrap`] of an argument of rows (the wrenches `f_ext`, `[[S; 6]; N]`).
#[inline(always)]
#[must_use]
pub fn wrap_rows<S: Copy, const J: usize, const K: usize>(x: &[[S; J]; K]) -> [[Lane<S>; J]; K] {
    x.map(|row| row.map(Lane))
}

/// The values of a kernel's result in [`Lane`]s: arrays of any depth, and pairs and triples of
/// them.
pub trait Unlane {
    /// The result with each [`Lane`] replaced by its value.
    type Out;
    /// Each [`Lane`]'s value.
    fn unlane(self) -> Self::Out;
}

impl<S> Unlane for Lane<S> {
    type Out = S;
    #[inline(always)]
    fn unlane(self) -> S {
        self.0
    }
}

impl<T: Unlane, const K: usize> Unlane for [T; K] {
    type Out = [T::Out; K];
    #[inline(always)]
    fn unlane(self) -> Self::Out {
        self.map(Unlane::unlane)
    }
}

impl<A: Unlane, B: Unlane> Unlane for (A, B) {
    type Out = (A::Out, B::Out);
    #[inline(always)]
    fn unlane(self) -> Self::Out {
        (self.0.unlane(), self.1.unlane())
    }
}

impl<A: Unlane, B: Unlane, C: Unlane> Unlane for (A, B, C) {
    type Out = (A::Out, B::Out, C::Out);
    #[inline(always)]
    fn unlane(self) -> Self::Out {
        (self.0.unlane(), self.1.unlane(), self.2.unlane())
    }
}
