//! Per-step time of the compiled simulator (`kanegen::scene!`) against the interpreted one
//! (`kanegen::sim`). Both run the one right-hand side `kanegen_runtime::scene::deriv` under the
//! same integrators (`kanegen::ode`); they differ in its provider and sizes: the compiled run
//! over the generated dynamics of the scene's model (`NameModel`), through
//! `kanegen_runtime::scene::SceneOde`, specialized to the scene's effects as a `const`
//! (`SceneModel::EFFECTS`: what the scene does not name is compiled out), state and scratch on
//! the stack; the interpreted run over the run-time algorithms, sized at run time.
//!
//! The first group runs the SSRMS effects scene (`scenes/ssrms_effects.toml`: lunar gravity, PD
//! drives, joint damping, a tabulated inertial-frame wrench at the wrist; RK4, 1000 steps of
//! 0.01 s): each benchmark integrates the whole scene, so the time per step is the reported
//! time / 1000. The interpreted run is the `kanegen simulate` loop (`simulate_to`, samples to a
//! sink that drops them) on its run-time fast path (the workspace ABA), and on the LDLᵀ path
//! with the `recurrent` algorithm (`SimulationSpec::forward = Ldlt`, what naming an algorithm
//! selects); the compiled run calls an observer that does nothing.
//!
//! Run: `cargo bench --bench scene`. Compare within one run; the machines are shared. Measured
//! (two runs, LDLᵀ recurrent then the only interpreted path): compiled 1.67 / 1.44 ms,
//! interpreted 20.5 / 18.3 ms per run, 12.3× / 12.7×. With the fast path (one run): compiled
//! 1.52 ms, interpreted 9.24 ms, interpreted LDLᵀ recurrent 21.1 ms.
//!
//! The second group runs the capture scene (`scenes/capture_free_floating.toml`: the
//! free-floating 7-dof arm, PD drives, dopri5 at 1e-11, a capture at 2 s and a release at 6 s;
//! the compiled run integrates segment by segment and applies the capture impulse over the
//! generated mass matrices and frame Jacobian). Measured
//! (one run, the machine busy with a build): compiled 6.1 ms (3.8–7.1), interpreted 129 ms
//! (124–134) per run, 21× (about 10 µs against 210 µs per dopri5 step).

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate_to, Control, Sample};
use std::time::Duration;

kanegen::scene!(SsrmsEffects, "scenes/ssrms_effects.toml");
kanegen::scene!(Capture, "scenes/capture_free_floating.toml");
kanegen::scene!(SsrmsFlexible, "scenes/ssrms_flexible.toml");

fn scene_run(c: &mut Criterion) {
    bench_scene(
        c,
        "ssrms_effects run (1000 RK4 steps)",
        "scenes/ssrms_effects.toml",
        &|| {
            let mut last = 0.0;
            SsrmsEffects::run(|t, s| last = t + s.q[0]).unwrap();
            last
        },
    );
    bench_scene(
        c,
        "capture_free_floating run (dopri5, 613 steps, a capture and a release)",
        "scenes/capture_free_floating.toml",
        &|| {
            let mut last = 0.0;
            Capture::run(|t, s| last = t + s.q[7]).unwrap();
            last
        },
    );
}

/// The compiled run `compiled` against `simulate_to` on the scene `file`, side by side.
fn bench_scene(c: &mut Criterion, group: &str, file: &str, compiled: &dyn Fn() -> f64) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let scene = Scene::load(&path).unwrap();
    let mut g = c.benchmark_group(group);
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("compiled", |b| b.iter(|| black_box(compiled())));
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
