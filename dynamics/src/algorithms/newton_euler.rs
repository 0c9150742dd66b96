//! The classical recursive Newton–Euler algorithm in local body coordinates (J. Y. S. Luh,
//! M. W. Walker and R. P. C. Paul, "On-line computational scheme for mechanical manipulators",
//! 1980; in the customized form of W. Khalil and J.-F. Kleinfinger, "Minimum operations and
//! minimum parameters of the dynamic models of tree structure robots", 1987, and Khalil & Dombre,
//! *Modeling, Identification and Control of Robots*, 2002, §9.5): inverse dynamics and `τ − c`
//! with 3-vectors instead of spatial vectors.
//!
//! The spatial RNEA ([`crate::algorithms::rnea`]) carries each body's twist `[ω; v]`; this one
//! carries `ω`, `ω̇` and the *classical* acceleration `a` of the body origin, which needs no linear
//! velocity at all (Khalil & Dombre eq. (9.89)–(9.95)):
//!
//! - forward, body `j` from its parent `λ` through `Xup_j = (E, r)` ([`crate::joint::xup`]):
//!   `ω_j = E ω_λ + u q̇_j`, `ω̇_j = E ω̇_λ + (E ω_λ) × u q̇_j + u q̈_j` (revolute);
//!   `a_j = E (a_λ + U_λ r) + 2 ω_j × u q̇_j + u q̈_j` (the last two for prismatic joints only),
//!   with `U = ω̇̃ + ω̃ ω̃` so that `U r = ω̇ × r + ω × (ω × r)` (one matrix per body, shared by
//!   every child's `r` and by the body's own first moment);
//! - the body's Newton–Euler wrench about its origin, from its spatial inertia `(m, h, Ī)`
//!   (`h = m c`): `F_j = m a_j + U_j h`, `N_j = Ī ω̇_j + ω_j × (Ī ω_j) + h × a_j`, minus the
//!   external wrenches on it;
//! - backward: `τ_j = uᵀ n_j` (revolute) or `uᵀ f_j` (prismatic) with `f_j = F_j + Σ_c Eᵀ f_c`,
//!   `n_j = N_j + Σ_c (Eᵀ n_c + r_c × Eᵀ f_c)` over the children `c` of `j`.
//!
//! Gravity is the fictitious base acceleration `a_0 = −g` (as in the spatial RNEA). The results
//! equal the spatial RNEA's; the traced operation counts differ, and code generation keeps the
//! cheaper ([`crate::NonlinearEffectsMethod::NewtonEuler`]). Any kinematic tree, fixed or free-floating base.
//!
//! ```
//! use kanegen_dynamics::algorithms::{newton_euler, rnea};
//! use kanegen_dynamics::{Loads, Params};
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let model = random_chain(&ChainSpec { n: 4, ..Default::default() }, 2);
//! let p = Params::<f64>::new(&model);
//! let (q, qd) = ([0.1, -0.4, 0.9, 0.3], [0.5, 0.2, -0.3, 1.0]);
//! let a = newton_euler::tau_minus_c(&p, &q, &qd, &Loads::default());
//! let b = rnea::tau_minus_c(&p, &q, &qd, &Loads::default());
//! assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-10));
//! ```

use crate::base::{FloatingBase, FloatingState, BASE_BODY, FLOATING_BASE_DOF};
use crate::joint::{rotate_down, rotate_up, xup_trig, XupTrig};
use crate::linalg::{Mat3, Vec3};
use crate::loads::{LoadFrame, Loads};
use crate::params::{JointParams, Params};
use crate::scalar::Scalar;
use crate::spatial::RbInertia;
use kanegen_model::JointKind;

/// The motion of one body in its own coordinates: angular velocity, angular acceleration and the
/// classical acceleration of its origin.
#[derive(Clone, Debug)]
struct BodyMotion<S> {
    w: Vec3<S>,
    wd: Vec3<S>,
    a: Vec3<S>,
}

/// A force and a moment about the body origin, body coordinates.
#[derive(Clone, Debug)]
struct Wrench<S> {
    f: Vec3<S>,
    n: Vec3<S>,
}

impl<S: Scalar> Wrench<S> {
    fn plus(self, o: Wrench<S>) -> Wrench<S> {
        Wrench {
            f: self.f + o.f,
            n: self.n + o.n,
        }
    }
}

/// `U r = ω̇ × r + ω × (ω × r)` with `U = ω̇̃ + ω̃ω̃` (Khalil & Dombre eq. (9.92)); entries built
/// on demand, so an `r` with zeros (or an unused entry) costs nothing.
struct UMatrix<S> {
    w: Vec3<S>,
    wd: Vec3<S>,
}

impl<S: Scalar> UMatrix<S> {
    /// `U_ik`: `ω_i ω_k − δ_ik |ω|² − ε_ikl ω̇_l`, the diagonal as `−(ω_k² + ω_l²)`.
    fn at(&self, i: usize, k: usize) -> S {
        let w = |m: usize| self.w.at(m);
        if i == k {
            let (a, b) = ((i + 1) % 3, (i + 2) % 3);
            -(w(a) * w(a) + w(b) * w(b))
        } else {
            // ω̃_ik = −ε_ikl ω_l: ω̃_01 = −ω_2, ω̃_10 = ω_2, …
            let l = 3 - i - k;
            let sign_positive = (k + 1) % 3 == i; // ω̃_ik = +ω_l when (i, k) is (1,0), (2,1), (0,2)
            let wd = self.wd.at(l);
            let ww = w(i) * w(k);
            if sign_positive {
                ww + wd
            } else {
                ww - wd
            }
        }
    }

    fn mul_vec(&self, r: &Vec3<S>) -> Vec3<S> {
        Vec3(core::array::from_fn(|i| {
            (0..3)
                .map(|k| self.at(i, k) * r.at(k))
                .reduce(|x, y| x + y)
                .expect("three terms")
        }))
    }
}

/// Body −1 (the fixed base, or the free-floating base body) in its own coordinates, and `E_0`,
/// the rotation from the frame of base-frame wrenches into them.
struct Start<S> {
    m: BodyMotion<S>,
    e0: Mat3<S>,
}

/// `F = m a + U h`, `N = Ī ω̇ + ω × (Ī ω) + h × a` for the spatial inertia `(m, h, Ī)`.
fn body_wrench<S: Scalar>(i: &RbInertia<S>, m: &BodyMotion<S>) -> Wrench<S> {
    let u = UMatrix {
        w: m.w.clone(),
        wd: m.wd.clone(),
    };
    Wrench {
        f: m.a.scale(&i.m) + u.mul_vec(&i.h),
        n: i.ibar.mul_vec(&m.wd) + m.w.cross(&i.ibar.mul_vec(&m.w)) + i.h.cross(&m.a),
    }
}

/// The wrench minus the external wrenches on `body` (`e0`: base frame to body coordinates).
fn subtract_external<S: Scalar>(
    mut w: Wrench<S>,
    loads: &Loads<S>,
    body: usize,
    e0: &Mat3<S>,
) -> Wrench<S> {
    for ext in loads.external.iter().filter(|e| e.body == body) {
        let (f, n) = match ext.frame {
            LoadFrame::Body => (ext.force.clone(), ext.moment.clone()),
            LoadFrame::Base => (e0.mul_vec(&ext.force), e0.mul_vec(&ext.moment)),
        };
        w = Wrench {
            f: w.f - f,
            n: w.n - n,
        };
    }
    w
}

/// `Eᵀ` applied to a child's wrench, moved to the parent origin: `(Eᵀ f, Eᵀ n + r × Eᵀ f)`
/// (rotations by [`rotate_down`]).
fn carry<S: Scalar>(jp: &JointParams<S>, x: &XupTrig<S>, w: &Wrench<S>) -> Wrench<S> {
    let f = rotate_down(jp, x, &w.f);
    Wrench {
        n: rotate_down(jp, x, &w.n) + x.0.r.cross(&f),
        f,
    }
}

/// Both passes: `(τ_j for every joint, Σ of the wrenches carried onto body −1)`. `qdd = None` is
/// `q̈ = 0` and adds no operation.
fn passes<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    qd: &[S],
    qdd: Option<&[S]>,
    loads: &Loads<S>,
    start: &Start<S>,
) -> (Vec<S>, Option<Wrench<S>>) {
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
    let mut xups: Vec<XupTrig<S>> = Vec::with_capacity(n);
    let mut motion: Vec<BodyMotion<S>> = Vec::with_capacity(n);
    let mut e0s: Vec<Mat3<S>> = Vec::with_capacity(if need_rot { n } else { 0 });
    let mut w: Vec<Wrench<S>> = Vec::with_capacity(n);
    for (j, jp) in p.joints.iter().enumerate() {
        let parent = jp.parent.map_or(&start.m, |l| &motion[l]);
        let x = xup_trig(jp, &q[j]);
        let u = &jp.axis;
        // ω in body coordinates before the joint's own rate: E ω_λ (E by `rotate_up`).
        let w_in = rotate_up(jp, &x, &parent.w);
        // a_λ + U_λ r: the classical acceleration of O_j, parent coordinates (9.95).
        let u_parent = UMatrix {
            w: parent.w.clone(),
            wd: parent.wd.clone(),
        };
        let a_origin = rotate_up(jp, &x, &(&parent.a + &u_parent.mul_vec(&x.0.r)));
        let m = match jp.kind {
            JointKind::Revolute => {
                let uqd = u.scale(&qd[j]);
                // ω̇_j = E ω̇_λ + (E ω_λ) × u q̇_j (+ u q̈_j)   (9.90)
                let mut wd = rotate_up(jp, &x, &parent.wd) + w_in.cross(&uqd);
                if let Some(qdd) = qdd {
                    wd = wd + u.scale(&qdd[j]);
                }
                BodyMotion {
                    w: w_in + uqd, // (9.89)
                    wd,
                    a: a_origin,
                }
            }
            JointKind::Prismatic => {
                // a_j = E (a_λ + U_λ r) + 2 ω_j × u q̇_j (+ u q̈_j)   (9.96)
                let uqd = u.scale(&qd[j]);
                let two = S::constant(2.0);
                let mut a = a_origin + w_in.cross(&uqd).scale(&two);
                if let Some(qdd) = qdd {
                    a = a + u.scale(&qdd[j]);
                }
                BodyMotion {
                    w: w_in,
                    wd: rotate_up(jp, &x, &parent.wd),
                    a,
                }
            }
        };
        if need_rot {
            let e0_parent = jp.parent.map_or(&start.e0, |l| &e0s[l]);
            e0s.push(x.0.e.mul_mat(e0_parent));
        }
        let e0 = if need_rot { &e0s[j] } else { &start.e0 };
        w.push(subtract_external(
            body_wrench(&jp.inertia, &m),
            loads,
            j,
            e0,
        ));
        motion.push(m);
        xups.push(x);
    }
    let mut tau = vec![S::zero(); n];
    let mut onto_base: Option<Wrench<S>> = None;
    for j in (0..n).rev() {
        let jp = &p.joints[j];
        tau[j] = match jp.kind {
            JointKind::Revolute => jp.axis.dot(&w[j].n),
            JointKind::Prismatic => jp.axis.dot(&w[j].f),
        };
        let carried = carry(jp, &xups[j], &w[j]);
        match jp.parent {
            Some(l) => w[l] = w[l].clone().plus(carried),
            None => {
                onto_base = Some(match onto_base {
                    Some(sum) => sum.plus(carried),
                    None => carried,
                });
            }
        }
    }
    (tau, onto_base)
}

/// A fixed base: at rest, accelerating by `−g`.
fn fixed_start<S: Scalar>(loads: &Loads<S>) -> Start<S> {
    Start {
        m: BodyMotion {
            w: Vec3::zero(),
            wd: Vec3::zero(),
            a: loads
                .gravity
                .as_ref()
                .map_or_else(Vec3::zero, |g| -g.clone()),
        },
        e0: Mat3::identity(),
    }
}

/// `b_j = τ_j − C_j` (or `−C_j` without drives).
fn with_drives<S: Scalar>(c: Vec<S>, loads: &Loads<S>) -> Vec<S> {
    match &loads.tau {
        Some(tau) => {
            assert_eq!(tau.len(), c.len(), "loads.tau has the wrong length");
            tau.iter().zip(c).map(|(t, c)| t.clone() - c).collect()
        }
        None => c.into_iter().map(|c| -c).collect(),
    }
}

/// `τ − c(q, q̇, f_ext)` with `q̈ = 0`, fixed base; arguments and
/// loads as [`crate::algorithms::rnea::tau_minus_c`]. Section `"newton-euler"`.
pub fn tau_minus_c<S: Scalar>(p: &Params<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
    S::section("newton-euler");
    let (c, _) = passes(p, q, qd, None, loads, &fixed_start(loads));
    with_drives(c, loads)
}

/// Inverse dynamics, fixed base: `τ = H q̈ + C(q, q̇, f_ext)` (`loads.tau` ignored), as
/// [`crate::algorithms::rnea::inverse_dynamics`]. Section `"newton-euler"`.
pub fn inverse_dynamics<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    qd: &[S],
    qdd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    S::section("newton-euler");
    passes(p, q, qd, Some(qdd), loads, &fixed_start(loads)).0
}

/// The free-floating base body as body −1: `ω_0 = ω_b`, `ω̇_0 = ω̇_b`, the classical acceleration
/// of its origin `a_0 = v̇_b + ω_b × v_b − R₀ᵀ g` (`ν̇_b = [v̇_b; ω̇_b]` the base-coordinate rates of
/// [`crate::base`], zero when not given), `E_0 = R₀ᵀ`.
fn floating_start<S: Scalar>(
    state: &FloatingState<S>,
    base_acc: Option<&[S; 6]>,
    loads: &Loads<S>,
) -> Start<S> {
    let r0t = state.rotation.transpose();
    let mut a = state.omega_b.cross(&state.v_b);
    let mut wd = Vec3::zero();
    if let Some(acc) = base_acc {
        a = a + Vec3::new(acc[0].clone(), acc[1].clone(), acc[2].clone());
        wd = Vec3::new(acc[3].clone(), acc[4].clone(), acc[5].clone());
    }
    if let Some(g) = &loads.gravity {
        a = a - r0t.mul_vec(g);
    }
    Start {
        m: BodyMotion {
            w: state.omega_b.clone(),
            wd,
            a,
        },
        e0: r0t,
    }
}

/// The base body's own wrench plus what its children carry onto it, minus the loads on it.
fn base_total<S: Scalar>(
    base: &FloatingBase<S>,
    loads: &Loads<S>,
    start: &Start<S>,
    onto_base: Option<Wrench<S>>,
) -> Wrench<S> {
    let own = subtract_external(
        body_wrench(&base.inertia, &start.m),
        loads,
        BASE_BODY,
        &start.e0,
    );
    match onto_base {
        Some(w) => own.plus(w),
        None => own,
    }
}

/// `τ − c` (`6 + N` entries) of the tree `p` on the free-floating base `base` in the state `state`,
/// as [`crate::algorithms::rnea::floating_tau_minus_c`]: `b_base = −[f_0; n_0]`, `b_arm = τ − C`.
/// Section `"newton-euler"`.
pub fn floating_tau_minus_c<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    S::section("newton-euler");
    let start = floating_start(state, None, loads);
    let (c, onto_base) = passes(p, q, qd, None, loads, &start);
    let w0 = base_total(base, loads, &start, onto_base);
    let mut b: Vec<S> = w0.f.0.into_iter().chain(w0.n.0).map(|x| -x).collect();
    debug_assert_eq!(b.len(), FLOATING_BASE_DOF);
    b.extend(with_drives(c, loads));
    b
}

/// Inverse dynamics on a free-floating base, as
/// [`crate::algorithms::rnea::floating_inverse_dynamics`]: `[w_b (6); τ (N)]`.
/// Section `"newton-euler"`.
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
    S::section("newton-euler");
    let start = floating_start(state, Some(base_acc), loads);
    let (tau, onto_base) = passes(p, q, qd, Some(qdd), loads, &start);
    let w0 = base_total(base, loads, &start, onto_base);
    w0.f.0.into_iter().chain(w0.n.0).chain(tau).collect()
}
