//! The composite-rigid-body algorithm (Stepanenko's method, the CRBA) in the paper's base-frame
//! notation: the comparison baseline of Table 1 (Stepanenko's method, `docs/paper.md`).
//!
//! It starts from the same base-frame inputs as the recurrent algorithm ([`BodyKinematics`]:
//! `r_{j-1,j}`, `a_j`, `m_j`, `c_j`, `I_j` about `O_j`) and the same reference points `O_i`.
//! Indices are 0-based (paper body `j` is our `j − 1`).
//!
//! 1. Composite bodies (section `"crba:composite"`), from the tip: mass `m^c_i`, first moment
//!    `h^c_i` and inertia `J^c_i` of bodies `i..N` about `O_i`, by the parallel-axis shift from
//!    `O_{i+1}` to `O_i` (`r = r_{i,i+1}`, `g = m^c_{i+1} r + h^c_{i+1}`):
//!    `m^c_i = m_i + m^c_{i+1}`, `h^c_i = c_i + g`, `J^c_i = I_i + J^c_{i+1} + r̃ g̃ᵀ + h̃^c_{i+1} r̃ᵀ`.
//! 2. Columns (section `"crba:columns"`): the composite body `j..N` moving with unit joint rate
//!    `j` has momentum `f` and angular momentum `n` about `O_j`:
//!    revolute `f = a_j × h^c_j`, `n = J^c_j a_j`; prismatic `f = m^c_j e_j`, `n = h^c_j × e_j`.
//!    Moving the reference point down the chain, `n ← n + r_{i,i+1} × f`, and
//!    `A_ij = a_i · n` (revolute `i`) or `e_i · f` (prismatic `i`).
//!
//! `b` reuses the recurrent algorithm's base-frame force recursion
//! ([`recurrent::bias_base`]).

use crate::algorithms::kinematics::{base_frame, inertial_external, motion, BodyKinematics};
use crate::algorithms::recurrent;
use crate::linalg::{Mat3, Vec3};
use crate::loads::Loads;
use crate::params::Params;
use crate::scalar::Scalar;
use kanegen_model::JointKind;

/// The generalized inertia matrix `A` (full symmetric, `a[i][j]`) from base-frame inputs by the
/// composite-rigid-body algorithm. Panics if `kin` is empty.
pub fn mass_matrix_base<S: Scalar>(kin: &[BodyKinematics<S>]) -> Vec<Vec<S>> {
    let n = kin.len();
    assert!(n > 0, "crba_base: empty chain");
    let last = n - 1;

    S::section("crba:composite");
    // m^c_N = m_N, h^c_N = c_N, J^c_N = I_N; then the parallel-axis shift O_{i+1} → O_i.
    let mut m_c: Vec<S> = vec![S::zero(); n];
    let mut h_c: Vec<Vec3<S>> = vec![Vec3::zero(); n];
    let mut j_c: Vec<Mat3<S>> = vec![Mat3::zero(); n];
    m_c[last] = kin[last].m.clone();
    h_c[last] = kin[last].c.clone();
    j_c[last] = kin[last].inertia.clone();
    for i in (0..last).rev() {
        let r = &kin[i + 1].r; // r_{i,i+1}
        m_c[i] = kin[i].m.clone() + m_c[i + 1].clone();
        // g = m^c_{i+1} r + h^c_{i+1}: first moment of bodies i+1..N about O_i.
        let g = r.scale(&m_c[i + 1]) + h_c[i + 1].clone();
        h_c[i] = &kin[i].c + &g;
        // Σ dm (ρ + r)~(ρ + r)~ᵀ = J^c_{i+1} + r̃ g̃ᵀ + h̃^c_{i+1} r̃ᵀ, ρ measured from O_{i+1}.
        let sr = Mat3::skew(r);
        j_c[i] = &kin[i].inertia
            + &j_c[i + 1]
            + sr.mul_mat(&Mat3::skew(&g).transpose())
            + Mat3::skew(&h_c[i + 1]).mul_mat(&sr.transpose());
    }

    S::section("crba:columns");
    let mut a = vec![vec![S::zero(); n]; n];
    for j in 0..n {
        let aj = &kin[j].axis;
        // Momentum f and angular momentum n about O_j of bodies j..N at unit rate of joint j.
        let (f, mut nn) = match kin[j].kind {
            JointKind::Revolute => (aj.cross(&h_c[j]), j_c[j].mul_vec(aj)),
            JointKind::Prismatic => (aj.scale(&m_c[j]), h_c[j].cross(aj)),
        };
        let project = |i: usize, nn: &Vec3<S>| match kin[i].kind {
            JointKind::Revolute => kin[i].axis.dot(nn),
            JointKind::Prismatic => kin[i].axis.dot(&f),
        };
        a[j][j] = project(j, &nn);
        for i in (0..j).rev() {
            // n ← n + r_{i,i+1} × f  (angular momentum about O_i)
            nn = nn + kin[i + 1].r.cross(&f);
            let x = project(i, &nn);
            a[j][i] = x.clone();
            a[i][j] = x;
        }
    }
    a
}

/// The generalized inertia matrix `A(q)`: base-frame kinematics (1), (2), (6) then
/// [`mass_matrix_base`].
///
/// # Panics
/// On a kinematic tree (serial chains only; [`Params::assert_chain`]).
pub fn mass_matrix<S: Scalar>(p: &Params<S>, q: &[S]) -> Vec<Vec<S>> {
    p.assert_chain("crba-base");
    mass_matrix_base(&base_frame(p, q))
}

/// The generalized forces `b(q, q̇) = Q − h`: the same base-frame computation as the recurrent
/// algorithm — kinematics (1)–(7), resultants (11) and the force recursion (17)–(21) of
/// [`recurrent::bias_base`] (a CRBA computes only `A`; `b` comes from an inverse-dynamics pass).
///
/// # Panics
/// On a kinematic tree (serial chains only; [`Params::assert_chain`]).
pub fn bias<S: Scalar>(p: &Params<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
    p.assert_chain("crba-base");
    let kin = base_frame(p, q);
    let mot = motion(&kin, qd);
    let f_ie = inertial_external(&kin, &mot, loads);
    recurrent::bias_base(&kin, &f_ie, loads.tau.as_deref())
}
