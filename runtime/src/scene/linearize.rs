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
//! On a free-floating base, `x = [p₀, quat, q, v_b, ω_b, q̇]` and the same blocks take the base's
//! speeds in (`(∂ν̇/∂q, ∂ν̇/∂ν, M⁻¹)`, `(6 + N)²`, of which the `N` joint columns of `M⁻¹` are
//! `∂ν̇/∂u`), around the derivatives of the kinematics ([`floating_kinematics`]) over the
//! quaternion's four numbers: `ṗ₀ = R(quat) v_b`, `q̇uat = ½ quat ⊗ (ω_b, 0)`, and gravity, the
//! one place the dynamics read the pose: a uniform field accelerates every body alike, so
//! `ν̇ = ν̇|_{g=0} + [R(quat)ᵀ g; 0; 0]` and `∂ν̇/∂quat = [∂(R(quat)ᵀ g)/∂quat; 0; 0]`
//! ([`rotation_jacobian`]), exact at any quaternion the RK4 stages reach, unit or not.
//! [`crate::ode::floating_rk4_step_jacobians`] takes these to the tangent space.
//!
//! With Spong's flexible joints, `x = [q, q̇, θ, θ̇]`: the links under the springs, the motors
//! under the drive (`flexible_jacobians`).
//!
//! External wrenches load the speeds by `τ_ext(q) = Σ J_wᵀ [F_w; n_w]` (base coordinates),
//! which depends on `q` ([`super::wrenches`]): then, and with rotor inertia, the acceleration
//! rows come from `(M + A) ∂ν̇ = ∂τ_ext − ∂ID` at the scene's `ν̇` (inverse-dynamics derivatives
//! and LDLᵀ solves, `implicit_derivatives`), and a computed-torque drive, which cancels the
//! wrenches, has `∂τ/∂q −= ∂τ_ext/∂q`. On a free-floating base a wrench fixed in the inertial
//! frame is `R(quat)ᵀ [F; n]` in base coordinates, so it adds
//! `(M + A)⁻¹ J_wᵀ ∂(R(quat)ᵀ [F; n])/∂quat` to the attitude columns, as gravity does.
//!
//! [`floating_kinematics`]: super::floating_kinematics
//! [`rotation_jacobian`]: crate::ode::quaternion::rotation_jacobian

// Index loops over matrix entries.
#![allow(clippy::needless_range_loop)]

use super::floating::floating_kinematics_jacobian;
use super::wrenches::{add_wrench_torque_derivatives, rotate, rotate_back};
use super::{deriv_input, drive_torques, Drive, Flexible, SceneDynamics, SceneEffects};
use crate::ldlt::{factor_in_place, solve_in_place};
use crate::ode::quaternion::quat_to_matrix;
use crate::ode::quaternion::rotation_jacobian;
use crate::ode::ControlledSystem;

/// The derivatives of a provider's dynamics (without external wrenches: their part is
/// [`super::wrenches`]), row-major `N × N` each.
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

    /// The gravity `g` the dynamics apply, in the inertial frame on a free-floating base (the
    /// frame the base's quaternion turns; read there only), zero for none.
    fn gravity(&self) -> [f64; 3];

    /// `(∂τ/∂q, ∂τ/∂q̇)` of inverse dynamics at `(q, q̇, q̈)` into `dq`, `dv`.
    fn inverse_derivatives(
        &mut self,
        q: &[f64],
        v: &[f64],
        qdd: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    );

    /// The body that wrench `k` of the scene acts on, at `q`: the Jacobian of its origin into
    /// `jac` (`6 × nv`, row-major, rows `[v; ω]` in base coordinates, Pinocchio's
    /// `LOCAL_WORLD_ALIGNED` of a fixed base; on a free-floating base that of the base at the
    /// inertial origin unturned, the base's columns `[e_m; 0]` and `[e_m × x; e_m]`), its
    /// rotation in base coordinates and the wrench's frame returned. NaN where the provider has
    /// no frame for it.
    fn wrench_body(&mut self, k: usize, q: &[f64], jac: &mut [f64]) -> WrenchBody;
}

/// The body a wrench acts on, at a configuration ([`SceneDerivatives::wrench_body`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WrenchBody {
    /// The body's rotation `R` in base coordinates, `x_base = R x_body`.
    pub rotation: [[f64; 3]; 3],
    /// Whether the wrench is given in the body's frame (it turns with the body), else in the
    /// base frame.
    pub body_fixed: bool,
}

/// Length of the work memory of [`deriv_jacobians`]: that of the right-hand side, two
/// `N × N` and four `nv × nv` matrices and a vector of speeds; with wrenches `∂τ_ext/∂q`
/// (`nv × nv`), a Jacobian (`6 × nv`) and `∂τ_ext/∂quat` (`nv × 4`); with wrenches or an
/// armature two more vectors of speeds.
#[must_use]
pub const fn jacobian_work_len(fx: &SceneEffects<'_>) -> usize {
    let (n, nv) = (fx.dof, fx.sizes().1);
    let wrenches = if fx.wrenches.is_empty() {
        0
    } else {
        nv * nv + 10 * nv
    };
    let implicit = if implicit(fx) { 2 * nv } else { 0 };
    fx.work_len() + 2 * n * n + 4 * nv * nv + nv + wrenches + implicit
}

/// Whether the acceleration rows come from the inverse-dynamics derivatives
/// (`implicit_derivatives`): with an armature or wrenches.
const fn implicit(fx: &SceneEffects<'_>) -> bool {
    fx.armature.is_some() || !fx.wrenches.is_empty()
}

/// `f(t, x, u)` into `dx` (as [`deriv_input`]), `∂f/∂x` into `fxm` (`d × d`, row-major) and
/// `∂f/∂u` into `fum` (`d × N`), `work` of [`jacobian_work_len`] (module doc). Slices of the
/// wrong length give NaN.
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
    let (n, d, (nq, nv)) = (fx.dof, fx.dim(), fx.sizes());
    if fxm.len() != d * d
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
    let (q, rest) = x.split_at(nq);
    let (v, motors) = rest.split_at(nv);
    // The coordinates the drive acts on: the joints', or the motors' with flexible joints.
    let (dq_drive, dv_drive) = match fx.flexible {
        None => (&q[nq - n..], &v[nv - n..]),
        Some(_) => motors.split_at(n),
    };
    let [tq, tv, mm, dq, dv, minv, tail] = matrices(work, n, nv);
    let (tau, rest) = rhs_work.split_at_mut(n);
    // ∂τ_ext/∂q and ∂τ_ext/∂quat of the wrench values `deriv_input` left after `τ` and a
    // joint vector.
    let (ext, tail) = tail.split_at_mut(if fx.wrenches.is_empty() { 0 } else { nv * nv });
    let (jac, tail) = tail.split_at_mut(if ext.is_empty() { 0 } else { 6 * nv });
    let (equat, tail) = tail.split_at_mut(if ext.is_empty() { 0 } else { 4 * nv });
    let ext = if ext.is_empty() {
        None
    } else {
        let w = &rest[n..n + 6 * fx.wrenches.len()];
        wrench_torque_derivatives(dynamics, fx.floating, q, w, [&mut *ext, jac, &mut *equat]);
        Some(&*ext)
    };
    drive_torques(dynamics, fx, t, dq_drive, dv_drive, &[], tau, &mut mm[..n]);
    for (ti, ui) in tau.iter_mut().zip(u) {
        *ti += ui;
    }
    drive_jacobians(dynamics, fx, t, dq_drive, dv_drive, ext, tq, tv, mm);
    // The torques the links move under: the springs' with flexible joints.
    let applied = match fx.flexible {
        None => &*tau,
        Some(f) => {
            let (th, thd) = motors.split_at(n);
            let springs = &mut rest[..n];
            for i in 0..n {
                springs[i] = f.stiffness[i] * (th[i] - q[i]) + f.damping[i] * (thd[i] - v[i]);
            }
            &*springs
        }
    };
    if implicit(fx) {
        let (d_inv, col) = tail[..2 * nv].split_at_mut(nv);
        let qdd = &dx[nq..nq + nv];
        let f = [&mut *dq, &mut *dv, &mut *minv];
        let m = &mut mm[..nv * nv];
        implicit_derivatives(dynamics, [q, v, qdd], fx.armature, ext, f, m, d_inv, col);
    } else {
        dynamics.forward_derivatives(q, v, applied, dq, dv, minv);
    }
    if let Some(f) = fx.flexible {
        return flexible_jacobians(&f, [tq, tv], [dq, dv, minv], fxm, fum);
    }
    fxm.fill(0.0);
    fum.fill(0.0);
    // The kinematic rows: `[0 I]`, or those of the free-floating base.
    if fx.floating {
        floating_kinematics_jacobian(q, v, fxm);
    } else {
        for i in 0..n {
            fxm[i * d + n + i] = 1.0;
        }
    }
    // The acceleration rows: `∂ν̇ + M⁻¹ ∂τ` on the joints, `M⁻¹` (joint columns) for `u`.
    let b = nv - n;
    for i in 0..nv {
        let (row, mrow) = (
            &mut fxm[(nq + i) * d..(nq + i + 1) * d],
            &minv[i * nv + b..],
        );
        let drive = |m: &[f64], j: usize| (0..n).map(|k| mrow[k] * m[k * n + j]).sum::<f64>();
        for j in 0..n {
            row[nq - n + j] = dq[i * nv + b + j] + drive(tq, j);
            fum[(nq + i) * n + j] = mrow[j];
        }
        for c in 0..nv {
            row[nq + c] = dv[i * nv + c] + if c >= b { drive(tv, c - b) } else { 0.0 };
        }
    }
    if fx.floating {
        // ∂ν̇/∂quat = [∂(R(quat)ᵀ g)/∂quat; 0; 0] (module doc).
        let quat = [q[3], q[4], q[5], q[6]];
        let dg = rotation_jacobian(&quat, &dynamics.gravity(), true);
        for (r, dr) in dg.iter().enumerate() {
            fxm[(nq + r) * d + 3..(nq + r) * d + 7].copy_from_slice(dr);
        }
        // Wrenches fixed in the inertial frame: (M + A)⁻¹ ∂τ_ext/∂quat.
        for i in 0..nv.min(equat.len() / 4) {
            for c in 0..4 {
                let e = (0..nv).map(|k| minv[i * nv + k] * equat[k * 4 + c]);
                fxm[(nq + i) * d + 3 + c] += e.sum::<f64>();
            }
        }
    }
}

/// `F` (`4N × 4N`) and `G` (`4N × N`) of Spong's flexible joints, `x = [q, q̇, θ, θ̇]`, the
/// links under the springs `τ_s = K (θ − q) + D (θ̇ − q̇)` and the motors under the drive
/// `τ_m(θ, θ̇) + u` (`θ̈ = B⁻¹ (τ_m − τ_s)`), from the drive's `∂τ_m/∂θ`, `∂τ_m/∂θ̇`
/// (`drive`) and `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` of forward dynamics at `τ_s` (`links`), `K`, `D`, `B`
/// diagonal:
///
/// ```text
/// F = [ 0                  I                  0                    0                   ]
///     [ ∂q̈/∂q − M⁻¹K       ∂q̈/∂q̇ − M⁻¹D       M⁻¹K                 M⁻¹D                ]
///     [ 0                  0                  0                    I                   ]
///     [ B⁻¹K               B⁻¹D               B⁻¹(∂τ_m/∂θ − K)     B⁻¹(∂τ_m/∂θ̇ − D)    ]
/// G = [0; 0; 0; B⁻¹]
/// ```
fn flexible_jacobians(
    f: &Flexible<'_>,
    [tq, tv]: [&mut [f64]; 2],
    [dq, dv, minv]: [&mut [f64]; 3],
    fxm: &mut [f64],
    fum: &mut [f64],
) {
    let n = f.stiffness.len();
    let d = 4 * n;
    let (k, c, b) = (f.stiffness, f.damping, f.reflected);
    fxm.fill(0.0);
    fum.fill(0.0);
    for i in 0..n {
        fxm[i * d + n + i] = 1.0;
        fxm[(2 * n + i) * d + 3 * n + i] = 1.0;
        let (link, motor) = ((n + i) * d, (3 * n + i) * d);
        for j in 0..n {
            let m = minv[i * n + j];
            fxm[link + j] = dq[i * n + j] - m * k[j];
            fxm[link + n + j] = dv[i * n + j] - m * c[j];
            fxm[link + 2 * n + j] = m * k[j];
            fxm[link + 3 * n + j] = m * c[j];
            let (kd, cd) = if i == j { (k[i], c[i]) } else { (0.0, 0.0) };
            fxm[motor + j] = kd / b[i];
            fxm[motor + n + j] = cd / b[i];
            fxm[motor + 2 * n + j] = (tq[i * n + j] - kd) / b[i];
            fxm[motor + 3 * n + j] = (tv[i * n + j] - cd) / b[i];
        }
        fum[(3 * n + i) * n + i] = 1.0 / b[i];
    }
}

/// `(∂ν̇/∂q, ∂ν̇/∂ν, (M + A)⁻¹)` into `f` (`nv × nv` each) with the armature `A = diag(a)` on
/// the joint diagonal (RBDA Sec. 9.1; the base of a free-floating one has none) and the joint
/// torques of external wrenches `τ_ext(q)` on a fixed base (`ext` = `∂τ_ext/∂q`):
/// `(M + A) ν̇ = τ + τ_ext − c` differentiated at fixed `τ` is
/// `(M + A) ∂ν̇ = ∂τ_ext − ∂ID/∂x` with `ID(q, ν, ν̇) = M ν̇ + c` (no armature, no wrench) at the
/// scene's `ν̇` (Carpentier & Mansard, RSS 2018, eq. (3), with `M + A` for `M`): the provider's
/// inverse-dynamics derivatives, then LDLᵀ solves ([`crate::ldlt`]) of `M + A` column by
/// column. `m` (`nv²`), `d_inv` and `col` (`nv` each) are work memory; a pivot that is not
/// positive gives NaN.
#[allow(clippy::too_many_arguments)]
fn implicit_derivatives<D: SceneDerivatives + ?Sized>(
    dynamics: &mut D,
    [q, qd, qdd]: [&[f64]; 3],
    a: Option<&[f64]>,
    ext: Option<&[f64]>,
    f: [&mut [f64]; 3],
    m: &mut [f64],
    d_inv: &mut [f64],
    col: &mut [f64],
) {
    let n = qd.len();
    let [dq, dv, minv] = f;
    dynamics.inverse_derivatives(q, qd, qdd, dq, dv);
    if let Some(ext) = ext {
        for (d, e) in dq.iter_mut().zip(ext) {
            *d -= e;
        }
    }
    dynamics.mass_matrix(q, m);
    let a = a.unwrap_or(&[]);
    let b = n - a.len();
    for (i, ai) in a.iter().enumerate() {
        m[(b + i) * n + b + i] += ai;
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
            // Lengths hold: `m` is `nv²`, `d_inv` and `col` `nv`.
            let _ = solve_in_place(m, n, d_inv, col);
            for i in 0..n {
                x[i * n + j] = col[i];
            }
        }
    }
}

/// At the start of `work`: two `N × N` matrices, one of `nv² + nv`, three `nv × nv`; then the
/// rest.
fn matrices(work: &mut [f64], n: usize, nv: usize) -> [&mut [f64]; 7] {
    let (a, w) = work.split_at_mut(n * n);
    let (b, w) = w.split_at_mut(n * n);
    let (c, w) = w.split_at_mut(nv * nv + nv);
    let (d, w) = w.split_at_mut(nv * nv);
    let (e, w) = w.split_at_mut(nv * nv);
    let (f, w) = w.split_at_mut(nv * nv);
    [a, b, c, d, e, f, w]
}

/// `∂τ_ext/∂q` into `ext` (`nv × nv`; on a free-floating base its joint columns) and
/// `∂τ_ext/∂quat` into `equat` (`nv × 4`, zero on a fixed base) of the scene's wrenches, values
/// `w` (6 a wrench, force then moment in the frame the scene names), in base coordinates
/// ([`super::wrenches`]): a body-fixed wrench turned by its body's rotation, one fixed in the
/// inertial frame of a free-floating base by `R(quat)ᵀ`. `jac` (`6 × nv`) is work memory.
fn wrench_torque_derivatives<D: SceneDerivatives + ?Sized>(
    dynamics: &mut D,
    floating: bool,
    q: &[f64],
    w: &[f64],
    [ext, jac, equat]: [&mut [f64]; 3],
) {
    ext.fill(0.0);
    equat.fill(0.0);
    let nv = jac.len() / 6;
    let quat = floating.then(|| [q[3], q[4], q[5], q[6]]);
    for (k, wk) in w.chunks_exact(6).enumerate() {
        let body = dynamics.wrench_body(k, q, jac);
        let (f, m) = ([wk[0], wk[1], wk[2]], [wk[3], wk[4], wk[5]]);
        let (fb, mb) = match (body.body_fixed, quat) {
            (true, _) => (rotate(&body.rotation, &f), rotate(&body.rotation, &m)),
            (false, Some(qt)) => {
                let r = quat_to_matrix(&qt);
                (rotate_back(&r, &f), rotate_back(&r, &m))
            }
            (false, None) => (f, m),
        };
        add_wrench_torque_derivatives(jac, &fb, &mb, body.body_fixed, ext);
        if let (false, Some(qt)) = (body.body_fixed, quat) {
            // τ_ext = Jᵀ R(quat)ᵀ [F; n]: ∂/∂quat = Jᵀ ∂(R(quat)ᵀ [F; n])/∂quat.
            let (df, dm) = (
                rotation_jacobian(&qt, &f, true),
                rotation_jacobian(&qt, &m, true),
            );
            for row in 0..nv {
                for c in 0..4 {
                    equat[row * 4 + c] += (0..3)
                        .map(|r| jac[r * nv + row] * df[r][c] + jac[(3 + r) * nv + row] * dm[r][c])
                        .sum::<f64>();
                }
            }
        }
    }
}

/// `∂τ/∂q` into `tq` and `∂τ/∂q̇` into `tv` of the applied torques `τ(t, q, q̇)` of the drive,
/// damping and friction of `fx` (module doc), `ext` the wrenches' `∂τ_ext/∂q` (a
/// computed-torque drive cancels them); `mm` (`N² + N`) is work memory.
#[allow(clippy::too_many_arguments)]
fn drive_jacobians<D: SceneDerivatives + ?Sized>(
    dynamics: &mut D,
    fx: &SceneEffects<'_>,
    t: f64,
    q: &[f64],
    qd: &[f64],
    ext: Option<&[f64]>,
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
            let cmd = &mut cmd[..n];
            super::drives::commanded_acceleration(&fx.drive, t, q, qd, cmd);
            dynamics.inverse_derivatives(q, qd, cmd, tq, tv);
            dynamics.mass_matrix(q, m);
            // The drive cancels the wrenches: τ = ID(…) − τ_ext(q).
            let ext = ext.unwrap_or(&[]);
            for i in 0..n {
                for j in 0..n {
                    let e = ext.get(i * n + j).copied().unwrap_or(0.0);
                    tq[i * n + j] -= m[i * n + j] * kp[j] + e;
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
