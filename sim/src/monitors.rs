//! The conservation monitors of a run: the energy (kinetic, rotors', springs' and gravitational
//! potential) and the momentum of a scene's state, and whether the scene conserves them.

use crate::events::EventReport;
use crate::scene::{Drives, Scene};
use crate::system::SceneSystem;
use kanegen_dynamics::algorithms::floating::{kinetic_energy, momentum};
use kanegen_dynamics::algorithms::frames;
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::FrameParams;
use kanegen_dynamics::Params;

impl SceneSystem<'_> {
    /// Total energy: kinetic, plus the gravitational potential `−g · Σ m_k x_{c,k}` on a fixed
    /// base with gravity. `None` for a free-floating base under gravity (not monitored).
    #[must_use]
    pub fn energy(&self, x: &[f64]) -> Option<f64> {
        let t = self.kinetic_energy(x);
        if self.dynamics.base.is_some() {
            return self.scene.gravity.is_none().then_some(t);
        }
        let q = &x[..self.n];
        let q_full = self.dynamics.full_positions(q);
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
                self.dynamics
                    .params
                    .joints
                    .iter()
                    .enumerate()
                    .map(|(k, jp)| {
                        let com = FrameParams {
                            parent: Some(k),
                            translation: jp.com.clone(),
                            rotation: Mat3::identity(),
                        };
                        let (x, _) = frames::placement(&self.dynamics.params, &q_full, &com);
                        -jp.mass * g.dot(&x)
                    })
                    .sum()
            }
        };
        Some(t + v)
    }

    /// Kinetic energy of bodies and rotors (no potential), on either base.
    #[must_use]
    pub fn kinetic_energy(&self, x: &[f64]) -> f64 {
        let (q, qd, st) = self.split(x);
        match (&self.dynamics.base, st) {
            (Some(b), Some(st)) => {
                let (q, qd_full) = (
                    self.dynamics.full_positions(q),
                    self.dynamics.full_rates(qd),
                );
                kinetic_energy(&self.dynamics.params, b, &st, &q, &qd_full) + self.rotor_energy(qd)
            }
            _ => {
                // ½ q̇ᵀ M q̇ with the mass matrix of the coordinates (reduced by mimic joints).
                let algorithm = self.scene.simulation.algorithm.mass_matrix;
                let a =
                    algorithm.mass_matrix(&self.dynamics.params, &self.dynamics.full_positions(q));
                let a = match &self.dynamics.coupling {
                    Some(c) => c.reduce_matrix(&a, 0),
                    None => a,
                };
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
        let (b, st) = (self.dynamics.base.as_ref()?, st?);
        let (q, qd) = (
            self.dynamics.full_positions(q),
            self.dynamics.full_rates(qd),
        );
        let (l, a) = momentum(&self.dynamics.params, b, &st, &q, &qd);
        Some((l.into_array(), a.into_array()))
    }
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

/// The monitors of a run: the energy and momentum baselines (moved at each event), the largest
/// drifts from them, and the smallest `σ_min(J*)` of the last body's frame with its time.
pub(crate) struct Monitors<'a> {
    /// A system of the scene whose model follows the events (the monitors' own).
    system: SceneSystem<'a>,
    frame: FrameParams<f64>,
    energy0: Option<f64>,
    momentum0: Option<([f64; 3], [f64; 3])>,
    /// Largest relative energy drift, when monitored.
    pub max_energy: Option<f64>,
    /// Largest relative linear and angular momentum drifts, when monitored.
    pub max_momentum: Option<(f64, f64)>,
    /// Smallest `σ_min(J*)` and its time.
    pub sigma: Option<(f64, f64)>,
}

impl<'a> Monitors<'a> {
    /// The monitors of `scene` from the initial state `x`.
    pub fn new(scene: &'a Scene, x: &[f64]) -> Self {
        let system = SceneSystem::new(scene);
        let energy0 = if conserves_energy(scene) {
            system.energy(x)
        } else {
            None
        };
        let momentum0 = if conserves_momentum(scene) {
            system.momentum(x)
        } else {
            None
        };
        Monitors {
            frame: system.last_body_frame(),
            system,
            energy0,
            momentum0,
            max_energy: energy0.map(|_| 0.0),
            max_momentum: momentum0.map(|_| (0.0, 0.0)),
            sigma: None,
        }
    }

    /// Watches the sample `(t, x)`: its energy and momentum drifts (relative, when monitored),
    /// kept as maxima and returned; its `σ_min(J*)`.
    pub fn observe(&mut self, t: f64, x: &[f64]) -> (Option<f64>, Option<(f64, f64)>) {
        if let Some(s) = self.system.sigma_min(x, &self.frame) {
            if self.sigma.is_none_or(|(m, _)| s < m) {
                self.sigma = Some((s, t));
            }
        }
        let energy = self
            .energy0
            .and_then(|e0| self.system.energy(x).map(|e| rel(e - e0, e0)));
        let momentum = self.momentum0.and_then(|(l0, a0)| {
            self.system.momentum(x).map(|(l, a)| {
                let dl: Vec<f64> = (0..3).map(|i| l[i] - l0[i]).collect();
                let da: Vec<f64> = (0..3).map(|i| a[i] - a0[i]).collect();
                (rel(norm(&dl), norm(&l0)), rel(norm(&da), norm(&a0)))
            })
        });
        if let (Some(m), Some(d)) = (self.max_energy.as_mut(), energy) {
            *m = m.max(d.abs());
        }
        if let (Some(m), Some(d)) = (self.max_momentum.as_mut(), momentum) {
            *m = (m.0.max(d.0.abs()), m.1.max(d.1.abs()));
        }
        (energy, momentum)
    }

    /// Moves the baselines by what the event of `report` changed (the payload's momentum in or
    /// out, the jump of energy) and switches the model to `params`.
    pub fn after_event(&mut self, report: &EventReport, params: Params<f64>) {
        self.system.set_params(params);
        if let Some(e) = self.energy0.as_mut() {
            *e += report.energy_change;
        }
        if let Some((l, a)) = self.momentum0.as_mut() {
            let sign = if report.kind == "capture" { 1.0 } else { -1.0 };
            for i in 0..3 {
                l[i] += sign * report.payload_linear_momentum[i];
                a[i] += sign * report.payload_angular_momentum[i];
            }
        }
    }
}
