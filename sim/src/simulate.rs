//! Running a [`Scene`]: integration segment by segment between its events, the conservation
//! monitors ([`crate::monitors`]) and the samples streamed to a [`Sink`]; the summary of a run.
//! The scene as a first-order system is [`SceneSystem`] ([`crate::system`]).

use crate::events::EventReport;
use crate::monitors::Monitors;
use crate::scene::{Event, Integrator, Scene, SimulationSpec};
use anyhow::Result;
use kanegen_runtime::ode::{self, Dopri5Options, Rk4Options, Stats, Stop, VecScratch};
use serde::Serialize;
use std::cell::{Cell, RefCell};
use std::ops::ControlFlow;
use std::sync::atomic::AtomicBool;

pub use crate::monitors::{conserves_energy, conserves_momentum};
pub use crate::sinks::{Decimated, Sample, Sink};
pub use crate::system::{quintic_reference, SceneSystem};

/// The progress bar of a run: `indicatif`'s with the `progress` feature (default).
#[cfg(feature = "progress")]
pub use indicatif::ProgressBar;

/// Without the `progress` feature there is no progress bar: this type has no values, so
/// [`Control::progress`] and the argument of [`simulate`] can only be `None`.
#[cfg(not(feature = "progress"))]
#[derive(Debug)]
pub enum ProgressBar {}

#[cfg(not(feature = "progress"))]
impl ProgressBar {
    /// Never called (there is no value to call it on).
    pub fn set_position(&self, _pos: u64) {
        match *self {}
    }
}

/// The final joint state of a run.
#[derive(Clone, Debug, Serialize)]
pub struct FinalState {
    /// Joint positions.
    pub q: Vec<f64>,
    /// Joint rates.
    pub qd: Vec<f64>,
}

/// The JSON summary of a run. Drifts are `max_t |X(t) − X(0)| / |X(0)|` over the output samples
/// (absolute when `X(0) = 0`), and `null` when the scene does not conserve `X`: energy needs no
/// drives, no damping, no wrenches, and (free-floating) no gravity — on a fixed base the
/// gravitational potential is included; momentum needs a free-floating base with no wrenches and
/// no gravity (drives and damping are internal).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// `"fixed"` or `"free-floating"`.
    pub base: &'static str,
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (dopri5).
    pub rejected_steps: usize,
    /// Right-hand-side evaluations.
    pub evals: usize,
    /// Wall-clock time of the integration, s.
    pub wall_s: f64,
    /// Maximal relative energy drift.
    pub max_energy_drift_rel: Option<f64>,
    /// Maximal relative linear-momentum drift.
    pub max_linear_momentum_drift_rel: Option<f64>,
    /// Maximal relative angular-momentum drift.
    pub max_angular_momentum_drift_rel: Option<f64>,
    /// The final joint state (at `t_end`).
    #[serde(rename = "final")]
    pub final_state: FinalState,
    /// Whether the run reached the scene's duration.
    pub complete: bool,
    /// Time reached, s (the duration when complete).
    pub t_end: f64,
    /// Why an incomplete run stopped: `interrupted`, or the integrator's error; `null` when
    /// complete.
    pub stopped: Option<String>,
    /// What each payload capture or release did (`[[events]]`; absent from the JSON when the
    /// scene has none): the momentum of system and payload before, its error through the event,
    /// and the jump of kinetic energy.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<EventReport>,
    /// The smallest `σ_min` of the generalized Jacobian `J*` of the last body's frame over the
    /// output samples, with its time: how close the run came to a dynamic singularity
    /// ([`crate::singularity`]). Free-floating scenes with at least 6 joints only (absent from
    /// the JSON otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub singularity: Option<SigmaMin>,
}

/// The smallest `σ_min(J*)` of a run ([`Summary::singularity`]).
#[derive(Clone, Debug, Serialize)]
pub struct SigmaMin {
    /// The body whose origin frame `J*` maps to.
    pub body: String,
    /// The smallest `σ_min(J*)` over the output samples (m/rad-mixed units of `J*`).
    pub sigma_min: f64,
    /// Its time, s.
    pub t: f64,
}

/// A finished run.
#[derive(Clone, Debug)]
pub struct Run {
    /// The summary.
    pub summary: Summary,
    /// The output samples, `t = 0` first, the final time last.
    pub samples: Vec<Sample>,
}

/// How a run is watched and stopped.
#[derive(Clone, Copy, Default)]
pub struct Control<'a> {
    /// Advanced to the simulated time in milliseconds.
    pub progress: Option<&'a ProgressBar>,
    /// When set (by a Ctrl-C handler), the run stops after the current step and the summary says
    /// `complete: false`, `stopped: "interrupted"`.
    pub stop: Option<&'a AtomicBool>,
}

/// Integrates `scene` over its duration, sampling every `output_every` steps (RK4, midpoint) or
/// every `output_every · step` seconds of dense output (dopri5), and streams each sample to
/// `sink`; only the drift maxima and the last state are kept, so memory does not grow with the
/// duration.
///
/// An integrator failure (a non-finite state, a step-size underflow) or a stop through
/// [`Control::stop`] ends the run early with a summary saying `complete: false` and why
/// (`stopped`); every sample up to there has gone to the sink.
///
/// # Errors
/// Only the sink's.
pub fn simulate_to(scene: &Scene, sink: &mut dyn Sink, control: Control<'_>) -> Result<Summary> {
    let mut sys = SceneSystem::new(scene).with_stop(control.stop);
    let mut x = sys.initial_state();
    let monitors = RefCell::new(Monitors::new(scene, &x));
    let mut sink_error: Option<anyhow::Error> = None;
    let last_t = Cell::new(f64::NAN);
    let mut record = |t: f64, x: &[f64]| -> ControlFlow<()> {
        if sink_error.is_some() {
            return ControlFlow::Break(());
        }
        let (energy_drift, momentum_drift) = monitors.borrow_mut().observe(t, x);
        if let Some(pb) = control.progress {
            pb.set_position((t * 1000.0) as u64);
        }
        last_t.set(t);
        let sample = Sample {
            t,
            x: x.to_vec(),
            energy_drift,
            momentum_drift,
        };
        match sink.sample(&sample) {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                sink_error = Some(e);
                ControlFlow::Break(())
            }
        }
    };
    let start = std::time::Instant::now();
    let (stats, reports, result) = run_segments(&mut sys, &monitors, &mut x, &mut record);
    let wall_s = start.elapsed().as_secs_f64();
    let (t_end, stopped) = match &result {
        Ok(()) => (scene.simulation.duration, None),
        Err(e) => (e.t(), Some(stop_reason(e, &sys))),
    };
    // An early stop: the state reached (the last accepted one) ends the samples.
    if result.is_err() && last_t.get() != t_end {
        let _ = record(t_end, &x);
    }
    if let Some(e) = sink_error {
        return Err(e);
    }
    let (q, qd, _) = sys.split(&x);
    let end = RunEnd {
        stats,
        wall_s,
        complete: result.is_ok(),
        t_end,
        stopped,
        final_state: FinalState {
            q: q.to_vec(),
            qd: qd.to_vec(),
        },
        events: reports,
    };
    Ok(summary(scene, end, &monitors.into_inner()))
}

/// Integrates `sys` over the scene's duration from `x`, one segment between events at a time:
/// each ends exactly at its event time (the state at `t_e⁻` is sampled), the event switches
/// the model and jumps `ν` (the monitors' baselines move with it, see [`crate::events`],
/// "Monitors"), and the next segment starts with a sample at `t_e⁺`. Events at or after the
/// end (a scene whose duration was shortened) do not happen. Returns the work, the events'
/// reports and how the run ended.
fn run_segments<'s>(
    sys: &mut SceneSystem<'s>,
    monitors: &RefCell<Monitors<'_>>,
    x: &mut [f64],
    record: &mut impl FnMut(f64, &[f64]) -> ControlFlow<()>,
) -> (Stats, Vec<EventReport>, Result<(), Stop>) {
    let scene = sys.scene();
    let sim = &scene.simulation;
    let events: Vec<&Event> = scene
        .events
        .iter()
        .filter(|e| e.time < sim.duration)
        .collect();
    let ends: Vec<f64> = events
        .iter()
        .map(|e| e.time)
        .chain([sim.duration])
        .collect();
    let mut stats = Stats::default();
    let mut reports = Vec::new();
    let mut t0 = 0.0;
    let mut scratch = VecScratch::default();
    for (seg, &t1) in ends.iter().enumerate() {
        if seg > 0 {
            let report = sys.apply_event(events[seg - 1], x);
            monitors
                .borrow_mut()
                .after_event(&report, sys.params().clone());
            reports.push(report);
        }
        match integrate_segment(sys, sim, (t0, t1), x, &mut scratch, record) {
            Ok(s) => stats.accumulate(s),
            Err(e) => {
                stats.accumulate(e.stats());
                return (stats, reports, Err(e));
            }
        }
        t0 = t1;
    }
    (stats, reports, Ok(()))
}

/// Why a run stopped early, for the summary.
fn stop_reason(e: &Stop, sys: &SceneSystem<'_>) -> String {
    match e {
        Stop::Interrupted { .. } => "interrupted".to_string(),
        Stop::NonFinite { t, index, .. } => format!(
            "`{}` became non-finite in the step to t = {t} (the state overflowed: a singular \
             mass matrix or an unstable drive)",
            sys.component_name(*index)
        ),
        other => other.to_string(),
    }
}

/// How a run ended (what [`summary`] reports besides the monitors).
struct RunEnd {
    stats: Stats,
    wall_s: f64,
    complete: bool,
    t_end: f64,
    stopped: Option<String>,
    final_state: FinalState,
    events: Vec<EventReport>,
}

/// The summary of a run of `scene`.
fn summary(scene: &Scene, end: RunEnd, monitors: &Monitors<'_>) -> Summary {
    Summary {
        base: if scene.is_floating() {
            "free-floating"
        } else {
            "fixed"
        },
        steps: end.stats.steps,
        rejected_steps: end.stats.rejected_steps,
        evals: end.stats.evals,
        wall_s: end.wall_s,
        max_energy_drift_rel: monitors.max_energy,
        max_linear_momentum_drift_rel: monitors.max_momentum.map(|m| m.0),
        max_angular_momentum_drift_rel: monitors.max_momentum.map(|m| m.1),
        final_state: end.final_state,
        complete: end.complete,
        t_end: end.t_end,
        stopped: end.stopped,
        events: end.events,
        singularity: monitors.sigma.map(|(sigma_min, t)| SigmaMin {
            body: scene.model.joints()[scene.model.dof() - 1].body.clone(),
            sigma_min,
            t,
        }),
    }
}

/// Integrates `sys` from `t0` to `t1` (ending exactly at `t1`) with the scene's integrator
/// ([`kanegen_runtime::ode`], in `scratch`), sampling through `record` as [`simulate_to`]
/// describes (the segment's first and last states included).
fn integrate_segment(
    sys: &mut SceneSystem<'_>,
    sim: &SimulationSpec,
    (t0, t1): (f64, f64),
    x: &mut [f64],
    scratch: &mut VecScratch,
    record: &mut impl FnMut(f64, &[f64]) -> ControlFlow<()>,
) -> Result<Stats, Stop> {
    let fixed = Rk4Options {
        step: sim.step,
        output_every: sim.output_every,
    };
    let adaptive = Dopri5Options {
        tolerance: sim.tolerance,
        max_step: sim.max_step,
        initial_step: sim.step,
        output_interval: sim.step * sim.output_every as f64,
    };
    match sim.integrator {
        Integrator::Rk4 => ode::rk4(sys, t0, t1, &fixed, x, scratch, record),
        Integrator::Midpoint => ode::midpoint(sys, t0, t1, &fixed, x, scratch, record),
        Integrator::Dopri5 => ode::dopri5(sys, t0, t1, &adaptive, x, scratch, record),
        Integrator::Rosenbrock => ode::rosenbrock(sys, t0, t1, &adaptive, x, scratch, record),
    }
}

/// [`simulate_to`] keeping every sample in memory (tests and short runs).
///
/// # Errors
/// If the run did not complete (the integrator's error).
pub fn simulate(scene: &Scene, progress: Option<&ProgressBar>) -> Result<Run> {
    let mut samples: Vec<Sample> = Vec::new();
    let mut sink = |s: &Sample| -> Result<()> {
        samples.push(s.clone());
        Ok(())
    };
    let control = Control {
        progress,
        stop: None,
    };
    let summary = simulate_to(scene, &mut sink, control)?;
    if let Some(why) = &summary.stopped {
        anyhow::bail!("{why}");
    }
    Ok(Run { summary, samples })
}

impl Summary {
    /// Checks every number of the summary is finite.
    ///
    /// # Errors
    /// Naming the first field that is not.
    pub fn check_finite(&self) -> Result<()> {
        let mut fields: Vec<(String, f64)> = vec![("t_end".into(), self.t_end)];
        for (k, v) in [
            ("max_energy_drift_rel", self.max_energy_drift_rel),
            (
                "max_linear_momentum_drift_rel",
                self.max_linear_momentum_drift_rel,
            ),
            (
                "max_angular_momentum_drift_rel",
                self.max_angular_momentum_drift_rel,
            ),
        ] {
            if let Some(v) = v {
                fields.push((k.into(), v));
            }
        }
        for (i, v) in self.final_state.q.iter().enumerate() {
            fields.push((format!("final.q[{i}]"), *v));
        }
        for (i, v) in self.final_state.qd.iter().enumerate() {
            fields.push((format!("final.qd[{i}]"), *v));
        }
        match fields.iter().find(|(_, v)| !v.is_finite()) {
            Some((k, v)) => anyhow::bail!(
                "summary field `{k}` is {v} (not finite): a monitored quantity overflowed"
            ),
            None => Ok(()),
        }
    }
}
