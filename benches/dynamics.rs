//! Generated code against the interpreted f64 algorithms (`recurrent`, `crba-inertial`, `spatial`):
//! SSRMS (the checked-in `kanegen-generated` code) and random chains N = 2, 4, 8, 16, 32
//! (compiled here through `kanegen::dynamics!` from `benches/data/random_n*.toml`).
//!
//! Run: `cargo bench --bench dynamics`. Compare ratios within one run; the machines are shared.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use kanegen::dynamics::Params;
use kanegen::dynamics::{Loads, Methods};
use kanegen::model::random::{random_vec, rng};
use kanegen::model::Model;
use kanegen_generated::ssrms::Ssrms;

kanegen::dynamics!(Rand2, "benches/data/random_n2.toml");
kanegen::dynamics!(Rand4, "benches/data/random_n4.toml");
kanegen::dynamics!(Rand8, "benches/data/random_n8.toml");
kanegen::dynamics!(Rand16, "benches/data/random_n16.toml");
kanegen::dynamics!(Rand32, "benches/data/random_n32.toml");

const INTERPRETED: [Methods; 3] = [Methods::RECURRENT, Methods::CRBA_INERTIAL, Methods::SPATIAL];

fn load(path: &str) -> Model {
    kanegen::model::io::load_model(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path))
        .unwrap()
}

fn state<const N: usize>(seed: u64) -> ([f64; N], [f64; N]) {
    let mut r = rng(seed);
    let q = random_vec(&mut r, N, 3.0);
    let qd = random_vec(&mut r, N, 0.5);
    (
        core::array::from_fn(|i| q[i]),
        core::array::from_fn(|i| qd[i]),
    )
}

fn interpreted(c: &mut Criterion, group: &str, chain: &Model, q: &[f64], qd: &[f64]) {
    let p = Params::<f64>::new(chain);
    let mut g = c.benchmark_group(group);
    for alg in INTERPRETED {
        g.bench_function(BenchmarkId::new("interpreted", alg.name()), |b| {
            b.iter(|| alg.dynamics(&p, black_box(q), black_box(qd), &Loads::default()))
        });
    }
    g.finish();
}

fn ssrms(c: &mut Criterion) {
    let chain = load("tests/data/reference/ssrms_nguyen_hughes_1994.urdf");
    let (q, qd) = state::<7>(7);
    c.bench_function("ssrms M+c/generated", |b| {
        b.iter(|| Ssrms::mass_matrix_and_nonlinear_effects(black_box(&q), black_box(&qd)))
    });
    interpreted(c, "ssrms M+c", &chain, &q, &qd);
}

macro_rules! random_chain_bench {
    ($fn:ident, $ty:ident, $n:literal) => {
        fn $fn(c: &mut Criterion) {
            let chain = load(concat!("benches/data/random_n", stringify!($n), ".toml"));
            let (q, qd) = state::<$n>($n);
            let group = concat!("random N=", stringify!($n), " M+c");
            c.bench_function(
                concat!("random N=", stringify!($n), " M+c/generated"),
                |b| {
                    b.iter(|| $ty::mass_matrix_and_nonlinear_effects(black_box(&q), black_box(&qd)))
                },
            );
            interpreted(c, group, &chain, &q, &qd);
        }
    };
}
random_chain_bench!(random2, Rand2, 2);
random_chain_bench!(random4, Rand4, 4);
random_chain_bench!(random8, Rand8, 8);
random_chain_bench!(random16, Rand16, 16);
random_chain_bench!(random32, Rand32, 32);

criterion_group!(benches, ssrms, random2, random4, random8, random16, random32);
criterion_main!(benches);
