//! The generated API, in one place: which functions a generated type has, their arguments,
//! results and documentation, in the field's convention `M(q) q̈ + c(q, q̇) = τ`.
//!
//! Fixed base (`N` joints; `q`, `qd`, `qdd`, `tau` of `N` entries):
//!
//! | function | returns |
//! |---|---|
//! | `mass_matrix(q)` | `M(q)`, symmetric (upper triangle computed, both written) |
//! | `nonlinear_effects(q, qd)` | `c(q, q̇)`: velocity products, plus gravity when generated with it (Pinocchio's `nonLinearEffects`) |
//! | `gravity(q)` | `g(q)`, the gravity part of `c` (only when generated with gravity) |
//! | `inverse_dynamics(q, qd, qdd)` | `τ = M q̈ + c`, one Newton–Euler pass |
//! | `forward_dynamics(q, qd, tau)` | `q̈ = M⁻¹ (τ − c)`, unrolled: branch-free LDLᵀ on `M` and `c`, or the articulated-body algorithm, whichever is cheaper |
//! | `forward_dynamics_with_wrenches(q, qd, tau, f_ext)` | the same with a wrench on every body |
//! | `mass_matrix_and_nonlinear_effects(q, qd)` | `(M, c)` sharing sines, cosines and kinematics |
//! | `<frame>_placement(q)`, `<frame>_jacobian(q)` | each named frame's pose and geometric Jacobian |
//! | `inverse_dynamics_derivatives(q, qd, qdd)` | `(∂τ/∂q, ∂τ/∂q̇)`, Carpentier & Mansard's RNEA derivatives (unrolled form only) |
//! | `forward_dynamics_derivatives(q, qd, tau)` | `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` (unrolled form only) |
//! | `mass_matrix_inverse(q)` | `M(q)⁻¹`, symmetric (unrolled form only) |
//!
//! The derivatives are Pinocchio's layouts: row `i` = output `i`, column `j` = `∂/∂` input `j`.
//!
//! Free-floating base (Pinocchio's free-flyer layout: `q = [p₀, quaternion x y z w, joints]`
//! (`7 + N`), `v = [v_b, ω_b, q̇]` (`6 + N`, base coordinates), `a = v̇`): the same functions on
//! `(q, v)` with `6 + N` speeds, `inverse_dynamics` returning the base wrench then the drives,
//! and `momentum(q, v)`, `base_reaction(q, v, a)`, `<frame>_generalized_jacobian(q)`; the
//! derivatives' base columns of `∂/∂q` are in the tangent space (`6 + N`, Pinocchio's
//! `integrate(q, δv)`).

use crate::emit::Shape;
use crate::options::Options;
use kanegen_dynamics::ForwardMethod;
use kanegen_model::{BaseKind, Model};
use kanegen_trace::Function;

/// The functions generated for `model` under `opts`, in emission order: `gravity` only with
/// gravity; the free-floating ones only on a free-floating base; three (fixed: two) per named
/// frame. Functions a base cannot trace yet are left out.
#[must_use]
pub fn functions(model: &Model, opts: &Options) -> Vec<Function> {
    let floating = model.base_kind() == BaseKind::FreeFloating;
    let mut v: Vec<Function> = [
        Function::MassMatrix,
        Function::NonlinearEffects,
        Function::Gravity,
        Function::InverseDynamics,
        Function::ForwardDynamics,
        Function::MassMatrixAndNonlinearEffects,
        Function::ForwardDynamicsWithWrenches,
        Function::Momentum,
        Function::BaseReaction,
        Function::InverseDynamicsDerivatives,
        Function::ForwardDynamicsDerivatives,
        Function::MassMatrixInverse,
    ]
    .into_iter()
    .filter(|f| *f != Function::Gravity || opts.gravity.is_some())
    .filter(|f| floating || !f.floating_only())
    .collect();
    for k in 0..model.frames().len() {
        v.push(Function::FramePlacement(k));
        v.push(Function::FrameJacobian(k));
        if floating {
            v.push(Function::GeneralizedJacobian(k));
        }
    }
    v
}

/// A frame name as a Rust identifier: lowercase ASCII letters, digits and `_` (`Tool0` →
/// `tool0`, `ee-link` → `ee_link`, a leading digit gets `frame_`).
#[must_use]
pub fn frame_ident(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert_str(0, "frame_");
    }
    s
}

/// The generated function's name: [`Function::name`], prefixed by the frame for a frame's.
#[must_use]
pub fn fn_name(f: Function, model: &Model) -> String {
    match f.frame() {
        Some(k) => format!("{}_{}", frame_ident(&model.frames()[k].name), f.name()),
        None => f.name().to_string(),
    }
}

/// How a function's outputs are returned, for `n` joints on the given base.
#[must_use]
pub fn shape(f: Function, n: usize, floating: bool) -> Shape {
    let nv = n + if floating { 6 } else { 0 };
    match f {
        Function::MassMatrix | Function::MassMatrixInverse => Shape::SymMatrix(nv),
        Function::InverseDynamicsDerivatives => Shape::Matrices(2, nv),
        Function::ForwardDynamicsDerivatives => Shape::Matrices(3, nv),
        Function::MassMatrixAndNonlinearEffects => Shape::SymMatrixAndVector(nv),
        Function::Momentum | Function::BaseReaction => Shape::Vector(6),
        Function::FramePlacement(_) => Shape::Placement,
        Function::FrameJacobian(_) => Shape::Matrix(6, nv),
        Function::GeneralizedJacobian(_) => Shape::Matrix(6, n),
        _ => Shape::Vector(nv),
    }
}

/// How the derivatives' columns of `∂/∂q` read on a free-floating base.
fn tangent(floating: bool) -> &'static str {
    if floating {
        "; the base columns of `∂/∂q` are in the tangent space: `q` moved by Pinocchio's \
         `integrate(q, δv)`"
    } else {
        ""
    }
}

/// The first line of a generated function's documentation; `forward`: the forward method of
/// the emitted candidate (read for forward dynamics only).
#[must_use]
pub fn doc(f: Function, floating: bool, forward: ForwardMethod) -> String {
    let speeds = if floating {
        "`v̇ = [v̇_b, ω̇_b, q̈]`"
    } else {
        "`q̈`"
    };
    match f {
        Function::MassMatrix => {
            "The joint-space inertia matrix `M(q)` (symmetric, both triangles written).".into()
        }
        Function::NonlinearEffects => "The nonlinear effects `c(q, v)` of `M v̇ + c = τ`: velocity \
             products, plus gravity when the model has it (Pinocchio's `nonLinearEffects`)."
            .into(),
        Function::Gravity => {
            "The generalized gravity `g(q)`: the gravity part of `c` (`c` at zero velocity).".into()
        }
        Function::InverseDynamics if floating => "Inverse dynamics: the external wrench on the \
             base (force, moment about its origin, base coordinates) and the joint drives that \
             produce `a`, i.e. `M a + c`."
            .into(),
        Function::InverseDynamics => {
            "Inverse dynamics: the drives `τ = M q̈ + c` that produce `q̈`.".into()
        }
        Function::ForwardDynamics => match forward {
            ForwardMethod::Ldlt => format!(
                "Forward dynamics: {speeds} from the joint drives, `M⁻¹ (τ − c)`, by an unrolled \
                 branch-free LDLᵀ."
            ),
            ForwardMethod::Aba => format!(
                "Forward dynamics: {speeds} from the joint drives, `M⁻¹ (τ − c)`, by an unrolled \
                 articulated-body algorithm (no `M` is formed)."
            ),
        },
        Function::ForwardDynamicsWithWrenches => {
            format!(
            "Forward dynamics {speeds} with an external wrench on every body: `f_ext[i]` = force \
             (3) then moment (3), in the body's frame at its origin{}.",
            if floating { "; `f_ext[0]` is the base's" } else { "" }
        )
        }
        Function::MassMatrixAndNonlinearEffects => {
            "`(M(q), c(q, v))` in one call, sharing sines, cosines and kinematics.".into()
        }
        Function::Momentum => "The total momentum `[P (3), L (3)]` of base and arm: linear, and \
             angular about the inertial origin, in inertial coordinates."
            .into(),
        Function::BaseReaction => "The wrench the arm exerts on the base (force, moment about the \
             base origin, base coordinates) in the motion `(q, v, a)`."
            .into(),
        Function::FramePlacement(_) => format!(
            "The frame's placement: its origin and rotation matrix (frame to {} axes).",
            if floating { "inertial" } else { "base" }
        ),
        Function::FrameJacobian(_) => format!(
            "The frame's geometric Jacobian: rows `[v (3); ω (3)]` of its origin in {} axes, one \
             column per speed (Pinocchio's LOCAL_WORLD_ALIGNED).",
            if floating { "inertial" } else { "base" }
        ),
        Function::GeneralizedJacobian(_) => "The frame's generalized Jacobian (Umetani–Yoshida): \
             rows `[v; ω]` in inertial axes from `q̇` when the total momentum is zero."
            .into(),
        Function::GeneralizedForces => {
            "The paper's generalized forces `b = Q − h` of `A q̈ = b` (`b = τ − c`).".into()
        }
        Function::InverseDynamicsDerivatives => format!(
            "`(∂τ/∂q, ∂τ/∂{v})` of inverse dynamics (Carpentier & Mansard, RSS 2018; Pinocchio's \
             `computeRNEADerivatives`): row `i` = `τ_i`, column `j` = `∂/∂` speed `j`{tangent}.",
            v = if floating { "v" } else { "q̇" },
            tangent = tangent(floating),
        ),
        Function::ForwardDynamicsDerivatives => format!(
            "`(∂{speeds}/∂q, ∂{speeds}/∂{v}, M⁻¹)` of forward dynamics at the drives `tau` \
             (`−M⁻¹ ∂τ/∂x` at `{speeds} = FD(q, {v}, τ)`; Pinocchio's `computeABADerivatives`): \
             row `i` = output `i`, column `j` = `∂/∂` speed `j`{tangent}.",
            speeds = if floating { "v̇" } else { "q̈" },
            v = if floating { "v" } else { "q̇" },
            tangent = tangent(floating),
        ),
        Function::MassMatrixInverse => {
            "The inverse of the joint-space inertia matrix, `M(q)⁻¹` (symmetric, both triangles \
             written), from the LDLᵀ factors of `M`."
                .into()
        }
    }
}
