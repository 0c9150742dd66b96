//! The same robot in frames that make its dynamics cheap to compute: float noise snapped, every
//! joint axis along `z` of its joint frame, and each body's `x` axis along the common normal to
//! its first child's axis (the frame choice of the modified Denavit–Hartenberg convention, used
//! by the customized symbolic models of Khalil and Kleinfinger).
//!
//! Every body frame may be turned about its own joint axis, and every joint frame with it,
//! without changing the robot: `B' = B R_j` with `R_j e_z = u_j` (the joint axis `u_j`, whose
//! coordinates are the same in the joint and the body frame). The joint rotation becomes
//! `Θ_z(q)` — two sines and cosines instead of a dense Rodrigues matrix —, the joint
//! placements `Υ' = R_pᵀ Υ R_j`, `l' = R_pᵀ l`, the inertials `c' = R_jᵀ c`, `I' = R_jᵀ I R_j`
//! and the named frames `R_jᵀ (t, R)`. Joint-space quantities (`M`, `c`, drives), frame
//! placements in the base frame and everything about the base are unchanged; only the bodies'
//! own frames turn. A body whose axis already is a coordinate axis gets a signed permutation
//! (no rounding at all).
//!
//! Snapping, with a tolerance `tol` ([`DEFAULT_SNAP`] unless given): a rotation all of whose
//! entries lie within `tol` of 0 or ±1 becomes that exact signed permutation, and translations,
//! centres of mass (m) and inertia entries (relative to the tensor's largest) below `tol` become
//! 0, as do axis components. URDF's `rpy = "0 1.5707963267948966 0"` leaves `cos = 6.1e-17` in
//! a rotation, a real multiplication in generated code. The default only removes such
//! representation residues, so the dynamics stay within 1e-15 of the file's; a larger
//! tolerance (`1e-9` catches `rpy = 1.570796325`, whose residue is 4.9e-12) changes the robot by
//! about that much, and [`Canonical::report`] says what changed and by how much.
//!
//! ```
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let model = random_chain(&ChainSpec { n: 4, ..Default::default() }, 3);
//! let c = model.canonical().unwrap();
//! assert!(c.model.joints().iter().all(|j| j.axis == [0.0, 0.0, 1.0]));
//! assert_eq!(c.report.turned, 4);
//! ```

use crate::inertial::rotate_inertia;
use crate::placement::{mat_mul, mat_vec, transpose, Placement, M3, V3};
use crate::{Frame, Inertial, Joint, Model, Validation};

/// The snap tolerance of [`Model::canonical`]: representation residues only (`cos(π/2)` in
/// `f64` is 6.1e-17, `sin(π)` 1.2e-16).
pub const DEFAULT_SNAP: f64 = 1e-15;

/// What [`Model::canonical`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CanonicalReport {
    /// Numbers snapped to 0 or ±1.
    pub snapped: usize,
    /// The largest change a snap made.
    pub largest_snap: f64,
    /// Bodies whose frame was turned (their axis was not already `z`).
    pub turned: usize,
}

/// A model in canonical frames, and what changed.
#[derive(Clone, Debug, PartialEq)]
pub struct Canonical {
    /// The same robot.
    pub model: Model,
    /// The changes.
    pub report: CanonicalReport,
}

fn snap_rotation(r: &mut M3, tol: f64, rep: &mut CanonicalReport) {
    // Zeros one by one; ±1 only when the whole matrix is a signed permutation, so a snapped
    // rotation stays orthogonal to within `tol`.
    let near = |x: f64| [0.0, 1.0, -1.0].into_iter().find(|t| (x - t).abs() <= tol);
    let permutation = r.iter().flatten().all(|x| near(*x).is_some());
    for x in r.iter_mut().flatten() {
        if let Some(t) = near(*x).filter(|t| permutation || *t == 0.0) {
            if *x != t {
                rep.snapped += 1;
                rep.largest_snap = rep.largest_snap.max((*x - t).abs());
                *x = t;
            }
        }
    }
}

fn snap_small(xs: &mut [f64], tol: f64, rep: &mut CanonicalReport) {
    for x in xs {
        if *x != 0.0 && x.abs() < tol {
            rep.snapped += 1;
            rep.largest_snap = rep.largest_snap.max(x.abs());
            *x = 0.0;
        }
    }
}

fn snap_inertial(i: &mut Inertial, tol: f64, rep: &mut CanonicalReport) {
    snap_small(&mut i.com, tol, rep);
    let scale = i
        .inertia
        .iter()
        .flatten()
        .fold(0.0_f64, |m, x| m.max(x.abs()));
    snap_small(i.inertia.as_flattened_mut(), tol * scale, rep);
}

fn cross(a: &V3, b: &V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalized(v: V3) -> Option<V3> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (n > 1e-9).then(|| v.map(|x| x / n))
}

/// Whether `u` is a signed coordinate axis.
fn is_coordinate(u: &V3) -> bool {
    u.iter().filter(|x| **x == 0.0).count() == 2
}

/// `R` with `R e_z = u` (unit) and `R e_x = x` when given (unit, ⊥ u); otherwise `x` along a
/// coordinate axis ⊥ `u` when `u` is one (a signed permutation), else `u × e` normalized for the
/// coordinate axis `e` least aligned with `u`.
fn frame_for(u: &V3, x: Option<V3>) -> M3 {
    let x = x.unwrap_or_else(|| {
        let k = (0..3)
            .min_by(|a, b| u[*a].abs().total_cmp(&u[*b].abs()))
            .expect("three axes");
        let mut e = [0.0; 3];
        e[k] = 1.0;
        if is_coordinate(u) {
            e
        } else {
            normalized(cross(u, &e)).expect("e is not along u")
        }
    });
    let y = cross(u, &x);
    [[x[0], y[0], u[0]], [x[1], y[1], u[1]], [x[2], y[2], u[2]]]
}

impl Model {
    /// The same robot in canonical frames ([module docs](crate::canonical)): representation
    /// residues snapped ([`DEFAULT_SNAP`]), every joint axis `z`, each body's `x` along the
    /// common normal to its first child's axis.
    ///
    /// # Errors
    /// As [`Model::canonical_with`].
    pub fn canonical(&self) -> Result<Canonical, crate::ModelError> {
        self.canonical_with(DEFAULT_SNAP)
    }

    /// The same robot with float noise snapped and its frames left as they are: the snapping of
    /// [`Model::canonical_with`] alone (`turned` is 0). A rotation is made an exact signed
    /// permutation only when all its entries are within `tol` of 0 or ±1, so it stays
    /// orthonormal; elsewhere only entries below `tol` become 0 (a change of at most `tol`).
    #[must_use]
    pub fn snapped(&self, tol: f64) -> Canonical {
        let mut rep = CanonicalReport::default();
        let (joints, frames, base_inertial) = self.snap_parts(tol, &mut rep);
        let model = self
            .rebuilt(joints, frames, base_inertial)
            .expect("snapping keeps a valid model valid");
        Canonical { model, report: rep }
    }

    /// Joints, frames and base inertial with float noise below `tol` snapped.
    fn snap_parts(
        &self,
        tol: f64,
        rep: &mut CanonicalReport,
    ) -> (Vec<Joint>, Vec<Frame>, Option<Inertial>) {
        let mut joints = self.joints().to_vec();
        let mut frames = self.frames().to_vec();
        let mut base_inertial = self.base_inertial().cloned();
        if let Some(b) = base_inertial.as_mut() {
            snap_inertial(b, tol, rep);
        }
        for j in &mut joints {
            snap_rotation(&mut j.origin.rotation, tol, rep);
            snap_small(&mut j.origin.translation, tol, rep);
            snap_inertial(&mut j.inertial, tol, rep);
            let mut axis = j.axis;
            snap_small(&mut axis, tol, rep);
            if let Some(u) = normalized(axis) {
                j.axis = u;
            }
        }
        for f in &mut frames {
            snap_rotation(&mut f.placement.rotation, tol, rep);
            snap_small(&mut f.placement.translation, tol, rep);
        }
        (joints, frames, base_inertial)
    }

    /// This model's name, base and base kind with other joints, frames and base inertial
    /// (inertias already validated where they came from; also [`Model::lock_joint`]'s).
    pub(crate) fn rebuilt(
        &self,
        joints: Vec<Joint>,
        frames: Vec<Frame>,
        base_inertial: Option<Inertial>,
    ) -> Result<Model, crate::ModelError> {
        Model::new_with(
            self.name(),
            self.base(),
            base_inertial,
            joints,
            Validation {
                allow_nonphysical_inertia: true,
            },
        )
        .and_then(|m| m.with_frames(frames))
        .and_then(|m| m.with_base_kind(self.base_kind()))
        .and_then(|m| match m.dof() == self.dof() {
            // The same joints: their limits and couplings stay.
            true => m
                .with_limits(self.limits().to_vec())?
                .with_mimics(self.mimics().to_vec()),
            false => Ok(m),
        })
    }

    /// [`Model::canonical`] with the snap tolerance `tol` (0 snaps nothing).
    ///
    /// # Errors
    /// When turning the frames moves a number of a model at its validation bounds past them
    /// (an inertia of exactly 1e18 kg·m² may come out 1.0000000000000001e18): the model in its
    /// own frames is the one to use.
    pub fn canonical_with(&self, tol: f64) -> Result<Canonical, crate::ModelError> {
        let mut rep = CanonicalReport::default();
        let (mut joints, frames, base_inertial) = self.snap_parts(tol, &mut rep);
        // R_j for every body: z along the axis, x along the common normal to the first child's
        // axis (as seen in this body's original frame: Υ_c u_c).
        let rot: Vec<M3> = (0..joints.len())
            .map(|j| {
                let u = joints[j].axis;
                let child = joints
                    .iter()
                    .find(|c| c.parent == Some(j))
                    .map(|c| mat_vec(&c.origin.rotation, &c.axis));
                let x = child.and_then(|uc| normalized(cross(&u, &uc)));
                if u == [0.0, 0.0, 1.0] && x.is_none() {
                    crate::placement::I3
                } else {
                    frame_for(&u, x)
                }
            })
            .collect();
        let of = |p: Option<usize>| p.map_or(crate::placement::I3, |p| rot[p]);
        for (j, jt) in joints.iter_mut().enumerate() {
            if rot[j] != crate::placement::I3 {
                rep.turned += 1;
            }
            let rp = transpose(&of(jt.parent));
            jt.origin = Placement {
                translation: mat_vec(&rp, &jt.origin.translation),
                rotation: mat_mul(&mat_mul(&rp, &jt.origin.rotation), &rot[j]),
            };
            snap_rotation(&mut jt.origin.rotation, tol, &mut rep);
            jt.axis = [0.0, 0.0, 1.0];
            let rt = transpose(&rot[j]);
            jt.inertial = Inertial {
                mass: jt.inertial.mass,
                com: mat_vec(&rt, &jt.inertial.com),
                inertia: rotate_inertia(&rt, &jt.inertial.inertia),
            };
        }
        let frames = frames
            .into_iter()
            .map(|f| {
                let rt = transpose(&of(f.parent));
                Frame {
                    placement: Placement {
                        translation: mat_vec(&rt, &f.placement.translation),
                        rotation: mat_mul(&rt, &f.placement.rotation),
                    },
                    ..f
                }
            })
            .collect();
        let model = self.rebuilt(joints, frames, base_inertial)?;
        Ok(Canonical { model, report: rep })
    }
}
