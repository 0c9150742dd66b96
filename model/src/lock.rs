//! Locking a joint: the model with one joint turned into a fixed placement.

use crate::placement::{axis_rotation, mat_mul, mat_vec, Placement};
use crate::{Frame, JointKind, Model, ModelError};

impl Model {
    /// The model with joint `index` locked at `value` (rad or m): the joint becomes a fixed
    /// placement and its body is merged into its parent body (or the base) by [`crate::Inertial::merge`]; its child joints and frames are re-expressed in the
    /// parent frame. The result has `N − 1` joints and the same dynamics as the original with
    /// `q[index] = value` and `q̇[index] = 0` (rows and columns of the locked joint removed). The
    /// merged inertia is not re-checked for the triangle inequality (it holds when it held for
    /// the parts).
    ///
    /// # Errors
    /// If `index` is out of range, `value` is not finite or exceeds
    /// [`POSITION`](crate::bounds::POSITION), the model has mimic joints (not supported), or
    /// the model would become empty.
    pub fn lock_joint(&self, index: usize, value: f64) -> Result<Model, ModelError> {
        let n = self.joints().len();
        if let Some(m) = self.mimics().iter().position(Option::is_some) {
            return Err(ModelError::invalid(
                &self.joints()[m].name,
                "lock_joint",
                "locking a joint of a model with mimic joints is not supported",
            ));
        }
        if index >= n {
            return Err(ModelError::invalid(
                &format!("#{index}"),
                "lock_joint",
                format!("joint index {index} out of range (N = {n})"),
            ));
        }
        let j = &self.joints()[index];
        crate::bounds::POSITION
            .check(&[value])
            .map_err(|reason| ModelError::invalid(&j.name, "lock value", reason))?;
        // Placement of body `index` in its parent frame at q = value.
        let ups = &j.origin.rotation;
        let moved = match j.kind {
            JointKind::Revolute => {
                let (s, c) = value.sin_cos();
                Placement {
                    translation: j.origin.translation,
                    rotation: mat_mul(ups, &axis_rotation(&j.axis, s, c)),
                }
            }
            JointKind::Prismatic => {
                let d = mat_vec(ups, &j.axis.map(|a| value * a));
                Placement {
                    translation: [0, 1, 2].map(|k| j.origin.translation[k] + d[k]),
                    rotation: *ups,
                }
            }
        };
        // The locked body's mass properties in the parent frame.
        let body = j.inertial.moved(&moved);
        let parent = j.parent;
        let mut joints = self.joints().to_vec();
        let mut base_inertial = self.base_inertial().cloned();
        match parent {
            None => base_inertial = base_inertial.map(|b| b.merge(&body)),
            Some(p) => {
                let pi = &mut joints[p].inertial;
                *pi = pi.merge(&body);
            }
        }
        // Children of the locked body hang from its parent now; later indices move down by one.
        let reindex = |x: Option<usize>| match x {
            Some(k) if k == index => parent,
            Some(k) if k > index => Some(k - 1),
            other => other,
        };
        for c in joints.iter_mut() {
            if c.parent == Some(index) {
                c.origin = moved.then(&c.origin);
            }
            c.parent = reindex(c.parent);
        }
        let frames = self
            .frames()
            .iter()
            .map(|f| Frame {
                name: f.name.clone(),
                placement: if f.parent == Some(index) {
                    moved.then(&f.placement)
                } else {
                    f.placement
                },
                parent: reindex(f.parent),
            })
            .collect();
        joints.remove(index);
        let mut limits = self.limits().to_vec();
        limits.remove(index);
        self.rebuilt(joints, frames, base_inertial)?
            .with_limits(limits)
    }
}
