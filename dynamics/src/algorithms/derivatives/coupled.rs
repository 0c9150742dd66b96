//! Derivatives in the independent coordinates of mimic joints ([`crate::mimic`]): with the
//! constant coupling `q_full = G q + o` and `τ = Gᵀ τ_full`, the chain rule gives
//! `∂τ/∂q = Gᵀ (∂τ_full/∂q_full) G` and the same for `q̇`; forward dynamics solves the reduced
//! `M = Gᵀ M_full G` (LDLᵀ), and its derivatives are `−M⁻¹ ∂τ/∂x` at that `q̈` (Carpentier &
//! Mansard, RSS 2018, eq. (3), in the reduced coordinates). `offset`: the base's six speeds of a
//! free-floating model, first and kept.

use super::{minverse, neg_product, Matrix};
use crate::mimic::Coupling;
use crate::scalar::Scalar;

/// `(Gᵀ D_q G, Gᵀ D_v G)`: the inverse-dynamics derivatives of the full joint list reduced to the
/// independent coordinates.
#[must_use]
pub fn reduce_pair<S: Scalar>(
    c: &Coupling,
    offset: usize,
    (dq, dv): (Matrix<S>, Matrix<S>),
) -> (Matrix<S>, Matrix<S>) {
    (c.reduce_matrix(&dq, offset), c.reduce_matrix(&dv, offset))
}

/// `(Gᵀ M_full G)⁻¹`.
#[must_use]
pub fn mass_matrix_inverse<S: Scalar>(c: &Coupling, offset: usize, m_full: &[Vec<S>]) -> Matrix<S> {
    S::section("derivatives:minverse");
    minverse::inverse(&c.reduce_matrix(m_full, offset))
}

/// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` in the independent coordinates, from the full `M`, the full
/// `τ − c` (drives on the independent joints only) and the full inverse-dynamics derivatives
/// `id_derivatives(ν̇_full)` at the full accelerations.
pub fn forward_dynamics_derivatives<S: Scalar>(
    c: &Coupling,
    offset: usize,
    m_full: &[Vec<S>],
    b_full: &[S],
    id_derivatives: impl FnOnce(&[S]) -> (Matrix<S>, Matrix<S>),
) -> (Matrix<S>, Matrix<S>, Matrix<S>) {
    let minv = mass_matrix_inverse(c, offset, m_full);
    // q̈ = M⁻¹ Gᵀ (τ_full − c_full), then ν̇_full = [base; G q̈]
    let nu_dot = super::aba::product(&minv, &c.reduce_vector(b_full, offset));
    let (head, qdd) = nu_dot.split_at(offset);
    let full = [head.to_vec(), c.full_rates(qdd)].concat();
    let (dq, dv) = reduce_pair(c, offset, id_derivatives(&full));
    S::section("derivatives:aba");
    (neg_product(&minv, &dq), neg_product(&minv, &dv), minv)
}
