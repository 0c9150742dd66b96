//! An arm on a free-floating base (spacecraft): `6 + N` generalized speeds, `M` is
//! `(6+N)×(6+N)`, `τ − c` has `6+N` entries. The conventions are stated once, in [`crate::base`];
//! they are repeated here for the reader.
//!
//! # Conventions
//!
//! - **Base pose**: position `p₀` of the base-frame origin in the inertial frame, and the attitude
//!   as a unit quaternion stored `[x, y, z, w]` (Pinocchio order), i.e. the rotation `R₀` from base
//!   to inertial coordinates ([`quat_to_matrix`](crate::base::quat_to_matrix)). [`FloatingState`] holds `R₀` as a matrix.
//! - **Generalized velocity** `ν = [v_b (3), ω_b (3), q̇ (N)]` (Pinocchio free-flyer): `v_b` the
//!   linear velocity of the base-frame origin and `ω_b` the base's angular velocity, both in
//!   **base** coordinates.
//! - `M ν̇ + c = τ` (the paper's `A ν̇ = b`, `b = τ − c`), where `ν̇` is the time derivative of the components of `ν` (so
//!   `v̇_b` is the derivative of the base-coordinate components, not the base origin's
//!   acceleration). Rows `0..3` of `τ − c` hold the external + gravity force on the system and rows
//!   `3..6` its moment about the base origin, both in base coordinates, minus the velocity-product
//!   terms; rows `6..` are the arm's rows.
//! - **Position state** for integrators: `[p₀ (3), quat (4: x, y, z, w), q (N)]`, with
//!   `ṗ₀ = R₀ v_b`, `Ṙ₀ = R₀ ω̃_b`, `q̇` as given.
//! - **Loads** ([`Loads`]): `gravity` is in the **inertial** frame. An [`ExternalWrench`] with
//!   `body = j < N` acts on arm body `j` (force at `O_j`, moment about `O_j`) and with
//!   `body =` [`BASE_BODY`] on the base body (force at the base origin); its frame
//!   [`LoadFrame::Body`](crate::LoadFrame::Body) is that body's frame and [`LoadFrame::Base`](crate::LoadFrame::Base) means the **inertial**
//!   frame (which is the base frame of a fixed-base chain). `tau` has `N` entries (arm drives;
//!   the base is not actuated).
//!
//! # How (one algorithm source)
//!
//! The inertial-frame algorithms (`recurrent`, `recurrent-r1`, `crba-inertial`, `kane-direct`) run
//! unchanged on the extended body list of [`kinematics::floating_inertial_frame`]: the base as six
//! virtual joints (3 prismatic, then 3 revolute, axes `R₀e_m` through `p₀`) whose partial
//! velocities are exactly those of `ν_b`, everything in the inertial frame. The velocity-product
//! recursion starts from the base body's true motion ([`kinematics::floating_base_motion`]).
//! This extension is **serial-chain only**, like the inertial-frame algorithms (it panics on a tree).
//! `spatial` ([`Methods::SPATIAL`]) is an independent implementation that takes any kinematic
//! tree: Featherstone's floating-base CRBA and RNEA in body coordinates
//! ([`crba::floating_mass_matrix`], [`rnea::floating_tau_minus_c`]).
//!
//! Momentum and kinetic energy ([`momentum()`], [`kinetic_energy()`], re-exported from
//! [`crate::algorithms::momentum`]) take any tree; [`momentum_by_bodies`] and
//! [`kinetic_energy_by_bodies`] sum them body by body over the virtual-joint extension (chains
//! only), the cross-check. Frame placements and Jacobians, and the generalized Jacobian, are in
//! [`crate::algorithms::frames`].
//!
//! ```
//! use kanegen_dynamics::algorithms::floating;
//! use kanegen_dynamics::base::{FloatingBase, FloatingState};
//! use kanegen_dynamics::{Loads, Methods, Params};
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let chain = random_chain(&ChainSpec { n: 3, ..Default::default() }, 1);
//! let p = Params::<f64>::new(&chain);
//! let base = FloatingBase::<f64>::from_inertial(&kanegen_model::Inertial {
//!     mass: 100.0, com: [0.0; 3], inertia: [[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]],
//! });
//! let state = FloatingState::<f64>::at_rest();
//! let d = floating::dynamics(Methods::RECURRENT, &p, &base, &state, &[0.1, 0.2, 0.3], &[0.0; 3],
//!     &Loads::default());
//! assert_eq!(d.mass_matrix.len(), 9);
//! // The linear block is the total mass times the identity.
//! let total = 100.0 + chain.joints().iter().map(|j| j.inertial.mass).sum::<f64>();
//! assert!((d.mass_matrix[0][0] - total).abs() < 1e-9 && d.mass_matrix[0][1].abs() < 1e-9);
//! ```

use crate::algorithms::kinematics::{
    self, floating_inertial_frame, floating_motion, BodyKinematics, BodyMotion,
};
use crate::algorithms::methods::{
    Dynamics, ForwardMethod, MassMatrixMethod, Methods, NonlinearEffectsMethod,
};
use crate::algorithms::{aba, crba, kane_direct, newton_euler, recurrent, rnea};
use crate::base::{FloatingBase, FloatingState, BASE_BODY, FLOATING_BASE_DOF};
use crate::linalg::Vec3;
use crate::loads::{ExternalWrench, Loads};
use crate::params::Params;
use crate::scalar::Scalar;

pub use crate::algorithms::momentum::{kinetic_energy, momentum};

/// The loads of the extended body list: arm wrenches shifted by 6, base wrenches on virtual
/// body 5 (the one carrying the base's inertia), arm drives prefixed by 6 zeros.
fn extended_loads<S: Scalar>(loads: &Loads<S>, n: usize) -> Loads<S> {
    if let Some(t) = &loads.tau {
        assert_eq!(t.len(), n, "loads.tau has the wrong length");
    }
    Loads {
        tau: loads.tau.as_ref().map(|t| {
            let mut v = vec![S::zero(); FLOATING_BASE_DOF];
            v.extend(t.iter().cloned());
            v
        }),
        gravity: loads.gravity.clone(),
        external: loads
            .external
            .iter()
            .map(|e| {
                let body = if e.body == BASE_BODY {
                    FLOATING_BASE_DOF - 1
                } else {
                    assert!(e.body < n, "an external wrench names a body past the end");
                    e.body + FLOATING_BASE_DOF
                };
                ExternalWrench { body, ..e.clone() }
            })
            .collect(),
    }
}

/// `M` (`(6+N)×(6+N)`) of the arm `p` on the free-floating base `base` at arm positions `q`.
/// The inertial-frame methods run on the virtual-joint extension of [`floating_inertial_frame`] (serial
/// chains only); [`MassMatrixMethod::Crba`] runs [`crba::floating_mass_matrix`] (any tree). `M`
/// does not depend on the base pose; `state` is the pose the inertial-frame methods express their
/// quantities in.
///
/// # Panics
/// A serial-chain-only method on a tree ([`MassMatrixMethod::check`]).
pub fn mass_matrix<S: Scalar>(
    method: MassMatrixMethod,
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
) -> Vec<Vec<S>> {
    match method {
        MassMatrixMethod::Crba => crba::floating_mass_matrix(p, base, q),
        inertial_frame => {
            p.assert_chain(inertial_frame.name());
            inertial_frame
                .from_inertial_frame(&floating_inertial_frame(p, base, state, q))
                .expect("every method but the CRBA starts from inertial-frame quantities")
        }
    }
}

/// `τ − c` (`6+N` entries) of `M ν̇ + c = τ` for the arm `p` on the free-floating base `base` in the state
/// `state`, with arm rates `qd` and `loads` (conventions of [`crate::base`]).
/// [`NonlinearEffectsMethod::Rnea`] runs [`rnea::floating_tau_minus_c`] (any tree), the inertial-frame methods the
/// virtual-joint extension (serial chains only).
///
/// # Panics
/// A serial-chain-only method on a tree ([`NonlinearEffectsMethod::check`]).
pub fn tau_minus_c<S: Scalar>(
    method: NonlinearEffectsMethod,
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    let n = p.dof();
    assert_eq!(qd.len(), n, "qd has the wrong length");
    match method {
        NonlinearEffectsMethod::Rnea => {
            return rnea::floating_tau_minus_c(p, base, state, q, qd, loads)
        }
        NonlinearEffectsMethod::NewtonEuler => {
            return newton_euler::floating_tau_minus_c(p, base, state, q, qd, loads)
        }
        NonlinearEffectsMethod::Recurrent | NonlinearEffectsMethod::KaneDirect => {}
    }
    p.assert_chain(method.name());
    let kin = floating_inertial_frame(p, base, state, q);
    let mot = floating_motion(&kin, state, qd);
    let ext = extended_loads(loads, n);
    let f_ie = kinematics::inertial_external(&kin, &mot, &ext);
    let tau = ext.tau.as_deref();
    match method {
        NonlinearEffectsMethod::Recurrent => recurrent::tau_minus_c_inertial(&kin, &f_ie, tau),
        NonlinearEffectsMethod::KaneDirect => kane_direct::tau_minus_c_inertial(&kin, &f_ie, tau),
        NonlinearEffectsMethod::Rnea | NonlinearEffectsMethod::NewtonEuler => {
            unreachable!("handled above")
        }
    }
}

/// `M` and `τ − c` of the free-floating system ([`mass_matrix`], [`tau_minus_c`]); any tree with
/// [`Methods::SPATIAL`].
pub fn dynamics<S: Scalar>(
    methods: Methods,
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
) -> Dynamics<S> {
    Dynamics {
        mass_matrix: mass_matrix(methods.mass_matrix, p, base, state, q),
        tau_minus_c: tau_minus_c(methods.nonlinear_effects, p, base, state, q, qd, loads),
    }
}

/// Forward dynamics `ν̇ = M⁻¹ (τ − c)` (`[v̇_b; ω̇_b; q̈]`): by the branch-free LDLᵀ of
/// [`crate::ldlt`] on [`dynamics`] ([`ForwardMethod::Ldlt`]), or by the floating-base
/// articulated-body algorithm ([`ForwardMethod::Aba`], [`aba::floating`]; any tree).
pub fn forward_dynamics<S: Scalar>(
    methods: Methods,
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    match methods.forward {
        ForwardMethod::Ldlt => {
            let d = dynamics(methods, p, base, state, q, qd, loads);
            crate::ldlt::solve(&crate::ldlt::ldlt(&d.mass_matrix), &d.tau_minus_c)
        }
        ForwardMethod::Aba => aba::floating(p, base, state, q, qd, loads),
    }
}

/// Positions (inertial frame, from the inertial origin) of the frame origins of the extended
/// bodies of [`floating_inertial_frame`].
fn positions<S: Scalar>(kin: &[BodyKinematics<S>], state: &FloatingState<S>) -> Vec<Vec3<S>> {
    let mut x = state.position.clone();
    kin.iter()
        .enumerate()
        .map(|(j, k)| {
            if j >= FLOATING_BASE_DOF {
                x = &x + &k.r;
            }
            x.clone()
        })
        .collect()
}

/// The real bodies (base body, then the arm) of the extended list with their motion and origin.
fn bodies<'a, S: Scalar>(
    kin: &'a [BodyKinematics<S>],
    mot: &'a [BodyMotion<S>],
    x: &'a [Vec3<S>],
) -> impl Iterator<Item = ((&'a BodyKinematics<S>, &'a BodyMotion<S>), &'a Vec3<S>)> {
    kin.iter().zip(mot).zip(x).skip(FLOATING_BASE_DOF - 1)
}

/// [`momentum()`] summed directly over the bodies of the virtual-joint extension (base and arm;
/// independent of `A` and of the spatial algorithms; serial chains only), the cross-check:
/// `P = Σ (m_k v_k + ω_k × c_k)`, `L = Σ [x_k × (m_k v_k + ω_k × c_k) + c_k × v_k + I_k ω_k]`
/// with `x_k` the body origin, `v_k` its velocity, `c_k` the first moment and `I_k` the inertia
/// about `O_k`, all in the inertial frame.
///
/// # Panics
/// On a tree.
pub fn momentum_by_bodies<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
) -> (Vec3<S>, Vec3<S>) {
    let kin = floating_inertial_frame(p, base, state, q);
    let mot = floating_motion(&kin, state, qd);
    let x = positions(&kin, state);
    let mut lin = Vec3::zero();
    let mut ang = Vec3::zero();
    for ((k, m), xk) in bodies(&kin, &mot, &x) {
        let pk = m.v.scale(&k.m) + m.omega.cross(&k.c);
        ang = ang + xk.cross(&pk) + k.c.cross(&m.v) + k.inertia.mul_vec(&m.omega);
        lin = lin + pk;
    }
    (lin, ang)
}

/// [`kinetic_energy()`] summed directly over the bodies of the virtual-joint extension (serial
/// chains only), the cross-check: `T = Σ ½ (m_k |v_k|² + 2 v_k · (ω_k × c_k) + ω_k · I_k ω_k)`.
///
/// # Panics
/// On a tree.
pub fn kinetic_energy_by_bodies<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
) -> S {
    let kin = floating_inertial_frame(p, base, state, q);
    let mot = floating_motion(&kin, state, qd);
    let x = positions(&kin, state);
    let two = S::constant(2.0);
    let mut t = S::zero();
    for ((k, m), _) in bodies(&kin, &mot, &x) {
        t = t
            + k.m.clone() * m.v.dot(&m.v)
            + two.clone() * m.v.dot(&m.omega.cross(&k.c))
            + m.omega.dot(&k.inertia.mul_vec(&m.omega));
    }
    t * S::constant(0.5)
}
