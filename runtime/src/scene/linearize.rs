//! The Jacobians of a scene's right-hand side with an input, `ẋ = f(t, x, u)`, `u` the joint
//! torques added to the scene's own drive: `F = ∂f/∂x` and `G = ∂f/∂u` from the provider's
//! derivatives of forward dynamics ([`SceneDerivatives`]) and the drive's own derivatives, so
//! [`crate::ode::linearize`] gives the exact Jacobians of one step.
//!
//! With `x = [q, q̇]` and the applied torques `τ(t, q, q̇) + u` (module [`super::drives`]):
//!
//! ```text
//! F = [ 0                        I                      ]     G = [ 0   ]
//!     [ ∂q̈/∂q + M⁻¹ ∂τ/∂q       ∂q̈/∂q̇ + M⁻¹ ∂τ/∂q̇     ]         [ M⁻¹ ]
//! ```
//!
//! with `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` of forward dynamics at the applied torques (Carpentier &
//! Mansard, RSS 2018, eq. (3); with rotor inertia, of `M + diag(armature)`, from the
//! inverse-dynamics derivatives and LDLᵀ solves) and the drive's `∂τ`: `−diag(k_p)`, `−diag(k_d)` for PD;
//! `∂ID/∂q − M diag(k_p)`, `∂ID/∂q̇ − M diag(k_d)` for computed torque; `−diag(b)` of joint
//! damping and `−diag(τ_c / v_s · sech²(q̇ / v_s))` of Coulomb friction on `∂τ/∂q̇`.
//!
//! Covered ([`linearizable`]): a fixed base without external wrenches or flexible joints.

// Index loops over matrix entries.
#![allow(clippy::needless_range_loop)]

use super::{deriv_input, drive_torques, Drive, SceneDynamics, SceneEffects};
use crate::ldlt::{factor_in_place, solve_in_place};
use crate::ode::ControlledSystem;

/// The derivatives of a provider's dynamics (no external wrench), row-major `N × N` each.
pub trait SceneDerivatives: SceneDynamics {
    /// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` of forward dynamics at `(q, q̇, τ)` into `dq`, `dv`, `minv`.
    fn forward_derivatives(
        &mut self,
        q: &[f64],
        v: &[f64],
        tau: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
        minv: &mut [f64],
    );

    /// `(∂τ/∂q, ∂τ/∂q̇)` of inverse dynamics at `(q, q̇, q̈)` into `dq`, `dv`.
    fn inverse_derivatives(
        &mut self,
        q: &[f64],
        v: &[f64],
        qdd: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    );
}

/// `Ok` when [`deriv_jacobians`] covers the effects `fx`; else what it does not cover.
///
/// # Errors
/// The first effect not covered, in words.
pub const fn linearizable(fx: &SceneEffects<'_>) -> Result<(), &'static str> {
    if fx.floating {
        Err("a free-floating base (its quaternion has no additive step Jacobian here)")
    } else if !fx.wrenches.is_empty() {
        Err("external wrenches")
    } else if fx.flexible.is_some() {
        Err("flexible joints")
    } else {
        Ok(())
    }
}

/// Length of the work memory of [`deriv_jacobians`]: that of the right-hand side and six
/// `N × N` matrices.
#[must_use]
pub const fn jacobian_work_len(fx: &SceneEffects<'_>) -> usize {
    fx.work_len() + 6 * fx.dof * fx.dof + fx.dof
}

/// `f(t, x, u)` into `dx` (as [`deriv_input`]), `∂f/∂x` into `fxm` (`d × d`, row-major) and
/// `∂f/∂u` into `fum` (`d × N`), `work` of [`jacobian_work_len`] (module doc). Effects that
/// [`linearizable`] refuses, or slices of the wrong length, give NaN.
#[allow(clippy::too_many_arguments)]
pub fn deriv_jacobians<D: SceneDerivatives + ?Sized>(
    dynamics: &mut D,
    fx: &SceneEffects<'_>,
    t: f64,
    x: &[f64],
    u: &[f64],
    dx: &mut [f64],
    fxm: &mut [f64],
    fum: &mut [f64],
    work: &mut [f64],
) {
    let (n, d) = (fx.dof, fx.dim());
    if linearizable(fx).is_err()
        || fxm.len() != d * d
        || fum.len() != d * n
        || u.len() != n
        || work.len() < jacobian_work_len(fx)
    {
        dx.fill(f64::NAN);
        fxm.fill(f64::NAN);
        fum.fill(f64::NAN);
        return;
    }
    let (rhs_work, work) = work.split_at_mut(fx.work_len());
    deriv_input(dynamics, fx, t, x, u, dx, rhs_work);
    let (q, qd) = x.split_at(n);
    let [tq, tv, dq, dv, minv, mm] = matrices(work, n);
    let (tau, rest) = rhs_work.split_at_mut(n);
    drive_torques(dynamics, fx, t, q, qd, &[], tau, &mut mm[..n]);
    for (ti, ui) in tau.iter_mut().zip(u) {
        *ti += ui;
    }
    drive_jacobians(dynamics, fx, t, q, qd, tq, tv, mm);
    match fx.armature {
        None => dynamics.forward_derivatives(q, qd, tau, dq, dv, minv),
        Some(a) => {
            // The scene's own work holds `nv² + 2 nv` more with an armature ([`work_len`]).
            let (d_inv, col) = rest[..2 * n].split_at_mut(n);
            let qdd = &dx[n..];
            let f = [&mut *dq, &mut *dv, &mut *minv];
            armature_derivatives(dynamics, q, qd, qdd, a, f, &mut mm[..n * n], d_inv, col);
        }
    }
    // F: the kinematic rows [0 I], then ∂q̈ + M⁻¹ ∂τ; G: [0; M⁻¹].
    fxm.fill(0.0);
    fum.fill(0.0);
    for i in 0..n {
        fxm[i * d + n + i] = 1.0;
        for j in 0..n {
            let (mut sq, mut sv) = (dq[i * n + j], dv[i * n + j]);
            for k in 0..n {
                sq += minv[i * n + k] * tq[k * n + j];
                sv += minv[i * n + k] * tv[k * n + j];
            }
            fxm[(n + i) * d + j] = sq;
            fxm[(n + i) * d + n + j] = sv;
            fum[(n + i) * n + j] = minv[i * n + j];
        }
    }
}

/// `(∂q̈/∂q, ∂q̈/∂q̇, (M + A)⁻¹)` into `f` with the armature `A = diag(a)` on the joint diagonal
/// (RBDA Sec. 9.1): `(M + A) q̈ = τ − c` differentiated at fixed `τ` is
/// `(M + A) ∂q̈ = −∂ID/∂x` with `ID(q, q̇, q̈) = M q̈ + c` (no armature) at the scene's `q̈`
/// (Carpentier & Mansard, RSS 2018, eq. (3), with `M + A` for `M`): the provider's
/// inverse-dynamics derivatives, then LDLᵀ solves ([`crate::ldlt`]) of `M + A` column by column.
/// `m` (`N²`), `d_inv` and `col` (`N` each) are work memory; a pivot that is not positive gives
/// NaN.
#[allow(clippy::too_many_arguments)]
fn armature_derivatives<D: SceneDerivatives + ?Sized>(
    dynamics: &mut D,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    a: &[f64],
    f: [&mut [f64]; 3],
    m: &mut [f64],
    d_inv: &mut [f64],
    col: &mut [f64],
) {
    let n = q.len();
    let [dq, dv, minv] = f;
    dynamics.inverse_derivatives(q, qd, qdd, dq, dv);
    dynamics.mass_matrix(q, m);
    for (i, ai) in a.iter().enumerate() {
        m[i * n + i] += ai;
    }
    if factor_in_place(m, n, d_inv).is_err() || !d_inv.iter().all(|d| *d > 0.0 && d.is_finite()) {
        for x in [dq, dv, minv] {
            x.fill(f64::NAN);
        }
        return;
    }
    // Column j of each result: `(M + A)⁻¹` times column j of `−∂ID/∂q`, `−∂ID/∂q̇`, `I`.
    for (x, sign) in [(dq, -1.0), (dv, -1.0), (minv, 0.0)] {
        for j in 0..n {
            for i in 0..n {
                col[i] = if sign == 0.0 {
                    f64::from(u8::from(i == j))
                } else {
                    sign * x[i * n + j]
                };
            }
            // Lengths hold: `m` is `N²`, `d_inv` and `col` `N`.
            let _ = solve_in_place(m, n, d_inv, col);
            for i in 0..n {
                x[i * n + j] = col[i];
            }
        }
    }
}

/// Six `N × N` matrices at the start of `work`.
fn matrices(work: &mut [f64], n: usize) -> [&mut [f64]; 6] {
    let (a, w) = work.split_at_mut(n * n);
    let (b, w) = w.split_at_mut(n * n);
    let (c, w) = w.split_at_mut(n * n);
    let (d, w) = w.split_at_mut(n * n);
    let (e, w) = w.split_at_mut(n * n);
    [a, b, c, d, e, &mut w[..n * n + n]]
}

/// `∂τ/∂q` into `tq` and `∂τ/∂q̇` into `tv` of the applied torques `τ(t, q, q̇)` of the drive,
/// damping and friction of `fx` (module doc); `mm` (`N² + N`) is work memory.
#[allow(clippy::too_many_arguments)]
fn drive_jacobians<D: SceneDerivatives + ?Sized>(
    dynamics: &mut D,
    fx: &SceneEffects<'_>,
    t: f64,
    q: &[f64],
    qd: &[f64],
    tq: &mut [f64],
    tv: &mut [f64],
    mm: &mut [f64],
) {
    let n = fx.dof;
    tq.fill(0.0);
    tv.fill(0.0);
    match fx.drive {
        Drive::None | Drive::Constant(_) => {}
        Drive::Pd { kp, kd, .. } => {
            for i in 0..n {
                tq[i * n + i] = -kp[i];
                tv[i * n + i] = -kd[i];
            }
        }
        Drive::ComputedTorque { kp, kd, .. } => {
            // τ = ID(q, q̇, q̈_cmd), q̈_cmd = q̈_d + k_d (q̇_d − q̇) + k_p (q_d − q).
            let (m, cmd) = mm.split_at_mut(n * n);
            super::drives::commanded_acceleration(&fx.drive, t, q, qd, cmd);
            dynamics.inverse_derivatives(q, qd, cmd, tq, tv);
            dynamics.mass_matrix(q, m);
            for i in 0..n {
                for j in 0..n {
                    tq[i * n + j] -= m[i * n + j] * kp[j];
                    tv[i * n + j] -= m[i * n + j] * kd[j];
                }
            }
        }
    }
    if let Some(b) = fx.damping {
        for i in 0..n {
            tv[i * n + i] -= b[i];
        }
    }
    if let Some(c) = fx.coulomb {
        let inv = 1.0 / c.v_s;
        for i in 0..n {
            let th = libm::tanh(qd[i] * inv);
            tv[i * n + i] -= c.tau_c[i] * inv * (1.0 - th * th);
        }
    }
}

/// A scene's right-hand side with the joint torques `u` as its input, as a
/// [`ControlledSystem`] (what [`crate::ode::rk4_step_jacobians`] and
/// [`crate::ode::midpoint_step_jacobians`] linearize). `scene!` passes its `const` effects
/// (`&Name::EFFECTS`), the interpreted simulator the scene's.
#[derive(Debug)]
pub struct SceneControl<'a, 'e, D: ?Sized> {
    /// The provider of the dynamics and their derivatives.
    pub dynamics: &'a mut D,
    /// The scene's effects.
    pub effects: &'a SceneEffects<'e>,
    /// Work memory of [`jacobian_work_len`] (or more).
    pub work: &'a mut [f64],
}

impl<D: SceneDerivatives + ?Sized> ControlledSystem for SceneControl<'_, '_, D> {
    fn dim(&self) -> usize {
        self.effects.dim()
    }

    fn inputs(&self) -> usize {
        self.effects.dof
    }

    fn deriv(&mut self, t: f64, x: &[f64], u: &[f64], dx: &mut [f64]) {
        deriv_input(self.dynamics, self.effects, t, x, u, dx, self.work);
    }

    fn jacobians(
        &mut self,
        t: f64,
        x: &[f64],
        u: &[f64],
        dx: &mut [f64],
        fx: &mut [f64],
        fu: &mut [f64],
    ) {
        let e = self.effects;
        deriv_jacobians(self.dynamics, e, t, x, u, dx, fx, fu, self.work);
    }
}
