//! The articulated-body algorithm against LDLᵀ on the CRBA mass matrix and the RNEA bias, and
//! against the RNEA run backwards (inverse dynamics of ABA's `q̈` gives back `τ`): random trees
//! and chains with prismatic joints, fixed and free-floating base, gravity, drives, and external
//! wrenches in the body and the base (inertial) frame. On regrouped parameters ABA gives the
//! same `q̈` as on the model's own; a perturbed inertia gives a different one (the comparison
//! can fail), and ABA reads the spatial inertia `JointParams::inertia`, as the CRBA and the RNEA
//! do, not the centre-of-mass form.

mod common;

use common::{base_inertial, base_state, loads, models};
use kanegen_dynamics::algorithms::{aba, floating, rnea};
use kanegen_dynamics::base::{FloatingBase, FloatingState};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::metrics::rel_err;
use kanegen_dynamics::regroup::regrouped;
use kanegen_dynamics::{ForwardMethod, Loads, Methods, Params};
use kanegen_model::random::{random_vec, rng};

const TOL: f64 = 1e-12;

#[test]
fn fixed_base_aba_equals_ldlt_and_inverts_the_rnea() {
    let mut worst = (0.0_f64, 0.0_f64);
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        for variant in 0..3 {
            let mut g = rng(1000 * k as u64 + variant as u64);
            let (q, qd) = (random_vec(&mut g, n, 2.5), random_vec(&mut g, n, 1.5));
            let l = loads(n, 7 * k as u64 + variant as u64, false, variant);
            let qdd = aba::forward_dynamics(&p, &q, &qd, &l);
            let want = Methods::SPATIAL.forward_dynamics(&p, &q, &qd, &l);
            let e = rel_err(&qdd, &want);
            assert!(e < TOL, "{} variant {variant}: ABA vs LDLᵀ {e:e}", m.name());
            worst.0 = worst.0.max(e);
            // The dispatch runs the same function.
            assert_eq!(Methods::ABA.forward_dynamics(&p, &q, &qd, &l), qdd);
            // τ = ID(q, q̇, q̈) with the same gravity and wrenches: the drives come back.
            let tau = l.tau.clone().unwrap_or_else(|| vec![0.0; n]);
            let back = rnea::inverse_dynamics(&p, &q, &qd, &qdd, &l);
            // Relative to the terms that cancel in τ = M q̈ + c.
            let c = rnea::inverse_dynamics(&p, &q, &qd, &vec![0.0; n], &l);
            let mq = rnea::inverse_dynamics(&p, &q, &vec![0.0; n], &qdd, &Loads::default());
            let scale = tau
                .iter()
                .chain(&c)
                .chain(&mq)
                .fold(1.0_f64, |a, x| a.max(x.abs()));
            let e = tau
                .iter()
                .zip(&back)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
                / scale;
            assert!(
                e < TOL,
                "{} variant {variant}: ID(ABA) vs τ {e:e}",
                m.name()
            );
            worst.1 = worst.1.max(e);
        }
    }
    println!(
        "fixed base: ABA vs LDLᵀ {:.1e}, ID(ABA) vs τ {:.1e}",
        worst.0, worst.1
    );
}

#[test]
fn floating_base_aba_equals_ldlt_and_inverts_the_rnea() {
    let mut worst = (0.0_f64, 0.0_f64);
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        let base = FloatingBase::<f64>::from_inertial(&base_inertial(300 + k as u64));
        for variant in 0..3 {
            let s = base_state(500 + 3 * k as u64 + variant as u64);
            let mut g = rng(2000 * k as u64 + variant as u64);
            let (q, qd) = (random_vec(&mut g, n, 2.5), random_vec(&mut g, n, 1.5));
            let l = loads(n, 11 * k as u64 + variant as u64, true, variant);
            let nu_dot = aba::floating(&p, &base, &s, &q, &qd, &l);
            assert_eq!(nu_dot.len(), 6 + n);
            let want = floating::forward_dynamics(Methods::SPATIAL, &p, &base, &s, &q, &qd, &l);
            let e = rel_err(&nu_dot, &want);
            assert!(e < TOL, "{} variant {variant}: ABA vs LDLᵀ {e:e}", m.name());
            worst.0 = worst.0.max(e);
            let via = floating::forward_dynamics(Methods::ABA, &p, &base, &s, &q, &qd, &l);
            assert_eq!(via, nu_dot);
            // Pinocchio's rnea on a free-flyer: zero wrench on the base, the drives on the joints.
            let base_acc: [f64; 6] = core::array::from_fn(|i| nu_dot[i]);
            let back = rnea::floating_inverse_dynamics(
                &p,
                &base,
                &s,
                &q,
                &qd,
                &base_acc,
                &nu_dot[6..],
                &l,
            );
            let mut want = vec![0.0; 6];
            want.extend(l.tau.clone().unwrap_or_else(|| vec![0.0; n]));
            // Relative to the terms that cancel: A ν̇ and the bias.
            let zero = vec![0.0; n];
            let c = rnea::floating_inverse_dynamics(&p, &base, &s, &q, &qd, &[0.0; 6], &zero, &l);
            let rest = FloatingState {
                v_b: Vec3::zero(),
                omega_b: Vec3::zero(),
                ..s.clone()
            };
            let a_nu = rnea::floating_inverse_dynamics(
                &p,
                &base,
                &rest,
                &q,
                &zero,
                &base_acc,
                &nu_dot[6..],
                &Loads::default(),
            );
            let scale = want
                .iter()
                .chain(&c)
                .chain(&a_nu)
                .fold(1.0_f64, |a, x| a.max(x.abs()));
            let e = want
                .iter()
                .zip(&back)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
                / scale;
            assert!(e < TOL, "{} variant {variant}: ID(ABA) {e:e}", m.name());
            worst.1 = worst.1.max(e);
        }
    }
    println!(
        "floating base: ABA vs LDLᵀ {:.1e}, ID(ABA) {:.1e}",
        worst.0, worst.1
    );
}

#[test]
fn regrouped_parameters_give_the_same_accelerations() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        let mut g = rng(70 + k as u64);
        let (q, qd) = (random_vec(&mut g, n, 2.5), random_vec(&mut g, n, 1.5));
        // Fixed base (what reaches the base is dropped).
        let r = regrouped::<f64>(m, None, &[]);
        assert!(r.report.moved > 0, "{}: regrouping moved nothing", m.name());
        let l = loads(n, 90 + k as u64, false, 0);
        let e = rel_err(
            &aba::forward_dynamics(&r.params, &q, &qd, &l),
            &aba::forward_dynamics(&p, &q, &qd, &l),
        );
        assert!(e < TOL, "{}: fixed, regrouped {e:e}", m.name());
        worst = worst.max(e);
        // Free-floating (the base receives), and with the last body kept (a runtime payload).
        let bi = base_inertial(600 + k as u64);
        let base = FloatingBase::<f64>::from_inertial(&bi);
        let s = base_state(800 + k as u64);
        let l = loads(n, 95 + k as u64, true, 0);
        let want = aba::floating(&p, &base, &s, &q, &qd, &l);
        for keep in [vec![], vec![n - 1]] {
            let r = regrouped::<f64>(m, Some(&bi), &keep);
            let rb = r.base.expect("a floating base");
            let e = rel_err(&aba::floating(&r.params, &rb, &s, &q, &qd, &l), &want);
            assert!(
                e < TOL,
                "{}: floating, regrouped, keep {keep:?} {e:e}",
                m.name()
            );
            worst = worst.max(e);
        }
    }
    println!("regrouped vs own parameters: worst {worst:.1e}");
}

/// Discriminating: one body's spatial inertia changed (and only `inertia`, not the
/// centre-of-mass form) changes ABA's `q̈` by far more than the tolerance, and LDLᵀ on the
/// CRBA and RNEA, which read the same `inertia`, follows it.
#[test]
fn a_perturbed_inertia_changes_the_accelerations() {
    for (k, m) in models().iter().enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        let mut g = rng(30 + k as u64);
        let (q, qd) = (random_vec(&mut g, n, 2.5), random_vec(&mut g, n, 1.5));
        let l = loads(n, 31 + k as u64, false, 0);
        let before = aba::forward_dynamics(&p, &q, &qd, &l);
        let body = k % n;
        let mut changed = p.clone();
        let i = &mut changed.joints[body].inertia;
        i.m *= 1.3;
        i.ibar.0[0][0] *= 1.2;
        i.h.0[1] += 0.05 * i.m;
        assert_eq!(changed.joints[body].mass, p.joints[body].mass);
        let after = aba::forward_dynamics(&changed, &q, &qd, &l);
        let moved = rel_err(&after, &before);
        assert!(
            moved > 1e-4,
            "{} body {body}: q̈ moved only {moved:e}",
            m.name()
        );
        let ldlt = Methods::SPATIAL.forward_dynamics(&changed, &q, &qd, &l);
        let e = rel_err(&after, &ldlt);
        assert!(
            e < TOL,
            "{} body {body}: perturbed ABA vs LDLᵀ {e:e}",
            m.name()
        );
    }
}

/// A coordinate axis (`JointParams::coordinate_axis`) is structure: ABA writes exact zeros for
/// `I^a S = 0` there. Clearing the flag computes those entries instead; both agree.
#[test]
fn coordinate_axis_zeros_agree_with_the_computed_projection() {
    let m = kanegen_model::io::load_model(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/reference/ssrms_nguyen_hughes_1994.urdf"),
    )
    .unwrap();
    let p = Params::<f64>::new(&m);
    assert!(p.joints.iter().all(|j| j.coordinate_axis.is_some()));
    let mut general = p.clone();
    for j in &mut general.joints {
        j.coordinate_axis = None;
    }
    let n = p.dof();
    for seed in 0..10 {
        let mut g = rng(seed);
        let (q, qd) = (random_vec(&mut g, n, 3.0), random_vec(&mut g, n, 1.0));
        let l = loads(n, seed, false, 0);
        let e = rel_err(
            &aba::forward_dynamics(&p, &q, &qd, &l),
            &aba::forward_dynamics(&general, &q, &qd, &l),
        );
        assert!(e < TOL, "seed {seed}: {e:e}");
    }
}

#[test]
fn forward_method_names() {
    assert_eq!(Methods::ABA.name(), "aba");
    assert_eq!(Methods::SPATIAL.name(), "spatial");
    let rec_aba = Methods {
        forward: ForwardMethod::Aba,
        ..Methods::RECURRENT
    };
    assert_eq!(rec_aba.name(), "recurrent+aba");
    assert!(Methods::ALL
        .iter()
        .all(|m| m.forward == ForwardMethod::Ldlt));
    for f in ForwardMethod::ALL {
        assert_eq!(ForwardMethod::from_name(f.name()), Some(f));
    }
}

/// `(A + diag(0…0, a)) x = b` by LDLᵀ: the armature on the last `a.len()` diagonal entries.
fn solve_with_armature(mut d: kanegen_dynamics::Dynamics<f64>, a: &[f64]) -> Vec<f64> {
    let off = d.mass_matrix.len() - a.len();
    for (i, ai) in a.iter().enumerate() {
        d.mass_matrix[off + i][off + i] += ai;
    }
    kanegen_dynamics::ldlt::solve(
        &kanegen_dynamics::ldlt::ldlt(&d.mass_matrix),
        &d.tau_minus_c,
    )
}

/// The workspace path ([`aba::forward_dynamics_in`], [`aba::floating_in`]) with an armature
/// (reflected rotor inertia `a_i`, here 0.05…2, the order of the bodies' own inertias) against
/// LDLᵀ on `A + diag(a)` and the RNEA's `b`, fixed and free-floating, on the random trees and
/// chains and on SSRMS (coordinate axes): measured worst 1.7e-14 (fixed) and 3.5e-14 (floating)
/// relative on the random models, bound 1e-12; SSRMS on a light random base 1.1e-12, bound 1e-11
/// (its `A` is far worse conditioned). Without the armature's exception to the coordinate axes'
/// zero rows of `I^a`, SSRMS is off by 7.7e-3. One workspace serves every state of a model, and a
/// call after another state gives bit for bit the allocating function's result (nothing carries
/// over); without armature, the same.
#[test]
fn workspace_with_armature_equals_ldlt_on_the_augmented_mass_matrix() {
    let mut worst = (0.0_f64, 0.0_f64);
    // SSRMS too: its coordinate axes' zero rows of `I^a` do not hold with an armature.
    let ssrms = kanegen_model::io::load_model(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/reference/ssrms_nguyen_hughes_1994.urdf"),
    )
    .unwrap();
    for (k, m) in models().iter().chain([&ssrms]).enumerate() {
        let p = Params::<f64>::new(m);
        let n = p.dof();
        let base = FloatingBase::<f64>::from_inertial(&base_inertial(700 + k as u64));
        let mut ws = aba::Workspace::new(&p);
        let mut g = rng(9000 + k as u64);
        let armature: Vec<f64> = random_vec(&mut g, n, 1.0)
            .iter()
            .map(|x| 0.05 + 1.95 * x.abs())
            .collect();
        for variant in 0..3 {
            let (q, qd) = (random_vec(&mut g, n, 2.5), random_vec(&mut g, n, 1.5));
            // Fixed base.
            let l = loads(n, 13 * k as u64 + variant as u64, false, variant);
            let mut qdd = vec![0.0; n];
            aba::forward_dynamics_in(&p, &mut ws, &q, &qd, &l, Some(&armature), &mut qdd);
            let want = solve_with_armature(Methods::SPATIAL.dynamics(&p, &q, &qd, &l), &armature);
            let e = rel_err(&qdd, &want);
            assert!(e < TOL, "{} variant {variant}: fixed {e:e}", m.name());
            worst.0 = worst.0.max(e);
            // Armature changes q̈ (the comparison can fail).
            let plain = aba::forward_dynamics(&p, &q, &qd, &l);
            assert!(rel_err(&plain, &want) > 1e-6, "{}", m.name());
            aba::forward_dynamics_in(&p, &mut ws, &q, &qd, &l, None, &mut qdd);
            assert_eq!(qdd, plain);
            // Free-floating base, the same workspace.
            let s = base_state(900 + 3 * k as u64 + variant as u64);
            let l = loads(n, 17 * k as u64 + variant as u64, true, variant);
            let mut nu = vec![0.0; 6 + n];
            aba::floating_in(
                &p,
                &mut ws,
                &base,
                &s,
                &q,
                &qd,
                &l,
                Some(&armature),
                &mut nu,
            );
            let d = floating::dynamics(Methods::SPATIAL, &p, &base, &s, &q, &qd, &l);
            let want = solve_with_armature(d, &armature);
            let e = rel_err(&nu, &want);
            // SSRMS on a light random base: A's condition number is ~100× the random trees'.
            let tol = if m.name().starts_with("ssrms") {
                1e-11
            } else {
                TOL
            };
            assert!(e < tol, "{} variant {variant}: floating {e:e}", m.name());
            worst.1 = worst.1.max(e);
            aba::floating_in(&p, &mut ws, &base, &s, &q, &qd, &l, None, &mut nu);
            assert_eq!(nu, aba::floating(&p, &base, &s, &q, &qd, &l));
        }
    }
    println!(
        "workspace with armature vs LDLᵀ: fixed {:.1e}, floating {:.1e}",
        worst.0, worst.1
    );
}
