//! Effects decide the code: a scene without gravity has no gravity term (trace, emitted
//! code, `kanegen count SCENE`), every enabled effect costs operations, and the simulated motion of
//! a free-floating arm with zero momentum follows the generalized Jacobian for small steps.
//!
//! Run with `--nocapture` to see the measured numbers.

use kanegen::dynamics::algorithms::floating;
use kanegen::dynamics::algorithms::frames::generalized_jacobian;
use kanegen::dynamics::algorithms::kinematics::floating_inertial_frame;
use kanegen::dynamics::base::FLOATING_BASE_DOF;
use kanegen::dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen::dynamics::linalg::{Mat3, Vec3};
use kanegen::dynamics::{FrameParams, Params};
use kanegen::dynamics::{Loads, Methods};
use kanegen::model::Model;
use kanegen::sim::integrate::{dopri5, Dopri5Options};
use kanegen::sim::scene::{BaseSpec, Scene};
use kanegen::sim::simulate::SceneSystem;
use kanegen::trace::sym::{Convention, Sym, Tracer};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn ssrms() -> Model {
    kanegen::model::io::load_model(
        &root().join("tests/data/reference/ssrms_nguyen_hughes_1994.urdf"),
    )
    .unwrap()
}

/// Traces `b` of `alg` for `chain`; gravity (when on) is the symbolic input `g_x, g_y, g_z`.
fn trace_b(chain: &Model, alg: Methods, gravity: bool) -> kanegen::trace::sym::Trace {
    let t = Tracer::new();
    let p = Params::<Sym>::new(chain);
    let n = chain.dof();
    let q: Vec<Sym> = (0..n).map(|i| t.input(format!("q{i}"))).collect();
    let qd: Vec<Sym> = (0..n).map(|i| t.input(format!("qd{i}"))).collect();
    let tau: Vec<Sym> = (0..n).map(|i| t.input(format!("tau{i}"))).collect();
    let g = gravity.then(|| Vec3::new(t.input("g_x"), t.input("g_y"), t.input("g_z")));
    let loads = Loads {
        tau: Some(tau),
        gravity: g,
        external: Vec::new(),
    };
    let b = alg.nonlinear_effects.tau_minus_c(&p, &q, &qd, &loads);
    t.finish(&b)
}

#[test]
fn a_trace_without_gravity_has_no_gravity_term() {
    let chain = ssrms();
    let n = chain.dof();
    for alg in Methods::ALL {
        let off = trace_b(&chain, alg, false);
        let on = trace_b(&chain, alg, true);
        assert!(
            off.input_names().iter().all(|s| !s.starts_with("g_")),
            "{alg:?}: {:?}",
            off.input_names()
        );
        assert_eq!(off.input_names().len(), 3 * n);
        assert_eq!(on.input_names().len(), 3 * n + 3);
        // Gravity reaches b in the gravity-on trace: changing g changes b.
        let x: Vec<f64> = (0..3 * n).map(|i| 0.1 + 0.37 * i as f64).collect();
        let with = |g: [f64; 3]| on.eval(&[x.as_slice(), &g].concat());
        let (b0, b1) = (with([0.0; 3]), with([0.0, 0.0, -9.81]));
        assert!(
            b0.iter().zip(&b1).any(|(a, b)| (a - b).abs() > 1e-6),
            "{alg:?}"
        );
        // With g = 0 the gravity-on trace is the gravity-free one.
        let bf = off.eval(&x);
        for (a, b) in b0.iter().zip(&bf) {
            assert!(
                (a - b).abs() <= 1e-9 * (1.0 + b.abs()),
                "{alg:?}: {a} vs {b}"
            );
        }
        let (c_off, c_on) = (
            off.counts(Convention::Emitted),
            on.counts(Convention::Emitted),
        );
        println!(
            "{:<13} b emitted: no gravity {:>5} m {:>5} a; gravity input {:>5} m {:>5} a",
            alg.name(),
            c_off.mul,
            c_off.add,
            c_on.mul,
            c_on.add
        );
        assert!(c_off.mul + c_off.add < c_on.mul + c_on.add, "{alg:?}");
        assert!(c_off.mul < c_on.mul, "{alg:?}");
    }
}

#[test]
fn generated_code_has_gravity_only_when_asked() {
    let chain = ssrms();
    let mut opts = kanegen::codegen::Options::new("Ssrms");
    let space = kanegen::codegen::generate_file(&chain, &opts).unwrap();
    opts.gravity = Some([0.0, 0.0, -9.81]);
    let earth = kanegen::codegen::generate_file(&chain, &opts).unwrap();
    assert!(!space.contains("fn gravity"));
    assert!(earth.contains("fn gravity"));
    // The gravity function is only in the gravity file, and c differs (g enters c).
    // The straight-line body is `NAME_lanes`'s (`NAME` calls it).
    let body = |src: &str, f: &str| {
        let i = src.find(&format!("fn {f}_lanes<")).unwrap();
        src[i..i + src[i..].find("\n    }").unwrap()].to_string()
    };
    assert_ne!(
        body(&space, "nonlinear_effects"),
        body(&earth, "nonlinear_effects")
    );
    assert_eq!(body(&space, "mass_matrix"), body(&earth, "mass_matrix"));
}

fn count_scene(scene: &Path) -> Value {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .args(["count", "--json", "--algorithm", "recurrent"])
        .arg(scene)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn effect_names(r: &Value) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    for e in r["effects"].as_array().unwrap() {
        let s = e["effect"].as_str().unwrap().to_string();
        if !v.contains(&s) {
            v.push(s);
        }
    }
    v
}

#[test]
fn count_scene_reports_the_cost_of_each_enabled_effect() {
    let r = count_scene(&root().join("tests/data/scenes/gravity_wrench.toml"));
    assert_eq!(r["base"], "fixed");
    assert_eq!(r["n"], 7);
    assert_eq!(
        r["counts"].as_array().unwrap().len(),
        2 * 3,
        "A and b, three conventions"
    );
    assert_eq!(
        effect_names(&r),
        ["gravity", "wrench[0]", "wrench[1]", "damping"]
    );
    // The same wrench on the same body, constant (folded into the code: its zero components
    // vanish) and tabulated (six runtime inputs): the tabulated one cannot cost less.
    let emitted = |name: &str| {
        let e = r["effects"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["effect"] == name && e["convention"] == "emitted")
            .unwrap();
        (e["mul"].as_i64().unwrap(), e["add"].as_i64().unwrap())
    };
    let (constant, tabulated) = (emitted("wrench[0]"), emitted("wrench[1]"));
    println!("wrench on B8, emitted: constant {constant:?}, tabulated {tabulated:?}");
    assert!(
        tabulated.0 > constant.0 && tabulated.1 >= constant.1,
        "constant {constant:?} tabulated {tabulated:?}"
    );
    for e in r["effects"].as_array().unwrap() {
        let (m, a) = (e["mul"].as_i64().unwrap(), e["add"].as_i64().unwrap());
        println!("{} {}: {m} mul, {a} add", e["effect"], e["convention"]);
        assert!(m >= 0 && a >= 0 && m + a > 0, "{e}");
        if e["effect"] == "damping" && e["convention"] == "emitted" {
            // τ − c q̇ on every joint: a subtraction each, a multiplication where c ≠ 1
            // (c = 5, 5, 5, 5, 1, 1, 1: `1·q̇` folds away).
            assert_eq!((m, a), (4, 7), "{e}");
        }
    }
    // srms.toml names damping only; the free-floating example names no effect.
    let r = count_scene(&root().join("scenes/srms.toml"));
    assert_eq!(effect_names(&r), ["damping"]);
    let r = count_scene(&root().join("scenes/free_floating_7dof.toml"));
    assert_eq!(r["base"], "free-floating");
    assert!(r["effects"].as_array().unwrap().is_empty());
    let b = r["counts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["function"] == "tau_minus_c" && c["convention"] == "emitted")
        .unwrap();
    assert!(b["mul"].as_u64().unwrap() > 0);
}

/// Origin of the last arm body (inertial frame).
fn tip(chain: &Model, base: &FloatingBase<f64>, st: &FloatingState<f64>, q: &[f64]) -> [f64; 3] {
    let kin = floating_inertial_frame(&Params::new(chain), base, st, q);
    let mut x = st.position.clone();
    for k in &kin[FLOATING_BASE_DOF..] {
        x = &x + &k.r;
    }
    x.into_array()
}

#[test]
fn simulated_motion_follows_the_generalized_jacobian() {
    let text = r#"
model = "tests/data/reference/bmsd_7dof_free_floating.urdf"
allow_nonphysical = true
[base]
type = "free-floating"
position = [0.5, -0.2, 1.0]
quaternion = [0.1, -0.2, 0.3, 0.9]
[initial]
q = [0.2, 0.3, -0.1, -0.5, 0.4, 0.2, -0.3]
qd = [0.3, -0.2, 0.4, 0.25, -0.3, 0.2, 0.35]
[simulation]
duration = 1.0
integrator = "dopri5"
"#;
    let mut scene = Scene::parse(text, &root()).unwrap();
    let (q, qd) = (scene.q0.clone(), scene.qd0.clone());
    let n = q.len();
    let BaseSpec::FreeFloating {
        inertial,
        position,
        quaternion,
        ..
    } = scene.base.clone()
    else {
        panic!("free-floating")
    };
    let base = FloatingBase::<f64>::from_inertial(&inertial);
    let rot = quat_to_matrix(&quaternion);
    let st0 = FloatingState {
        position: Vec3::from_f64(position),
        rotation: rot.clone(),
        v_b: Vec3::zero(),
        omega_b: Vec3::zero(),
    };
    // Zero momentum: ν_b = −A_bb⁻¹ A_bm q̇.
    let p = Params::<f64>::new(&scene.model);
    let a = floating::dynamics(
        Methods::RECURRENT,
        &p,
        &base,
        &st0,
        &q,
        &qd,
        &Loads::default(),
    )
    .mass_matrix;
    let nb = FLOATING_BASE_DOF;
    let a_bb: Vec<Vec<f64>> = a[..nb].iter().map(|r| r[..nb].to_vec()).collect();
    let rhs: Vec<f64> = (0..nb)
        .map(|i| -(0..n).map(|j| a[i][nb + j] * qd[j]).sum::<f64>())
        .collect();
    let nu_b = kanegen::dynamics::ldlt::solve(&kanegen::dynamics::ldlt::ldlt(&a_bb), &rhs);
    let v_b = [nu_b[0], nu_b[1], nu_b[2]];
    if let BaseSpec::FreeFloating { v, omega, .. } = &mut scene.base {
        *v = v_b;
        *omega = [nu_b[3], nu_b[4], nu_b[5]];
    }
    // Predictions: tip velocity J* q̇, base origin velocity R₀ v_b (inertial frame).
    let tip_frame = FrameParams {
        parent: Some(n - 1),
        translation: Vec3::zero(),
        rotation: Mat3::identity(),
    };
    let js = generalized_jacobian(&p, &base, &st0, &q, &tip_frame);
    let tip_rate: Vec<f64> = (0..3)
        .map(|r| (0..n).map(|j| js[r][j] * qd[j]).sum())
        .collect();
    let base_rate = rot.mul_vec(&Vec3::from_f64(v_b)).into_array();
    let tip0 = tip(&scene.model, &base, &st0, &q);

    let mut sys = SceneSystem::new(&scene);
    let x0 = sys.initial_state();
    let (l, h0) = sys.momentum(&x0).unwrap();
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!(
        norm(&l) < 1e-9 && norm(&h0) < 1e-9,
        "zero momentum: {l:?} {h0:?}"
    );
    let mut errs = Vec::new();
    for h in [1e-3, 5e-4, 2.5e-4, 1.25e-4] {
        let mut x = x0.clone();
        let opts = Dopri5Options {
            tolerance: 1e-13,
            max_step: h,
            initial_step: h,
            output_interval: h,
        };
        dopri5(&mut sys, 0.0, h, &opts, &mut x, |_, _| {}).unwrap();
        let (qh, _, sth) = sys.split(&x);
        let sth = sth.unwrap();
        let tiph = tip(&scene.model, &base, &sth, qh);
        let rel = |moved: [f64; 3], pred: &[f64]| {
            let e: Vec<f64> = (0..3).map(|k| moved[k] / h - pred[k]).collect();
            norm(&e) / norm(pred)
        };
        let e_tip = rel([0, 1, 2].map(|k| tiph[k] - tip0[k]), &tip_rate);
        let pos = sth.position.into_array();
        let e_base = rel([0, 1, 2].map(|k| pos[k] - position[k]), &base_rate);
        println!("h = {h:.3e}: tip rel. error {e_tip:.3e}, base rel. error {e_base:.3e}");
        errs.push((e_tip, e_base));
    }
    for w in errs.windows(2) {
        for (a, b) in [(w[0].0, w[1].0), (w[0].1, w[1].1)] {
            let ratio = b / a;
            assert!(
                (0.4..0.6).contains(&ratio),
                "error must halve with h: {errs:?}"
            );
        }
    }
    let (e_tip, e_base) = *errs.last().unwrap();
    assert!(e_tip < 1e-3 && e_base < 1e-3, "{errs:?}");
    assert!(
        norm(&tip_rate) > 1e-3 && norm(&base_rate) > 1e-6,
        "{tip_rate:?} {base_rate:?}"
    );
}
