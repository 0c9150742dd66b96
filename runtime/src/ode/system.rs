//! The first-order system `ẋ = f(t, x)` the integrators advance, and its closure form for
//! fixed-size states ([`FnSystem`]; a scene's right-hand side is `crate::scene::SceneOde`).

use super::quaternion;

/// A first-order system `ẋ = f(t, x)` over states of length [`System::dim`].
pub trait System {
    /// Dimension of the state.
    fn dim(&self) -> usize;
    /// Writes `f(t, x)` into `dx` (both of length [`System::dim`]).
    fn deriv(&mut self, t: f64, x: &[f64], dx: &mut [f64]);
    /// Projects an accepted state back onto the constraint manifold (e.g. renormalizes a unit
    /// quaternion, [`quaternion::normalize_quaternion`]). Default: nothing.
    fn project(&self, _x: &mut [f64]) {}
    /// Writes into `out` the state reached from `x` by following, for a time `h`, the flow
    /// frozen at the point `at` where the derivative `f = f(t, at)` was evaluated — the update
    /// of [`midpoint`](super::midpoint()). Default: the additive `out = x + h f`. A system with
    /// a Lie-group component overrides it for that component (e.g. `quat ⊗ exp(h ω(at) / 2)`
    /// for a unit quaternion, [`quaternion::advance_floating`], so it stays unit without
    /// [`System::project`]); the update must be symmetric (following `−h` from `out` with the
    /// same `at` gives back `x`).
    fn advance(&self, x: &[f64], h: f64, _at: &[f64], f: &[f64], out: &mut [f64]) {
        quaternion::advance_additive(x, h, f, out);
    }
    /// Whether the run was asked to stop (Ctrl-C): checked after every accepted step; the
    /// integrator then returns [`Stop::Interrupted`](super::Stop::Interrupted) with the state
    /// reached in `x`. Default: never.
    fn interrupted(&self) -> bool {
        false
    }
}

/// The [`System`] of a right-hand side `rhs(t, &x) -> ẋ` over `[f64; D]`. With `floating`, the state is a free-floating one, `[p₀, quat, q, v_b, ω_b, q̇]`
/// (`D = 13 + 2n`): the quaternion is renormalized by [`System::project`] and advanced by the
/// exponential map ([`quaternion::advance_floating`]).
#[derive(Clone, Copy, Debug)]
pub struct FnSystem<const D: usize, F> {
    /// The right-hand side.
    pub rhs: F,
    /// Whether the state has a free-floating base's quaternion at `x[3..7]`.
    pub floating: bool,
}

impl<const D: usize, F: FnMut(f64, &[f64; D]) -> [f64; D]> System for FnSystem<D, F> {
    fn dim(&self) -> usize {
        D
    }

    /// `rhs` on `x`; a slice of another length (which the integrators refuse before they call
    /// this) gives NaN.
    fn deriv(&mut self, t: f64, x: &[f64], dx: &mut [f64]) {
        match (
            <&[f64; D]>::try_from(x),
            <&mut [f64; D]>::try_from(&mut *dx),
        ) {
            (Ok(x), Ok(dx)) => *dx = (self.rhs)(t, x),
            _ => dx.fill(f64::NAN),
        }
    }

    fn project(&self, x: &mut [f64]) {
        if self.floating {
            quaternion::normalize_quaternion(x);
        }
    }

    fn advance(&self, x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
        if self.floating {
            quaternion::advance_floating(x, h, at, f, out);
        } else {
            quaternion::advance_additive(x, h, f, out);
        }
    }
}
