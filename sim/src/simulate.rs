//! Running a [`Scene`]: the scene as a first-order [`System`], integration, conservation
//! monitors, and the trajectory as CSV (the CLI writes it with the summary and plots).
//!
//! State vector: fixed base `[q (N), q̇ (N)]`; free-floating base
//! `[p₀ (3), quat (4: x, y, z, w), q (N), v_b (3), ω_b (3), q̇ (N)]` with `ṗ₀ = R₀ v_b` and
//! `q̇uat = ½ quat ⊗ (ω_b, 0)` (body-frame `ω_b`); with flexible joints (fixed base)
//! `[q (N), q̇ (N), θ (N), θ̇ (N)]`, the motor coordinates last ([`crate::flexible`]). RK4,
//! dopri5 and rosenbrock renormalize the quaternion after every accepted step
//! ([`System::project`]); the implicit midpoint rule updates it by the exponential map
//! ([`System::advance`]) and needs no projection.

use crate::events::{self, CaptureSystem, EventReport};
use crate::scene::{
    BaseSpec, Drives, Event, EventKind, Integrator, Scene, SceneWrench, SimulationSpec,
};
use crate::singularity;
use anyhow::Result;
use kanegen_dynamics::algorithms::aba::{self, Workspace};
use kanegen_dynamics::algorithms::floating::{self, kinetic_energy, momentum};
use kanegen_dynamics::algorithms::frames;
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::{ForwardMethod, FrameParams, Loads, Params};
use kanegen_runtime::ode::{
    self, quaternion, Dopri5Options, Rk4Options, Stats, Stop, System, VecScratch,
};
use serde::Serialize;
use std::cell::{Cell, RefCell};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};

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

/// A scene as a first-order system for the integrators.
pub struct SceneSystem<'a> {
    scene: &'a Scene,
    params: Params<f64>,
    base: Option<FloatingBase<f64>>,
    /// Loads without `tau` (gravity and constant wrenches, as the scene names them).
    passive: Loads<f64>,
    /// Whether some wrench is tabulated in time (then `deriv` evaluates the wrenches at `t`).
    time_varying: bool,
    n: usize,
    /// Set (by a Ctrl-C handler) to stop the run at the next step.
    stop: Option<&'a AtomicBool>,
    /// The run-time fast path ([`crate::scene::SimulationSpec::forward`] is
    /// [`ForwardMethod::Aba`]): the workspace of the articulated-body algorithm, and the loads
    /// and the accelerations of `deriv`, allocated once.
    fast: Option<FastPath>,
}

/// The preallocated data of the run-time fast path.
struct FastPath {
    ws: Workspace<f64>,
    /// The passive loads with `tau = Some(N zeros)`: `deriv` writes the torques and, when
    /// tabulated, the wrenches in place.
    loads: Loads<f64>,
    /// `q̈` (fixed base) or `ν̇` (free-floating).
    acc: Vec<f64>,
}

/// The desired trajectory of a computed-torque drive at `t`: `(q_d, q̇_d, q̈_d)` along the
/// quintic time scaling ([`ode::quintic`]).
#[must_use]
pub fn quintic_reference(
    q0: &[f64],
    target: &[f64],
    duration: f64,
    t: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (s, ds, dds) = ode::quintic(t, duration);
    let d: Vec<f64> = q0.iter().zip(target).map(|(a, b)| b - a).collect();
    (
        q0.iter().zip(&d).map(|(a, di)| a + s * di).collect(),
        d.iter().map(|di| ds * di).collect(),
        d.iter().map(|di| dds * di).collect(),
    )
}

impl<'a> SceneSystem<'a> {
    /// The system of `scene`.
    #[must_use]
    pub fn new(scene: &'a Scene) -> Self {
        let base = match &scene.base {
            BaseSpec::Fixed => None,
            BaseSpec::FreeFloating { inertial, .. } => Some(FloatingBase::from_inertial(inertial)),
        };
        SceneSystem {
            scene,
            params: Params::new(&scene.model),
            base,
            passive: Loads {
                tau: None,
                gravity: scene.gravity.map(Vec3::from_f64),
                external: scene.wrenches.iter().map(|w| w.at(0.0)).collect(),
            },
            time_varying: scene.wrenches.iter().any(SceneWrench::is_tabulated),
            n: scene.model.dof(),
            stop: None,
            fast: None,
        }
        .with_forward(scene.simulation.forward)
    }

    /// The system solving for the accelerations by `forward`: [`ForwardMethod::Aba`] is the
    /// run-time fast path (workspace ABA, no allocation unless the drive is computed torque),
    /// [`ForwardMethod::Ldlt`] `A` and `b` by the scene's algorithm then LDLᵀ (the default is
    /// the scene's [`crate::scene::SimulationSpec::forward`]). Both give the same right-hand
    /// side to rounding (`sim` tests).
    #[must_use]
    pub fn with_forward(mut self, forward: ForwardMethod) -> Self {
        self.fast = match forward {
            ForwardMethod::Ldlt => None,
            ForwardMethod::Aba => {
                let n = self.n;
                let base = if self.base.is_some() { 6 } else { 0 };
                Some(FastPath {
                    ws: Workspace::new(&self.params),
                    loads: Loads {
                        tau: Some(vec![0.0; n]),
                        ..self.passive.clone()
                    },
                    acc: vec![0.0; base + n],
                })
            }
        };
        self
    }

    /// The system, stopped at the next step once `stop` is set ([`System::interrupted`]).
    #[must_use]
    pub fn with_stop(mut self, stop: Option<&'a AtomicBool>) -> Self {
        self.stop = stop;
        self
    }

    /// The name of state component `i` (the CSV column, see [`csv_header`]).
    #[must_use]
    pub fn component_name(&self, i: usize) -> String {
        let n = self.n;
        let joint = |k: usize| self.scene.model.joints()[k].name.clone();
        let xyz = ["x", "y", "z"];
        if self.base.is_none() {
            return match i / n {
                0 => format!("q_{}", joint(i)),
                1 => format!("qd_{}", joint(i - n)),
                2 => format!("theta_{}", joint(i - 2 * n)),
                _ => format!("thetad_{}", joint(i - 3 * n)),
            };
        }
        match i {
            0..=2 => format!("p0_{}", xyz[i]),
            3..=6 => format!("quat_{}", ["x", "y", "z", "w"][i - 3]),
            _ if i < 7 + n => format!("q_{}", joint(i - 7)),
            _ if i < 10 + n => format!("v_b_{}", xyz[i - 7 - n]),
            _ if i < 13 + n => format!("omega_b_{}", xyz[i - 10 - n]),
            _ => format!("qd_{}", joint(i - 13 - n)),
        }
    }

    /// The initial state vector.
    #[must_use]
    pub fn initial_state(&self) -> Vec<f64> {
        let s = self.scene;
        match &s.base {
            BaseSpec::Fixed if s.flexible.is_some() => {
                [s.q0.as_slice(), &s.qd0, &s.q0, &s.qd0].concat()
            }
            BaseSpec::Fixed => [s.q0.as_slice(), &s.qd0].concat(),
            BaseSpec::FreeFloating {
                position,
                quaternion,
                v,
                omega,
                ..
            } => [position.as_slice(), quaternion, &s.q0, v, omega, &s.qd0].concat(),
        }
    }

    /// Splits a state into `(q, q̇, base)`.
    #[must_use]
    pub fn split<'x>(&self, x: &'x [f64]) -> (&'x [f64], &'x [f64], Option<FloatingState<f64>>) {
        let n = self.n;
        if self.base.is_none() {
            return (&x[..n], &x[n..2 * n], None);
        }
        let quat: [f64; 4] = x[3..7].try_into().expect("4 entries");
        let st = FloatingState {
            position: Vec3::new(x[0], x[1], x[2]),
            rotation: quat_to_matrix(&quat),
            v_b: Vec3::new(x[7 + n], x[8 + n], x[9 + n]),
            omega_b: Vec3::new(x[10 + n], x[11 + n], x[12 + n]),
        };
        (&x[7..7 + n], &x[13 + n..13 + 2 * n], Some(st))
    }

    /// The joint drive torques minus damping (viscous friction) and Coulomb friction at
    /// `(t, q, q̇)`: `τ_applied = τ_drive − b q̇ − τ_c tanh(q̇ / v_s)`; `None` when the scene has
    /// none of them.
    #[must_use]
    pub fn torques(&self, t: f64, q: &[f64], qd: &[f64]) -> Option<Vec<f64>> {
        let mut tau = vec![0.0; self.n];
        self.torques_into(t, q, qd, &mut tau).then_some(tau)
    }

    /// [`SceneSystem::torques`] into `tau` (length `N`; zeros when the scene has none of them,
    /// then `false`). Allocates nothing except for a computed-torque drive.
    pub fn torques_into(&self, t: f64, q: &[f64], qd: &[f64], tau: &mut [f64]) -> bool {
        let s = self.scene;
        let mut any = true;
        match &s.drives {
            Drives::None => {
                tau.fill(0.0);
                any = false;
            }
            Drives::Constant { tau: c } => tau.copy_from_slice(c),
            Drives::Pd { kp, kd, target } => {
                for i in 0..self.n {
                    tau[i] = kp[i] * (target[i] - q[i]) - kd[i] * qd[i];
                }
            }
            Drives::ComputedTorque {
                kp,
                kd,
                target,
                duration,
            } => {
                let (qr, qdr, qddr) = quintic_reference(&s.q0, target, *duration, t);
                let cmd: Vec<f64> = (0..self.n)
                    .map(|i| qddr[i] + kd[i] * (qdr[i] - qd[i]) + kp[i] * (qr[i] - q[i]))
                    .collect();
                // The controller compensates the scene's loads as they are at `t`.
                let at_t;
                let loads = if self.time_varying {
                    at_t = Loads {
                        external: s.wrenches.iter().map(|w| w.at(t)).collect(),
                        ..self.passive.clone()
                    };
                    &at_t
                } else {
                    &self.passive
                };
                tau.copy_from_slice(&s.simulation.algorithm.inverse_dynamics(
                    &self.params,
                    q,
                    qd,
                    &cmd,
                    loads,
                ));
            }
        }
        if let Some(c) = &s.damping {
            any = true;
            for i in 0..self.n {
                tau[i] -= c[i] * qd[i];
            }
        }
        if let Some(c) = &s.coulomb {
            any = true;
            for i in 0..self.n {
                tau[i] -= c.torque(i, qd[i]);
            }
        }
        any
    }

    /// Total energy: kinetic, plus the gravitational potential `−g · Σ m_k x_{c,k}` on a fixed
    /// base with gravity. `None` for a free-floating base under gravity (not monitored).
    #[must_use]
    pub fn energy(&self, x: &[f64]) -> Option<f64> {
        let t = self.kinetic_energy(x);
        if self.base.is_some() {
            return self.scene.gravity.is_none().then_some(t);
        }
        let q = &x[..self.n];
        // The motors' kinetic and the springs' potential energy.
        let t = match &self.scene.flexible {
            Some(f) => {
                let n = self.n;
                t + f.energy(q, &x[2 * n..3 * n], &x[3 * n..4 * n])
            }
            None => t,
        };
        // Gravitational potential: −g · Σ m_k x_k over the bodies' centres of mass.
        let v = match self.scene.gravity {
            None => 0.0,
            Some(g) => {
                let g = Vec3::from_f64(g);
                self.params
                    .joints
                    .iter()
                    .enumerate()
                    .map(|(k, jp)| {
                        let com = FrameParams {
                            parent: Some(k),
                            translation: jp.com.clone(),
                            rotation: Mat3::identity(),
                        };
                        let (x, _) = frames::placement(&self.params, q, &com);
                        -jp.mass * g.dot(&x)
                    })
                    .sum()
            }
        };
        Some(t + v)
    }

    /// The scene.
    #[must_use]
    pub fn scene(&self) -> &Scene {
        self.scene
    }

    /// Joint degrees of freedom `N`.
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }

    /// The model's numbers the dynamics read now (the scene's model, or the model after the last
    /// [`SceneSystem::apply_event`]).
    #[must_use]
    pub fn params(&self) -> &Params<f64> {
        &self.params
    }

    /// Replaces the model's numbers (a payload captured or released).
    pub fn set_params(&mut self, params: Params<f64>) {
        self.params = params;
    }

    /// The free-floating base body, `None` on a fixed base.
    #[must_use]
    pub fn floating_base(&self) -> Option<&FloatingBase<f64>> {
        self.base.as_ref()
    }

    /// `σ_min(J*)` of `frame` at state `x` ([`singularity::sigma_min`]); `None` on a fixed base
    /// or with fewer than 6 joints.
    #[must_use]
    pub fn sigma_min(&self, x: &[f64], frame: &FrameParams<f64>) -> Option<f64> {
        let (q, _, st) = self.split(x);
        singularity::sigma_min(&self.params, self.base.as_ref()?, &st?, q, frame)
    }

    /// The origin frame of the last body (the frame whose `σ_min(J*)` the summary reports).
    fn last_body_frame(&self) -> FrameParams<f64> {
        FrameParams {
            parent: Some(self.n - 1),
            translation: Vec3::zero(),
            rotation: Mat3::identity(),
        }
    }

    /// Adds the armature `I_m,i n_i²` of `[effects] rotor` to the joint diagonal of a mass
    /// matrix (`N × N`, or `(6+N) × (6+N)` on a free-floating base: `H[6+i][6+i]`); nothing
    /// without a rotor.
    pub fn add_armature(&self, a: &mut [Vec<f64>]) {
        if let Some(r) = &self.scene.rotor {
            let off = a.len() - self.n;
            for (i, ri) in r.reflected.iter().enumerate() {
                a[off + i][off + i] += ri;
            }
        }
    }

    /// Kinetic energy of bodies and rotors (no potential), on either base.
    #[must_use]
    pub fn kinetic_energy(&self, x: &[f64]) -> f64 {
        let (q, qd, st) = self.split(x);
        match (&self.base, st) {
            (Some(b), Some(st)) => {
                kinetic_energy(&self.params, b, &st, q, qd) + self.rotor_energy(qd)
            }
            _ => {
                let a = self
                    .scene
                    .simulation
                    .algorithm
                    .mass_matrix
                    .mass_matrix(&self.params, q);
                0.5 * (0..self.n)
                    .map(|i| qd[i] * (0..self.n).map(|j| a[i][j] * qd[j]).sum::<f64>())
                    .sum::<f64>()
                    + self.rotor_energy(qd)
            }
        }
    }

    /// The rotors' kinetic energy `½ Σ I_m,i n_i² q̇_i²` of the armature model (0 without
    /// `[effects] rotor`).
    fn rotor_energy(&self, qd: &[f64]) -> f64 {
        self.scene.rotor.as_ref().map_or(0.0, |r| {
            0.5 * (0..self.n)
                .map(|i| r.reflected[i] * qd[i] * qd[i])
                .sum::<f64>()
        })
    }

    /// Linear and angular momentum (inertial frame, about the inertial origin) of a free-floating
    /// system; `None` on a fixed base. With `[effects] rotor` this is the momentum of the bodies,
    /// which the armature model conserves (see [`crate::events`] and `docs/scenes.md`, "What the simulator does").
    #[must_use]
    pub fn momentum(&self, x: &[f64]) -> Option<([f64; 3], [f64; 3])> {
        let (q, qd, st) = self.split(x);
        let (b, st) = (self.base.as_ref()?, st?);
        let (l, a) = momentum(&self.params, b, &st, q, qd);
        Some((l.into_array(), a.into_array()))
    }
}

impl SceneSystem<'_> {
    /// [`System::deriv`] on the run-time fast path: the workspace ABA, the reflected rotor
    /// inertia as its armature (`D_i += I_m n²`), the loads written in place.
    fn deriv_fast(&mut self, t: f64, x: &[f64], dx: &mut [f64]) {
        let mut fast = self.fast.take().expect("the fast path");
        let n = self.n;
        let (q, qd, st) = self.split(x);
        let tau = fast.loads.tau.as_mut().expect("tau is preallocated");
        self.torques_into(t, q, qd, tau);
        if self.time_varying {
            for (l, w) in fast.loads.external.iter_mut().zip(&self.scene.wrenches) {
                *l = w.at(t);
            }
        }
        let armature = self.scene.rotor.as_ref().map(|r| r.reflected.as_slice());
        match (&self.base, st) {
            (Some(b), Some(st)) => {
                aba::floating_in(
                    &self.params,
                    &mut fast.ws,
                    b,
                    &st,
                    q,
                    qd,
                    &fast.loads,
                    armature,
                    &mut fast.acc,
                );
                floating_kinematics(n, x, &st, qd, dx);
                dx[7 + n..].copy_from_slice(&fast.acc);
            }
            _ => {
                aba::forward_dynamics_in(
                    &self.params,
                    &mut fast.ws,
                    q,
                    qd,
                    &fast.loads,
                    armature,
                    &mut fast.acc,
                );
                dx[..n].copy_from_slice(qd);
                dx[n..].copy_from_slice(&fast.acc);
            }
        }
        self.fast = Some(fast);
    }
}

/// The kinematic part of a free-floating state's derivative: `ṗ₀ = R₀ v_b`, `q̇uat`, `q̇`
/// (`dx[..7 + N]`).
fn floating_kinematics(n: usize, x: &[f64], st: &FloatingState<f64>, qd: &[f64], dx: &mut [f64]) {
    let pd = st.rotation.mul_vec(&st.v_b);
    dx[..3].copy_from_slice(&pd.0);
    // q̇uat = ½ quat ⊗ (ω, 0): u̇ = ½ (w ω + u × ω), ẇ = −½ u · ω.
    let (u, w) = (Vec3::new(x[3], x[4], x[5]), x[6]);
    let om = &st.omega_b;
    let ud = (om.scale(&w) + u.cross(om)).scale(&0.5);
    dx[3..6].copy_from_slice(&ud.0);
    dx[6] = -0.5 * u.dot(om);
    dx[7..7 + n].copy_from_slice(qd);
}

impl SceneSystem<'_> {
    /// Applies `event` at state `x` (free-floating): switches the model to `event.model` and, for
    /// a capture, replaces `ν` by the post-capture velocity of the plastic-impact equation
    /// ([`events::capture`], with the armature of `[effects] rotor` on both mass matrices).
    ///
    /// # Panics
    /// On a fixed base (the scene parser rejects events there).
    pub fn apply_event(&mut self, event: &Event, x: &mut [f64]) -> EventReport {
        let n = self.n;
        let before = self.momentum(x).expect("events need a free-floating base");
        let e_before = self.kinetic_energy(x);
        let new_params = Params::new(&event.model);
        let (kind, pay) = match &event.kind {
            EventKind::Capture { payload, v, omega } => {
                let (q, _, st) = self.split(x);
                let st = st.expect("free-floating");
                let armature = |a: &mut [Vec<f64>]| self.add_armature(a);
                let sys = CaptureSystem {
                    method: self.scene.simulation.algorithm.mass_matrix,
                    base: self.base.as_ref().expect("free-floating"),
                    state: &st,
                    q,
                    armature: &armature,
                };
                let (nu, pay) = events::capture(
                    &sys,
                    &self.params,
                    &new_params,
                    &x[7 + n..],
                    event.body,
                    payload,
                    *v,
                    *omega,
                );
                x[7 + n..].copy_from_slice(&nu);
                ("capture", pay)
            }
            EventKind::Release { .. } => ("release", (before.0, before.1)),
        };
        self.params = new_params;
        let after = self.momentum(x).expect("free-floating");
        // The released payload's momentum: the system's with it minus without it.
        let pay = if kind == "release" {
            (
                events::add(&pay.0, &after.0, -1.0),
                events::add(&pay.1, &after.1, -1.0),
            )
        } else {
            pay
        };
        // System and payload, before and after: the payload is free before a capture and after
        // a release.
        let (total_before, total_after) = if kind == "capture" {
            (
                (
                    events::add(&before.0, &pay.0, 1.0),
                    events::add(&before.1, &pay.1, 1.0),
                ),
                after,
            )
        } else {
            (
                before,
                (
                    events::add(&after.0, &pay.0, 1.0),
                    events::add(&after.1, &pay.1, 1.0),
                ),
            )
        };
        EventReport {
            t: event.time,
            kind,
            body: self.scene.model.joints()[event.body].body.clone(),
            linear_momentum_before: total_before.0,
            angular_momentum_before: total_before.1,
            linear_momentum_error_rel: events::rel_diff(&total_after.0, &total_before.0),
            angular_momentum_error_rel: events::rel_diff(&total_after.1, &total_before.1),
            energy_change: self.kinetic_energy(x) - e_before,
            payload_linear_momentum: pay.0,
            payload_angular_momentum: pay.1,
        }
    }
}

impl System for SceneSystem<'_> {
    fn dim(&self) -> usize {
        if self.base.is_some() {
            13 + 2 * self.n
        } else if self.scene.flexible.is_some() {
            4 * self.n
        } else {
            2 * self.n
        }
    }

    fn deriv(&mut self, t: f64, x: &[f64], dx: &mut [f64]) {
        let n = self.n;
        let (q, qd, st) = self.split(x);
        // Flexible joints first: their state is `[q, q̇, θ, θ̇]`, which the fast path does not
        // know (it evaluates the link side by the scene's algorithm).
        if let Some(f) = &self.scene.flexible {
            // Spong's model: the spring loads the links, the drives act on the motors.
            let (th, thd) = (&x[2 * n..3 * n], &x[3 * n..4 * n]);
            let tau_s = f.spring_torque(q, qd, th, thd);
            let tau_m = self.torques(t, th, thd);
            let mut loads = Loads {
                tau: Some(tau_s.clone()),
                ..self.passive.clone()
            };
            if self.time_varying {
                loads.external = self.scene.wrenches.iter().map(|w| w.at(t)).collect();
            }
            let alg = self.scene.simulation.algorithm;
            let qdd = alg.forward_dynamics(&self.params, q, qd, &loads);
            dx[..n].copy_from_slice(qd);
            dx[n..2 * n].copy_from_slice(&qdd);
            dx[2 * n..3 * n].copy_from_slice(thd);
            for i in 0..n {
                let tm = tau_m.as_ref().map_or(0.0, |v| v[i]);
                dx[3 * n + i] = (tm - tau_s[i]) / f.reflected[i];
            }
            return;
        }
        if self.fast.is_some() {
            return self.deriv_fast(t, x, dx);
        }
        let mut loads = Loads {
            tau: self.torques(t, q, qd),
            ..self.passive.clone()
        };
        if self.time_varying {
            loads.external = self.scene.wrenches.iter().map(|w| w.at(t)).collect();
        }
        let alg = self.scene.simulation.algorithm;
        match (&self.base, st) {
            (Some(b), Some(st)) => {
                let nu_dot = match &self.scene.rotor {
                    None => floating::forward_dynamics(alg, &self.params, b, &st, q, qd, &loads),
                    // The armature model on a free-floating base: I_m n² on the joint diagonal
                    // H[6+i][6+i] of the (6+N) mass matrix before the LDLᵀ solve.
                    Some(_) => {
                        let mut d = floating::dynamics(alg, &self.params, b, &st, q, qd, &loads);
                        self.add_armature(&mut d.a);
                        kanegen_dynamics::ldlt::solve(&kanegen_dynamics::ldlt::ldlt(&d.a), &d.b)
                    }
                };
                floating_kinematics(n, x, &st, qd, dx);
                dx[7 + n..].copy_from_slice(&nu_dot);
            }
            _ => {
                let qdd = match &self.scene.rotor {
                    None => alg.forward_dynamics(&self.params, q, qd, &loads),
                    // (M + diag(I_m n²)) q̈ = τ − c: the reflected rotor inertia on M's
                    // diagonal before the LDLᵀ solve.
                    Some(_) => {
                        let mut d = alg.dynamics(&self.params, q, qd, &loads);
                        self.add_armature(&mut d.a);
                        kanegen_dynamics::ldlt::solve(&kanegen_dynamics::ldlt::ldlt(&d.a), &d.b)
                    }
                };
                dx[..n].copy_from_slice(qd);
                dx[n..].copy_from_slice(&qdd);
            }
        }
    }

    /// Additive, except the quaternion on a free-floating base: `quat ⊗ exp(h ω_b(at) / 2)`
    /// ([`quaternion::advance_floating`]).
    fn advance(&self, x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
        if self.base.is_some() {
            quaternion::advance_floating(x, h, at, f, out);
        } else {
            quaternion::advance_additive(x, h, f, out);
        }
    }

    fn interrupted(&self) -> bool {
        self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }

    fn project(&self, x: &mut [f64]) {
        if self.base.is_some() {
            quaternion::normalize_quaternion(x);
        }
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

/// One output sample.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Time.
    pub t: f64,
    /// The state vector (see the module doc).
    pub x: Vec<f64>,
    /// Energy drift (relative) at `t`, when monitored.
    pub energy_drift: Option<f64>,
    /// Linear and angular momentum drift (relative) at `t`, when monitored.
    pub momentum_drift: Option<(f64, f64)>,
}

/// A finished run.
#[derive(Clone, Debug)]
pub struct Run {
    /// The summary.
    pub summary: Summary,
    /// The output samples, `t = 0` first, the final time last.
    pub samples: Vec<Sample>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn rel(x: f64, x0: f64) -> f64 {
    if x0 == 0.0 {
        x.abs()
    } else {
        x / x0.abs()
    }
}

/// Whether the scene conserves energy (see [`Summary`]).
#[must_use]
pub fn conserves_energy(scene: &Scene) -> bool {
    matches!(scene.drives, Drives::None)
        && scene.damping.is_none()
        && scene.coulomb.is_none()
        && !scene
            .flexible
            .as_ref()
            .is_some_and(crate::flexible::Flexible::dissipates)
        && scene.wrenches.is_empty()
        && !(scene.is_floating() && scene.gravity.is_some())
}

/// Whether the scene conserves linear and angular momentum (see [`Summary`]).
#[must_use]
pub fn conserves_momentum(scene: &Scene) -> bool {
    scene.is_floating() && scene.wrenches.is_empty() && scene.gravity.is_none()
}

/// Where the output samples of a run go, one at a time, as they are produced (the CLI's CSV
/// writer and plot buffer, [`Decimated`], or a closure).
pub trait Sink {
    /// Takes one sample. An error stops the run; [`simulate_to`] returns it.
    ///
    /// # Errors
    /// Whatever the sink cannot do (a full disk).
    fn sample(&mut self, s: &Sample) -> Result<()>;
}

impl<F: FnMut(&Sample) -> Result<()>> Sink for F {
    fn sample(&mut self, s: &Sample) -> Result<()> {
        self(s)
    }
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

/// A bounded, evenly decimated copy of a run's samples, for plots: at most `cap` samples (every
/// `stride`-th; when full, every other one is dropped and the stride doubles), plus the last
/// sample seen. Memory stays `O(cap)` however long the run.
#[derive(Clone, Debug)]
pub struct Decimated {
    cap: usize,
    stride: usize,
    seen: usize,
    kept: Vec<Sample>,
    last: Option<Sample>,
}

impl Decimated {
    /// An empty buffer of at most `cap` (≥ 2) samples.
    #[must_use]
    pub fn new(cap: usize) -> Self {
        Decimated {
            cap: cap.max(2),
            stride: 1,
            seen: 0,
            kept: Vec::new(),
            last: None,
        }
    }

    /// The kept samples in time order, the last sample seen at the end.
    #[must_use]
    pub fn into_samples(self) -> Vec<Sample> {
        let mut v = self.kept;
        if let Some(l) = self.last {
            if v.last().is_none_or(|k| k.t != l.t) {
                v.push(l);
            }
        }
        v
    }
}

impl Sink for Decimated {
    fn sample(&mut self, s: &Sample) -> Result<()> {
        // `stride` is a power of two.
        if self.seen & (self.stride - 1) == 0 {
            if self.kept.len() == self.cap {
                let mut i = 0;
                self.kept.retain(|_| {
                    i += 1;
                    i % 2 == 1
                });
                self.stride *= 2;
            }
            if self.seen & (self.stride - 1) == 0 {
                self.kept.push(s.clone());
            }
        }
        self.seen += 1;
        self.last = Some(s.clone());
        Ok(())
    }
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
    let sim = &scene.simulation;
    let energy_on = conserves_energy(scene);
    let momentum_on = conserves_momentum(scene);
    // The baselines move at the events (see `crate::events`, "Monitors").
    let e0 = Cell::new(if energy_on { sys.energy(&x) } else { None });
    let p0 = Cell::new(if momentum_on { sys.momentum(&x) } else { None });
    let monitor = RefCell::new(SceneSystem::new(scene));
    let mut max_e: Option<f64> = e0.get().map(|_| 0.0);
    let mut max_p: Option<(f64, f64)> = p0.get().map(|_| (0.0, 0.0));
    let mut sink_error: Option<anyhow::Error> = None;
    let last_t = Cell::new(f64::NAN);
    let frame = sys.last_body_frame();
    let mut sigma: Option<(f64, f64)> = None;
    let mut record = |t: f64, x: &[f64]| -> ControlFlow<()> {
        if sink_error.is_some() {
            return ControlFlow::Break(());
        }
        let monitor = monitor.borrow();
        if let Some(s) = monitor.sigma_min(x, &frame) {
            if sigma.is_none_or(|(m, _)| s < m) {
                sigma = Some((s, t));
            }
        }
        let energy_drift = e0
            .get()
            .and_then(|e0| monitor.energy(x).map(|e| rel(e - e0, e0)));
        let momentum_drift = p0.get().and_then(|(l0, a0)| {
            monitor.momentum(x).map(|(l, a)| {
                let dl: Vec<f64> = (0..3).map(|i| l[i] - l0[i]).collect();
                let da: Vec<f64> = (0..3).map(|i| a[i] - a0[i]).collect();
                (rel(norm(&dl), norm(&l0)), rel(norm(&da), norm(&a0)))
            })
        });
        if let (Some(m), Some(d)) = (max_e.as_mut(), energy_drift) {
            *m = m.max(d.abs());
        }
        if let (Some(m), Some(d)) = (max_p.as_mut(), momentum_drift) {
            *m = (m.0.max(d.0.abs()), m.1.max(d.1.abs()));
        }
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
    // One integration per segment between events: each ends exactly at its event time (the
    // state at t_e⁻ is sampled), the event switches the model and jumps ν, and the next segment
    // starts with a sample at t_e⁺.
    // Events at or after the end (a scene whose duration was shortened) do not happen.
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
    let mut result: Result<(), Stop> = Ok(());
    let mut scratch = VecScratch::default();
    for (seg, &t1) in ends.iter().enumerate() {
        if seg > 0 {
            let event = events[seg - 1];
            let report = sys.apply_event(event, &mut x);
            monitor.borrow_mut().set_params(sys.params().clone());
            if let Some(e) = e0.get() {
                e0.set(Some(e + report.energy_change));
            }
            if let Some((l, a)) = p0.get() {
                let sign = if report.kind == "capture" { 1.0 } else { -1.0 };
                let shift = |v: [f64; 3], d: [f64; 3]| [0, 1, 2].map(|i| v[i] + sign * d[i]);
                p0.set(Some((
                    shift(l, report.payload_linear_momentum),
                    shift(a, report.payload_angular_momentum),
                )));
            }
            reports.push(report);
        }
        let segment = integrate_segment(&mut sys, sim, (t0, t1), &mut x, &mut scratch, &mut record);
        match segment {
            Ok(s) => stats.accumulate(s),
            Err(e) => {
                stats.accumulate(e.stats());
                result = Err(e);
                break;
            }
        }
        t0 = t1;
    }
    let wall_s = start.elapsed().as_secs_f64();
    let (t_end, stopped) = match &result {
        Ok(()) => (sim.duration, None),
        Err(e) => {
            let why = match e {
                Stop::Interrupted { .. } => "interrupted".to_string(),
                Stop::NonFinite { t, index, .. } => format!(
                    "`{}` became non-finite in the step to t = {t} (the state overflowed: a \
                     singular mass matrix or an unstable drive)",
                    sys.component_name(*index)
                ),
                other => other.to_string(),
            };
            (e.t(), Some(why))
        }
    };
    // An early stop: the state reached (the last accepted one) ends the samples.
    if result.is_err() && last_t.get() != t_end {
        let _ = record(t_end, &x);
    }
    if let Some(e) = sink_error {
        return Err(e);
    }
    let (q, qd, _) = sys.split(&x);
    Ok(Summary {
        base: if scene.is_floating() {
            "free-floating"
        } else {
            "fixed"
        },
        steps: stats.steps,
        rejected_steps: stats.rejected_steps,
        evals: stats.evals,
        wall_s,
        max_energy_drift_rel: max_e,
        max_linear_momentum_drift_rel: max_p.map(|m| m.0),
        max_angular_momentum_drift_rel: max_p.map(|m| m.1),
        final_state: FinalState {
            q: q.to_vec(),
            qd: qd.to_vec(),
        },
        complete: result.is_ok(),
        t_end,
        stopped,
        events: reports,
        singularity: sigma.map(|(sigma_min, t)| SigmaMin {
            body: scene.model.joints()[scene.model.dof() - 1].body.clone(),
            sigma_min,
            t,
        }),
    })
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

/// A human-readable summary.
#[must_use]
pub fn render_text(s: &Summary) -> String {
    let f = |x: Option<f64>| x.map_or("not conserved".to_string(), |v| format!("{v:.3e}"));
    let status = if s.complete {
        String::new()
    } else {
        format!(
            "INCOMPLETE: stopped at t = {} ({})\n",
            s.t_end,
            s.stopped.as_deref().unwrap_or("")
        )
    };
    format!(
        "{status}base: {}\nsteps: {} accepted, {} rejected, {} evaluations, {:.3} s\n\
         energy drift (rel): {}\nlinear momentum drift (rel): {}\n\
         angular momentum drift (rel): {}\nfinal q: {:?}\nfinal qd: {:?}",
        s.base,
        s.steps,
        s.rejected_steps,
        s.evals,
        s.wall_s,
        f(s.max_energy_drift_rel),
        f(s.max_linear_momentum_drift_rel),
        f(s.max_angular_momentum_drift_rel),
        s.final_state.q,
        s.final_state.qd,
    ) + &events_text(s)
        + &s.singularity.as_ref().map_or(String::new(), |m| {
            format!(
                "\nsmallest σ_min of J* ({}): {:.3e} at t = {} s",
                m.body, m.sigma_min, m.t
            )
        })
}

/// One line per payload event of a summary (empty without events).
fn events_text(s: &Summary) -> String {
    s.events
        .iter()
        .map(|e| {
            format!(
                "\nevent at t = {}: {} by {}, momentum error through it (rel) {:.3e} linear, \
                 {:.3e} angular, kinetic energy change {:.6e} J",
                e.t,
                e.kind,
                e.body,
                e.linear_momentum_error_rel,
                e.angular_momentum_error_rel,
                e.energy_change
            )
        })
        .collect()
}

/// The CSV header of a scene's trajectory: `t`, `q_<joint>`…, `qd_<joint>`…, and for a
/// free-floating base `p0_x…`, `quat_x, quat_y, quat_z, quat_w`, `v_b_x…`, `omega_b_x…`.
#[must_use]
pub fn csv_header(scene: &Scene) -> Vec<String> {
    let names: Vec<&str> = scene
        .model
        .joints()
        .iter()
        .map(|j| j.name.as_str())
        .collect();
    let mut h = vec!["t".to_string()];
    h.extend(names.iter().map(|n| format!("q_{n}")));
    h.extend(names.iter().map(|n| format!("qd_{n}")));
    if scene.flexible.is_some() {
        h.extend(names.iter().map(|n| format!("theta_{n}")));
        h.extend(names.iter().map(|n| format!("thetad_{n}")));
    }
    if scene.is_floating() {
        for (p, comps) in [
            ("p0", &["x", "y", "z"][..]),
            ("quat", &["x", "y", "z", "w"][..]),
            ("v_b", &["x", "y", "z"][..]),
            ("omega_b", &["x", "y", "z"][..]),
        ] {
            h.extend(comps.iter().map(|c| format!("{p}_{c}")));
        }
    }
    h
}

/// One CSV row of a sample (see [`csv_header`]), with its newline. Numbers in Rust's shortest
/// round-trip `{:e}` form.
#[must_use]
pub fn csv_row(scene: &Scene, s: &Sample) -> String {
    let n = scene.model.dof();
    let x = &s.x;
    let mut row: Vec<f64> = vec![s.t];
    if scene.is_floating() {
        row.extend(&x[7..7 + n]);
        row.extend(&x[13 + n..13 + 2 * n]);
        row.extend(&x[..7]);
        row.extend(&x[7 + n..13 + n]);
    } else {
        row.extend(x);
    }
    let cells: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
    let mut out = cells.join(",");
    out.push('\n');
    out
}

/// The trajectory as CSV text (see [`csv_header`]).
#[must_use]
pub fn trajectory_csv(scene: &Scene, run: &Run) -> String {
    let mut out = csv_header(scene).join(",");
    out.push('\n');
    for s in &run.samples {
        out.push_str(&csv_row(scene, s));
    }
    out
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
