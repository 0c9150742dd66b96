//! The integration part of `kanegen accuracy`: for each integrator and a ladder of steps or
//! tolerances, the final-state error against a tight reference solution versus wall time (the
//! classic work–precision diagram).
//!
//! A scene with flexible joints (`[effects] flexible`) also gets the stiff integrator's ladder
//! (`rosenbrock`, Rodas4, over [`TOLERANCES`]) and finer fixed steps ([`STIFF_STEPS`]): its
//! spring modes bound an explicit method's step by stability.
//!
//! The reference is dopri5 at tolerance [`REFERENCE_TOLERANCE`]; its own error is estimated by
//! comparing it with dopri5 at 100× that tolerance, and reported, so that no error below it is
//! read as meaningful.

use anyhow::Result;
use kanegen_sim::scene::{Integrator, Scene};
use kanegen_sim::simulate::simulate;
use serde::{Deserialize, Serialize};

/// Tolerance of the reference solution.
pub const REFERENCE_TOLERANCE: f64 = 1e-13;

/// One integrator setting of the ladder.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct IntegrationRow {
    /// `rk4`, `midpoint`, `dopri5` or `rosenbrock`.
    pub integrator: String,
    /// `h = 0.01` or `tol = 1e-8`.
    pub setting: String,
    /// `max |x(T) − x_ref(T)| / max |x_ref(T)|` over the whole state vector (joints, and the
    /// base pose and twist of a free-floating scene); `null` when the run failed or diverged.
    pub final_error: Option<f64>,
    /// Wall time of the integration, s.
    pub wall_s: f64,
    /// Accepted steps.
    pub steps: usize,
    /// Right-hand-side evaluations.
    pub evals: usize,
    /// Why the run failed (`null` when it did not): the integrator's error.
    #[serde(default)]
    pub failure: Option<String>,
}

/// The integration ladder of one scene.
#[derive(Clone, Debug, Serialize)]
pub struct IntegrationReport {
    /// Simulated time, s.
    pub duration: f64,
    /// The reference's estimated own error (against dopri5 at 100× its tolerance).
    pub reference_error: f64,
    /// The ladder, integrator by integrator, coarse to fine.
    pub rows: Vec<IntegrationRow>,
}

/// Steps of the fixed-step ladders, s.
pub const STEPS: [f64; 5] = [0.1, 0.05, 0.025, 0.0125, 0.00625];
/// Steps of the fixed-step ladders of a scene with flexible joints, s.
pub const STIFF_STEPS: [f64; 5] = [1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5];
/// Tolerances of the dopri5 and rosenbrock ladders.
pub const TOLERANCES: [f64; 5] = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12];

/// The scene with another integrator setting, sampling only its first and last state.
pub(crate) fn with_setting(
    scene: &Scene,
    integrator: Integrator,
    step: f64,
    tolerance: f64,
) -> Scene {
    let mut s = scene.clone();
    let sim = &mut s.simulation;
    sim.integrator = integrator;
    sim.tolerance = tolerance;
    if integrator.is_adaptive() {
        sim.step = 1e-3;
        sim.max_step = scene.simulation.duration;
    } else {
        sim.step = step;
    }
    sim.output_every = usize::MAX / 4;
    s
}

/// What one run gives: the final state (or why there is none), wall time, steps, evaluations.
pub(crate) struct Outcome {
    pub(crate) x: std::result::Result<Vec<f64>, String>,
    pub(crate) wall_s: f64,
    pub(crate) steps: usize,
    pub(crate) evals: usize,
}

/// Runs `scene`; a failed or non-finite run is an outcome, not an error.
fn run(scene: &Scene) -> Outcome {
    let start = std::time::Instant::now();
    match simulate(scene, None) {
        Ok(r) => {
            let x = match r.samples.last() {
                Some(s) if s.x.iter().all(|v| v.is_finite()) => Ok(s.x.clone()),
                _ => Err("non-finite final state".to_string()),
            };
            Outcome {
                x,
                wall_s: r.summary.wall_s,
                steps: r.summary.steps,
                evals: r.summary.evals,
            }
        }
        Err(e) => Outcome {
            x: Err(format!("{e:#}")),
            wall_s: start.elapsed().as_secs_f64(),
            steps: 0,
            evals: 0,
        },
    }
}

/// Runs `scene` `repeats` times (at least once): the first run's outcome with the median wall
/// time (runs of a few milliseconds on a shared machine are noisy).
pub(crate) fn run_scene(scene: &Scene, repeats: usize) -> Outcome {
    let mut o = run(scene);
    let mut walls = vec![o.wall_s];
    for _ in 1..repeats {
        walls.push(run(scene).wall_s);
    }
    walls.sort_by(f64::total_cmp);
    o.wall_s = walls[walls.len() / 2];
    o
}

/// `max |x − r| / max |r|`.
#[must_use]
pub fn state_error(x: &[f64], r: &[f64]) -> f64 {
    let scale = r
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    x.iter()
        .zip(r)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
        / scale
}

/// Runs the ladder on `scene` (its duration, drives and effects; only the integrator changes).
/// Each setting runs `repeats` times (at least once) and reports the median wall time: runs of a
/// few milliseconds on a shared machine are noisy.
pub fn integration_report(scene: &Scene, repeats: usize) -> Result<IntegrationReport> {
    let reference = |tol: f64| -> Result<Vec<f64>> {
        run(&with_setting(scene, Integrator::Dopri5, 0.0, tol))
            .x
            .map_err(|e| {
                anyhow::anyhow!("the reference solution (dopri5, tol {tol:e}) failed: {e}")
            })
    };
    let xref = reference(REFERENCE_TOLERANCE)?;
    let reference_error = state_error(&reference(100.0 * REFERENCE_TOLERANCE)?, &xref);
    let mut rows = Vec::new();
    let stiff = scene.flexible.is_some();
    let steps: &[f64] = if stiff { &STIFF_STEPS } else { &STEPS };
    let mut ladders: Vec<(Integrator, &str, &[f64])> = vec![
        (Integrator::Rk4, "rk4", steps),
        (Integrator::Midpoint, "midpoint", steps),
        (Integrator::Dopri5, "dopri5", &TOLERANCES),
    ];
    if stiff {
        ladders.push((Integrator::Rosenbrock, "rosenbrock", &TOLERANCES));
    }
    for (integrator, name, values) in ladders {
        for &v in values {
            let (step, tol, setting) = if integrator.is_adaptive() {
                (0.0, v, format!("tol = {v:e}"))
            } else {
                (v, 1e-8, format!("h = {v}"))
            };
            let o = run_scene(&with_setting(scene, integrator, step, tol), repeats);
            rows.push(IntegrationRow {
                integrator: name.into(),
                setting,
                final_error: o.x.as_ref().ok().map(|x| state_error(x, &xref)),
                wall_s: o.wall_s,
                steps: o.steps,
                evals: o.evals,
                failure: o.x.err(),
            });
        }
    }
    Ok(IntegrationReport {
        duration: scene.simulation.duration,
        reference_error,
        rows,
    })
}
