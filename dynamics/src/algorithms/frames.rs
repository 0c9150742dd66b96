//! Frames fixed to bodies (named frames of the model, or any point on a body built ad hoc as a
//! [`FrameParams`]): their placement and Jacobian, on a fixed or a free-floating base, and the
//! generalized Jacobian of a free-floating system (Umetani & Yoshida 1989).
//!
//! Forward kinematics walks only the **support set** `κ(i)` of the frame's body `i`, the joints on
//! its path to the base (RBDA ch. 4 notation): with `Xup_k = (E_k, r_k)` of [`crate::spatial`],
//! body `k`'s placement in the base frame is `R_k = R_λ E_kᵀ`, `x_k = x_λ + R_λ r_k`, and the
//! frame's is `x_f = x_i + R_i t_f`, `R_f = R_i R_{f,i}`. A body frame's origin lies on its
//! joint's axis (it is the joint frame moved along or about the axis), so the Jacobian column of
//! a joint `k ∈ κ(i)` with world axis `a_k = R_k s_k` is `[a_k × (x_f − x_k); a_k]` (revolute)
//! or `[a_k; 0]` (prismatic), and zero for the joints that do not support the body.
//!
//! Rows are `[v (3); ω (3)]`: the velocity of the frame origin and the angular velocity of its
//! body, in base-frame axes (fixed base) or inertial axes (free-floating base) — Pinocchio's
//! `LOCAL_WORLD_ALIGNED` frame Jacobian. Free-floating conventions: [`crate::base`].
//!
//! ```
//! use kanegen_dynamics::algorithms::frames;
//! use kanegen_dynamics::linalg::{Mat3, Vec3};
//! use kanegen_dynamics::{FrameParams, Params};
//! use kanegen_model::random::{random_tree, ChainSpec};
//! let tree = random_tree(&ChainSpec { n: 5, ..Default::default() }, 2);
//! let p = Params::<f64>::new(&tree);
//! // A tool point 0.1 m along x of body 4.
//! let tool = FrameParams { parent: Some(4), translation: Vec3::new(0.1, 0.0, 0.0), rotation: Mat3::identity() };
//! let q = [0.1, 0.2, -0.3, 0.4, 0.5];
//! let (x, _r) = frames::placement(&p, &q, &tool);
//! let j = frames::jacobian(&p, &q, &tool);
//! // A small joint motion moves the point by J q̇ dt.
//! let (h, qd) = (1e-6, [0.3, -0.1, 0.2, 0.5, -0.4]);
//! let q2: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
//! let (x2, _) = frames::placement(&p, &q2, &tool);
//! for r in 0..3 {
//!     let v: f64 = (0..5).map(|k| j[r][k] * qd[k]).sum();
//!     assert!(((x2.at(r) - x.at(r)) / h - v).abs() < 1e-5);
//! }
//! ```

use crate::algorithms::crba;
use crate::base::{FloatingBase, FloatingState, FLOATING_BASE_DOF};
use crate::joint::xup;
use crate::ldlt::{ldlt, solve};
use crate::linalg::{Mat3, Vec3};
use crate::params::{FrameParams, Params};
use crate::scalar::Scalar;
use kanegen_model::JointKind;

/// A placement `(x, R)`: origin and orientation (`x_outer = R x_inner + x`).
type Pose<S> = (Vec3<S>, Mat3<S>);

/// The support set `κ(i)` of body `i` (`None`: the base, an empty set), ordered from the base.
fn support<S>(p: &Params<S>, body: Option<usize>) -> Vec<usize> {
    let mut path = Vec::new();
    let mut b = body;
    while let Some(k) = b {
        assert!(
            k < p.dof(),
            "frame on body #{k}, but the model has {} bodies",
            p.dof()
        );
        path.push(k);
        b = p.joints[k].parent;
    }
    path.reverse();
    path
}

/// The placement `(x_k, R_k)` in the base frame of every body `k` of `path` (ordered from the
/// base, each the parent of the next), and the frame's placement at the end.
fn walk<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    path: &[usize],
    f: &FrameParams<S>,
) -> (Vec<Pose<S>>, Pose<S>) {
    assert_eq!(q.len(), p.dof(), "q has the wrong length");
    let mut x = Vec3::zero();
    let mut r = Mat3::identity();
    let mut bodies = Vec::with_capacity(path.len());
    for &k in path {
        // x_k = x_λ + R_λ r_k, R_k = R_λ E_kᵀ
        let xk = xup(&p.joints[k], &q[k]);
        x = &x + &r.mul_vec(&xk.r);
        r = r.mul_mat(&xk.e.transpose());
        bodies.push((x.clone(), r.clone()));
    }
    // x_f = x_i + R_i t_f, R_f = R_i R_{f,i}
    let xf = &x + &r.mul_vec(&f.translation);
    let rf = r.mul_mat(&f.rotation);
    (bodies, (xf, rf))
}

/// The placement of frame `f` in the base frame at joint positions `q`: its origin `x_f` and its
/// orientation `R_f` (`x_base = R_f x_frame + x_f`), fixed base.
pub fn placement<S: Scalar>(p: &Params<S>, q: &[S], f: &FrameParams<S>) -> (Vec3<S>, Mat3<S>) {
    walk(p, q, &support(p, f.parent), f).1
}

/// The Jacobian of frame `f` at `q`, fixed base: 6 rows `[v (3); ω (3)]` (velocity of the frame
/// origin, angular velocity of its body, base-frame axes), `N` columns, `[v; ω] = J q̇`.
/// Columns of joints outside the support set `κ` of the frame's body are zero.
pub fn jacobian<S: Scalar>(p: &Params<S>, q: &[S], f: &FrameParams<S>) -> Vec<Vec<S>> {
    jacobian_and_origin(p, q, f).0
}

/// [`jacobian`] and the frame origin `x_f` (base frame).
fn jacobian_and_origin<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    f: &FrameParams<S>,
) -> (Vec<Vec<S>>, Vec3<S>) {
    let path = support(p, f.parent);
    let (bodies, (xf, _)) = walk(p, q, &path, f);
    let mut j = vec![vec![S::zero(); p.dof()]; 6];
    for (&k, (xk, rk)) in path.iter().zip(&bodies) {
        let jp = &p.joints[k];
        let a = rk.mul_vec(&jp.axis);
        let (v, w) = match jp.kind {
            JointKind::Revolute => (a.cross(&(&xf - xk)), a),
            JointKind::Prismatic => (a, Vec3::zero()),
        };
        for m in 0..3 {
            j[m][k] = v.at(m);
            j[3 + m][k] = w.at(m);
        }
    }
    (j, xf)
}

/// The placement of frame `f` in the inertial frame, free-floating base in pose `state`:
/// `(p₀ + R₀ x_f, R₀ R_f)` with `(x_f, R_f)` of [`placement`].
pub fn floating_placement<S: Scalar>(
    p: &Params<S>,
    state: &FloatingState<S>,
    q: &[S],
    f: &FrameParams<S>,
) -> (Vec3<S>, Mat3<S>) {
    let (x, r) = placement(p, q, f);
    (
        &state.position + &state.rotation.mul_vec(&x),
        state.rotation.mul_mat(&r),
    )
}

/// The Jacobian of frame `f`, free-floating base: 6 rows `[v (3); ω (3)]` in inertial axes,
/// `6 + N` columns for `ν = [v_b, ω_b, q̇]` (base coordinates, [`crate::base`]). Base columns:
/// `v_b,m` gives `[R₀ e_m; 0]`, `ω_b,m` gives `[R₀ (e_m × x_f); R₀ e_m]` (`x_f` in the base
/// frame); the joint columns are `R₀` times those of [`jacobian`].
pub fn floating_jacobian<S: Scalar>(
    p: &Params<S>,
    state: &FloatingState<S>,
    q: &[S],
    f: &FrameParams<S>,
) -> Vec<Vec<S>> {
    let n = p.dof();
    let nb = FLOATING_BASE_DOF;
    let (fixed, xf) = jacobian_and_origin(p, q, f);
    let r0 = &state.rotation;
    let mut j = vec![vec![S::zero(); nb + n]; 6];
    let mut put = |col: usize, v: &Vec3<S>, w: &Vec3<S>| {
        let (v, w) = (r0.mul_vec(v), r0.mul_vec(w));
        for m in 0..3 {
            j[m][col] = v.at(m);
            j[3 + m][col] = w.at(m);
        }
    };
    for m in 0..3 {
        let mut e = Vec3::zero();
        e.0[m] = S::one();
        put(m, &e, &Vec3::zero());
        put(3 + m, &e.cross(&xf), &e);
    }
    #[allow(clippy::needless_range_loop)] // column k of `fixed` is read across its rows
    for k in 0..n {
        let part = |top: usize| Vec3(core::array::from_fn(|m| fixed[top + m][k].clone()));
        put(nb + k, &part(0), &part(3));
    }
    j
}

/// The generalized Jacobian of frame `f` (Umetani & Yoshida 1989): `J* = J_m − J_b A_bb⁻¹ A_bm`
/// (6 × N), with `[J_b J_m]` of [`floating_jacobian`] and `A` of
/// [`crba::floating_mass_matrix`] (`A_bb⁻¹` by LDLᵀ). When the system's momentum is zero the base
/// twist is `ν_b = −A_bb⁻¹ A_bm q̇`, and `J* q̇` is the frame's `[v; ω]` (inertial axes).
pub fn generalized_jacobian<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    f: &FrameParams<S>,
) -> Vec<Vec<S>> {
    let n = p.dof();
    let nb = FLOATING_BASE_DOF;
    let a = crba::floating_mass_matrix(p, base, q);
    let a_bb: Vec<Vec<S>> = a[..nb].iter().map(|r| r[..nb].to_vec()).collect();
    let factor = ldlt(&a_bb);
    // Column j of A_bb⁻¹ A_bm.
    let sol: Vec<Vec<S>> = (0..n)
        .map(|j| {
            let col: Vec<S> = (0..nb).map(|i| a[i][nb + j].clone()).collect();
            solve(&factor, &col)
        })
        .collect();
    floating_jacobian(p, state, q, f)
        .iter()
        .map(|row| {
            (0..n)
                .map(|j| {
                    let jb =
                        (0..nb).fold(S::zero(), |acc, i| acc + row[i].clone() * sol[j][i].clone());
                    row[nb + j].clone() - jb
                })
                .collect()
        })
        .collect()
}
