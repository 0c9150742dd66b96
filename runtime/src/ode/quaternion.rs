//! The unit quaternion of a free-floating base's state `[p₀, quat (x y z w), q, v_b, ω_b, q̇]`
//! (`13 + 2n` long with `n` joints): its projection back to unit length, its exponential-map
//! update (the Lie-group part of [`midpoint`](super::midpoint())) and its rotation matrix.

use crate::scalar::Scalar;

/// Renormalizes the unit quaternion `x[3..7]` of a free-floating state (the projection after
/// an accepted step); a shorter state is left alone.
#[inline]
pub fn normalize_quaternion(x: &mut [f64]) {
    if let Some(quat) = x.get_mut(3..7) {
        let norm = Scalar::sqrt(
            quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3],
        );
        for v in quat {
            *v /= norm;
        }
    }
}

/// The additive update `out = x + h f` (the [`System::advance`](super::System::advance) of a
/// state without a Lie-group part).
#[inline]
pub fn advance_additive(x: &[f64], h: f64, f: &[f64], out: &mut [f64]) {
    for ((o, xi), fi) in out.iter_mut().zip(x).zip(f) {
        *o = xi + h * fi;
    }
}

/// The update of a free-floating state `[p₀, quat, q, v_b, ω_b, q̇]` with `n` joints
/// (`13 + 2n` long): additive ([`advance_additive`]), except the quaternion `x[3..7]`, which
/// becomes `quat ⊗ exp(h ω_b(at) / 2)` (exponential map, unit by construction, symmetric in
/// `h`; `sin(|ω| h/2)/|ω|` by its Taylor series below `|ω| h/2 = 1e-8`). A state shorter than
/// 13 has no base: additive.
pub fn advance_floating(x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
    advance_additive(x, h, f, out);
    let d = x.len().min(at.len()).min(out.len());
    if d < 13 {
        return;
    }
    // ω_b at 10 + n.
    let n = (d - 13) / 2;
    let om = [at[10 + n], at[11 + n], at[12 + n]];
    let w_norm = Scalar::sqrt(om[0] * om[0] + om[1] * om[1] + om[2] * om[2]);
    let half = 0.5 * h * w_norm;
    let s = if libm::fabs(half) < 1e-8 {
        0.5 * h * (1.0 - half * half / 6.0)
    } else {
        Scalar::sin(half) / w_norm
    };
    let (rho, rw) = ([s * om[0], s * om[1], s * om[2]], Scalar::cos(half));
    let (u, w) = ([x[3], x[4], x[5]], x[6]);
    let cross = [
        u[1] * rho[2] - u[2] * rho[1],
        u[2] * rho[0] - u[0] * rho[2],
        u[0] * rho[1] - u[1] * rho[0],
    ];
    for i in 0..3 {
        out[3 + i] = w * rho[i] + rw * u[i] + cross[i];
    }
    out[6] = w * rw - (u[0] * rho[0] + u[1] * rho[1] + u[2] * rho[2]);
}

/// The rotation matrix (row-major, body to inertial axes) of a quaternion `[x, y, z, w]`:
/// `I + 2w [u]× + 2 [u]×²`, not normalized (as `kanegen::dynamics::base::quat_to_matrix`).
#[must_use]
pub fn quat_to_matrix(q: &[f64; 4]) -> [[f64; 3]; 3] {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}
