//! The generated API, in one place: which functions a generated type has, their arguments,
//! results and documentation, in the field's convention `M(q) q̈ + c(q, q̇) = τ`.
//!
//! | function | returns |
//! |---|---|
//! | `mass_matrix(q)` | `M(q)`, symmetric (upper triangle computed, both written) |
//! | `nonlinear_effects(q, qd)` | `c(q, q̇)`: velocity products, plus gravity when generated with it (Pinocchio's `nonLinearEffects`) |
//! | `gravity(q)` | `g(q)`, the gravity part of `c` (only when generated with gravity) |
//! | `inverse_dynamics(q, qd, qdd)` | `τ = M q̈ + c`, one Newton–Euler pass |
//! | `forward_dynamics(q, qd, tau)` | `q̈ = M⁻¹ (τ − c)`, unrolled branch-free LDLᵀ |
//! | `mass_matrix_and_nonlinear_effects(q, qd)` | `(M, c)` sharing sines, cosines and kinematics |

use crate::emit::Shape;
use crate::options::Options;
use kanegen_trace::Function;

/// The functions generated for `opts`, in emission order (`gravity` only with gravity).
#[must_use]
pub fn functions(opts: &Options) -> Vec<Function> {
    [
        Function::MassMatrix,
        Function::NonlinearEffects,
        Function::Gravity,
        Function::InverseDynamics,
        Function::ForwardDynamics,
        Function::MassMatrixAndNonlinearEffects,
    ]
    .into_iter()
    .filter(|f| *f != Function::Gravity || opts.gravity.is_some())
    .collect()
}

/// How a function's outputs are returned, for `n` degrees of freedom.
#[must_use]
pub fn shape(f: Function, n: usize) -> Shape {
    match f {
        Function::MassMatrix => Shape::SymMatrix(n),
        Function::MassMatrixAndNonlinearEffects => Shape::SymMatrixAndVector(n),
        _ => Shape::Vector(n),
    }
}

/// The first line of a generated function's documentation.
#[must_use]
pub fn doc(f: Function) -> &'static str {
    match f {
        Function::MassMatrix => {
            "The joint-space inertia matrix `M(q)` (symmetric, both triangles written)."
        }
        Function::NonlinearEffects => {
            "The nonlinear effects `c(q, q̇)` of `M q̈ + c = τ`: velocity products, plus gravity \
             when the model has it (Pinocchio's `nonLinearEffects`)."
        }
        Function::Gravity => {
            "The generalized gravity `g(q)`: the gravity part of `c` (`c` at `q̇ = 0`)."
        }
        Function::InverseDynamics => "Inverse dynamics: the drives `τ = M q̈ + c` that produce `q̈`.",
        Function::ForwardDynamics => {
            "Forward dynamics `q̈ = M⁻¹ (τ − c)`, by an unrolled branch-free LDLᵀ."
        }
        Function::MassMatrixAndNonlinearEffects => {
            "`(M(q), c(q, q̇))` in one call, sharing sines, cosines and kinematics."
        }
        Function::GeneralizedForces => {
            "The paper's generalized forces `b = Q − h` of `A q̈ = b` (`b = τ − c`)."
        }
    }
}
