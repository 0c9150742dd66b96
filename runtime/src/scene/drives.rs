//! The joint torques a scene applies: its drive (none, constant, PD, or computed torque along a
//! quintic reference) minus joint viscous damping and regularized Coulomb friction,
//! `τ = τ_drive − b q̇ − τ_c tanh(q̇ / v_s)`.

use super::{Drive, SceneDynamics, SceneEffects};

/// The desired `(q_d, q̇_d, q̈_d)` of joint `i` of a computed-torque drive at `t`: the quintic
/// time scaling ([`crate::ode::quintic`]) from `q0` to `target`.
#[must_use]
#[inline(always)]
pub fn quintic_reference(q0: f64, target: f64, duration: f64, t: f64) -> (f64, f64, f64) {
    let (s, ds, dds) = crate::ode::quintic(t, duration);
    let d = target - q0;
    (q0 + s * d, ds * d, dds * d)
}

/// The applied joint torques at `(t, q, q̇)` into `tau` (`N`): the drive of `fx`, minus its
/// damping and Coulomb friction. `cmd` (`N`) is work memory (the commanded acceleration of a
/// computed-torque drive, whose inverse dynamics includes the wrenches `w` at `t`).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn drive_torques<D: SceneDynamics + ?Sized>(
    dynamics: &mut D,
    fx: &SceneEffects<'_>,
    t: f64,
    q: &[f64],
    qd: &[f64],
    w: &[f64],
    tau: &mut [f64],
    cmd: &mut [f64],
) {
    let n = tau.len();
    match fx.drive {
        Drive::None => tau.fill(0.0),
        Drive::Constant(c) => super::copy_into(tau, c),
        Drive::Pd { kp, kd, target } => {
            for i in 0..n {
                tau[i] = kp[i] * (target[i] - q[i]) - kd[i] * qd[i];
            }
        }
        Drive::ComputedTorque { .. } => {
            commanded_acceleration(&fx.drive, t, q, qd, cmd);
            dynamics.inverse(q, qd, cmd, w, tau);
        }
    }
    if let Some(b) = fx.damping {
        for i in 0..n {
            tau[i] -= b[i] * qd[i];
        }
    }
    if let Some(c) = fx.coulomb {
        let inv = 1.0 / c.v_s;
        for i in 0..n {
            tau[i] -= c.tau_c[i] * libm::tanh(qd[i] * inv);
        }
    }
}

/// The commanded acceleration `q̈_cmd = q̈_d + k_d (q̇_d − q̇) + k_p (q_d − q)` of a
/// computed-torque drive at `(t, q, q̇)` into `cmd` (nothing for another drive).
#[inline(always)]
pub fn commanded_acceleration(drive: &Drive<'_>, t: f64, q: &[f64], qd: &[f64], cmd: &mut [f64]) {
    if let Drive::ComputedTorque {
        kp,
        kd,
        q0,
        target,
        duration,
    } = *drive
    {
        for i in 0..cmd.len() {
            let (qr, qdr, qddr) = quintic_reference(q0[i], target[i], duration, t);
            cmd[i] = qddr + kd[i] * (qdr - qd[i]) + kp[i] * (qr - q[i]);
        }
    }
}
