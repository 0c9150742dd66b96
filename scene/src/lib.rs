//! # kanegen-scene
//!
//! Simulation scenes: a TOML file naming a model, the base (fixed or free-floating),
//! an optional payload, the effects (gravity, joint damping, constant or tabulated wrenches), the joint
//! drives, the initial state, the integrator, and payload captures and releases at given times
//! (`[[events]]`, free-floating base; the simulator's `kanegen_sim::events` does them). See
//! `docs/scenes.md`.
//!
//! The format as plain validated data, read by the interpreted simulator (`kanegen-sim`, which
//! re-exports this crate as `kanegen_sim::scene`) and by the `scene!` proc-macro; it depends on
//! the model and the dynamics' load types only, so that `scene!` builds without the simulator.
//!
//! Every table rejects unknown keys, and every validation error names its key
//! (`simulation.tolerance: must be > 0`), with the line where the table starts for the tables
//! that can repeat or nest ([`SceneError`]). "Effects decide the code": only the effects a scene
//! names end up in the [`Loads`](kanegen_dynamics::Loads) of the simulation.
//!
//! ```
//! let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
//! let scene = kanegen_scene::Scene::parse(r#"
//!     model = "models/two_link.toml"
//!     [simulation]
//!     duration = 1.0
//! "#, &dir).unwrap();
//! assert_eq!(scene.q0.len(), scene.model.dof());
//! ```
#![warn(missing_docs)]

/// A [`SceneError::Invalid`] with a formatted message naming the key.
macro_rules! invalid {
    ($($arg:tt)*) => {
        $crate::SceneError::invalid(format!($($arg)*))
    };
}

/// Returns early with [`invalid!`].
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err(invalid!($($arg)*))
    };
}

mod effects;
mod error;
pub mod flexible;

pub use error::SceneError;

use error::Coordinates;

use kanegen_dynamics::base::BASE_BODY;
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::{ExternalWrench, ForwardMethod, LoadFrame, Methods};
use kanegen_model::bounds::{Bound, FORCE, GAIN, GRAVITY, LENGTH, POSITION, RATE};
use kanegen_model::io::InertiaSpec;
use kanegen_model::{Inertial, Model, Validation};
use serde::Deserialize;
use std::path::Path;

/// The result of reading a scene.
pub type Result<T, E = SceneError> = std::result::Result<T, E>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    model: String,
    #[serde(default)]
    allow_nonphysical: bool,
    base: Option<RawBase>,
    payload: Option<RawPayload>,
    #[serde(default)]
    effects: RawEffects,
    drives: Option<RawDrives>,
    #[serde(default)]
    initial: RawInitial,
    simulation: RawSimulation,
    #[serde(default)]
    events: Vec<toml::Spanned<RawEvent>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBase {
    #[serde(rename = "type")]
    kind: String,
    mass: Option<f64>,
    com: Option<[f64; 3]>,
    inertia: Option<InertiaSpec>,
    position: Option<[f64; 3]>,
    quaternion: Option<[f64; 4]>,
    v: Option<[f64; 3]>,
    omega: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPayload {
    /// Name of the body (link) that holds the payload; default the last body.
    body: Option<String>,
    mass: f64,
    com: [f64; 3],
    inertia: InertiaSpec,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEvent {
    #[serde(rename = "type")]
    kind: String,
    time: f64,
    body: Option<String>,
    mass: Option<f64>,
    com: Option<[f64; 3]>,
    inertia: Option<InertiaSpec>,
    v: Option<[f64; 3]>,
    omega: Option<[f64; 3]>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawEffects {
    gravity: Option<[f64; 3]>,
    damping: Option<Vec<f64>>,
    #[serde(default)]
    wrench: Vec<RawWrench>,
    rotor: Option<toml::Spanned<RawRotor>>,
    friction: Option<toml::Spanned<RawFriction>>,
    flexible: Option<toml::Spanned<flexible::RawFlexible>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRotor {
    inertia: Vec<f64>,
    gear_ratio: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFriction {
    viscous: Option<Vec<f64>>,
    coulomb: Option<Vec<f64>>,
    v_s: Option<f64>,
}

/// Default regularization speed of Coulomb friction, rad/s (or m/s for a prismatic joint).
pub const DEFAULT_V_S: f64 = 1e-3;

/// Motor rotor inertia reflected through a rigid gear: `I_m,i n_i²` added to `M_ii`.
#[derive(Clone, Debug, PartialEq)]
pub struct Rotor {
    /// Rotor inertia about its axis `I_m,i`, kg·m² (`>= 0`).
    pub inertia: Vec<f64>,
    /// Gear ratio `n_i` (motor turns per joint turn, `!= 0`).
    pub gear_ratio: Vec<f64>,
    /// `I_m,i n_i²`, kg·m².
    pub reflected: Vec<f64>,
}

/// Regularized Coulomb drive friction `τ_c,i tanh(q̇_i / v_s)`, subtracted from the drive
/// torque (the viscous part of `[effects] friction` is `damping`).
#[derive(Clone, Debug, PartialEq)]
pub struct Coulomb {
    /// Coulomb friction torques `τ_c,i`, N·m (`>= 0`).
    pub tau_c: Vec<f64>,
    /// Regularization speed `v_s > 0`.
    pub v_s: f64,
}

impl Coulomb {
    /// The friction torque of joint `i` at rate `qd` (`τ_c,i tanh(q̇ / v_s)`).
    #[must_use]
    pub fn torque(&self, i: usize, qd: f64) -> f64 {
        self.tau_c[i] * (qd * (1.0 / self.v_s)).tanh()
    }
}

/// 1-based line of byte offset `at` in `text` (the line of a `toml::Spanned` value).
#[must_use]
pub fn line_of(text: &str, at: usize) -> usize {
    text[..at.min(text.len())].matches('\n').count() + 1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWrench {
    body: String,
    frame: String,
    /// Sample times of a tabulated wrench (strictly increasing, s); absent for a constant one.
    time: Option<Vec<f64>>,
    force: Option<RawProfile>,
    moment: Option<RawProfile>,
}

/// One vector (constant wrench) or one row per sample time (tabulated wrench).
#[derive(Deserialize)]
#[serde(untagged)]
enum RawProfile {
    Constant([f64; 3]),
    Table(Vec<[f64; 3]>),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawGain {
    Scalar(f64),
    Vector(Vec<f64>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDrives {
    #[serde(rename = "type")]
    kind: String,
    kp: Option<RawGain>,
    kd: Option<RawGain>,
    target: Option<Vec<f64>>,
    duration_s: Option<f64>,
    tau: Option<Vec<f64>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawInitial {
    q: Option<Vec<f64>>,
    qd: Option<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSimulation {
    duration: f64,
    integrator: Option<String>,
    step: Option<f64>,
    tolerance: Option<f64>,
    max_step: Option<f64>,
    output_every: Option<usize>,
    algorithm: Option<String>,
    #[serde(default)]
    allow_long: bool,
}

/// The base of a scene.
// One value per scene: the size difference of the variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum BaseSpec {
    /// Fixed to the inertial frame.
    Fixed,
    /// Free-floating (see [`kanegen_dynamics::base`] for the conventions).
    FreeFloating {
        /// Mass properties of the base body (base frame).
        inertial: Inertial,
        /// Initial `p₀`.
        position: [f64; 3],
        /// Initial attitude, unit quaternion `[x, y, z, w]`.
        quaternion: [f64; 4],
        /// Initial `v_b` (base coordinates).
        v: [f64; 3],
        /// Initial `ω_b` (base coordinates).
        omega: [f64; 3],
    },
}

/// Joint drives.
#[derive(Clone, Debug)]
pub enum Drives {
    /// No drive torques.
    None,
    /// Constant joint torques/forces `τ`.
    Constant {
        /// The `N` drive values.
        tau: Vec<f64>,
    },
    /// `τ = kp (q_target − q) − kd q̇`.
    Pd {
        /// Proportional gains (`N`).
        kp: Vec<f64>,
        /// Derivative gains (`N`).
        kd: Vec<f64>,
        /// Target positions (`N`).
        target: Vec<f64>,
    },
    /// Computed torque along a quintic from the initial `q` to `target` over `duration`:
    /// `τ = ID(q, q̇, q̈_d + kd (q̇_d − q̇) + kp (q_d − q))` (fixed base only).
    ComputedTorque {
        /// Proportional gains (`N`).
        kp: Vec<f64>,
        /// Derivative gains (`N`).
        kd: Vec<f64>,
        /// Final positions (`N`).
        target: Vec<f64>,
        /// Duration of the quintic, s.
        duration: f64,
    },
}

/// The integrator of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Fixed-step RK4 with the scene's `step`.
    Rk4,
    /// Adaptive Dormand–Prince 5(4) with `rtol = atol = tolerance`.
    Dopri5,
    /// Fixed-step Lie-group implicit midpoint rule with the scene's `step` (long runs: bounded
    /// energy error, unit quaternion without projection; see `integrate::midpoint`).
    Midpoint,
    /// Adaptive Rodas4, the stiffly accurate L-stable Rosenbrock method (`integrator =
    /// "rosenbrock"`, `kanegen_runtime::ode::rosenbrock`) with `rtol = atol = tolerance`, for stiff scenes
    /// (flexible joints); its steps land on the output times.
    Rosenbrock,
}

impl Integrator {
    /// Whether the integrator adapts its step to `tolerance` (dopri5, rosenbrock).
    #[must_use]
    pub fn is_adaptive(self) -> bool {
        matches!(self, Integrator::Dopri5 | Integrator::Rosenbrock)
    }
}

/// The `[simulation]` table, validated.
#[derive(Clone, Debug)]
pub struct SimulationSpec {
    /// End time, s.
    pub duration: f64,
    /// The integrator.
    pub integrator: Integrator,
    /// RK4 and midpoint step; for dopri5 and rosenbrock the first step tried (default 0.01 s).
    pub step: f64,
    /// dopri5 and rosenbrock tolerance (default 1e-8).
    pub tolerance: f64,
    /// dopri5 and rosenbrock largest step (default: the duration).
    pub max_step: f64,
    /// Output every k-th RK4 or midpoint step; dopri5 samples its dense output every `output_every · step`
    /// seconds (default 10).
    pub output_every: usize,
    /// The dynamics algorithm evaluating `A`, `b` (default `recurrent` on a chain, `spatial` on
    /// a tree).
    pub algorithm: Methods,
    /// How the interpreted simulator solves for the accelerations: without
    /// `simulation.algorithm`, [`ForwardMethod::Aba`] (the run-time fast path: the
    /// articulated-body algorithm in a preallocated workspace, allocation-free, reflected rotor
    /// inertia as Pinocchio's armature); with a named algorithm, [`ForwardMethod::Ldlt`] (`A` and
    /// `b` by that algorithm, then LDLᵀ), so that a scene can compare the methods.
    pub forward: ForwardMethod,
    /// Whether more than [`MAX_STEPS`] steps or output samples were allowed
    /// (`allow_long = true`, or [`SceneOptions::allow_long`]).
    pub allow_long: bool,
}

/// Most steps (RK4, midpoint: `duration / step`) or output samples (every integrator:
/// `duration / (step · output_every)`) a scene may ask for without `allow_long = true` in
/// `[simulation]` (or `kanegen simulate --allow-long`): 1e8 steps of a 7-dof arm take about an
/// hour and 1e8 samples fill about 15 GB of CSV.
pub const MAX_STEPS: f64 = 1e8;

/// Even with `allow_long`, at most this many steps or samples (2⁵³: the step counter and `k·h`
/// stay exact).
pub const MAX_STEPS_LONG: f64 = 9_007_199_254_740_992.0;

/// Smallest dopri5 tolerance: below it the error estimate is dominated by the rounding error of
/// the state (`ε ≈ 2.2e-16` relative) and the step size shrinks until it underflows.
pub const MIN_TOLERANCE: f64 = 1e-14;

/// Options of [`Scene::load_with`] and [`Scene::parse_with`].
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneOptions {
    /// Allow more than [`MAX_STEPS`] steps or samples (as `allow_long = true` in the file).
    pub allow_long: bool,
}

/// How an external wrench varies in time.
#[derive(Clone, Debug, PartialEq)]
pub enum WrenchProfile {
    /// The same force and moment at all times.
    Constant {
        /// Force, N.
        force: [f64; 3],
        /// Moment, N·m.
        moment: [f64; 3],
    },
    /// Samples `(time[k], force[k], moment[k])`, interpolated linearly between samples and held
    /// at the first (last) sample before (after) the table.
    Table {
        /// Strictly increasing sample times, s (at least two).
        time: Vec<f64>,
        /// Force at each sample time, N.
        force: Vec<[f64; 3]>,
        /// Moment at each sample time, N·m.
        moment: Vec<[f64; 3]>,
    },
}

/// An external wrench of a scene: where it acts, in which frame, and its time profile.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneWrench {
    /// Body index (joint index of the body's inboard joint), or [`BASE_BODY`].
    pub body: usize,
    /// Frame of the force and moment vectors.
    pub frame: LoadFrame,
    /// Constant or tabulated.
    pub profile: WrenchProfile,
}

impl SceneWrench {
    /// Whether the wrench varies in time (a runtime input of the dynamics, not a constant).
    #[must_use]
    pub fn is_tabulated(&self) -> bool {
        matches!(self.profile, WrenchProfile::Table { .. })
    }

    /// Force and moment at time `t`.
    #[must_use]
    pub fn value_at(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        match &self.profile {
            WrenchProfile::Constant { force, moment } => (*force, *moment),
            WrenchProfile::Table {
                time,
                force,
                moment,
            } => kanegen_runtime::ode::table(t, time, force, moment),
        }
    }

    /// The wrench at time `t` as a load of the dynamics.
    #[must_use]
    pub fn at(&self, t: f64) -> ExternalWrench<f64> {
        let (force, moment) = self.value_at(t);
        ExternalWrench {
            body: self.body,
            frame: self.frame,
            force: Vec3::from_f64(force),
            moment: Vec3::from_f64(moment),
        }
    }
}

/// Validates `[[effects.wrench]]` number `key`'s force/moment profiles against its `time`.
fn wrench_profile(
    key: &str,
    time: Option<Vec<f64>>,
    force: Option<RawProfile>,
    moment: Option<RawProfile>,
) -> Result<WrenchProfile> {
    let Some(time) = time else {
        let constant = |name: &str, p: Option<RawProfile>| match p {
            None => Ok([0.0; 3]),
            Some(RawProfile::Constant(v)) => {
                check_bound(&format!("{key}.{name}"), &v, FORCE)?;
                Ok(v)
            }
            Some(RawProfile::Table(_)) => Err(invalid!(
                "{key}.{name}: one row per sample needs `{key}.time` (or give one vector [x, y, z])"
            )),
        };
        return Ok(WrenchProfile::Constant {
            force: constant("force", force)?,
            moment: constant("moment", moment)?,
        });
    };
    let tkey = format!("{key}.time");
    if time.len() < 2 {
        bail!("{tkey}: a table needs at least 2 sample times");
    }
    check_finite(&tkey, &time)?;
    if let Some(k) = time.windows(2).position(|w| w[1] <= w[0]) {
        bail!(
            "{tkey}: sample times must be strictly increasing (time[{}] = {} after {})",
            k + 1,
            time[k + 1],
            time[k]
        );
    }
    let rows = |name: &str, p: Option<RawProfile>| -> Result<Vec<[f64; 3]>> {
        let k = format!("{key}.{name}");
        match p {
            None => Ok(vec![[0.0; 3]; time.len()]),
            Some(RawProfile::Constant(_)) => Err(invalid!(
                "{k}: with `{tkey}` give one [x, y, z] row per sample time ({} rows)",
                time.len()
            )),
            Some(RawProfile::Table(v)) => {
                if v.len() != time.len() {
                    bail!(
                        "{k}: expected {} rows (one per sample time), got {}",
                        time.len(),
                        v.len()
                    );
                }
                check_bound(&k, v.as_flattened(), FORCE)?;
                Ok(v)
            }
        }
    };
    if force.is_none() && moment.is_none() {
        bail!("{key}: a tabulated wrench needs `force` or `moment` rows");
    }
    Ok(WrenchProfile::Table {
        force: rows("force", force)?,
        moment: rows("moment", moment)?,
        time,
    })
}

/// What happens at a scene event (`[[events]]`).
#[derive(Clone, Debug, PartialEq)]
pub enum EventKind {
    /// A free payload is captured by a body: perfectly plastic, it moves with the body from the
    /// event on.
    Capture {
        /// The payload's mass properties in the capturing body's frame (like `[payload]`).
        payload: Inertial,
        /// Velocity of the payload's centre of mass just before the capture, inertial frame.
        v: [f64; 3],
        /// Angular velocity of the payload just before the capture, inertial frame.
        omega: [f64; 3],
    },
    /// A payload the body holds (the static `[payload]` or a captured one) is let go with the
    /// body's velocity; it then flies ballistically.
    Release {
        /// The payload's mass properties in the body's frame.
        payload: Inertial,
    },
}

/// A payload capture or release at a given time (free-floating base only), see
/// `simulate::SceneSystem::apply_event`.
#[derive(Clone, Debug)]
pub struct Event {
    /// Event time, s (`0 < time < duration`, strictly increasing over the events).
    pub time: f64,
    /// The body that captures or releases (joint index of its inboard joint).
    pub body: usize,
    /// Capture or release.
    pub kind: EventKind,
    /// The model from the event on (payloads held then merged into their bodies).
    pub model: Model,
}

/// A validated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The arm, with the payload (if any) merged into the body that holds it (default the last).
    pub model: Model,
    /// Fixed or free-floating base.
    pub base: BaseSpec,
    /// Uniform gravity (base frame for a fixed base, inertial frame for a free-floating one).
    pub gravity: Option<[f64; 3]>,
    /// Joint viscous damping coefficients: `τ_d = −c q̇`.
    pub damping: Option<Vec<f64>>,
    /// External wrenches, constant or tabulated in time ([`BASE_BODY`] for the free-floating base
    /// body).
    pub wrenches: Vec<SceneWrench>,
    /// Reflected rotor inertia (`[effects] rotor`): the armature model, on a fixed or a
    /// free-floating base.
    pub rotor: Option<Rotor>,
    /// Regularized Coulomb drive friction (`[effects] friction.coulomb`).
    pub coulomb: Option<Coulomb>,
    /// Flexible joints (`[effects] flexible`, Spong 1987), fixed base only: the state gains the
    /// motor positions and rates, and the drives, damping and friction act on the motors.
    pub flexible: Option<flexible::Flexible>,
    /// The joint drives.
    pub drives: Drives,
    /// Initial joint positions.
    pub q0: Vec<f64>,
    /// Initial joint rates.
    pub qd0: Vec<f64>,
    /// Integrator settings.
    pub simulation: SimulationSpec,
    /// Payload captures and releases (`[[events]]`), in time order; empty when the scene has
    /// none.
    pub events: Vec<Event>,
}

/// One value per coordinate of the model (`n`), within the bound `b`.
fn check_len(key: &str, v: &[f64], n: Coordinates<'_>, b: Bound) -> Result<()> {
    if v.len() != n.len() {
        return Err(n.wrong_count(key, v.len()));
    }
    check_bound(key, v, b)
}

fn check_finite(key: &str, v: &[f64]) -> Result<()> {
    if v.iter().any(|x| !x.is_finite()) {
        bail!("{key}: values must be finite");
    }
    Ok(())
}

/// Finite and within the magnitude bound `b` ([`kanegen_model::bounds`]).
fn check_bound(key: &str, v: &[f64], b: Bound) -> Result<()> {
    b.check(v).map_err(|e| invalid!("{key}: {e}"))
}

fn gain(key: &str, g: Option<RawGain>, n: Coordinates<'_>) -> Result<Vec<f64>> {
    let v = match g.ok_or_else(|| invalid!("{key}: required by this drive type"))? {
        RawGain::Scalar(x) => vec![x; n.len()],
        RawGain::Vector(v) => {
            check_len(key, &v, n, GAIN)?;
            v
        }
    };
    if v.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
        bail!("{key}: gains must be finite and >= 0");
    }
    check_bound(key, &v, GAIN)?;
    Ok(v)
}

/// The index of the moving body `name` (the joint whose outboard body it is).
fn body_index(chain: &Model, name: &str) -> Option<usize> {
    chain.joints().iter().position(|j| j.body == name)
}

/// The moving bodies' names, comma-separated (error messages).
fn body_names(chain: &Model) -> String {
    let names: Vec<&str> = chain.joints().iter().map(|j| j.body.as_str()).collect();
    names.join(", ")
}

/// `chain` with each payload `(body, inertial)` merged into its body, in order.
fn with_payloads(
    chain: &Model,
    payloads: &[(usize, Inertial)],
    validation: Validation,
) -> Result<Model> {
    if payloads.is_empty() {
        return Ok(chain.clone());
    }
    let mut joints = chain.joints().to_vec();
    for (body, pay) in payloads {
        joints[*body].inertial = joints[*body].inertial.merge(pay);
    }
    Model::new_with(
        chain.name(),
        chain.base(),
        chain.base_inertial().cloned(),
        joints,
        validation,
    )
    .and_then(|m| m.with_mimics(chain.mimics().to_vec()))
    .map_err(|e| invalid!("{e}"))
}

/// Validates `[[events]]` (times inside the run and increasing, known bodies, positive mass, a
/// physical inertia, a release only of a payload the body holds) and builds the model after each.
fn parse_events(
    raw: Vec<toml::Spanned<RawEvent>>,
    text: &str,
    chain0: &Model,
    mut attached: Vec<(usize, Inertial)>,
    floating: bool,
    duration: f64,
    validation: Validation,
) -> Result<Vec<Event>> {
    let mut events: Vec<Event> = Vec::new();
    for (k, e) in raw.into_iter().enumerate() {
        let line = line_of(text, e.span().start);
        let e = e.into_inner();
        let key = |f: &str| format!("events[{k}].{f} (line {line})");
        if !floating {
            bail!(
                "events[{k}] (line {line}): payload capture and release need a free-floating \
                 base (base.type = \"free-floating\"), where the impulse conserves momentum"
            );
        }
        if chain0.has_mimics() {
            bail!(
                "events[{k}] (line {line}): payload capture and release are not supported on \
                 a model with mimic joints"
            );
        }
        if !(e.time.is_finite() && e.time > 0.0 && e.time < duration) {
            bail!(
                "{}: must be inside the run (0 < time < simulation.duration = {duration})",
                key("time")
            );
        }
        if let Some(prev) = events.last() {
            if e.time <= prev.time {
                bail!(
                    "{}: events must be in strictly increasing time order ({} after {})",
                    key("time"),
                    e.time,
                    prev.time
                );
            }
        }
        let body = match &e.body {
            None => None,
            Some(name) => Some(body_index(chain0, name).ok_or_else(|| {
                invalid!(
                    "{}: unknown body `{name}` (moving bodies: {})",
                    key("body"),
                    body_names(chain0)
                )
            })?),
        };
        let kind = match e.kind.as_str() {
            "capture" => {
                let mass = e
                    .mass
                    .ok_or_else(|| invalid!("{}: required", key("mass")))?;
                if !(mass.is_finite() && mass > 0.0) {
                    bail!("{}: must be > 0", key("mass"));
                }
                let com = e.com.unwrap_or([0.0; 3]);
                check_bound(&key("com"), &com, LENGTH)?;
                let inertia = e
                    .inertia
                    .ok_or_else(|| invalid!("{}: required", key("inertia")))?
                    .0;
                let payload = Inertial { mass, com, inertia };
                kanegen_model::validate_inertial_with("payload", "inertia", &payload, validation)
                    .map_err(|err| invalid!("{}: {err}", key("inertia")))?;
                let v = e.v.unwrap_or([0.0; 3]);
                let omega = e.omega.unwrap_or([0.0; 3]);
                check_bound(&key("v"), &v, RATE)?;
                check_bound(&key("omega"), &omega, RATE)?;
                let body = body.unwrap_or(chain0.dof() - 1);
                attached.push((body, payload.clone()));
                (body, EventKind::Capture { payload, v, omega })
            }
            "release" => {
                for (f, given) in [
                    ("mass", e.mass.is_some()),
                    ("com", e.com.is_some()),
                    ("inertia", e.inertia.is_some()),
                    ("v", e.v.is_some()),
                    ("omega", e.omega.is_some()),
                ] {
                    if given {
                        bail!(
                            "{}: not used by a release (it lets go of the payload the body holds)",
                            key(f)
                        );
                    }
                }
                let at = attached
                    .iter()
                    .rposition(|(b, _)| body.is_none_or(|bb| bb == *b))
                    .ok_or_else(|| {
                        invalid!(
                            "{}: no payload held then (give a [payload] or capture one first)",
                            key("body")
                        )
                    })?;
                let (body, payload) = attached.remove(at);
                (body, EventKind::Release { payload })
            }
            other => bail!(
                "{}: unknown event type `{other}` (expected \"capture\" or \"release\")",
                key("type")
            ),
        };
        let model = with_payloads(chain0, &attached, validation)
            .map_err(|err| invalid!("events[{k}] (line {line}): {err}"))?;
        events.push(Event {
            time: e.time,
            body: kind.0,
            kind: kind.1,
            model,
        });
    }
    Ok(events)
}

/// The scene's model at `model_path`: loaded, its forward dynamics defined (errors name the
/// model file). With mimic joints the scene runs in the model's coordinates, the joints that
/// follow none ([`Model::coordinates`]).
fn load_chain(model_path: &Path, validation: Validation) -> Result<Model> {
    let chain = kanegen_model::io::load_model_with(model_path, validation)
        .map_err(|e| invalid!("model: `{}`: {e}", model_path.display()))?;
    chain
        .check_forward_dynamics()
        .map_err(|e| invalid!("model: `{}`: {e}", model_path.display()))?;
    Ok(chain)
}

/// `[payload]`: its holding body (the last by default) and its validated inertial.
fn parse_payload(
    raw: Option<RawPayload>,
    chain0: &Model,
    validation: Validation,
) -> Result<Option<(usize, Inertial)>> {
    let Some(p) = raw else {
        return Ok(None);
    };
    if !(p.mass.is_finite() && p.mass > 0.0) {
        bail!("payload.mass: must be > 0");
    }
    check_bound("payload.com", &p.com, LENGTH)?;
    let pay = Inertial {
        mass: p.mass,
        com: p.com,
        inertia: p.inertia.0,
    };
    kanegen_model::validate_inertial_with("payload", "inertia", &pay, validation)
        .map_err(|e| invalid!("payload.inertia: {e}"))?;
    let holder = match &p.body {
        None => chain0.dof() - 1,
        Some(name) => body_index(chain0, name).ok_or_else(|| {
            invalid!(
                "payload.body: unknown body `{name}` (moving bodies: {})",
                body_names(chain0)
            )
        })?,
    };
    Ok(Some((holder, pay)))
}

/// `[base]`: fixed (no other keys), or free-floating with its inertial (the model's base
/// inertial by default), its normalized attitude and its initial position and velocity.
fn parse_base(raw: Option<RawBase>, chain: &Model, validation: Validation) -> Result<BaseSpec> {
    let Some(b) = raw else {
        return Ok(BaseSpec::Fixed);
    };
    match b.kind.as_str() {
        "fixed" => {
            let given = [
                ("mass", b.mass.is_some()),
                ("com", b.com.is_some()),
                ("inertia", b.inertia.is_some()),
                ("position", b.position.is_some()),
                ("quaternion", b.quaternion.is_some()),
                ("v", b.v.is_some()),
                ("omega", b.omega.is_some()),
            ];
            if let Some((k, _)) = given.iter().find(|(_, g)| *g) {
                bail!("base.{k}: only for type = \"free-floating\"");
            }
            Ok(BaseSpec::Fixed)
        }
        "free-floating" => parse_floating_base(b, chain, validation),
        other => bail!(
            "base.type: unknown base type `{other}` (expected \"fixed\" or \"free-floating\")"
        ),
    }
}

/// The free-floating `[base]` of [`parse_base`].
fn parse_floating_base(b: RawBase, chain: &Model, validation: Validation) -> Result<BaseSpec> {
    let model = chain.base_inertial();
    let mass = b.mass.or(model.map(|i| i.mass)).ok_or_else(|| {
        invalid!("base.mass: the model has no base inertial; give mass, com, inertia")
    })?;
    let com = b.com.or(model.map(|i| i.com)).unwrap_or([0.0; 3]);
    let inertia = b
        .inertia
        .map(|i| i.0)
        .or(model.map(|i| i.inertia))
        .ok_or_else(|| invalid!("base.inertia: the model has no base inertial"))?;
    if !(mass.is_finite() && mass > 0.0) {
        bail!("base.mass: must be > 0");
    }
    check_bound("base.com", &com, LENGTH)?;
    let inertial = Inertial { mass, com, inertia };
    kanegen_model::validate_inertial_with("base", "inertia", &inertial, validation)
        .map_err(|e| invalid!("base.inertia: {e}"))?;
    let quat = b.quaternion.unwrap_or([0.0, 0.0, 0.0, 1.0]);
    check_finite("base.quaternion", &quat)?;
    // Scaled by its largest entry first, so that entries near f64's range normalize instead of
    // overflowing the sum of squares.
    let scale = quat.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let unit_scaled = quat.map(|x| if scale > 0.0 { x / scale } else { 0.0 });
    let norm_scaled = unit_scaled.iter().map(|x| x * x).sum::<f64>().sqrt();
    if scale * norm_scaled < 1e-12 {
        bail!("base.quaternion: must be non-zero");
    }
    let position = b.position.unwrap_or([0.0; 3]);
    let v = b.v.unwrap_or([0.0; 3]);
    let omega = b.omega.unwrap_or([0.0; 3]);
    check_bound("base.position", &position, LENGTH)?;
    check_bound("base.v", &v, RATE)?;
    check_bound("base.omega", &omega, RATE)?;
    Ok(BaseSpec::FreeFloating {
        inertial,
        position,
        quaternion: unit_scaled.map(|x| x / norm_scaled),
        v,
        omega,
    })
}

/// `[[effects.wrench]]`: each on a known body (the base only when it floats), in its body's
/// or the inertial frame, with its profile.
fn parse_wrenches(raw: Vec<RawWrench>, chain: &Model, floating: bool) -> Result<Vec<SceneWrench>> {
    let mut wrenches = Vec::new();
    for (k, w) in raw.into_iter().enumerate() {
        let key = format!("effects.wrench[{k}]");
        let body = if w.body == "base" || w.body == chain.base() {
            if !floating {
                bail!("{key}.body: a wrench on a fixed base has no effect");
            }
            BASE_BODY
        } else {
            body_index(chain, &w.body).ok_or_else(|| {
                invalid!(
                    "{key}.body: unknown body `{}` (known: base, {})",
                    w.body,
                    body_names(chain)
                )
            })?
        };
        let frame = match w.frame.as_str() {
            "body" => LoadFrame::Body,
            "inertial" => LoadFrame::Base,
            other => bail!("{key}.frame: unknown frame `{other}` (expected body or inertial)"),
        };
        wrenches.push(SceneWrench {
            body,
            frame,
            profile: wrench_profile(&key, w.time, w.force, w.moment)?,
        });
    }
    Ok(wrenches)
}

/// `[effects.rotor]`: rotor inertias and gear ratios, `N` each, and the reflected inertia.
fn parse_rotor(
    raw: Option<toml::Spanned<RawRotor>>,
    text: &str,
    n: Coordinates<'_>,
) -> Result<Option<Rotor>> {
    let Some(r) = raw else {
        return Ok(None);
    };
    let line = line_of(text, r.span().start);
    let r = r.into_inner();
    let key = |k: &str| format!("effects.rotor.{k} (line {line})");
    check_len(&key("inertia"), &r.inertia, n, GAIN)?;
    check_len(&key("gear_ratio"), &r.gear_ratio, n, GAIN)?;
    if r.inertia.iter().any(|x| *x < 0.0) {
        bail!("{}: must be >= 0", key("inertia"));
    }
    if r.gear_ratio.contains(&0.0) {
        bail!("{}: must be non-zero", key("gear_ratio"));
    }
    let reflected: Vec<f64> = r
        .inertia
        .iter()
        .zip(&r.gear_ratio)
        .map(|(i, g)| i * g * g)
        .collect();
    check_bound(&key("inertia"), &reflected, GAIN)?;
    Ok(Some(Rotor {
        inertia: r.inertia,
        gear_ratio: r.gear_ratio,
        reflected,
    }))
}

/// `[effects.friction]`: its viscous part becomes `damping` (given once), its Coulomb part
/// the returned friction.
fn parse_friction(
    raw: Option<toml::Spanned<RawFriction>>,
    text: &str,
    n: Coordinates<'_>,
    damping: &mut Option<Vec<f64>>,
) -> Result<Option<Coulomb>> {
    let Some(f) = raw else {
        return Ok(None);
    };
    let line = line_of(text, f.span().start);
    let f = f.into_inner();
    let key = |k: &str| format!("effects.friction.{k} (line {line})");
    if f.viscous.is_none() && f.coulomb.is_none() {
        bail!("effects.friction (line {line}): give `viscous` and/or `coulomb` coefficients");
    }
    if let Some(b) = f.viscous {
        if damping.is_some() {
            bail!(
                "{}: viscous friction is `effects.damping`; give it once",
                key("viscous")
            );
        }
        check_len(&key("viscous"), &b, n, GAIN)?;
        if b.iter().any(|x| *x < 0.0) {
            bail!("{}: coefficients must be >= 0", key("viscous"));
        }
        *damping = Some(b);
    }
    let Some(c) = f.coulomb else {
        if f.v_s.is_some() {
            bail!("{}: only with `coulomb`", key("v_s"));
        }
        return Ok(None);
    };
    check_len(&key("coulomb"), &c, n, FORCE)?;
    if c.iter().any(|x| *x < 0.0) {
        bail!("{}: friction torques must be >= 0", key("coulomb"));
    }
    let v_s = f.v_s.unwrap_or(DEFAULT_V_S);
    if !(v_s.is_finite() && v_s > 0.0) {
        bail!("{}: must be > 0", key("v_s"));
    }
    Ok(Some(Coulomb { tau_c: c, v_s }))
}

/// `[effects.flexible]`: Spong's flexible joints, on a fixed base and without `[effects.rotor]`.
fn parse_flexible(
    raw: Option<toml::Spanned<flexible::RawFlexible>>,
    text: &str,
    n: Coordinates<'_>,
    floating: bool,
    rotor: bool,
) -> Result<Option<flexible::Flexible>> {
    let Some(f) = raw else {
        return Ok(None);
    };
    let line = line_of(text, f.span().start);
    if floating {
        bail!(
            "effects.flexible (line {line}): flexible joints are supported on a fixed \
             base only"
        );
    }
    if rotor {
        bail!(
            "effects.flexible (line {line}): `motor_inertia` and `gear_ratio` give the \
             motor inertia of a flexible joint; `effects.rotor` (the rigid-gear \
             model) cannot be given with it"
        );
    }
    Ok(Some(flexible::Flexible::from_raw(f.into_inner(), n, line)?))
}

/// `[drives]`: the keys its type uses (and no other), validated.
fn parse_drives(raw: Option<RawDrives>, n: Coordinates<'_>, floating: bool) -> Result<Drives> {
    let Some(d) = raw else {
        return Ok(Drives::None);
    };
    let extra = |keys: &[(&str, bool)]| -> Result<()> {
        if let Some((k, _)) = keys.iter().find(|(_, g)| *g) {
            bail!("drives.{k}: not used by drives.type = \"{}\"", d.kind);
        }
        Ok(())
    };
    match d.kind.as_str() {
        "none" => {
            extra(&[
                ("kp", d.kp.is_some()),
                ("kd", d.kd.is_some()),
                ("target", d.target.is_some()),
                ("duration_s", d.duration_s.is_some()),
                ("tau", d.tau.is_some()),
            ])?;
            Ok(Drives::None)
        }
        "constant" => {
            extra(&[
                ("kp", d.kp.is_some()),
                ("kd", d.kd.is_some()),
                ("target", d.target.is_some()),
                ("duration_s", d.duration_s.is_some()),
            ])?;
            let tau = d
                .tau
                .ok_or_else(|| invalid!("drives.tau: required by type = \"constant\""))?;
            check_len("drives.tau", &tau, n, FORCE)?;
            Ok(Drives::Constant { tau })
        }
        "pd" => {
            extra(&[("duration_s", d.duration_s.is_some()), ("tau", d.tau.is_some())])?;
            let target = d
                .target
                .ok_or_else(|| invalid!("drives.target: required by type = \"pd\""))?;
            check_len("drives.target", &target, n, POSITION)?;
            Ok(Drives::Pd {
                kp: gain("drives.kp", d.kp, n)?,
                kd: gain("drives.kd", d.kd, n)?,
                target,
            })
        }
        "computed-torque" => {
            extra(&[("tau", d.tau.is_some())])?;
            if floating {
                bail!("drives.type: computed-torque needs a fixed base");
            }
            let target = d.target.ok_or_else(|| {
                invalid!("drives.target: required by type = \"computed-torque\"")
            })?;
            check_len("drives.target", &target, n, POSITION)?;
            let duration = d.duration_s.ok_or_else(|| {
                invalid!("drives.duration_s: required by type = \"computed-torque\"")
            })?;
            if !(duration.is_finite() && duration > 0.0) {
                bail!("drives.duration_s: must be > 0");
            }
            Ok(Drives::ComputedTorque {
                kp: gain("drives.kp", d.kp, n)?,
                kd: gain("drives.kd", d.kd, n)?,
                target,
                duration,
            })
        }
        other => bail!(
            "drives.type: unknown drive type `{other}` (expected none, constant, pd or computed-torque)"
        ),
    }
}

/// `[simulation]`: the integrator and its settings, the step and sample limits, and the
/// algorithm (the model's default, or the one named, which a tree must allow).
fn parse_simulation(
    s: RawSimulation,
    chain: &Model,
    options: SceneOptions,
) -> Result<SimulationSpec> {
    if !(s.duration.is_finite() && s.duration > 0.0) {
        bail!("simulation.duration: must be > 0");
    }
    let integrator = match s.integrator.as_deref().unwrap_or("rk4") {
        "rk4" => Integrator::Rk4,
        "dopri5" => Integrator::Dopri5,
        "midpoint" => Integrator::Midpoint,
        "rosenbrock" => Integrator::Rosenbrock,
        other => {
            bail!(
                "simulation.integrator: unknown integrator `{other}` \
                 (expected rk4, dopri5, midpoint or rosenbrock)"
            )
        }
    };
    let step = s.step.unwrap_or(0.01);
    if !(step.is_finite() && step > 0.0) {
        bail!("simulation.step: must be > 0");
    }
    let tolerance = s.tolerance.unwrap_or(1e-8);
    if !(tolerance.is_finite() && tolerance > 0.0) {
        bail!("simulation.tolerance: must be > 0");
    }
    if tolerance < MIN_TOLERANCE {
        bail!(
            "simulation.tolerance: {tolerance:e} is below {MIN_TOLERANCE:e}: the error \
             estimate would be dominated by the rounding error of the state (2.2e-16 \
             relative) and the step size would shrink until it underflows"
        );
    }
    let max_step = s.max_step.unwrap_or(s.duration);
    if !(max_step.is_finite() && max_step > 0.0) {
        bail!("simulation.max_step: must be > 0");
    }
    let output_every = s.output_every.unwrap_or(10);
    if output_every == 0 {
        bail!("simulation.output_every: must be >= 1");
    }
    let allow_long = s.allow_long || options.allow_long;
    check_run_length(&s, integrator, step, output_every, allow_long)?;
    let (algorithm, forward) = parse_algorithm(s.algorithm, chain)?;
    if !integrator.is_adaptive() {
        if s.tolerance.is_some() {
            bail!("simulation.tolerance: only for integrator = \"dopri5\" or \"rosenbrock\"");
        }
        if s.max_step.is_some() {
            bail!("simulation.max_step: only for integrator = \"dopri5\" or \"rosenbrock\"");
        }
    }
    Ok(SimulationSpec {
        duration: s.duration,
        integrator,
        step,
        tolerance,
        max_step,
        output_every,
        algorithm,
        forward,
        allow_long,
    })
}

/// The steps (fixed-step integrators) and output samples of `[simulation]` within
/// [`MAX_STEPS`], or [`MAX_STEPS_LONG`] when `allow_long`.
fn check_run_length(
    s: &RawSimulation,
    integrator: Integrator,
    step: f64,
    output_every: usize,
    allow_long: bool,
) -> Result<()> {
    let limit = if allow_long {
        MAX_STEPS_LONG
    } else {
        MAX_STEPS
    };
    let hint = if allow_long {
        ""
    } else {
        " (set allow_long = true in [simulation], or pass --allow-long, to run it)"
    };
    let samples = s.duration / (step * output_every as f64);
    if !integrator.is_adaptive() && s.duration / step > limit {
        bail!(
            "simulation.step: duration / step = {:.3e} steps exceeds the limit {limit:.0e}{hint}",
            s.duration / step
        );
    }
    if samples > limit {
        bail!(
            "simulation.output_every: duration / (step · output_every) = {samples:.3e} output \
             samples exceeds the limit {limit:.0e}{hint}"
        );
    }
    Ok(())
}

/// `simulation.algorithm`: the algorithm and the forward method it selects (none named: the
/// articulated-body algorithm, the recurrent methods on a chain and the spatial ones on a
/// tree; a named one runs on LDLᵀ and must handle the model's topology).
fn parse_algorithm(name: Option<String>, chain: &Model) -> Result<(Methods, ForwardMethod)> {
    // The paper's algorithms handle serial chains; a tree takes the local-frame ones.
    let forward = if name.is_some() {
        ForwardMethod::Ldlt
    } else {
        ForwardMethod::Aba
    };
    let algorithm = match name {
        None if chain.is_chain() => Methods::RECURRENT,
        None => Methods::SPATIAL,
        Some(a) => Methods::from_name(&a).ok_or_else(|| {
            let names: Vec<&str> = Methods::PRESETS.iter().map(|(n, _)| *n).collect();
            invalid!(
                "simulation.algorithm: unknown algorithm `{a}` (known: {})",
                names.join(", ")
            )
        })?,
    };
    if let Some(j) = chain.first_branch() {
        if algorithm != Methods::SPATIAL {
            bail!(
                "simulation.algorithm: `{algorithm}` handles serial chains only, and the \
                 model is a tree (joint `{}` does not hang from the joint before it): use \
                 \"spatial\"",
                j.name
            );
        }
    }
    Ok((algorithm, forward))
}

impl Scene {
    /// Reads and validates a scene file; the model path is relative to the file's directory.
    pub fn load(path: &Path) -> Result<Scene> {
        Scene::load_with(path, SceneOptions::default())
    }

    /// [`Scene::load`] with options.
    pub fn load_with(path: &Path, options: SceneOptions) -> Result<Scene> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Scene::parse_with(&text, dir, options).map_err(|e| SceneError::InFile {
            path: path.to_path_buf(),
            source: Box::new(e),
        })
    }

    /// The model file a scene names (relative to `dir`), without validating the rest.
    #[must_use]
    pub fn model_path(text: &str, dir: &Path) -> Option<std::path::PathBuf> {
        let t: toml::Table = text.parse().ok()?;
        Some(dir.join(t.get("model")?.as_str()?))
    }

    /// Parses and validates scene text; `dir` is the directory the model path is relative to.
    pub fn parse(text: &str, dir: &Path) -> Result<Scene> {
        Scene::parse_with(text, dir, SceneOptions::default())
    }

    /// [`Scene::parse`] with options.
    pub fn parse_with(text: &str, dir: &Path, options: SceneOptions) -> Result<Scene> {
        let raw: RawScene = toml::from_str(text).map_err(|e| invalid!("{e}"))?;
        let validation = Validation {
            allow_nonphysical_inertia: raw.allow_nonphysical,
        };
        let chain0 = load_chain(&dir.join(&raw.model), validation)?;
        let n = Coordinates(&chain0);
        let attached: Vec<(usize, Inertial)> = parse_payload(raw.payload, &chain0, validation)?
            .into_iter()
            .collect();
        let chain =
            with_payloads(&chain0, &attached, validation).map_err(|e| invalid!("payload: {e}"))?;
        let base = parse_base(raw.base, &chain, validation)?;
        let floating = matches!(base, BaseSpec::FreeFloating { .. });
        let e = raw.effects;
        if let Some(g) = &e.gravity {
            check_bound("effects.gravity", g, GRAVITY)?;
        }
        if let Some(c) = &e.damping {
            check_len("effects.damping", c, n, GAIN)?;
            if c.iter().any(|x| *x < 0.0) {
                bail!("effects.damping: coefficients must be >= 0");
            }
        }
        let wrenches = parse_wrenches(e.wrench, &chain, floating)?;
        let mut damping = e.damping;
        let rotor = parse_rotor(e.rotor, text, n)?;
        let coulomb = parse_friction(e.friction, text, n, &mut damping)?;
        let flexible = parse_flexible(e.flexible, text, n, floating, rotor.is_some())?;
        let q0 = raw.initial.q.unwrap_or_else(|| vec![0.0; n.len()]);
        check_len("initial.q", &q0, n, POSITION)?;
        let qd0 = raw.initial.qd.unwrap_or_else(|| vec![0.0; n.len()]);
        check_len("initial.qd", &qd0, n, RATE)?;
        let drives = parse_drives(raw.drives, n, floating)?;
        let simulation = parse_simulation(raw.simulation, &chain, options)?;
        let events = parse_events(
            raw.events,
            text,
            &chain0,
            attached,
            floating,
            simulation.duration,
            validation,
        )?;
        Ok(Scene {
            events,
            model: chain,
            base,
            gravity: e.gravity,
            damping,
            wrenches,
            rotor,
            coulomb,
            flexible,
            drives,
            q0,
            qd0,
            simulation,
        })
    }

    /// The joint degrees of freedom of the state: the model's coordinates, its joints without
    /// the mimic joints (a mimic joint moves with the joint it follows).
    #[must_use]
    pub fn dof(&self) -> usize {
        self.model.coordinate_count()
    }

    /// The names of the joints of the state, in its order ([`Scene::dof`] of them).
    #[must_use]
    pub fn coordinate_names(&self) -> Vec<&str> {
        let joints = self.model.joints();
        let coordinates = self.model.coordinates();
        coordinates
            .into_iter()
            .map(|j| joints[j].name.as_str())
            .collect()
    }

    /// Whether the base is free-floating.
    #[must_use]
    pub fn is_floating(&self) -> bool {
        matches!(self.base, BaseSpec::FreeFloating { .. })
    }
}
