//! The kinematic part of a free-floating state's derivative (Pinocchio's free-flyer
//! configuration `[p₀, quat (x y z w), q]`, speeds `[v_b, ω_b, q̇]` in base coordinates).

use crate::ode::quat_to_matrix;
use crate::ode::quaternion::{rotation_jacobian, skew};

/// `dq = [ṗ₀, q̇uat, q̇]` (`7 + N`) from positions `q` (`7 + N`) and speeds `v` (`6 + N`):
/// `ṗ₀ = R₀ v_b`, `q̇uat = ½ quat ⊗ (ω_b, 0)`, i.e. `u̇ = ½ (w ω + u × ω)`, `ẇ = −½ u · ω`
/// (quaternion `(u, w)`, body-frame `ω_b`).
#[inline(always)]
pub fn floating_kinematics(q: &[f64], v: &[f64], dq: &mut [f64]) {
    if q.len() < 7 || v.len() < 6 || dq.len() < 7 {
        dq.fill(f64::NAN);
        return;
    }
    let r = quat_to_matrix(&[q[3], q[4], q[5], q[6]]);
    for i in 0..3 {
        dq[i] = r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2];
    }
    let (u, w, om) = ([q[3], q[4], q[5]], q[6], [v[3], v[4], v[5]]);
    let cross = [
        u[1] * om[2] - u[2] * om[1],
        u[2] * om[0] - u[0] * om[2],
        u[0] * om[1] - u[1] * om[0],
    ];
    for i in 0..3 {
        dq[3 + i] = 0.5 * (om[i] * w + cross[i]);
    }
    dq[6] = -0.5 * (u[0] * om[0] + u[1] * om[1] + u[2] * om[2]);
    super::copy_into(&mut dq[7..], &v[6..]);
}

/// The rows `0..7 + N` of `∂ẋ/∂x` (row-major, `d = 13 + 2N` columns, into `f`, whose other
/// entries are left alone) of [`floating_kinematics`] over the state `[q, v]`, the quaternion's
/// four numbers as they are (unit or not): `ṗ₀ = R(quat) v_b` by `∂/∂quat`
/// ([`rotation_jacobian`]) and `∂/∂v_b = R(quat)`; `u̇ = ½ (w ω + u × ω)`,
/// `ẇ = −½ u · ω` by `∂u̇/∂u = −½ [ω]×`, `∂u̇/∂w = ½ ω`, `∂ẇ/∂u = −½ ωᵀ`,
/// `∂u̇/∂ω = ½ (w 1 + [u]×)`, `∂ẇ/∂ω = −½ uᵀ`; `q̇` by the identity.
pub fn floating_kinematics_jacobian(q: &[f64], v: &[f64], f: &mut [f64]) {
    let (nq, d) = (q.len(), q.len() + v.len());
    if nq < 7 || v.len() + 1 != nq || f.len() < nq * d {
        f.fill(f64::NAN);
        return;
    }
    let quat = [q[3], q[4], q[5], q[6]];
    let (u, w, om) = ([q[3], q[4], q[5]], q[6], [v[3], v[4], v[5]]);
    let r = quat_to_matrix(&quat);
    let dp = rotation_jacobian(&quat, &[v[0], v[1], v[2]], false);
    let (s_om, s_u) = (skew(&om), skew(&u));
    for i in 0..3 {
        let (prow, urow) = (i * d, (3 + i) * d);
        f[prow + 3..prow + 7].copy_from_slice(&dp[i]);
        for j in 0..3 {
            f[prow + nq + j] = r[i][j];
            f[urow + 3 + j] = -0.5 * s_om[i][j];
            let diag = if i == j { w } else { 0.0 };
            f[urow + nq + 3 + j] = 0.5 * (diag + s_u[i][j]);
        }
        f[urow + 6] = 0.5 * om[i];
        f[6 * d + 3 + i] = -0.5 * om[i];
        f[6 * d + nq + 3 + i] = -0.5 * u[i];
    }
    for j in 7..nq {
        f[j * d + nq + 6 + j - 7] = 1.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`floating_kinematics_jacobian`] against central differences of [`floating_kinematics`],
    /// at a quaternion that is not unit.
    #[test]
    fn kinematics_jacobian_matches_central_differences() {
        const NQ: usize = 9;
        const D: usize = 17;
        let (nq, d) = (NQ, D);
        let x: [f64; D] = core::array::from_fn(|i| 0.3 * libm::sin(i as f64 * 1.3) + 0.1);
        let mut f = [0.0; D * D];
        floating_kinematics_jacobian(&x[..nq], &x[nq..], &mut f);
        let e = 1e-6;
        for c in 0..d {
            let (mut p, mut m) = (x, x);
            p[c] += e;
            m[c] -= e;
            let (mut fp, mut fm) = ([0.0; NQ], [0.0; NQ]);
            floating_kinematics(&p[..nq], &p[nq..], &mut fp);
            floating_kinematics(&m[..nq], &m[nq..], &mut fm);
            for r in 0..nq {
                let diff = (fp[r] - fm[r]) / (2.0 * e);
                assert!(
                    (diff - f[r * d + c]).abs() < 1e-9,
                    "{r} {c}: {diff} {}",
                    f[r * d + c]
                );
            }
        }
    }
}
