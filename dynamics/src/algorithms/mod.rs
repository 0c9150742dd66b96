//! The dynamics algorithms, one per file, each generic over the scalar.
//!
//! Every algorithm computes the generalized inertia matrix `A(q)` and/or the generalized force
//! vector `b(q, q̇, loads) = Q − h` of `A q̈ = b` (paper eq. (8)): `Q` the joint drives plus the
//! generalized external loads and gravity, `h` the velocity-product terms. In the field's
//! convention `M q̈ + c = τ`: `M = A` and the nonlinear effects are `c = −b(τ = 0)`.
//!
//! | file | what |
//! |---|---|
//! | [`kinematics`] | the paper's base-frame kinematics (1)–(7) and resultants (11) |
//! | [`recurrent`] | the paper's O(N²) recursion (12)–(21) |
//! | [`kane_direct`] | the direct Kane sums (9)–(11), O(N³) |
//! | [`crba_base`] | composite rigid bodies in base-frame notation |
//! | [`crba`] | Featherstone's local-frame CRBA (fixed and floating base) |
//! | [`rnea`] | Featherstone's local-frame RNEA: bias forces and O(N) inverse dynamics (fixed and floating base) |
//! | [`newton_euler`] | the classical local-frame Newton–Euler with 3-vectors (Luh–Walker–Paul, Khalil): the same, no linear velocities |
//! | [`aba`] | Featherstone's articulated-body algorithm: O(N) forward dynamics (fixed and floating base) |
//! | [`frames`] | placements and Jacobians of frames on bodies, the generalized Jacobian |
//! | [`momentum`] | total momentum and kinetic energy of a free-floating system |
//! | [`floating`] | a free-floating base: the dispatch, and the base-frame algorithms on six virtual joints |
//! | [`methods`] | the choice of mass-matrix and bias method, and the fixed-base dispatch |
//!
//! **Trees.** `crba`, `rnea`, `newton_euler`, `aba`, `frames` and `momentum` take any kinematic tree
//! (`λ(i)` = [`crate::JointParams::parent`]); the paper's base-frame algorithms (`kinematics`,
//! `recurrent`, `kane_direct`, `crba_base`, and the virtual-joint extension of `floating`) are
//! serial-chain only and panic on a tree ([`crate::Params::assert_chain`];
//! [`methods::Methods::check`] asks first).
//!
//! Module dependencies run one way: `methods` and `floating` use the algorithm files, which use
//! `kinematics` and the crate's leaf modules; no algorithm file uses `methods` or `floating`
//! (`frames` uses `crba` for the generalized Jacobian, `aba` applies loads with `rnea`'s helper).

pub mod aba;
pub mod crba;
pub mod crba_base;
pub mod floating;
pub mod frames;
pub mod kane_direct;
pub mod kinematics;
pub mod methods;
pub mod momentum;
pub mod newton_euler;
pub mod recurrent;
pub mod rnea;
