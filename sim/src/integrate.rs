//! The integrators of the simulation: those of [`kanegen_runtime::ode`] (RK4, Dormand–Prince
//! 5(4) with dense output, Rodas4, the Lie-group implicit midpoint rule — the same code the
//! `scene!` simulators run), each with heap scratch allocated once per run
//! ([`VecScratch`]) and, for the fixed-step methods, an observer that also gets the step index.

use kanegen_runtime::ode::{self, VecScratch};
pub use kanegen_runtime::ode::{Dopri5Options, Flow, Rk4Options, Stats, Stop, System};

/// The options of a fixed-step run ([`ode::rk4`], [`ode::midpoint`]) with step about `h`
/// observing every step, and its observer: `observe(step, t, x)` with the step index (0 at
/// `t0`).
fn every_step<R: Flow>(
    h: f64,
    mut observe: impl FnMut(usize, f64, &[f64]) -> R,
) -> (Rk4Options, impl FnMut(f64, &[f64]) -> R) {
    let opts = Rk4Options {
        step: h,
        output_every: 1,
    };
    let mut step = 0;
    let observe = move |t: f64, x: &[f64]| {
        let flow = observe(step, t, x);
        step += 1;
        flow
    };
    (opts, observe)
}

/// Classical RK4 ([`ode::rk4`]) from `t0` to `t1` with `n = ⌈(t1 − t0)/h⌉` equal steps;
/// `observe(step, t, x)` at `t0` (step 0) and after every step.
///
/// # Errors
/// The runtime's [`Stop`]: a non-finite state, an interruption, invalid input.
pub fn rk4<S: System + ?Sized, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    h: f64,
    x: &mut [f64],
    observe: impl FnMut(usize, f64, &[f64]) -> R,
) -> Result<Stats, Stop> {
    let (opts, observe) = every_step(h, observe);
    ode::rk4(sys, t0, t1, &opts, x, &mut VecScratch::default(), observe)
}

/// The Lie-group implicit midpoint rule ([`ode::midpoint`], whose module doc says what it
/// preserves) from `t0` to `t1` with `n = ⌈(t1 − t0)/h⌉` equal steps; `observe(step, t, x)` at
/// `t0` (step 0) and after every step.
///
/// # Errors
/// The runtime's [`Stop`]: a non-finite state, iterations that do not converge, an
/// interruption, invalid input.
pub fn midpoint<S: System + ?Sized, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    h: f64,
    x: &mut [f64],
    observe: impl FnMut(usize, f64, &[f64]) -> R,
) -> Result<Stats, Stop> {
    let (opts, observe) = every_step(h, observe);
    ode::midpoint(sys, t0, t1, &opts, x, &mut VecScratch::default(), observe)
}

/// Adaptive Dormand–Prince 5(4) ([`ode::dopri5`]) from `t0` to `t1`: `observe(t, x)` at `t0`,
/// at every `t0 + k·output_interval < t1` (dense output) and at `t1`.
///
/// # Errors
/// The runtime's [`Stop`].
pub fn dopri5<S: System + ?Sized, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    opts: &Dopri5Options,
    x: &mut [f64],
    observe: impl FnMut(f64, &[f64]) -> R,
) -> Result<Stats, Stop> {
    ode::dopri5(sys, t0, t1, opts, x, &mut VecScratch::default(), observe)
}

/// Adaptive Rodas4 ([`ode::rosenbrock`], the stiff integrator) from `t0` to `t1`:
/// `observe(t, x)` at `t0`, at every `t0 + k·output_interval < t1` (the steps land on them)
/// and at `t1`.
///
/// # Errors
/// The runtime's [`Stop`].
pub fn rosenbrock<S: System + ?Sized, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    opts: &Dopri5Options,
    x: &mut [f64],
    observe: impl FnMut(f64, &[f64]) -> R,
) -> Result<Stats, Stop> {
    ode::rosenbrock(sys, t0, t1, opts, x, &mut VecScratch::default(), observe)
}
