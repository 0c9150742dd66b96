//! Derivatives of forward dynamics, `∂q̈/∂q` and `∂q̈/∂q̇` of `q̈ = FD(q, q̇, τ)`, and `∂q̈/∂τ =
//! M⁻¹`: differentiating `M(q) q̈ + c(q, q̇) = τ` at fixed `τ` gives
//! `∂q̈/∂x = −M⁻¹ ∂RNEA/∂x |_(q, q̇, q̈ = FD(q, q̇, τ))` (J. Carpentier and N. Mansard,
//! "Analytical Derivatives of Rigid Body Dynamics Algorithms", RSS 2018, eq. (3); Pinocchio's
//! `computeABADerivatives` returns the same three matrices). `M⁻¹` by [`super::minverse`], then
//! `q̈ = M⁻¹ (τ − c)` with `τ − c` from one RNEA pass at `q̈ = 0` ([`crate::algorithms::rnea`]):
//! the inverse is needed anyway, so this costs `N²` products beyond the pass where the
//! articulated-body algorithm would cost a second O(N) pass about three times as long (traced:
//! 5,734 operations of the articulated-body algorithm against 2,031 at N = 8); then the RNEA
//! derivatives by [`super::rnea`] at that `q̈`.

use super::{minverse, neg_product, rnea, Matrix};
use crate::algorithms::rnea as id;
use crate::base::{FloatingBase, FloatingState, FLOATING_BASE_DOF};
use crate::linalg::Vec3;
use crate::loads::Loads;
use crate::params::Params;
use crate::scalar::Scalar;

/// The loads of forward dynamics here: the drives `τ` and gravity, no external wrench.
fn drives_and_gravity<S: Scalar>(tau: &[S], gravity: Option<&Vec3<S>>) -> Loads<S> {
    Loads {
        tau: Some(tau.to_vec()),
        gravity: gravity.cloned(),
        ..Loads::default()
    }
}

/// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` of fixed-base forward dynamics, `N × N` each.
///
/// `tau`: the joint drives (length `N`); `gravity`: `g` in the base frame. Section
/// `"derivatives:aba"`.
pub fn derivatives<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    qd: &[S],
    tau: &[S],
    gravity: Option<&Vec3<S>>,
) -> (Matrix<S>, Matrix<S>, Matrix<S>) {
    let loads = drives_and_gravity(tau, gravity);
    let minv = minverse::mass_matrix_inverse(p, q);
    // q̈ = M⁻¹ (τ − c)
    let qdd = product(&minv, &id::tau_minus_c(p, q, qd, &loads));
    let (dtau_dq, dtau_dv) = rnea::derivatives(p, q, qd, &qdd, gravity);
    S::section("derivatives:aba");
    // ∂q̈/∂x = −M⁻¹ ∂τ/∂x
    (
        neg_product(&minv, &dtau_dq),
        neg_product(&minv, &dtau_dv),
        minv,
    )
}

/// `(∂ν̇/∂q, ∂ν̇/∂ν, M⁻¹)` of free-floating forward dynamics
/// ([`crate::algorithms::aba::floating`]: `ν̇ = [v̇_b; ω̇_b; q̈]`), `(6 + N) × (6 + N)` each,
/// the base columns of `∂/∂q` in the tangent space (as [`rnea::floating_derivatives`]).
///
/// `tau`: the `N` joint drives (the base is not actuated); `gravity`: `g` in the inertial frame.
/// Section `"derivatives:aba"`.
pub fn floating_derivatives<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    tau: &[S],
    gravity: Option<&Vec3<S>>,
) -> (Matrix<S>, Matrix<S>, Matrix<S>) {
    let loads = drives_and_gravity(tau, gravity);
    let minv = minverse::floating_mass_matrix_inverse(p, base, q);
    // ν̇ = M⁻¹ (τ − c)
    let nu_dot = product(
        &minv,
        &id::floating_tau_minus_c(p, base, state, q, qd, &loads),
    );
    let (head, qdd) = nu_dot.split_at(FLOATING_BASE_DOF);
    let base_acc: [S; FLOATING_BASE_DOF] = core::array::from_fn(|k| head[k].clone());
    let (dtau_dq, dtau_dv) =
        rnea::floating_derivatives(p, base, state, q, qd, &base_acc, qdd, gravity);
    S::section("derivatives:aba");
    (
        neg_product(&minv, &dtau_dq),
        neg_product(&minv, &dtau_dv),
        minv,
    )
}

/// `M⁻¹ b`.
pub(crate) fn product<S: Scalar>(minv: &[Vec<S>], b: &[S]) -> Vec<S> {
    minv.iter()
        .map(|row| {
            row.iter()
                .zip(b)
                .fold(S::zero(), |acc, (m, x)| acc + m.clone() * x.clone())
        })
        .collect()
}
