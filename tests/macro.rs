//! `kanegen::dynamics!` on random-geometry models (prismatic joints, gravity, a runtime payload):
//! the emitted functions equal the interpreted f64 algorithms. The precision variants of the
//! SSRMS code (`scalar = f32`, `fma = true`) agree with the checked-in f64 code to their
//! precision. Types named `f64`, `Option`, `Some`, … (and a module that defines every such
//! name) compile and compute what a plainly named type of the same options does.

use kanegen::dynamics::metrics::rel_err;
use kanegen::dynamics::Params;
use kanegen::dynamics::{Loads, Methods};
use kanegen::model::random::{random_vec, rng};
use kanegen::model::{Inertial, Model};
use std::path::Path;

mod common;

kanegen::dynamics!(Random3, "tests/data/codegen/random3_prismatic.toml");
kanegen::dynamics!(Random5, "tests/data/codegen/random5.toml");
kanegen::dynamics!(
    Random5OwnFrames,
    "tests/data/codegen/random5.toml",
    canonical = false
);
// xArm7 writes `rpy = 1.5708` for π/2: every placement 3.7e-6 off a signed permutation.
kanegen::dynamics!(XArm7, "tests/data/erd/xarm7.urdf");
kanegen::dynamics!(
    Random5Libm,
    "tests/data/codegen/random5.toml",
    libm_trig = true
);
kanegen::dynamics!(
    Random5Gravity,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    runtime_payload = true,
);

// Joint and frame names with U+202E, U+2066/7 and BEL: the expansion compiles (rustc denies
// bidirectional code points in literals and comments), the names kept, escaped.
kanegen::dynamics!(Bidi, "tests/data/reliability/bidi_names.toml");

#[test]
fn bidirectional_names_compile_and_are_kept() {
    assert_eq!(Bidi::JOINTS[0], "shoulder\u{202E}\u{2066}evil\u{7}");
    assert_eq!(Bidi::FRAMES[0], "tool\u{202E}\u{2067}");
    let m = Bidi::mass_matrix(&[0.1, 0.2]);
    assert!(m[0][0] > 0.0 && m[1][1] > 0.0);
}

const G: [f64; 3] = [0.3, -1.2, -9.81];

fn load(rel: &str) -> Model {
    kanegen::model::io::load_model(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

fn flat<const N: usize>(a: [[f64; N]; N]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

fn flat_v(a: Vec<Vec<f64>>) -> Vec<f64> {
    a.into_iter().flatten().collect()
}

/// Random `(q, qd, tau, qdd)`.
fn state<const N: usize>(seed: u64) -> [[f64; N]; 4] {
    let mut r = rng(seed);
    let mut v = |s| -> [f64; N] { random_vec(&mut r, N, s).try_into().unwrap() };
    [v(2.0), v(1.0), v(20.0), v(1.0)]
}

macro_rules! check_constant_model {
    ($t:ident, $n:literal, $file:literal) => {{
        let chain = load($file);
        let p = Params::<f64>::new(&chain);
        assert_eq!($t::N, $n);
        assert_eq!($t::JOINTS.len(), chain.dof());
        for seed in 0..20 {
            let [q, qd, tau, qdd] = state::<$n>(seed);
            let loads = Loads {
                tau: Some(tau.to_vec()),
                ..Loads::default()
            };
            for alg in Methods::ALL {
                let m = flat($t::mass_matrix(&q));
                let e = rel_err(&m, &flat_v(alg.mass_matrix.mass_matrix(&p, &q)));
                assert!(e < 1e-12, "{}: M vs {alg}: {e:e}", $file);
                // c = −b(τ = 0): the field's sign.
                let c: Vec<f64> = alg
                    .nonlinear_effects
                    .tau_minus_c(&p, &q, &qd, &Loads::default())
                    .iter()
                    .map(|b| -b)
                    .collect();
                let e = rel_err(&$t::nonlinear_effects(&q, &qd), &c);
                assert!(e < 1e-12, "{}: c vs {alg}: {e:e}", $file);
                let (m2, c2) = $t::mass_matrix_and_nonlinear_effects(&q, &qd);
                assert!(rel_err(&flat(m2), &m) < 1e-15, "{}: (M, c).0", $file);
                assert!(rel_err(&c2, &c) < 1e-12, "{}: (M, c).1", $file);
                let id = alg.inverse_dynamics(&p, &q, &qd, &qdd, &loads);
                let e = rel_err(&$t::inverse_dynamics(&q, &qd, &qdd), &id);
                assert!(e < 1e-11, "{}: ID vs {alg}: {e:e}", $file);
                let fd = alg.forward_dynamics(&p, &q, &qd, &loads);
                let e = rel_err(&$t::forward_dynamics(&q, &qd, &tau), &fd);
                assert!(e < 1e-10, "{}: FD vs {alg}: {e:e}", $file);
            }
        }
    }};
}

#[test]
fn random_models_through_the_macro_equal_interpreted() {
    check_constant_model!(Random3, 3, "tests/data/codegen/random3_prismatic.toml");
    check_constant_model!(Random5, 5, "tests/data/codegen/random5.toml");
    // One OP_COUNTS entry per generated function, each the cheapest of its candidates.
    let names: Vec<&str> = Random5::OP_COUNTS.iter().map(|c| c.function).collect();
    assert_eq!(
        names,
        [
            "mass_matrix",
            "nonlinear_effects",
            "inverse_dynamics",
            "forward_dynamics",
            "mass_matrix_and_nonlinear_effects",
            "forward_dynamics_with_wrenches",
            "inverse_dynamics_derivatives",
            "forward_dynamics_derivatives",
            "mass_matrix_inverse"
        ]
    );
    for chosen in Random5::OP_COUNTS {
        let candidates: Vec<_> = Random5::CANDIDATES
            .iter()
            .filter(|c| c.function == chosen.function)
            .collect();
        // The derivatives have one method, traced in the model's and the canonical frames.
        let derivative =
            chosen.function.contains("derivatives") || chosen.function.ends_with("inverse");
        assert!(
            candidates.len() >= if derivative { 2 } else { 3 },
            "{}",
            chosen.function
        );
        let best = candidates.iter().map(|c| c.mul + c.add).min().unwrap();
        assert_eq!(chosen.mul + chosen.add, best, "{}", chosen.function);
        assert!(candidates
            .iter()
            .any(|c| c.mass_matrix_method == chosen.mass_matrix_method
                && c.nonlinear_effects_method == chosen.nonlinear_effects_method));
    }
}

/// `canonical = false` traces in the model's own frames only: every candidate says so, the
/// default's joint-space functions are canonical and cheaper, and both give the same `(M, c)`.
#[test]
fn canonical_frames_can_be_turned_off() {
    assert!(Random5OwnFrames::CANDIDATES
        .iter()
        .all(|c| c.frames == "model"));
    let canonical = |f: &str| Random5::OP_COUNTS.iter().find(|c| c.function == f).unwrap();
    let own = |f: &str| {
        Random5OwnFrames::OP_COUNTS
            .iter()
            .find(|c| c.function == f)
            .unwrap()
    };
    for f in ["mass_matrix", "mass_matrix_and_nonlinear_effects"] {
        assert_eq!(canonical(f).frames, "canonical", "{f}");
        assert!(
            canonical(f).mul + canonical(f).add < own(f).mul + own(f).add,
            "{f}"
        );
    }
    let q = [0.3, -1.1, 0.7, 2.0, -0.4];
    let v = [0.5, 0.1, -0.9, 0.2, 1.3];
    let (m1, c1) = Random5::mass_matrix_and_nonlinear_effects(&q, &v);
    let (m2, c2) = Random5OwnFrames::mass_matrix_and_nonlinear_effects(&q, &v);
    let a: Vec<f64> = m1.iter().flatten().chain(&c1).copied().collect();
    let b: Vec<f64> = m2.iter().flatten().chain(&c2).copied().collect();
    assert!(rel_err(&a, &b) < 1e-13);
}

/// The chain with its last body's mass properties replaced.
fn with_payload(chain: &Model, p: &Random5GravityPayload) -> Model {
    let mut joints = chain.joints().to_vec();
    joints.last_mut().unwrap().inertial = Inertial {
        mass: p.mass,
        com: p.com,
        inertia: p.inertia,
    };
    Model::new(
        chain.name(),
        chain.base(),
        chain.base_inertial().cloned(),
        joints,
    )
    .unwrap()
}

#[test]
fn runtime_payload_and_gravity_equal_interpreted_with_modified_chain() {
    let chain = load("tests/data/codegen/random5.toml");
    let nominal = Random5GravityPayload::NOMINAL;
    assert_eq!(nominal.mass, chain.joints()[4].inertial.mass);
    let heavy = Random5GravityPayload {
        mass: 42.0,
        com: [0.3, -0.2, 0.5],
        inertia: [[2.0, 0.1, -0.2], [0.1, 1.5, 0.05], [-0.2, 0.05, 1.8]],
    };
    for payload in [nominal, heavy] {
        let modified = with_payload(&chain, &payload);
        let p = Params::<f64>::new(&modified);
        let g = Some(kanegen::dynamics::linalg::Vec3(G));
        for seed in 0..10 {
            let [q, qd, tau, qdd] = state::<5>(100 + seed);
            let loads = Loads {
                tau: Some(tau.to_vec()),
                gravity: g.clone(),
                external: Vec::new(),
            };
            let alg = Methods::RECURRENT;
            let e = rel_err(
                &flat(Random5Gravity::mass_matrix(&q, &payload)),
                &flat_v(alg.mass_matrix.mass_matrix(&p, &q)),
            );
            assert!(e < 1e-12, "A: {e:e}");
            // c = −b(τ = 0) with gravity; g = c(q̇ = 0).
            let grav = Loads {
                gravity: g.clone(),
                ..Loads::default()
            };
            let neg = |v: Vec<f64>| -> Vec<f64> { v.iter().map(|x| -x).collect() };
            let e = rel_err(
                &Random5Gravity::nonlinear_effects(&q, &qd, &payload),
                &neg(alg.nonlinear_effects.tau_minus_c(&p, &q, &qd, &grav)),
            );
            assert!(e < 1e-12, "c: {e:e}");
            let e = rel_err(
                &Random5Gravity::gravity(&q, &payload),
                &neg(alg.nonlinear_effects.tau_minus_c(&p, &q, &[0.0; 5], &grav)),
            );
            assert!(e < 1e-12, "gravity: {e:e}");
            let e = rel_err(
                &Random5Gravity::inverse_dynamics(&q, &qd, &qdd, &payload),
                &alg.inverse_dynamics(&p, &q, &qd, &qdd, &loads),
            );
            assert!(e < 1e-11, "ID: {e:e}");
            let e = rel_err(
                &Random5Gravity::forward_dynamics(&q, &qd, &tau, &payload),
                &alg.forward_dynamics(&p, &q, &qd, &loads),
            );
            assert!(e < 1e-10, "FD: {e:e}");
        }
    }
    // The payload matters: a heavier payload changes A.
    let q = [0.1, 0.2, 0.3, 0.1, 0.5];
    assert_ne!(
        Random5Gravity::mass_matrix(&q, &nominal),
        Random5Gravity::mass_matrix(&q, &heavy)
    );
}

// ---------------------------------------------------------------------------------------------
// Precision variants of the SSRMS code: `scalar = f32`, `fma = true`.

kanegen::dynamics!(
    SsrmsF64,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    scalar = f64,
);
kanegen::dynamics!(
    SsrmsF32,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    scalar = f32,
);
kanegen::dynamics!(
    SsrmsFma,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    fma = true,
);
kanegen::dynamics!(
    SsrmsMulAdd,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    fma = true,
    fma_path = f64::mul_add,
);
kanegen::dynamics!(
    Random5F32Fma,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    runtime_payload = true,
    scalar = f32,
    fma = true,
);

use kanegen_generated::ssrms::Ssrms;

/// Random SSRMS states `(q, qd, tau, qdd)`, exactly representable in `f32` (so the `f32` code
/// and the `f64` reference see the same numbers and the error is the arithmetic's alone).
fn ssrms_states(count: u64) -> Vec<[[f64; 7]; 4]> {
    (0..count)
        .map(|seed| state::<7>(1000 + seed).map(|v| v.map(|x| f64::from(x as f32))))
        .collect()
}

fn to_f32<const N: usize>(x: &[f64; N]) -> [f32; N] {
    x.map(|v| v as f32)
}

fn widen(x: &[f32]) -> Vec<f64> {
    x.iter().map(|&v| f64::from(v)).collect()
}

/// `scalar = f32` agrees with the f64 code to f32 precision, and is clearly worse than it.
///
/// Measured over these 200 states (max of `rel_err`, the max-norm relative error): `A` 2.1e-7,
/// `b` 1.3e-6, `q̈` 5.3e-5 (the f32 unit roundoff is 6e-8; `q̈` loses the condition number of
/// `A` on top). The bounds are about 10× those: `A` 2e-6, `b` 1.5e-5, `q̈` 5e-4. The floor:
/// every state's `A` error is above 1e-9 (measured min 2.1e-8, 20× above it), where f64 code
/// gives ~1e-16 — the test fails if the f32 code silently computed in f64.
#[test]
fn f32_code_agrees_to_f32_precision() {
    let (mut ea, mut eb, mut efd, mut min_a) = (0.0_f64, 0.0_f64, 0.0_f64, f64::INFINITY);
    for [q, qd, tau, _] in ssrms_states(200) {
        let a: [[f32; 7]; 7] = SsrmsF32::mass_matrix(&to_f32(&q));
        let a = flat_v(a.iter().map(|r| widen(r)).collect());
        let e = rel_err(&a, &flat(Ssrms::mass_matrix(&q)));
        ea = ea.max(e);
        min_a = min_a.min(e);
        let c = SsrmsF32::nonlinear_effects(&to_f32(&q), &to_f32(&qd));
        eb = eb.max(rel_err(&widen(&c), &Ssrms::nonlinear_effects(&q, &qd)));
        let fd = SsrmsF32::forward_dynamics(&to_f32(&q), &to_f32(&qd), &to_f32(&tau));
        efd = efd.max(rel_err(
            &widen(&fd),
            &Ssrms::forward_dynamics(&q, &qd, &tau),
        ));
    }
    eprintln!("f32 vs f64: A {ea:.2e} (min {min_a:.2e}), c {eb:.2e}, q̈ {efd:.2e}");
    assert!(ea < 2e-6, "A: {ea:e}");
    assert!(eb < 1.5e-5, "c: {eb:e}");
    assert!(efd < 5e-4, "q̈: {efd:e}");
    assert!(min_a > 1e-9, "A is as accurate as f64: {min_a:e}");
}

/// `scalar = f64` is the default: bit for bit the checked-in code.
#[test]
fn explicit_f64_is_the_default() {
    for [q, qd, tau, qdd] in ssrms_states(20) {
        assert_eq!(SsrmsF64::mass_matrix(&q), Ssrms::mass_matrix(&q));
        assert_eq!(
            SsrmsF64::forward_dynamics(&q, &qd, &tau),
            Ssrms::forward_dynamics(&q, &qd, &tau)
        );
        assert_eq!(
            SsrmsF64::inverse_dynamics(&q, &qd, &qdd),
            Ssrms::inverse_dynamics(&q, &qd, &qdd)
        );
    }
}

/// `fma = true` agrees with the plain f64 code to rounding level, differs from it in the last
/// bits (the products are really fused), and `libm::fma` and `f64::mul_add` (both correctly
/// rounded) give the same bits.
///
/// Measured over these 200 states (max-norm relative): `A` 3.3e-16, `b` 3.2e-15, `τ` 1.4e-15,
/// `q̈` 1.4e-13 (`q̈` carries the condition number of `A`). Bounds about 10× those: 3e-14 for
/// `A`, `b`, `τ` and 1.5e-12 for `q̈`. Every one of the 200 `q̈` differs from the plain code's
/// in some bit (measured 200/200; required > 100).
#[test]
fn fma_code_agrees_with_plain_f64() {
    let (mut ea, mut eb, mut eid, mut efd) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    let mut differs = 0;
    for [q, qd, tau, qdd] in ssrms_states(200) {
        let a = SsrmsFma::mass_matrix(&q);
        assert_eq!(a, SsrmsMulAdd::mass_matrix(&q));
        ea = ea.max(rel_err(&flat(a), &flat(Ssrms::mass_matrix(&q))));
        let c = SsrmsFma::nonlinear_effects(&q, &qd);
        assert_eq!(c, SsrmsMulAdd::nonlinear_effects(&q, &qd));
        eb = eb.max(rel_err(&c, &Ssrms::nonlinear_effects(&q, &qd)));
        let id = SsrmsFma::inverse_dynamics(&q, &qd, &qdd);
        assert_eq!(id, SsrmsMulAdd::inverse_dynamics(&q, &qd, &qdd));
        eid = eid.max(rel_err(&id, &Ssrms::inverse_dynamics(&q, &qd, &qdd)));
        let fd = SsrmsFma::forward_dynamics(&q, &qd, &tau);
        assert_eq!(fd, SsrmsMulAdd::forward_dynamics(&q, &qd, &tau));
        let plain = Ssrms::forward_dynamics(&q, &qd, &tau);
        efd = efd.max(rel_err(&fd, &plain));
        differs += usize::from(fd != plain);
    }
    eprintln!(
        "fma vs plain: A {ea:.2e}, c {eb:.2e}, τ {eid:.2e}, q̈ {efd:.2e}; {differs}/200 differ"
    );
    assert!(ea < 3e-14, "A: {ea:e}");
    assert!(eb < 3e-14, "c: {eb:e}");
    assert!(eid < 3e-14, "τ: {eid:e}");
    assert!(efd < 1.5e-12, "q̈: {efd:e}");
    assert!(
        differs > 100,
        "fused code gives the plain code's bits: {differs}/200 differ"
    );
}

/// The `fma` counts in `OP_COUNTS` of the macro's code are those the generator's header states.
#[test]
fn fma_counts_match_the_header() {
    let chain = load("tests/data/reference/ssrms_nguyen_hughes_1994.urdf");
    let mut o = kanegen::codegen::Options::new("SsrmsFma");
    o.fma = true;
    let src = kanegen::codegen::generate_file(&chain, &o).unwrap();
    let total: u64 = SsrmsFma::OP_COUNTS.iter().map(|c| c.fma).sum();
    let per = SsrmsFma::OP_COUNTS
        .iter()
        .map(|c| format!("`{}` {}", c.function, c.fma))
        .collect::<Vec<_>>()
        .join(", ");
    let line = format!("//! Fused multiply-adds: {total} ({per}), ");
    assert!(src.contains(&line), "{line}");
    assert!(total > 0);
    let fmas = |c: &[SsrmsFmaOpCount]| c.iter().map(|c| c.fma).collect::<Vec<_>>();
    let fmas2 = |c: &[SsrmsMulAddOpCount]| c.iter().map(|c| c.fma).collect::<Vec<_>>();
    assert_eq!(fmas(&SsrmsFma::OP_COUNTS), fmas2(&SsrmsMulAdd::OP_COUNTS));
}

/// f32 with fma, gravity and a runtime payload (f32 fields) on a random model: the same
/// dynamics as the interpreted f64 algorithm, to f32 precision (measured over these 50 states
/// `A` 2.8e-7, `q̈` 1.7e-6; bounds about 10×: 3e-6 and 2e-5; floor 1e-9 as for SSRMS).
#[test]
fn f32_fma_payload_gravity_through_the_macro() {
    let chain = load("tests/data/codegen/random5.toml");
    let p = Params::<f64>::new(&chain);
    let nominal: Random5F32FmaPayload = Random5F32FmaPayload::NOMINAL;
    assert_eq!(nominal.mass, chain.joints()[4].inertial.mass as f32);
    let (mut ea, mut efd) = (0.0_f64, 0.0_f64);
    for seed in 0..50 {
        let [q, qd, tau, _] = state::<5>(300 + seed).map(|v| v.map(|x| f64::from(x as f32)));
        let loads = Loads {
            tau: Some(tau.to_vec()),
            gravity: Some(kanegen::dynamics::linalg::Vec3(G)),
            external: Vec::new(),
        };
        let a = Random5F32Fma::mass_matrix(&to_f32(&q), &nominal);
        let a = flat_v(a.iter().map(|r| widen(r)).collect());
        ea = ea.max(rel_err(
            &a,
            &flat_v(Methods::RECURRENT.mass_matrix.mass_matrix(&p, &q)),
        ));
        let fd =
            Random5F32Fma::forward_dynamics(&to_f32(&q), &to_f32(&qd), &to_f32(&tau), &nominal);
        efd = efd.max(rel_err(
            &widen(&fd),
            &Methods::RECURRENT.forward_dynamics(&p, &q, &qd, &loads),
        ));
    }
    eprintln!("random5 f32 + fma: A {ea:.2e}, q̈ {efd:.2e}");
    assert!(ea < 3e-6 && ea > 1e-9, "A: {ea:e}");
    assert!(efd < 2e-5 && efd > 1e-9, "q̈: {efd:e}");
    // Every straight-line function fuses (a function in loops has no candidate and its kernel's
    // traced counts).
    let straight = |c: &&Random5F32FmaOpCount| {
        (Random5F32Fma::CANDIDATES.iter()).any(|k| k.function == c.function)
    };
    let mut fused = Random5F32Fma::OP_COUNTS.iter().filter(straight);
    assert!(fused.clone().count() >= 6 && fused.all(|c| c.fma > 0));
}

kanegen::dynamics!(
    SsrmsUnfused,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    gravity = [0.0, 0.0, -9.81],
    target_fma = false,
);

/// `target_fma = false` writes products and sums out: no fused count, the same operations, and
/// (on a build without FMA, as the test profile is) the same bits as the fused-where-available
/// default; with FMA the two differ by rounding only.
#[test]
fn target_fma_off_writes_every_operation_out() {
    for (off, on) in SsrmsUnfused::OP_COUNTS
        .iter()
        .zip(SsrmsRegrouped::OP_COUNTS)
    {
        assert_eq!(off.function, on.function);
        assert_eq!(
            (off.fma, off.mul, off.add),
            (0, on.mul, on.add),
            "{}",
            on.function
        );
        assert!(on.fma > 0, "{}", on.function);
    }
    let fused = cfg!(all(target_arch = "x86_64", target_feature = "fma"))
        || cfg!(all(target_arch = "aarch64", target_feature = "neon"));
    let mut worst = 0.0_f64;
    for [q, qd, _, _] in ssrms_states(20) {
        let (a, b) = (
            SsrmsUnfused::nonlinear_effects(&q, &qd),
            SsrmsRegrouped::nonlinear_effects(&q, &qd),
        );
        if !fused {
            assert_eq!(a, b);
        }
        worst = worst.max(rel_err(&a, &b));
    }
    assert!(worst < 1e-13, "{worst:e}");
}

kanegen::dynamics!(
    SsrmsOwnInertia,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    gravity = [0.0, 0.0, -9.81],
    regroup = false,
);
kanegen::dynamics!(
    SsrmsRegrouped,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    gravity = [0.0, 0.0, -9.81],
);

/// `regroup = false` traces the model's own inertias: the same dynamics (to rounding), more
/// operations, and a header that says which.
#[test]
fn regrouping_keeps_the_dynamics_and_saves_operations() {
    let ops = |c: &[SsrmsRegroupedOpCount]| c.iter().map(|e| e.mul + e.add).collect::<Vec<_>>();
    let own: Vec<u64> = SsrmsOwnInertia::OP_COUNTS
        .iter()
        .map(|e| e.mul + e.add)
        .collect();
    let reg = ops(&SsrmsRegrouped::OP_COUNTS);
    for ((e, a), b) in SsrmsRegrouped::OP_COUNTS.iter().zip(&own).zip(&reg) {
        assert!(b < a, "{}: regrouped {b} ops, own {a}", e.function);
    }
    let mut worst = 0.0_f64;
    for [q, qd, tau, qdd] in ssrms_states(50) {
        let pairs = [
            (
                flat(SsrmsOwnInertia::mass_matrix(&q)),
                flat(SsrmsRegrouped::mass_matrix(&q)),
            ),
            (
                SsrmsOwnInertia::nonlinear_effects(&q, &qd).to_vec(),
                SsrmsRegrouped::nonlinear_effects(&q, &qd).to_vec(),
            ),
            (
                SsrmsOwnInertia::gravity(&q).to_vec(),
                SsrmsRegrouped::gravity(&q).to_vec(),
            ),
            (
                SsrmsOwnInertia::inverse_dynamics(&q, &qd, &qdd).to_vec(),
                SsrmsRegrouped::inverse_dynamics(&q, &qd, &qdd).to_vec(),
            ),
            (
                SsrmsOwnInertia::forward_dynamics(&q, &qd, &tau).to_vec(),
                SsrmsRegrouped::forward_dynamics(&q, &qd, &tau).to_vec(),
            ),
        ];
        for (a, b) in pairs {
            worst = worst.max(rel_err(&b, &a));
        }
    }
    println!("regrouped vs own inertias: worst {worst:.1e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// `libm_trig = true` takes libm's sines and cosines instead of the type's own `sincos`: the
/// same emitted operations, the same forward dynamics to rounding, and `Random5::sincos` is
/// libm's to 1 ulp of 1.
#[test]
fn libm_trig_gives_the_same_dynamics() {
    assert_eq!(
        Random5::OP_COUNTS.map(|c| (c.function, c.mul, c.add, c.sincos)),
        Random5Libm::OP_COUNTS.map(|c| (c.function, c.mul, c.add, c.sincos))
    );
    let mut r = rng(17);
    for _ in 0..20 {
        let q: [f64; 5] = random_vec(&mut r, 5, 3.0).try_into().unwrap();
        let v: [f64; 5] = random_vec(&mut r, 5, 1.0).try_into().unwrap();
        let tau: [f64; 5] = random_vec(&mut r, 5, 10.0).try_into().unwrap();
        let a = Random5::forward_dynamics(&q, &v, &tau);
        let b = Random5Libm::forward_dynamics(&q, &v, &tau);
        assert!(rel_err(&a, &b) < 1e-12, "{a:?} {b:?}");
        for x in q {
            let (s, c) = Random5::sincos(x);
            let (s0, c0) = libm::sincos(x);
            assert!((s - s0).abs() <= f64::EPSILON && (c - c0).abs() <= f64::EPSILON);
        }
    }
}

/// xArm7's placements are 3.7e-6 off signed permutations, each a turn about x: the generator also
/// traces the two-step inertia carry through them (`NEAR_PERMUTATION`, `axis_turn`) and emits it
/// where cheaper — its
/// mass matrix in fewer operations than any candidate with exact permutations only — and every
/// function still equals every interpreted algorithm.
#[test]
fn near_permutation_placements_take_the_two_step_carry() {
    use kanegen::dynamics::params::NEAR_PERMUTATION;
    use kanegen::trace::{trace, Convention, Function, Spec, Subject};
    let m = load("tests/data/erd/xarm7.urdf");
    let ops = |tol: f64| {
        let spec = Spec {
            regroup: true,
            two_step_placement: tol,
            ..Spec::default()
        };
        let t = trace(
            Subject::Model(&m),
            Function::MassMatrix,
            Methods::SPATIAL,
            &spec,
        )
        .unwrap();
        t.trace.counts(Convention::Emitted).total()
    };
    let (exact, near) = (ops(0.0), ops(NEAR_PERMUTATION));
    let emitted = XArm7::OP_COUNTS
        .iter()
        .find(|c| c.function == "mass_matrix")
        .unwrap();
    assert!(near < exact, "{near} against {exact}");
    assert_eq!(emitted.mul + emitted.add, near);
    check_constant_model!(XArm7, 7, "tests/data/erd/xarm7.urdf");
}

/// The generated limit constants are the URDF's `<limit>` attributes, joint by joint, read here
/// from the file's text independently of the model reader; a model without limits gives ±∞.
#[test]
fn limits_are_the_urdf_limit_attributes() {
    let text = std::fs::read_to_string("tests/data/erd/xarm7.urdf").unwrap();
    let attr = |tag: &str, name: &str| -> f64 {
        let start = tag.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
        let len = tag[start..].find('"').unwrap();
        tag[start..start + len].parse().unwrap()
    };
    for (i, joint) in XArm7::JOINTS.iter().enumerate() {
        let at = text
            .find(&format!("<joint name=\"{joint}\" type="))
            .unwrap();
        let tag = &text[at + text[at..].find("<limit").unwrap()..];
        let tag = &tag[..tag.find("/>").unwrap()];
        assert_eq!(
            XArm7::LOWER_POSITION_LIMIT[i],
            attr(tag, "lower"),
            "{joint}"
        );
        assert_eq!(
            XArm7::UPPER_POSITION_LIMIT[i],
            attr(tag, "upper"),
            "{joint}"
        );
        assert_eq!(XArm7::VELOCITY_LIMIT[i], attr(tag, "velocity"), "{joint}");
        assert_eq!(XArm7::EFFORT_LIMIT[i], attr(tag, "effort"), "{joint}");
    }
    assert!(Random5::LOWER_POSITION_LIMIT
        .iter()
        .all(|x| *x == f64::NEG_INFINITY));
    assert!(Random5::EFFORT_LIMIT.iter().all(|x| *x == f64::INFINITY));
}

// ---------------------------------------------------------------------------------------------
// Types named like primitive types and prelude items: the expansion names those by full paths.

/// Declares, in module `$module`, `dynamics!` of a small spacecraft arm named `$name` in a module
/// of its own (`shadowed`, where the type shadows the primitive type or prelude item of that
/// name, and the items after `;` give more names a meaning of their own) and named `Plain`,
/// both with the options `$key = $value`: the same code, so the same results, bit for bit.
macro_rules! twins {
    ($module:ident, $name:ident $(, $key:ident = $value:tt)* $(; $($item:item)*)?) => {
        #[allow(non_camel_case_types, dead_code)]
        mod $module {
            pub mod shadowed {
                $($($item)*)?
                kanegen::dynamics!(
                    $name,
                    "tests/data/reference/spart_sc_3dof.urdf",
                    derivatives = false
                    $(, $key = $value)*
                );
            }
            kanegen::dynamics!(
                Plain,
                "tests/data/reference/spart_sc_3dof.urdf",
                derivatives = false
                $(, $key = $value)*
            );
        }
    };
}

twins!(
    named_f64,
    f64,
    runtime_payload = true,
    gravity = [0.0, 0.0, -9.81]
);
twins!(named_f32, f32, scalar = f32);
twins!(named_option, Option, form = "compact");
twins!(named_some, Some, base = "free-floating");
twins!(named_none, None, base = "free-floating", form = "compact");
twins!(named_usize, usize);
twins!(named_str, str);
// Every primitive type, prelude item and built-in macro the expansion could name, and `core`,
// defined next to a type with a runtime payload.
twins!(
    crowded,
    Arm,
    runtime_payload = true;
    crate::common::shadowing_items!();
);

/// Joint angles of any length and precision (the same for both twins).
fn angles<T: From<f32>, const K: usize>() -> [T; K] {
    core::array::from_fn(|k| T::from((0.4 + 0.9 * k as f32).sin()))
}

/// Asserts that each `module::Name`'s mass matrix is its `Plain` twin's.
macro_rules! same_mass_matrix {
    ($($module:ident :: $name:ident),*) => {$(
        assert_eq!(
            $module::shadowed::$name::mass_matrix(&angles()),
            $module::Plain::mass_matrix(&angles()),
            stringify!($name)
        );
    )*};
}

#[test]
fn types_named_like_primitives_and_prelude_items_compute_what_plain_ones_do() {
    same_mass_matrix!(
        named_f32::f32,
        named_option::Option,
        named_some::Some,
        named_none::None,
        named_usize::usize,
        named_str::str
    );
    let m =
        named_f64::shadowed::f64::mass_matrix(&angles(), &named_f64::shadowed::f64Payload::NOMINAL);
    assert!(m[0][0] > 0.0);
    assert_eq!(
        m,
        named_f64::Plain::mass_matrix(&angles(), &named_f64::PlainPayload::NOMINAL)
    );
    assert_eq!(
        crowded::shadowed::Arm::mass_matrix(&angles(), &crowded::shadowed::ArmPayload::NOMINAL),
        crowded::Plain::mass_matrix(&angles(), &crowded::PlainPayload::NOMINAL)
    );
    // The constants and op counts come through too.
    assert_eq!(named_usize::shadowed::usize::N, named_usize::Plain::N);
    assert_eq!(named_some::shadowed::Some::NQ, named_some::Plain::NQ);
    assert_eq!(named_str::shadowed::str::JOINTS, named_str::Plain::JOINTS);
    let crowded_ops =
        crowded::shadowed::Arm::OP_COUNTS.map(|c| (c.function, c.mass_matrix_method, c.mul));
    let plain_ops = crowded::Plain::OP_COUNTS.map(|c| (c.function, c.mass_matrix_method, c.mul));
    assert_eq!(crowded_ops, plain_ops);
}
