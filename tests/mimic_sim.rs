//! The simulator on a model with mimic joints: Panda, whose second finger follows the first
//! (`panda_finger_joint2`, URDF `<mimic>`), simulated in its 8 coordinates.
//!
//! - The interpreted run of `tests/data/scenes/panda_mimic_pd.toml` (PD drives, damping,
//!   gravity, a body-frame wrench on the link the mimic joint moves, RK4) equals, at every
//!   sample, an RK4 integration written here of the coupling imposed by hand on the *generated*
//!   full model (`ignore_mimic = true`, every joint independent): `M = Gᵀ M_full G`,
//!   `b = Gᵀ M_full a_w` with `a_w` the full model's forward dynamics under the wrench and the
//!   drives on the independent joints (`τ_full + Jᵀ f − c_full = M_full a_w`); and again on
//!   the same URDF with the coupling `q_f2 = −0.5 q_f1 + 0.01`.
//! - The compiled `scene!` of that scene equals the interpreted run.
//! - A passive run (gravity, a payload on the mimic finger, dopri5) conserves energy to the
//!   integrator's tolerance, and the monitor's kinetic energy is the generated full model's
//!   `½ q̇_fullᵀ M_full q̇_full`.
//! - The step Jacobians of a mimic scene match central differences of the step.
//! - `kanegen simulate` runs a mimic scene (CSV columns of the coordinates), and a scene that
//!   gives a value to the mimic joint is refused naming the file, the key and the joint it
//!   follows.

mod common;

use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::simulate;
use kanegen::sim::system::SceneSystem;

kanegen::dynamics!(
    PandaFull,
    "tests/data/erd_all/panda.urdf",
    ignore_mimic = true,
    gravity = [0.0, 0.0, -9.81],
    derivatives = false
);
kanegen::scene!(PandaPd, "tests/data/scenes/panda_mimic_pd.toml");

const PD_SCENE: &str = "tests/data/scenes/panda_mimic_pd.toml";

/// The coupling of the last joint (the second finger) to coordinate 7: `q_8 = k q_7 + o`.
#[derive(Clone, Copy)]
struct Coupled {
    k: f64,
    o: f64,
}

impl Coupled {
    fn positions(self, q: &[f64]) -> [f64; 9] {
        core::array::from_fn(|j| if j < 8 { q[j] } else { self.k * q[7] + self.o })
    }

    fn rates(self, qd: &[f64]) -> [f64; 9] {
        core::array::from_fn(|j| if j < 8 { qd[j] } else { self.k * qd[7] })
    }

    /// `G[a][i]` of the 9 × 8 coupling matrix.
    fn g(self, a: usize, i: usize) -> f64 {
        match (a, i) {
            (8, 7) => self.k,
            (a, i) if a == i => 1.0,
            _ => 0.0,
        }
    }
}

/// `x = A⁻¹ b` by Gaussian elimination with partial pivoting.
#[allow(clippy::needless_range_loop)] // elimination reads best with indices
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            for k in c..n {
                a[r][k] -= f * a[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    x
}

/// The drives, damping and the wrench of `panda_mimic_pd.toml`, read from the scene.
struct Effects {
    kp: Vec<f64>,
    kd: Vec<f64>,
    target: Vec<f64>,
    damping: Vec<f64>,
    wrench: [f64; 6],
}

fn effects(scene: &Scene) -> Effects {
    let kanegen::sim::scene::Drives::Pd { kp, kd, target } = &scene.drives else {
        panic!("a PD scene");
    };
    let (f, m) = scene.wrenches[0].value_at(0.0);
    assert_eq!(
        scene.wrenches[0].body, 8,
        "the wrench is on the mimic finger"
    );
    Effects {
        kp: kp.clone(),
        kd: kd.clone(),
        target: target.clone(),
        damping: scene.damping.clone().unwrap(),
        wrench: [f[0], f[1], f[2], m[0], m[1], m[2]],
    }
}

/// `[q̇, q̈]` of the coupled Panda in its 8 coordinates, by the generated full model reduced by
/// hand.
#[allow(clippy::needless_range_loop)] // Gᵀ M G reads best with indices
fn oracle_rhs(c: Coupled, e: &Effects, x: &[f64]) -> Vec<f64> {
    let (q, qd) = x.split_at(8);
    let tau: Vec<f64> = (0..8)
        .map(|i| e.kp[i] * (e.target[i] - q[i]) - e.kd[i] * qd[i] - e.damping[i] * qd[i])
        .collect();
    let (qf, vf) = (c.positions(q), c.rates(qd));
    let tau_full: [f64; 9] = core::array::from_fn(|j| if j < 8 { tau[j] } else { 0.0 });
    let mut f_ext = [[0.0; 6]; 9];
    f_ext[8] = e.wrench;
    let a_w = PandaFull::forward_dynamics_with_wrenches(&qf, &vf, &tau_full, &f_ext);
    let m_full = PandaFull::mass_matrix(&qf);
    let b_full: Vec<f64> = (0..9)
        .map(|a| (0..9).map(|b| m_full[a][b] * a_w[b]).sum())
        .collect();
    let m: Vec<Vec<f64>> = (0..8)
        .map(|i| {
            (0..8)
                .map(|j| {
                    let mut s = 0.0;
                    for a in 0..9 {
                        for b in 0..9 {
                            s += c.g(a, i) * m_full[a][b] * c.g(b, j);
                        }
                    }
                    s
                })
                .collect()
        })
        .collect();
    let b: Vec<f64> = (0..8)
        .map(|i| (0..9).map(|a| c.g(a, i) * b_full[a]).sum())
        .collect();
    [qd.to_vec(), solve(m, b)].concat()
}

/// Classical RK4 of [`oracle_rhs`] over the scene's duration, a sample every `output_every`
/// steps (`t = 0` first).
fn oracle_run(c: Coupled, scene: &Scene) -> Vec<(f64, Vec<f64>)> {
    let e = effects(scene);
    let sim = &scene.simulation;
    let h = sim.step;
    let steps = (sim.duration / h).round() as usize;
    let mut x = [scene.q0.clone(), scene.qd0.clone()].concat();
    let mut out = vec![(0.0, x.clone())];
    let axpy = |x: &[f64], a: f64, k: &[f64]| -> Vec<f64> {
        x.iter().zip(k).map(|(x, k)| x + a * k).collect()
    };
    for s in 1..=steps {
        let k1 = oracle_rhs(c, &e, &x);
        let k2 = oracle_rhs(c, &e, &axpy(&x, h / 2.0, &k1));
        let k3 = oracle_rhs(c, &e, &axpy(&x, h / 2.0, &k2));
        let k4 = oracle_rhs(c, &e, &axpy(&x, h, &k3));
        x = (0..x.len())
            .map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
            .collect();
        if s % sim.output_every == 0 {
            out.push((s as f64 * h, x.clone()));
        }
    }
    out
}

/// Worst `|x_s − x_o| / (1 + |x_o|)` of the simulator's run of `scene` against the oracle's.
fn against_oracle(c: Coupled, scene: &Scene) -> f64 {
    let run = simulate(scene, None).unwrap();
    let oracle = oracle_run(c, scene);
    assert_eq!(run.samples.len(), oracle.len(), "samples");
    let mut worst = 0.0_f64;
    for (s, (t, x)) in run.samples.iter().zip(&oracle) {
        assert!((s.t - t).abs() < 1e-9, "t {} vs {t}", s.t);
        assert_eq!(
            s.x.len(),
            16,
            "the state holds the 8 coordinates and their rates"
        );
        for (a, b) in s.x.iter().zip(x) {
            worst = worst.max((a - b).abs() / (1.0 + b.abs()));
        }
    }
    worst
}

/// The scene equals the coupling imposed by hand on the generated full model; the run moves
/// (the finger and the arm leave their initial state), so equal trajectories are not trivial.
#[test]
fn trajectory_equals_the_full_model_coupled_by_hand() {
    let scene = common::load(PD_SCENE);
    assert_eq!((scene.dof(), scene.model.dof()), (8, 9));
    let w = against_oracle(Coupled { k: 1.0, o: 0.0 }, &scene);
    println!("panda_mimic_pd: worst relative difference to the oracle {w:e}");
    assert!(w < 1e-10, "{w:e}");
    let run = simulate(&scene, None).unwrap();
    let last = &run.samples.last().unwrap().x;
    assert!((last[7] - scene.q0[7]).abs() > 1e-3, "the finger moves");
}

/// The same with a coupling of multiplier −0.5 and offset 0.01 (the URDF's `<mimic>` edited
/// into a copy), which a multiplier of one would not tell from a wrong sign or scale.
#[test]
fn trajectory_with_multiplier_and_offset() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("mimic_sim");
    std::fs::create_dir_all(&dir).unwrap();
    let urdf = std::fs::read_to_string(common::root().join("tests/data/erd_all/panda.urdf"))
        .unwrap()
        .replace(
            r#"<mimic joint="panda_finger_joint1"/>"#,
            r#"<mimic joint="panda_finger_joint1" multiplier="-0.5" offset="0.01"/>"#,
        );
    assert!(urdf.contains("multiplier=\"-0.5\""));
    std::fs::write(dir.join("panda_scaled.urdf"), urdf).unwrap();
    let text = std::fs::read_to_string(common::root().join(PD_SCENE))
        .unwrap()
        .replace("../erd_all/panda.urdf", "panda_scaled.urdf");
    let scene = Scene::parse(&text, &dir).unwrap();
    let c = Coupled { k: -0.5, o: 0.01 };
    let w = against_oracle(c, &scene);
    println!("multiplier -0.5, offset 0.01: worst relative difference {w:e}");
    assert!(w < 1e-10, "{w:e}");
    // A wrong coupling in the oracle is seen: the check can fail.
    let wrong = against_oracle(Coupled { k: 1.0, o: 0.0 }, &scene);
    println!("against the unscaled coupling: {wrong:e}");
    assert!(wrong > 1e-4, "{wrong:e}");
}

/// `scene!` on the mimic scene: the compiled run is the interpreted one.
#[test]
fn compiled_scene_equals_the_interpreted_run() {
    let scene = common::load(PD_SCENE);
    let run = simulate(&scene, None).unwrap();
    let mut compiled = Vec::new();
    PandaPd::run(|t, s| compiled.push((t, s.to_array()))).unwrap();
    let w = common::worst("panda_mimic_pd", &compiled, &run);
    println!("scene! against the interpreted run: {w:e}");
    assert!(w < 1e-9, "{w:e}");
}

/// A passive run (gravity, a payload on the mimic finger) conserves energy; the monitor's
/// kinetic energy is the generated full model's `½ q̇_fullᵀ M_full q̇_full` on the scene
/// without payload.
#[test]
fn passive_run_conserves_energy() {
    let scene = common::load("tests/data/scenes/panda_mimic.toml");
    let run = simulate(&scene, None).unwrap();
    let drift = run.summary.max_energy_drift_rel.unwrap();
    println!("passive Panda with coupled fingers: energy drift {drift:e}");
    assert!(drift < 1e-8, "{drift:e}");
    assert_eq!(run.summary.final_state.q.len(), 8);

    let pd = common::load(PD_SCENE);
    let sys = SceneSystem::new(&pd);
    let c = Coupled { k: 1.0, o: 0.0 };
    let mut worst = 0.0_f64;
    for s in simulate(&pd, None).unwrap().samples.iter().step_by(10) {
        let (q, qd) = s.x.split_at(8);
        let (qf, vf) = (c.positions(q), c.rates(qd));
        let m = PandaFull::mass_matrix(&qf);
        let t: f64 = 0.5
            * (0..9)
                .map(|a| vf[a] * (0..9).map(|b| m[a][b] * vf[b]).sum::<f64>())
                .sum::<f64>();
        worst = worst.max((sys.kinetic_energy(&s.x) - t).abs() / t);
    }
    println!("kinetic energy against the full model: {worst:e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// The step Jacobians of a mimic scene (PD drives, damping, gravity; no wrench) are central
/// differences of the step.
#[test]
fn step_jacobians_match_differences() {
    let text = std::fs::read_to_string(common::root().join(PD_SCENE)).unwrap();
    let text = text.split("[[effects.wrench]]").next().unwrap().to_string()
        + "[drives]"
        + text.split("[drives]").nth(1).unwrap();
    let scene = Scene::parse(&text, &common::root().join("tests/data/scenes")).unwrap();
    assert!(scene.wrenches.is_empty());
    let mut sys = SceneSystem::new(&scene);
    let x = sys.initial_state();
    let (h, u) = (scene.simulation.step, vec![0.0; 8]);
    let j = kanegen::sim::linearize::step_jacobians(&mut sys, 0.0, &x, &u, h).unwrap();
    let mut worst = 0.0_f64;
    let eps = 1e-6;
    for c in 0..16 {
        let mut step = |d: f64| {
            let mut xp = x.clone();
            xp[c] += d;
            kanegen::sim::linearize::step_jacobians(&mut sys, 0.0, &xp, &u, h)
                .unwrap()
                .state
        };
        let (p, m) = (step(eps), step(-eps));
        for r in 0..16 {
            let fd = (p[r] - m[r]) / (2.0 * eps);
            worst = worst.max((fd - j.a[r][c]).abs() / (1.0 + fd.abs()));
        }
    }
    println!("step Jacobian A against central differences: {worst:e}");
    assert!(worst < 1e-7, "{worst:e}");
}

/// `kanegen simulate` runs the mimic scene: the CSV has a column per coordinate and none for
/// the mimic joint.
#[test]
fn cli_simulates_a_mimic_scene() {
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("mimic_sim_cli");
    let _ = std::fs::remove_dir_all(&out);
    let o = common::kanegen(&[
        "simulate",
        "tests/data/scenes/panda_mimic.toml",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["complete"], true);
    assert_eq!(j["final"]["q"].as_array().unwrap().len(), 8);
    assert!(j["max_energy_drift_rel"].as_f64().unwrap() < 1e-8);
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.contains("q_panda_finger_joint1"), "{header}");
    assert!(!header.contains("panda_finger_joint2"), "{header}");
    assert_eq!(header.split(',').count(), 1 + 16);
}

/// A scene that gives the mimic joint a value of its own (9 initial positions for 8
/// coordinates) is refused naming the file, the key and the joint the mimic joint follows.
#[test]
fn a_value_for_the_mimic_joint_is_refused() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("mimic_sim_bad");
    std::fs::create_dir_all(&dir).unwrap();
    let model = common::root().join("tests/data/erd_all/panda.urdf");
    let file = dir.join("nine_values.toml");
    std::fs::write(
        &file,
        format!(
            "model = {:?}\n[initial]\nq = [0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0, 0.02, 0.02]\n\
             [simulation]\nduration = 0.1\n",
            model.display().to_string()
        ),
    )
    .unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .args(["simulate", file.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{err}");
    for part in [
        "nine_values.toml",
        "initial.q: expected 8 values, one per coordinate",
        "got 9",
        "`panda_finger_joint2` follows `panda_finger_joint1`",
    ] {
        assert!(err.contains(part), "`{part}` missing from: {err}");
    }
}
