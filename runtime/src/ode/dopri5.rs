//! Adaptive Dormand–Prince 5(4) with dense output (Hairer, Nørsett & Wanner, *Solving ODEs I*,
//! Sec. II.5, Table 5.2; the step-size control of Sec. II.4 with Hairer's PI controller of
//! DOPRI5, and its 4th-order continuous extension, Sec. II.6).
//!
//! Local extrapolation: the 5th-order solution is propagated, the embedded 4th-order one gives
//! the error estimate. Error norm: RMS of `err_i / (tol + tol·max(|x_i|, |x_new_i|))` (HNW I,
//! eq. (4.11) with `rtol = atol`); a step is accepted when the norm is ≤ 1. After an accepted
//! step the state is projected ([`System::project`]) and the derivative re-evaluated at the
//! projected state (FSAL only when the projection changed nothing).

use super::{check_run, non_finite, pow, take, Flow, Scratch, Stats, Stop, System};

/// Options of [`dopri5()`] (and of [`rosenbrock`](super::rosenbrock())).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dopri5Options {
    /// Relative and absolute tolerance (`rtol = atol`).
    pub tolerance: f64,
    /// Largest step.
    pub max_step: f64,
    /// First step tried.
    pub initial_step: f64,
    /// Spacing of the samples passed to `observe` (dense output, or the output times the
    /// Rosenbrock steps land on).
    pub output_interval: f64,
}

impl Dopri5Options {
    /// `Ok` when every field is positive (and the tolerance finite).
    pub(super) fn check(&self, t0: f64) -> Result<(), Stop> {
        // `!(v > 0)` also refuses NaN.
        let positive = |v: f64| v > 0.0;
        if !(positive(self.tolerance)
            && self.tolerance.is_finite()
            && positive(self.max_step)
            && positive(self.initial_step)
            && positive(self.output_interval))
        {
            return Err(Stop::Invalid {
                t: t0,
                what: "the tolerance, the largest and first step and the output interval must \
                       be positive",
            });
        }
        Ok(())
    }
}

/// The scratch floats of [`dopri5()`] for a state of dimension `d`: seven stages, the stage
/// state (the new state), the accepted new state and a dense-output sample.
#[must_use]
pub const fn scratch_len(d: usize) -> usize {
    10 * d
}

/// Stage times `c_i` (HNW I, Table 5.2).
const C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
/// Stage weights `a_ij` (HNW I, Table 5.2); row 6 is the 5th-order solution (FSAL).
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
const DENSE: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// PI controller (HNW I, Sec. II.4, DOPRI5): `β`, safety factor.
const BETA: f64 = 0.04;
const SAFETY: f64 = 0.9;

/// Stages 2–7 of a step of size `h` from `(t, x)` given `k₁` (`k[..d]`): `k` holds the seven
/// stages, `y` the 5th-order solution (where stage 7 was evaluated). Six evaluations.
fn stages<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &[f64],
    k: &mut [f64],
    y: &mut [f64],
) {
    let d = x.len();
    for s in 1..7 {
        let (done, rest) = k.split_at_mut(s * d);
        for i in 0..d {
            let mut acc = 0.0;
            for j in 0..s {
                acc += A[s][j] * done[j * d + i];
            }
            y[i] = x[i] + h * acc;
        }
        sys.deriv(t + C[s] * h, y, &mut rest[..d]);
    }
}

/// The RMS error norm of the step `x → xnew` of size `h` with stages `k` at tolerance `tol`.
fn error_norm(h: f64, x: &[f64], xnew: &[f64], k: &[f64], tol: f64) -> f64 {
    let d = x.len();
    let mut err = 0.0;
    for i in 0..d {
        let mut e = 0.0;
        for s in 0..7 {
            e += E[s] * k[s * d + i];
        }
        let e = h * e;
        let sc = tol + tol * libm::fabs(x[i]).max(libm::fabs(xnew[i]));
        err += (e / sc) * (e / sc);
    }
    libm::sqrt(err / d as f64)
}

/// The dense output at `θ = (ts − t)/h` of the step `x → xnew` with stages `k`, into `out`.
fn dense_output(th: f64, h: f64, x: &[f64], xnew: &[f64], k: &[f64], out: &mut [f64]) {
    let d = x.len();
    let th1 = 1.0 - th;
    for i in 0..d {
        let ydiff = xnew[i] - x[i];
        let bspl = h * k[i] - ydiff;
        let r4 = ydiff - h * k[6 * d + i] - bspl;
        let mut r5 = 0.0;
        for s in 0..7 {
            r5 += DENSE[s] * k[s * d + i];
        }
        let r5 = h * r5;
        out[i] = x[i] + th * (ydiff + th1 * (bspl + th * (r4 + th1 * r5)));
    }
}

/// Adaptive Dormand–Prince 5(4) from `t0` to `t1` (see the module doc), Hairer's PI
/// controller (exponents `0.2 − 0.75β` and `β = 0.04`, safety 0.9, factor limits
/// `[0.2, 10]`). `observe(t, x)` at `t0`, at every `t0 + k·output_interval < t1` from the
/// dense output, and at `t1`. `scratch` holds at least [`scratch_len`]`(x.len())` floats.
///
/// # Errors
/// A [`Stop`] when the state becomes non-finite, the step size underflows, the error estimate
/// overflows, the run is interrupted, or the input is invalid; `x` keeps the last accepted
/// state.
pub fn dopri5<S: System + ?Sized, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    opts: &Dopri5Options,
    x: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
    mut observe: impl FnMut(f64, &[f64]) -> R,
) -> Result<Stats, Stop> {
    check_run(sys, t0, t1, x)?;
    opts.check(t0)?;
    let d = x.len();
    let (work, _) = take(scratch, t0, scratch_len(d), 0)?;
    let (k, work) = work.split_at_mut(7 * d);
    let (tmp, work) = work.split_at_mut(d);
    let (xnew, dense) = work.split_at_mut(d);
    let dense = &mut dense[..d];
    let tol = opts.tolerance;
    let mut stats = Stats::default();
    let mut t = t0;
    let mut h = opts.initial_step.min(opts.max_step);
    let expo = 0.2 - 0.75 * BETA;
    let mut facold: f64 = 1e-4;
    let mut next_out = 1usize;
    if observe(t0, x).stop() {
        return Err(Stop::Interrupted { t: t0, stats });
    }
    sys.deriv(t, x, &mut k[..d]);
    stats.evals += 1;
    while t < t1 {
        let last = t + h >= t1 - 1e-12 * libm::fabs(t1).max(1.0);
        if last {
            h = t1 - t;
        }
        if h <= f64::EPSILON * libm::fabs(t).max(1.0) {
            return Err(Stop::StepTooSmall { t, stats });
        }
        stages(sys, t, h, x, k, tmp);
        stats.evals += 6;
        xnew.copy_from_slice(tmp);
        let err = error_norm(h, x, xnew, k, tol);
        if !err.is_finite() {
            return Err(match non_finite(xnew) {
                Some(index) => Stop::NonFinite {
                    t: t + h,
                    index,
                    stats,
                },
                None => Stop::ErrorEstimate { t, stats },
            });
        }
        let fac11 = pow(err, expo);
        if err > 1.0 {
            stats.rejected_steps += 1;
            h /= (fac11 / SAFETY).min(5.0);
            continue;
        }
        // Dense output over [t, t + h] before projecting.
        let tn = if last { t1 } else { t + h };
        while next_out as f64 * opts.output_interval + t0 < tn - 1e-12 * libm::fabs(tn).max(1.0) {
            let ts = t0 + next_out as f64 * opts.output_interval;
            dense_output((ts - t) / h, h, x, xnew, k, dense);
            if observe(ts, dense).stop() {
                return Err(Stop::Interrupted { t, stats });
            }
            next_out += 1;
        }
        sys.project(xnew);
        if let Some(index) = non_finite(xnew) {
            return Err(Stop::NonFinite {
                t: tn,
                index,
                stats,
            });
        }
        x.copy_from_slice(xnew);
        t = tn;
        stats.steps += 1;
        if x == &*tmp {
            k.copy_within(6 * d..7 * d, 0);
        } else {
            sys.deriv(t, x, &mut k[..d]);
            stats.evals += 1;
        }
        if last {
            if observe(t1, x).stop() {
                return Err(Stop::Interrupted { t, stats });
            }
            break;
        }
        if sys.interrupted() {
            return Err(Stop::Interrupted { t, stats });
        }
        let fac = (fac11 / pow(facold, BETA) / SAFETY).clamp(0.1, 5.0);
        facold = err.max(1e-4);
        h = (h / fac).min(opts.max_step);
    }
    Ok(stats)
}
