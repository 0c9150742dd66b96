//! Adaptive Rodas4 (the stiff integrator of `integrator = "rosenbrock"` scenes) on fixed-size
//! states, `no_std`, mirroring `kanegen::sim::rosenbrock` operation for operation: the same
//! tableau (Hairer & Wanner, *Solving ODEs II*, Sec. IV.7), central-difference `J`, forward `∂f/∂t`,
//! LU with partial pivoting on `[[f64; D]; D]`, error norm, step control, and steps landing on
//! the output times — so a generated simulator and the interpreted one agree to the rounding
//! of their right-hand sides (amplified by the difference quotients of `J`; well inside the
//! tolerance).

// Index loops over stages and matrix entries, in the same order in both mirrors.
#![allow(clippy::needless_range_loop)]

use super::{libm, non_finite, Dopri5Options, Stats, Stop};

/// Options of [`rosenbrock`]: the fields of [`Dopri5Options`] (`output_interval`: the spacing of
/// the output times the steps land on).
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
    [
        1.221_224_509_226_641,
        6.019_134_481_288_629,
        12.537_083_329_320_87,
        -0.687_886_036_105_895,
        0.0,
        0.0,
    ],
    [
        1.221_224_509_226_641,
        6.019_134_481_288_629,
        12.537_083_329_320_87,
        -0.687_886_036_105_895,
        1.0,
        0.0,
    ],
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
pub const M: [f64; STAGES] = [
    1.221_224_509_226_641,
    6.019_134_481_288_629,
    12.537_083_329_320_87,
    -0.687_886_036_105_895,
    1.0,
    1.0,
];
/// Error weights `e_i`: the embedded order-3 solution differs by `K_6`.
pub const E: [f64; STAGES] = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0];

/// The derivative, `∂f/∂x` (row-major, `jac[i][j] = ∂f_i/∂x_j`, central differences) and
/// `∂f/∂t` (forward difference) at `(t, x)`: `2D + 2` evaluations.
#[allow(clippy::type_complexity)]
fn linearize<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    t: f64,
    x: &[f64; D],
    jac: &mut [[f64; D]; D],
) -> ([f64; D], [f64; D]) {
    let sq = libm::sqrt(f64::EPSILON);
    let cb = libm::cbrt(f64::EPSILON);
    let f0 = f(t, x);
    for j in 0..D {
        let dj = cb * libm::fabs(x[j]).max(1.0);
        let mut xj = *x;
        xj[j] += dj;
        let fp = f(t, &xj);
        xj[j] = x[j] - dj;
        let fm = f(t, &xj);
        for i in 0..D {
            jac[i][j] = (fp[i] - fm[i]) / (2.0 * dj);
        }
    }
    let dt = sq * libm::fabs(t).max(1.0);
    let mut ft = f(t + dt, x);
    for i in 0..D {
        ft[i] = (ft[i] - f0[i]) / dt;
    }
    (f0, ft)
}

/// LU with partial pivoting in place (`piv[k]`: the row swapped with row `k`); `false` on a zero
/// or non-finite pivot.
fn lu_factor<const D: usize>(a: &mut [[f64; D]; D], piv: &mut [usize; D]) -> bool {
    for k in 0..D {
        let mut p = k;
        for i in k + 1..D {
            if libm::fabs(a[i][k]) > libm::fabs(a[p][k]) {
                p = i;
            }
        }
        piv[k] = p;
        let pv = a[p][k];
        if pv == 0.0 || !pv.is_finite() {
            return false;
        }
        if p != k {
            a.swap(k, p);
        }
        for i in k + 1..D {
            let l = a[i][k] / pv;
            a[i][k] = l;
            for j in k + 1..D {
                a[i][j] -= l * a[k][j];
            }
        }
    }
    true
}

fn lu_solve<const D: usize>(a: &[[f64; D]; D], piv: &[usize; D], b: &mut [f64; D]) {
    // The factorization swapped whole rows: all the swaps first, then `L`.
    for k in 0..D {
        b.swap(k, piv[k]);
    }
    for k in 0..D {
        for i in k + 1..D {
            b[i] -= a[i][k] * b[k];
        }
    }
    for k in (0..D).rev() {
        let mut s = b[k];
        for j in k + 1..D {
            s -= a[k][j] * b[j];
        }
        b[k] = s / a[k][k];
    }
}

/// One Rodas4 attempt of size `h` from `(t, x)` given `f0 = f(t, x)`, `J`, `∂f/∂t`: the new state
/// and the RMS error norm at tolerance `tol` (`None` when the iteration matrix is singular).
#[allow(clippy::too_many_arguments)]
fn attempt<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    t: f64,
    x: &[f64; D],
    f0: &[f64; D],
    jac: &[[f64; D]; D],
    ft: &[f64; D],
    h: f64,
    tol: f64,
    stats: &mut Stats,
) -> Option<([f64; D], f64)> {
    let ghinv = 1.0 / (h * GAMMA);
    let mut g = [[0.0f64; D]; D];
    for i in 0..D {
        for j in 0..D {
            g[i][j] = -jac[i][j];
        }
        g[i][i] += ghinv;
    }
    let mut piv = [0usize; D];
    if !lu_factor(&mut g, &mut piv) {
        return None;
    }
    let mut k = [[0.0f64; D]; STAGES];
    for s in 0..STAGES {
        let mut ks = [0.0f64; D];
        if s == 0 {
            ks = *f0;
        } else {
            let mut y = [0.0f64; D];
            for i in 0..D {
                let mut acc = x[i];
                for j in 0..s {
                    acc += A[s][j] * k[j][i];
                }
                y[i] = acc;
            }
            let fy = f(t + ALPHA[s] * h, &y);
            stats.evals += 1;
            for i in 0..D {
                let mut acc = fy[i];
                for j in 0..s {
                    acc += (C[s][j] / h) * k[j][i];
                }
                ks[i] = acc;
            }
        }
        for i in 0..D {
            ks[i] += GAMMA_SUM[s] * h * ft[i];
        }
        lu_solve(&g, &piv, &mut ks);
        k[s] = ks;
    }
    let mut xnew = [0.0f64; D];
    let mut err = 0.0;
    for i in 0..D {
        let mut acc = x[i];
        let mut e = 0.0;
        for s in 0..STAGES {
            acc += M[s] * k[s][i];
            e += E[s] * k[s][i];
        }
        xnew[i] = acc;
        let sc = tol + tol * libm::fabs(x[i]).max(libm::fabs(acc));
        err += (e / sc) * (e / sc);
    }
    Some((xnew, libm::sqrt(err / D as f64)))
}

/// One Rodas4 step of size `h` from `(t, x)` with no step control (`scene!`'s `step` of a
/// rosenbrock scene).
///
/// # Errors
/// [`Stop::NonFinite`] when the new state is not finite (or the iteration matrix is singular).
pub fn rosenbrock_step<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    t: f64,
    x: &[f64; D],
    h: f64,
    stats: &mut Stats,
) -> Result<[f64; D], Stop> {
    let mut jac = [[0.0f64; D]; D];
    let (f0, ft) = linearize(f, t, x, &mut jac);
    stats.evals += 2 * D + 2;
    let bad = |index, stats: &Stats| Stop::NonFinite {
        t: t + h,
        index,
        stats: *stats,
    };
    let (xn, _) = attempt(f, t, x, &f0, &jac, &ft, h, 1.0, stats).ok_or(bad(0, stats))?;
    if let Some(index) = non_finite(&xn) {
        return Err(bad(index, stats));
    }
    stats.steps += 1;
    Ok(xn)
}

/// Adaptive Rodas4 from `t0` to `t1` as `kanegen::sim::rosenbrock::rosenbrock`: `observe(t, x)`
/// at `t0`, at every `t0 + k·output_interval < t1` (the steps land on them) and at `t1`.
///
/// # Errors
/// A [`Stop`] when the state becomes non-finite, the step size underflows (also when the
/// iteration matrix stays singular) or the error estimate overflows.
pub fn rosenbrock<const D: usize>(
    f: &mut impl FnMut(f64, &[f64; D]) -> [f64; D],
    project: impl Fn(&mut [f64; D]),
    t0: f64,
    t1: f64,
    opts: &RosenbrockOptions,
    x: &mut [f64; D],
    mut observe: impl FnMut(f64, &[f64; D]),
) -> Result<Stats, Stop> {
    let tol = opts.tolerance;
    let mut stats = Stats::default();
    let mut t = t0;
    let mut h = opts.initial_step.min(opts.max_step);
    let mut next_out = 1usize;
    let mut rejected = false;
    let mut jac = [[0.0f64; D]; D];
    observe(t0, x);
    while t < t1 {
        let (f0, ft) = linearize(f, t, x, &mut jac);
        stats.evals += 2 * D + 2;
        loop {
            let t_out = (t0 + next_out as f64 * opts.output_interval).min(t1);
            let land = t + h >= t_out - 1e-12 * libm::fabs(t_out).max(1.0);
            let hs = if land { t_out - t } else { h };
            if hs <= f64::EPSILON * libm::fabs(t).max(1.0) {
                return Err(Stop::StepTooSmall { t, stats });
            }
            let (mut xnew, err) = match attempt(f, t, x, &f0, &jac, &ft, hs, tol, &mut stats) {
                Some(r) => r,
                None => ([0.0; D], f64::INFINITY),
            };
            if err.is_nan() {
                if let Some(index) = non_finite(&xnew) {
                    return Err(Stop::NonFinite {
                        t: t + hs,
                        index,
                        stats,
                    });
                }
                return Err(Stop::ErrorEstimate { t, stats });
            }
            let mut fac = (0.9 / libm::pow(err, 0.25)).clamp(0.2, 6.0);
            if err <= 1.0 {
                if rejected {
                    fac = fac.min(1.0);
                }
                rejected = false;
                project(&mut xnew);
                let tn = if land { t_out } else { t + hs };
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
                h = (hs * fac).min(opts.max_step);
                if land {
                    next_out += 1;
                    observe(t, x);
                }
                break;
            }
            stats.rejected_steps += 1;
            rejected = true;
            h = hs * fac;
        }
    }
    Ok(stats)
}
