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
//! `ode_solvers` is explicit only; and the compiled simulators of `scene!` need the same method
//! step for step, `no_std` on fixed-size arrays (`kanegen::ode::rosenbrock`), which mirrors this
//! file — hence also the hand-written LU (the same operations in the same order, so both
//! simulators agree to the rounding of their right-hand sides and of `J`).
//!
//! [`dopri5`]: crate::integrate::dopri5

// Index loops over stages and matrix entries, in the same order in both mirrors.
#![allow(clippy::needless_range_loop)]

use crate::integrate::{Dopri5Options, Flow, IntegrateError, Stats, System};

/// Options of [`rosenbrock`]: the same fields as [`dopri5`](crate::integrate::dopri5)'s
/// (`output_interval`: the spacing of the output times the steps land on).
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

/// Factors `a` (row-major `d × d`) in place into `P a = L U` by Gaussian elimination with
/// partial pivoting (`piv[k]`: the row swapped with row `k`). `false` when a pivot is zero or
/// not finite.
pub fn lu_factor(a: &mut [f64], piv: &mut [usize], d: usize) -> bool {
    for k in 0..d {
        let mut p = k;
        for i in k + 1..d {
            if a[i * d + k].abs() > a[p * d + k].abs() {
                p = i;
            }
        }
        piv[k] = p;
        let pv = a[p * d + k];
        if pv == 0.0 || !pv.is_finite() {
            return false;
        }
        if p != k {
            for j in 0..d {
                a.swap(k * d + j, p * d + j);
            }
        }
        for i in k + 1..d {
            let l = a[i * d + k] / pv;
            a[i * d + k] = l;
            for j in k + 1..d {
                a[i * d + j] -= l * a[k * d + j];
            }
        }
    }
    true
}

/// Solves `a x = b` in place (`b` becomes `x`) with the factors of [`lu_factor`].
pub fn lu_solve(a: &[f64], piv: &[usize], b: &mut [f64], d: usize) {
    // The factorization swapped whole rows: all the swaps first, then `L`.
    for k in 0..d {
        b.swap(k, piv[k]);
    }
    for k in 0..d {
        for i in k + 1..d {
            b[i] -= a[i * d + k] * b[k];
        }
    }
    for k in (0..d).rev() {
        let mut s = b[k];
        for j in k + 1..d {
            s -= a[k * d + j] * b[j];
        }
        b[k] = s / a[k * d + k];
    }
}

/// Adaptive Rodas4 from `t0` to `t1` (see the module doc). `observe(t, x)` is called at `t0`,
/// at every `t0 + k·output_interval < t1` (steps land on these times) and at `t1`.
///
/// # Errors
/// As [`dopri5`](crate::integrate::dopri5): a non-finite state, a step-size underflow (also
/// when the iteration matrix stays singular), an overflowing error estimate, an interruption.
pub fn rosenbrock<S: System, R: Flow>(
    sys: &mut S,
    t0: f64,
    t1: f64,
    opts: &RosenbrockOptions,
    x: &mut [f64],
    mut observe: impl FnMut(f64, &[f64]) -> R,
) -> Result<Stats, IntegrateError> {
    assert!(opts.tolerance > 0.0 && opts.max_step > 0.0 && opts.initial_step > 0.0);
    assert!(opts.output_interval > 0.0 && t1 >= t0);
    let d = sys.dim();
    let tol = opts.tolerance;
    let sq = f64::EPSILON.sqrt();
    let (mut f0, mut ft, mut tmp, mut xnew) =
        (vec![0.0; d], vec![0.0; d], vec![0.0; d], vec![0.0; d]);
    let mut jac = vec![0.0; d * d];
    let mut g = vec![0.0; d * d];
    let mut piv = vec![0usize; d];
    let mut k: Vec<Vec<f64>> = vec![vec![0.0; d]; STAGES];
    let mut stats = Stats::default();
    let mut t = t0;
    let mut h = opts.initial_step.min(opts.max_step);
    let mut next_out = 1usize;
    let mut rejected = false;
    if observe(t0, x).stop() {
        return Err(IntegrateError::Interrupted { t: t0, stats });
    }
    while t < t1 {
        // f, ∂f/∂x and ∂f/∂t at (t, x) by forward differences.
        sys.deriv(t, x, &mut f0);
        let cb = f64::EPSILON.cbrt();
        for j in 0..d {
            let dj = cb * x[j].abs().max(1.0);
            tmp.copy_from_slice(x);
            tmp[j] += dj;
            sys.deriv(t, &tmp, &mut xnew);
            tmp[j] = x[j] - dj;
            sys.deriv(t, &tmp, &mut ft);
            for i in 0..d {
                jac[i * d + j] = (xnew[i] - ft[i]) / (2.0 * dj);
            }
        }
        let dt = sq * t.abs().max(1.0);
        sys.deriv(t + dt, x, &mut ft);
        for i in 0..d {
            ft[i] = (ft[i] - f0[i]) / dt;
        }
        stats.evals += 2 * d + 2;
        loop {
            let t_out = (t0 + next_out as f64 * opts.output_interval).min(t1);
            let land = t + h >= t_out - 1e-12 * t_out.abs().max(1.0);
            let hs = if land { t_out - t } else { h };
            if hs <= f64::EPSILON * t.abs().max(1.0) {
                return Err(IntegrateError::StepTooSmall { t, stats });
            }
            let ghinv = 1.0 / (hs * GAMMA);
            for (gi, ji) in g.iter_mut().zip(&jac) {
                *gi = -ji;
            }
            for i in 0..d {
                g[i * d + i] += ghinv;
            }
            let singular = !lu_factor(&mut g, &mut piv, d);
            for s in (0..STAGES).take_while(|_| !singular) {
                if s == 0 {
                    k[0].copy_from_slice(&f0);
                } else {
                    for i in 0..d {
                        let mut acc = x[i];
                        for (j, kj) in k.iter().enumerate().take(s) {
                            acc += A[s][j] * kj[i];
                        }
                        tmp[i] = acc;
                    }
                    sys.deriv(t + ALPHA[s] * hs, &tmp, &mut xnew);
                    stats.evals += 1;
                    for i in 0..d {
                        let mut acc = xnew[i];
                        for (j, kj) in k.iter().enumerate().take(s) {
                            acc += (C[s][j] / hs) * kj[i];
                        }
                        tmp[i] = acc;
                    }
                    k[s].copy_from_slice(&tmp);
                }
                for i in 0..d {
                    k[s][i] += GAMMA_SUM[s] * hs * ft[i];
                }
                lu_solve(&g, &piv, &mut k[s], d);
            }
            let mut err = f64::INFINITY;
            if !singular {
                err = 0.0;
                for i in 0..d {
                    let mut acc = x[i];
                    let mut e = 0.0;
                    for s in 0..STAGES {
                        acc += M[s] * k[s][i];
                        e += E[s] * k[s][i];
                    }
                    xnew[i] = acc;
                    let sc = tol + tol * x[i].abs().max(acc.abs());
                    err += (e / sc) * (e / sc);
                }
                err = (err / d as f64).sqrt();
                if err.is_nan() {
                    if let Some(index) = xnew.iter().position(|v| !v.is_finite()) {
                        return Err(IntegrateError::NonFinite {
                            t: t + hs,
                            index,
                            stats,
                        });
                    }
                    return Err(IntegrateError::ErrorEstimate { t, stats });
                }
            }
            let mut fac = (0.9 / err.powf(0.25)).clamp(0.2, 6.0);
            if err <= 1.0 {
                if rejected {
                    fac = fac.min(1.0);
                }
                rejected = false;
                sys.project(&mut xnew);
                let tn = if land { t_out } else { t + hs };
                if let Some(index) = xnew.iter().position(|v| !v.is_finite()) {
                    return Err(IntegrateError::NonFinite {
                        t: tn,
                        index,
                        stats,
                    });
                }
                x.copy_from_slice(&xnew);
                t = tn;
                stats.steps += 1;
                h = (hs * fac).min(opts.max_step);
                if land {
                    next_out += 1;
                    if observe(t, x).stop() {
                        return Err(IntegrateError::Interrupted { t, stats });
                    }
                }
                if t < t1 && sys.interrupted() {
                    return Err(IntegrateError::Interrupted { t, stats });
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `lu_factor` + `lu_solve` against a known solution on a 5×5 system that needs pivoting at
    /// every column (a wrong order of the row swaps fails this).
    #[test]
    fn lu_solves_with_pivoting() {
        let d = 5;
        let mut a: Vec<f64> = (0..d * d)
            .map(|k| {
                let (i, j) = (k / d, k % d);
                (((i * 7 + j * 3) % 11) as f64 - 5.0) + if (i + j) % 4 == 0 { 9.0 } else { 0.0 }
            })
            .collect();
        let x: Vec<f64> = (0..d).map(|i| 1.0 + i as f64 * 0.5).collect();
        let mut b: Vec<f64> = (0..d)
            .map(|i| (0..d).map(|j| a[i * d + j] * x[j]).sum())
            .collect();
        let mut piv = vec![0; d];
        assert!(lu_factor(&mut a, &mut piv, d));
        lu_solve(&a, &piv, &mut b, d);
        for i in 0..d {
            assert!((b[i] - x[i]).abs() < 1e-12, "{b:?}");
        }
    }

    struct Osc;
    impl System for Osc {
        fn dim(&self) -> usize {
            2
        }
        fn deriv(&mut self, _t: f64, x: &[f64], dx: &mut [f64]) {
            dx[0] = x[1];
            dx[1] = -x[0];
        }
    }

    /// Fixed steps (tolerance huge, `max_step = h`) on `ẍ = −x` over 1 s: the error falls 16×
    /// per halving (order 4). Measured 6.07e-8, 3.81e-9, 2.38e-10 at h = 0.1, 0.05, 0.025.
    #[test]
    fn order_four_on_the_oscillator() {
        let errs: Vec<f64> = [0.1, 0.05, 0.025]
            .iter()
            .map(|&h| {
                let mut x = [1.0, 0.0];
                let opts = RosenbrockOptions {
                    tolerance: 1e30,
                    max_step: h,
                    initial_step: h,
                    output_interval: 100.0,
                };
                rosenbrock(&mut Osc, 0.0, 1.0, &opts, &mut x, |_, _| ()).unwrap();
                (x[0] - 1f64.cos()).abs().max((x[1] + 1f64.sin()).abs())
            })
            .collect();
        for w in errs.windows(2) {
            let p = (w[0] / w[1]).log2();
            assert!((3.7..4.5).contains(&p), "order {p} from {errs:?}");
        }
    }
}
