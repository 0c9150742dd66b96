//! Derivatives of the dynamics for controllers (MPC, iLQR, trajectory optimization), one
//! algorithm per file, each generic over the scalar:
//!
//! | file | what |
//! |---|---|
//! | [`rnea`] | `∂τ/∂q`, `∂τ/∂q̇` of inverse dynamics: J. Carpentier and N. Mansard, "Analytical Derivatives of Rigid Body Dynamics Algorithms", RSS 2018, Algorithm 1 (Pinocchio's `computeRNEADerivatives`) |
//! | [`minverse`] | `M(q)⁻¹` from the LDLᵀ factors of the CRBA mass matrix |
//! | [`aba`] | `∂q̈/∂q`, `∂q̈/∂q̇` of forward dynamics: `−M⁻¹ ∂τ/∂x` at `q̈ = FD(q, q̇, τ)` (Carpentier & Mansard 2018, eq. (3)) |
//! | [`coupled`] | the three above in the independent coordinates of mimic joints (`Gᵀ D G`, the reduced `M⁻¹`) |
//!
//! **Layout** (Pinocchio's): row `i` = output `i`, column `j` = `∂/∂` input `j`; `NV` speeds
//! (`N` on a fixed base, `6 + N` on a free-floating one, base first in `ν = [v_b; ω_b; q̇]`).
//!
//! **Tangent space** of a free-floating base: the derivative with respect to the base pose is
//! along Pinocchio's `integrate(q, δν)`, `M₀ ← M₀ exp(δν_b)` (the perturbation in base
//! coordinates, linear part first), so the base columns of `∂/∂q` have dimension 6, not 7.
//!
//! **Loads**: gravity only (`gravity` in the base frame of a fixed base, in the inertial frame of
//! a free-floating one), no external wrenches; `τ` the joint drives.

pub mod aba;
pub mod coupled;
pub mod minverse;
pub mod rnea;

use crate::linalg::Vec3;
use crate::scalar::Scalar;
use crate::spatial::{Force, Motion, Xform};

/// A `rows × cols` matrix stored as rows (row = output, column = input).
pub type Matrix<S> = Vec<Vec<S>>;

/// `X⁻¹ m = [Eᵀ ω; Eᵀ v + r × Eᵀ ω]`: a motion of frame B coordinates in frame A's, for
/// `X = (E, r)` from A to B (the inverse of [`Xform::apply`], RBDA eq. (2.24)).
pub(crate) fn motion_back<S: Scalar>(x: &Xform<S>, m: &Motion<S>) -> Motion<S> {
    let ang = x.e.tr_mul_vec(&m.ang);
    Motion {
        lin: x.e.tr_mul_vec(&m.lin) + x.r.cross(&ang),
        ang,
    }
}

/// `Xup ∘ X0`: the transform from the base frame to a child body, given `X0` from the base to
/// its parent and `Xup` from the parent to the child (`E = E_up E_0`, `r = r_0 + E_0ᵀ r_up`).
pub(crate) fn compose<S: Scalar>(up: &Xform<S>, x0: &Xform<S>) -> Xform<S> {
    Xform {
        e: up.e.mul_mat(&x0.e),
        r: &x0.r + &x0.e.tr_mul_vec(&up.r),
    }
}

/// `fᵀ m`: the power of a force on a motion.
pub(crate) fn power<S: Scalar>(f: &Force<S>, m: &Motion<S>) -> S {
    f.ang.dot(&m.ang) + f.lin.dot(&m.lin)
}

/// `s m`: a motion scaled.
pub(crate) fn motion_scale<S: Scalar>(m: &Motion<S>, s: &S) -> Motion<S> {
    Motion {
        ang: m.ang.scale(s),
        lin: m.lin.scale(s),
    }
}

/// The unit motion of base speed `c` of `ν_b = [v_b; ω_b]` (linear first, Pinocchio's order), in
/// base coordinates: `[0; e_c]` for `c < 3`, `[e_{c−3}; 0]` otherwise.
pub(crate) fn base_unit<S: Scalar>(c: usize) -> Motion<S> {
    let unit = |k: usize| {
        Vec3(core::array::from_fn(|i| {
            if i == k {
                S::one()
            } else {
                S::zero()
            }
        }))
    };
    if c < 3 {
        Motion {
            ang: Vec3::zero(),
            lin: unit(c),
        }
    } else {
        Motion {
            ang: unit(c - 3),
            lin: Vec3::zero(),
        }
    }
}

/// `−A B` for `A` (`r × k`) and `B` (`k × c`), as rows.
pub(crate) fn neg_product<S: Scalar>(a: &[Vec<S>], b: &[Vec<S>]) -> Matrix<S> {
    let cols = b.first().map_or(0, Vec::len);
    a.iter()
        .map(|row| {
            (0..cols)
                .map(|c| {
                    let sum = row
                        .iter()
                        .zip(b)
                        .map(|(x, brow)| x.clone() * brow[c].clone())
                        .reduce(|s, t| s + t)
                        .unwrap_or_else(S::zero);
                    -sum
                })
                .collect()
        })
        .collect()
}
