//! A scene's right-hand side, composed once: the effects a scene names (drives, joint damping,
//! Coulomb friction, external wrenches, reflected rotor inertia, Spong's flexible joints, the
//! kinematics of a free-floating base) around the dynamics of a [`SceneDynamics`] provider.
//!
//! The interpreted simulator (`kanegen-sim`, the run-time algorithms over a model's numbers) and
//! the simulators `scene!` emits (a generated dynamics type, the effects as `const` data) call
//! the same [`deriv`]: only the provider differs. With `const` [`SceneEffects`] the optimizer
//! removes every effect a scene does not name from the emitted code.
//! [`linearize`] gives the Jacobians of the same right-hand side with joint torques as its input,
//! for the step Jacobians of MPC and iLQR.
//!
//! State layout (`q` positions, `v` speeds of the provider):
//! - fixed base `[q (N), q̇ (N)]`; with flexible joints `[q (N), q̇ (N), θ (N), θ̇ (N)]`, the
//!   motor coordinates last;
//! - free-floating base `[p₀ (3), quat (4: x, y, z, w), q (N), v_b (3), ω_b (3), q̇ (N)]`
//!   (Pinocchio's free-flyer layout, `v_b` and `ω_b` in base coordinates).
//!
//! Nothing here allocates or panics: the caller gives the work memory ([`work_len`]); a state,
//! derivative or work slice of the wrong length gives a NaN derivative.

mod armature;
mod capture;
mod drives;
mod floating;
pub mod linearize;
pub mod wrenches;

pub use armature::forward_with_armature;
pub use capture::{capture_velocity, CapturedPayload};
pub use drives::{drive_torques, quintic_reference};
pub use floating::floating_kinematics;
pub use linearize::{SceneControl, SceneDerivatives, WrenchBody};

/// The time profile of an external wrench: force and moment (N, N·m) in the frame the scene
/// names for it (the provider applies them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Profile<'a> {
    /// The same force and moment at all times.
    Constant {
        /// Force.
        force: [f64; 3],
        /// Moment.
        moment: [f64; 3],
    },
    /// Linear between samples, held outside the table ([`crate::ode::table`]).
    Table {
        /// Strictly increasing sample times, s.
        time: &'a [f64],
        /// Force at each sample.
        force: &'a [[f64; 3]],
        /// Moment at each sample.
        moment: &'a [[f64; 3]],
    },
}

impl Profile<'_> {
    /// `(force, moment)` at `t`.
    #[must_use]
    #[inline(always)]
    pub fn at(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        match *self {
            Profile::Constant { force, moment } => (force, moment),
            Profile::Table {
                time,
                force,
                moment,
            } => crate::ode::table(t, time, force, moment),
        }
    }
}

/// The joint drives of a scene (`N` values each).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive<'a> {
    /// No drive torques.
    None,
    /// Constant torques `τ`.
    Constant(&'a [f64]),
    /// `τ = kp (q_target − q) − kd q̇`.
    Pd {
        /// Proportional gains.
        kp: &'a [f64],
        /// Derivative gains.
        kd: &'a [f64],
        /// Target positions.
        target: &'a [f64],
    },
    /// Computed torque along the quintic from `q0` to `target` over `duration`:
    /// `τ = ID(q, q̇, q̈_d + kd (q̇_d − q̇) + kp (q_d − q))` with the scene's wrenches.
    ComputedTorque {
        /// Proportional gains.
        kp: &'a [f64],
        /// Derivative gains.
        kd: &'a [f64],
        /// Start of the quintic (the initial positions).
        q0: &'a [f64],
        /// End of the quintic.
        target: &'a [f64],
        /// Duration of the quintic, s.
        duration: f64,
    },
}

/// Regularized Coulomb friction `τ_c,i tanh(q̇_i / v_s)`, subtracted from the drive torque.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coulomb<'a> {
    /// Friction torques `τ_c,i`.
    pub tau_c: &'a [f64],
    /// Regularization speed `v_s > 0`.
    pub v_s: f64,
}

/// Spong's flexible joints (Spong 1987): a spring-damper between each link and its motor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flexible<'a> {
    /// Spring stiffnesses `K_i`.
    pub stiffness: &'a [f64],
    /// Spring dampings `D_i`.
    pub damping: &'a [f64],
    /// Reflected motor inertias `B_i = I_m,i n_i²`.
    pub reflected: &'a [f64],
}

/// The effects of a scene as plain data (what `scene!` writes as a `const`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneEffects<'a> {
    /// Joint degrees of freedom `N`.
    pub dof: usize,
    /// Whether the base is free-floating (state layout above).
    pub floating: bool,
    /// The drives.
    pub drive: Drive<'a>,
    /// Joint viscous damping `b_i` (`τ −= b q̇`).
    pub damping: Option<&'a [f64]>,
    /// Coulomb drive friction.
    pub coulomb: Option<Coulomb<'a>>,
    /// The external wrenches' profiles, in the provider's wrench order.
    pub wrenches: &'a [Profile<'a>],
    /// Reflected rotor inertia `I_m,i n_i²` on the joint diagonal of the mass matrix.
    pub armature: Option<&'a [f64]>,
    /// Flexible joints (fixed base).
    pub flexible: Option<Flexible<'a>>,
}

impl SceneEffects<'_> {
    /// `(positions, speeds)` of the provider: `(N, N)`, or `(7 + N, 6 + N)` free-floating.
    #[must_use]
    #[inline(always)]
    pub const fn sizes(&self) -> (usize, usize) {
        if self.floating {
            (7 + self.dof, 6 + self.dof)
        } else {
            (self.dof, self.dof)
        }
    }

    /// Length of the state vector.
    #[must_use]
    #[inline(always)]
    pub const fn dim(&self) -> usize {
        let (nq, nv) = self.sizes();
        nq + nv
            + if self.flexible.is_some() {
                2 * self.dof
            } else {
                0
            }
    }

    /// Length of the work memory [`deriv`] needs ([`work_len`] of these effects).
    #[must_use]
    #[inline(always)]
    pub const fn work_len(&self) -> usize {
        work_len(
            self.dof,
            self.sizes().1,
            self.wrenches.len(),
            self.armature.is_some(),
        )
    }
}

/// Length of the work memory of [`deriv`] for `dof` joints, `nv` speeds, `wrenches` wrenches
/// and (`armature`) reflected rotor inertia: `τ`, a second joint vector, the wrench values and,
/// with armature, the mass matrix, the right-hand side and the inverse pivots.
#[must_use]
pub const fn work_len(dof: usize, nv: usize, wrenches: usize, armature: bool) -> usize {
    2 * dof + 6 * wrenches + if armature { nv * nv + 2 * nv } else { 0 }
}

/// The dynamics a scene's right-hand side runs on: the interpreted run-time algorithms or a
/// generated type. Positions `q` and speeds `v` are the provider's (see the module doc);
/// `wrenches` holds 6 numbers a wrench of the scene (force then moment, in the frame the scene
/// names for it, in the order of [`SceneEffects::wrenches`]).
pub trait SceneDynamics {
    /// The accelerations `acc` (`v̇`) under joint torques `tau` (`N`) and the wrenches.
    fn forward(&mut self, q: &[f64], v: &[f64], tau: &[f64], wrenches: &[f64], acc: &mut [f64]);

    /// The joint-space mass matrix at `q`, row-major into `m` (`nv × nv`).
    fn mass_matrix(&mut self, q: &[f64], m: &mut [f64]);

    /// Inverse dynamics of a fixed base: the torques `tau` that give the joint accelerations
    /// `qdd` at `(q, q̇)` under the wrenches.
    fn inverse(&mut self, q: &[f64], qd: &[f64], qdd: &[f64], wrenches: &[f64], tau: &mut [f64]);

    /// [`SceneDynamics::forward`] with `armature` (`N`) added to the joint diagonal of the
    /// mass matrix. Default: [`forward_with_armature`] (the mass matrix, then LDLᵀ);
    /// a provider whose algorithm takes an armature (the articulated-body algorithm) does it
    /// there.
    #[allow(clippy::too_many_arguments)]
    fn forward_armature(
        &mut self,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        wrenches: &[f64],
        armature: &[f64],
        acc: &mut [f64],
        work: &mut [f64],
    ) {
        forward_with_armature(self, q, v, tau, wrenches, armature, acc, work);
    }
}

/// The state derivative `dx = f(t, x)` of a scene with effects `fx` over `dynamics`, with
/// `work` of [`SceneEffects::work_len`] (or more). Steps: the wrenches at `t`, the drive
/// torques minus damping and friction on the joints the drives act on (the motors with flexible
/// joints), the springs of flexible joints, the accelerations (with armature), the kinematics.
#[inline(always)]
pub fn deriv<D: SceneDynamics + ?Sized>(
    dynamics: &mut D,
    fx: &SceneEffects<'_>,
    t: f64,
    x: &[f64],
    dx: &mut [f64],
    work: &mut [f64],
) {
    deriv_input(dynamics, fx, t, x, &[], dx, work);
}

/// [`deriv`] with the input `u`: joint torques added to the drive's (to the motors' with
/// flexible joints); `u` of length `N`, or empty for none.
#[inline(always)]
pub fn deriv_input<D: SceneDynamics + ?Sized>(
    dynamics: &mut D,
    fx: &SceneEffects<'_>,
    t: f64,
    x: &[f64],
    u: &[f64],
    dx: &mut [f64],
    work: &mut [f64],
) {
    let (n, (nq, nv)) = (fx.dof, fx.sizes());
    let dim = fx.dim();
    let u_ok = u.is_empty() || u.len() == n;
    if x.len() != dim || dx.len() != dim || work.len() < fx.work_len() || !u_ok {
        dx.fill(f64::NAN);
        return;
    }
    let (q, rest) = x.split_at(nq);
    let (v, motors) = rest.split_at(nv);
    let (tau, work) = work.split_at_mut(n);
    let (aux, work) = work.split_at_mut(n);
    let (w, work) = work.split_at_mut(6 * fx.wrenches.len());
    wrench_values(fx.wrenches, t, w);
    let (dq, rest) = dx.split_at_mut(nq);
    let (acc, dmotors) = rest.split_at_mut(nv);
    match fx.flexible {
        None => {
            drive_torques(dynamics, fx, t, &q[nq - n..], &v[nv - n..], w, tau, aux);
            add_input(tau, u);
        }
        Some(f) => {
            // Spong's model: the drives act on the motors, the springs on the links.
            let (th, thd) = motors.split_at(n);
            drive_torques(dynamics, fx, t, th, thd, w, aux, tau);
            add_input(aux, u);
            flexible_joints(&f, q, v, th, thd, aux, tau, dmotors);
        }
    }
    match fx.armature {
        None => dynamics.forward(q, v, tau, w, acc),
        Some(arm) => dynamics.forward_armature(q, v, tau, w, arm, acc, work),
    }
    if fx.floating {
        floating_kinematics(q, v, dq);
    } else {
        dq.copy_from_slice(v);
    }
}

/// A provider whose scene's effects are known at compile time (what `scene!` emits): the
/// right-hand side of [`SceneOde`] over it is specialized to them, every effect the scene
/// does not name removed by the optimizer.
pub trait SceneModel: SceneDynamics {
    /// The scene's effects.
    const EFFECTS: SceneEffects<'static>;
}

/// The right-hand side of a scene ([`deriv`] of [`SceneModel::EFFECTS`] over `dynamics`, in
/// `work`) as an [`ode::System`](crate::ode::System): the integrators call [`deriv`] on their
/// own state slices. On a free-floating base the quaternion is renormalized by
/// [`System::project`](crate::ode::System::project) and advanced by the exponential map
/// ([`crate::ode::quaternion::advance_floating`]).
#[derive(Debug)]
pub struct SceneOde<'a, D> {
    /// The provider of the dynamics and the effects.
    pub dynamics: D,
    /// Work memory of [`SceneEffects::work_len`] (or more).
    pub work: &'a mut [f64],
}

impl<D: SceneModel> crate::ode::System for SceneOde<'_, D> {
    #[inline(always)]
    fn dim(&self) -> usize {
        D::EFFECTS.dim()
    }

    #[inline]
    fn deriv(&mut self, t: f64, x: &[f64], dx: &mut [f64]) {
        deriv(&mut self.dynamics, &D::EFFECTS, t, x, dx, self.work);
    }

    fn project(&self, x: &mut [f64]) {
        if D::EFFECTS.floating {
            crate::ode::quaternion::normalize_quaternion(x);
        }
    }

    fn advance(&self, x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
        if D::EFFECTS.floating {
            crate::ode::quaternion::advance_floating(x, h, at, f, out);
        } else {
            crate::ode::quaternion::advance_additive(x, h, f, out);
        }
    }
}

/// `tau += u` (nothing for an empty `u`).
#[inline(always)]
fn add_input(tau: &mut [f64], u: &[f64]) {
    for (t, ui) in tau.iter_mut().zip(u) {
        *t += ui;
    }
}

/// Each wrench's `(force, moment)` at `t` into `w` (6 a wrench).
#[inline(always)]
fn wrench_values(profiles: &[Profile<'_>], t: f64, w: &mut [f64]) {
    for (p, wk) in profiles.iter().zip(w.chunks_exact_mut(6)) {
        let (f, m) = p.at(t);
        wk[..3].copy_from_slice(&f);
        wk[3..].copy_from_slice(&m);
    }
}

/// Spong's flexible joints (Spong 1987, "Modeling and control of elastic joint robots"): the
/// spring torque `τ_s = K (θ − q) + D (θ̇ − q̇)` into `tau_s` (what loads the links) and the
/// motor derivative `[θ̇, (τ_m − τ_s) / B]` into `dmotors`, `τ_m` the motor torque.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn flexible_joints(
    f: &Flexible<'_>,
    q: &[f64],
    qd: &[f64],
    th: &[f64],
    thd: &[f64],
    tau_m: &[f64],
    tau_s: &mut [f64],
    dmotors: &mut [f64],
) {
    let n = tau_s.len();
    let (dth, dthd) = dmotors.split_at_mut(n);
    dth.copy_from_slice(thd);
    for i in 0..n {
        tau_s[i] = f.stiffness[i] * (th[i] - q[i]) + f.damping[i] * (thd[i] - qd[i]);
        dthd[i] = (tau_m[i] - tau_s[i]) / f.reflected[i];
    }
}

/// Copies `src` into `dst` entry by entry as far as both go (the forwards of a generated
/// provider, whose arrays have the slices' lengths).
#[inline(always)]
pub fn copy_into(dst: &mut [f64], src: &[f64]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d = *s;
    }
}
