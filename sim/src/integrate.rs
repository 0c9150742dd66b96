//! ODE integrators for the simulation (`f64`): fixed-step classical Runge–Kutta 4 ([`rk4`]) and
//! adaptive Dormand–Prince 5(4) with dense output ([`dopri5`]), both explicit over a [`System`]
//! with a post-step [`System::project`] hook (quaternion renormalization); and the fixed-step
//! Lie-group implicit midpoint rule ([`midpoint`], for long runs: symmetric, bounded energy error,
//! unit quaternion by construction — see its doc for what it does and does not preserve).
//!
//! Hand-written rather than taken from a crate: `ode_solvers` (the obvious candidate) supports
//! dynamically sized `DVector` states, but its `System::solout` callback sees the state
//! immutably, so there is no way to project the state (renormalize the base quaternion) after an
//! accepted step; the two methods are ~200 lines here and are tested for their order and
//! accuracy in `tests/simulate.rs`.

use std::ops::ControlFlow;

/// A first-order system `ẋ = f(t, x)`.
pub trait System {
    /// Dimension of the state.
    fn dim(&self) -> usize;
    /// Writes `f(t, x)` into `dx` (both of length [`System::dim`]).
    fn deriv(&mut self, t: f64, x: &[f64], dx: &mut [f64]);
    /// Projects an accepted state back onto the constraint manifold (e.g. renormalizes a unit
    /// quaternion). Default: nothing.
    fn project(&self, _x: &mut [f64]) {}
    /// Writes into `out` the state reached from `x` by following, for a time `h`, the flow
    /// frozen at the point `at` where the derivative `f = f(t, at)` was evaluated — the update
    /// of [`midpoint`]. Default: the additive `out = x + h f`. A system with a Lie-group
    /// component overrides it for that component (e.g. `quat ⊗ exp(h ω(at) / 2)` for a unit
    /// quaternion, so it stays unit without [`System::project`]); the update must be symmetric
    /// (following `−h` from `out` with the same `at` gives back `x`).
    fn advance(&self, x: &[f64], h: f64, _at: &[f64], f: &[f64], out: &mut [f64]) {
        for i in 0..out.len() {
            out[i] = x[i] + h * f[i];
        }
    }
    /// Whether the run was asked to stop (Ctrl-C): checked after every accepted step; the
    /// integrator then returns [`IntegrateError::Interrupted`] with the state reached in `x`.
    /// Default: never.
    fn interrupted(&self) -> bool {
        false
    }
}

/// What an `observe` callback returns: `()` (go on) or a [`ControlFlow`] (`Break` stops the run
/// with [`IntegrateError::Interrupted`]).
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
    /// Rejected steps (always 0 for [`rk4`]).
    pub rejected_steps: usize,
    /// Evaluations of [`System::deriv`].
    pub evals: usize,
}

/// Why an integration stopped early. Each variant carries the time reached and the work done
/// up to there; the state passed in holds the last accepted state.
#[derive(Debug)]
pub enum IntegrateError {
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
    /// The error estimate of a [`dopri5`] step overflowed while the state stayed finite: the
    /// tolerance is too small for the size of the state, or the derivative overflowed.
    ErrorEstimate {
        /// Time reached.
        t: f64,
        /// Work done.
        stats: Stats,
    },
    /// The implicit equations of a [`midpoint`] step were not solved.
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
}

impl IntegrateError {
    /// The time reached.
    #[must_use]
    pub fn t(&self) -> f64 {
        match self {
            IntegrateError::StepTooSmall { t, .. }
            | IntegrateError::NonFinite { t, .. }
            | IntegrateError::ErrorEstimate { t, .. }
            | IntegrateError::NotConverged { t, .. }
            | IntegrateError::Interrupted { t, .. } => *t,
        }
    }

    /// The work done up to the stop.
    #[must_use]
    pub fn stats(&self) -> Stats {
        match self {
            IntegrateError::StepTooSmall { stats, .. }
            | IntegrateError::NonFinite { stats, .. }
            | IntegrateError::ErrorEstimate { stats, .. }
            | IntegrateError::NotConverged { stats, .. }
            | IntegrateError::Interrupted { stats, .. } => *stats,
        }
    }
}

impl std::error::Error for IntegrateError {}

impl std::fmt::Display for IntegrateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IntegrateError::StepTooSmall { t, .. } => write!(
                f,
                "step size underflow at t = {t} (the tolerance cannot be met at this time: a \
                 singularity or a stiff drive)"
            ),
            IntegrateError::NonFinite { t, index, .. } => write!(
                f,
                "state component {index} became non-finite in the step to t = {t}"
            ),
            IntegrateError::ErrorEstimate { t, .. } => write!(
                f,
                "the dopri5 error estimate overflowed at t = {t} while the state stayed finite \
                 (the tolerance is too small for the size of the state, or the derivative \
                 overflowed)"
            ),
            IntegrateError::NotConverged { t, .. } => write!(
                f,
                "implicit midpoint iterations did not converge at t = {t} (reduce the step)"
            ),
            IntegrateError::Interrupted { t, .. } => write!(f, "interrupted at t = {t}"),
        }
    }
}

/// The first non-finite component of `x`.
fn non_finite(x: &[f64]) -> Option<usize> {
    x.iter().position(|v| !v.is_finite())
}

fn axpy(out: &mut [f64], x: &[f64], terms: &[(f64, &[f64])]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = x[i] + terms.iter().map(|(c, k)| c * k[i]).sum::<f64>();
    }
}

/// Classical RK4 from `t0` to `t1` with `n = ⌈(t1 − t0)/h⌉` equal steps (the step is shortened
/// to `(t1 − t0)/n` so the run ends exactly at `t1`). `x` is advanced in place and projected
/// after each step. `observe(step, t, x)` is called at `t0` (step 0) and after every step.
pub fn rk4<S: System, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    h: f64,
    x: &mut [f64],
    mut observe: impl FnMut(usize, f64, &[f64]) -> R,
) -> Result<Stats, IntegrateError> {
    assert!(h > 0.0 && t1 >= t0, "rk4 needs h > 0 and t1 >= t0");
    let n = ((t1 - t0) / h - 1e-9).ceil().max(1.0) as usize;
    let h = (t1 - t0) / n as f64;
    let d = sys.dim();
    let (mut k1, mut k2, mut k3, mut k4, mut tmp) = (
        vec![0.0; d],
        vec![0.0; d],
        vec![0.0; d],
        vec![0.0; d],
        vec![0.0; d],
    );
    let mut stats = Stats::default();
    if observe(0, t0, x).stop() {
        return Err(IntegrateError::Interrupted { t: t0, stats });
    }
    for step in 1..=n {
        let t = t0 + (step - 1) as f64 * h;
        sys.deriv(t, x, &mut k1);
        axpy(&mut tmp, x, &[(0.5 * h, &k1)]);
        sys.deriv(t + 0.5 * h, &tmp, &mut k2);
        axpy(&mut tmp, x, &[(0.5 * h, &k2)]);
        sys.deriv(t + 0.5 * h, &tmp, &mut k3);
        axpy(&mut tmp, x, &[(h, &k3)]);
        sys.deriv(t + h, &tmp, &mut k4);
        axpy(
            &mut tmp,
            x,
            &[
                (h / 6.0, &k1),
                (h / 3.0, &k2),
                (h / 3.0, &k3),
                (h / 6.0, &k4),
            ],
        );
        stats.evals += 4;
        let t = if step == n { t1 } else { t0 + step as f64 * h };
        sys.project(&mut tmp);
        if let Some(index) = non_finite(&tmp) {
            return Err(IntegrateError::NonFinite { t, index, stats });
        }
        x.copy_from_slice(&tmp);
        stats.steps += 1;
        if observe(step, t, x).stop() || (step < n && sys.interrupted()) {
            return Err(IntegrateError::Interrupted { t, stats });
        }
    }
    Ok(stats)
}

/// Options of [`dopri5`].
#[derive(Clone, Copy, Debug)]
pub struct Dopri5Options {
    /// Relative and absolute tolerance (`rtol = atol`).
    pub tolerance: f64,
    /// Largest step.
    pub max_step: f64,
    /// First step tried.
    pub initial_step: f64,
    /// Spacing of the dense-output samples passed to `observe`.
    pub output_interval: f64,
}

// Dormand–Prince 5(4) tableau (Hairer, Nørsett & Wanner, *Solving ODEs I*, Table 5.2).
const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// 5th-order minus embedded 4th-order weights (the error estimate).
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Dense-output coefficients of Hairer's DOPRI5 (the 4th-order continuous extension).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// Adaptive Dormand–Prince 5(4) from `t0` to `t1` (local extrapolation: the 5th-order solution is
/// propagated, the embedded 4th-order one gives the error estimate). Error norm: RMS of
/// `err_i / (tol + tol·max(|x_i|, |x_new_i|))`; Hairer's PI step-size controller (exponents
/// `0.2 − 0.75β`, `β = 0.04`, safety 0.9, factor limits `[0.2, 10]`); a step is accepted when
/// the norm is ≤ 1. After an accepted step the state is projected and the derivative is
/// re-evaluated at the projected state (so FSAL is used only when the projection changed nothing).
///
/// `observe(t, x)` is called at `t0`, at every `t0 + k·output_interval < t1` — these samples come
/// from the standard DOPRI5 continuous extension (4th-order dense output, Hairer's coefficients)
/// — and at `t1`.
pub fn dopri5<S: System, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    opts: &Dopri5Options,
    x: &mut [f64],
    mut observe: impl FnMut(f64, &[f64]) -> R,
) -> Result<Stats, IntegrateError> {
    assert!(opts.tolerance > 0.0 && opts.max_step > 0.0 && opts.initial_step > 0.0);
    assert!(opts.output_interval > 0.0 && t1 >= t0);
    let d = sys.dim();
    let tol = opts.tolerance;
    let mut k: Vec<Vec<f64>> = vec![vec![0.0; d]; 7];
    let mut tmp = vec![0.0; d];
    let mut xnew = vec![0.0; d];
    let mut dense = vec![0.0; d];
    let mut stats = Stats::default();
    let mut t = t0;
    let mut h = opts.initial_step.min(opts.max_step);
    let (beta, safety) = (0.04, 0.9);
    let expo = 0.2 - 0.75 * beta;
    let mut facold: f64 = 1e-4;
    let mut next_out = 1usize;
    if observe(t0, x).stop() {
        return Err(IntegrateError::Interrupted { t: t0, stats });
    }
    sys.deriv(t, x, &mut k[0]);
    stats.evals += 1;
    while t < t1 {
        let last = t + h >= t1 - 1e-12 * t1.abs().max(1.0);
        if last {
            h = t1 - t;
        }
        if h <= f64::EPSILON * t.abs().max(1.0) {
            return Err(IntegrateError::StepTooSmall { t, stats });
        }
        for s in 1..7 {
            for i in 0..d {
                let mut acc = 0.0;
                for (j, kj) in k.iter().enumerate().take(s) {
                    acc += A[s][j] * kj[i];
                }
                tmp[i] = x[i] + h * acc;
            }
            sys.deriv(t + C[s] * h, &tmp, &mut k[s]);
        }
        stats.evals += 6;
        // tmp holds the 5th-order solution (stage 7 is evaluated there).
        xnew.copy_from_slice(&tmp);
        let mut err = 0.0;
        for i in 0..d {
            let e: f64 = h * (0..7).map(|s| E[s] * k[s][i]).sum::<f64>();
            let sc = tol + tol * x[i].abs().max(xnew[i].abs());
            err += (e / sc) * (e / sc);
        }
        let err = (err / d as f64).sqrt();
        if !err.is_finite() {
            return Err(match non_finite(&xnew) {
                Some(index) => IntegrateError::NonFinite {
                    t: t + h,
                    index,
                    stats,
                },
                None => IntegrateError::ErrorEstimate { t, stats },
            });
        }
        let fac11 = err.powf(expo);
        if err <= 1.0 {
            // Dense output over [t, t + h] before projecting.
            let tn = if last { t1 } else { t + h };
            while next_out as f64 * opts.output_interval + t0 < tn - 1e-12 * tn.abs().max(1.0) {
                let ts = t0 + next_out as f64 * opts.output_interval;
                let th = (ts - t) / h;
                let th1 = 1.0 - th;
                for i in 0..d {
                    let ydiff = xnew[i] - x[i];
                    let bspl = h * k[0][i] - ydiff;
                    let r4 = ydiff - h * k[6][i] - bspl;
                    let r5 = h * (0..7).map(|s| D[s] * k[s][i]).sum::<f64>();
                    dense[i] = x[i] + th * (ydiff + th1 * (bspl + th * (r4 + th1 * r5)));
                }
                if observe(ts, &dense).stop() {
                    return Err(IntegrateError::Interrupted { t, stats });
                }
                next_out += 1;
            }
            sys.project(&mut xnew);
            if let Some(index) = non_finite(&xnew) {
                return Err(IntegrateError::NonFinite {
                    t: tn,
                    index,
                    stats,
                });
            }
            x.copy_from_slice(&xnew);
            t = tn;
            stats.steps += 1;
            if x == tmp.as_slice() {
                let k6 = k[6].clone();
                k[0].copy_from_slice(&k6);
            } else {
                sys.deriv(t, x, &mut k[0]);
                stats.evals += 1;
            }
            if last {
                if observe(t1, x).stop() {
                    return Err(IntegrateError::Interrupted { t, stats });
                }
                break;
            }
            if sys.interrupted() {
                return Err(IntegrateError::Interrupted { t, stats });
            }
            let fac = (fac11 / facold.powf(beta) / safety).clamp(0.1, 5.0);
            facold = err.max(1e-4);
            h = (h / fac).min(opts.max_step);
        } else {
            stats.rejected_steps += 1;
            h /= (fac11 / safety).min(5.0);
        }
    }
    Ok(stats)
}

/// Iteration limit of a [`midpoint`] step.
const MIDPOINT_MAX_ITER: usize = 60;

/// Fixed-step implicit midpoint rule on a Lie group (the structure-preserving integrator for long
/// runs): `n = ⌈(t1 − t0)/h⌉` equal steps, each solving
///
/// ```text
/// x_m = x_n ⊕ (h/2) f(t + h/2, x_m),      x_{n+1} = x_n ⊕ h f(t + h/2, x_m)
/// ```
///
/// where `⊕` is [`System::advance`] (additive by default, so `x_m = (x_n + x_{n+1})/2` — the
/// classical implicit midpoint rule). The implicit equation is solved by fixed-point iteration
/// from the explicit-Euler predictor until the max-norm update is ≤ `1e-14 · (1 + |x|∞)`
/// (converges when `h·L/2 < 1`, `L` the Lipschitz constant of `f`; a few iterations at the
/// usual steps). `observe(step, t, x)` as for [`rk4`]; [`System::project`] is **not** called.
///
/// Properties (Hairer, Lubich & Wanner, *Geometric Numerical Integration*): second order;
/// symmetric, hence ρ-reversible for the velocity flip of a mechanical system — for reversible,
/// near-integrable motions the energy error stays bounded with no secular drift (Ch. XI), which
/// `tests/integrators.rs` measures; in canonical variables `(q, p)` it would be symplectic and
/// conserve every quadratic invariant exactly, but here the state holds the quasi-velocities
/// `ν = [v_b, ω_b, q̇]` (not `p = A ν`), so it is **not** symplectic for these coordinates and
/// conserves neither energy nor momentum exactly — their errors are `O(h²)` and bounded (no
/// drift). The unit quaternion stays unit to round-off when the system's [`System::advance`]
/// is the exponential map (as `SceneSystem`'s is).
///
/// No crate fits: `ode_solvers`, `diffsol`, `russell_ode` offer implicit Runge–Kutta methods on
/// vector states only (no Lie-group update of a user state component), and the geometric crates
/// found target canonical Hamiltonians `H(q, p)`, which would need `∂A/∂q`.
pub fn midpoint<S: System, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    h: f64,
    x: &mut [f64],
    mut observe: impl FnMut(usize, f64, &[f64]) -> R,
) -> Result<Stats, IntegrateError> {
    assert!(h > 0.0 && t1 >= t0, "midpoint needs h > 0 and t1 >= t0");
    let n = ((t1 - t0) / h - 1e-9).ceil().max(1.0) as usize;
    let h = (t1 - t0) / n as f64;
    let d = sys.dim();
    let (mut f, mut xm, mut xm_new) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
    let mut stats = Stats::default();
    if observe(0, t0, x).stop() {
        return Err(IntegrateError::Interrupted { t: t0, stats });
    }
    for step in 1..=n {
        let t = t0 + (step - 1) as f64 * h;
        let tm = t + 0.5 * h;
        // Predictor: explicit Euler to the midpoint.
        sys.deriv(t, x, &mut f);
        stats.evals += 1;
        sys.advance(x, 0.5 * h, x, &f, &mut xm);
        let scale = 1.0 + x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let mut converged = false;
        for _ in 0..MIDPOINT_MAX_ITER {
            sys.deriv(tm, &xm, &mut f);
            stats.evals += 1;
            sys.advance(x, 0.5 * h, &xm, &f, &mut xm_new);
            let diff = xm
                .iter()
                .zip(&xm_new)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            std::mem::swap(&mut xm, &mut xm_new);
            if !diff.is_finite() {
                let index = non_finite(&xm).unwrap_or(0);
                return Err(IntegrateError::NonFinite { t, index, stats });
            }
            if diff <= 1e-14 * scale {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(IntegrateError::NotConverged { t, stats });
        }
        // Full step along the derivative at the (converged) midpoint.
        sys.advance(x, h, &xm, &f, &mut xm_new);
        let t = if step == n { t1 } else { t0 + step as f64 * h };
        if let Some(index) = non_finite(&xm_new) {
            return Err(IntegrateError::NonFinite { t, index, stats });
        }
        x.copy_from_slice(&xm_new);
        stats.steps += 1;
        if observe(step, t, x).stop() || (step < n && sys.interrupted()) {
            return Err(IntegrateError::Interrupted { t, stats });
        }
    }
    Ok(stats)
}
