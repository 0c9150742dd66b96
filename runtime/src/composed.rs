//! Forward-dynamics derivatives composed from a generated type's own functions (Carpentier &
//! Mansard, RSS 2018, eq. (3)): `q̈ = M⁻¹ (τ − c)`, then `∂q̈/∂x = −M⁻¹ ∂τ/∂x` for
//! `x = q, q̇`, with `∂τ/∂x` the inverse-dynamics derivatives at that `q̈`. A straight-line
//! `forward_dynamics_derivatives` grows past the instruction cache from about eight joints
//! (`kanegen_codegen::compact::DERIVATIVES_AUTO_LIMIT`); composed, it calls the type's
//! `mass_matrix_inverse`, `nonlinear_effects` and `inverse_dynamics_derivatives` (each emitted
//! in its own best form) and adds the two loops here. On a free-floating base the matrices are
//! `NV × NV` (`NV = 6 + N`) in Pinocchio's tangent space and the drives act on the last `N`
//! speeds; with mimic joints everything is in the independent coordinates. The loops are over a
//! [`Ring`]: the generated `f64` or `f32`, or a lane vector of [`crate::lanes`], where
//! `forward_dynamics_derivatives_lanes` composes its parts' lane forms the same way.

use crate::compact::derivatives::{accelerations as solve, neg_product};
use crate::Ring;

/// `q̈ = M⁻¹ (τ_full − c)`, `τ_full = [0 (NV − N); τ]` (no drive on a free-floating base's own
/// six speeds).
#[inline]
#[must_use]
pub fn accelerations<S: Ring, const N: usize, const NV: usize>(
    minv: &[[S; NV]; NV],
    tau: &[S; N],
    c: &[S; NV],
) -> [S; NV] {
    let mut full = [S::zero(); NV];
    for (f, t) in full[NV.saturating_sub(N)..].iter_mut().zip(tau) {
        *f = *t;
    }
    let mut qdd = [S::zero(); NV];
    solve(minv.as_flattened(), &full, c, &mut qdd);
    qdd
}

/// Pinocchio's three matrices of the forward-dynamics derivatives: `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)`.
pub type Derivatives<S, const NV: usize> = ([[S; NV]; NV], [[S; NV]; NV], [[S; NV]; NV]);

/// `∂q̈/∂x = −M⁻¹ ∂τ/∂x` into `d.0` (`x = q`) and `d.1` (`x = q̇`), from `d.2 = M⁻¹` and the
/// inverse-dynamics derivatives `(∂τ/∂q, ∂τ/∂q̇)` at the forward dynamics' `q̈`
/// ([`accelerations`]); in place, so that no matrix is copied.
#[inline]
pub fn forward_dynamics_derivatives<S: Ring, const NV: usize>(
    d: &mut Derivatives<S, NV>,
    (dtq, dtv): &([[S; NV]; NV], [[S; NV]; NV]),
) {
    let m = d.2.as_flattened();
    neg_product(m, dtq.as_flattened(), NV, d.0.as_flattened_mut());
    neg_product(m, dtv.as_flattened(), NV, d.1.as_flattened_mut());
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a 2 × 2 example worked by hand: `q̈ = M⁻¹ (τ − c)` with the free-floating offset,
    /// and `−M⁻¹ D`.
    #[test]
    fn composes_by_hand() {
        let minv = [[2.0, 1.0], [1.0, 3.0]];
        assert_eq!(accelerations(&minv, &[5.0, 7.0], &[1.0, 2.0]), [13.0, 19.0]);
        assert_eq!(accelerations(&minv, &[7.0], &[1.0, 2.0]), [3.0, 14.0]);
        let d = [[1.0, 0.0], [0.0, 2.0]];
        let mut out = ([[9.0; 2]; 2], [[9.0; 2]; 2], minv);
        forward_dynamics_derivatives(&mut out, &(d, [[0.0; 2]; 2]));
        assert_eq!(out.0, [[-2.0, -2.0], [-1.0, -6.0]]);
        assert_eq!(out.1, [[0.0; 2]; 2]);
        assert_eq!(out.2, minv);
    }
}
