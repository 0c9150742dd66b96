//! Fixed-step classical Runge–Kutta 4 (Hairer, Nørsett & Wanner, *Solving ODEs I*, Sec. II.1,
//! Table 1.2, "the" Runge–Kutta method): `x + h/6 (k₁ + 2k₂ + 2k₃ + k₄)`, projected
//! ([`System::project`]) after every step.

use super::{fixed_run, one_step, Flow, Scratch, Stats, Stop, System};

/// Options of [`rk4()`] and [`midpoint`](super::midpoint()).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rk4Options {
    /// Step (shortened so that a whole number of steps ends at `t1`,
    /// [`fixed_steps`](super::fixed_steps)).
    pub step: f64,
    /// `observe` after every this many steps (and after the last); 0 counts as 1.
    pub output_every: usize,
}

/// The scratch floats of [`rk4()`] and [`rk4_step`] for a state of dimension `d`: the new
/// state and the four stages.
#[must_use]
pub const fn scratch_len(d: usize) -> usize {
    5 * d
}

/// One RK4 step of size `h` from `(t, x)` into `out`, then [`System::project`]; `k` holds the
/// four stages (`4 d`). Four evaluations; never fails.
fn step<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &[f64],
    out: &mut [f64],
    k: &mut [f64],
    stats: &mut Stats,
) -> Result<(), Stop> {
    let d = x.len();
    let (k1, k) = k.split_at_mut(d);
    let (k2, k) = k.split_at_mut(d);
    let (k3, k4) = k.split_at_mut(d);
    let k4 = &mut k4[..d];
    let euler = |out: &mut [f64], c: f64, k: &[f64]| {
        for ((o, xi), ki) in out.iter_mut().zip(x).zip(k) {
            *o = xi + c * ki;
        }
    };
    sys.deriv(t, x, k1);
    euler(out, 0.5 * h, k1);
    sys.deriv(t + 0.5 * h, out, k2);
    euler(out, 0.5 * h, k2);
    sys.deriv(t + 0.5 * h, out, k3);
    euler(out, h, k3);
    sys.deriv(t + h, out, k4);
    let (h6, h3) = (h / 6.0, h / 3.0);
    for i in 0..d {
        out[i] = x[i] + (h6 * k1[i] + h3 * k2[i] + h3 * k3[i] + h6 * k4[i]);
    }
    stats.evals += 4;
    sys.project(out);
    Ok(())
}

/// Fixed-step RK4 from `t0` to `t1` ([`fixed_steps`](super::fixed_steps)), projecting after
/// every step; `observe(t, x)` at `t0`, after every `output_every`-th step and after the last.
/// `scratch` holds at least [`scratch_len`]`(x.len())` floats.
///
/// # Errors
/// [`Stop::NonFinite`] when a step's state is not finite, [`Stop::Interrupted`], or
/// [`Stop::Invalid`]; `x` keeps the last accepted state.
pub fn rk4<S: System + ?Sized, R: Flow>(
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

/// One RK4 step of size `h` from `(t, x)` in place, then the projection (`scratch`: at least
/// [`scratch_len`]`(x.len())` floats); the work done.
///
/// # Errors
/// [`Stop::NonFinite`] at `t + h` when the new state is not finite (`x` unchanged), or
/// [`Stop::Invalid`].
pub fn rk4_step<S: System + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
) -> Result<Stats, Stop> {
    let len = (scratch_len(x.len()), 0);
    one_step(sys, t, h, x, scratch, len, |sys, x, out, k, _, stats| {
        step(sys, t, h, x, out, k, stats)
    })
}
