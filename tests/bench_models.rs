//! The random-chain models the criterion benches compile through `kanegen::dynamics!` are
//! committed files; this test regenerates them from `random_chain` and fails when they are stale
//! (`KANEGEN_BLESS=1 cargo test --release --test bench_models` rewrites them).

use kanegen::model::io::to_toml;
use kanegen::model::random::{random_chain, ChainSpec};

/// Sizes of the benchmarked random chains.
pub const SIZES: [usize; 9] = [2, 4, 8, 12, 16, 24, 32, 48, 64];

#[test]
fn bench_models_are_current() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/data");
    let bless = std::env::var_os("KANEGEN_BLESS").is_some();
    for n in SIZES {
        let chain = random_chain(
            &ChainSpec {
                n,
                ..Default::default()
            },
            1000 + n as u64,
        );
        let text = to_toml(&chain);
        let path = dir.join(format!("random_n{n}.toml"));
        if bless {
            std::fs::write(&path, &text).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == text,
            "{} is stale: rerun with KANEGEN_BLESS=1",
            path.display()
        );
    }
}
