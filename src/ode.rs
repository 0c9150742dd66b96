//! Allocation-free, `no_std` integrators over fixed-size states `[f64; D]`, for the simulators
//! that [`scene!`](crate::scene!) generates: one classical Runge–Kutta 4 step ([`rk4_step`]),
//! fixed-step RK4 runs ([`rk4`]), adaptive Dormand–Prince 5(4) runs with dense output
//! ([`dopri5`]), and the fixed-step Lie-group implicit midpoint rule ([`midpoint_step`],
//! [`midpoint`]; Hairer, Lubich & Wanner, *Geometric Numerical Integration*).
//!
//! They mirror the interpreted simulator's integrators (`kanegen::sim::integrate`, `std`) step
//! for step — the same step counts and times, the same tableau (Hairer, Nørsett & Wanner,
//! *Solving ODEs I*, Table 5.2), error norm, PI step-size controller, dense output (Hairer's
//! DOPRI5 coefficients) and projection after an accepted step — so a generated simulator and
//! the interpreted one agree to the rounding of their right-hand sides. Nothing here allocates
//! or panics: a failure is a [`Stop`].

use crate::__private::libm;

mod rosenbrock;
pub use rosenbrock::{rosenbrock, rosenbrock_step, RosenbrockOptions};

/// Work counters of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (always 0 for RK4).
    pub rejected_steps: usize,
    /// Right-hand-side evaluations.
    pub evals: usize,
}

/// Why a run stopped before its end time; the state holds the last accepted state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stop {
    /// The state became non-finite in the step to `t` (component `index`).
    NonFinite {
        /// Time of the step that overflowed.
        t: f64,
        /// The first non-finite component of the new state.
        index: usize,
        /// Work done.
        stats: Stats,
    },
    /// The adaptive step size fell below the floating-point resolution of `t`.
    StepTooSmall {
        /// Time reached.
        t: f64,
        /// Work done.
        stats: Stats,
    },
    /// The DP5(4) error estimate overflowed while the state stayed finite.
    ErrorEstimate {
        /// Time reached.
        t: f64,
        /// Work done.
        stats: Stats,
    },
    /// The fixed-point iterations of an implicit midpoint step did not converge.
    NotConverged {
        /// Time of the step.
        t: f64,
        /// Work done.
        stats: Stats,
    },
}

/// The number of RK4 steps from `t0` to `t1` with step about `h`, and the step actually taken:
/// `n = ⌈(t1 − t0)/h⌉` (less a `1e-9` slack, at least 1) equal steps of `(t1 − t0)/n`.
#[must_use]
pub fn fixed_steps(t0: f64, t1: f64, h: f64) -> (usize, f64) {
    let n = libm::ceil((t1 - t0) / h - 1e-9);
    let n = if n >= 1.0 { n as usize } else { 1 };
    (n, (t1 - t0) / n as f64)
}

fn non_finite<const D: usize>(x: &[f64; D]) -> Option<usize> {
    x.iter().position(|v| !v.is_finite())
}

/// One classical RK4 step of size `h` from `(t, x)`: `x + h/6 (k₁ + 2k₂ + 2k₃ + k₄)`.
#[inline]
pub fn rk4_step<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    t: f64,
    x: &[f64; D],
    h: f64,
) -> [f64; D] {
    let k1 = f(t, x);
    let tmp: [f64; D] = core::array::from_fn(|i| x[i] + 0.5 * h * k1[i]);
    let k2 = f(t + 0.5 * h, &tmp);
    let tmp: [f64; D] = core::array::from_fn(|i| x[i] + 0.5 * h * k2[i]);
    let k3 = f(t + 0.5 * h, &tmp);
    let tmp: [f64; D] = core::array::from_fn(|i| x[i] + h * k3[i]);
    let k4 = f(t + h, &tmp);
    let (h6, h3) = (h / 6.0, h / 3.0);
    core::array::from_fn(|i| x[i] + (h6 * k1[i] + h3 * k2[i] + h3 * k3[i] + h6 * k4[i]))
}

/// Options of [`rk4`] and [`midpoint`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rk4Options {
    /// Step (shortened so that a whole number of steps ends at `t1`, [`fixed_steps`]).
    pub step: f64,
    /// `observe` after every this many steps (and after the last).
    pub output_every: usize,
}

/// Fixed-step RK4 from `t0` to `t1` ([`fixed_steps`]), projecting after every step;
/// `observe(t, x)` at `t0`, after every `output_every`-th step and after the last.
///
/// # Errors
/// [`Stop::NonFinite`] when a step's state is not finite (`x` keeps the last finite one).
pub fn rk4<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    project: impl Fn(&mut [f64; D]),
    t0: f64,
    t1: f64,
    opts: &Rk4Options,
    x: &mut [f64; D],
    mut observe: impl FnMut(f64, &[f64; D]),
) -> Result<Stats, Stop> {
    let (n, h) = fixed_steps(t0, t1, opts.step);
    let every = opts.output_every.max(1);
    let mut stats = Stats::default();
    observe(t0, x);
    for step in 1..=n {
        let t = t0 + (step - 1) as f64 * h;
        let mut next = rk4_step(f, t, x, h);
        stats.evals += 4;
        let t = if step == n { t1 } else { t0 + step as f64 * h };
        project(&mut next);
        if let Some(index) = non_finite(&next) {
            return Err(Stop::NonFinite { t, index, stats });
        }
        *x = next;
        stats.steps += 1;
        if step % every == 0 || step == n {
            observe(t, x);
        }
    }
    Ok(stats)
}

/// Options of [`dopri5`] (as the interpreted simulator's `Dopri5Options`).
#[derive(Clone, Copy, Debug, PartialEq)]
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
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
const DENSE: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// Adaptive Dormand–Prince 5(4) from `t0` to `t1`, as `kanegen::sim::integrate::dopri5`: local
/// extrapolation, error norm the RMS of `err_i / (tol + tol·max(|x_i|, |x_new_i|))`, Hairer's PI
/// controller (`β = 0.04`, safety 0.9), projection after an accepted step (then the first
/// stage is re-evaluated unless the projection changed nothing). `observe(t, x)` at `t0`, at
/// every `t0 + k·output_interval < t1` from the 4th-order dense output, and at `t1`.
///
/// # Errors
/// A [`Stop`] when the state becomes non-finite, the step size underflows or the error
/// estimate overflows.
pub fn dopri5<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    project: impl Fn(&mut [f64; D]),
    t0: f64,
    t1: f64,
    opts: &Dopri5Options,
    x: &mut [f64; D],
    mut observe: impl FnMut(f64, &[f64; D]),
) -> Result<Stats, Stop> {
    let tol = opts.tolerance;
    let mut k = [[0.0; D]; 7];
    let mut tmp = [0.0; D];
    let mut stats = Stats::default();
    let mut t = t0;
    let mut h = opts.initial_step.min(opts.max_step);
    let (beta, safety) = (0.04, 0.9);
    let expo = 0.2 - 0.75 * beta;
    let mut facold: f64 = 1e-4;
    let mut next_out = 1usize;
    observe(t0, x);
    k[0] = f(t, x);
    stats.evals += 1;
    while t < t1 {
        let last = t + h >= t1 - 1e-12 * libm::fabs(t1).max(1.0);
        if last {
            h = t1 - t;
        }
        if h <= f64::EPSILON * libm::fabs(t).max(1.0) {
            return Err(Stop::StepTooSmall { t, stats });
        }
        for s in 1..7 {
            for i in 0..D {
                let mut acc = 0.0;
                for (j, kj) in k.iter().enumerate().take(s) {
                    acc += A[s][j] * kj[i];
                }
                tmp[i] = x[i] + h * acc;
            }
            k[s] = f(t + C[s] * h, &tmp);
        }
        stats.evals += 6;
        let mut xnew = tmp;
        let mut err = 0.0;
        for i in 0..D {
            let mut e = 0.0;
            for (s, ks) in k.iter().enumerate() {
                e += E[s] * ks[i];
            }
            let e = h * e;
            let sc = tol + tol * libm::fabs(x[i]).max(libm::fabs(xnew[i]));
            err += (e / sc) * (e / sc);
        }
        let err = libm::sqrt(err / D as f64);
        if !err.is_finite() {
            return Err(match non_finite(&xnew) {
                Some(index) => Stop::NonFinite {
                    t: t + h,
                    index,
                    stats,
                },
                None => Stop::ErrorEstimate { t, stats },
            });
        }
        let fac11 = libm::pow(err, expo);
        if err <= 1.0 {
            let tn = if last { t1 } else { t + h };
            while next_out as f64 * opts.output_interval + t0 < tn - 1e-12 * libm::fabs(tn).max(1.0)
            {
                let ts = t0 + next_out as f64 * opts.output_interval;
                let th = (ts - t) / h;
                let th1 = 1.0 - th;
                let dense: [f64; D] = core::array::from_fn(|i| {
                    let ydiff = xnew[i] - x[i];
                    let bspl = h * k[0][i] - ydiff;
                    let r4 = ydiff - h * k[6][i] - bspl;
                    let mut r5 = 0.0;
                    for (s, ks) in k.iter().enumerate() {
                        r5 += DENSE[s] * ks[i];
                    }
                    let r5 = h * r5;
                    x[i] + th * (ydiff + th1 * (bspl + th * (r4 + th1 * r5)))
                });
                observe(ts, &dense);
                next_out += 1;
            }
            project(&mut xnew);
            if let Some(index) = non_finite(&xnew) {
                return Err(Stop::NonFinite {
                    t: tn,
                    index,
                    stats,
                });
            }
            *x = xnew;
            t = tn;
            stats.steps += 1;
            if *x == tmp {
                k[0] = k[6];
            } else {
                k[0] = f(t, x);
                stats.evals += 1;
            }
            if last {
                observe(t1, x);
                break;
            }
            let fac = (fac11 / libm::pow(facold, beta) / safety).clamp(0.1, 5.0);
            facold = err.max(1e-4);
            h = (h / fac).min(opts.max_step);
        } else {
            stats.rejected_steps += 1;
            h /= (fac11 / safety).min(5.0);
        }
    }
    Ok(stats)
}

/// Renormalizes the unit quaternion `x[3..7]` of a free-floating state (the projection of the
/// interpreted simulator).
#[inline]
pub fn normalize_quaternion<const D: usize>(x: &mut [f64; D]) {
    if D >= 7 {
        let norm = libm::sqrt(x[3] * x[3] + x[4] * x[4] + x[5] * x[5] + x[6] * x[6]);
        for v in &mut x[3..7] {
            *v /= norm;
        }
    }
}

/// The rotation matrix (row-major, body to inertial axes) of a quaternion `[x, y, z, w]`:
/// `I + 2w [u]× + 2 [u]×²`, not normalized (as `kanegen::dynamics::base::quat_to_matrix`).
#[must_use]
pub fn quat_to_matrix(q: &[f64; 4]) -> [[f64; 3]; 3] {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// A tabulated force and moment at `t`: linear between samples, held at the first (last) sample
/// before (after) the table (as `kanegen::sim::scene::SceneWrench::value_at`). `time` is
/// strictly increasing with at least two samples.
#[must_use]
pub fn table<const K: usize>(
    t: f64,
    time: &[f64; K],
    force: &[[f64; 3]; K],
    moment: &[[f64; 3]; K],
) -> ([f64; 3], [f64; 3]) {
    let k = time.partition_point(|&tk| tk <= t);
    if k == 0 || K < 2 {
        return (force[0], moment[0]);
    }
    if k >= K {
        return (force[K - 1], moment[K - 1]);
    }
    let s = (t - time[k - 1]) / (time[k] - time[k - 1]);
    let lerp = |v: &[[f64; 3]; K]| [0, 1, 2].map(|i| v[k - 1][i] + s * (v[k][i] - v[k - 1][i]));
    (lerp(force), lerp(moment))
}

/// Quintic time scaling `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵` of a computed-torque drive over `duration`,
/// at `t`: `(s, ṡ, s̈)` (`ṡ = s̈ = 0` from `duration` on), as the interpreted simulator's
/// `quintic_reference`.
#[must_use]
pub fn quintic(t: f64, duration: f64) -> (f64, f64, f64) {
    let tau = (t / duration).clamp(0.0, 1.0);
    let s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    if t >= duration {
        return (s, 0.0, 0.0);
    }
    let ds = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau);
    let dds = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau);
    (s, ds / duration, dds / (duration * duration))
}

/// Iteration limit of a [`midpoint_step`] (as the interpreted simulator's).
pub const MIDPOINT_MAX_ITER: usize = 60;

/// The additive update `x + h f` (the `advance` of a state without a Lie-group part).
#[must_use]
pub fn advance_additive<const D: usize>(
    x: &[f64; D],
    h: f64,
    _at: &[f64; D],
    f: &[f64; D],
) -> [f64; D] {
    core::array::from_fn(|i| x[i] + h * f[i])
}

/// The update of a free-floating state `[p₀, quat, q, v_b, ω_b, q̇]` with `n` joints: additive,
/// except the quaternion `x[3..7]`, which becomes `quat ⊗ exp(h ω_b(at) / 2)` (exponential map,
/// unit by construction, symmetric in `h`), as the interpreted `SceneSystem::advance`. `D` is
/// `13 + 2n`.
#[must_use]
pub fn advance_floating<const D: usize>(
    x: &[f64; D],
    h: f64,
    at: &[f64; D],
    f: &[f64; D],
) -> [f64; D] {
    let mut out = advance_additive(x, h, at, f);
    // D = 13 + 2n: ω_b at 10 + n (a shorter state has no base: additive).
    if D < 13 {
        return out;
    }
    let n = (D - 13) / 2;
    let om = [at[10 + n], at[11 + n], at[12 + n]];
    let w_norm = libm::sqrt(om[0] * om[0] + om[1] * om[1] + om[2] * om[2]);
    let half = 0.5 * h * w_norm;
    let s = if libm::fabs(half) < 1e-8 {
        0.5 * h * (1.0 - half * half / 6.0)
    } else {
        libm::sin(half) / w_norm
    };
    let (rho, rw) = ([s * om[0], s * om[1], s * om[2]], libm::cos(half));
    let (u, w) = ([x[3], x[4], x[5]], x[6]);
    let cross = [
        u[1] * rho[2] - u[2] * rho[1],
        u[2] * rho[0] - u[0] * rho[2],
        u[0] * rho[1] - u[1] * rho[0],
    ];
    for i in 0..3 {
        out[3 + i] = w * rho[i] + rw * u[i] + cross[i];
    }
    out[6] = w * rw - (u[0] * rho[0] + u[1] * rho[1] + u[2] * rho[2]);
    out
}

/// One step of the implicit midpoint rule from `(t, x)`: `x_m = x ⊕ (h/2) f(t + h/2, x_m)`
/// solved by fixed-point iteration from the explicit-Euler predictor until the max-norm update
/// is ≤ `1e-14 (1 + |x|∞)`, then `x ⊕ h f(t + h/2, x_m)`; `⊕` is `advance` ([`advance_additive`]
/// or [`advance_floating`]). As `kanegen::sim::integrate::midpoint`. `stats` counts the
/// evaluations.
///
/// # Errors
/// [`Stop::NonFinite`] when an iterate or the result is not finite, [`Stop::NotConverged`]
/// after [`MIDPOINT_MAX_ITER`] iterations.
pub fn midpoint_step<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    advance: impl Fn(&[f64; D], f64, &[f64; D], &[f64; D]) -> [f64; D],
    t: f64,
    x: &[f64; D],
    h: f64,
    stats: &mut Stats,
) -> Result<[f64; D], Stop> {
    let tm = t + 0.5 * h;
    let mut fx = f(t, x);
    stats.evals += 1;
    let mut xm = advance(x, 0.5 * h, x, &fx);
    let scale = 1.0 + x.iter().fold(0.0_f64, |m, v| m.max(libm::fabs(*v)));
    let mut converged = false;
    for _ in 0..MIDPOINT_MAX_ITER {
        fx = f(tm, &xm);
        stats.evals += 1;
        let next = advance(x, 0.5 * h, &xm, &fx);
        let diff = xm
            .iter()
            .zip(&next)
            .fold(0.0_f64, |m, (a, b)| m.max(libm::fabs(a - b)));
        xm = next;
        if !diff.is_finite() {
            let index = non_finite(&xm).unwrap_or(0);
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
    let out = advance(x, h, &xm, &fx);
    if let Some(index) = non_finite(&out) {
        return Err(Stop::NonFinite {
            t: t + h,
            index,
            stats: *stats,
        });
    }
    Ok(out)
}

/// The fixed-step implicit midpoint rule from `t0` to `t1` ([`fixed_steps`], [`midpoint_step`]);
/// no projection; `observe(t, x)` at `t0`, after every `output_every`-th step and after the
/// last.
///
/// # Errors
/// The first failed step's [`Stop`] (`x` keeps the last accepted state).
pub fn midpoint<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    advance: impl Fn(&[f64; D], f64, &[f64; D], &[f64; D]) -> [f64; D],
    t0: f64,
    t1: f64,
    opts: &Rk4Options,
    x: &mut [f64; D],
    mut observe: impl FnMut(f64, &[f64; D]),
) -> Result<Stats, Stop> {
    let (n, h) = fixed_steps(t0, t1, opts.step);
    let every = opts.output_every.max(1);
    let mut stats = Stats::default();
    observe(t0, x);
    for step in 1..=n {
        let t = t0 + (step - 1) as f64 * h;
        let next = midpoint_step(f, &advance, t, x, h, &mut stats)?;
        *x = next;
        stats.steps += 1;
        if step % every == 0 || step == n {
            let t = if step == n { t1 } else { t0 + step as f64 * h };
            observe(t, x);
        }
    }
    Ok(stats)
}

/// Solves `A x = b` for a symmetric positive definite `A` by a fixed-size LDLᵀ factorization
/// (only the lower triangle is read), in place of `b`: no allocation, no panic. `None` when a
/// pivot is not positive (or not finite): `A` is not positive definite. Used by `scene!` for
/// `(M + diag(I_m n²)) q̈ = τ − c` with rotor inertia.
#[must_use]
#[allow(clippy::needless_range_loop)]
pub fn solve_spd<const N: usize>(a: &[[f64; N]; N], b: &[f64; N]) -> Option<[f64; N]> {
    // l[i][k] for k < i; w[i][k] = L_ik D_k.
    let mut l = [[0.0f64; N]; N];
    let mut w = [[0.0f64; N]; N];
    let mut d_inv = [0.0f64; N];
    for j in 0..N {
        let mut dj = a[j][j];
        for k in 0..j {
            dj -= l[j][k] * w[j][k];
        }
        // `!(dj > 0)` also catches NaN.
        if !(dj > 0.0 && dj.is_finite()) {
            return None;
        }
        let inv = 1.0 / dj;
        d_inv[j] = inv;
        for i in (j + 1)..N {
            let mut s = a[i][j];
            for k in 0..j {
                s -= l[i][k] * w[j][k];
            }
            l[i][j] = s * inv;
            w[i][j] = s;
        }
    }
    let mut x = *b;
    for i in 0..N {
        for k in 0..i {
            x[i] -= l[i][k] * x[k];
        }
    }
    for i in 0..N {
        x[i] *= d_inv[i];
    }
    for i in (0..N).rev() {
        for k in (i + 1)..N {
            x[i] -= l[k][i] * x[k];
        }
    }
    Some(x)
}

#[cfg(test)]
mod solve_spd_tests {
    #[test]
    fn solves_and_refuses_indefinite() {
        let a = [[4.0, 2.0], [2.0, 3.0]];
        let x = super::solve_spd(&a, &[2.0, 1.0]).unwrap();
        assert!((4.0 * x[0] + 2.0 * x[1] - 2.0).abs() < 1e-15);
        assert!((2.0 * x[0] + 3.0 * x[1] - 1.0).abs() < 1e-15);
        assert!(super::solve_spd(&[[1.0, 2.0], [2.0, 1.0]], &[1.0, 1.0]).is_none());
        assert!(super::solve_spd(&[[f64::NAN]], &[1.0]).is_none());
    }
}
