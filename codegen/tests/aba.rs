//! Forward dynamics chosen per model between LDLᵀ on `M` and `c` and the articulated-body
//! algorithm: the emitted operation counts of both for SSRMS and random chains
//! (`benches/data`'s seeds), the table of `dynamics/src/algorithms/aba.rs` checked against a
//! fresh measurement (it fails when stale), the crossovers it states, and the time a chain of
//! 64 joints takes to trace and emit.

use kanegen_codegen::{choose, generate_file, Options};
use kanegen_dynamics::{ForwardMethod, MassMatrixMethod, Methods};
use kanegen_model::random::{random_chain, ChainSpec};
use kanegen_model::Model;
use kanegen_trace::{Counts, Function};
use std::path::Path;
use std::time::Instant;

/// The random chains of the table: `random_chain(N, seed 1000 + N)`, as `benches/data`.
const SIZES: [usize; 5] = [4, 8, 16, 32, 64];

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn chain(n: usize) -> Model {
    random_chain(
        &ChainSpec {
            n,
            ..Default::default()
        },
        1000 + n as u64,
    )
}

/// One row of the table: emitted counts of the generated `forward_dynamics` (regrouped
/// parameters, no gravity, in the body frames the generator chose, as it traces them) by LDLᵀ on the CRBA's `M` and the
/// RNEA's `c`, by the cheapest LDLᵀ candidate the generator has (its chosen mass-matrix method,
/// every nonlinear-effects method), and by ABA; and the method it emits.
struct Row {
    spatial: Counts,
    best_ldlt: Counts,
    aba: Counts,
    chosen: Methods,
}

fn measure(model: &Model) -> Row {
    let opts = Options::new("M");
    let (m, _) =
        choose::choose(model, Function::MassMatrix, MassMatrixMethod::Crba, &opts).unwrap();
    let (fd, _) = choose::choose(
        model,
        Function::ForwardDynamics,
        m.chosen.mass_matrix,
        &opts,
    )
    .unwrap();
    let spatial = if m.chosen.mass_matrix == MassMatrixMethod::Crba {
        fd.candidates
            .iter()
            .find(|c| c.methods == Methods::SPATIAL && c.frames == fd.frames)
            .unwrap()
            .counts
    } else {
        // The generator would not pair LDLᵀ with the CRBA here; trace that pair alone.
        let (c, _) = choose::choose(
            model,
            Function::ForwardDynamics,
            MassMatrixMethod::Crba,
            &opts,
        )
        .unwrap();
        c.candidates
            .iter()
            .find(|c| c.methods == Methods::SPATIAL && c.frames == fd.frames)
            .unwrap()
            .counts
    };
    let best_ldlt = fd
        .candidates
        .iter()
        .filter(|c| c.methods.forward == ForwardMethod::Ldlt && c.frames == fd.frames)
        .map(|c| c.counts)
        .min_by_key(Counts::total)
        .unwrap();
    let aba = fd
        .candidates
        .iter()
        .find(|c| c.methods == Methods::ABA && c.frames == fd.frames)
        .unwrap()
        .counts;
    Row {
        spatial,
        best_ldlt,
        aba,
        chosen: fd.chosen,
    }
}

/// The rows `| model | N | crba+rnea | cheapest LDLᵀ | aba | div | emitted |` of the table in
/// `aba.rs`, as strings.
fn doc_table() -> Vec<Vec<String>> {
    let src = std::fs::read_to_string(root().join("dynamics/src/algorithms/aba.rs")).unwrap();
    src.lines()
        .filter_map(|l| l.strip_prefix("//! | "))
        .filter(|l| l.starts_with("SSRMS") || l.starts_with("random chain"))
        .map(|l| {
            l.trim_end_matches(" |")
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

#[test]
fn the_op_count_table_in_aba_rs_is_current() {
    let ssrms = kanegen_model::io::load_model(
        &root().join("tests/data/reference/ssrms_nguyen_hughes_1994.urdf"),
    )
    .unwrap();
    let mut models = vec![("SSRMS (Nguyen & Hughes 1994)".to_string(), ssrms)];
    models.extend(SIZES.map(|n| ("random chain".to_string(), chain(n))));
    let doc = doc_table();
    assert_eq!(doc.len(), models.len(), "rows of the table in aba.rs");
    let mut stale = Vec::new();
    for ((name, model), row) in models.iter().zip(&doc) {
        let r = measure(model);
        let fresh: Vec<String> = vec![
            name.clone(),
            model.dof().to_string(),
            r.spatial.total().to_string(),
            r.best_ldlt.total().to_string(),
            r.aba.total().to_string(),
            format!("{} / {}", r.best_ldlt.div, r.aba.div),
            if r.chosen == Methods::ABA {
                "ABA"
            } else {
                "LDLᵀ"
            }
            .to_string(),
        ];
        println!("| {} |", fresh.join(" | "));
        if &fresh != row {
            stale.push(format!(
                "have | {} |, measured | {} |",
                row.join(" | "),
                fresh.join(" | ")
            ));
        }
        // The cheaper is emitted; LDLᵀ on ties.
        assert_eq!(
            r.chosen == Methods::ABA,
            r.aba.total() < r.best_ldlt.total()
        );
    }
    assert!(
        stale.is_empty(),
        "aba.rs's table is stale:\n{}",
        stale.join("\n")
    );
}

/// The crossovers on random chains the doc states (every N from 4 to 24, then 32, 48, 64):
/// ABA is cheaper than LDLᵀ on the CRBA and the RNEA from N = 11 on, and than the generator's
/// cheapest LDLᵀ from N = 13 on, and stays so; the generator emits it from there.
#[test]
fn aba_wins_on_random_chains_from_the_stated_crossovers() {
    let sizes = (4..=24).chain([32, 48, 64]);
    let (mut first_spatial, mut first_emitted) = (None, None);
    for n in sizes {
        let r = measure(&chain(n));
        println!(
            "N = {n:2}: LDLᵀ (CRBA + RNEA) {:6}, cheapest LDLᵀ {:6}, ABA {:6}, emitted {}",
            r.spatial.total(),
            r.best_ldlt.total(),
            r.aba.total(),
            r.chosen.name()
        );
        for (wins, first, what) in [
            (
                r.aba.total() < r.spatial.total(),
                &mut first_spatial,
                "CRBA + RNEA",
            ),
            (r.chosen == Methods::ABA, &mut first_emitted, "emitted"),
        ] {
            match (wins, *first) {
                (true, None) => *first = Some(n),
                (false, Some(k)) => panic!("{what}: ABA wins at N = {k} but not at N = {n}"),
                _ => {}
            }
        }
    }
    assert_eq!((first_spatial, first_emitted), (Some(11), Some(13)));
}

/// Tracing, choosing and emitting the whole generated file of a 64-joint chain (every function,
/// every candidate) stays a matter of seconds.
#[test]
fn a_64_joint_chain_generates_in_seconds() {
    let m = chain(64);
    let t = Instant::now();
    let src = generate_file(&m, &Options::new("Chain64")).unwrap();
    let s = t.elapsed().as_secs_f64();
    println!("N = 64: generate_file {s:.2} s, {} bytes", src.len());
    assert!(src.contains("forward dynamics by `ldlt` on `M` and `c`, or by `aba`"));
    assert!(s < 120.0, "{s} s");
}
