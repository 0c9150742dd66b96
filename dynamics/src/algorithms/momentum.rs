//! Total momentum and kinetic energy of a kinematic tree on a free-floating base, from the spatial
//! velocities of its bodies in local coordinates (RBDA §2.13: the spatial momentum of a body is
//! `h = I v`, its kinetic energy `T = ½ v · I v`, and momenta of several bodies add once they
//! are expressed in one frame).
//!
//! Forward pass (as in [`crate::algorithms::rnea`]): `v_0 = [ω_b; v_b]` for the base (body −1 of
//! the arm), `v_i = Xup_i v_λ(i) + S_i q̇_i`. Backward pass: `h_i = I_i v_i`,
//! `h_λ(i) += Xup_iᵀ h_i`, `h_0 = I_0 v_0 + Σ_{λ(i) = base} Xup_iᵀ h_i` (the whole system's momentum
//! about the base origin, base coordinates, which is also `A[0..6, :] ν`); then into inertial
//! coordinates about the inertial origin: `P = R₀ h_0.f`, `L_O = R₀ h_0.n + p₀ × P`.
//! Conventions of [`crate::base`]. Any kinematic tree.
//!
//! ```
//! use kanegen_dynamics::algorithms::{crba, momentum};
//! use kanegen_dynamics::base::{FloatingBase, FloatingState};
//! use kanegen_dynamics::Params;
//! use kanegen_model::random::{random_tree, ChainSpec};
//! let tree = random_tree(&ChainSpec { n: 4, ..Default::default() }, 5);
//! let p = Params::<f64>::new(&tree);
//! let base = FloatingBase::<f64>::from_inertial(&kanegen_model::Inertial {
//!     mass: 50.0, com: [0.1, 0.0, 0.0], inertia: [[4.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 6.0]],
//! });
//! let mut state = FloatingState::<f64>::at_rest();
//! state.omega_b.0 = [0.1, -0.2, 0.3];
//! let (q, qd) = ([0.1, 0.2, 0.3, 0.4], [0.5, -0.5, 1.0, 0.2]);
//! // T = ½ νᵀ A ν
//! let a = crba::floating_mass_matrix(&p, &base, &q);
//! let nu = [0.0, 0.0, 0.0, 0.1, -0.2, 0.3, 0.5, -0.5, 1.0, 0.2];
//! let t: f64 = (0..10).map(|i| (0..10).map(|j| 0.5 * nu[i] * a[i][j] * nu[j]).sum::<f64>()).sum();
//! assert!((momentum::kinetic_energy(&p, &base, &state, &q, &qd) - t).abs() < 1e-12 * t);
//! ```

use crate::base::{FloatingBase, FloatingState};
use crate::joint::{s_times, xup};
use crate::linalg::Vec3;
use crate::params::Params;
use crate::scalar::Scalar;
use crate::spatial::{base_rows, Force, Motion, RbInertia, Xform};

/// The forward pass: `Xup_i`, `v_i` and the body inertia `I_i` of every body, and `(I_0, v_0)`
/// of the base.
#[allow(clippy::type_complexity)] // one tuple per body, read right away by the two callers
fn velocities<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
) -> (
    (RbInertia<S>, Motion<S>),
    Vec<(Xform<S>, Motion<S>, RbInertia<S>)>,
) {
    let n = p.dof();
    assert_eq!(q.len(), n, "q has the wrong length");
    assert_eq!(qd.len(), n, "qd has the wrong length");
    let v0 = Motion {
        ang: state.omega_b.clone(),
        lin: state.v_b.clone(),
    };
    let i0 = base.inertia.clone();
    let mut bodies: Vec<(Xform<S>, Motion<S>, RbInertia<S>)> = Vec::with_capacity(n);
    for (jp, (qj, qdj)) in p.joints.iter().zip(q.iter().zip(qd)) {
        let x = xup(jp, qj);
        // v_i = Xup_i v_λ(i) + S_i q̇_i
        let v_parent = match jp.parent {
            Some(lambda) => &bodies[lambda].1,
            None => &v0,
        };
        let v = x.apply(v_parent) + s_times(jp, qdj);
        bodies.push((x, v, jp.inertia.clone()));
    }
    ((i0, v0), bodies)
}

/// Total linear momentum `P` and angular momentum `L` about the inertial origin, both in inertial
/// coordinates, of the base and every body of the tree `p` (Pinocchio's `momentum` reference:
/// `[P; L_O]`). `state` is the base's pose and twist, `q`, `qd` the joint positions and rates.
pub fn momentum<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
) -> (Vec3<S>, Vec3<S>) {
    let h0 = spatial_momentum(p, base, state, q, qd);
    let lin = state.rotation.mul_vec(&h0.lin);
    let ang = state.rotation.mul_vec(&h0.ang) + state.position.cross(&lin);
    (lin, ang)
}

/// The system's total momentum about the base origin in base coordinates, `[P (3); L (3)]`
/// (linear first, as the base rows of `ν`): it equals `A[0..6, :] ν` (the reference files'
/// `momentum_base`).
pub fn momentum_base<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
) -> [S; 6] {
    base_rows(&spatial_momentum(p, base, state, q, qd))
}

/// `h_0 = [n; f]`: the backward pass of the module doc.
fn spatial_momentum<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
) -> Force<S> {
    let ((i0, v0), bodies) = velocities(p, base, state, q, qd);
    // h_i = I_i v_i, then h_λ(i) += Xup_iᵀ h_i from the leaves.
    let mut h: Vec<Force<S>> = bodies.iter().map(|(_, v, i)| i.mul(v)).collect();
    let mut h0 = i0.mul(&v0);
    for (i, jp) in p.joints.iter().enumerate().rev() {
        let carried = bodies[i].0.tr_apply(&h[i]);
        match jp.parent {
            Some(lambda) => {
                let parent = h[lambda].clone();
                h[lambda] = parent + carried;
            }
            None => h0 = h0 + carried,
        }
    }
    h0
}

/// Total kinetic energy of the base and every body of the tree:
/// `T = ½ (v_0 · I_0 v_0 + Σ_i v_i · I_i v_i)` (equal to `½ νᵀ A ν`).
pub fn kinetic_energy<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
) -> S {
    let ((i0, v0), bodies) = velocities(p, base, state, q, qd);
    let twice = |i: &RbInertia<S>, v: &Motion<S>| {
        let h = i.mul(v);
        v.ang.dot(&h.ang) + v.lin.dot(&h.lin)
    };
    let sum = bodies
        .iter()
        .fold(twice(&i0, &v0), |acc, (_, v, i)| acc + twice(i, v));
    sum * S::constant(0.5)
}
