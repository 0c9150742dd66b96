//! The dynamics algorithms, one per file, each generic over the scalar.
//!
//! Every algorithm computes the generalized inertia matrix `M(q)` and/or `τ − c(q, q̇)` of
//! `M q̈ + c = τ` (Pinocchio's convention): `τ` the joint drives plus the generalized forces of
//! the external loads, `c` the nonlinear effects (velocity products and gravity). The paper's own
//! files (`kinematics`, `recurrent`, `kane_direct`, `crba_inertial`) write it as the paper does,
//! `A q̈ = b` (eq. (8)), with `A = M` and `b = τ − c`.
//!
//! | file | what |
//! |---|---|
//! | [`kinematics`] | the paper's inertial-frame kinematics (1)–(7) and resultants (11) |
//! | [`recurrent`] | the paper's O(N²) recursion (12)–(21) |
//! | [`kane_direct`] | the direct Kane sums (9)–(11), O(N³) |
//! | [`crba_inertial`] | composite rigid bodies in inertial-frame notation |
//! | [`crba`] | Featherstone's local-frame CRBA (fixed and floating base) |
//! | [`rnea`] | Featherstone's local-frame RNEA: `τ − c` and O(N) inverse dynamics (fixed and floating base) |
//! | [`newton_euler`] | the classical local-frame Newton–Euler with 3-vectors (Luh–Walker–Paul, Khalil): the same, no linear velocities |
//! | [`aba`] | Featherstone's articulated-body algorithm: O(N) forward dynamics (fixed and floating base) |
//! | [`frames`] | placements and Jacobians of frames on bodies, the generalized Jacobian |
//! | [`momentum`] | total momentum and kinetic energy of a free-floating system |
//! | [`floating`] | a free-floating base: the dispatch, and the inertial-frame algorithms on six virtual joints |
//! | [`derivatives`] | `∂τ/∂q`, `∂τ/∂q̇`, `∂q̈/∂q`, `∂q̈/∂q̇`, `M⁻¹` (Carpentier & Mansard, RSS 2018) |
//! | [`methods`] | the choice of mass-matrix and nonlinear-effects method, and the fixed-base dispatch |
//!
//! **Trees.** `crba`, `rnea`, `newton_euler`, `aba`, `frames` and `momentum` take any kinematic tree
//! (`λ(i)` = [`crate::JointParams::parent`]); the paper's inertial-frame algorithms (`kinematics`,
//! `recurrent`, `kane_direct`, `crba_inertial`, and the virtual-joint extension of `floating`) are
//! serial-chain only and panic on a tree ([`crate::Params::assert_chain`];
//! [`methods::Methods::check`] asks first).
//!
//! Module dependencies run one way: `methods` and `floating` use the algorithm files, which use
//! `kinematics` and the crate's leaf modules; no algorithm file uses `methods` or `floating`
//! (`frames` uses `crba` for the generalized Jacobian, `aba` applies loads with `rnea`'s helper).

pub mod aba;
pub mod crba;
pub mod crba_inertial;
pub mod derivatives;
pub mod floating;
pub mod frames;
pub mod kane_direct;
pub mod kinematics;
pub mod methods;
pub mod momentum;
pub mod newton_euler;
pub mod recurrent;
pub mod rnea;
