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
    /// `τ = M q̈ + c`: the drives that produce `q̈`.
    InverseDynamics,
    /// `q̈ = M⁻¹ (τ − c)`.
    ForwardDynamics,
    /// `M` (upper triangle) then `c`, in one graph sharing the kinematics.
    MassMatrixAndNonlinearEffects,
}

impl Function {
    /// Every function, in emission order.
    pub const ALL: [Function; 7] = [
        Function::MassMatrix,
        Function::GeneralizedForces,
        Function::NonlinearEffects,
        Function::Gravity,
        Function::InverseDynamics,
        Function::ForwardDynamics,
        Function::MassMatrixAndNonlinearEffects,
    ];

    /// The snake-case name (the generated function's name).
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
        }
    }

    /// The joint-space arguments, in order.
    #[must_use]
    pub fn args(self) -> &'static [Arg] {
        match self {
            Function::MassMatrix | Function::Gravity => &[Arg::Q],
            Function::GeneralizedForces | Function::ForwardDynamics => &[Arg::Q, Arg::Qd, Arg::Tau],
            Function::NonlinearEffects | Function::MassMatrixAndNonlinearEffects => {
                &[Arg::Q, Arg::Qd]
            }
            Function::InverseDynamics => &[Arg::Q, Arg::Qd, Arg::Qdd],
        }
    }

    /// Whether its result involves the mass matrix (and so a mass-matrix method).
    #[must_use]
    pub fn uses_mass_matrix(self) -> bool {
        matches!(
            self,
            Function::MassMatrix
                | Function::ForwardDynamics
                | Function::MassMatrixAndNonlinearEffects
        )
    }

    /// Whether its result involves the bias forces (and so a bias method).
    #[must_use]
    pub fn uses_bias(self) -> bool {
        !matches!(self, Function::MassMatrix)
    }
}

/// A joint-space argument vector of a generated function (length `N`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Arg {
    /// Joint positions `q` (rad or m).
    Q,
    /// Joint velocities `q̇`.
    Qd,
    /// Joint accelerations `q̈`.
    Qdd,
    /// Joint drives `τ` (N·m or N).
    Tau,
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

/// A part of the free-floating base state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BaseField {
    /// `p₀` component (inertial frame).
    Position(usize),
    /// Attitude quaternion component, `[x, y, z, w]`.
    Quaternion(usize),
    /// `v_b` component (base frame).
    V(usize),
    /// `ω_b` component (base frame).
    Omega(usize),
}

/// One runtime input of a trace, in the order [`crate::Traced::inputs`] lists them.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Input {
    /// Entry `i` of a joint-space argument.
    Joint(Arg, usize),
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
    /// Part of the free-floating base state.
    Base(BaseField),
    /// A model parameter made symbolic (generic traces for Table 1), by name.
    Parameter(String),
}

impl core::fmt::Display for Input {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        const XYZ: [&str; 3] = ["x", "y", "z"];
        match self {
            Input::Joint(a, i) => write!(f, "{}[{i}]", a.name()),
            Input::Payload(PayloadField::Mass) => f.write_str("payload.mass"),
            Input::Payload(PayloadField::Com(k)) => write!(f, "payload.com[{k}]"),
            Input::Payload(PayloadField::Inertia(r, c)) => write!(f, "payload.inertia[{r}][{c}]"),
            Input::Wrench { index, component } => {
                let p = if *component < 3 { "f" } else { "m" };
                write!(f, "{p}{index}_{}", XYZ[component % 3])
            }
            Input::Base(BaseField::Position(k)) => write!(f, "p0_{}", XYZ[*k]),
            Input::Base(BaseField::Quaternion(k)) => write!(f, "quat_{}", ["x", "y", "z", "w"][*k]),
            Input::Base(BaseField::V(k)) => write!(f, "v_b_{}", XYZ[*k]),
            Input::Base(BaseField::Omega(k)) => write!(f, "omega_b_{}", XYZ[*k]),
            Input::Parameter(name) => f.write_str(name),
        }
    }
}
