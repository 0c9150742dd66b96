//! Small f64 rigid-transform and inertia helpers shared by the readers.

use crate::linalg::rpy_to_matrix;
use crate::model::Placement;

pub(crate) type M3 = [[f64; 3]; 3];
pub(crate) type V3 = [f64; 3];

/// A rigid transform `x_parent = r · x_child + t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tf {
    pub r: M3,
    pub t: V3,
}

pub(crate) const I3: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

pub(crate) fn mm(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for (i, row) in c.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

pub(crate) fn mv(a: &M3, v: &V3) -> V3 {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

pub(crate) fn tr(a: &M3) -> M3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[j][i]))
}

/// `R I Rᵀ`: an inertia tensor re-expressed in rotated axes.
pub(crate) fn rotate_inertia(r: &M3, i: &M3) -> M3 {
    mm(&mm(r, i), &tr(r))
}

/// `m (|c|² 1 − c cᵀ)`: the parallel-axis term.
pub(crate) fn steiner(m: f64, c: &V3) -> M3 {
    let n2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m * (if i == j { n2 } else { 0.0 } - c[i] * c[j])))
}

impl Tf {
    pub fn identity() -> Self {
        Tf { r: I3, t: [0.0; 3] }
    }
    pub fn from_xyz_rpy(xyz: V3, rpy: V3) -> Self {
        Tf {
            r: rpy_to_matrix(rpy),
            t: xyz,
        }
    }
    pub fn trans(t: V3) -> Self {
        Tf { r: I3, t }
    }
    pub fn rot_x(a: f64) -> Self {
        let (s, c) = a.sin_cos();
        Tf {
            r: [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
            t: [0.0; 3],
        }
    }
    pub fn rot_z(a: f64) -> Self {
        let (s, c) = a.sin_cos();
        Tf {
            r: [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
            t: [0.0; 3],
        }
    }
    /// `self ∘ o`: first `o`, then `self` (`x ↦ self(o(x))`).
    pub fn then(&self, o: &Tf) -> Tf {
        let t = mv(&self.r, &o.t);
        Tf {
            r: mm(&self.r, &o.r),
            t: [t[0] + self.t[0], t[1] + self.t[1], t[2] + self.t[2]],
        }
    }
    pub fn point(&self, p: &V3) -> V3 {
        let q = mv(&self.r, p);
        [q[0] + self.t[0], q[1] + self.t[1], q[2] + self.t[2]]
    }
    pub fn placement(&self) -> Placement {
        Placement {
            translation: self.t,
            rotation: self.r,
        }
    }
}

/// Accumulates rigid parts of one body, in the body frame.
#[derive(Clone, Debug, Default)]
pub(crate) struct MassAcc {
    mass: f64,
    first_moment: V3,
    /// Inertia about the body-frame origin.
    inertia_origin: M3,
}

impl MassAcc {
    /// Adds a part of mass `m`, centre of mass `com` and inertia `inertia` about its CoM, all
    /// given in a frame placed at `tf` in the body frame.
    pub fn add(&mut self, tf: &Tf, m: f64, com: &V3, inertia: &M3) {
        let c = tf.point(com);
        let i = rotate_inertia(&tf.r, inertia);
        let s = steiner(m, &c);
        self.mass += m;
        for k in 0..3 {
            self.first_moment[k] += m * c[k];
            for l in 0..3 {
                self.inertia_origin[k][l] += i[k][l] + s[k][l];
            }
        }
    }
    /// Total mass, combined CoM and inertia about the combined CoM (zeros when massless).
    pub fn finish(&self) -> (f64, V3, M3) {
        if self.mass == 0.0 {
            return (0.0, [0.0; 3], [[0.0; 3]; 3]);
        }
        let c = self.first_moment.map(|x| x / self.mass);
        let s = steiner(self.mass, &c);
        let i = [0, 1, 2].map(|k| [0, 1, 2].map(|l| self.inertia_origin[k][l] - s[k][l]));
        // Re-symmetrize against rounding.
        let i = [0, 1, 2].map(|k| [0, 1, 2].map(|l| 0.5 * (i[k][l] + i[l][k])));
        (self.mass, c, i)
    }
}
