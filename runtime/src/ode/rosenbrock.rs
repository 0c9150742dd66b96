//! The stiff integrator: adaptive Rodas4, the stiffly accurate, L-stable 6-stage Rosenbrock
//! method of order 4 with an embedded order-3 solution (Hairer & Wanner, *Solving ODEs II*,
//! Sec. IV.7, Table 7.5 coefficients as distributed with RODAS and KPP), for scenes with
//! flexible joints (`[effects] flexible`), where the spring's fast modes bound an explicit
//! method's step by stability, not accuracy.
//!
//! Step (the form without Jacobian–vector products, HW eq. (7.25)), `γ = 1/4`:
//!
//! ```text
//! (I/(hγ) − J) K_i = f(t + α_i h, x + Σ_{j<i} a_ij K_j) + Σ_{j<i} (c_ij/h) K_j + γ_i h ∂f/∂t
//! x_new = x + Σ m_i K_i,            error estimate  Σ e_i K_i  (= K_6)
//! ```
//!
//! `J = ∂f/∂x` by central differences (increment `ε^(1/3) · max(|x_j|, 1)`) and `∂f/∂t` by a
//! forward difference (`√ε · max(|t|, 1)`) at the start of each step (`2d + 2` evaluations of
//! [`System::deriv`]), the matrix by LU with partial pivoting ([`lu_factor`], once per step
//! attempt); error norm and tolerance as [`dopri5`]'s (RMS of
//! `err_i / (tol + tol·max(|x_i|, |x_new_i|))`), step factor `clamp(0.9 · err^(−1/4), 0.2, 6)`
//! (no growth right after a rejection). Steps are shortened to land on every output time
//! `t0 + k · output_interval` (no dense output); after an accepted step the state is projected
//! ([`System::project`]).
//!
//! Rosenbrock methods take `J` into their order conditions, so its accuracy matters at tight
//! tolerances: on the flexible two-link arm (K = 1e6, 2 s, `tests/flexible.rs`) forward
//! differences (`~√ε` relative error) needed 2742 steps at 1e-10 and 32621 at 1e-12 (error
//! 1.5e-11); central differences (`~ε^(2/3)`) need 693 and 2937 (error 1.5e-12) — fewer
//! evaluations in all from 1e-10 down, about as many at 1e-8 (213 steps against 309).
//!
//! Hand-written rather than taken from a crate: `diffsol` (BDF, SDIRK) brings its own matrix
//! and equation traits and a sizeable dependency tree, `russell_ode` needs a system BLAS/LAPACK,
//! `ode_solvers` is explicit only; and the compiled simulators of `scene!` need the method
//! `no_std` and allocation-free — hence also the hand-written LU ([`lu`](super::lu)).
//!
//! [`dopri5`]: super::dopri5()
//! [`lu_factor`]: super::lu::lu_factor

// Index loops over stages and matrix entries.
#![allow(clippy::needless_range_loop)]

use super::lu::{lu_factor, lu_solve};
use super::{
    cbrt, check_run, non_finite, one_step, pow, take, Dopri5Options, Flow, Scratch, Stats, Stop,
    System,
};

/// Options of [`rosenbrock()`]: the fields of [`Dopri5Options`] (`output_interval`: the
/// spacing of the output times the steps land on).
pub type RosenbrockOptions = Dopri5Options;

/// Stages of Rodas4.
pub const STAGES: usize = 6;
/// The diagonal `γ`.
pub const GAMMA: f64 = 0.25;
/// Stage times `α_i`.
pub const ALPHA: [f64; STAGES] = [0.0, 0.386, 0.21, 0.63, 1.0, 1.0];
/// `γ_i = Σ_j γ_ij` (the weights of `∂f/∂t`).
pub const GAMMA_SUM: [f64; STAGES] = [0.25, -0.1043, 0.1035, -0.036_200_000_000_000_23, 0.0, 0.0];
/// `a_ij` (row `i`, `j < i`).
pub const A: [[f64; STAGES]; STAGES] = [
    [0.0; STAGES],
    [1.544, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        0.946_678_528_081_582_6,
        0.255_701_169_898_328_4,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        3.314_825_187_068_521,
        2.896_124_015_972_201,
        0.998_641_913_997_781_7,
        0.0,
        0.0,
        0.0,
    ],
    [W[0], W[1], W[2], W[3], 0.0, 0.0],
    [W[0], W[1], W[2], W[3], 1.0, 0.0],
];
/// The weights of `K_1 … K_4` shared by stages 5 and 6 and the solution (stiffly accurate).
const W: [f64; 4] = [
    1.221_224_509_226_641,
    6.019_134_481_288_629,
    12.537_083_329_320_87,
    -0.687_886_036_105_895,
];
/// `c_ij` (row `i`, `j < i`).
pub const C: [[f64; STAGES]; STAGES] = [
    [0.0; STAGES],
    [-5.6688, 0.0, 0.0, 0.0, 0.0, 0.0],
    [
        -2.430_093_356_833_875,
        -0.206_359_915_709_191_5,
        0.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        -0.107_352_905_815_137_5,
        -9.594_562_251_023_355,
        -20.470_286_148_096_16,
        0.0,
        0.0,
        0.0,
    ],
    [
        7.496_443_313_967_647,
        -10.246_804_314_643_52,
        -33.999_903_528_199_05,
        11.708_908_932_061_6,
        0.0,
        0.0,
    ],
    [
        8.083_246_795_921_522,
        -7.981_132_988_064_893,
        -31.521_594_328_743_71,
        16.319_305_431_231_36,
        -6.058_818_238_834_054,
        0.0,
    ],
];
/// Solution weights `m_i` (stiffly accurate: the last stage's point plus `K_6`).
pub const M: [f64; STAGES] = [W[0], W[1], W[2], W[3], 1.0, 1.0];
/// Error weights `e_i`: the embedded order-3 solution differs by `K_6`.
pub const E: [f64; STAGES] = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// The scratch floats of [`rosenbrock()`] and [`rosenbrock_step`] for a state of dimension
/// `d`: `f`, `∂f/∂t`, a stage state, the new state, six stages, `J` and the iteration matrix
/// (`10 d + 2 d²`); the scratch also holds `d` pivots.
#[must_use]
pub const fn scratch_len(d: usize) -> usize {
    10 * d + 2 * d * d
}

/// The scratch of one run, split.
struct Work<'a> {
    /// `f(t, x)`.
    f0: &'a mut [f64],
    /// `∂f/∂t`.
    ft: &'a mut [f64],
    /// A stage state.
    tmp: &'a mut [f64],
    /// The new state.
    xnew: &'a mut [f64],
    /// The stages `K_i`, `STAGES × d`.
    k: &'a mut [f64],
    /// `J = ∂f/∂x`, row-major.
    jac: &'a mut [f64],
    /// The iteration matrix `I/(hγ) − J`, then its LU factors.
    g: &'a mut [f64],
    /// The pivots of `g`.
    piv: &'a mut [usize],
}

impl<'a> Work<'a> {
    /// The scratch of a state of dimension `d`: the new state `xnew` and the rest of
    /// [`scratch_len`]`(d)` floats, `d` pivots.
    fn split(xnew: &'a mut [f64], floats: &'a mut [f64], piv: &'a mut [usize], d: usize) -> Self {
        let (f0, rest) = floats.split_at_mut(d);
        let (ft, rest) = rest.split_at_mut(d);
        let (tmp, rest) = rest.split_at_mut(d);
        let (k, rest) = rest.split_at_mut(STAGES * d);
        let (jac, g) = rest.split_at_mut(d * d);
        Work {
            f0,
            ft,
            tmp,
            xnew,
            k,
            jac,
            g,
            piv,
        }
    }

    /// `f`, `J` (central differences, increment `ε^(1/3) · max(|x_j|, 1)`) and `∂f/∂t`
    /// (forward difference, `√ε · max(|t|, 1)`) at `(t, x)`: `2d + 2` evaluations.
    fn linearize<S: System + ?Sized>(&mut self, sys: &mut S, t: f64, x: &[f64], stats: &mut Stats) {
        let d = x.len();
        let (fp, fm) = (&mut *self.xnew, &mut *self.ft);
        sys.deriv(t, x, self.f0);
        let cb = cbrt(f64::EPSILON);
        for j in 0..d {
            let dj = cb * libm::fabs(x[j]).max(1.0);
            self.tmp.copy_from_slice(x);
            self.tmp[j] += dj;
            sys.deriv(t, self.tmp, fp);
            self.tmp[j] = x[j] - dj;
            sys.deriv(t, self.tmp, fm);
            for i in 0..d {
                self.jac[i * d + j] = (fp[i] - fm[i]) / (2.0 * dj);
            }
        }
        let dt = libm::sqrt(f64::EPSILON) * libm::fabs(t).max(1.0);
        sys.deriv(t + dt, x, self.ft);
        for i in 0..d {
            self.ft[i] = (self.ft[i] - self.f0[i]) / dt;
        }
        stats.evals += 2 * d + 2;
    }

    /// One Rodas4 attempt of size `h` from `(t, x)` (HW eq. (7.25), module doc) after
    /// [`Work::linearize`]: the new state in `xnew` and the RMS error norm at tolerance `tol`
    /// (`None` when the iteration matrix is singular).
    fn attempt<S: System + ?Sized>(
        &mut self,
        sys: &mut S,
        t: f64,
        x: &[f64],
        h: f64,
        tol: f64,
        stats: &mut Stats,
    ) -> Option<f64> {
        let d = x.len();
        let ghinv = 1.0 / (h * GAMMA);
        for (gi, ji) in self.g.iter_mut().zip(self.jac.iter()) {
            *gi = -ji;
        }
        for i in 0..d {
            self.g[i * d + i] += ghinv;
        }
        if !lu_factor(self.g, self.piv, d) {
            return None;
        }
        for s in 0..STAGES {
            let (done, rest) = self.k.split_at_mut(s * d);
            let ks = &mut rest[..d];
            if s == 0 {
                ks.copy_from_slice(self.f0);
            } else {
                for i in 0..d {
                    let mut acc = x[i];
                    for j in 0..s {
                        acc += A[s][j] * done[j * d + i];
                    }
                    self.tmp[i] = acc;
                }
                sys.deriv(t + ALPHA[s] * h, self.tmp, self.xnew);
                stats.evals += 1;
                for i in 0..d {
                    let mut acc = self.xnew[i];
                    for j in 0..s {
                        acc += (C[s][j] / h) * done[j * d + i];
                    }
                    ks[i] = acc;
                }
            }
            for i in 0..d {
                ks[i] += GAMMA_SUM[s] * h * self.ft[i];
            }
            lu_solve(self.g, self.piv, ks, d);
        }
        let mut err = 0.0;
        for i in 0..d {
            let mut acc = x[i];
            let mut e = 0.0;
            for s in 0..STAGES {
                acc += M[s] * self.k[s * d + i];
                e += E[s] * self.k[s * d + i];
            }
            self.xnew[i] = acc;
            let sc = tol + tol * libm::fabs(x[i]).max(libm::fabs(acc));
            err += (e / sc) * (e / sc);
        }
        Some(libm::sqrt(err / d as f64))
    }
}

/// One Rodas4 step of size `h` from `(t, x)` in place with no step control (`scratch`: at
/// least [`scratch_len`]`(x.len())` floats and `x.len()` pivots); the work done.
///
/// # Errors
/// [`Stop::NonFinite`] at `t + h` when the new state is not finite (or the iteration matrix is
/// singular), or [`Stop::Invalid`]; `x` is then unchanged.
pub fn rosenbrock_step<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
) -> Result<Stats, Stop> {
    let len = (scratch_len(x.len()), x.len());
    one_step(
        sys,
        t,
        h,
        x,
        scratch,
        len,
        |sys, x, xnew, floats, piv, stats| {
            let mut w = Work::split(xnew, floats, piv, x.len());
            w.linearize(sys, t, x, stats);
            // A singular iteration matrix leaves no new state.
            match w.attempt(sys, t, x, h, 1.0, stats) {
                Some(_) => Ok(()),
                None => Err(Stop::NonFinite {
                    t: t + h,
                    index: 0,
                    stats: *stats,
                }),
            }
        },
    )
}

/// Adaptive Rodas4 from `t0` to `t1` (see the module doc). `observe(t, x)` is called at `t0`,
/// at every `t0 + k·output_interval < t1` (steps land on these times) and at `t1`. `scratch`
/// holds at least [`scratch_len`]`(x.len())` floats and `x.len()` pivots.
///
/// # Errors
/// As [`dopri5`](super::dopri5()): a non-finite state, a step-size underflow (also when the
/// iteration matrix stays singular), an overflowing error estimate, an interruption, invalid
/// input; `x` keeps the last accepted state.
pub fn rosenbrock<S: System + ?Sized, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    opts: &RosenbrockOptions,
    x: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
    mut observe: impl FnMut(f64, &[f64]) -> R,
) -> Result<Stats, Stop> {
    check_run(sys, t0, t1, x)?;
    opts.check(t0)?;
    let d = x.len();
    let (floats, piv) = take(scratch, t0, scratch_len(d), d)?;
    let (xnew, floats) = floats.split_at_mut(d);
    let mut w = Work::split(xnew, floats, piv, d);
    let tol = opts.tolerance;
    let mut stats = Stats::default();
    let mut t = t0;
    let mut h = opts.initial_step.min(opts.max_step);
    let mut next_out = 1usize;
    let mut rejected = false;
    if observe(t0, x).stop() {
        return Err(Stop::Interrupted { t: t0, stats });
    }
    while t < t1 {
        w.linearize(sys, t, x, &mut stats);
        loop {
            let t_out = (t0 + next_out as f64 * opts.output_interval).min(t1);
            let land = t + h >= t_out - 1e-12 * libm::fabs(t_out).max(1.0);
            let hs = if land { t_out - t } else { h };
            if hs <= f64::EPSILON * libm::fabs(t).max(1.0) {
                return Err(Stop::StepTooSmall { t, stats });
            }
            let err = w
                .attempt(sys, t, x, hs, tol, &mut stats)
                .unwrap_or(f64::INFINITY);
            if err.is_nan() {
                return Err(match non_finite(w.xnew) {
                    Some(index) => Stop::NonFinite {
                        t: t + hs,
                        index,
                        stats,
                    },
                    None => Stop::ErrorEstimate { t, stats },
                });
            }
            // Step factor clamp(0.9 · err^(−1/4), 0.2, 6), no growth right after a rejection.
            let mut fac = (0.9 / pow(err, 0.25)).clamp(0.2, 6.0);
            if err > 1.0 {
                stats.rejected_steps += 1;
                rejected = true;
                h = hs * fac;
                continue;
            }
            if rejected {
                fac = fac.min(1.0);
            }
            rejected = false;
            sys.project(w.xnew);
            let tn = if land { t_out } else { t + hs };
            if let Some(index) = non_finite(w.xnew) {
                return Err(Stop::NonFinite {
                    t: tn,
                    index,
                    stats,
                });
            }
            x.copy_from_slice(w.xnew);
            t = tn;
            stats.steps += 1;
            h = (hs * fac).min(opts.max_step);
            if land {
                next_out += 1;
                if observe(t, x).stop() {
                    return Err(Stop::Interrupted { t, stats });
                }
            }
            if t < t1 && sys.interrupted() {
                return Err(Stop::Interrupted { t, stats });
            }
            break;
        }
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::super::tests::Oscillator;
    use super::*;
    use crate::ode::ArrayScratch;

    /// Fixed steps (tolerance huge, `max_step = h`) on `ẍ = −x` over 1 s: the error falls 16×
    /// per halving (order 4). Measured 6.07e-8, 3.81e-9, 2.38e-10 at h = 0.1, 0.05, 0.025.
    #[test]
    fn order_four_on_the_oscillator() {
        let errs = [0.1, 0.05, 0.025].map(|h| {
            let mut x = [1.0, 0.0];
            let opts = RosenbrockOptions {
                tolerance: 1e30,
                max_step: h,
                initial_step: h,
                output_interval: 100.0,
            };
            let mut scratch = ArrayScratch::<{ scratch_len(2) }, 2>::new();
            rosenbrock(
                &mut Oscillator,
                0.0,
                1.0,
                &opts,
                &mut x,
                &mut scratch,
                |_, _| (),
            )
            .unwrap();
            libm::fabs(x[0] - libm::cos(1.0)).max(libm::fabs(x[1] + libm::sin(1.0)))
        });
        for w in errs.windows(2) {
            let p = libm::log2(w[0] / w[1]);
            assert!((3.7..4.5).contains(&p), "order {p} from {errs:?}");
        }
    }
}
