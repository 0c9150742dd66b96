//! Rigid placements of one frame in another, and the few `f64` 3×3 helpers the readers and the
//! model edits need (the generic, traced algebra is `kanegen-dynamics`' `linalg`).
//!
//! ```
//! use kanegen_model::Placement;
//! let a = Placement::trans([1.0, 0.0, 0.0]).then(&Placement::rot_z(core::f64::consts::FRAC_PI_2));
//! let p = a.point(&[1.0, 0.0, 0.0]);
//! assert!((p[0] - 1.0).abs() < 1e-15 && (p[1] - 1.0).abs() < 1e-15);
//! ```

use serde::Serialize;

/// A 3×3 matrix, row-major.
pub type M3 = [[f64; 3]; 3];
/// A 3-vector.
pub type V3 = [f64; 3];

/// The identity matrix.
pub const I3: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// `a · b`.
#[must_use]
pub fn mat_mul(a: &M3, b: &M3) -> M3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j]))
}

/// `a · v`.
#[must_use]
pub fn mat_vec(a: &M3, v: &V3) -> V3 {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

/// `aᵀ`.
#[must_use]
pub fn transpose(a: &M3) -> M3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[j][i]))
}

/// Rotation matrix from URDF roll-pitch-yaw: `R = Rz(yaw) · Ry(pitch) · Rx(roll)`.
#[must_use]
pub fn rpy_to_matrix(rpy: V3) -> M3 {
    let (sr, cr) = rpy[0].sin_cos();
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Rotation about the unit axis `u` by the angle with sine `s` and cosine `c` (Rodrigues:
/// `R = c·1 + s·ũ + (1 − c)·u uᵀ`), in the same order of operations as the traced
/// `kanegen_dynamics::linalg::axis_rotation`, so both give the same bits.
#[must_use]
pub fn axis_rotation(u: &V3, s: f64, c: f64) -> M3 {
    let k = 1.0 - c;
    let skew = [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]];
    [0, 1, 2].map(|i| {
        [0, 1, 2].map(|j| {
            let ci = c * if i == j { 1.0 } else { 0.0 };
            ci + s * skew[i][j] + k * (u[i] * u[j])
        })
    })
}

/// A rigid placement of one frame in another: `x_parent = rotation · x_child + translation`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Placement {
    /// Translation, in the parent frame.
    pub translation: V3,
    /// Rotation matrix (row-major), orthonormal with determinant +1.
    pub rotation: M3,
}

impl Default for Placement {
    fn default() -> Self {
        Placement::identity()
    }
}

impl Placement {
    /// The identity placement.
    #[must_use]
    pub fn identity() -> Self {
        Placement {
            translation: [0.0; 3],
            rotation: I3,
        }
    }
    /// URDF `<origin xyz rpy>`.
    #[must_use]
    pub fn from_xyz_rpy(xyz: V3, rpy: V3) -> Self {
        Placement {
            translation: xyz,
            rotation: rpy_to_matrix(rpy),
        }
    }
    /// A pure translation.
    #[must_use]
    pub fn trans(t: V3) -> Self {
        Placement {
            translation: t,
            rotation: I3,
        }
    }
    /// A rotation by `a` about `x`.
    #[must_use]
    pub fn rot_x(a: f64) -> Self {
        let (s, c) = a.sin_cos();
        Placement {
            translation: [0.0; 3],
            rotation: [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        }
    }
    /// A rotation by `a` about `z`.
    #[must_use]
    pub fn rot_z(a: f64) -> Self {
        let (s, c) = a.sin_cos();
        Placement {
            translation: [0.0; 3],
            rotation: [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        }
    }
    /// `self ∘ o`: the placement of a frame placed at `o` in a frame placed at `self`
    /// (`x ↦ self(o(x))`).
    #[must_use]
    pub fn then(&self, o: &Placement) -> Placement {
        let t = mat_vec(&self.rotation, &o.translation);
        Placement {
            translation: [
                t[0] + self.translation[0],
                t[1] + self.translation[1],
                t[2] + self.translation[2],
            ],
            rotation: mat_mul(&self.rotation, &o.rotation),
        }
    }
    /// A point given in the child frame, in the parent frame.
    #[must_use]
    pub fn point(&self, p: &V3) -> V3 {
        let q = mat_vec(&self.rotation, p);
        [
            q[0] + self.translation[0],
            q[1] + self.translation[1],
            q[2] + self.translation[2],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `rpy_to_matrix` is `Rz(yaw) · Ry(pitch) · Rx(roll)`, composed from axis rotations.
    #[test]
    fn rpy_matches_composition() {
        let rpy = [0.3, -0.4, 1.1];
        let m = rpy_to_matrix(rpy);
        let rot = |u: &V3, a: f64| axis_rotation(u, a.sin(), a.cos());
        let (ex, ey, ez) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        let r = mat_mul(
            &mat_mul(&rot(&ez, rpy[2]), &rot(&ey, rpy[1])),
            &rot(&ex, rpy[0]),
        );
        for i in 0..3 {
            for j in 0..3 {
                assert!((r[i][j] - m[i][j]).abs() < 1e-14);
            }
        }
    }
}
