//! Hard cases for the numerics: ill-conditioned inertia matrices, long chains, extreme mass
//! ratios, degenerate joint geometry, fast joints, and a long free-floating run.
//!
//! The reference is the same algorithm run on [`Wide`] (double-double, ~32 digits) with the same
//! model numbers, so each error is the rounding error of `f64` (or `f32`). Errors are
//! [`rel_err`] (`max |x − y| / max |y|`), and `ε = f64::EPSILON`, `ε₃₂ = f32::EPSILON`.
//! `cond` is cond₂ of the reference `A` (nalgebra `SymmetricEigen`). `cond_s` is cond₂ of the
//! Jacobi-scaled `D^{-1/2} A D^{-1/2}` with `D = diag A`. LDLᵀ without pivoting is invariant
//! under that scaling, so `cond_s` is the condition that matters for it. The measured numbers
//! below are from `--nocapture`. Every bound is at least 2.9× the worst measured
//! value, and no test asserts on timing.
//!
//! Two measurements also run on every state: `recurrent` against `spatial` (independent
//! algorithms), and the `Wide` LDLᵀ pivots of `A`.
//!
//! | case | what | measured (worst) | bound |
//! |---|---|---|---|
//! | 1 | SSRMS + 116 t payload (scene merge), 16 states | cond 7.1e2…3.0e5; f64 q̈ 0.114·cond·ε (4.6e-12); f32 q̈ 0.31·cond·ε₃₂ (3.9e-3) | f64 ≤ cond·ε, f32 ≤ cond·ε₃₂ |
//! | 2 | random chains N = 8…128, 5 seeds each | A 3.1ε → 9.9ε (exponent 0.38); q̈ 1.0e-14 → 4.7e-12 (exp. 2.3, cond exp. 2.8); q̈ ≤ 0.060·cond·ε; ‖Aq̈ − b‖/‖b‖ ≤ 2.1·Nε | A exp. ≤ 1, A(128)/A(8) ≤ 16; q̈(128)/q̈(8) ≤ 16³; q̈ ≤ 0.25·cond·ε; residual ≤ 10·Nε; pivots > 0 |
//! | 3 | 1e-3 kg beside 1e5 kg (alternating, light chain with heavy tip) | cond ≤ 1.4e10; alternating q̈ ≤ 2e-15 (cond_s ≤ 143); heavy tip q̈ 6.3e-8 = 0.21·cond·ε = 0.34·cond_s·ε; f32 q̈ ≈ 1 (fails) | f64 ≤ cond·ε and ≤ cond_s·ε; f32 error > 0.1 asserted |
//! | 4 | consecutive axes 1e-6 rad from parallel / 1e-9 m from intersecting / both | cond ≤ 440: harmless on their own. With a 1e-3 (1e-6) kg body between near-coincident axes: cond 1.1e6 (1.1e9), q̈ 0.23·cond·ε, f32 fails | SPD (f64 and Wide pivots > 0); geometric cond ≤ 5e3; f64 ≤ cond·ε |
//! | 5 | joint rates ±10 rad/s, τ = 0 (b = −h) on SSRMS, SSRMS + payload, random N = 16 | b recurrent 6.4ε, spatial 9.4ε; recurrent vs spatial in Wide 7.9e-32 (SSRMS), 1.5e-15 (random: the f64 model is orthonormal only to ~ε) | b ≤ 32ε; Wide agreement ≤ 1e-30 / ≤ 30ε |
//! | 6 | bmsd 7-dof free-floating, τ = 0, 1e5 steps of 0.01 s | midpoint: ΔE/E 3.9e-6, ΔP 2.0e-6, ΔL 2.0e-5, ‖q‖−1 1.8e-14; RK4: 5.3e-10, 5.2e-10, 7.3e-9, 2.2e-16 | 5× the measured values; ‖q‖−1 ≤ 1e-13 (midpoint, no projection) |
//!
//! Findings:
//!
//! - In every case the f64 forward-dynamics error stays below 0.23·cond·ε. A large cond comes
//!   from a mass ratio along the chain, or from a light body between nearly coincident axes.
//!   It does not come from the geometry alone, because `A` is a mass matrix and not a Jacobian.
//! - In the alternating 1e-3/1e5 kg chain, cond is 1e10 but the error is ε-sized. The
//!   conditioning there is a diagonal scaling, which LDLᵀ does not feel (cond_s ≤ 143).
//! - f32 stays within 0.31·cond·ε₃₂ on the SSRMS payload case, an absolute error of up to
//!   3.9e-3. It fails (relative error ≈ 1 or non-finite) where cond ≳ 1e9.
//! - In case 6 the midpoint rule's energy error grows on this passive 7-dof motion: the worst
//!   |ΔE|/E in the first quarter is 9.1e-7 and in the last 3.2e-6. RK4 at the same step is
//!   7000× more accurate here: the motion is slow, and RK4's error is O(h⁴).

use kanegen::dynamics::ldlt::{ldlt, solve};
use kanegen::dynamics::metrics::{rel_err, rel_err_mat, rel_err_wide};
use kanegen::dynamics::scalars::wide::Wide;
use kanegen::dynamics::Params;
use kanegen::dynamics::{Loads, Methods, Real, Scalar};
use kanegen::model::placement::rpy_to_matrix;
use kanegen::model::random::{
    random_chain, random_inertial, random_rotation, random_vec, rng, ChainSpec,
};
use kanegen::model::{Inertial, Joint, JointKind, Model, Placement};
use kanegen::sim::integrate::{midpoint, rk4};
use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::SceneSystem;
use nalgebra::{DMatrix, SymmetricEigen};
use std::path::PathBuf;
use std::time::Instant;

const EPS: f64 = f64::EPSILON;
const EPS32: f64 = f32::EPSILON as f64;

/// f64 forward dynamics: `err(q̈) ≤ C64 · cond(A) · ε` in every case (worst measured 0.225, in
/// case 4; 4.4× margin). The textbook a-priori constant is O(N) or more. The measured one is
/// below 1 because cond₂ is a worst case over right-hand sides.
const C64: f64 = 1.0;
/// f32 forward dynamics on SSRMS + payload: `≤ C32 · cond(A) · ε₃₂` (measured 0.31; 3.2×).
const C32: f64 = 1.0;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn ssrms() -> Model {
    kanegen::model::io::load_model(
        &root().join("tests/data/reference/ssrms_nguyen_hughes_1994.urdf"),
    )
    .unwrap()
}

/// SSRMS with the 116 t payload of `scenes/ssrms_payload_fixed.toml`, merged into the last body
/// by the scene reader ([`kanegen::sim::scene::combine_inertials`], parallel-axis theorem).
fn ssrms_payload() -> Model {
    Scene::load(&root().join("scenes/ssrms_payload_fixed.toml"))
        .unwrap_or_else(|e| panic!("{e:#}"))
        .model
}

fn to_f64_vec<S: Real>(x: &[S]) -> Vec<f64> {
    x.iter().map(Real::to_f64).collect()
}

fn to_f64_mat<S: Real>(a: &[Vec<S>]) -> Vec<Vec<f64>> {
    a.iter().map(|r| to_f64_vec(r)).collect()
}

fn consts<S: Scalar>(x: &[f64]) -> Vec<S> {
    x.iter().map(|&v| S::constant(v)).collect()
}

fn drives<S: Scalar>(tau: &[f64]) -> Loads<S> {
    Loads {
        tau: Some(consts(tau)),
        ..Loads::default()
    }
}

/// `(cond₂, λ_min)` of a symmetric matrix, by nalgebra's `SymmetricEigen`.
fn cond2(m: DMatrix<f64>) -> (f64, f64) {
    let ev = SymmetricEigen::new(m).eigenvalues;
    let lo = ev.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ev.iter().copied().fold(0.0_f64, f64::max);
    (hi / lo, lo)
}

/// What one state measures: `f64` and `f32` results against the `Wide` reference.
#[derive(Clone, Debug)]
struct Measured {
    /// cond₂ of the reference `A`.
    cond: f64,
    /// cond₂ of the Jacobi-scaled reference `A`.
    cond_s: f64,
    /// Smallest eigenvalue of the reference `A`.
    lambda_min: f64,
    err_a: f64,
    err_b: f64,
    err_qdd: f64,
    err_qdd_f32: f64,
    /// `‖A q̈ − b‖₂ / ‖b‖₂` of the `f64` solve, with the `f64` `A` and `b`. The residual is
    /// summed in `Wide`, so the products are exact.
    residual: f64,
    /// All `f64` LDLᵀ pivots positive.
    pivots_positive: bool,
    /// Smallest `f64` and `Wide` LDLᵀ pivot, each over the largest diagonal entry of `A`.
    min_pivot: f64,
    min_pivot_wide: f64,
    /// `q̈` of `recurrent` against `spatial`, both in `f64`.
    err_alg: f64,
}

impl Measured {
    /// The f64 error in units of `cond · ε`.
    fn k64(&self) -> f64 {
        self.err_qdd / (self.cond * EPS)
    }
    /// The f32 error in units of `cond · ε₃₂`.
    fn k32(&self) -> f64 {
        self.err_qdd_f32 / (self.cond * EPS32)
    }
}

/// `A`, `b` and `q̈ = A⁻¹ b` by `recurrent` (LDLᵀ) in `Wide`, `f64` and `f32`, at `(q, q̇, τ)`.
fn measure(chain: &Model, q: &[f64], qd: &[f64], tau: &[f64]) -> Measured {
    let alg = Methods::RECURRENT;
    let dw = alg.dynamics(
        &Params::<Wide>::new(chain),
        &consts::<Wide>(q),
        &consts(qd),
        &drives(tau),
    );
    let fw = ldlt(&dw.mass_matrix);
    let xw = to_f64_vec(&solve(&fw, &dw.tau_minus_c));
    let aw = to_f64_mat(&dw.mass_matrix);
    let n = aw.len();
    let (cond, lambda_min) = cond2(DMatrix::from_fn(n, n, |i, j| aw[i][j]));
    let (cond_s, _) = cond2(DMatrix::from_fn(n, n, |i, j| {
        aw[i][j] / (aw[i][i] * aw[j][j]).sqrt()
    }));
    let diag = (0..n).fold(0.0_f64, |m, i| m.max(aw[i][i]));

    let p = Params::<f64>::new(chain);
    let d = alg.dynamics(&p, q, qd, &drives(tau));
    let f = ldlt(&d.mass_matrix);
    let x = solve(&f, &d.tau_minus_c);
    let (mut r2, mut b2) = (0.0, 0.0);
    for i in 0..n {
        let s = (0..n).fold(Wide::constant(d.tau_minus_c[i]), |s, j| {
            s - Wide::constant(d.mass_matrix[i][j]) * Wide::constant(x[j])
        });
        r2 += s.to_f64().powi(2);
        b2 += d.tau_minus_c[i].powi(2);
    }
    let x32 = alg.forward_dynamics(
        &Params::<f32>::new(chain),
        &consts::<f32>(q),
        &consts(qd),
        &drives(tau),
    );
    let xs = Methods::SPATIAL.forward_dynamics(&p, q, qd, &drives(tau));
    Measured {
        cond,
        cond_s,
        lambda_min,
        err_a: rel_err_mat(&d.mass_matrix, &aw),
        err_b: rel_err(&d.tau_minus_c, &to_f64_vec(&dw.tau_minus_c)),
        err_qdd: rel_err(&x, &xw),
        err_qdd_f32: rel_err(&to_f64_vec(&x32), &xw),
        residual: (r2 / b2).sqrt(),
        pivots_positive: f.d.iter().all(|&p| p > 0.0),
        min_pivot: f.d.iter().copied().fold(f64::INFINITY, f64::min) / diag,
        min_pivot_wide: fw.d.iter().map(Real::to_f64).fold(f64::INFINITY, f64::min) / diag,
        err_alg: rel_err(&xs, &x),
    }
}

/// Random joint angles in (−π, π), rates in (−qd, qd), drives in (−tau, tau).
fn random_state(n: usize, seed: u64, qd: f64, tau: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut r = rng(seed);
    (
        random_vec(&mut r, n, std::f64::consts::PI),
        random_vec(&mut r, n, qd),
        random_vec(&mut r, n, tau),
    )
}

fn print(label: &str, m: &Measured) {
    println!(
        "{label}: cond {:.2e} (scaled {:.2e}) λmin {:.2e} | A {:.2}ε b {:.2}ε q̈ {:.2e} = {:.3}·cond·ε \
         | f32 q̈ {:.2e} = {:.3}·cond·ε32 | res {:.2e} | min pivot f64/Wide {:.2e}/{:.2e} | recurrent vs spatial {:.2e}",
        m.cond,
        m.cond_s,
        m.lambda_min,
        m.err_a / EPS,
        m.err_b / EPS,
        m.err_qdd,
        m.k64(),
        m.err_qdd_f32,
        m.k32(),
        m.residual,
        m.min_pivot,
        m.min_pivot_wide,
        m.err_alg,
    );
}

fn max_of(ms: &[Measured], f: impl Fn(&Measured) -> f64) -> f64 {
    ms.iter().map(f).fold(0.0, f64::max)
}

/// A is SPD, by three checks: the reference's smallest eigenvalue is positive, and all LDLᵀ
/// pivots are positive in `Wide` and in `f64`. The f64 forward dynamics is within `C64·cond·ε`.
fn assert_spd_and_bounded(label: &str, m: &Measured) {
    assert!(m.lambda_min > 0.0, "{label}: λmin = {:e}", m.lambda_min);
    assert!(
        m.min_pivot_wide > 0.0 && m.pivots_positive,
        "{label}: LDLᵀ pivot not positive (Wide {:e}, f64 {:e})",
        m.min_pivot_wide,
        m.min_pivot
    );
    assert!(
        m.err_qdd <= C64 * m.cond * EPS,
        "{label}: f64 q̈ error {:e} > {C64}·cond·ε = {:e}",
        m.err_qdd,
        C64 * m.cond * EPS
    );
    // The two algorithms differ by their own rounding, each within cond·ε of the reference.
    assert!(
        m.err_alg <= 2.0 * C64 * m.cond * EPS,
        "{label}: recurrent vs spatial {:e}",
        m.err_alg
    );
}

/// Case 1: SSRMS holding a 116 t payload (`scenes/ssrms_payload_fixed.toml`), 16 random states,
/// q̇ in ±0.05 rad/s, τ in ±2000 N·m.
///
/// Measured: cond 7.1e2 … 3.0e5. f64 q̈ error ≤ 4.6e-12 = 0.114·cond·ε, so the bound
/// `C64 = 1` has an 8.8× margin. f32 q̈ error ≤ 3.9e-3 = 0.31·cond·ε₃₂ (bound `C32 = 1`,
/// 3.2×). So f32 stays inside its cond bound, but it loses 2–3 digits near ill-conditioned
/// poses. Without the payload, the f64 error is ≤ 9.2e-16.
#[test]
fn case1_ssrms_with_116t_payload() {
    let bare = ssrms();
    let chain = ssrms_payload();
    let n = chain.dof();
    // The scene merged the payload into the last body (parallel-axis theorem).
    let (b0, b1) = (
        &bare.joints()[n - 1].inertial,
        &chain.joints()[n - 1].inertial,
    );
    assert!((b1.mass - (b0.mass + 116_000.0)).abs() < 1e-9);
    let com_x = (b0.mass * b0.com[0] + 116_000.0 * 1.5) / b1.mass;
    assert!((b1.com[0] - com_x).abs() < 1e-12, "{:?}", b1.com);
    println!(
        "last body: bare m {} com {:?}; with payload m {} com {:?} I diag {:?}",
        b0.mass,
        b0.com,
        b1.mass,
        b1.com,
        [0, 1, 2].map(|i| b1.inertia[i][i])
    );

    let ms: Vec<Measured> = (0..16)
        .map(|s| {
            let (q, qd, tau) = random_state(n, 100 + s, 0.05, 2000.0);
            let m = measure(&chain, &q, &qd, &tau);
            print(&format!("ssrms+payload s{s}"), &m);
            m
        })
        .collect();
    let mut conds: Vec<f64> = ms.iter().map(|m| m.cond).collect();
    conds.sort_by(f64::total_cmp);
    println!(
        "SSRMS+payload: cond min/median/max {:.2e}/{:.2e}/{:.2e}; f64 q̈ max {:.2e}, max {:.3}·cond·ε; \
         f32 q̈ max {:.2e}, max {:.3}·cond·ε32",
        conds[0],
        conds[conds.len() / 2],
        conds[conds.len() - 1],
        max_of(&ms, |m| m.err_qdd),
        max_of(&ms, Measured::k64),
        max_of(&ms, |m| m.err_qdd_f32),
        max_of(&ms, Measured::k32),
    );
    for (s, m) in ms.iter().enumerate() {
        let label = format!("ssrms+payload s{s}");
        assert_spd_and_bounded(&label, m);
        assert!(
            m.err_qdd_f32 <= C32 * m.cond * EPS32,
            "{label}: f32 q̈ error {:e} > {C32}·cond·ε32 = {:e}",
            m.err_qdd_f32,
            C32 * m.cond * EPS32
        );
    }
    for s in 0..4 {
        let (q, qd, tau) = random_state(n, 100 + s, 0.05, 2000.0);
        let m = measure(&bare, &q, &qd, &tau);
        print(&format!("ssrms (no payload) s{s}"), &m);
        assert_spd_and_bounded("ssrms", &m);
    }
}

/// Least-squares slope of `ln y` over `ln x`.
fn loglog_slope(x: &[f64], y: &[f64]) -> f64 {
    let (lx, ly): (Vec<f64>, Vec<f64>) = x.iter().zip(y).map(|(a, b)| (a.ln(), b.ln())).unzip();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = lx.iter().map(|a| (a - mx).powi(2)).sum();
    sxy / sxx
}

/// Case 2: random chains (`random_chain`, 10 kg, 1 m links), N = 8 … 128, five seeds per N,
/// q̇ in ±1 rad/s, τ in ±10. The worst of the five is taken at each N.
///
/// Measured, N = 8, 16, 32, 64, 128:
/// - A error 3.1, 7.0, 9.9, 9.6, 9.95 ε: log-log slope 0.38, A(128)/A(8) = 3.2.
/// - q̈ error 1.0e-14, 2.4e-14, 1.4e-13, 1.2e-12, 4.7e-12: slope 2.3.
/// - cond 1.9e3, 8.4e3, 8.6e4, 3.2e5, 5.3e6: slope 2.8.
/// - q̈ in units of cond·ε: 0.060, 0.045, 0.051, 0.016, 0.014.
/// - Residual ≤ 3.7e-15 = 2.1·Nε.
/// - Smallest LDLᵀ pivot 3.1e-6 of max diag A (N = 128), positive.
///
/// So the q̈ error grows no faster than cond(A), and A's own error grows sub-linearly in N.
/// Bounds: A slope ≤ 1 and A(128)/A(8) ≤ 16, q̈(128)/q̈(8) ≤ 16³ = 4096 (measured 455, 9×),
/// q̈ ≤ 0.25·cond·ε at every N (4.2×), residual ≤ 10·Nε (4.7×), every pivot positive.
#[test]
fn case2_random_chains_growth() {
    let sizes = [8usize, 16, 32, 64, 128];
    let mut worst_a = Vec::new();
    let mut worst_q = Vec::new();
    let mut worst_cond = Vec::new();
    for &n in &sizes {
        let ms: Vec<Measured> = (0..5u64)
            .map(|seed| {
                let chain = random_chain(
                    &ChainSpec {
                        n,
                        ..Default::default()
                    },
                    1000 + seed,
                );
                let (q, qd, tau) = random_state(n, 2000 + seed, 1.0, 10.0);
                let m = measure(&chain, &q, &qd, &tau);
                print(&format!("random N={n} s{seed}"), &m);
                m
            })
            .collect();
        let res = max_of(&ms, |m| m.residual);
        println!(
            "N = {n}: worst A {:.2}ε, q̈ {:.2e}, cond {:.2e}, q̈ {:.3}·cond·ε, residual {:.2e} = {:.2}·Nε, \
             smallest pivot {:.2e}, f32 q̈ {:.2e}",
            max_of(&ms, |m| m.err_a / EPS),
            max_of(&ms, |m| m.err_qdd),
            max_of(&ms, |m| m.cond),
            max_of(&ms, Measured::k64),
            res,
            res / (n as f64 * EPS),
            ms.iter().map(|m| m.min_pivot).fold(f64::INFINITY, f64::min),
            max_of(&ms, |m| m.err_qdd_f32),
        );
        for (s, m) in ms.iter().enumerate() {
            let label = format!("random N={n} s{s}");
            assert_spd_and_bounded(&label, m);
            assert!(m.k64() <= 0.25, "{label}: q̈ {:.3}·cond·ε", m.k64());
            assert!(
                m.residual <= 10.0 * n as f64 * EPS,
                "{label}: residual {:e} > 10·Nε",
                m.residual
            );
        }
        worst_a.push(max_of(&ms, |m| m.err_a));
        worst_q.push(max_of(&ms, |m| m.err_qdd));
        worst_cond.push(max_of(&ms, |m| m.cond));
    }
    let ns: Vec<f64> = sizes.iter().map(|&n| n as f64).collect();
    let (pa, pq, pc) = (
        loglog_slope(&ns, &worst_a),
        loglog_slope(&ns, &worst_q),
        loglog_slope(&ns, &worst_cond),
    );
    let last = sizes.len() - 1;
    let (ra, rq) = (worst_a[last] / worst_a[0], worst_q[last] / worst_q[0]);
    println!(
        "growth N = 8 → 128: A error slope {pa:.2} (ratio {ra:.2}), q̈ error slope {pq:.2} (ratio {rq:.1}), \
         cond slope {pc:.2}"
    );
    assert!(pa <= 1.0, "A error grows like N^{pa:.2}");
    assert!(ra <= 16.0, "A error ratio {ra}");
    assert!(rq <= 4096.0, "q̈ error ratio {rq}");
}

/// The inertial `i` with mass `mass`, inertia scaled along. The centre of mass stays, so the
/// body stays physical.
fn scaled(mut i: Inertial, mass: f64) -> Inertial {
    let k = mass / i.mass;
    i.mass = mass;
    i.inertia = i.inertia.map(|r| r.map(|x| x * k));
    i
}

fn with_masses(chain: &Model, masses: &[f64]) -> Model {
    let joints = chain
        .joints()
        .iter()
        .zip(masses)
        .map(|(j, &m)| Joint {
            inertial: scaled(j.inertial.clone(), m),
            ..j.clone()
        })
        .collect();
    Model::new("mass_ratio", "base", None, joints).unwrap()
}

/// Case 3: mass ratio 1e8. Random 8-link geometry (6 seeds), either alternating 1e5 / 1e-3 kg,
/// or seven 1e-3 kg links holding a 1e5 kg tip.
///
/// Measured:
/// - Alternating: cond 2.3e9 … 1.4e10, yet q̈ error ≤ 2.0e-15. Its cond_s is only 25 … 143: the
///   ill-conditioning is a diagonal scaling that LDLᵀ does not feel.
/// - Heavy tip: cond 9.1e8 … 2.5e9 and cond_s 2.9e8 … 1.8e9, so the ill-conditioning is real.
///   q̈ error ≤ 6.3e-8, at most 0.21·cond·ε and 0.34·cond_s·ε.
/// - f32: relative q̈ error 0.89 … 1.17 on the heavy tip. f32 fails, and the test asserts that
///   (> 0.1).
///
/// Bounds: f64 ≤ cond·ε (4.8×) and ≤ cond_s·ε (2.9×).
#[test]
fn case3_mass_ratio() {
    let n = 8;
    for seed in 0..6u64 {
        let base = random_chain(
            &ChainSpec {
                n,
                ..Default::default()
            },
            3000 + seed,
        );
        let alternating: Vec<f64> = (0..n)
            .map(|j| if j % 2 == 0 { 1e5 } else { 1e-3 })
            .collect();
        let heavy_tip: Vec<f64> = (0..n)
            .map(|j| if j == n - 1 { 1e5 } else { 1e-3 })
            .collect();
        let (q, qd, tau) = random_state(n, 4000 + seed, 1.0, 10.0);
        for (name, masses) in [("alternating", &alternating), ("heavy tip", &heavy_tip)] {
            let label = format!("{name} s{seed}");
            let m = measure(&with_masses(&base, masses), &q, &qd, &tau);
            print(&label, &m);
            assert!(m.cond > 1e8, "{label}: not a hard case, cond {:e}", m.cond);
            assert_spd_and_bounded(&label, &m);
            assert!(
                m.err_qdd <= m.cond_s * EPS,
                "{label}: q̈ {:e} > cond_s·ε = {:e}",
                m.err_qdd,
                m.cond_s * EPS
            );
            if name == "heavy tip" {
                assert!(
                    m.err_qdd_f32 > 0.1,
                    "{label}: f32 expected to fail, error {:e}",
                    m.err_qdd_f32
                );
            }
        }
    }
}

/// Pairs of revolute joints `(2k, 2k+1)`. Joint `2k+1` sits at `at` in body `2k`, with its axis
/// `theta` rad from joint `2k`'s. Every axis is `z` of its joint frame, so the angle between two
/// paired axes and the distance between them are the same at every `q`. Between pairs the
/// placements are random. Body `2k`, the one between the paired axes, has mass `inner_mass`,
/// with its random inertia scaled along.
fn pair_chain(pairs: usize, theta: f64, at: [f64; 3], inner_mass: f64, seed: u64) -> Model {
    let mut r = rng(seed);
    let joints = (0..2 * pairs)
        .map(|k| {
            let origin = if k % 2 == 1 {
                Placement {
                    translation: at,
                    rotation: rpy_to_matrix([0.0, theta, 0.0]),
                }
            } else {
                Placement {
                    translation: [0, 1, 2].map(|_| random_vec(&mut r, 1, 1.0)[0]),
                    rotation: random_rotation(&mut r),
                }
            };
            let inertial = random_inertial(&mut r, 10.0, 1.0);
            Joint {
                name: format!("j{k}"),
                kind: JointKind::Revolute,
                parent: k.checked_sub(1),
                origin,
                axis: [0.0, 0.0, 1.0],
                body: format!("b{k}"),
                inertial: if k % 2 == 0 {
                    scaled(inertial, inner_mass)
                } else {
                    inertial
                },
            }
        })
        .collect();
    Model::new("pairs", "base", None, joints).unwrap()
}

/// Case 4: degenerate joint geometry. 6-dof chains (three pairs, 4 seeds) whose paired axes are
/// (a) 1e-6 rad from parallel and 1 m apart; (b) perpendicular and 1e-9 m from intersecting;
/// (c) both 1e-6 rad from parallel and 1e-9 m apart, i.e. nearly the same line.
///
/// Measured:
/// - (a)–(c): cond ≤ 440 and q̈ error ≤ 3e-15. Degenerate axes alone do not make `A`
///   ill-conditioned. Two joints on nearly the same line still move the body between them
///   differently, and `A` is a mass matrix, not a Jacobian.
/// - (c) with a light body between the two axes, 1e-3 kg: cond 3.2e5 … 1.1e6, q̈ error ≤ 3.7e-11
///   (0.225·cond·ε, the worst of all cases).
/// - (c) with 1e-6 kg between: cond 3.2e8 … 1.1e9, q̈ error ≤ 1.5e-8 (0.091·cond·ε). f32 fails:
///   errors 0.17 … 0.87, and one state non-finite. A stays SPD in f64: every pivot is positive,
///   the smallest 3.8e-9 of the largest diagonal entry.
///
/// Bounds: (a)–(c) cond ≤ 5e3 (11×); SPD (f64 and Wide pivots); f64 ≤ cond·ε (4.4×).
#[test]
fn case4_near_parallel_and_near_intersecting_axes() {
    let half_pi = std::f64::consts::FRAC_PI_2;
    let cases = [
        (
            "near-parallel 1e-6 rad, 1 m apart",
            1e-6,
            [1.0, 0.3, 0.2],
            10.0,
            true,
        ),
        (
            "near-intersecting, 1e-9 m",
            half_pi,
            [0.0, 1e-9, 0.5],
            10.0,
            true,
        ),
        (
            "near-coincident 1e-6 rad + 1e-9 m",
            1e-6,
            [0.0, 1e-9, 0.5],
            10.0,
            true,
        ),
        (
            "near-coincident, 1e-3 kg between",
            1e-6,
            [0.0, 1e-9, 0.5],
            1e-3,
            false,
        ),
        (
            "near-coincident, 1e-6 kg between",
            1e-6,
            [0.0, 1e-9, 0.5],
            1e-6,
            false,
        ),
    ];
    for (name, theta, at, inner, geometric) in cases {
        let ms: Vec<Measured> = (0..4u64)
            .map(|seed| {
                let c = pair_chain(3, theta, at, inner, 5000 + seed);
                let (q, qd, tau) = random_state(6, 6000 + seed, 1.0, 10.0);
                let m = measure(&c, &q, &qd, &tau);
                let label = format!("{name} s{seed}");
                print(&label, &m);
                assert_spd_and_bounded(&label, &m);
                if geometric {
                    assert!(m.cond <= 5e3, "{label}: cond {:e}", m.cond);
                }
                m
            })
            .collect();
        println!(
            "{name}: worst cond {:.2e}, q̈ {:.2e} = {:.3}·cond·ε, f32 q̈ {:.2e}",
            max_of(&ms, |m| m.cond),
            max_of(&ms, |m| m.err_qdd),
            max_of(&ms, Measured::k64),
            max_of(&ms, |m| m.err_qdd_f32),
        );
    }
}

/// Case 5: joint rates ±10 rad/s (random signs), τ = 0, so `b = −h` is all velocity products,
/// |b| up to 7e9. Models: SSRMS, SSRMS + payload and a random 16-link chain, 6 states each.
///
/// Measured:
/// - f64 `b` error: recurrent ≤ 6.4ε, spatial ≤ 9.4ε; the two f64 results differ by ≤ 11.2ε.
///   Bound: 32ε (3.4×).
/// - f32 `b` error ≤ 8e-7 (6.7 ε₃₂).
/// - q̈ error ≤ 0.123·cond·ε.
/// - `recurrent` against `spatial`, both in `Wide`: ≤ 7.9e-32 on the SSRMS models (bound 1e-30),
///   so two independent algorithms agree to double-double. On the random chain they differ by
///   ≤ 1.5e-15 (bound 30ε = 6.7e-15). That is not rounding: random rotations and axes are
///   orthonormal only to ~ε in f64, and the algorithms use the model numbers differently.
#[test]
fn case5_fast_joints() {
    let random16 = random_chain(
        &ChainSpec {
            n: 16,
            ..Default::default()
        },
        7000,
    );
    for (name, chain, exact_model) in [
        ("ssrms", &ssrms(), true),
        ("ssrms+payload", &ssrms_payload(), true),
        ("random16", &random16, false),
    ] {
        let n = chain.dof();
        let (p, pw, p32) = (
            Params::<f64>::new(chain),
            Params::<Wide>::new(chain),
            Params::<f32>::new(chain),
        );
        let mut worst = [0.0_f64; 5];
        for seed in 0..6u64 {
            let mut r = rng(8000 + seed);
            let q = random_vec(&mut r, n, std::f64::consts::PI);
            let qd: Vec<f64> = random_vec(&mut r, n, 1.0)
                .iter()
                .map(|x| 10.0 * x.signum())
                .collect();
            let tau = vec![0.0; n];
            let label = format!("{name} 10 rad/s s{seed}");
            let m = measure(chain, &q, &qd, &tau);
            print(&label, &m);
            assert_spd_and_bounded(&label, &m);

            let (qw, qdw) = (consts::<Wide>(&q), consts::<Wide>(&qd));
            let bwr =
                Methods::RECURRENT
                    .nonlinear_effects
                    .tau_minus_c(&pw, &qw, &qdw, &drives(&tau));
            let bws = Methods::SPATIAL
                .nonlinear_effects
                .tau_minus_c(&pw, &qw, &qdw, &drives(&tau));
            let reference = to_f64_vec(&bwr);
            let br = Methods::RECURRENT
                .nonlinear_effects
                .tau_minus_c(&p, &q, &qd, &drives(&tau));
            let bs = Methods::SPATIAL
                .nonlinear_effects
                .tau_minus_c(&p, &q, &qd, &drives(&tau));
            let b32 = Methods::RECURRENT.nonlinear_effects.tau_minus_c(
                &p32,
                &consts::<f32>(&q),
                &consts::<f32>(&qd),
                &drives(&tau),
            );
            let e = [
                rel_err(&br, &reference) / EPS,
                rel_err(&bs, &to_f64_vec(&bws)) / EPS,
                rel_err(&br, &bs) / EPS,
                rel_err_wide(&bws, &bwr),
                rel_err(&to_f64_vec(&b32), &reference),
            ];
            println!(
                "   max|b| {:.2e}: b recurrent {:.2}ε, spatial {:.2}ε, recurrent vs spatial {:.2}ε; \
                 Wide recurrent vs spatial {:.2e}; f32 b {:.2e}",
                reference.iter().fold(0.0_f64, |m, x| m.max(x.abs())),
                e[0],
                e[1],
                e[2],
                e[3],
                e[4]
            );
            assert!(e[0] <= 32.0 && e[1] <= 32.0, "{label}: b error {e:?}");
            assert!(e[2] <= 64.0, "{label}: recurrent vs spatial {}ε", e[2]);
            let wide_bound = if exact_model { 1e-30 } else { 30.0 * EPS };
            assert!(
                e[3] <= wide_bound,
                "{label}: Wide recurrent vs spatial {:e}",
                e[3]
            );
            for (w, x) in worst.iter_mut().zip(e) {
                *w = w.max(x);
            }
        }
        println!(
            "{name}: worst b recurrent {:.2}ε, spatial {:.2}ε, recurrent vs spatial {:.2}ε, Wide agreement {:.2e}, f32 b {:.2e}",
            worst[0], worst[1], worst[2], worst[3], worst[4]
        );
    }
}

/// Conservation monitors of one run.
struct Drift {
    /// max |E − E₀| / E₀.
    energy: f64,
    /// max |P − P₀| / |P₀| (linear momentum, inertial frame).
    linear: f64,
    /// max |L − L₀| / |L₀| (angular momentum about the inertial origin).
    angular: f64,
    /// max ||quat| − 1|.
    quat: f64,
}

/// `steps` steps of `h`, with the integrator loop of `tests/integrators.rs`. The quaternion
/// norm is checked after every step, energy and momentum after every 10th.
fn run_floating(scene: &Scene, implicit: bool, h: f64, steps: usize) -> Drift {
    let mut sys = SceneSystem::new(scene);
    let mon = SceneSystem::new(scene);
    let mut x = sys.initial_state();
    let e0 = mon.energy(&x).expect("energy is conserved");
    let (l0, a0) = mon.momentum(&x).expect("momentum is conserved");
    let norm = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let mut de = Vec::with_capacity(steps / 10 + 1);
    let (mut dl, mut da, mut dq) = (0.0_f64, 0.0_f64, 0.0_f64);
    let t = Instant::now();
    let obs = |k: usize, _t: f64, x: &[f64]| {
        let qn = x[3..7].iter().map(|v| v * v).sum::<f64>().sqrt();
        dq = dq.max((qn - 1.0).abs());
        // Energy and momentum every 10th step (steps 0, 10, 20, …).
        if k != 10 * (k / 10) {
            return;
        }
        de.push((mon.energy(x).unwrap() - e0).abs() / e0.abs());
        let (l, a) = mon.momentum(x).unwrap();
        dl = dl.max(norm([0, 1, 2].map(|i| l[i] - l0[i])) / norm(l0));
        da = da.max(norm([0, 1, 2].map(|i| a[i] - a0[i])) / norm(a0));
    };
    let t1 = h * steps as f64;
    let stats = if implicit {
        midpoint(&mut sys, 0.0, t1, h, &mut x, obs).unwrap()
    } else {
        rk4(&mut sys, 0.0, t1, h, &mut x, obs).unwrap()
    };
    assert_eq!(stats.steps, steps);
    let quarter = de.len() / 4;
    let mx = |s: &[f64]| s.iter().fold(0.0_f64, |m, v| m.max(*v));
    let d = Drift {
        energy: mx(&de),
        linear: dl,
        angular: da,
        quat: dq,
    };
    println!(
        "{}: h {h}, {steps} steps, {} evaluations, E0 {e0:.4} J, |P0| {:.3}, |L0| {:.3}: \
         max ΔE/E0 {:.3e} (first/last quarter {:.3e} / {:.3e}), ΔP/|P0| {:.3e}, ΔL/|L0| {:.3e}, \
         ||quat| − 1| {:.2e}; wall {:.2} s",
        if implicit { "midpoint" } else { "rk4" },
        stats.evals,
        norm(l0),
        norm(a0),
        d.energy,
        mx(&de[..quarter]),
        mx(&de[de.len() - quarter..]),
        d.linear,
        d.angular,
        d.quat,
        t.elapsed().as_secs_f64()
    );
    d
}

/// Case 6: 1e5 steps of h = 0.01 s (1000 s) of the passive free-floating 7-dof arm
/// `tests/data/hard/free_floating_7dof_passive.toml` (τ = 0, no gravity, no wrenches; the base
/// and the joints start moving).
///
/// Measured, as relative drifts:
///
/// | | ΔE/E₀ | ΔP/P₀ | ΔL/L₀ | ‖q‖−1 | bound for each |
/// |---|---|---|---|---|---|
/// | midpoint | 3.9e-6 | 2.0e-6 | 2.0e-5 | 1.8e-14, no projection | 2e-5, 1e-5, 1e-4, 1e-13 |
/// | RK4 | 5.3e-10 | 5.2e-10 | 7.3e-9 | 2.2e-16, projected | 3e-9, 3e-9, 4e-8, 4ε |
///
/// The margins are about 5×. Neither method conserves energy or momentum exactly in these
/// quasi-velocity coordinates. The midpoint energy error grows here (first/last quarter 9.1e-7
/// / 3.2e-6): its boundedness is a result for near-integrable motions.
#[test]
fn case6_long_free_floating_run() {
    let scene = Scene::load(&root().join("tests/data/hard/free_floating_7dof_passive.toml"))
        .unwrap_or_else(|e| panic!("{e:#}"));
    let (h, steps) = (scene.simulation.step, 100_000);
    assert!((h * steps as f64 - scene.simulation.duration).abs() < 1e-9);
    let mid = run_floating(&scene, true, h, steps);
    assert!(mid.energy <= 2e-5, "midpoint ΔE/E0 {:e}", mid.energy);
    assert!(mid.linear <= 1e-5, "midpoint ΔP/P0 {:e}", mid.linear);
    assert!(mid.angular <= 1e-4, "midpoint ΔL/L0 {:e}", mid.angular);
    assert!(mid.quat <= 1e-13, "midpoint ||quat| − 1| {:e}", mid.quat);
    let rk = run_floating(&scene, false, h, steps);
    assert!(rk.energy <= 3e-9, "rk4 ΔE/E0 {:e}", rk.energy);
    assert!(rk.linear <= 3e-9, "rk4 ΔP/P0 {:e}", rk.linear);
    assert!(rk.angular <= 4e-8, "rk4 ΔL/L0 {:e}", rk.angular);
    assert!(rk.quat <= 4.0 * EPS, "rk4 ||quat| − 1| {:e}", rk.quat);
}
