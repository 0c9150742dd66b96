//! Orders of convergence and run mechanics of the integrators on `ẍ = −x` (exact solution
//! `(cos t, −sin t)`) and on a spinning free-floating quaternion.

use super::*;

/// `ẍ = −x` as `[x, ẋ]`.
pub(super) struct Oscillator;

impl System for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn deriv(&mut self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = -x[0];
    }
}

/// The max-norm error of `x` at `t = 1` against the exact solution from `[1, 0]`.
fn error_at_one(x: &[f64; 2]) -> f64 {
    libm::fabs(x[0] - libm::cos(1.0)).max(libm::fabs(x[1] + libm::sin(1.0)))
}

/// A fixed-step run ([`rk4()`], [`midpoint()`]) of the oscillator, observing nothing.
type FixedRun = fn(
    &mut Oscillator,
    f64,
    f64,
    &Rk4Options,
    &mut [f64],
    &mut ArrayScratch<{ rk4::scratch_len(2) }>,
    fn(f64, &[f64]),
) -> Result<Stats, Stop>;

/// The observed orders `log₂(e(h)/e(h/2))` of a fixed-step method over `h = 0.1, 0.05, 0.025`
/// on the oscillator over 1 s.
fn orders(run: FixedRun) -> [f64; 2] {
    let e = [0.1, 0.05, 0.025].map(|h| {
        let mut x = [1.0, 0.0];
        let opts = Rk4Options {
            step: h,
            output_every: 1,
        };
        let mut scratch = ArrayScratch::new();
        run(
            &mut Oscillator,
            0.0,
            1.0,
            &opts,
            &mut x,
            &mut scratch,
            |_, _| (),
        )
        .unwrap();
        error_at_one(&x)
    });
    [libm::log2(e[0] / e[1]), libm::log2(e[1] / e[2])]
}

#[test]
fn rk4_is_fourth_order_and_observes_every_kth_step() {
    let p = orders(rk4);
    assert!(p.iter().all(|p| (3.8..4.3).contains(p)), "orders {p:?}");
    // 10 steps of 0.1, every 3rd observed, and the last: t = 0, 0.3, 0.6, 0.9, 1.
    let (mut seen, mut n) = ([0.0; 8], 0);
    let opts = Rk4Options {
        step: 0.1,
        output_every: 3,
    };
    let mut scratch = ArrayScratch::<{ rk4::scratch_len(2) }>::new();
    let stats = rk4(
        &mut Oscillator,
        0.0,
        1.0,
        &opts,
        &mut [1.0, 0.0],
        &mut scratch,
        |t, _| {
            seen[n] = t;
            n += 1;
        },
    )
    .unwrap();
    assert_eq!((stats.steps, stats.evals, n), (10, 40, 5));
    assert_eq!(seen[4], 1.0);
    assert!(libm::fabs(seen[2] - 0.6) < 1e-15, "{seen:?}");
}

#[test]
fn midpoint_is_second_order_and_symmetric() {
    let p = orders(midpoint);
    assert!(p.iter().all(|p| (1.9..2.1).contains(p)), "orders {p:?}");
    // Symmetric: a step of −h undoes a step of h (to the iteration tolerance).
    let mut scratch = ArrayScratch::<{ midpoint::scratch_len(2) }>::new();
    let mut x = [0.3, -0.7];
    midpoint_step(&mut Oscillator, 0.0, 0.2, &mut x, &mut scratch).unwrap();
    midpoint_step(&mut Oscillator, 0.2, -0.2, &mut x, &mut scratch).unwrap();
    assert!(
        libm::fabs(x[0] - 0.3).max(libm::fabs(x[1] + 0.7)) < 1e-13,
        "{x:?}"
    );
}

#[test]
fn dopri5_meets_its_tolerance_and_its_dense_output_is_accurate() {
    let mut errs = [0.0; 3];
    for (e, tol) in errs.iter_mut().zip([1e-6, 1e-8, 1e-10]) {
        let opts = Dopri5Options {
            tolerance: tol,
            max_step: 1.0,
            initial_step: 0.01,
            output_interval: 0.05,
        };
        let mut scratch = ArrayScratch::<{ dopri5::scratch_len(2) }>::new();
        let mut worst: f64 = 0.0;
        let mut x = [1.0, 0.0];
        dopri5(
            &mut Oscillator,
            0.0,
            10.0,
            &opts,
            &mut x,
            &mut scratch,
            |t, x| {
                let e = libm::fabs(x[0] - libm::cos(t)).max(libm::fabs(x[1] + libm::sin(t)));
                worst = worst.max(e);
            },
        )
        .unwrap();
        *e = worst;
    }
    // Each tolerance 100× tighter: the (dense-output) error at least 20× smaller, and within
    // 100× of the tolerance over 10 s.
    assert!(
        errs[0] > 20.0 * errs[1] && errs[1] > 20.0 * errs[2],
        "{errs:?}"
    );
    assert!(errs[2] < 1e-8, "{errs:?}");
}

/// A free rigid body's quaternion `x[3..7]` spinning at a constant `ω_b` (no joints, `D = 13`).
struct Spinner;

impl System for Spinner {
    fn dim(&self) -> usize {
        13
    }
    fn deriv(&mut self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx.fill(0.0);
        // q̇uat = ½ quat ⊗ (ω, 0).
        let (u, w, om) = ([x[3], x[4], x[5]], x[6], [x[10], x[11], x[12]]);
        for i in 0..3 {
            let cross = u[(i + 1) % 3] * om[(i + 2) % 3] - u[(i + 2) % 3] * om[(i + 1) % 3];
            dx[3 + i] = 0.5 * (w * om[i] + cross);
        }
        dx[6] = -0.5 * (u[0] * om[0] + u[1] * om[1] + u[2] * om[2]);
    }
    fn advance(&self, x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
        quaternion::advance_floating(x, h, at, f, out);
    }
}

#[test]
fn the_exponential_map_keeps_the_quaternion_unit_and_exact() {
    let mut x = [0.0; 13];
    x[6] = 1.0;
    x[10..13].copy_from_slice(&[0.0, 0.0, 2.0]);
    let opts = Rk4Options {
        step: 0.25,
        output_every: 1,
    };
    let mut scratch = ArrayScratch::<{ midpoint::scratch_len(13) }>::new();
    midpoint(
        &mut Spinner,
        0.0,
        10.0,
        &opts,
        &mut x,
        &mut scratch,
        |_, _| (),
    )
    .unwrap();
    // A constant ω about z: exactly a turn of 20 rad, quat = (0, 0, sin 10, cos 10).
    let unit = x[3] * x[3] + x[4] * x[4] + x[5] * x[5] + x[6] * x[6];
    assert!(libm::fabs(unit - 1.0) < 1e-14, "|quat|² = {unit}");
    assert!(libm::fabs(x[5] - libm::sin(10.0)) < 1e-12, "{x:?}");
    assert!(libm::fabs(x[6] - libm::cos(10.0)) < 1e-12, "{x:?}");
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let opts = Rk4Options {
        step: 0.1,
        output_every: 1,
    };
    let invalid = |r: Result<Stats, Stop>| assert!(matches!(r, Err(Stop::Invalid { .. })), "{r:?}");
    let mut x = [1.0, 0.0];
    let run = |t0, t1, x: &mut [f64], scratch: &mut dyn Scratch, opts: &Rk4Options| {
        invalid(rk4(&mut Oscillator, t0, t1, opts, x, scratch, |_, _| ()));
        invalid(midpoint(
            &mut Oscillator,
            t0,
            t1,
            opts,
            x,
            scratch,
            |_, _| (),
        ));
    };
    let mut scratch = ArrayScratch::<{ rk4::scratch_len(3) }>::new();
    // Scratch too small, a state of the wrong length, an end before the start, a zero step.
    run(0.0, 1.0, &mut x, &mut ArrayScratch::<3>::new(), &opts);
    run(0.0, 1.0, &mut [0.0; 3], &mut scratch, &opts);
    run(1.0, 0.0, &mut x, &mut scratch, &opts);
    run(
        0.0,
        1.0,
        &mut x,
        &mut scratch,
        &Rk4Options { step: 0.0, ..opts },
    );
    run(0.0, f64::NAN, &mut x, &mut scratch, &opts);
    let adaptive = Dopri5Options {
        tolerance: 0.0,
        max_step: 1.0,
        initial_step: 0.1,
        output_interval: 0.1,
    };
    let mut big = ArrayScratch::<{ rosenbrock::scratch_len(2) }, 2>::new();
    invalid(dopri5(
        &mut Oscillator,
        0.0,
        1.0,
        &adaptive,
        &mut x,
        &mut big,
        |_, _| (),
    ));
    invalid(rosenbrock(
        &mut Oscillator,
        0.0,
        1.0,
        &adaptive,
        &mut x,
        &mut big,
        |_, _| (),
    ));
    let mut no_pivots = ArrayScratch::<{ rosenbrock::scratch_len(2) }>::new();
    invalid(rosenbrock_step(
        &mut Oscillator,
        0.0,
        0.1,
        &mut x,
        &mut no_pivots,
    ));
    assert_eq!(x, [1.0, 0.0]);
}

#[test]
fn observe_can_stop_a_run() {
    let opts = Dopri5Options {
        tolerance: 1e-8,
        max_step: 1.0,
        initial_step: 0.01,
        output_interval: 0.1,
    };
    let mut scratch = ArrayScratch::<{ dopri5::scratch_len(2) }>::new();
    let mut x = [1.0, 0.0];
    let r = dopri5(
        &mut Oscillator,
        0.0,
        10.0,
        &opts,
        &mut x,
        &mut scratch,
        |t, _| {
            if t >= 0.5 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    match r {
        Err(Stop::Interrupted { t, stats }) => assert!(t < 1.0 && stats.steps > 0, "{t} {stats:?}"),
        other => panic!("{other:?}"),
    }
}
