//! The compact form at the source level: what `generate_file` writes with `Form::Compact`
//! (loops, no allocation, no panicking call), which form `Form::Auto` picks, and what it refuses.

use kanegen_codegen::choose::choose;
use kanegen_codegen::compact::{AUTO_LIMIT, LINEAR_AUTO_LIMIT};
use kanegen_codegen::kanegen_dynamics::MassMatrixMethod;
use kanegen_codegen::{generate_file, generate_items, plan, Float, Form, Options};
use kanegen_model::random::{random_chain, random_tree, ChainSpec};
use kanegen_model::{BaseKind, Model};
use kanegen_trace::Function;
use std::path::Path;

fn chain(n: usize, seed: u64) -> Model {
    random_chain(
        &ChainSpec {
            n,
            prismatic_fraction: 0.3,
            ..Default::default()
        },
        seed,
    )
}

fn compact_opts() -> Options {
    let mut o = Options::new("Arm");
    o.form = Form::Compact;
    o
}

/// The source without comments and doc attributes: the code itself.
fn code(src: &str) -> String {
    src.lines()
        .filter(|l| {
            let t = l.trim_start();
            !t.starts_with("//") && !t.starts_with("#[doc") && !t.starts_with("#![doc")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn compact_source_loops_without_allocation_or_panics() {
    for (model, gravity, float) in [
        (chain(5, 1), Some([0.0, 0.0, -9.81]), Float::F64),
        (random_tree(&ChainSpec::default(), 2), None, Float::F32),
    ] {
        let mut o = compact_opts();
        o.gravity = gravity;
        o.float = float;
        let src = generate_file(&model, &o).unwrap();
        assert!(
            src.contains("//! Form: compact: loops over constant tables"),
            "{src}"
        );
        let body = code(&src);
        for word in [
            "alloc",
            "Vec",
            "Box",
            "unwrap",
            "expect(",
            "panic",
            "unreachable",
            "todo!",
            "String",
        ] {
            assert!(!body.contains(word), "`{word}` in the compact source");
        }
        // The tables are data; the loops are the runtime's kernels, called once per function.
        assert!(body.contains("const CX: kanegen_runtime::compact::Tables<"));
        assert!(
            !body.contains("fn cx_") && !body.contains("RBDA Table"),
            "no algorithm is pasted into the type"
        );
        // f64: the kernels call the type's own sine–cosine (libm's beyond its range).
        if float == Float::F32 {
            assert!(body.contains("libm::sincosf"));
            assert!(!body.contains("f64"), "f32 code names no f64");
        } else {
            assert!(body.contains("Self::sincos") && body.contains("::sincos::sincos_n"));
        }
        // Straight-line bodies are `let` chains; compact ones call the kernels.
        assert!(src
            .replace([' ', '\n'], "")
            .contains("kanegen_runtime::compact::mass_matrix(&Self::CX,Self::CX.inertia,q,"));
        assert!(src.contains("Compact form: loops over the model's constant tables"));
    }
}

/// `Form::Auto` picks by the emitted operations of the unrolled `M + c`: compact for a random
/// chain of 16 and of 64 joints, unrolled for SSRMS and for random N = 4 and 8 (in canonical
/// frames N = 8 emits fewer than `AUTO_LIMIT`); the header says which and why.
/// Fails when the rule's inputs (the limit, the traced counts) move across these models.
#[test]
fn auto_picks_compact_for_large_models_only() {
    let auto = Options::new("Arm");
    let big = generate_items(&chain_default(64), &auto).unwrap();
    let line = form_line(&big.header);
    assert!(
        line.starts_with("Form: compact") && line.contains("auto: unrolled M + c would be"),
        "{line}"
    );
    let eight = generate_items(&chain_default(8), &auto).unwrap();
    assert!(form_line(&eight.header).starts_with("Form: unrolled"));
    let sixteen = generate_items(&chain_default(16), &auto).unwrap();
    assert!(form_line(&sixteen.header).starts_with("Form: compact"));
    // The O(N) Newton–Euler functions of a compact model stay straight-line within
    // LINEAR_AUTO_LIMIT (N = 16: about 2,800 operations each), not at N = 64; the body says so.
    // The body of `NAME_lanes`: the straight-line code (`NAME` calls it), or the lanes of a
    // function in loops.
    let fn_body = |g: &kanegen_codegen::Generated, name: &str| {
        let src = g.items.to_string().replace(' ', "");
        let at = src.find(&format!("pubfn{name}_lanes<")).unwrap();
        let end = src[at + 5..]
            .find("pubfn")
            .map_or(src.len(), |e| at + 5 + e);
        src[at..end].to_string()
    };
    let ops = |g: &kanegen_codegen::Generated, name: &str| {
        let c = g
            .choices
            .iter()
            .find(|c| c.function.name() == name)
            .unwrap();
        c.counts().total()
    };
    for (name, f) in [
        ("nonlinear_effects", Function::NonlinearEffects),
        ("inverse_dynamics", Function::InverseDynamics),
    ] {
        assert!(ops(&sixteen, name) <= LINEAR_AUTO_LIMIT);
        assert!(traced_ops(&chain_default(64), f) > LINEAR_AUTO_LIMIT);
        // A body in loops has no unrolled candidate traced (its `OP_COUNTS` entry is its
        // kernel's traced count, `compact_kernels.rs`).
        assert_eq!(ops(&big, name), 0);
        assert!(untraced(&big, name));
        assert!(
            fn_body(&sixteen, name).contains("letx"),
            "{name} unrolled at N = 16"
        );
        assert!(
            !fn_body(&big, name).contains("letx"),
            "{name} compact at N = 64"
        );
        assert!(form_line(&sixteen.header).contains(&format!("`{name}` (")));
    }
    assert!(!fn_body(&sixteen, "mass_matrix").contains("letx"));
    assert!(!form_line(&big.header).contains("Straight-line all the same"));
    let forced = generate_items(
        &chain_default(16),
        &Options {
            form: Form::Compact,
            ..auto.clone()
        },
    )
    .unwrap();
    assert!(
        !fn_body(&forced, "nonlinear_effects").contains("letx"),
        "forced compact"
    );
    let small = generate_items(&chain_default(4), &auto).unwrap();
    assert!(form_line(&small.header).starts_with("Form: unrolled straight-line code (auto: "));
    let ssrms = kanegen_model::io::load_model(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data/reference/ssrms_nguyen_hughes_1994.urdf"),
    )
    .unwrap();
    let g = generate_items(&ssrms, &auto).unwrap();
    let line = form_line(&g.header);
    assert!(line.starts_with("Form: unrolled"), "{line}");
    // The limit sits between the measured crossovers (docs/performance.md, "Compact against unrolled").
    let mc = |g: &kanegen_codegen::Generated| {
        g.choices
            .iter()
            .find(|c| c.function.name() == "mass_matrix_and_nonlinear_effects")
            .unwrap()
            .counts()
            .total()
    };
    assert!(mc(&small) <= AUTO_LIMIT && mc(&g) <= AUTO_LIMIT && mc(&eight) <= AUTO_LIMIT);
    assert!(untraced(&sixteen, "mass_matrix_and_nonlinear_effects"));
    assert!(untraced(&big, "forward_dynamics"));
    assert!(traced_ops(&chain_default(16), Function::MassMatrixAndNonlinearEffects) > AUTO_LIMIT);
}

/// Whether the function `name` of `g` was left untraced: no candidate, the loops' methods.
fn untraced(g: &kanegen_codegen::Generated, name: &str) -> bool {
    let c = g
        .choices
        .iter()
        .find(|c| c.function.name() == name)
        .unwrap();
    c.candidates.is_empty() && c.counts().total() == 0
}

/// The emitted `mul + add` of the cheapest unrolled candidate of `f` traced on the whole
/// (snapped) model, after `M`'s choice as the generator makes it: what the form rule compared
/// before it traced prefixes.
fn traced_ops(model: &Model, f: Function) -> u64 {
    let opts = Options::new("Arm");
    let model = model.snapped(opts.snap).model;
    let (m, _) = choose(&model, Function::MassMatrix, MassMatrixMethod::Crba, &opts).unwrap();
    if f == Function::MassMatrix {
        return m.counts().total();
    }
    let (c, _) = choose(&model, f, m.chosen.mass_matrix, &opts).unwrap();
    c.counts().total()
}

/// The form `Form::Auto` decides from prefixes of the model (`plan::form`) is the one the
/// whole model's traced `M + c` gives against `AUTO_LIMIT`, on random chains N = 2..64 (the
/// default geometry and a third prismatic), random trees and the test suite's models; a
/// compact decision on a model of more than `FIRST_PREFIX` joints traced a prefix only.
/// Fails when a prefix costs more than its model, or the rule moves.
#[test]
fn prefix_decisions_equal_whole_trace_decisions() {
    let auto = Options::new("Arm");
    let mut models: Vec<Model> = (2..=64).map(chain_default).collect();
    models.extend((2..=40).step_by(3).map(|n| chain(n, n as u64)));
    models.extend([7, 10, 20, 33].map(|n| {
        random_tree(
            &ChainSpec {
                n,
                prismatic_fraction: 0.3,
                ..Default::default()
            },
            n as u64,
        )
    }));
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data");
    for file in [
        "reference/ssrms_nguyen_hughes_1994.urdf",
        "reference/srms_nguyen_hughes_1994.urdf",
        "erd/panda.urdf",
        "compact/chain12.toml",
        "compact/tree10.toml",
    ] {
        models.push(kanegen_model::io::load_model(&data.join(file)).unwrap());
    }
    let (mut compact, mut unrolled) = (0, 0);
    for model in &models {
        let n = model.dof();
        let decision = plan::form(model, &auto).unwrap();
        let whole = traced_ops(model, Function::MassMatrixAndNonlinearEffects) > AUTO_LIMIT;
        assert_eq!(
            decision.form == Form::Compact,
            whole,
            "{} (N = {n}): {}",
            model.name(),
            decision.line
        );
        if whole {
            compact += 1;
            assert_eq!(
                decision.line.contains("joints alone"),
                n > plan::FIRST_PREFIX,
                "{}",
                decision.line
            );
        } else {
            unrolled += 1;
        }
    }
    assert!(
        compact > 40 && unrolled > 10,
        "{compact} compact, {unrolled} unrolled"
    );
}

fn chain_default(n: usize) -> Model {
    random_chain(
        &ChainSpec {
            n,
            ..Default::default()
        },
        1000 + n as u64,
    )
}

fn form_line(header: &[String]) -> String {
    header
        .iter()
        .find(|l| l.starts_with("Form: "))
        .cloned()
        .unwrap_or_default()
}

/// A free-floating base takes the compact form when asked (its dynamics functions call the
/// floating kernels, its frames stay straight-line) and stays unrolled under `Auto` at 7 joints;
/// a forced algorithm is an error under `Compact`; a runtime payload is compact; `Unrolled` is
/// obeyed at any size.
#[test]
fn unsupported_models_stay_unrolled() {
    let ssrms = kanegen_model::io::load_model(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/ssrms.toml"),
    )
    .unwrap();
    let mut o = Options::new("Arm");
    o.base = Some(BaseKind::FreeFloating);
    let g = generate_items(&ssrms, &o).unwrap();
    assert!(form_line(&g.header).starts_with("Form: unrolled straight-line code (auto: "));
    o.form = Form::Compact;
    let src = generate_file(&ssrms, &o).unwrap().replace([' ', '\n'], "");
    for kernel in [
        "mass_matrix::<_,7,13",
        "inverse_dynamics::<_,7,13",
        "forward_dynamics::<_,7,13",
    ] {
        assert!(
            src.contains(&format!("kanegen_runtime::compact::floating::{kernel}")),
            "{kernel}"
        );
    }
    o.algorithm = Some(kanegen_dynamics::Methods::RECURRENT);
    assert!(generate_items(&ssrms, &o).is_err());
    // A runtime payload is supported: the last body's inertia is built from it per call.
    let mut o = compact_opts();
    o.runtime_payload = true;
    let src = generate_file(&chain(3, 5), &o).unwrap();
    assert!(src.replace([' ', '\n'], "").contains(
        "kanegen_runtime::compact::mass_matrix(&Self::CX,&kanegen_runtime::compact::with_payload::<_,"
    ));
    let mut o = Options::new("Arm");
    o.form = Form::Unrolled;
    let g = generate_items(&chain_default(64), &o).unwrap();
    // 64 speeds: the derivatives are not generated, and the form line says so.
    assert_eq!(
        form_line(&g.header),
        "Form: unrolled straight-line code (asked for). Not generated: \
         `inverse_dynamics_derivatives`, `forward_dynamics_derivatives`, `mass_matrix_inverse` \
         (generated straight-line up to 24 speeds and in loops at any size, but \
         `form = \"unrolled\"` or a forced algorithm has no loops; docs/limits.md)."
    );
}

/// `derivatives = false` leaves the three derivative functions out, and the header says why; by
/// default they are generated.
#[test]
fn derivatives_are_left_out_when_not_asked_for() {
    let model = chain(4, 3);
    let mut o = Options::new("Arm");
    let with = generate_file(&model, &o).unwrap();
    o.derivatives = false;
    let without = generate_file(&model, &o).unwrap();
    for f in [
        "inverse_dynamics_derivatives",
        "forward_dynamics_derivatives",
        "mass_matrix_inverse",
    ] {
        let def = format!("pub fn {f}(");
        assert!(with.contains(&def), "{f} generated by default");
        assert!(!without.contains(&def), "{f} left out");
    }
    assert!(without.contains(
        "Not generated: `inverse_dynamics_derivatives`, `forward_dynamics_derivatives`, \
         `mass_matrix_inverse` (not asked for: `derivatives = false`, `--no-derivatives`)."
    ));
    assert!(without.len() < with.len(), "the file is smaller");
}

/// A random chain of 500 joints generates in seconds: the form is decided on a prefix of 16
/// joints, and no unrolled candidate of a function in loops is traced (161 s and 5.6 GB when
/// they all were; 1.2 s and 34 MB for `kanegen generate` since). The budget is generous for a
/// shared machine; tracing the unrolled candidates again would exceed it.
#[test]
fn a_500_joint_chain_generates_compact_in_seconds() {
    let model = chain_default(500);
    let t = std::time::Instant::now();
    let g = generate_items(&model, &Options::new("Chain500")).unwrap();
    let s = t.elapsed().as_secs_f64();
    println!("N = 500: generate_items {s:.2} s");
    let line = form_line(&g.header);
    assert!(line.contains("its first 16 joints alone"), "{line}");
    for f in [
        "mass_matrix",
        "nonlinear_effects",
        "inverse_dynamics",
        "forward_dynamics",
        "forward_dynamics_with_wrenches",
        "mass_matrix_and_nonlinear_effects",
    ] {
        assert!(untraced(&g, f), "{f}");
    }
    assert!(s < 60.0, "{s} s");
}

/// Under `Auto`, an unrolled model keeps its derivative functions straight-line while they are
/// small, and calls the compact derivative kernels for those past the size rule
/// (`compact::derivative_keeps_unrolled`); the form line names them; `Unrolled` keeps them all
/// straight-line.
#[test]
fn large_derivatives_of_an_unrolled_model_run_in_loops() {
    let kernel = |f: &str| format!("kanegen_runtime::compact::derivatives::{f}(&Self::CX");
    let names = [
        "inverse_dynamics_derivatives",
        "forward_dynamics_derivatives",
        "mass_matrix_inverse",
    ];
    let o = Options::new("Arm");
    let small = generate_file(&chain_default(3), &o)
        .unwrap()
        .replace([' ', '\n'], "");
    assert!(names.iter().all(|f| !small.contains(&kernel(f))));
    let model = chain_default(8);
    let g = generate_items(&model, &o).unwrap();
    let line = form_line(&g.header);
    assert!(
        line.starts_with("Form: unrolled straight-line code (auto: "),
        "{line}"
    );
    assert!(line.contains(" In loops all the same: `"), "{line}");
    let src = generate_file(&model, &o).unwrap().replace([' ', '\n'], "");
    let looped: Vec<_> = names.iter().filter(|f| src.contains(&kernel(f))).collect();
    assert!(!looped.is_empty(), "{line}");
    for f in &looped {
        assert!(line.contains(&format!("`{f}`")), "{f}: {line}");
    }
    assert!(src.contains("constCX:kanegen_runtime::compact::Tables"));
    let mut o = o;
    o.form = Form::Unrolled;
    let src = generate_file(&model, &o).unwrap().replace([' ', '\n'], "");
    assert!(names.iter().all(|f| !src.contains(&kernel(f))));
}

/// A compact model keeps `mass_matrix_inverse` straight-line while its body is within
/// `DERIVATIVES_AUTO_LIMIT` (a 12-joint chain, the header says so with its count), and calls the
/// kernel above it (16 joints) or when the compact form is forced.
#[test]
fn a_compact_model_keeps_a_small_mass_matrix_inverse_straight_line() {
    use kanegen_codegen::compact::DERIVATIVES_AUTO_LIMIT;
    let kernel = "kanegen_runtime::compact::derivatives::mass_matrix_inverse(&Self::CX";
    let o = Options::new("Arm");
    let model = chain_default(12);
    let g = generate_items(&model, &o).unwrap();
    let line = form_line(&g.header);
    assert!(line.starts_with("Form: compact"), "{line}");
    let kept = line
        .split("Straight-line too: `mass_matrix_inverse` (")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or_else(|| panic!("{line}"));
    assert!(kept <= DERIVATIVES_AUTO_LIMIT && kept > 1000, "{line}");
    let src = generate_file(&model, &o).unwrap().replace([' ', '\n'], "");
    assert!(!src.contains(kernel));
    assert!(src.contains("kanegen_runtime::compact::derivatives::inverse_dynamics_derivatives("));
    let big = chain_default(16);
    let line = form_line(&generate_items(&big, &o).unwrap().header);
    assert!(!line.contains("Straight-line too"), "{line}");
    let src = generate_file(&big, &o).unwrap().replace([' ', '\n'], "");
    assert!(src.contains(kernel));
    let src = generate_file(&model, &compact_opts())
        .unwrap()
        .replace([' ', '\n'], "");
    assert!(src.contains(kernel));
}
