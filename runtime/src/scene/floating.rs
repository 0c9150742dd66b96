//! The kinematic part of a free-floating state's derivative (Pinocchio's free-flyer
//! configuration `[p₀, quat (x y z w), q]`, speeds `[v_b, ω_b, q̇]` in base coordinates).

use crate::ode::quat_to_matrix;

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
