//! The compact form's kernels: the local-frame dynamics algorithms written once as loops over a
//! model's numbers held in [`Tables`], for models where straight-line code loses.
//!
//! A compact generated type (`form = "compact"` of `kanegen-codegen`) holds one `const`
//! [`Tables`] and each of its functions is one call of a kernel here:
//!
//! - [`mass_matrix`]: the composite-rigid-body algorithm (RBDA Table 6.2), [`crba`];
//! - [`nonlinear_effects`], [`gravity`], [`inverse_dynamics`]: the recursive Newton–Euler
//!   algorithm (RBDA Table 5.1; gravity as the base's fictitious acceleration `a₀ = −a_g`,
//!   RBDA §5.3), [`rnea`];
//! - [`mass_matrix_and_nonlinear_effects`]: both on one set of joint transforms;
//! - [`forward_dynamics`], [`forward_dynamics_with_wrenches`]: the articulated-body algorithm
//!   (RBDA Table 7.1), [`aba`];
//! - [`with_payload`]: the inertia table with a runtime payload as the last body's, [`payload`];
//! - [`frame_placement`], [`frame_jacobian`]: a named frame's placement and Jacobian over its
//!   body's support path ([`Frame`]), [`frames`];
//! - [`derivatives`]: `∂τ/∂q`, `∂τ/∂q̇` (Carpentier–Mansard), `∂q̈/∂q`, `∂q̈/∂q̇` and `M⁻¹`;
//! - [`floating`]: `M`, `c`, inverse and forward dynamics, the momentum and the arm's reaction
//!   on its base on a free-floating base; [`floating_frames`]: its frames' placements,
//!   Jacobians and generalized Jacobians;
//! - [`coupled`]: all of the above for a model with mimic joints, in its independent
//!   coordinates (the state expanded to the full joint list, the results reduced, forward
//!   dynamics solved with the reduced `M`; [`crate::coupling`]);
//! - [`aba::aba_floating_on_world`]: forward dynamics on a free-floating base ([`FloatingRoot`]);
//!   the run-time path calls it and [`aba::aba_on_world`] on tables built at run time, with
//!   the armature and wrenches of a scene.
//!
//! Every kernel is generic over the scalar (`S: Scalar + Copy`: `f64`, `f32`, and the tracer
//! `Sym` of `kanegen-trace`, which runs them to count what a compact type executes) and written
//! once over slices of any length `N` with caller-provided scratch ([`crba::crba`],
//! [`rnea::rnea`], [`aba::aba`] on [`Bodies`] and their own per-joint scratch), so that one
//! instance per scalar serves every model. The entry points above are thin wrappers for
//! `N` known at compile time: their scratch lives in arrays on the stack ([`BodyStore`]), and
//! their results are arrays. Nothing allocates, no kernel panics (slices are read with `get` or
//! in loops over their own length; slices shorter than `N` leave entries unwritten), and the
//! only branches are on the tables' flags (joint kinds, parents), never on values. Sines and cosines are the caller's
//! (`sincos`, called once per revolute joint): the generated type's own `Self::sincos` or libm's.
//!
//! Trees are handled through the parent table (`λ(i) < i`).
//!
//! # The joint transform in three constant matrices
//!
//! `Xup_j = XJ(q_j) Xtree_j` has rotation `E_j = (Υ_j Θ(q_j))ᵀ` (RBDA §4.4, Table 4.1) with
//! Rodrigues' `Θ = u uᵀ + c (1 − u uᵀ) + s ũ` for the unit axis `u`, so
//! `E_j = A_j + c B_j + s C_j` with the constants `A = (Υ u uᵀ)ᵀ`, `B = (Υ (1 − u uᵀ))ᵀ`,
//! `C = (Υ ũ)ᵀ`; a prismatic joint has `A = Υᵀ`, `B = C = 0` and `r_j = l_j + q_j Υ u`. One
//! table serves both kinds without a branch on the kind in the transforms.

pub mod aba;
pub mod coupled;
pub mod crba;
pub mod derivatives;
pub mod floating;
pub mod floating_frames;
pub mod frames;
pub mod payload;
pub mod rnea;
pub mod spatial;
pub mod tables;

pub use aba::{
    forward_dynamics, forward_dynamics_with_wrenches, Articulated, ArticulatedStore, FloatingRoot,
    Rates,
};
pub use crba::{mass_matrix, mass_matrix_and_nonlinear_effects};
pub use frames::{frame_jacobian, frame_placement, Frame};
pub use payload::{payload_inertia, with_payload};
pub use rnea::{gravity, inverse_dynamics, nonlinear_effects, Motions};
pub use spatial::Transform;
pub use tables::{Bodies, BodyStore, Tables, TablesStore};
