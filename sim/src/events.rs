//! Payload capture and release at a given time on a free-floating base (`[[events]]` of a
//! scene): the velocity jump of a perfectly plastic capture, and the momentum the payloads carry
//! in and out, for the monitors.
//!
//! # Capture
//!
//! Just before the capture the system (base and arm, generalized velocity `ν⁻`, mass matrix `H`)
//! and the free payload (mass `m_p`, inertia `I_p` about its centre of mass, velocity `v_p` of
//! its centre of mass and angular velocity `ω_p`, inertial frame) move independently. The capture
//! is an impulsive internal constraint: from then on the payload moves with the capturing body,
//! its twist `J_p ν` (`J_p` the 6 × (6+N) Jacobian of the payload's centre-of-mass frame,
//! [`frames::floating_jacobian`]). The impulse equation of a perfectly plastic impact (no
//! rebound; e.g. Yoshida, Nenchev & Uchiyama, "Impact dynamics of space robots", and Brach,
//! *Mechanical Impact Dynamics*, ch. 7) keeps the generalized momentum of the combined system:
//!
//! `H' ν⁺ = H ν⁻ + J_pᵀ h_p`,  `h_p = [m_p v_p; R I_p Rᵀ ω_p]`,
//!
//! with `H' = H + J_pᵀ M_p J_p` the mass matrix with the payload merged into the body
//! (computed from the merged model, not by this sum). Rows `0..6` of `H ν` are the total linear
//! momentum and the angular momentum about the base origin (base coordinates), and rows `0..6`
//! of `J_pᵀ h_p` the payload's, so total linear and angular momentum are conserved exactly (to
//! rounding); kinetic energy is lost (the plastic impact's loss, reported as
//! [`EventReport::energy_change`]).
//!
//! # Release
//!
//! A release lets go of a payload the body holds with the body's motion: `ν` is unchanged (no
//! impulse), the model loses the payload, and the payload flies ballistically with constant
//! linear momentum and constant angular momentum about the inertial origin (a torque-free rigid
//! body: `x_c × m v_c` is constant since `ẋ_c = v_c`, and its spin momentum `I ω` about its
//! centre of mass is constant in the inertial frame). Its momentum is the system's momentum with
//! the payload minus without it, at the release state.
//!
//! # Monitors
//!
//! The momentum monitors compare the system's momentum with a baseline: the initial momentum plus
//! the momentum of every payload captured so far minus that of every payload released, i.e. the
//! total momentum of system and payloads is what is monitored. The energy baseline takes the
//! jump `E⁺ − E⁻` of each event (the plastic loss, or the kinetic energy the released payload
//! carries away).

use crate::scene::{Event, EventKind};
use crate::system::SceneSystem;
use kanegen_dynamics::algorithms::{floating, frames};
use kanegen_dynamics::base::{FloatingBase, FloatingState};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::{FrameParams, MassMatrixMethod, Params};
use kanegen_model::Inertial;
use serde::Serialize;

/// What one event did, in the summary of a run.
#[derive(Clone, Debug, Serialize)]
pub struct EventReport {
    /// Event time, s.
    pub t: f64,
    /// `capture` or `release`.
    pub kind: &'static str,
    /// The body that captured or released.
    pub body: String,
    /// Linear momentum of system and payload before the event (inertial frame).
    pub linear_momentum_before: [f64; 3],
    /// Angular momentum about the inertial origin of system and payload before the event.
    pub angular_momentum_before: [f64; 3],
    /// `|P⁺ − P⁻| / |P⁻|` (absolute when `P⁻ = 0`) of system and payload through the event.
    pub linear_momentum_error_rel: f64,
    /// `|L⁺ − L⁻| / |L⁻|` (absolute when `L⁻ = 0`) of system and payload through the event.
    pub angular_momentum_error_rel: f64,
    /// The system's kinetic energy after minus before, J (≤ 0 for a capture: the plastic loss;
    /// minus the released payload's kinetic energy for a release).
    pub energy_change: f64,
    /// The payload's linear momentum (inertial frame).
    pub payload_linear_momentum: [f64; 3],
    /// The payload's angular momentum about the inertial origin.
    pub payload_angular_momentum: [f64; 3],
}

/// `|a − b| / |b|` (absolute when `b = 0`).
#[must_use]
pub fn rel_diff(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    let n = b.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n == 0.0 {
        d
    } else {
        d / n
    }
}

/// `a + sign · b`.
#[must_use]
pub fn add(a: &[f64; 3], b: &[f64; 3], sign: f64) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i] + sign * b[i])
}

/// What a capture needs of the system: the mass-matrix method, the base body, its pose, the arm
/// positions, and the armature to add to a mass matrix.
pub struct CaptureSystem<'a> {
    /// How `H` is computed.
    pub method: MassMatrixMethod,
    /// The free-floating base body.
    pub base: &'a FloatingBase<f64>,
    /// The base pose and twist at the event.
    pub state: &'a FloatingState<f64>,
    /// Arm positions at the event.
    pub q: &'a [f64],
    /// Adds `[effects] rotor`'s armature to a `(6+N)` mass matrix (nothing without).
    pub armature: &'a dyn Fn(&mut [Vec<f64>]),
}

/// The post-capture generalized velocity `ν⁺` of the module doc's impulse equation (LDLᵀ
/// solve of `H'`) and the payload's momentum `(m v_p, x_c × m v_p + R I_p Rᵀ ω_p)` (inertial
/// frame, about the inertial origin), for a payload `payload` (in body `body`'s frame) moving
/// with `v`, `omega` (inertial) caught by body `body` of the system `before` (→ `after` with
/// the payload) at velocity `nu`.
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn capture(
    sys: &CaptureSystem<'_>,
    before: &Params<f64>,
    after: &Params<f64>,
    nu: &[f64],
    body: usize,
    payload: &Inertial,
    v: [f64; 3],
    omega: [f64; 3],
) -> (Vec<f64>, ([f64; 3], [f64; 3])) {
    let (q, st) = (sys.q, sys.state);
    let mut h = floating::mass_matrix(sys.method, before, sys.base, st, q);
    (sys.armature)(&mut h);
    let mut p: Vec<f64> = h
        .iter()
        .map(|row| row.iter().zip(nu).map(|(a, b)| a * b).sum())
        .collect();
    // The payload's centre-of-mass frame on the capturing body, its Jacobian and placement
    // (inertial frame).
    let frame = FrameParams {
        parent: Some(body),
        translation: Vec3::from_f64(payload.com),
        rotation: Mat3::identity(),
    };
    let jp = frames::floating_jacobian(before, st, q, &frame);
    let (xc, r) = frames::floating_placement(before, st, q, &frame);
    // Spin momentum R I_p Rᵀ ω_p about the payload's centre of mass.
    let i_body = Mat3::from_f64(payload.inertia);
    let spin = r.mul_vec(&i_body.mul_vec(&r.transpose().mul_vec(&Vec3::from_f64(omega))));
    let lin = Vec3::from_f64(v).scale(&payload.mass);
    let hp: Vec<f64> = lin.0.iter().chain(&spin.0).copied().collect();
    for (col, pk) in p.iter_mut().enumerate() {
        *pk += (0..6).map(|row| jp[row][col] * hp[row]).sum::<f64>();
    }
    let mut h_new = floating::mass_matrix(sys.method, after, sys.base, st, q);
    (sys.armature)(&mut h_new);
    let nu_new = kanegen_dynamics::ldlt::solve(&kanegen_dynamics::ldlt::ldlt(&h_new), &p);
    let ang = xc.cross(&lin) + spin;
    (nu_new, (lin.into_array(), ang.into_array()))
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
                    base: self.dynamics.base.as_ref().expect("free-floating"),
                    state: &st,
                    q,
                    armature: &armature,
                };
                let (nu, pay) = capture(
                    &sys,
                    &self.dynamics.params,
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
        self.dynamics.set_params(new_params);
        let after = self.momentum(x).expect("free-floating");
        // The released payload's momentum: the system's with it minus without it.
        let pay = if kind == "release" {
            (add(&pay.0, &after.0, -1.0), add(&pay.1, &after.1, -1.0))
        } else {
            pay
        };
        // System and payload, before and after: the payload is free before a capture and after
        // a release.
        let (total_before, total_after) = if kind == "capture" {
            (
                (add(&before.0, &pay.0, 1.0), add(&before.1, &pay.1, 1.0)),
                after,
            )
        } else {
            (
                before,
                (add(&after.0, &pay.0, 1.0), add(&after.1, &pay.1, 1.0)),
            )
        };
        EventReport {
            t: event.time,
            kind,
            body: self.scene.model.joints()[event.body].body.clone(),
            linear_momentum_before: total_before.0,
            angular_momentum_before: total_before.1,
            linear_momentum_error_rel: rel_diff(&total_after.0, &total_before.0),
            angular_momentum_error_rel: rel_diff(&total_after.1, &total_before.1),
            energy_change: self.kinetic_energy(x) - e_before,
            payload_linear_momentum: pay.0,
            payload_angular_momentum: pay.1,
        }
    }
}
