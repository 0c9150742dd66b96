//! The hard cases of `tests/hard_cases.rs` on generated code: the same references (the
//! interpreted algorithm in double-double, [`Wide`], on the same model numbers), the same kind
//! of bounds, now on what `dynamics!` and `scene!` emit (unrolled and compact forms, `f64`).
//! The measured values are from `--nocapture`; every bound has a margin of at least 3× over
//! the worst measured value.
//!
//! | case | generated code | measured (worst) | bound |
//! |---|---|---|---|
//! | 1 | `scene!` of SSRMS + 116 t payload (`scenes/ssrms_payload_fixed.toml`), the interpreted case's 16 states | q̈ 0.62·cond·ε; M 2.6ε; c 16ε | q̈ ≤ 2·cond·ε; M, c ≤ 64ε |
//! | 2 | `dynamics!` of the random chains N = 8 (compact and unrolled), 16, 32, 64 (compact) of `benches/data`, 4 states each | q̈ 0.050·cond·ε; M 46ε (N = 32); c 37ε (N = 64) | q̈ ≤ 0.25·cond·ε; M, c ≤ 160ε |
//! | 5 | joint rates ±10 rad/s, τ = 0: the generated SSRMS (`kanegen_generated`) and the payload `scene!` | c 2.8ε (SSRMS), 1.9ε (payload); q̈ 1.01·cond·ε (payload, one state of cond 1.3e3) | c ≤ 32ε; q̈ ≤ 4·cond·ε |
//! | 6 | `scene!` of the passive free-floating 7-dof arm, 1e5 steps of 0.01 s | midpoint ΔE/E₀ 4.2e-6, ΔP/P₀ 1.4e-6, ΔL/L₀ 2.5e-5; RK4 8.6e-10, 3.2e-10, 7.9e-9 | the interpreted case's: 2e-5, 1e-5, 1e-4; 3e-9, 3e-9, 4e-8 |
//!
//! Findings: the generated code is as stable as the interpreted algorithms, with its own
//! rounding. Its q̈ errors are larger on the payload case (0.62·cond·ε against 0.11 for the
//! interpreted recurrent algorithm; 1.01·cond·ε at 10 rad/s): LDLᵀ on the local-frame CRBA with
//! regrouped parameters rounds differently, still far inside the first-order perturbation bound
//! `cond·(‖δM‖/‖M‖ + ‖δc‖/‖c‖)` that its M and c errors allow. The compact form (loops, the
//! articulated-body algorithm for q̈) is as accurate as the unrolled one at N = 8. Momentum and
//! energy drift in the compiled long run are the interpreted run's (case 6 of
//! `tests/hard_cases.rs`), within the same bounds; 2e5 compiled steps take about a second.
//!
//! `ε = f64::EPSILON`; errors are `max |x − y| / max |y|`; `cond` is cond₂ of the reference
//! `M`. Cases 3 and 4 of `tests/hard_cases.rs` build their models in code (mass ratios, nearly
//! coincident axes), and `dynamics!` reads files; they stay interpreted.

use kanegen::dynamics::ldlt::{ldlt, solve};
use kanegen::dynamics::metrics::{rel_err, rel_err_mat};
use kanegen::dynamics::scalars::wide::Wide;
use kanegen::dynamics::{Loads, Methods, Params, Real, Scalar};
use kanegen::model::random::{random_vec, rng};
use kanegen::model::Model;
use kanegen_generated::ssrms::Ssrms;
use nalgebra::{DMatrix, SymmetricEigen};
use std::path::PathBuf;

kanegen::scene!(Payload, "scenes/ssrms_payload_fixed.toml");
kanegen::dynamics!(Random8, "benches/data/random_n8.toml");
kanegen::dynamics!(
    Random8Unrolled,
    "benches/data/random_n8.toml",
    form = "unrolled"
);
kanegen::dynamics!(Random16, "benches/data/random_n16.toml");
kanegen::dynamics!(Random32, "benches/data/random_n32.toml");
kanegen::dynamics!(Random64, "benches/data/random_n64.toml");
kanegen::scene!(
    PassiveMidpoint,
    "tests/data/hard/free_floating_7dof_passive.toml"
);
kanegen::scene!(
    PassiveRk4,
    "tests/data/hard/free_floating_7dof_passive_rk4.toml"
);

const EPS: f64 = f64::EPSILON;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn load(rel: &str) -> Model {
    kanegen::model::io::load_model_with(
        &root().join(rel),
        kanegen::model::Validation {
            allow_nonphysical_inertia: true,
        },
    )
    .unwrap_or_else(|e| panic!("{rel}: {e:#}"))
}

fn wide(x: &[f64]) -> Vec<Wide> {
    x.iter().map(|&v| Wide::constant(v)).collect()
}

fn to_f64(x: &[Wide]) -> Vec<f64> {
    x.iter().map(Real::to_f64).collect()
}

/// The double-double reference at `(q, q̇, τ)`: `M`, `c` (`b` at `τ = 0` is `−c`), `q̈`, and
/// cond₂ of `M`.
struct Reference {
    m: Vec<Vec<f64>>,
    c: Vec<f64>,
    qdd: Vec<f64>,
    cond: f64,
}

fn reference(model: &Model, q: &[f64], qd: &[f64], tau: &[f64]) -> Reference {
    let p = Params::<Wide>::new(model);
    let loads = Loads {
        tau: Some(wide(tau)),
        ..Loads::default()
    };
    let d = Methods::RECURRENT.dynamics(&p, &wide(q), &wide(qd), &loads);
    let qdd = to_f64(&solve(&ldlt(&d.mass_matrix), &d.tau_minus_c));
    let b0 = Methods::RECURRENT.nonlinear_effects.tau_minus_c(
        &p,
        &wide(q),
        &wide(qd),
        &Loads::default(),
    );
    let m: Vec<Vec<f64>> = d.mass_matrix.iter().map(|r| to_f64(r)).collect();
    let n = m.len();
    let ev = SymmetricEigen::new(DMatrix::from_fn(n, n, |i, j| m[i][j])).eigenvalues;
    let (lo, hi) = ev.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &e| {
        (lo.min(e), hi.max(e))
    });
    assert!(
        lo > 0.0,
        "the reference M is not positive definite: λmin {lo:e}"
    );
    Reference {
        m,
        c: to_f64(&b0).iter().map(|b| -b).collect(),
        qdd,
        cond: hi / lo,
    }
}

/// A generated `forward_dynamics(q, q̇, τ)`.
type ForwardDynamics<const N: usize> = fn(&[f64; N], &[f64; N], &[f64; N]) -> [f64; N];

/// The functions of one generated fixed-base type.
struct Generated<const N: usize> {
    m: fn(&[f64; N]) -> [[f64; N]; N],
    c: fn(&[f64; N], &[f64; N]) -> [f64; N],
    fd: ForwardDynamics<N>,
}

/// The [`Generated`] functions of a generated type.
macro_rules! generated {
    ($t:ty) => {
        Generated {
            m: <$t>::mass_matrix,
            c: <$t>::nonlinear_effects,
            fd: <$t>::forward_dynamics,
        }
    };
}

/// Worst errors over the states: `(q̈ / (cond·ε), M / ε, c / ε)`.
fn measure<const N: usize>(
    label: &str,
    model: &Model,
    g: &Generated<N>,
    states: &[(Vec<f64>, Vec<f64>, Vec<f64>)],
) -> [f64; 3] {
    let mut worst = [0.0_f64; 3];
    for (s, (q, qd, tau)) in states.iter().enumerate() {
        let r = reference(model, q, qd, tau);
        let arr = |x: &[f64]| -> [f64; N] { x.try_into().unwrap() };
        let m: Vec<Vec<f64>> = (g.m)(&arr(q)).iter().map(|r| r.to_vec()).collect();
        let e = [
            rel_err(&(g.fd)(&arr(q), &arr(qd), &arr(tau)), &r.qdd) / (r.cond * EPS),
            rel_err_mat(&m, &r.m) / EPS,
            rel_err(&(g.c)(&arr(q), &arr(qd)), &r.c) / EPS,
        ];
        println!(
            "{label} s{s}: cond {:.2e}; q̈ {:.3}·cond·ε, M {:.2}ε, c {:.2}ε",
            r.cond, e[0], e[1], e[2]
        );
        for (w, x) in worst.iter_mut().zip(e) {
            *w = w.max(x);
        }
    }
    println!(
        "{label}: worst q̈ {:.3}·cond·ε, M {:.2}ε, c {:.2}ε",
        worst[0], worst[1], worst[2]
    );
    worst
}

/// `k` random states: angles in (−π, π), rates in (−qd, qd), drives in (−tau, tau).
fn states(n: usize, seed: u64, k: u64, qd: f64, tau: f64) -> Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    (0..k)
        .map(|s| {
            let mut r = rng(seed + s);
            (
                random_vec(&mut r, n, std::f64::consts::PI),
                random_vec(&mut r, n, qd),
                random_vec(&mut r, n, tau),
            )
        })
        .collect()
}

/// Case 1: the payload scene's generated dynamics at the interpreted case's 16 states.
#[test]
fn case1_generated_ssrms_with_116t_payload() {
    let model = kanegen::sim::scene::Scene::load(&root().join("scenes/ssrms_payload_fixed.toml"))
        .unwrap()
        .model;
    let g = generated!(PayloadDynamics);
    let w = measure("payload", &model, &g, &states(7, 100, 16, 0.05, 2000.0));
    assert!(w[0] <= 2.0, "q̈ {}·cond·ε", w[0]);
    assert!(w[1] <= 64.0 && w[2] <= 64.0, "M {}ε, c {}ε", w[1], w[2]);
}

/// Case 2: random chains with general geometry, unrolled and compact.
#[test]
fn case2_generated_random_chains() {
    let mut worst = [0.0_f64; 3];
    let mut add = |w: [f64; 3]| {
        for (a, b) in worst.iter_mut().zip(w) {
            *a = a.max(b);
        }
    };
    let m8 = load("benches/data/random_n8.toml");
    let s8 = states(8, 9000, 4, 1.0, 10.0);
    add(measure("random 8 compact", &m8, &generated!(Random8), &s8));
    add(measure(
        "random 8 unrolled",
        &m8,
        &generated!(Random8Unrolled),
        &s8,
    ));
    add(measure(
        "random 16",
        &load("benches/data/random_n16.toml"),
        &generated!(Random16),
        &states(16, 9100, 4, 1.0, 10.0),
    ));
    add(measure(
        "random 32",
        &load("benches/data/random_n32.toml"),
        &generated!(Random32),
        &states(32, 9200, 4, 1.0, 10.0),
    ));
    add(measure(
        "random 64",
        &load("benches/data/random_n64.toml"),
        &generated!(Random64),
        &states(64, 9300, 4, 1.0, 10.0),
    ));
    assert!(worst[0] <= 0.25, "q̈ {}·cond·ε", worst[0]);
    assert!(
        worst[1] <= 64.0 && worst[2] <= 64.0,
        "M {}ε, c {}ε",
        worst[1],
        worst[2]
    );
}

/// Case 5: joint rates of ±10 rad/s (`c` is then dominated by the velocity products).
#[test]
fn case5_generated_fast_joints() {
    let fast = |n: usize, seed: u64| -> Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        states(n, seed, 6, 1.0, 1.0)
            .into_iter()
            .map(|(q, qd, _)| {
                (
                    q,
                    qd.iter().map(|x| 10.0 * x.signum()).collect(),
                    vec![0.0; n],
                )
            })
            .collect()
    };
    let ssrms = load("tests/data/reference/ssrms_nguyen_hughes_1994.urdf");
    let w = measure("ssrms 10 rad/s", &ssrms, &generated!(Ssrms), &fast(7, 8000));
    assert!(w[2] <= 32.0, "ssrms c {}ε", w[2]);
    assert!(w[0] <= 4.0, "ssrms q̈ {}·cond·ε", w[0]);
    let payload = kanegen::sim::scene::Scene::load(&root().join("scenes/ssrms_payload_fixed.toml"))
        .unwrap()
        .model;
    let w = measure(
        "payload 10 rad/s",
        &payload,
        &generated!(PayloadDynamics),
        &fast(7, 8000),
    );
    assert!(w[2] <= 32.0, "payload c {}ε", w[2]);
    assert!(w[0] <= 4.0, "payload q̈ {}·cond·ε", w[0]);
}

/// Energy `½ vᵀ M v` and momentum `[P, L]` drifts (relative, worst over the samples) of a
/// compiled free-floating run, by the scene's generated `mass_matrix` and `momentum`.
fn drifts(samples: &[([f64; 14], [f64; 13])]) -> [f64; 3] {
    let energy = |q: &[f64; 14], v: &[f64; 13]| {
        let m = PassiveRk4Dynamics::mass_matrix(q);
        0.5 * (0..13)
            .map(|i| v[i] * (0..13).map(|j| m[i][j] * v[j]).sum::<f64>())
            .sum::<f64>()
    };
    let norm = |x: &[f64]| x.iter().map(|a| a * a).sum::<f64>().sqrt();
    let (q0, v0) = &samples[0];
    let (e0, h0) = (energy(q0, v0), PassiveRk4Dynamics::momentum(q0, v0));
    let mut d = [0.0_f64; 3];
    for (q, v) in samples {
        let h = PassiveRk4Dynamics::momentum(q, v);
        let dh: Vec<f64> = h.iter().zip(&h0).map(|(a, b)| a - b).collect();
        d[0] = d[0].max((energy(q, v) - e0).abs() / e0);
        d[1] = d[1].max(norm(&dh[..3]) / norm(&h0[..3]));
        d[2] = d[2].max(norm(&dh[3..]) / norm(&h0[3..]));
    }
    d
}

/// Case 6: 1e5 steps of the passive free-floating arm, compiled, with the interpreted case's
/// bounds (there: midpoint 2e-5, 1e-5, 1e-4; RK4 3e-9, 3e-9, 4e-8, for ΔE/E₀, ΔP/P₀, ΔL/L₀;
/// sampled every 100 steps here, every 10 there).
#[test]
fn case6_generated_long_free_floating_run() {
    let mut mid = Vec::new();
    let stats = PassiveMidpoint::run(|_, s| mid.push((s.q, s.v))).unwrap();
    assert_eq!(stats.steps, 100_000);
    let mut rk = Vec::new();
    let stats = PassiveRk4::run(|_, s| rk.push((s.q, s.v))).unwrap();
    assert_eq!(stats.steps, 100_000);
    let (dm, dr) = (drifts(&mid), drifts(&rk));
    println!(
        "midpoint: ΔE/E0 {:.3e}, ΔP/P0 {:.3e}, ΔL/L0 {:.3e}",
        dm[0], dm[1], dm[2]
    );
    println!(
        "rk4: ΔE/E0 {:.3e}, ΔP/P0 {:.3e}, ΔL/L0 {:.3e}",
        dr[0], dr[1], dr[2]
    );
    assert!(
        dm[0] <= 2e-5 && dm[1] <= 1e-5 && dm[2] <= 1e-4,
        "midpoint {dm:?}"
    );
    assert!(
        dr[0] <= 3e-9 && dr[1] <= 3e-9 && dr[2] <= 4e-8,
        "rk4 {dr:?}"
    );
    let quat = |s: &[([f64; 14], [f64; 13])]| {
        s.iter()
            .map(|(q, _)| (q[3..7].iter().map(|a| a * a).sum::<f64>().sqrt() - 1.0).abs())
            .fold(0.0_f64, f64::max)
    };
    assert!(quat(&mid) <= 1e-13, "midpoint |quat| − 1: {:e}", quat(&mid));
    assert!(quat(&rk) <= 4.0 * EPS, "rk4 |quat| − 1: {:e}", quat(&rk));
}
