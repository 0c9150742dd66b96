//! The generated functions allocate nothing: a global allocator counting each thread's
//! allocations is read (on the test's thread) before and
//! after many calls of every function (generated crate and `dynamics!` output), and around whole
//! runs of `scene!` simulators (RK4 with a tabulated wrench, dopri5 on a free-floating base),
//! and around the interpreted simulator's right-hand side on its run-time fast path (the
//! workspace ABA: a tabulated wrench, rotor inertia and friction, a free-floating base).

use std::alloc::{GlobalAlloc, Layout, System};

struct Counting;

thread_local! {
    /// Allocations of this thread: the test harness's other threads may allocate meanwhile (a
    /// process-wide count saw 4 foreign allocations in 2 of 4 runs once the scene runs were
    /// added). A `const` `Cell` needs no allocation.
    static THREAD_ALLOCATIONS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

fn count() {
    let _ = THREAD_ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

/// Allocations made by the calling thread so far.
fn allocations() -> usize {
    THREAD_ALLOCATIONS.with(std::cell::Cell::get)
}

// SAFETY: forwards to `System`; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: the caller upholds `alloc`'s contract.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller upholds `dealloc`'s contract.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: the caller upholds `realloc`'s contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

kanegen::dynamics!(
    Random5,
    "tests/data/codegen/random5.toml",
    gravity = [0.0, 0.0, -9.81],
    runtime_payload = true
);

use kanegen_generated::ssrms::Ssrms;

kanegen::scene!(SsrmsEffects, "scenes/ssrms_effects.toml");
kanegen::scene!(FreeFloating7, "scenes/free_floating_7dof.toml");

/// The scene runs (called from the one test: the counter is global, a second test thread's
/// allocations would count).
fn scene_runs_do_not_allocate() {
    let mut acc = 0.0;
    let before = allocations();
    let a = SsrmsEffects::run(|t, s| acc += t + s.q[0]).unwrap();
    let b = FreeFloating7::run(|t, s| acc += t + s.v[0]).unwrap();
    let mut st = SsrmsEffects::initial_state();
    SsrmsEffects::step(0.5, &mut st, 0.01).unwrap();
    let d = FreeFloating7::rhs(0.0, &FreeFloating7::initial_state());
    assert_eq!(allocations(), before);
    assert!(a.steps == 1000 && b.steps > 0 && acc.is_finite() && st.q[0].is_finite());
    assert!(d.q[3].is_finite());
}

/// The interpreted simulator's right-hand side on the run-time fast path, once its
/// `SceneSystem` is built (called from the one test, as above).
fn runtime_fast_path_does_not_allocate() {
    use kanegen::sim::integrate::System;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in [
        "scenes/ssrms_effects.toml",
        "scenes/ssrms_drives.toml",
        "scenes/free_floating_7dof.toml",
    ] {
        let scene = kanegen::sim::scene::Scene::load(&root.join(name)).unwrap();
        let mut sys = kanegen::sim::simulate::SceneSystem::new(&scene);
        let x = sys.initial_state();
        let mut dx = vec![0.0; x.len()];
        let before = allocations();
        for k in 0..100 {
            sys.deriv(0.03 * f64::from(k), &x, &mut dx);
        }
        assert_eq!(allocations(), before, "{name}");
        assert!(dx.iter().all(|v| v.is_finite()));
    }
}

#[test]
fn generated_functions_do_not_allocate() {
    scene_runs_do_not_allocate();
    runtime_fast_path_does_not_allocate();
    // The counter itself works: a Vec allocates.
    let before = allocations();
    let v = std::hint::black_box(vec![1.0f64; 16]);
    assert!(allocations() > before);
    drop(v);

    let payload = Random5Payload::NOMINAL;
    let mut acc = 0.0;
    let before = allocations();
    for k in 0..1000 {
        let x = f64::from(k) * 1e-3;
        let q7 = std::hint::black_box([x, 0.1, -0.2, 0.3, x, 0.5, -x]);
        let a = Ssrms::mass_matrix(&q7);
        let c = Ssrms::nonlinear_effects(&q7, &q7);
        let (m, h) = Ssrms::mass_matrix_and_nonlinear_effects(&q7, &q7);
        let t = Ssrms::inverse_dynamics(&q7, &q7, &q7);
        let f = Ssrms::forward_dynamics(&q7, &q7, &q7);
        acc += a[6][6] + c[0] + m[0][1] + h[1] + t[2] + f[3];
        let q5 = std::hint::black_box([x, 0.1, -0.2, 0.3, x]);
        let a = Random5::mass_matrix(&q5, &payload);
        let c = Random5::nonlinear_effects(&q5, &q5, &payload);
        let g = Random5::gravity(&q5, &payload);
        let (m, h) = Random5::mass_matrix_and_nonlinear_effects(&q5, &q5, &payload);
        let t = Random5::inverse_dynamics(&q5, &q5, &q5, &payload);
        let f = Random5::forward_dynamics(&q5, &q5, &q5, &payload);
        acc += a[4][4] + c[0] + g[1] + m[1][0] + h[2] + t[2] + f[3];
    }
    let after = allocations();
    assert!(acc.is_finite());
    assert_eq!(
        after - before,
        0,
        "generated code allocated {} times",
        after - before
    );
}
