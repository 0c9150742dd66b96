//! What can be traced: the functions of a model's dynamics, their arguments, and the runtime
//! inputs a trace reads.
//!
//! Signs: the paper writes `A q̈ = b` with `b = Q − h` ([`Function::GeneralizedForces`]); the
//! field (Pinocchio, RBDL, MuJoCo) writes `M q̈ + c = τ`, with `M = A`, the nonlinear effects
//! `c = −b(τ = 0)` ([`Function::NonlinearEffects`]) and the gravity term `g = c(q̇ = 0)` of `c`
//! ([`Function::Gravity`]).

/// A function of the dynamics.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Function {
    /// `M(q) = A(q)`, symmetric; outputs the upper triangle, row-major.
    MassMatrix,
    /// The paper's `b(q, q̇, τ) = Q − h`: drives and applied loads minus velocity products.
    GeneralizedForces,
    /// `c(q, q̇)` of `M q̈ + c = τ`: velocity products, gravity and (minus) the applied loads.
    NonlinearEffects,
    /// `g(q)`: the gravity part of `c` (needs gravity).
    Gravity,
    /// `τ = M q̈ + c`: the drives that produce `q̈` (free-floating: the external wrench on the
    /// base, then the joint drives, that produce `ν̇`).
    InverseDynamics,
    /// `q̈ = M⁻¹ (τ − c)` (free-floating: `ν̇`).
    ForwardDynamics,
    /// `M` (upper triangle) then `c`, in one graph sharing the kinematics.
    MassMatrixAndNonlinearEffects,
    /// Forward dynamics with an external wrench on every body (`f_ext`: per body, force then
    /// moment, in the body frame at its origin; free-floating: the base first).
    ForwardDynamicsWithWrenches,
    /// Free-floating: the total momentum `[P; L]`, inertial frame, about the inertial origin.
    Momentum,
    /// Free-floating: the wrench the arm exerts on the base (force, moment about the base
    /// origin, base coordinates) for the motion `(q, v, a)`.
    BaseReaction,
    /// The placement of named frame `k`: its origin and orientation in the base frame (fixed
    /// base) or the inertial frame (free-floating).
    FramePlacement(usize),
    /// The geometric Jacobian of named frame `k`: rows `[v; ω]` of its origin, base-frame
    /// (fixed) or inertial (free-floating) axes, one column per speed.
    FrameJacobian(usize),
    /// Free-floating: the generalized Jacobian (Umetani–Yoshida) of named frame `k`, `6 × N`.
    GeneralizedJacobian(usize),
    /// `(∂τ/∂q, ∂τ/∂q̇)` of inverse dynamics, `NV × NV` each, row-major (Pinocchio's
    /// `computeRNEADerivatives`; free-floating: `∂/∂q` in the tangent space).
    InverseDynamicsDerivatives,
    /// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` of forward dynamics, `NV × NV` each, row-major (Pinocchio's
    /// `computeABADerivatives`).
    ForwardDynamicsDerivatives,
    /// `M(q)⁻¹`, symmetric; outputs the upper triangle, row-major.
    MassMatrixInverse,
}

impl Function {
    /// The functions without a frame, in emission order.
    pub const ALL: [Function; 13] = [
        Function::MassMatrix,
        Function::GeneralizedForces,
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
    ];

    /// The snake-case name (the generated function's name; a frame's functions are named
    /// `<frame>_placement`, `<frame>_jacobian`, `<frame>_generalized_jacobian`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Function::MassMatrix => "mass_matrix",
            Function::GeneralizedForces => "generalized_forces",
            Function::NonlinearEffects => "nonlinear_effects",
            Function::Gravity => "gravity",
            Function::InverseDynamics => "inverse_dynamics",
            Function::ForwardDynamics => "forward_dynamics",
            Function::MassMatrixAndNonlinearEffects => "mass_matrix_and_nonlinear_effects",
            Function::ForwardDynamicsWithWrenches => "forward_dynamics_with_wrenches",
            Function::Momentum => "momentum",
            Function::BaseReaction => "base_reaction",
            Function::FramePlacement(_) => "placement",
            Function::FrameJacobian(_) => "jacobian",
            Function::GeneralizedJacobian(_) => "generalized_jacobian",
            Function::InverseDynamicsDerivatives => "inverse_dynamics_derivatives",
            Function::ForwardDynamicsDerivatives => "forward_dynamics_derivatives",
            Function::MassMatrixInverse => "mass_matrix_inverse",
        }
    }

    /// The named frame it is about, if any.
    #[must_use]
    pub fn frame(self) -> Option<usize> {
        match self {
            Function::FramePlacement(k)
            | Function::FrameJacobian(k)
            | Function::GeneralizedJacobian(k) => Some(k),
            _ => None,
        }
    }

    /// Whether it exists only for a free-floating base.
    #[must_use]
    pub fn floating_only(self) -> bool {
        matches!(
            self,
            Function::Momentum | Function::BaseReaction | Function::GeneralizedJacobian(_)
        )
    }

    /// The arguments, in order, for a fixed or a free-floating base ([`Arg`]).
    #[must_use]
    pub fn args(self, floating: bool) -> &'static [Arg] {
        let (v, a) = if floating {
            (Arg::V, Arg::A)
        } else {
            (Arg::Qd, Arg::Qdd)
        };
        match (self, v, a) {
            (
                Function::MassMatrix
                | Function::MassMatrixInverse
                | Function::Gravity
                | Function::FramePlacement(_)
                | Function::FrameJacobian(_)
                | Function::GeneralizedJacobian(_),
                _,
                _,
            ) => &[Arg::Q],
            (
                Function::GeneralizedForces
                | Function::ForwardDynamics
                | Function::ForwardDynamicsDerivatives,
                Arg::V,
                _,
            ) => &[Arg::Q, Arg::V, Arg::Tau],
            (
                Function::GeneralizedForces
                | Function::ForwardDynamics
                | Function::ForwardDynamicsDerivatives,
                _,
                _,
            ) => &[Arg::Q, Arg::Qd, Arg::Tau],
            (
                Function::NonlinearEffects
                | Function::MassMatrixAndNonlinearEffects
                | Function::Momentum,
                Arg::V,
                _,
            ) => &[Arg::Q, Arg::V],
            (
                Function::NonlinearEffects
                | Function::MassMatrixAndNonlinearEffects
                | Function::Momentum,
                _,
                _,
            ) => &[Arg::Q, Arg::Qd],
            (
                Function::InverseDynamics
                | Function::BaseReaction
                | Function::InverseDynamicsDerivatives,
                Arg::V,
                _,
            ) => &[Arg::Q, Arg::V, Arg::A],
            (
                Function::InverseDynamics
                | Function::BaseReaction
                | Function::InverseDynamicsDerivatives,
                _,
                _,
            ) => &[Arg::Q, Arg::Qd, Arg::Qdd],
            (Function::ForwardDynamicsWithWrenches, Arg::V, _) => {
                &[Arg::Q, Arg::V, Arg::Tau, Arg::FExt]
            }
            (Function::ForwardDynamicsWithWrenches, _, _) => {
                &[Arg::Q, Arg::Qd, Arg::Tau, Arg::FExt]
            }
        }
    }

    /// Whether it is forward dynamics ([`Function::ForwardDynamics`],
    /// [`Function::ForwardDynamicsWithWrenches`]), and so has a forward method
    /// (`kanegen_dynamics::ForwardMethod`: LDLᵀ on `M` and `c`, or the articulated-body
    /// algorithm, which uses neither).
    #[must_use]
    pub fn is_forward_dynamics(self) -> bool {
        matches!(
            self,
            Function::ForwardDynamics | Function::ForwardDynamicsWithWrenches
        )
    }

    /// Whether it is one of the derivative functions ([`Function::InverseDynamicsDerivatives`],
    /// [`Function::ForwardDynamicsDerivatives`], [`Function::MassMatrixInverse`]), traced by the
    /// analytical algorithms of `kanegen_dynamics::algorithms::derivatives`.
    #[must_use]
    pub fn is_derivative(self) -> bool {
        matches!(
            self,
            Function::InverseDynamicsDerivatives
                | Function::ForwardDynamicsDerivatives
                | Function::MassMatrixInverse
        )
    }

    /// Whether it reads and writes joint-space quantities only (`q`, `q̇`, `q̈`, `τ`, `M`, `c`,
    /// `g`; on a free-floating base also the base's, in base coordinates), so it can be computed
    /// in any body frames. Not: named frames, body-frame wrenches, and the base reaction and the
    /// momentum, which code generation reads from the model as given.
    #[must_use]
    pub fn is_joint_space(self) -> bool {
        matches!(
            self,
            Function::MassMatrix
                | Function::NonlinearEffects
                | Function::Gravity
                | Function::InverseDynamics
                | Function::ForwardDynamics
                | Function::MassMatrixAndNonlinearEffects
                | Function::InverseDynamicsDerivatives
                | Function::ForwardDynamicsDerivatives
                | Function::MassMatrixInverse
        )
    }

    /// Whether its result involves the mass matrix (and so a mass-matrix method; with LDLᵀ for
    /// forward dynamics).
    #[must_use]
    pub fn uses_mass_matrix(self) -> bool {
        matches!(
            self,
            Function::MassMatrix
                | Function::ForwardDynamics
                | Function::ForwardDynamicsWithWrenches
                | Function::MassMatrixAndNonlinearEffects
                | Function::GeneralizedJacobian(_)
        )
    }

    /// Whether its result involves the bias forces (and so a nonlinear-effects method; with LDLᵀ for forward
    /// dynamics).
    #[must_use]
    pub fn uses_nonlinear_effects(self) -> bool {
        matches!(
            self,
            Function::GeneralizedForces
                | Function::NonlinearEffects
                | Function::Gravity
                | Function::InverseDynamics
                | Function::ForwardDynamics
                | Function::ForwardDynamicsWithWrenches
                | Function::MassMatrixAndNonlinearEffects
                | Function::BaseReaction
        )
    }
}

/// An argument array of a generated function. For a free-floating base the layout is
/// Pinocchio's free-flyer: `q = [p₀ (3), quaternion x, y, z, w (4), joints (N)]`,
/// `v = [v_b (3), ω_b (3), q̇ (N)]` (base coordinates), `a = v̇`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Arg {
    /// Positions: the joints' (`N`), or free-floating the base pose then the joints' (`7 + N`).
    Q,
    /// Joint velocities `q̇` (fixed base, `N`).
    Qd,
    /// Joint accelerations `q̈` (fixed base, `N`).
    Qdd,
    /// Joint drives `τ` (N·m or N, `N`).
    Tau,
    /// Free-floating velocities `v = [v_b, ω_b, q̇]` (`6 + N`).
    V,
    /// Free-floating accelerations `a = v̇` (`6 + N`).
    A,
    /// External wrenches, one row `[f (3), m (3)]` per body in its frame at its origin
    /// (free-floating: the base first; `N` or `1 + N` rows).
    FExt,
}

impl Arg {
    /// The argument's name in generated code.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Arg::Q => "q",
            Arg::Qd => "qd",
            Arg::Qdd => "qdd",
            Arg::Tau => "tau",
            Arg::V => "v",
            Arg::A => "a",
            Arg::FExt => "f_ext",
        }
    }

    /// Its number of entries for `n` joints (rows of 6 for [`Arg::FExt`]).
    #[must_use]
    pub fn len(self, n: usize, floating: bool) -> usize {
        let base = usize::from(floating);
        match self {
            Arg::Q => n + 7 * base,
            Arg::Qd | Arg::Qdd | Arg::Tau => n,
            Arg::V | Arg::A => n + 6 * base,
            Arg::FExt => n + base,
        }
    }
}

/// A field of a runtime payload (the last body's mass properties).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PayloadField {
    /// Mass.
    Mass,
    /// Centre of mass component.
    Com(usize),
    /// Inertia entry `(row, col)`, `row ≤ col` (the tensor is symmetric).
    Inertia(usize, usize),
}

/// One runtime input of a trace, in the order [`crate::Traced::inputs`] lists them.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Input {
    /// Entry `i` of an argument array.
    Joint(Arg, usize),
    /// Entry `(row, col)` of an argument of rows ([`Arg::FExt`]).
    Row(Arg, usize, usize),
    /// A payload field.
    Payload(PayloadField),
    /// Component `k` (force x, y, z, then moment x, y, z) of the runtime wrench `index` of the
    /// spec.
    Wrench {
        /// Index in [`crate::Spec::wrenches`].
        index: usize,
        /// 0..3 force, 3..6 moment.
        component: usize,
    },
    /// A model parameter made symbolic (generic traces for Table 1), by name.
    Parameter(String),
}

impl core::fmt::Display for Input {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        const XYZ: [&str; 3] = ["x", "y", "z"];
        match self {
            Input::Joint(a, i) => write!(f, "{}[{i}]", a.name()),
            Input::Row(a, r, c) => write!(f, "{}[{r}][{c}]", a.name()),
            Input::Payload(PayloadField::Mass) => f.write_str("payload.mass"),
            Input::Payload(PayloadField::Com(k)) => write!(f, "payload.com[{k}]"),
            Input::Payload(PayloadField::Inertia(r, c)) => write!(f, "payload.inertia[{r}][{c}]"),
            Input::Wrench { index, component } => {
                let p = if *component < 3 { "f" } else { "m" };
                write!(f, "{p}{index}_{}", XYZ[component % 3])
            }
            Input::Parameter(name) => f.write_str(name),
        }
    }
}
