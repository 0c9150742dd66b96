//! STUB — being written.
use crate::algorithms::Loads;
use crate::model::ChainParams;
use crate::scalar::Scalar;

/// Generalized inertia matrix (stub).
pub fn mass_matrix<S: Scalar>(p: &ChainParams<S>, _q: &[S]) -> Vec<Vec<S>> {
    let n = p.dof();
    vec![vec![S::zero(); n]; n]
}
/// Generalized forces (stub).
pub fn bias<S: Scalar>(p: &ChainParams<S>, _q: &[S], _qd: &[S], _loads: &Loads<S>) -> Vec<S> {
    vec![S::zero(); p.dof()]
}
