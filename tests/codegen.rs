//! The checked-in generated code (`generated/`): byte-identical to a fresh generation, equal to
//! the interpreted f64 algorithms, and cheaper than Featherstone's generic CRBA for SSRMS.

use kanegen::cli::commands::generate::GENERATED;
use kanegen::dynamics::metrics::rel_err;
use kanegen::dynamics::Params;
use kanegen::dynamics::{Loads, MassMatrixMethod, Methods, NonlinearEffectsMethod};
use kanegen::model::random::{random_vec, rng};
use kanegen::model::Model;
use kanegen_generated::{
    srms::Srms, ssrms::Ssrms, ssrms6::Ssrms6, ssrms_recurrent::SsrmsRecurrent,
};
use std::path::Path;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn generated_files_are_up_to_date() {
    for g in GENERATED {
        let want = g.render(root()).unwrap();
        let have = std::fs::read_to_string(root().join(g.file)).unwrap();
        assert!(
            have == want,
            "{} is stale: regenerate with `{}`",
            g.file,
            g.command()
        );
    }
}

/// `(q, qd, x) -> y` on slices.
type Fn3 = fn(&[f64], &[f64], &[f64]) -> Vec<f64>;

/// `(q, qd) -> (M, c)` on slices.
type Pair = fn(&[f64], &[f64]) -> (Vec<Vec<f64>>, Vec<f64>);

/// `(methods, mul + add)` of one emitted function, from `OP_COUNTS`.
type Chosen = fn(&str) -> (Methods, u64);

/// The generated functions of one struct, as slices, for the comparison.
struct Fns {
    mass_matrix: fn(&[f64]) -> Vec<Vec<f64>>,
    nonlinear_effects: fn(&[f64], &[f64]) -> Vec<f64>,
    mass_matrix_and_nonlinear_effects: Pair,
    inverse_dynamics: Fn3,
    forward_dynamics: Fn3,
    chosen: Chosen,
}

/// The methods of an `OP_COUNTS` entry (an unused method is reported as the CRBA / RNEA;
/// forward dynamics by `aba` is [`Methods::ABA`]).
fn methods_of(
    mass: Option<&str>,
    nonlinear_effects: Option<&str>,
    forward: Option<&str>,
) -> Methods {
    if forward == Some("aba") {
        return Methods::ABA;
    }
    Methods {
        mass_matrix: mass.map_or(MassMatrixMethod::Crba, |m| {
            MassMatrixMethod::from_name(m).unwrap()
        }),
        nonlinear_effects: nonlinear_effects.map_or(NonlinearEffectsMethod::Rnea, |b| {
            NonlinearEffectsMethod::from_name(b).unwrap()
        }),
        ..Methods::SPATIAL
    }
}

macro_rules! fns {
    ($t:ty) => {
        Fns {
            mass_matrix: |q| {
                <$t>::mass_matrix(q.try_into().unwrap())
                    .iter()
                    .map(|r| r.to_vec())
                    .collect()
            },
            nonlinear_effects: |q, qd| {
                <$t>::nonlinear_effects(q.try_into().unwrap(), qd.try_into().unwrap()).to_vec()
            },
            mass_matrix_and_nonlinear_effects: |q, qd| {
                let (m, c) = <$t>::mass_matrix_and_nonlinear_effects(
                    q.try_into().unwrap(),
                    qd.try_into().unwrap(),
                );
                (m.iter().map(|r| r.to_vec()).collect(), c.to_vec())
            },
            inverse_dynamics: |q, qd, qdd| {
                <$t>::inverse_dynamics(
                    q.try_into().unwrap(),
                    qd.try_into().unwrap(),
                    qdd.try_into().unwrap(),
                )
                .to_vec()
            },
            forward_dynamics: |q, qd, tau| {
                <$t>::forward_dynamics(
                    q.try_into().unwrap(),
                    qd.try_into().unwrap(),
                    tau.try_into().unwrap(),
                )
                .to_vec()
            },
            chosen: |name| {
                let c = <$t>::OP_COUNTS.iter().find(|c| c.function == name).unwrap();
                (
                    methods_of(
                        c.mass_matrix_method,
                        c.nonlinear_effects_method,
                        c.forward_method,
                    ),
                    c.mul + c.add,
                )
            },
        }
    };
}

fn chosen(f: &Fns, name: &str) -> Methods {
    (f.chosen)(name).0
}

fn compare(chain: &Model, f: &Fns, seed: u64) {
    let n = chain.dof();
    let p = Params::<f64>::new(chain);
    let mut r = rng(seed);
    for _ in 0..20 {
        let q = random_vec(&mut r, n, 3.0);
        let qd = random_vec(&mut r, n, 1.0);
        let tau = random_vec(&mut r, n, 50.0);
        let qdd = random_vec(&mut r, n, 1.0);
        let loads = Loads {
            tau: Some(tau.clone()),
            ..Loads::default()
        };
        let flat = |a: Vec<Vec<f64>>| a.into_iter().flatten().collect::<Vec<_>>();
        let a_want = flat(chosen(f, "mass_matrix").mass_matrix.mass_matrix(&p, &q));
        let a_have = flat((f.mass_matrix)(&q));
        assert!(rel_err(&a_have, &a_want) < 1e-12, "{}: A", chain.name());
        // Against every algorithm: the generated code is the model's dynamics, not one method's.
        for alg in Methods::ALL {
            let e = rel_err(&a_have, &flat(alg.mass_matrix.mass_matrix(&p, &q)));
            assert!(e < 1e-12, "{}: A vs {alg}: {e:e}", chain.name());
            // c = −b(τ = 0), and b = τ − c.
            let b = alg.nonlinear_effects.tau_minus_c(&p, &q, &qd, &loads);
            let c = (f.nonlinear_effects)(&q, &qd);
            let tau_minus_c: Vec<f64> = tau.iter().zip(&c).map(|(t, c)| t - c).collect();
            let e = rel_err(&tau_minus_c, &b);
            assert!(e < 1e-12, "{}: τ − c vs b of {alg}: {e:e}", chain.name());
            let h = alg
                .nonlinear_effects
                .tau_minus_c(&p, &q, &qd, &Loads::default());
            let minus_h: Vec<f64> = c.iter().map(|c| -c).collect();
            let e = rel_err(&minus_h, &h);
            assert!(e < 1e-12, "{}: −c vs −h of {alg}: {e:e}", chain.name());
        }
        let (m2, c2) = (f.mass_matrix_and_nonlinear_effects)(&q, &qd);
        assert!(
            rel_err(&flat(m2), &a_have) < 1e-15,
            "{}: (M, c).0",
            chain.name()
        );
        let e = rel_err(&c2, &(f.nonlinear_effects)(&q, &qd));
        assert!(e < 1e-13, "{}: (M, c).1 {e:e}", chain.name());
        let id = chosen(f, "inverse_dynamics").inverse_dynamics(&p, &q, &qd, &qdd, &loads);
        let e = rel_err(&(f.inverse_dynamics)(&q, &qd, &qdd), &id);
        assert!(e < 1e-12, "{}: inverse dynamics {e:e}", chain.name());
        let fd = chosen(f, "forward_dynamics").forward_dynamics(&p, &q, &qd, &loads);
        let e = rel_err(&(f.forward_dynamics)(&q, &qd, &tau), &fd);
        assert!(e < 1e-12, "{}: forward dynamics {e:e}", chain.name());
        // Round trip: forward then inverse dynamics gives back the drives.
        let x = (f.forward_dynamics)(&q, &qd, &tau);
        let back = (f.inverse_dynamics)(&q, &qd, &x);
        assert!(rel_err(&back, &tau) < 1e-9, "{}: round trip", chain.name());
    }
}

#[test]
fn generated_code_equals_interpreted_algorithms() {
    let fns = [fns!(Ssrms), fns!(Ssrms6), fns!(Srms)];
    for (g, f) in GENERATED.iter().zip(&fns) {
        let model = g.model(root()).unwrap();
        compare(&model, f, 11);
    }
    assert_eq!((Ssrms::N, Ssrms6::N, Srms::N), (7, 6, 6));
}

/// `--algorithm recurrent` forces the paper's algorithm: every function with a mass-matrix or
/// nonlinear-effects method traces it alone and says so (one candidate, the header's line), its code equals
/// the interpreted recurrent algorithm and the cheapest generated code (other algorithms) to
/// 1e-12, and it costs more operations than the cheapest; on a tree it is refused by name.
#[test]
fn the_recurrent_algorithm_can_be_forced() {
    let g = GENERATED
        .iter()
        .find(|g| g.type_name == "SsrmsRecurrent")
        .unwrap();
    assert_eq!(g.algorithm, Some("recurrent"));
    let model = g.model(root()).unwrap();
    compare(&model, &fns!(SsrmsRecurrent), 12);
    for e in SsrmsRecurrent::OP_COUNTS {
        let uses = e.mass_matrix_method.is_some() || e.nonlinear_effects_method.is_some();
        if uses {
            assert!(
                e.mass_matrix_method.is_none_or(|m| m == "recurrent")
                    && e.nonlinear_effects_method.is_none_or(|b| b == "recurrent"),
                "{}",
                e.function
            );
            let n = SsrmsRecurrent::CANDIDATES
                .iter()
                .filter(|c| c.function == e.function)
                .count();
            assert_eq!(n, 1, "{}", e.function);
            let cheapest = Ssrms::OP_COUNTS
                .iter()
                .find(|c| c.function == e.function)
                .unwrap();
            assert!(
                cheapest.mul + cheapest.add < e.mul + e.add,
                "{}",
                e.function
            );
        }
    }
    let mut r = rng(5);
    for _ in 0..10 {
        let q: [f64; 7] = random_vec(&mut r, 7, 3.0).try_into().unwrap();
        let qd: [f64; 7] = random_vec(&mut r, 7, 1.0).try_into().unwrap();
        let (m1, c1) = SsrmsRecurrent::mass_matrix_and_nonlinear_effects(&q, &qd);
        let (m2, c2) = Ssrms::mass_matrix_and_nonlinear_effects(&q, &qd);
        assert!(rel_err(m1.as_flattened(), m2.as_flattened()) < 1e-12);
        assert!(rel_err(&c1, &c2) < 1e-12);
    }
    let src = std::fs::read_to_string(root().join(g.file)).unwrap();
    assert!(src.contains("//! Algorithm: forced to `recurrent`"));
    let panda = kanegen::model::io::load_model(&root().join("tests/data/erd/panda.urdf"))
        .unwrap()
        .without_mimics();
    let mut o = kanegen::codegen::Options::new("Panda");
    o.algorithm = Some(kanegen::codegen::forced_algorithm("recurrent").unwrap());
    let e = kanegen::codegen::generate_items(&panda, &o)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("`recurrent` handles serial chains only"), "{e}");
    assert!(kanegen::codegen::forced_algorithm("fastest").is_err());
}

/// Locking the shoulder roll (index 0) at `v`: A and b of the 6-dof model are those of the
/// 7-dof model at `q[0] = v`, `q̇[0] = 0`, with row and column 0 removed.
#[test]
fn locked_joint_matches_full_model() {
    let full = kanegen::model::io::load_model(&root().join(GENERATED[0].model)).unwrap();
    let pf = Params::<f64>::new(&full);
    for (index, v) in [(0, 0.0), (0, 0.7), (3, -1.1), (6, 0.4)] {
        let locked = full.lock_joint(index, v).unwrap();
        assert_eq!(locked.dof(), 6);
        let pl = Params::<f64>::new(&locked);
        let mut r = rng(5 + index as u64);
        for _ in 0..5 {
            let q6 = random_vec(&mut r, 6, 3.0);
            let qd6 = random_vec(&mut r, 6, 1.0);
            let tau6 = random_vec(&mut r, 6, 10.0);
            let ins = |x: &[f64], val: f64| {
                let mut y = x.to_vec();
                y.insert(index, val);
                y
            };
            let (q, qd, tau) = (ins(&q6, v), ins(&qd6, 0.0), ins(&tau6, 0.0));
            let a7 = Methods::RECURRENT.mass_matrix.mass_matrix(&pf, &q);
            let a6 = Methods::SPATIAL.mass_matrix.mass_matrix(&pl, &q6);
            let a7r: Vec<f64> = (0..7)
                .filter(|&i| i != index)
                .flat_map(|i| {
                    let row = &a7[i];
                    (0..7).filter(|&j| j != index).map(move |j| row[j])
                })
                .collect();
            let a6f: Vec<f64> = a6.into_iter().flatten().collect();
            assert!(rel_err(&a6f, &a7r) < 1e-12, "A, lock {index}={v}");
            let l7 = Loads {
                tau: Some(tau),
                ..Loads::default()
            };
            let l6 = Loads {
                tau: Some(tau6),
                ..Loads::default()
            };
            let mut b7 = Methods::RECURRENT
                .nonlinear_effects
                .tau_minus_c(&pf, &q, &qd, &l7);
            b7.remove(index);
            let b6 = Methods::SPATIAL
                .nonlinear_effects
                .tau_minus_c(&pl, &q6, &qd6, &l6);
            assert!(rel_err(&b6, &b7) < 1e-12, "b, lock {index}={v}");
        }
    }
    assert!(full.lock_joint(7, 0.0).is_err());
}

/// Like with like. The emitted SSRMS mass matrix (a folded model: the geometry's zeros and ones
/// folded away) against the emitted `crba` of the same folded model (the generator traces every
/// candidate and emits the cheapest), and the emitted `crba` of a generic symbolic chain of 7
/// joints against the same method on the folded SSRMS (folding only removes operations).
/// (The generic chain against the printed RBDA polynomial is in `tests/table1.rs`.) `OP_COUNTS`
/// agrees with a fresh trace, and the inverse dynamics is the O(N) Newton–Euler pass, cheaper
/// than the mass matrix and the nonlinear effects together.
#[test]
fn ssrms_mass_matrix_against_like_candidates() {
    use kanegen::trace::sym::Convention;
    use kanegen::trace::table1::{trace_mass_matrix, TableAlgorithm};
    let m = Ssrms::OP_COUNTS[0];
    assert_eq!(m.function, "mass_matrix");
    let total = |f: &str| {
        let c = Ssrms::OP_COUNTS.iter().find(|c| c.function == f).unwrap();
        c.mul + c.add
    };
    // One Newton–Euler pass costs less than forming M q̈ + c.
    assert!(total("inverse_dynamics") < total("mass_matrix") + total("nonlinear_effects"));
    // OP_COUNTS agrees with a fresh trace.
    let model = GENERATED[0].model(root()).unwrap();
    let opts = kanegen::codegen::Options::new("Ssrms");
    let (choice, _) = kanegen::codegen::choose::choose(
        &model,
        kanegen::trace::Function::MassMatrix,
        MassMatrixMethod::Crba,
        &opts,
    )
    .unwrap();
    let c = choice.counts();
    assert_eq!((c.mul, c.add), (m.mul, m.add));
    // Folded model against folded model: every candidate's emitted count, the winner the least.
    for cand in &choice.candidates {
        assert!(
            m.mul + m.add <= cand.counts.total(),
            "{} ({} frames): {} < emitted {}",
            cand.methods,
            cand.frames.name(),
            cand.counts.total(),
            m.mul + m.add
        );
    }
    let folded_crba = choice
        .candidates
        .iter()
        .filter(|c| c.methods.mass_matrix == MassMatrixMethod::Crba)
        .map(|c| c.counts.total())
        .min()
        .unwrap();
    // Generic chain against folded model, the same method and convention.
    let generic = trace_mass_matrix(TableAlgorithm::Spatial, 7).counts(Convention::Emitted);
    eprintln!(
        "crba N = 7 emitted: generic {} m + {} a = {}, folded SSRMS {folded_crba}",
        generic.mul,
        generic.add,
        generic.mul + generic.add
    );
    assert!(folded_crba < generic.mul + generic.add);
}

/// Per-function counts of the header line `Fused multiply-adds: T (`f` k, …)`, and `T`.
fn header_fmas(src: &str, prefix: &str) -> (u64, Vec<(String, u64)>) {
    let line = src
        .lines()
        .find_map(|l| l.strip_prefix(prefix))
        .expect("the fma header line");
    let (total, rest) = line.split_once(" (").unwrap();
    let per = rest
        .split_once(')')
        .unwrap()
        .0
        .split(", ")
        .map(|p| {
            let (f, k) = p.split_once(' ').unwrap();
            (f.trim_matches('`').to_string(), k.parse().unwrap())
        })
        .collect();
    (total.parse().unwrap(), per)
}

/// Calls of `call` per generated function (`pub fn NAME` and `pub fn NAME_lanes`, which holds
/// the body, up to the next function), comments excluded; not in the helpers `sincos` and
/// `sincos_n`, whose fused products the header does not count.
fn calls_per_function(src: &str, call: &str) -> Vec<(String, u64)> {
    let mut out: Vec<(String, u64)> = Vec::new();
    for line in src.lines() {
        let code = line.trim_start();
        if code.starts_with("//") {
            continue;
        }
        if let Some(rest) = code.strip_prefix("pub fn ") {
            let name = rest.split(['(', '<']).next().unwrap();
            let name = name.strip_suffix("_lanes").unwrap_or(name);
            let name = name.strip_suffix("_batch").unwrap_or(name);
            if out.last().is_none_or(|(f, _)| f != name) {
                out.push((name.to_string(), 0));
            }
        } else if let Some(last) = out.last_mut() {
            last.1 += line.matches(call).count() as u64;
        }
    }
    out.retain(|(f, _)| !f.starts_with("sincos"));
    out
}

/// `fma = true` on SSRMS: every function fuses, the source has exactly the fused calls its
/// header and its per-function docs state, the op-count table is that of the plain code, and
/// the plain (default) file has no precision lines (it is the checked-in file, see
/// `generated_files_are_up_to_date`).
#[test]
fn fma_source_has_the_fused_calls_its_header_states() {
    let chain = GENERATED[0].model(root()).unwrap();
    let plain =
        kanegen::codegen::generate_file(&chain, &kanegen::codegen::Options::new("Ssrms")).unwrap();
    assert!(!plain.contains("//! Fused multiply-adds:") && !plain.contains("fma("));
    // The default fuses through `Self::mul_add` (fused where the build targets FMA): the calls
    // are those its header states, and that helper forwards to the runtime's (no `unsafe` here).
    let (total, per) = header_fmas(
        &plain,
        "//! Fused multiply-adds where the target has them: ",
    );
    assert_eq!(calls_per_function(&plain, "S::mul_add("), per);
    assert!(total > 0 && per.iter().all(|(_, k)| *k > 0), "{per:?}");
    assert!(!plain.contains("unsafe"));
    assert!(!plain.contains("fn mul_add(") && !plain.contains("Self::mul_add("));
    // Without it: no fusion, no helper, no unsafe.
    let mut o = kanegen::codegen::Options::new("Ssrms");
    o.target_fma = false;
    let unfused = kanegen::codegen::generate_file(&chain, &o).unwrap();
    assert!(
        !unfused.contains("//! Fused multiply-adds")
            && !unfused.contains("fn mul_add")
            && !unfused.contains("S::mul_add")
            && !unfused.contains("S::fma")
            && !unfused.contains("unsafe")
    );
    for path in [None, Some("f64::mul_add")] {
        let mut o = kanegen::codegen::Options::new("Ssrms");
        o.fma = true;
        o.fma_path = path.map(String::from);
        let src = kanegen::codegen::generate_file(&chain, &o).unwrap();
        let call = match path {
            Some(p) => p.to_string(),
            None => "S::fma(".to_string(),
        };
        let (total, per) = header_fmas(&src, "//! Fused multiply-adds: ");
        let have = calls_per_function(&src, &call);
        eprintln!("SSRMS fma ({call}): {total} in all, {per:?}");
        assert_eq!(have, per, "{call}");
        assert_eq!(have.iter().map(|(_, k)| k).sum::<u64>(), total);
        assert!(per.iter().all(|(_, k)| *k > 0), "every function fuses");
        for (f, k) in &per {
            let doc = format!("of which {k} fused multiply-adds");
            assert!(src.contains(&doc), "{f}: {doc}");
        }
        assert!(src.contains("//! Precision: `f64`."));
        // Same table of counts: an fma is one mul and one add.
        let table = |s: &str| -> Vec<String> {
            s.lines()
                .filter(|l| l.starts_with("//! | `"))
                .map(String::from)
                .collect()
        };
        assert_eq!(table(&src), table(&plain));
        assert!(!src.contains("unsafe"));
    }
}

/// `float = F32` on SSRMS: no `f64` anywhere in the file, f32 libm calls, the header says so.
#[test]
fn f32_source_is_f32_throughout() {
    let chain = GENERATED[0].model(root()).unwrap();
    let mut o = kanegen::codegen::Options::new("SsrmsF32");
    o.float = kanegen::codegen::Float::F32;
    let src = kanegen::codegen::generate_file(&chain, &o).unwrap();
    assert!(!src.contains("f64"));
    assert!(src.contains("//! Precision: `f32`"));
    assert!(src.contains(
        "pub fn mass_matrix(
        q: &[::core::primitive::f32; 7],
    ) -> [[::core::primitive::f32; 7]; 7] {"
    ));
    // libm's sine–cosine (no table in f32), lane by lane in the one `_lanes` body.
    assert!(src.contains("S::sincos(") && !src.contains("S::sincos_n"));
    assert!(src.contains("S: kanegen_runtime::lanes::Lanes<::core::primitive::f32>"));
}

/// Snapping float noise (`Options::snap`, default 1e-15) takes Panda's `cos(π/2) = 6.1e-17`
/// residues out of the traced rotations: (M, c) in 1455 operations instead of 2122, the header
/// saying how many numbers moved and by how much; `snap = 0` keeps them; a bad tolerance is an
/// error. (That the snapped model has the same dynamics is `tests/canonical.rs`.)
#[test]
fn snapping_float_noise_saves_operations_and_says_so() {
    use kanegen::codegen::{generate_items, Options};
    use kanegen::trace::Function;
    let panda = kanegen::model::io::load_model(&root().join("tests/data/erd/panda.urdf"))
        .unwrap()
        .without_mimics();
    let ops = |snap: f64| {
        let mut o = Options::new("Panda");
        o.snap = snap;
        let g = generate_items(&panda, &o).unwrap();
        let total = |f: Function| {
            g.choices
                .iter()
                .find(|c| c.function == f)
                .unwrap()
                .counts()
                .total()
        };
        let noise = g
            .header
            .iter()
            .find(|l| l.starts_with("Float noise"))
            .unwrap()
            .clone();
        (
            total(Function::MassMatrixAndNonlinearEffects),
            total(Function::MassMatrix),
            noise,
        )
    };
    let (kept, kept_m, kept_line) = ops(0.0);
    let (snapped, snapped_m, line) = ops(kanegen::model::canonical::DEFAULT_SNAP);
    println!("Panda (M, c): {kept} → {snapped}; M: {kept_m} → {snapped_m}; {line}");
    assert!(snapped * 5 < kept * 4, "{snapped} vs {kept}");
    assert!(snapped_m < kept_m);
    assert_eq!(kept_line, "Float noise: kept (snapping off).");
    assert!(
        line.contains("12 numbers snapped") && line.contains("6.1e-17"),
        "{line}"
    );
    let mut o = Options::new("Panda");
    o.snap = 0.5;
    let e = generate_items(&panda, &o).err().unwrap().to_string();
    assert!(e.contains("snap tolerance 0.5"), "{e}");
}
