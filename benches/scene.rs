//! Per-step time of the compiled simulator (`kanegen::scene!`) against the interpreted one
//! (`kanegen::sim`) on the SSRMS effects scene (`scenes/ssrms_effects.toml`: lunar gravity, PD
//! drives, joint damping, a tabulated inertial-frame wrench at the wrist; RK4, 1000 steps of
//! 0.01 s), side by side in one run: each benchmark integrates the whole scene, so the time per
//! step is the reported time / 1000. The interpreted run is the `kanegen simulate` loop
//! (`simulate_to`, samples to a sink that drops them) on its run-time fast path (the workspace
//! ABA), and on the LDLᵀ path with the `recurrent` algorithm it used before
//! (`SimulationSpec::forward = Ldlt`, what naming an algorithm selects); the compiled run calls
//! an observer that does nothing.
//!
//! Run: `cargo bench --bench scene`. Compare within one run; the machines are shared. Measured
//! (two runs, LDLᵀ recurrent then the only interpreted path): compiled 1.67 / 1.44 ms,
//! interpreted 20.5 / 18.3 ms per run, 12.3× / 12.7×. With the fast path (one run): compiled
//! 1.52 ms, interpreted 9.24 ms, interpreted LDLᵀ recurrent 21.1 ms.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate_to, Control, Sample};
use std::time::Duration;

kanegen::scene!(SsrmsEffects, "scenes/ssrms_effects.toml");

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
    // The run-time fast path (the scene names no algorithm) and the LDLᵀ path it replaced.
    let mut ldlt = scene.clone();
    ldlt.simulation.forward = kanegen::dynamics::ForwardMethod::Ldlt;
    for (name, s) in [
        ("interpreted", &scene),
        ("interpreted LDLᵀ recurrent", &ldlt),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut sink = |s: &Sample| -> anyhow::Result<()> {
                    black_box(s.x[0]);
                    Ok(())
                };
                simulate_to(black_box(s), &mut sink, Control::default()).unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, scene_run);
criterion_main!(benches);
