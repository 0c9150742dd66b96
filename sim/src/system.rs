//! A [`Scene`] as a first-order [`System`]: the state vector, and the right-hand side of
//! [`kanegen_runtime::scene`] over the run-time dynamics ([`crate::provider`]).
//!
//! State vector: fixed base `[q (N), q̇ (N)]`; free-floating base
//! `[p₀ (3), quat (4: x, y, z, w), q (N), v_b (3), ω_b (3), q̇ (N)]` with `ṗ₀ = R₀ v_b` and
//! `q̇uat = ½ quat ⊗ (ω_b, 0)` (body-frame `ω_b`); with flexible joints (fixed base)
//! `[q (N), q̇ (N), θ (N), θ̇ (N)]`, the motor coordinates last ([`crate::flexible`]). RK4,
//! dopri5 and rosenbrock renormalize the quaternion after every accepted step
//! ([`System::project`]); the implicit midpoint rule updates it by the exponential map
//! ([`System::advance`]) and needs no projection.

use crate::provider::{floating_state, RunTimeDynamics};
use crate::scene::Scene;
use crate::singularity;
use kanegen_dynamics::base::{FloatingBase, FloatingState};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::{ForwardMethod, FrameParams, Params};
use kanegen_runtime::ode::{quaternion, System};
use kanegen_runtime::scene::{self as rt_scene, Profile};
use std::sync::atomic::{AtomicBool, Ordering};

/// A scene as a first-order system for the integrators: the right-hand side of
/// [`kanegen_runtime::scene::deriv`] over the run-time dynamics ([`RunTimeDynamics`]).
pub struct SceneSystem<'a> {
    pub(crate) scene: &'a Scene,
    pub(crate) dynamics: RunTimeDynamics,
    /// The profiles of the scene's wrenches (borrowed by its effects).
    profiles: Vec<Profile<'a>>,
    /// The work memory of the right-hand side, allocated once.
    work: Vec<f64>,
    pub(crate) n: usize,
    /// Set (by a Ctrl-C handler) to stop the run at the next step.
    stop: Option<&'a AtomicBool>,
}

/// The desired trajectory of a computed-torque drive at `t`: `(q_d, q̇_d, q̈_d)` along the
/// quintic time scaling ([`kanegen_runtime::scene::quintic_reference`]).
#[must_use]
pub fn quintic_reference(
    q0: &[f64],
    target: &[f64],
    duration: f64,
    t: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let r: Vec<(f64, f64, f64)> = q0
        .iter()
        .zip(target)
        .map(|(a, b)| rt_scene::quintic_reference(*a, *b, duration, t))
        .collect();
    (
        r.iter().map(|x| x.0).collect(),
        r.iter().map(|x| x.1).collect(),
        r.iter().map(|x| x.2).collect(),
    )
}

impl<'a> SceneSystem<'a> {
    /// The system of `scene`.
    #[must_use]
    pub fn new(scene: &'a Scene) -> Self {
        let profiles = scene.wrench_profiles();
        let work = vec![0.0; scene.effects(&profiles).work_len()];
        SceneSystem {
            scene,
            dynamics: RunTimeDynamics::new(scene, scene.simulation.forward),
            profiles,
            work,
            n: scene.model.coordinate_count(),
            stop: None,
        }
    }

    /// The system solving for the accelerations by `forward`: [`ForwardMethod::Aba`] is the
    /// run-time fast path (workspace ABA, no allocation unless the drive is computed torque),
    /// [`ForwardMethod::Ldlt`] `A` and `b` by the scene's algorithm then LDLᵀ (the default is
    /// the scene's [`crate::scene::SimulationSpec::forward`]). Both give the same right-hand
    /// side to rounding (`sim` tests).
    #[must_use]
    pub fn with_forward(mut self, forward: ForwardMethod) -> Self {
        let params = self.dynamics.params.clone();
        self.dynamics = RunTimeDynamics::new(self.scene, forward);
        self.dynamics.set_params(params);
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
        let coordinates = self.scene.model.coordinates();
        let joint = |k: usize| self.scene.model.joints()[coordinates[k]].name.clone();
        let xyz = ["x", "y", "z"];
        if self.dynamics.base.is_none() {
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
        self.scene.initial_state()
    }

    /// Splits a state into `(q, q̇, base)`.
    #[must_use]
    pub fn split<'x>(&self, x: &'x [f64]) -> (&'x [f64], &'x [f64], Option<FloatingState<f64>>) {
        let n = self.n;
        if self.dynamics.base.is_none() {
            return (&x[..n], &x[n..2 * n], None);
        }
        let st = floating_state(x, &x[7 + n..]);
        (&x[7..7 + n], &x[13 + n..13 + 2 * n], Some(st))
    }

    /// The scene.
    #[must_use]
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }

    /// Joint degrees of freedom `N`: the model's coordinates (its joints without the mimic
    /// joints).
    #[must_use]
    pub fn n(&self) -> usize {
        self.n
    }

    /// The model's numbers the dynamics read now (the scene's model, or the model after the last
    /// [`SceneSystem::apply_event`]).
    #[must_use]
    pub fn params(&self) -> &Params<f64> {
        &self.dynamics.params
    }

    /// Replaces the model's numbers (a payload captured or released).
    pub fn set_params(&mut self, params: Params<f64>) {
        self.dynamics.set_params(params);
    }

    /// The free-floating base body, `None` on a fixed base.
    #[must_use]
    pub fn floating_base(&self) -> Option<&FloatingBase<f64>> {
        self.dynamics.base.as_ref()
    }

    /// `σ_min(J*)` of `frame` at state `x` ([`singularity::sigma_min`]); `None` on a fixed base
    /// or with fewer than 6 joints.
    #[must_use]
    pub fn sigma_min(&self, x: &[f64], frame: &FrameParams<f64>) -> Option<f64> {
        let (q, _, st) = self.split(x);
        singularity::sigma_min(
            &self.dynamics.params,
            self.dynamics.base.as_ref()?,
            &st?,
            (
                &self.dynamics.full_positions(q),
                self.dynamics.coupling.as_ref(),
            ),
            frame,
        )
    }

    /// The origin frame of the last body (the frame whose `σ_min(J*)` the summary reports).
    pub(crate) fn last_body_frame(&self) -> FrameParams<f64> {
        FrameParams {
            parent: Some(self.scene.model.dof() - 1),
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
}

impl System for SceneSystem<'_> {
    fn dim(&self) -> usize {
        if self.dynamics.base.is_some() {
            13 + 2 * self.n
        } else if self.scene.flexible.is_some() {
            4 * self.n
        } else {
            2 * self.n
        }
    }

    fn deriv(&mut self, t: f64, x: &[f64], dx: &mut [f64]) {
        let effects = self.scene.effects(&self.profiles);
        rt_scene::deriv(&mut self.dynamics, &effects, t, x, dx, &mut self.work);
    }

    /// Additive, except the quaternion on a free-floating base: `quat ⊗ exp(h ω_b(at) / 2)`
    /// ([`quaternion::advance_floating`]).
    fn advance(&self, x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
        if self.dynamics.base.is_some() {
            quaternion::advance_floating(x, h, at, f, out);
        } else {
            quaternion::advance_additive(x, h, f, out);
        }
    }

    fn interrupted(&self) -> bool {
        self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }

    fn project(&self, x: &mut [f64]) {
        if self.dynamics.base.is_some() {
            quaternion::normalize_quaternion(x);
        }
    }
}
