//! Per-step time of the compiled simulator (`kanegen::scene!`) against the interpreted one
//! (`kanegen::sim`) on the SSRMS effects scene (`scenes/ssrms_effects.toml`: lunar gravity, PD
//! drives, joint damping, a tabulated inertial-frame wrench at the wrist; RK4, 1000 steps of
//! 0.01 s), side by side in one run: each benchmark integrates the whole scene, so the time per
//! step is the reported time / 1000. The interpreted run is the `kanegen simulate` loop
//! (`simulate_to`, its `recurrent` algorithm, samples to a sink that drops them); the compiled
//! run calls an observer that does nothing.
//!
//! Run: `cargo bench --bench scene`. Compare within one run; the machines are shared. Measured
//! (two runs): compiled 1.67 / 1.44 ms, interpreted 20.5 / 18.3 ms per run, 12.3× / 12.7×.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate_to, Control, Sample};
use std::time::Duration;

kanegen::scene!(SsrmsEffects, "scenes/ssrms_effects.toml");
kanegen::scene!(SsrmsFlexible, "scenes/ssrms_flexible.toml");

fn scene_run(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ssrms_effects.toml");
    let scene = Scene::load(&path).unwrap();
    let mut g = c.benchmark_group("ssrms_effects run (1000 RK4 steps)");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("compiled", |b| {
        b.iter(|| {
            let mut last = 0.0;
            SsrmsEffects::run(|t, s| last = t + s.q[0]).unwrap();
            black_box(last)
        })
    });
    g.bench_function("interpreted", |b| {
        b.iter(|| {
            let mut sink = |s: &Sample| -> anyhow::Result<()> {
                black_box(s.x[0]);
                Ok(())
            };
            simulate_to(black_box(&scene), &mut sink, Control::default()).unwrap()
        })
    });
    g.finish();
}

/// The flexible-joint SSRMS (`scenes/ssrms_flexible.toml`, 30 s, Rodas4 at 1e-8: 527 steps
/// interpreted, 528 compiled, each with a difference-quotient Jacobian of 2·28 + 2 evaluations,
/// one 28×28 LU and 5 more evaluations): time per step = reported time / steps. Measured (one
/// run, beside another build): compiled 20.3 ms (38.5 µs per step), interpreted 270 ms
/// (512 µs per step), 13.3×.
fn flexible_run(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ssrms_flexible.toml");
    let scene = Scene::load(&path).unwrap();
    let mut g = c.benchmark_group("ssrms_flexible run (Rodas4, ~690 steps)");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("compiled", |b| {
        b.iter(|| {
            let mut last = 0.0;
            SsrmsFlexible::run(|t, s| last = t + s.q[0]).unwrap();
            black_box(last)
        })
    });
    g.bench_function("interpreted", |b| {
        b.iter(|| {
            let mut sink = |s: &Sample| -> anyhow::Result<()> {
                black_box(s.x[0]);
                Ok(())
            };
            simulate_to(black_box(&scene), &mut sink, Control::default()).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, scene_run, flexible_run);
criterion_main!(benches);
