//! A model's numbers in a scalar type: what the algorithms read.
//!
//! [`Params::new`] turns every number of a [`Model`] into a constant of `S`; a code generator or
//! a report may then replace some of them by runtime inputs (a payload's mass, or every parameter
//! for a generic symbolic chain).

use crate::linalg::{Mat3, Vec3};
use crate::scalar::Scalar;
use crate::spatial::RbInertia;
use kanegen_model::{Joint, JointKind, Model};

/// One joint and its child body, with every number in the scalar type `S`.
#[derive(Clone, Debug)]
pub struct JointParams<S> {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// The parent body `λ(j) < j`, or `None` for the base.
    pub parent: Option<usize>,
    /// `l^{(j-1)}_{j-1}`: joint origin in the parent body frame (eq. (2)).
    pub l: Vec3<S>,
    /// `Υ_{j-1}`: joint frame orientation in the parent body frame (eq. (1)).
    pub upsilon: Mat3<S>,
    /// Unit joint axis in the joint frame.
    pub axis: Vec3<S>,
    /// `Some(k)` when `axis` is exactly a signed coordinate axis `±e_k` (model structure, like
    /// `kind`: [`crate::algorithms::aba`] then writes the exact zeros of `I^a_j S_j = 0` instead
    /// of computing round-off); `None` for any other axis or a symbolic one.
    pub coordinate_axis: Option<usize>,
    /// Whether [`crate::joint::carry_inertia`] carries inertias through the joint in two steps
    /// (model structure, like `kind`): [`Params::new`] sets it where `upsilon` is exactly a
    /// signed permutation; a tracer may also set it where `upsilon` is near one
    /// ([`NEAR_PERMUTATION`]). The carry uses the true `upsilon` either way: the choice changes
    /// the operation count, not the result.
    pub placement_permutation: bool,
    /// `Some((k, sin α, cos α))` when `upsilon` is exactly the turn by an angle `α` about the
    /// coordinate axis `e_k` and not a signed permutation ([`axis_turn`]; model structure, like
    /// `kind`): the second step of a two-step carry then turns the inertia about `e_k` in the
    /// double-angle form ([`crate::spatial::RbInertia::turned_about_axis`]) instead of taking the
    /// full congruence through `upsilon`. URDF writes such placements as `rpy` with one non-zero
    /// angle (`rpy = "1.5708 0 0"`).
    pub placement_turn: Option<(usize, S, S)>,
    /// A constant added to the joint angle of a revolute joint before its sine and cosine
    /// ([`crate::joint::joint_sin_cos`]; `None`: nothing added). [`Params::new`] sets none; a
    /// tracer sets one where it splits a placement `Υ = Θ_k1(α) Θ_u(θ₀)` whose second turn is
    /// about the joint's own axis `u` ([`mdh_split`], the modified Denavit–Hartenberg `θ` offset
    /// of canonical frames): then `Υ Θ_u(q) = Θ_k1(α) Θ_u(q + θ₀)`, `upsilon` is `Θ_k1(α)` and
    /// this is `θ₀`, the same joint with one turn fewer.
    pub angle_offset: Option<S>,
    /// `m_j`.
    pub mass: S,
    /// `d^{(j)}_j`: centre of mass in the body frame.
    pub com: Vec3<S>,
    /// Inertia about the centre of mass, body axes.
    pub inertia_com: Mat3<S>,
    /// The body's spatial inertia about its frame origin, as the local-frame algorithms read it:
    /// [`RbInertia::from_com`] of `mass`, `com`, `inertia_com`, unless regrouped
    /// ([`crate::regroup`]: then equivalent in joint space only).
    pub inertia: RbInertia<S>,
}

impl<S: Scalar> JointParams<S> {
    /// For a revolute joint about a coordinate axis whose placement is two turns, the second
    /// about the joint's own axis ([`mdh_split`]: canonical frames' `Θ_x(α) Θ_z(θ₀)`): the second
    /// turn goes into the joint angle ([`JointParams::angle_offset`], `q + θ₀` before the sine
    /// and cosine) and the first stays as the placement (`upsilon`, with exact zeros and ones;
    /// [`JointParams::placement_turn`]), and the carries go in two steps
    /// ([`JointParams::placement_permutation`]), not through a dense `E`. The same joint, to the
    /// split's tolerance; the body frames do not move. `joint` is the model's joint these
    /// parameters were made from. Returns whether it split.
    pub fn split_placement(&mut self, joint: &Joint) -> bool {
        let Some(k) = self
            .coordinate_axis
            .filter(|_| joint.kind == JointKind::Revolute)
        else {
            return false;
        };
        let Some((first, theta0)) = mdh_split(&joint.origin.rotation, k) else {
            return false;
        };
        let (kp, sp, cp) = first.unwrap_or((k, 0.0, 1.0));
        self.upsilon = Mat3::from_f64(turn_matrix(kp, sp, cp));
        self.placement_turn = first.map(|(k1, s, c)| (k1, S::constant(s), S::constant(c)));
        self.placement_permutation = true;
        // Θ_k(θ₀) Θ_u(q) = Θ_u(q + u_k θ₀) for the axis u = ±e_k.
        self.angle_offset = Some(S::constant(joint.axis[k] * theta0));
        true
    }

    /// Sets `mass`, `com` and `inertia_com`, and `inertia` from them.
    pub fn set_inertial(&mut self, mass: S, com: Vec3<S>, inertia_com: Mat3<S>) {
        self.inertia = RbInertia::from_com(&mass, &com, &inertia_com);
        self.mass = mass;
        self.com = com;
        self.inertia_com = inertia_com;
    }
}

/// How far from a signed permutation a joint placement may be for the two-step inertia carry to
/// be worth a trace ([`JointParams::placement_permutation`]). Measured on emitted code: xArm7's
/// URDF writes `rpy = 1.5708` for π/2, which leaves entries of 3.7e-6 in every placement, and
/// the two steps take its mass matrix from 920 to 782 operations with the placement's full
/// rotation as the second step, and to 750 with its turn about x ([`axis_turn`]); on UR5
/// (residues of 4.9e-12) the full-rotation second step costs more (M 172 against 217), as after
/// random (dense) placements (random N = 2: 58 against 88). Hence a candidate, not a rule.
pub const NEAR_PERMUTATION: f64 = 1e-4;

/// Whether every entry of `r` is within `tol` of 0 or ±1, with one near ±1 per row.
#[must_use]
pub fn is_near_signed_permutation(r: &[[f64; 3]; 3], tol: f64) -> bool {
    r.iter().all(|row| {
        row.iter().filter(|x| (x.abs() - 1.0).abs() <= tol).count() == 1
            && row
                .iter()
                .all(|x| x.abs() <= tol || (x.abs() - 1.0).abs() <= tol)
    })
}

/// A turn about a coordinate axis: `(k, sin α, cos α)` for the turn by `α` about `e_k`.
pub type AxisTurn = (usize, f64, f64);

/// `Some((k, s, c))` when `r` is exactly the rotation by the angle of sine `s` and cosine `c`
/// about `e_k` (row and column `k` are `e_k`; with `(a, b) = (k + 1, k + 2) mod 3`,
/// `r_aa = r_bb = c` and `r_ba = −r_ab = s`) and not a signed permutation (`s ≠ 0`, `c ≠ 0`):
/// [`JointParams::placement_turn`].
#[must_use]
pub fn axis_turn(r: &[[f64; 3]; 3]) -> Option<AxisTurn> {
    (0..3).find_map(|k| {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        let axis_fixed = r[k][k] == 1.0 && [a, b].iter().all(|&m| r[k][m] == 0.0 && r[m][k] == 0.0);
        let (c, s) = (r[a][a], r[b][a]);
        (axis_fixed && r[b][b] == c && r[a][b] == -s && s != 0.0 && c != 0.0).then_some((k, s, c))
    })
}

/// The rotation by the angle of sine `s` and cosine `c` about `e_k`, with exact zeros and ones
/// (the matrix [`axis_turn`] reads).
#[must_use]
pub fn turn_matrix(k: usize, s: f64, c: f64) -> [[f64; 3]; 3] {
    let (a, b) = ((k + 1) % 3, (k + 2) % 3);
    let mut r = [[0.0; 3]; 3];
    r[k][k] = 1.0;
    (r[a][a], r[a][b], r[b][a], r[b][b]) = (c, -s, s, c);
    r
}

/// How far [`mdh_split`]'s two turns may be from the placement, entry by entry: representation
/// residues only, as [`kanegen_model::canonical::DEFAULT_SNAP`].
pub const MDH_SPLIT_TOL: f64 = 1e-15;

/// A placement `r` split as `Θ_k1(α) Θ_k(θ₀)`, the second turn about the joint's coordinate axis
/// `e_k`: `Some((first, θ₀))` with `first = Some((k1, sin α, cos α))` (`None` when `r` is `Θ_k(θ₀)`
/// alone), when the product of the two turns is within [`MDH_SPLIT_TOL`] of `r` and something
/// is left to gain (not a signed permutation, and not already a single turn about another axis,
/// [`axis_turn`]). Canonical frames ([`kanegen_model::Model::canonical`]) place every joint so:
/// `α` the twist about the common normal `x`, `θ₀` the constant part of the modified
/// Denavit–Hartenberg `θ`.
#[must_use]
pub fn mdh_split(r: &[[f64; 3]; 3], k: usize) -> Option<(Option<AxisTurn>, f64)> {
    if is_near_signed_permutation(r, 0.0) || axis_turn(r).is_some() {
        return None;
    }
    let close = |m: &[[f64; 3]; 3]| {
        (0..3).all(|i| (0..3).all(|j| (m[i][j] - r[i][j]).abs() <= MDH_SPLIT_TOL))
    };
    let (a, b) = ((k + 1) % 3, (k + 2) % 3);
    // Θ_k(θ₀) alone.
    let (s0, c0) = (r[b][a], r[a][a]);
    if close(&turn_matrix(k, s0, c0)) {
        return Some((None, s0.atan2(c0)));
    }
    for k1 in [a, b] {
        // Row k1 of Θ_k1(α) Θ_k(θ₀) is row k1 of Θ_k(θ₀); column k is Θ_k1(α) e_k.
        let (s0, c0) = if k1 == a {
            (-r[a][b], r[a][a])
        } else {
            (r[b][a], r[b][b])
        };
        let (a1, b1) = ((k1 + 1) % 3, (k1 + 2) % 3);
        let (s1, c1) = if k == a1 {
            (r[b1][k], r[a1][k])
        } else {
            (-r[a1][k], r[b1][k])
        };
        let m = Mat3(turn_matrix(k1, s1, c1)).mul_mat(&Mat3(turn_matrix(k, s0, c0)));
        if close(&m.0) {
            return Some((Some((k1, s1, c1)), s0.atan2(c0)));
        }
    }
    None
}

/// `Some(k)` when `axis` is `±e_k`: exactly one non-zero component.
#[must_use]
pub fn coordinate_axis(axis: [f64; 3]) -> Option<usize> {
    let mut nonzero = (0..3).filter(|&k| axis[k] != 0.0);
    match (nonzero.next(), nonzero.next()) {
        (Some(k), None) => Some(k),
        _ => None,
    }
}

/// A named frame fixed to a body, in the scalar type `S`.
#[derive(Clone, Debug)]
pub struct FrameParams<S> {
    /// The body it is fixed to (`None`: the base).
    pub parent: Option<usize>,
    /// Its origin in the body frame.
    pub translation: Vec3<S>,
    /// Its orientation in the body frame.
    pub rotation: Mat3<S>,
}

/// The model's numbers in the scalar type `S`.
#[derive(Clone, Debug)]
pub struct Params<S> {
    /// Joints in topological order (parents first).
    pub joints: Vec<JointParams<S>>,
    /// The model's named frames, in its order.
    pub frames: Vec<FrameParams<S>>,
}

impl<S: Scalar> Params<S> {
    /// Every number of `model` as a constant of `S`.
    #[must_use]
    pub fn new(model: &Model) -> Self {
        Params {
            joints: model
                .joints()
                .iter()
                .map(|j| {
                    let (mass, com, inertia_com) = (
                        S::constant(j.inertial.mass),
                        Vec3::from_f64(j.inertial.com),
                        Mat3::from_f64(j.inertial.inertia),
                    );
                    JointParams {
                        kind: j.kind,
                        parent: j.parent,
                        l: Vec3::from_f64(j.origin.translation),
                        upsilon: Mat3::from_f64(j.origin.rotation),
                        axis: Vec3::from_f64(j.axis),
                        coordinate_axis: coordinate_axis(j.axis),
                        placement_permutation: is_near_signed_permutation(&j.origin.rotation, 0.0),
                        placement_turn: axis_turn(&j.origin.rotation)
                            .map(|(k, s, c)| (k, S::constant(s), S::constant(c))),
                        angle_offset: None,
                        inertia: RbInertia::from_com(&mass, &com, &inertia_com),
                        mass,
                        com,
                        inertia_com,
                    }
                })
                .collect(),
            frames: model
                .frames()
                .iter()
                .map(|f| FrameParams {
                    parent: f.parent,
                    translation: Vec3::from_f64(f.placement.translation),
                    rotation: Mat3::from_f64(f.placement.rotation),
                })
                .collect(),
        }
    }
}

impl<S> Params<S> {
    /// Number of degrees of freedom.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Whether the tree is a serial chain (`λ(j) = j − 1`), as the paper's inertial-frame algorithms
    /// need.
    #[must_use]
    pub fn is_chain(&self) -> bool {
        self.first_branch().is_none()
    }

    /// The first joint `j`, in order, whose parent is not body `j − 1` (where the tree branches:
    /// body `λ(j)`, or the base, already has a child), or `None` for a serial chain.
    #[must_use]
    pub fn first_branch(&self) -> Option<usize> {
        self.joints
            .iter()
            .enumerate()
            .position(|(j, jp)| jp.parent != j.checked_sub(1))
    }

    /// `Ok` on a serial chain; on a tree, the [`MethodError`] of `method` (a serial-chain-only
    /// algorithm, named as in reports: `"recurrent"`, `"kane-direct"`, …) at the first branching
    /// joint.
    ///
    /// # Errors
    /// The model is a tree, not a chain.
    pub fn require_chain(&self, method: &'static str) -> Result<(), MethodError> {
        match self.first_branch() {
            None => Ok(()),
            Some(joint) => Err(MethodError {
                method,
                joint,
                parent: self.joints[joint].parent,
            }),
        }
    }

    /// Panics with the message of [`Params::require_chain`] on a tree: the guard of every
    /// serial-chain-only algorithm (a programming error once callers check with
    /// [`crate::Methods::check`]).
    ///
    /// # Panics
    /// The model is a tree.
    #[track_caller]
    pub fn assert_chain(&self, method: &'static str) {
        if let Err(e) = self.require_chain(method) {
            panic!("{e}");
        }
    }
}

/// A serial-chain-only method (the paper's inertial-frame algorithms) asked to run on a kinematic
/// tree: which method, and where the tree first branches.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MethodError {
    /// The method, by its report name (`"recurrent"`, `"crba-inertial"`, `"kane-direct"`, …).
    pub method: &'static str,
    /// The first joint (0-based) whose parent is not the body of the joint before it.
    pub joint: usize,
    /// That joint's parent body (`None`: the base).
    pub parent: Option<usize>,
}

impl core::fmt::Display for MethodError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let parent = match self.parent {
            Some(b) => format!("body #{b}"),
            None => "the base".to_string(),
        };
        let expected = match self.joint.checked_sub(1) {
            Some(b) => format!("body #{b}"),
            None => "the base".to_string(),
        };
        write!(
            f,
            "method `{}` handles serial chains only, but the model is a kinematic tree: joint #{} \
             hangs from {parent}, not from {expected}; use the local-frame methods `crba` and \
             `rnea` (Methods::SPATIAL) for trees",
            self.method, self.joint
        )
    }
}

impl std::error::Error for MethodError {}
