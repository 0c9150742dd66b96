//! The inverse of the mass matrix, `M(q)⁻¹`, from the LDLᵀ factors of the CRBA's `M`
//! (RBDA §6.2, Table 6.2; [`crate::ldlt`]): `M = L D Lᵀ`, then `M⁻¹ e_k` for each unit column
//! `e_k` by one forward and one back substitution (`N³/2` multiplications beyond the
//! factorization), symmetric up to rounding. It is the `M⁻¹` of forward dynamics, `∂q̈/∂τ`
//! (Carpentier & Mansard, RSS 2018, eq. (3)).

use super::Matrix;
use crate::algorithms::crba;
use crate::base::FloatingBase;
use crate::ldlt::{ldlt, solve};
use crate::params::Params;
use crate::scalar::Scalar;

/// `M⁻¹` of a symmetric positive definite `M`: `L D Lᵀ x = e_k` for every `k` (column `k` of
/// `M⁻¹`, stored as its row `k` by symmetry).
pub(crate) fn inverse<S: Scalar>(m: &[Vec<S>]) -> Matrix<S> {
    let n = m.len();
    let f = ldlt(m);
    (0..n)
        .map(|k| {
            let e: Vec<S> = (0..n)
                .map(|i| if i == k { S::one() } else { S::zero() })
                .collect();
            solve(&f, &e)
        })
        .collect()
}

/// `M(q)⁻¹`, `N × N`, of a fixed-base tree `p` at `q` (length `N`). Section
/// `"derivatives:minverse"`.
pub fn mass_matrix_inverse<S: Scalar>(p: &Params<S>, q: &[S]) -> Matrix<S> {
    S::section("derivatives:minverse");
    inverse(&crba::mass_matrix(p, q))
}

/// `M(q)⁻¹`, `(6 + N) × (6 + N)`, of the tree `p` on the free-floating base `base` (speeds
/// `ν = [v_b; ω_b; q̇]`; `M` does not depend on the base pose). Section
/// `"derivatives:minverse"`.
pub fn floating_mass_matrix_inverse<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    q: &[S],
) -> Matrix<S> {
    S::section("derivatives:minverse");
    inverse(&crba::floating_mass_matrix(p, base, q))
}
