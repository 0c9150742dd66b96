//! The direct Kane sums of the paper, eq. (9)–(11): `O(N³)`, the reference the recurrent
//! algorithm reorders.
//!
//! The partial-velocity matrices `T_j = ∂v_j/∂q̇` and `R_j = ∂ω_j/∂q̇` (3 × N, only columns
//! `0..=j` non-zero) are built by the recursion (3); then
//!
//! - (9) `A = Σ_j { T_jᵀ m_j T_j + T_jᵀ c̃_jᵀ R_j + [T_jᵀ c̃_jᵀ R_j]ᵀ + R_jᵀ I_j R_j }`,
//! - (10) `b = Σ_j [T_jᵀ f^IE_j + R_jᵀ m^IE_j] + Σ_j [T^rel(j)ᵀ f^J + R^rel(j)ᵀ m^J]`,
//!
//! with `f^IE`, `m^IE` from (11) ([`kinematics::inertial_external`]). Indices are 0-based: body `j`
//! is moved by joint `j`. `A` is accumulated on the upper triangle `i ≤ k ≤ j` and mirrored.
//!
//! ```
//! use kanegen_dynamics::algorithms::{crba, kane_direct};
//! use kanegen_model::random::{random_chain, ChainSpec};
//! use kanegen_dynamics::Params;
//! let chain = random_chain(&ChainSpec { n: 4, prismatic_fraction: 0.5, ..Default::default() }, 3);
//! let p = Params::<f64>::new(&chain);
//! let q = [0.3, -0.2, 0.5, 1.0];
//! let a = kane_direct::mass_matrix(&p, &q);
//! let h = crba::mass_matrix(&p, &q);
//! for i in 0..4 {
//!     for k in 0..4 {
//!         assert!((a[i][k] - h[i][k]).abs() < 1e-10 * (1.0 + h[i][k].abs()));
//!     }
//! }
//! ```

use crate::algorithms::kinematics::{self, BodyKinematics};
use crate::linalg::{Mat3, Vec3};
use crate::loads::Loads;
use crate::params::Params;
use crate::scalar::Scalar;
use kanegen_model::JointKind;

/// The partial-velocity matrices of one body: columns `0..=j` of `T_j` and `R_j` (the others are
/// zero and not stored).
struct PartialVelocities<S> {
    /// `T_j` columns: `∂v_j/∂q̇_l`, `l ≤ j`.
    t: Vec<Vec3<S>>,
    /// `R_j` columns: `∂ω_j/∂q̇_l`, `l ≤ j`.
    r: Vec<Vec3<S>>,
}

/// Eq. (3): `R_j = R_{j-1} + R^rel_j`, `T_j = T_{j-1} + r̃ᵀ_{j-1,j} R_{j-1} + T^rel_j`, fixed base
/// (`T_{-1} = R_{-1} = 0`). `R^rel_j` (revolute) or `T^rel_j` (prismatic) has the single non-zero
/// column `j`, the joint axis in the inertial frame.
fn partial_velocities<S: Scalar>(kin: &[BodyKinematics<S>]) -> Vec<PartialVelocities<S>> {
    S::section("(3)");
    let mut out: Vec<PartialVelocities<S>> = Vec::with_capacity(kin.len());
    for k in kin {
        let (mut t, mut r) = match out.last() {
            None => (Vec::new(), Vec::new()),
            Some(prev) => {
                // (3) r̃ᵀ_{j-1,j}
                let rt = Mat3::skew(&k.r).transpose();
                // (3) T_j = T_{j-1} + r̃ᵀ_{j-1,j} R_{j-1}, R_j = R_{j-1}  (columns l < j)
                let t = prev
                    .t
                    .iter()
                    .zip(&prev.r)
                    .map(|(tl, rl)| tl + &rt.mul_vec(rl))
                    .collect();
                (t, prev.r.clone())
            }
        };
        // (3) column j: + T^rel_j (prismatic) or + R^rel_j (revolute)
        match k.kind {
            JointKind::Revolute => {
                t.push(Vec3::zero());
                r.push(k.axis.clone());
            }
            JointKind::Prismatic => {
                t.push(k.axis.clone());
                r.push(Vec3::zero());
            }
        }
        out.push(PartialVelocities { t, r });
    }
    out
}

/// Eq. (9) from inertial-frame inputs (eq. (1), (2), (6): [`kinematics::inertial_frame`]): the generalized
/// inertia matrix `A`, full and symmetric (upper triangle accumulated, then mirrored).
/// Section `"(9)"` (the partial velocities are traced under `"(3)"`).
pub fn mass_matrix_inertial<S: Scalar>(kin: &[BodyKinematics<S>]) -> Vec<Vec<S>> {
    let n = kin.len();
    let pv = partial_velocities(kin);
    S::section("(9)");
    let mut a = vec![vec![S::zero(); n]; n];
    for (k, pvj) in kin.iter().zip(&pv) {
        let ct = Mat3::skew(&k.c);
        let ctt = ct.transpose();
        // Per column l of body j: u_l = m_j T_l + c̃_jᵀ R_l and w_l = c̃_j T_l + I_j R_l, so that
        // (9) A_il += T_iᵀ u_l + R_iᵀ w_l   [= T_iᵀ m T_l + T_iᵀ c̃ᵀ R_l + (R_iᵀ c̃ T_l) + R_iᵀ I R_l].
        let (u, w): (Vec<Vec3<S>>, Vec<Vec3<S>>) = pvj
            .t
            .iter()
            .zip(&pvj.r)
            .map(|(tl, rl)| {
                let u = tl.scale(&k.m) + ctt.mul_vec(rl);
                let w = ct.mul_vec(tl) + k.inertia.mul_vec(rl);
                (u, w)
            })
            .unzip();
        for (i, (ti, ri)) in pvj.t.iter().zip(&pvj.r).enumerate() {
            for (l, (ul, wl)) in u.iter().zip(&w).enumerate().skip(i) {
                // (9) upper triangle i ≤ l ≤ j
                let term = ti.dot(ul) + ri.dot(wl);
                a[i][l] = a[i][l].clone() + term;
            }
        }
    }
    // (9) A is symmetric: mirror the upper triangle.
    let upper = a.clone();
    for (i, row) in a.iter_mut().enumerate() {
        for (l, x) in row.iter_mut().enumerate().take(i) {
            *x = upper[l][i].clone();
        }
    }
    a
}

/// The generalized inertia matrix `A(q)` by the direct sum (9).
///
/// # Panics
/// On a kinematic tree (serial chains only; [`Params::assert_chain`]).
pub fn mass_matrix<S: Scalar>(p: &Params<S>, q: &[S]) -> Vec<Vec<S>> {
    p.assert_chain("kane-direct");
    mass_matrix_inertial(&kinematics::inertial_frame(p, q))
}

/// The generalized forces `b(q, q̇, loads) = Q − h` by the direct sum (10), with the resultants
/// (11) (gravity at each centre of mass, external wrenches at `O_j` in the body or the base frame) and
/// the joint drives `loads.tau` (added when present). Section `"(10)"`.
///
/// # Panics
/// On a kinematic tree (serial chains only; [`Params::assert_chain`]).
pub fn tau_minus_c<S: Scalar>(p: &Params<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
    p.assert_chain("kane-direct");
    let n = p.dof();
    if let Some(tau) = &loads.tau {
        assert_eq!(tau.len(), n, "loads.tau has the wrong length");
    }
    let kin = kinematics::inertial_frame(p, q);
    let mot = kinematics::motion(&kin, qd);
    let fie = kinematics::inertial_external(&kin, &mot, loads);
    tau_minus_c_inertial(&kin, &fie, loads.tau.as_deref())
}

/// The direct sum (10) from inertial-frame inputs: the kinematics `kin` of eq. (1), (2), (6), the
/// resultants `fie[j] = (f^IE_j, m^IE_j)` of eq. (11) and the joint drives `tau` (added when
/// present). Section `"(10)"` (the partial velocities are traced under `"(3)"`).
pub fn tau_minus_c_inertial<S: Scalar>(
    kin: &[BodyKinematics<S>],
    fie: &[(Vec3<S>, Vec3<S>)],
    tau: Option<&[S]>,
) -> Vec<S> {
    let n = kin.len();
    assert_eq!(fie.len(), n, "fie has the wrong length");
    if let Some(tau) = tau {
        assert_eq!(tau.len(), n, "tau has the wrong length");
    }
    let pv = partial_velocities(kin);
    S::section("(10)");
    let mut b = vec![S::zero(); n];
    for (pvj, (f, m)) in pv.iter().zip(fie) {
        for (l, (tl, rl)) in pvj.t.iter().zip(&pvj.r).enumerate() {
            // (10) b += T_jᵀ f^IE_j + R_jᵀ m^IE_j   (columns l ≤ j)
            b[l] = b[l].clone() + tl.dot(f) + rl.dot(m);
        }
    }
    if let Some(tau) = tau {
        for (bj, tj) in b.iter_mut().zip(tau) {
            // (10) + T^rel(j)ᵀ f^J(j) + R^rel(j)ᵀ m^J(j): the drive along the unit joint axis.
            *bj = bj.clone() + tj.clone();
        }
    }
    b
}
