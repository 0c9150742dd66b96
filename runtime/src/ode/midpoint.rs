//! The fixed-step implicit midpoint rule on a Lie group, the structure-preserving integrator
//! for long runs (Hairer, Lubich & Wanner, *Geometric Numerical Integration*, Sec. II.1 and,
//! for the Lie-group form, Sec. IV.8):
//!
//! ```text
//! x_m = x_n ⊕ (h/2) f(t + h/2, x_m),      x_{n+1} = x_n ⊕ h f(t + h/2, x_m)
//! ```
//!
//! where `⊕` is [`System::advance`] (additive by default, so `x_m = (x_n + x_{n+1})/2` — the
//! classical implicit midpoint rule). The implicit equation is solved by fixed-point iteration
//! from the explicit-Euler predictor until the max-norm update is ≤ `1e-14 · (1 + |x|∞)`
//! (converges when `h·L/2 < 1`, `L` the Lipschitz constant of `f`; a few iterations at the
//! usual steps); [`System::project`] is **not** called.
//!
//! Properties (GNI): second order; symmetric, hence ρ-reversible for the velocity flip of a
//! mechanical system — for reversible, near-integrable motions the energy error stays bounded
//! with no secular drift (Ch. XI), which `tests/integrators.rs` measures; in canonical
//! variables `(q, p)` it would be symplectic and conserve every quadratic invariant exactly,
//! but a scene's state holds the quasi-velocities `ν = [v_b, ω_b, q̇]` (not `p = A ν`), so it
//! is **not** symplectic for these coordinates and conserves neither energy nor momentum
//! exactly — their errors are `O(h²)` and bounded (no drift). The unit quaternion stays unit to
//! round-off when the system's [`System::advance`] is the exponential map
//! ([`advance_floating`](super::quaternion::advance_floating)).
//!
//! No crate fits: `ode_solvers`, `diffsol`, `russell_ode` offer implicit Runge–Kutta methods on
//! vector states only (no Lie-group update of a user state component), and the geometric crates
//! found target canonical Hamiltonians `H(q, p)`, which would need `∂A/∂q`.

use super::rk4::Rk4Options;
use super::{fixed_run, non_finite, one_step, Flow, Scratch, Stats, Stop, System};

/// Iteration limit of a midpoint step.
pub const MAX_ITER: usize = 60;

/// The scratch floats of [`midpoint()`] and [`midpoint_step`] for a state of dimension `d`:
/// the new state, the derivative and two midpoint iterates.
#[must_use]
pub const fn scratch_len(d: usize) -> usize {
    4 * d
}

/// One midpoint step of size `h` from `(t, x)` into `out` (`work`: `3 d`).
///
/// # Errors
/// [`Stop::NonFinite`] (at `t`) when an iterate is not finite, [`Stop::NotConverged`] after
/// [`MAX_ITER`] iterations.
fn step<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &[f64],
    out: &mut [f64],
    work: &mut [f64],
    stats: &mut Stats,
) -> Result<(), Stop> {
    let d = x.len();
    let (f, work) = work.split_at_mut(d);
    let (xm, rest) = work.split_at_mut(d);
    let (mut xm, mut xm_new) = (xm, &mut rest[..d]);
    let tm = t + 0.5 * h;
    // Predictor: explicit Euler to the midpoint.
    sys.deriv(t, x, f);
    stats.evals += 1;
    sys.advance(x, 0.5 * h, x, f, xm);
    let scale = 1.0 + x.iter().fold(0.0_f64, |m, v| m.max(libm::fabs(*v)));
    let mut converged = false;
    for _ in 0..MAX_ITER {
        sys.deriv(tm, xm, f);
        stats.evals += 1;
        sys.advance(x, 0.5 * h, xm, f, xm_new);
        let diff = xm
            .iter()
            .zip(xm_new.iter())
            .fold(0.0_f64, |m, (a, b)| m.max(libm::fabs(a - b)));
        core::mem::swap(&mut xm, &mut xm_new);
        if !diff.is_finite() {
            let index = non_finite(xm).unwrap_or(0);
            return Err(Stop::NonFinite {
                t,
                index,
                stats: *stats,
            });
        }
        if diff <= 1e-14 * scale {
            converged = true;
            break;
        }
    }
    if !converged {
        return Err(Stop::NotConverged { t, stats: *stats });
    }
    // Full step along the derivative at the (converged) midpoint.
    sys.advance(x, h, xm, f, out);
    Ok(())
}

/// The fixed-step implicit midpoint rule (see the module doc) from `t0` to `t1`
/// ([`fixed_steps`](super::fixed_steps)); `observe(t, x)` at `t0`, after every
/// `output_every`-th step and after the last. `scratch` holds at least
/// [`scratch_len`]`(x.len())` floats.
///
/// # Errors
/// The first failed step's [`Stop`] (`x` keeps the last accepted state), [`Stop::Interrupted`]
/// or [`Stop::Invalid`].
pub fn midpoint<S: System + ?Sized, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    opts: &Rk4Options,
    x: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
    observe: impl FnMut(f64, &[f64]) -> R,
) -> Result<Stats, Stop> {
    let scratch = (scratch, scratch_len(x.len()));
    fixed_run(sys, (t0, t1), opts, x, scratch, observe, step)
}

/// One implicit midpoint step of size `h` from `(t, x)` in place (`scratch`: at least
/// [`scratch_len`]`(x.len())` floats); the work done.
///
/// # Errors
/// [`Stop::NonFinite`] when an iterate or the result is not finite, [`Stop::NotConverged`]
/// after [`MAX_ITER`] iterations, or [`Stop::Invalid`]; `x` is then unchanged.
pub fn midpoint_step<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
) -> Result<Stats, Stop> {
    let len = (scratch_len(x.len()), 0);
    one_step(sys, t, h, x, scratch, len, |sys, x, out, work, _, stats| {
        step(sys, t, h, x, out, work, stats)
    })
}
