//! The run-time fast path of the interpreted simulator (`SceneSystem` with
//! `ForwardMethod::Aba`: the compact form's articulated-body kernel on tables built at run time,
//! reflected rotor inertia as its armature, loads written in place) against the LDLᵀ path (`M`
//! and `τ − c` by the scene's algorithm, rotor inertia on `M`'s diagonal): the same right-hand
//! side on every scene of `scenes/` and `tests/data/scenes/` (fixed and free-floating bases, a
//! tree, rotor inertia, PD, constant and computed-torque drives, damping, Coulomb friction,
//! gravity, constant and tabulated wrenches), at the initial state and at perturbed states and
//! times. Measured worst relative difference 5.3e-12 (`scenes/ssrms_payload_fixed.toml`: its
//! computed-torque drive makes `τ` cancel most of `M q̈_d + c` with a heavy payload, and `q̈` is
//! what remains), 1.3e-12 on SRMS: the kernel works in base coordinates, where the space arms'
//! 15 m lever arms meet rounding (`dynamics/tests/kernels.rs` measures both paths against
//! double-double).

use kanegen_dynamics::metrics::rel_err;
use kanegen_dynamics::ForwardMethod;
use kanegen_sim::integrate::System;
use kanegen_sim::scene::Scene;
use kanegen_sim::simulate::SceneSystem;
use std::path::{Path, PathBuf};

fn scenes() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut v = Vec::new();
    for dir in ["scenes", "tests/data/scenes"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "toml") {
                v.push(p);
            }
        }
    }
    v.sort();
    assert!(v.len() >= 12, "found {} scenes", v.len());
    v
}

#[test]
fn fast_path_agrees_with_ldlt_on_every_scene() {
    let mut worst = 0.0_f64;
    let mut with_rotor = 0;
    for path in scenes() {
        let scene = Scene::load(&path).unwrap();
        // No scene names an algorithm, so each runs on the fast path by default.
        assert_eq!(
            scene.simulation.forward,
            ForwardMethod::Aba,
            "{}",
            path.display()
        );
        with_rotor += usize::from(scene.rotor.is_some());
        let mut fast = SceneSystem::new(&scene);
        let mut ldlt = SceneSystem::new(&scene).with_forward(ForwardMethod::Ldlt);
        let x0 = fast.initial_state();
        let dim = fast.dim();
        for k in 0..4 {
            let t = 0.37 * k as f64;
            // A perturbed state, its quaternion renormalized.
            let mut x: Vec<f64> = x0
                .iter()
                .enumerate()
                .map(|(i, v)| v + 0.1 * k as f64 * ((i * 7 + k) as f64).sin())
                .collect();
            fast.project(&mut x);
            let (mut a, mut b) = (vec![0.0; dim], vec![0.0; dim]);
            fast.deriv(t, &x, &mut a);
            ldlt.deriv(t, &x, &mut b);
            let e = rel_err(&a, &b);
            // Two exact algorithms in different coordinates: the kernel in base coordinates (as
            // Pinocchio's world-frame ABA), where the space arms' 15 m lever arms meet rounding,
            // LDLᵀ on the local-frame CRBA and RNEA. Measured worst: 5.3e-12 (SSRMS with its
            // captured payload), 1.3e-12 (SRMS); 1e-11 is twice that, a thousandth of a bug's.
            let bound = 1e-11;
            assert!(e < bound, "{} state {k}: {e:e}", path.display());
            worst = worst.max(e);
            // Calling again gives the same (the scratch carries nothing over).
            let mut c = vec![0.0; dim];
            fast.deriv(t, &x, &mut c);
            assert_eq!(a, c);
        }
    }
    assert!(with_rotor >= 2);
    println!("fast path vs LDLᵀ: worst {worst:.1e}");
}

/// The fast path does include the rotor: without it the accelerations differ.
#[test]
fn fast_path_reads_the_rotor() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let scene = Scene::load(&root.join("tests/data/scenes/rotor_wrench.toml")).unwrap();
    let mut no_rotor = scene.clone();
    no_rotor.rotor = None;
    let (mut with, mut without) = (SceneSystem::new(&scene), SceneSystem::new(&no_rotor));
    let x = with.initial_state();
    let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    with.deriv(0.0, &x, &mut a);
    without.deriv(0.0, &x, &mut b);
    assert!(rel_err(&a, &b) > 1e-3, "{:e}", rel_err(&a, &b));
}
