//! The recursive Newton–Euler algorithm in local body coordinates (RBDA Table 5.1; spatial_v2
//! `ID`, and the `C` part of `HandC`): inverse dynamics in one O(N) pass, and `τ − c`
//! with `q̈ = 0`. Spatial algebra and conventions: [`crate::spatial`].
//!
//! Any kinematic tree (`λ(i)` = [`crate::JointParams::parent`]). Forward pass:
//! `v_i = Xup_i v_λ(i) + vJ_i`, `a_i = Xup_i a_λ(i) + S_i q̈_i + v_i ×ₘ vJ_i`,
//! `f_i = I_i a_i + v_i ×* I_i v_i − f^x_i`; backward pass: `τ_i = S_iᵀ f_i`,
//! `f_λ(i) += Xup_iᵀ f_i`. Gravity is the fictitious base acceleration `a_0 = −a_grav = [0; −g]`
//! (RBDA §5.3); external wrenches enter as `−f^x_i`, base-frame ones rotated by
//! `E_0i = E_i E_0λ(i)` along the body's own path. On a serial chain the operations are exactly
//! those of the chain algorithm.
//!
//! On a free-floating base (RBDA ch. 9, Pinocchio's free-flyer): [`floating_tau_minus_c`] (`ν̇ = 0`),
//! [`floating_inverse_dynamics`] and the arm's reaction on the base, [`base_reaction`].
//!
//! ```
//! use kanegen_dynamics::algorithms::{crba, rnea};
//! use kanegen_dynamics::{Loads, Params};
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let model = random_chain(&ChainSpec { n: 3, ..Default::default() }, 1);
//! let p = Params::<f64>::new(&model);
//! let (q, qd, qdd) = ([0.1, -0.4, 0.9], [0.5, 0.2, -0.3], [1.0, 0.0, -2.0]);
//! // τ = H q̈ + C: one O(N) pass against the mass matrix and the q̈ = 0 pass.
//! let tau = rnea::inverse_dynamics(&p, &q, &qd, &qdd, &Loads::default());
//! let h = crba::mass_matrix(&p, &q);
//! let b = rnea::tau_minus_c(&p, &q, &qd, &Loads::default());
//! for i in 0..3 {
//!     let hq: f64 = (0..3).map(|j| h[i][j] * qdd[j]).sum();
//!     assert!((tau[i] - (hq - b[i])).abs() < 1e-9);
//! }
//! ```

use crate::base::{FloatingBase, FloatingState, BASE_BODY, FLOATING_BASE_DOF};
use crate::joint::{s_times, s_tr, xup};
use crate::linalg::{Mat3, Vec3};
use crate::loads::{LoadFrame, Loads};
use crate::params::Params;
use crate::scalar::Scalar;
use crate::spatial::{base_rows, Force, Motion, Xform};

/// The starting motion of the forward pass: the velocity and acceleration of "body −1" in its own
/// coordinates, and `E_0`, the rotation from the frame of base-frame (`LoadFrame::Base`)
/// wrenches to body −1 coordinates (identity for a fixed base).
struct Start<S> {
    v: Motion<S>,
    a: Motion<S>,
    e0: Mat3<S>,
}

/// `−f^x`: the external wrenches on `body`, in the coordinates of that body (`e0`: rotation from
/// the wrenches' base frame to the body), subtracted one by one from `f` (shared with
/// [`crate::algorithms::aba`], which applies the loads exactly as the RNEA does).
pub(crate) fn subtract_external<S: Scalar>(
    mut f: Force<S>,
    loads: &Loads<S>,
    body: usize,
    e0: &Mat3<S>,
) -> Force<S> {
    for ext in loads.external.iter().filter(|e| e.body == body) {
        let fx = match ext.frame {
            LoadFrame::Body => Force {
                ang: ext.moment.clone(),
                lin: ext.force.clone(),
            },
            LoadFrame::Base => Force {
                ang: e0.mul_vec(&ext.moment),
                lin: e0.mul_vec(&ext.force),
            },
        };
        f = f - fx;
    }
    f
}

/// Both passes over the tree: `(τ_i = S_iᵀ f_i for every joint, Σ Xup_iᵀ f_i over the joints
/// on the base, carried onto body −1)`. `qdd = None` is `q̈ = 0` and adds no operation.
fn passes<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    qd: &[S],
    qdd: Option<&[S]>,
    loads: &Loads<S>,
    start: Start<S>,
) -> (Vec<S>, Option<Force<S>>) {
    let n = p.dof();
    assert_eq!(q.len(), n, "q has the wrong length");
    assert_eq!(qd.len(), n, "qd has the wrong length");
    if let Some(qdd) = qdd {
        assert_eq!(qdd.len(), n, "qdd has the wrong length");
    }
    assert!(
        loads
            .external
            .iter()
            .all(|e| e.body < n || e.body == BASE_BODY),
        "an external wrench names a body past the end of the chain"
    );
    let need_rot = loads.external.iter().any(|e| e.frame == LoadFrame::Base);
    let mut xups: Vec<Xform<S>> = Vec::with_capacity(n);
    let mut vs: Vec<Motion<S>> = Vec::with_capacity(n);
    let mut accs: Vec<Motion<S>> = Vec::with_capacity(n);
    // E_0j: rotation from the frame of base-frame wrenches to body j (kept only when needed).
    let mut e0s: Vec<Mat3<S>> = Vec::with_capacity(if need_rot { n } else { 0 });
    let mut f: Vec<Force<S>> = Vec::with_capacity(n);
    // Forward pass, each body from its parent λ(j) (or from body −1, the start).
    for (j, (jp, (qj, qdj))) in p.joints.iter().zip(q.iter().zip(qd)).enumerate() {
        let (v_parent, a_parent) = match jp.parent {
            Some(lambda) => (&vs[lambda], &accs[lambda]),
            None => (&start.v, &start.a),
        };
        let x = xup(jp, qj);
        let vj = s_times(jp, qdj);
        // v_j = Xup_j v_λ + vJ
        let v = x.apply(v_parent) + vj.clone();
        // a_j = Xup_j a_λ + S_j q̈_j + v_j ×ₘ vJ   (cJ = 0)
        let mut a = x.apply(a_parent);
        if let Some(qdd) = qdd {
            a = a + s_times(jp, &qdd[j]);
        }
        let a = a + v.crm(&vj);
        // f_j = I_j a_j + v_j ×* I_j v_j − f^x_j
        let inertia = jp.inertia.clone();
        let fj = inertia.mul(&a) + v.crf(&inertia.mul(&v));
        if need_rot {
            // E_0j = E_j E_0λ
            let e0_parent = match jp.parent {
                Some(lambda) => &e0s[lambda],
                None => &start.e0,
            };
            e0s.push(x.e.mul_mat(e0_parent));
        }
        let e0 = if need_rot { &e0s[j] } else { &start.e0 };
        f.push(subtract_external(fj, loads, j, e0));
        vs.push(v);
        accs.push(a);
        xups.push(x);
    }
    // Backward pass: τ_j = S_jᵀ f_j; f_λ += Xup_jᵀ f_j (onto body −1 for the joints on the base).
    let mut tau = vec![S::zero(); n];
    let mut onto_base: Option<Force<S>> = None;
    for j in (0..n).rev() {
        tau[j] = s_tr(&p.joints[j], &f[j]);
        let carried = xups[j].tr_apply(&f[j]);
        match p.joints[j].parent {
            Some(lambda) => {
                let parent = f[lambda].clone();
                f[lambda] = parent + carried;
            }
            None => {
                onto_base = Some(match onto_base {
                    Some(sum) => sum + carried,
                    None => carried,
                });
            }
        }
    }
    (tau, onto_base)
}

/// A fixed base: at rest, accelerating upwards by `−g` (gravity as a fictitious acceleration).
fn fixed_start<S: Scalar>(loads: &Loads<S>) -> Start<S> {
    Start {
        v: Motion::zero(),
        a: match &loads.gravity {
            Some(g) => Motion {
                ang: Vec3::zero(),
                lin: -g.clone(),
            },
            None => Motion::zero(),
        },
        e0: Mat3::identity(),
    }
}

/// Adds the drives: `b_j = τ_j − C_j` (or `−C_j` without drives).
fn with_drives<S: Scalar>(c: Vec<S>, loads: &Loads<S>) -> Vec<S> {
    match &loads.tau {
        Some(tau) => {
            assert_eq!(tau.len(), c.len(), "loads.tau has the wrong length");
            tau.iter().zip(c).map(|(t, c)| t.clone() - c).collect()
        }
        None => c.into_iter().map(|c| -c).collect(),
    }
}

/// `τ − c(q, q̇, f_ext)` (RBDA's `τ − C`) with `q̈ = 0`, fixed base.
///
/// `p`: the model's parameters; `q`, `q̇`: joint positions and velocities, length `N`; `loads`:
/// joint drives `Q = loads.tau` (added when present), gravity `g` in the base frame (entered as
/// the base acceleration `a_0 = [0; −g]`), and external wrenches (force at `O_j`, moment about
/// `O_j`; base-frame ones are rotated into body coordinates with the body's orientation), which
/// enter `C` as `−f^x_j`. Section `"spatial:rnea"`.
pub fn tau_minus_c<S: Scalar>(p: &Params<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
    S::section("spatial:rnea");
    let (c, _) = passes(p, q, qd, None, loads, fixed_start(loads));
    with_drives(c, loads)
}

/// Inverse dynamics, fixed base: the joint drives `τ = H(q) q̈ + C(q, q̇, f_ext)` (gravity and
/// external wrenches of `loads` included; `loads.tau` is ignored), in one O(N) pass.
/// Section `"spatial:rnea"`.
pub fn inverse_dynamics<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    qd: &[S],
    qdd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    S::section("spatial:rnea");
    passes(p, q, qd, Some(qdd), loads, fixed_start(loads)).0
}

/// The base as body −1 of the arm, in base coordinates: `v_0 = [ω_b; v_b]`,
/// `a_0 = [ω̇_b; v̇_b] + [0; −R₀ᵀ g]` (the base acceleration `ν̇_b` when given, gravity as a
/// fictitious acceleration when present), `E_0 = R₀ᵀ` (inertial-frame wrenches into base
/// coordinates).
fn floating_start<S: Scalar>(
    state: &FloatingState<S>,
    base_acc: Option<&[S; 6]>,
    loads: &Loads<S>,
) -> Start<S> {
    let r0t = state.rotation.transpose();
    let v = Motion {
        ang: state.omega_b.clone(),
        lin: state.v_b.clone(),
    };
    let gravity = loads.gravity.as_ref().map(|g| Motion {
        ang: Vec3::zero(),
        lin: -r0t.mul_vec(g),
    });
    let acc = base_acc.map(|a| Motion {
        ang: Vec3::new(a[3].clone(), a[4].clone(), a[5].clone()),
        lin: Vec3::new(a[0].clone(), a[1].clone(), a[2].clone()),
    });
    let a = match (acc, gravity) {
        (Some(acc), Some(g)) => acc + g,
        (Some(acc), None) => acc,
        (None, Some(g)) => g,
        (None, None) => Motion::zero(),
    };
    Start { v, a, e0: r0t }
}

/// `f_0 = I_0 a_0 + v_0 ×* I_0 v_0 − f^x_0`: the wrench the isolated base body needs for its
/// motion (gravity included in `a_0`), minus the external wrenches on it.
fn isolated_base<S: Scalar>(
    base: &FloatingBase<S>,
    loads: &Loads<S>,
    start: &Start<S>,
) -> Force<S> {
    let i_base = base.inertia.clone();
    let f0 = i_base.mul(&start.a) + start.v.crf(&i_base.mul(&start.v));
    subtract_external(f0, loads, BASE_BODY, &start.e0)
}

/// `τ − c` (`6 + N` entries) of the arm `p` (any kinematic tree) on the
/// free-floating base `base` in the state `state` (conventions of [`crate::base`]), RNEA with
/// `ν̇ = 0`: base `v_0 = [ω_b; v_b]`, `a_0 = [0; −R₀ᵀ g]`,
/// `f_0 = I_0 a_0 + v_0 ×* I_0 v_0 − f^x_0`, the arm as in [`tau_minus_c`],
/// `f_0 += Σ_{λ(i) = base} Xup_iᵀ f_i`; then `b_base = −[f_0.f; f_0.n]`,
/// `b_arm,j = τ_j − S_jᵀ f_j`. Inertial-frame wrenches are rotated into body coordinates with
/// `E_{0j} R₀ᵀ`. Section `"spatial:floating"`.
pub fn floating_tau_minus_c<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    S::section("spatial:floating");
    let start = floating_start(state, None, loads);
    let f0 = isolated_base(base, loads, &start);
    let (c, onto_base) = passes(p, q, qd, None, loads, start);
    let f0 = match onto_base {
        Some(f) => f0 + f,
        None => f0,
    };
    let mut b: Vec<S> = base_rows(&f0).into_iter().map(|x| -x).collect();
    debug_assert_eq!(b.len(), FLOATING_BASE_DOF);
    b.extend(with_drives(c, loads));
    b
}

/// Inverse dynamics of the tree `p` on the free-floating base `base` (Pinocchio's `rnea` on a
/// free-flyer model): the generalized forces `[w_b (6); τ (N)] = A(q) ν̇ − b(q, ν, τ = 0)` that
/// produce the accelerations `ν̇ = [base_acc; qdd]` in the state `(state, q, qd)` under the
/// gravity and external wrenches of `loads` (`loads.tau` is ignored).
///
/// - `base_acc = [v̇_b; ω̇_b]`: the time derivatives of the base-coordinate components of `v_b`
///   and `ω_b` ([`crate::base`]; so `v̇_b` is not the base origin's acceleration).
/// - `w_b = [f; n]`: the external wrench an actuator would have to apply to the base body, force
///   and moment about the base origin in base coordinates; `τ`: the joint drives.
///
/// One O(N) pass: [`floating_tau_minus_c`]'s recursion with `a_0 = [ω̇_b; v̇_b − R₀ᵀ g]` and `q̈`.
/// Section `"spatial:floating"`.
#[allow(clippy::too_many_arguments)] // the state of a free-floating system, as in Pinocchio
pub fn floating_inverse_dynamics<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    base_acc: &[S; 6],
    qdd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    S::section("spatial:floating");
    let start = floating_start(state, Some(base_acc), loads);
    let f0 = isolated_base(base, loads, &start);
    let (tau, onto_base) = passes(p, q, qd, Some(qdd), loads, start);
    let f0 = match onto_base {
        Some(f) => f0 + f,
        None => f0,
    };
    let mut out = base_rows(&f0).to_vec();
    out.extend(tau);
    out
}

/// The wrench the arm `p` exerts on the base body through the joints on the base, for the motion
/// `(state, q, qd, base_acc, qdd)` under the gravity and external wrenches of `loads` on the arm
/// (wrenches on [`BASE_BODY`] act on the base, not on the arm, and do not enter): `[f; n]`, force
/// and moment about the base origin in base coordinates. It does not depend on the base's mass
/// properties. Arguments as in [`floating_inverse_dynamics`].
///
/// **Sign.** It is the force *on the base* (Newton's third law: minus the wrench the base exerts
/// on the arm, `−Σ_{λ(i) = base} Xup_iᵀ f_i`). The base body's equation of motion is
/// `w_b + base_reaction + (loads on the base) = I_0 a_0 + v_0 ×* I_0 v_0`, so with `w_b` of
/// [`floating_inverse_dynamics`]:
/// `w_b = (I_0 a_0 + v_0 ×* I_0 v_0 − f^x_0) − base_reaction`, the wrench needed by the isolated
/// base minus the arm's reaction. Section `"spatial:floating"`.
pub fn base_reaction<S: Scalar>(
    p: &Params<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    base_acc: &[S; 6],
    qdd: &[S],
    loads: &Loads<S>,
) -> [S; 6] {
    S::section("spatial:floating");
    let start = floating_start(state, Some(base_acc), loads);
    let (_, onto_base) = passes(p, q, qd, Some(qdd), loads, start);
    match onto_base {
        Some(f) => base_rows(&f).map(|x| -x),
        None => core::array::from_fn(|_| S::zero()),
    }
}
