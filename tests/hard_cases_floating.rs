//! Free-floating hard cases, each run on interpreted and on generated code (`kanegen::scene!`):
//!
//! - **F1, a dynamic singularity**: the free-floating 7-dof arm driven by joint PD controllers
//!   toward a configuration where the generalized Jacobian `J*` of a frame on its last link is
//!   singular (`tests/data/hard/floating_singular.toml`; the target, found by a coordinate
//!   search from elbow straight, has `σ_min(J*) = 1.8e-8`). The equations of motion stay
//!   regular there (`A` is positive definite everywhere), so the run completes with finite
//!   states; [`SingularityWatch`] reports the singularity (`σ_min(J*)` below a threshold, with
//!   the interval and the smallest value). The base motion (`p₀`, attitude) of the run at the
//!   scene's tolerance 1e-8 is compared with a reference run at 1e-12.
//! - **F2, a free-floating random chain N = 64** (`tests/data/hard/random_chain_64.toml`,
//!   `random_chain` seed 64, 0.3 m links of about 5 kg on a 500 kg base): forward dynamics of
//!   the generated code (the unrolled `dynamics!` of the scene, 70 speeds), of the interpreted
//!   `recurrent` and `spatial` (ABA) algorithms, against the `recurrent` algorithm in
//!   [`Wide`] (double-double) at three random states; and a 1 s unactuated run
//!   (`random_chain_64_scene.toml`, dopri5 at 1e-10) conserving energy and momentum, interpreted
//!   and compiled.
//!
//! Measured (release build, `--nocapture`) and bounds (at least 3× the worst measured value):
//!
//! | case | what | measured | bound |
//! |---|---|---|---|
//! | F1 | `σ_min(J*)` (nalgebra's SVD) squared vs `λ_min(J* J*ᵀ)` (symmetric eigensolver), 11 states on the way: `\|Δσ²\| / σ_max²` | 2.4e-16 | 1e-14 |
//! | F1 | `σ_min(J*)` at the target (SVD) | 2.6e-8 | < 1e-7 |
//! | F1 | the watch (threshold 2e-2), interpreted and compiled | below in [3.3, 3.8], [4.7, 5.8], [6.6, 10] s; smallest 3.9e-4 at t = 10 s (both) | reported; compiled minimum within 1e-6 |
//! | F1 | base position / quaternion error, tolerance 1e-8 vs 1e-12 | 9.7e-10 m / 1.1e-9 | 1e-8 (9×) |
//! | F1 | compiled vs interpreted state, every sample | 3.0e-11 | 1e-9 (1 + \|x\|) |
//! | F1 | momentum drift (interpreted, tolerance 1e-8) | 7.1e-9 lin, 3.8e-8 ang | 2e-7 (5×) |
//! | F2 | `ν̇` error vs Wide, worst of 3 states: generated, recurrent, spatial (ABA) | 5.5e-14, 2.1e-12, 6.8e-12 | 3e-11 (4.4×) |
//! | F2 | 1 s run: energy, momentum drift (interpreted); momentum (compiled) | 4.0e-10, 2.4e-10 lin, 2.2e-10 ang; 2.4e-10, 2.2e-10 | 3e-9 (7.5×) |
//! | F2 | compiled vs interpreted state, every sample | 4.2e-13 | 1e-9 (1 + \|x\|) |
//!
//! The generated `N = 64` free-floating code (`dynamics!` through `scene!`) compiles in about
//! 25 s in a release build of this test.

use kanegen::dynamics::algorithms::floating;
use kanegen::dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen::dynamics::linalg::{Mat3, Vec3};
use kanegen::dynamics::metrics::rel_err;
use kanegen::dynamics::scalars::wide::Wide;
use kanegen::dynamics::{FrameParams, Loads, Methods, Params, Real, Scalar};
use kanegen::model::random::{random_vec, rng};
use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate, simulate_to, Control, Run, Sample, SceneSystem};
use kanegen::sim::singularity::SingularityWatch;
use nalgebra::DMatrix;
use std::path::Path;

kanegen::scene!(FloatingSingular, "tests/data/hard/floating_singular.toml");
kanegen::scene!(Random64, "tests/data/hard/random_chain_64_scene.toml");

fn load(file: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).unwrap()
}

/// The frame `J*` is taken of: 0.3 m along z of link_7.
fn tip() -> FrameParams<f64> {
    FrameParams {
        parent: Some(6),
        translation: Vec3::from_f64([0.0, 0.0, 0.3]),
        rotation: Mat3::identity(),
    }
}

/// Worst `|x_c − x_i| / (1 + |x_i|)` over the samples (same times).
fn worst<const D: usize>(c: &[(f64, [f64; D])], run: &Run) -> f64 {
    assert_eq!(c.len(), run.samples.len());
    let mut w: f64 = 0.0;
    for ((tc, xc), s) in c.iter().zip(&run.samples) {
        assert!((tc - s.t).abs() <= 1e-12 * (1.0 + s.t));
        for (a, b) in xc.iter().zip(&s.x) {
            w = w.max((a - b).abs() / (1.0 + b.abs()));
        }
    }
    w
}

#[test]
fn f1_dynamic_singularity_is_reported_not_a_nan() {
    let scene = load("tests/data/hard/floating_singular.toml");
    let monitor = SceneSystem::new(&scene);
    // The helper against nalgebra's SVD, along a path from the start to the target.
    let x0 = monitor.initial_state();
    let target = match &scene.drives {
        kanegen::sim::scene::Drives::Pd { target, .. } => target.clone(),
        _ => panic!("PD drives"),
    };
    let mut worst_svd: f64 = 0.0;
    for k in 0..=10 {
        let s = f64::from(k) / 10.0;
        let mut x = x0.clone();
        for i in 0..7 {
            x[7 + i] = (1.0 - s) * scene.q0[i] + s * target[i];
        }
        let (q, _, st) = monitor.split(&x);
        let j = kanegen::dynamics::algorithms::frames::generalized_jacobian(
            monitor.params(),
            monitor.floating_base().unwrap(),
            &st.unwrap(),
            q,
            &tip(),
        );
        let m = DMatrix::from_fn(6, 7, |r, c| j[r][c]);
        let sv = m.singular_values();
        let svd = sv.iter().copied().fold(f64::INFINITY, f64::min);
        let smax = sv.iter().copied().fold(0.0, f64::max);
        let mine = monitor.sigma_min(&x, &tip()).unwrap();
        assert_eq!(mine, svd, "the watch's σ_min is the SVD's");
        // An independent check of the SVD: λ_min of J* J*ᵀ (symmetric eigensolver), resolved
        // to the rounding of that product, |Δσ²| ≲ ε σ_max².
        let lmin = (&m * m.transpose())
            .symmetric_eigenvalues()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        worst_svd = worst_svd.max((lmin - svd * svd).abs() / (smax * smax));
        if k == 10 {
            eprintln!("σ_min(J*) at the target: {mine:.2e} (λ_min(J* J*ᵀ) {lmin:.2e})");
            assert!(mine < 1e-7);
        }
    }
    eprintln!("σ_min² (SVD) vs λ_min(J* J*ᵀ): |Δσ²|/σ_max² ≤ {worst_svd:.1e}");
    assert!(worst_svd <= 1e-14);

    // The run: completes, finite, the singularity reported.
    let threshold = 2e-2;
    let mut watch = SingularityWatch::new(threshold);
    let mut samples: Vec<Sample> = Vec::new();
    let mut sink = |s: &Sample| -> anyhow::Result<()> {
        watch.observe(s.t, monitor.sigma_min(&s.x, &tip()).unwrap());
        samples.push(s.clone());
        Ok(())
    };
    let summary = simulate_to(&scene, &mut sink, Control::default()).unwrap();
    assert!(summary.complete);
    assert!(samples.iter().all(|s| s.x.iter().all(|v| v.is_finite())));
    let report = watch.report().expect("the singularity is reported");
    // The summary reports the smallest σ_min(J*) of the last body's frame, as the watch would.
    let last = summary
        .singularity
        .as_ref()
        .expect("a free-floating scene of 7 joints");
    let frame = FrameParams {
        parent: Some(6),
        translation: Vec3::zero(),
        rotation: Mat3::identity(),
    };
    let mut own = SingularityWatch::new(threshold);
    for s in &samples {
        own.observe(s.t, monitor.sigma_min(&s.x, &frame).unwrap());
    }
    eprintln!("summary: {last:?}");
    assert_eq!((last.sigma_min, last.t), own.min);
    assert!(last.sigma_min.is_finite() && last.sigma_min > 0.0);
    eprintln!("{report}");
    assert!(watch.min.0 < threshold && watch.min.0 > 0.0);
    let (l, a) = (
        summary.max_linear_momentum_drift_rel.unwrap(),
        summary.max_angular_momentum_drift_rel.unwrap(),
    );
    eprintln!("momentum drift {l:.1e} lin, {a:.1e} ang");
    assert!(l <= 2e-7 && a <= 2e-7);

    // The base motion against a reference run at 1e-12.
    let mut tight = scene.clone();
    tight.simulation.tolerance = 1e-12;
    let reference = simulate(&tight, None).unwrap();
    assert_eq!(reference.samples.len(), samples.len());
    let (mut ep, mut eq): (f64, f64) = (0.0, 0.0);
    for (s, r) in samples.iter().zip(&reference.samples) {
        for i in 0..3 {
            ep = ep.max((s.x[i] - r.x[i]).abs());
        }
        for i in 3..7 {
            eq = eq.max((s.x[i] - r.x[i]).abs());
        }
    }
    eprintln!("base error vs tolerance 1e-12: position {ep:.1e} m, quaternion {eq:.1e}");
    assert!(ep <= 1e-8 && eq <= 1e-8);

    // Generated code: the same trajectory, and the watch sees the same singularity.
    let mut c = Vec::new();
    FloatingSingular::run(|t, s| c.push((t, s.to_array()))).unwrap();
    let run = Run {
        summary,
        samples: samples.clone(),
    };
    let w = worst(&c, &run);
    let mut watch_c = SingularityWatch::new(threshold);
    for (t, x) in &c {
        watch_c.observe(*t, monitor.sigma_min(x, &tip()).unwrap());
    }
    eprintln!(
        "compiled vs interpreted {w:.1e}; compiled smallest σ_min {:.3e} at t = {}",
        watch_c.min.0, watch_c.min.1
    );
    assert!(w <= 1e-9);
    assert!(watch_c.report().is_some());
    assert!((watch_c.min.0 - watch.min.0).abs() <= 1e-6);
}

fn consts<S: Scalar>(x: &[f64]) -> Vec<S> {
    x.iter().map(|&v| S::constant(v)).collect()
}

/// `ν̇` of the interpreted algorithm `m` in scalar `S` at `(quat, q, v)` (position 0).
fn nu_dot<S: Scalar + Real>(
    scene: &Scene,
    m: Methods,
    quat: [f64; 4],
    q: &[f64],
    v: &[f64],
) -> Vec<f64> {
    let inertial = base_inertial(scene);
    let p = Params::<S>::new(&scene.model);
    let base = FloatingBase::<S>::from_inertial(&inertial);
    let st = FloatingState {
        position: Vec3::zero(),
        rotation: quat_to_matrix(&quat.map(S::constant)),
        v_b: Vec3::from_f64([v[0], v[1], v[2]]),
        omega_b: Vec3::from_f64([v[3], v[4], v[5]]),
    };
    let a = floating::forward_dynamics(
        m,
        &p,
        &base,
        &st,
        &consts::<S>(q),
        &consts::<S>(&v[6..]),
        &Loads::default(),
    );
    a.iter().map(Real::to_f64).collect()
}

fn base_inertial(scene: &Scene) -> kanegen::model::Inertial {
    match &scene.base {
        kanegen::sim::scene::BaseSpec::FreeFloating { inertial, .. } => inertial.clone(),
        kanegen::sim::scene::BaseSpec::Fixed => panic!("free-floating"),
    }
}

#[test]
fn f2_random_free_floating_chain_n64() {
    let scene = load("tests/data/hard/random_chain_64_scene.toml");
    let n = scene.model.dof();
    assert_eq!(n, 64);
    let mut worst_err = [0.0_f64; 3];
    for seed in 0..3 {
        let mut r = rng(100 + seed);
        let q: Vec<f64> = random_vec(&mut r, n, 1.0);
        let v: Vec<f64> = random_vec(&mut r, 6 + n, 0.5);
        let u: Vec<f64> = random_vec(&mut r, 4, 1.0);
        let norm = u.iter().map(|x| x * x).sum::<f64>().sqrt();
        let quat = [u[0] / norm, u[1] / norm, u[2] / norm, u[3] / norm];
        let reference = nu_dot::<Wide>(&scene, Methods::RECURRENT, quat, &q, &v);
        let recurrent = nu_dot::<f64>(&scene, Methods::RECURRENT, quat, &q, &v);
        let spatial = nu_dot::<f64>(&scene, Methods::SPATIAL, quat, &q, &v);
        let qg: [f64; 71] = core::array::from_fn(|i| {
            if i < 3 {
                0.0
            } else if i < 7 {
                quat[i - 3]
            } else {
                q[i - 7]
            }
        });
        let vg: [f64; 70] = v.clone().try_into().unwrap();
        let generated = Random64Dynamics::forward_dynamics(&qg, &vg, &[0.0; 64]);
        let errs = [
            rel_err(&generated, &reference),
            rel_err(&recurrent, &reference),
            rel_err(&spatial, &reference),
        ];
        eprintln!("N = 64, state {seed}: ν̇ error vs Wide: generated {:.1e}, recurrent {:.1e}, spatial {:.1e}", errs[0], errs[1], errs[2]);
        for k in 0..3 {
            worst_err[k] = worst_err[k].max(errs[k]);
        }
    }
    assert!(worst_err.iter().all(|e| *e <= 3e-11), "{worst_err:?}");

    // A short unactuated run conserves energy and momentum, interpreted and compiled.
    let run = simulate(&scene, None).unwrap();
    let s = &run.summary;
    let (e, l, a) = (
        s.max_energy_drift_rel.unwrap(),
        s.max_linear_momentum_drift_rel.unwrap(),
        s.max_angular_momentum_drift_rel.unwrap(),
    );
    let x0 = Random64::initial_state();
    let p0 = Random64Dynamics::momentum(&x0.q, &x0.v);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let (mut dl, mut da) = (0.0_f64, 0.0_f64);
    let mut c = Vec::new();
    Random64::run(|t, st| {
        let p = Random64Dynamics::momentum(&st.q, &st.v);
        let d: Vec<f64> = (0..6).map(|i| p[i] - p0[i]).collect();
        dl = dl.max(norm(&d[..3]) / norm(&p0[..3]));
        da = da.max(norm(&d[3..]) / norm(&p0[3..]));
        c.push((t, st.to_array()));
    })
    .unwrap();
    let w = worst(&c, &run);
    eprintln!(
        "N = 64 run: interpreted drift energy {e:.1e}, momentum {l:.1e} lin {a:.1e} ang; compiled momentum {dl:.1e} lin {da:.1e} ang; compiled vs interpreted {w:.1e}"
    );
    assert!(e <= 3e-9 && l <= 3e-9 && a <= 3e-9);
    assert!(dl <= 3e-9 && da <= 3e-9);
    assert!(w <= 1e-9);
}
