//! The integrators of kanegen, written once: allocation-free, panic-free and `no_std`, over a
//! [`System`] whose state is a slice, with caller-provided [`Scratch`] memory — the interpreted
//! simulator (`kanegen-sim`, states sized at run time, [`VecScratch`]) and the simulators that
//! `scene!` emits ([`ArrayScratch`] on the stack, through [`crate::scene::SceneOde`])
//! run the same code step for step.
//!
//! - [`rk4()`]: fixed-step classical Runge–Kutta 4 (Hairer, Nørsett & Wanner, *Solving ODEs I*,
//!   Table 1.2 of Sec. II.1), projecting after every step.
//! - [`dopri5()`]: adaptive Dormand–Prince 5(4) (HNW I, Table 5.2) with Hairer's PI step-size
//!   controller and 4th-order dense output, projecting after every accepted step.
//! - [`rosenbrock()`]: adaptive Rodas4, the stiffly accurate, L-stable Rosenbrock method
//!   (Hairer & Wanner, *Solving ODEs II*, Sec. IV.7), with its LU solve ([`lu`]).
//! - [`midpoint()`]: the fixed-step Lie-group implicit midpoint rule (Hairer, Lubich & Wanner,
//!   *Geometric Numerical Integration*), with the quaternion exponential map of a free-floating
//!   base ([`quaternion`]).
//! - [`linearize`]: the Jacobians `(A, B)` of one RK4 or midpoint step of a system with
//!   inputs, exact for the scheme (what MPC and iLQR linearize about).
//! - [`profile`]: the time profiles of a scene's drives and loads ([`quintic`], [`table`]).
//!
//! Nothing here allocates or panics: a run that cannot go on returns a [`Stop`], with the last
//! accepted state left in `x`; bad input (a state of the wrong length, too little scratch, a
//! non-positive step or tolerance) is a [`Stop::Invalid`].

use core::ops::ControlFlow;

pub mod dopri5;
pub mod linearize;
pub mod lu;
pub mod midpoint;
pub mod profile;
pub mod quaternion;
pub mod rk4;
pub mod rosenbrock;
mod scratch;
mod system;

pub use dopri5::{dopri5, Dopri5Options};
pub use linearize::{
    floating_midpoint_step_jacobians, floating_rk4_step_jacobians, midpoint_step_jacobians,
    rk4_step_jacobians, ControlledSystem,
};
pub use lu::solve_spd;
pub use midpoint::{midpoint, midpoint_step};
pub use profile::{quintic, table};
pub use quaternion::{normalize_quaternion, quat_to_matrix};
pub use rk4::{rk4, rk4_step, Rk4Options};
pub use rosenbrock::{rosenbrock, rosenbrock_step, RosenbrockOptions};
#[cfg(feature = "std")]
pub use scratch::VecScratch;
pub use scratch::{ArrayScratch, Scratch};
pub use system::{FnSystem, System};

/// What an `observe` callback returns: `()` (go on) or a [`ControlFlow`] (`Break` stops the run
/// with [`Stop::Interrupted`]).
pub trait Flow {
    /// Whether the run is to stop.
    fn stop(self) -> bool;
}

impl Flow for () {
    fn stop(self) -> bool {
        false
    }
}

impl Flow for ControlFlow<()> {
    fn stop(self) -> bool {
        self.is_break()
    }
}

/// Work counters of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (always 0 for the fixed-step methods).
    pub rejected_steps: usize,
    /// Evaluations of [`System::deriv`].
    pub evals: usize,
}

impl Stats {
    /// Adds the work of `other` (a later segment of the same run).
    pub fn accumulate(&mut self, other: Stats) {
        self.steps += other.steps;
        self.rejected_steps += other.rejected_steps;
        self.evals += other.evals;
    }
}

/// Why a run stopped before its end time. Each variant carries the time reached and the work
/// done up to there; the state passed in holds the last accepted state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// The adaptive step size fell below the floating-point resolution of `t`.
    StepTooSmall {
        /// Time reached.
        t: f64,
        /// Work done.
        stats: Stats,
    },
    /// The state became non-finite (the last accepted state, in `x`, is still finite).
    NonFinite {
        /// Time of the step that overflowed.
        t: f64,
        /// The first non-finite component of the new state.
        index: usize,
        /// Work done.
        stats: Stats,
    },
    /// The error estimate of an adaptive step overflowed while the state stayed finite: the
    /// tolerance is too small for the size of the state, or the derivative overflowed.
    ErrorEstimate {
        /// Time reached.
        t: f64,
        /// Work done.
        stats: Stats,
    },
    /// The implicit equations of a [`midpoint()`] step were not solved.
    NotConverged {
        /// Time reached.
        t: f64,
        /// Work done.
        stats: Stats,
    },
    /// The run was stopped ([`System::interrupted`], or `observe` returned `Break`).
    Interrupted {
        /// Time reached.
        t: f64,
        /// Work done.
        stats: Stats,
    },
    /// The run was not started: `what` is wrong with its input.
    Invalid {
        /// The start time.
        t: f64,
        /// What is wrong (a state of the wrong length, too little scratch, a step, tolerance
        /// or interval that is not positive, an end before the start).
        what: &'static str,
    },
}

impl Stop {
    /// The time reached.
    #[must_use]
    pub fn t(&self) -> f64 {
        match self {
            Stop::StepTooSmall { t, .. }
            | Stop::NonFinite { t, .. }
            | Stop::ErrorEstimate { t, .. }
            | Stop::NotConverged { t, .. }
            | Stop::Interrupted { t, .. }
            | Stop::Invalid { t, .. } => *t,
        }
    }

    /// The work done up to the stop.
    #[must_use]
    pub fn stats(&self) -> Stats {
        match self {
            Stop::StepTooSmall { stats, .. }
            | Stop::NonFinite { stats, .. }
            | Stop::ErrorEstimate { stats, .. }
            | Stop::NotConverged { stats, .. }
            | Stop::Interrupted { stats, .. } => *stats,
            Stop::Invalid { .. } => Stats::default(),
        }
    }
}

impl core::fmt::Display for Stop {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Stop::StepTooSmall { t, .. } => write!(
                f,
                "step size underflow at t = {t} (the tolerance cannot be met at this time: a \
                 singularity or a stiff drive)"
            ),
            Stop::NonFinite { t, index, .. } => write!(
                f,
                "state component {index} became non-finite in the step to t = {t}"
            ),
            Stop::ErrorEstimate { t, .. } => write!(
                f,
                "the error estimate overflowed at t = {t} while the state stayed finite (the \
                 tolerance is too small for the size of the state, or the derivative overflowed)"
            ),
            Stop::NotConverged { t, .. } => write!(
                f,
                "implicit midpoint iterations did not converge at t = {t} (reduce the step)"
            ),
            Stop::Interrupted { t, .. } => write!(f, "interrupted at t = {t}"),
            Stop::Invalid { t, what } => write!(f, "integration from t = {t} not started: {what}"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for Stop {}

/// The first non-finite component of `x`.
fn non_finite(x: &[f64]) -> Option<usize> {
    x.iter().position(|v| !v.is_finite())
}

/// The number of fixed steps from `t0` to `t1` with step about `h`, and the step actually
/// taken: `n = ⌈(t1 − t0)/h⌉` (less a `1e-9` slack, at least 1) equal steps of `(t1 − t0)/n`,
/// so the run ends exactly at `t1`.
#[must_use]
pub fn fixed_steps(t0: f64, t1: f64, h: f64) -> (usize, f64) {
    let n = libm::ceil((t1 - t0) / h - 1e-9);
    let n = if n >= 1.0 { n as usize } else { 1 };
    (n, (t1 - t0) / n as f64)
}

/// `Ok` when `x` has the system's dimension and `[t0, t1]` is a non-empty, finite interval.
fn check_run<S: System + ?Sized>(sys: &S, t0: f64, t1: f64, x: &[f64]) -> Result<(), Stop> {
    let invalid = |what| Err(Stop::Invalid { t: t0, what });
    if x.len() != sys.dim() {
        return invalid("the state's length is not the system's dimension");
    }
    if t0.is_finite() && t1.is_finite() && t1 >= t0 {
        return Ok(());
    }
    invalid("the end time is before the start time (or not finite)")
}

/// `scratch`'s first `floats` floats and `pivots` indices, or [`Stop::Invalid`] at `t`.
fn take<Sc: Scratch + ?Sized>(
    scratch: &mut Sc,
    t: f64,
    floats: usize,
    pivots: usize,
) -> Result<(&mut [f64], &mut [usize]), Stop> {
    scratch.get(floats, pivots).ok_or(Stop::Invalid {
        t,
        what: "the scratch is smaller than the method needs for this state",
    })
}

/// `x^y` from the platform's `libm` with `std` (as the interpreted simulator always took it),
/// else the `libm` crate's.
fn pow(x: f64, y: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.powf(y);
    #[cfg(not(feature = "std"))]
    return libm::pow(x, y);
}

/// `∛x`, from the same library as [`pow`].
fn cbrt(x: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.cbrt();
    #[cfg(not(feature = "std"))]
    return libm::cbrt(x);
}

/// The fixed-step loop of [`rk4()`] and [`midpoint()`] ([`fixed_steps`]): `step(sys, t, h, x,
/// out, work, stats)` writes the state after one step into `out` (`scratch` holds `floats`
/// floats: `out` and `work`); the loop refuses bad input (a step not positive), rejects a
/// non-finite one, counts it, calls `observe(t, x)` at `t0`, after every `output_every`-th step
/// and after the last, and checks [`System::interrupted`] after every step but the last.
fn fixed_run<S, R, F>(
    sys: &mut S,
    (t0, t1): (f64, f64),
    opts: &Rk4Options,
    x: &mut [f64],
    (scratch, floats): (&mut (impl Scratch + ?Sized), usize),
    mut observe: impl FnMut(f64, &[f64]) -> R,
    mut step: F,
) -> Result<Stats, Stop>
where
    S: System + ?Sized,
    R: Flow,
    F: FnMut(&mut S, f64, f64, &[f64], &mut [f64], &mut [f64], &mut Stats) -> Result<(), Stop>,
{
    check_run(sys, t0, t1, x)?;
    if !(opts.step.is_finite() && opts.step > 0.0) {
        return Err(Stop::Invalid {
            t: t0,
            what: "the step is not positive and finite",
        });
    }
    let (work, _) = take(scratch, t0, floats, 0)?;
    let (n, h) = fixed_steps(t0, t1, opts.step);
    let every = opts.output_every.max(1);
    let (out, work) = work.split_at_mut(x.len());
    let mut stats = Stats::default();
    if observe(t0, x).stop() {
        return Err(Stop::Interrupted { t: t0, stats });
    }
    for k in 1..=n {
        let t = t0 + (k - 1) as f64 * h;
        step(sys, t, h, x, out, work, &mut stats)?;
        let t = if k == n { t1 } else { t0 + k as f64 * h };
        if let Some(index) = non_finite(out) {
            return Err(Stop::NonFinite { t, index, stats });
        }
        x.copy_from_slice(out);
        stats.steps += 1;
        let observed = (k % every == 0 || k == n) && observe(t, x).stop();
        if observed || (k < n && sys.interrupted()) {
            return Err(Stop::Interrupted { t, stats });
        }
    }
    Ok(stats)
}

/// One step in place ([`rk4_step`], [`midpoint_step`], [`rosenbrock_step`]) after checking
/// the input: `step(sys, x, out, work, pivots, stats)` writes the new state into `out` (the
/// first `x.len()` of `floats` scratch floats; `work` the rest); `x` takes it when it is
/// finite (else [`Stop::NonFinite`] at `t + h`, `x` unchanged).
#[allow(clippy::type_complexity)]
fn one_step<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
    (floats, pivots): (usize, usize),
    step: impl FnOnce(
        &mut S,
        &[f64],
        &mut [f64],
        &mut [f64],
        &mut [usize],
        &mut Stats,
    ) -> Result<(), Stop>,
) -> Result<Stats, Stop> {
    check_run(sys, t, t, x)?;
    let (work, piv) = take(scratch, t, floats, pivots)?;
    let (out, work) = work.split_at_mut(x.len());
    let mut stats = Stats::default();
    step(sys, x, out, work, piv, &mut stats)?;
    if let Some(index) = non_finite(out) {
        return Err(Stop::NonFinite {
            t: t + h,
            index,
            stats,
        });
    }
    x.copy_from_slice(out);
    stats.steps += 1;
    Ok(stats)
}

#[cfg(test)]
mod tests;
