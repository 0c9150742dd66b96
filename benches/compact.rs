//! Unrolled against compact generated code (`form = "unrolled"` / `"compact"`), side by side in
//! one process: `M`, `M + c`, `c`, inverse and forward dynamics on the random chains N = 2 … 32 of
//! `benches/data/` and on SSRMS. N = 48 and 64 (whose unrolled build takes minutes) are timed by
//! `tools/compact/measure.sh`, which also times the builds.
//!
//! Run: `cargo bench --bench compact`. Compare ratios within one run; the machines are shared.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use kanegen::model::random::{random_vec, rng};
use std::time::Duration;

macro_rules! pair {
    ($u:ident, $c:ident, $file:literal) => {
        kanegen::dynamics!($u, $file, form = "unrolled");
        kanegen::dynamics!($c, $file, form = "compact");
    };
}
pair!(U2, C2, "benches/data/random_n2.toml");
pair!(U4, C4, "benches/data/random_n4.toml");
pair!(U8, C8, "benches/data/random_n8.toml");
pair!(U12, C12, "benches/data/random_n12.toml");
pair!(U16, C16, "benches/data/random_n16.toml");
pair!(U24, C24, "benches/data/random_n24.toml");
pair!(U32, C32, "benches/data/random_n32.toml");
pair!(
    Ussrms,
    Cssrms,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf"
);

fn state<const N: usize>(seed: u64) -> ([f64; N], [f64; N]) {
    let mut r = rng(seed);
    let q = random_vec(&mut r, N, 3.0);
    let qd = random_vec(&mut r, N, 0.5);
    (
        core::array::from_fn(|i| q[i]),
        core::array::from_fn(|i| qd[i]),
    )
}

macro_rules! forms {
    ($fn:ident, $u:ident, $c:ident, $name:literal) => {
        fn $fn(c: &mut Criterion) {
            const N: usize = $u::N;
            let (q, qd) = state::<N>(N as u64);
            let mut g = c.benchmark_group($name);
            g.bench_function("M/unrolled", |b| b.iter(|| $u::mass_matrix(black_box(&q))));
            g.bench_function("M/compact", |b| b.iter(|| $c::mass_matrix(black_box(&q))));
            g.bench_function("M+c/unrolled", |b| {
                b.iter(|| $u::mass_matrix_and_nonlinear_effects(black_box(&q), black_box(&qd)))
            });
            g.bench_function("M+c/compact", |b| {
                b.iter(|| $c::mass_matrix_and_nonlinear_effects(black_box(&q), black_box(&qd)))
            });
            g.bench_function("c/unrolled", |b| {
                b.iter(|| $u::nonlinear_effects(black_box(&q), black_box(&qd)))
            });
            g.bench_function("c/compact", |b| {
                b.iter(|| $c::nonlinear_effects(black_box(&q), black_box(&qd)))
            });
            g.bench_function("ID/unrolled", |b| {
                b.iter(|| $u::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qd)))
            });
            g.bench_function("ID/compact", |b| {
                b.iter(|| $c::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qd)))
            });
            g.bench_function("FD/unrolled", |b| {
                b.iter(|| $u::forward_dynamics(black_box(&q), black_box(&qd), black_box(&qd)))
            });
            g.bench_function("FD/compact", |b| {
                b.iter(|| $c::forward_dynamics(black_box(&q), black_box(&qd), black_box(&qd)))
            });
            g.finish();
        }
    };
}
forms!(n2, U2, C2, "random N=2");
forms!(n4, U4, C4, "random N=4");
forms!(n8, U8, C8, "random N=8");
forms!(n12, U12, C12, "random N=12");
forms!(n16, U16, C16, "random N=16");
forms!(n24, U24, C24, "random N=24");
forms!(n32, U32, C32, "random N=32");
forms!(ssrms, Ussrms, Cssrms, "SSRMS");

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
        .sample_size(20);
    targets = ssrms, n2, n4, n8, n12, n16, n24, n32
}
criterion_main!(benches);
