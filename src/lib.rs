//! # kanegen
//!
//! Equations of motion of space manipulators, `M(q) q̈ + c(q, q̇) = τ`, as unrolled,
//! allocation-free, `no_std` Rust generated at compile time for one fixed robot
//! ([`dynamics!`]), and — behind features — the whole pipeline that produces and checks it.
//!
//! | feature | what it adds |
//! |---|---|
//! | (none) | [`dynamics!`], [`scene!`] and their runtime support (`libm`, [`ode`]): builds for `#![no_std]` targets |
//! | `std` | the library crates: [`model`] (robots as plain data, URDF/TOML readers), [`dynamics`] (algorithms generic over the scalar), [`trace`] (the counting tracer, Table 1), [`codegen`] (the emitter), [`sim`] (scenes, integrators) |
//! | `nalgebra` | [`nalgebra`](crate::nalgebra) conversions of generated arrays (f64 and f32) |
//! | `rayon` | `runtime::par`: a generated function's batch (`NAME_batch`) split across threads (needs `std` on the target, not the `std` feature) |
//! | `cli` (default) | the `kanegen` command line, and [`cli`] (with `std`, `nalgebra`, `rayon`) |
//!
//! A `#![no_std]` controller depends on `kanegen = { version = "…", default-features = false }`.
#![no_std]
#![warn(missing_docs)]

#[cfg(feature = "std")]
extern crate std;

/// Unrolled, allocation-free, `no_std` dynamics of a fixed model, generated at compile time.
///
/// `dynamics!(Name, "path/to/model.urdf" [, base = "free-floating"] [, gravity = [x, y, z]]
/// [, allow_nonphysical = true] [, allow_large = true] [, ignore_mimic = true] [, runtime_payload = true] [, scalar = f32] [, fma = true]
/// [, fma_path = f64::mul_add] [, target_fma = false] [, regroup = false] [, canonical = false]
/// [, libm_trig = true] [, snap = 1e-9] [, algorithm = "recurrent"] [, form = "compact"] [, derivatives = false])` defines `pub struct Name;` with the associated constants `N`,
/// `JOINTS`, `FRAMES`, `OP_COUNTS`, `CANDIDATES` and, on `&[f64; N]` arrays, the functions of
/// `M(q) q̈ + c(q, q̇) = τ`: `mass_matrix(q)`, `nonlinear_effects(q, qd)`,
/// `inverse_dynamics(q, qd, qdd)`, `forward_dynamics(q, qd, tau)`,
/// `forward_dynamics_with_wrenches(q, qd, tau, f_ext)`, `mass_matrix_and_nonlinear_effects(q, qd)`,
/// `gravity(q)` with gravity, each named frame's `<frame>_placement(q)` and
/// `<frame>_jacobian(q)`, and the derivatives `inverse_dynamics_derivatives(q, qd, qdd)`
/// (`(∂τ/∂q, ∂τ/∂q̇)`), `forward_dynamics_derivatives(q, qd, tau)` (`(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)`)
/// and `mass_matrix_inverse(q)` (unrolled form up to 24 speeds; `docs/limits.md`). With `base = "free-floating"` (or a model whose base is free-floating)
/// the arguments are Pinocchio's free-flyer `q` (`NQ = 7 + N`: base position, quaternion
/// `[x, y, z, w]`, joints) and `v` (`NV = 6 + N`: base linear and angular velocity in base
/// coordinates, joint rates), and `momentum(q, v)`, `base_reaction(q, v, a)` and each frame's
/// `<frame>_generalized_jacobian(q)` come in (`docs/codegen.md`, "Generated API and its sign convention"). It also defines `NameOpCount` (the entries of
/// `OP_COUNTS`) and, with `runtime_payload = true`, `NamePayload`, the last body's mass
/// properties, taken by every function as a last argument `payload: &NamePayload`.
///
/// `scalar = f32` (default `f64`) emits `f32` code: arrays, payload fields, constants (the
/// model's numbers rounded) and libm calls. `fma = true` fuses each single-use product into its
/// sum or difference as one call `fma(a, b, c)` = `a·b + c`, by default libm's `fma` / `fmaf`;
/// `fma_path = PATH` calls `PATH(a, b, c)` instead (e.g. `f64::mul_add`, which needs `std`).
/// Without `fma = true` the same products fuse through a private `Name::mul_add`: one fused
/// instruction where the build targets FMA (`x86_64` with `target_feature = "fma"`, e.g.
/// `-C target-cpu=native`; AArch64), `a·b + c` elsewhere, where results are bit-identical to
/// unfused code; `target_fma = false` writes every product and sum out instead.
/// `regroup = false` keeps the model's own inertial parameters in the local-frame algorithms
/// (by default each revolute body's axis mass is carried by its parent, as Khalil and
/// Kleinfinger regroup the inertial parameters: the same `M`, `c` and `τ` in fewer operations; the header says
/// what moved). `canonical = false` traces every function in the model's own body frames only
/// (by default the joint-space functions are also traced in canonical frames, every joint axis
/// z, and the cheaper is emitted; the header's table says which). `f64` code takes sines and
/// cosines from its own `Name::sincos` (a table of 128 sines and short polynomials, branch-free,
/// within 1 ulp of 1 of libm's: `docs/accuracy.md`); `libm_trig = true` calls libm's instead.
/// `snap = TOL` (default 1e-15, `0.0` off) snaps float noise in the model before
/// tracing: rotations within `TOL` of a signed permutation become it, smaller offsets and
/// inertia entries 0 (Panda's `cos(π/2) = 6.1e-17` residues: (M, c) in 1455 operations instead
/// of 2122 before canonical frames); the header says how many numbers moved and by how much. `algorithm = NAME` forces
/// one algorithm (`recurrent`, the paper's; `recurrent-r1`, `kane-direct`, `crba-inertial`,
/// `spatial`, `aba`) for every function with a mass-matrix, nonlinear-effects or forward method instead of
/// the cheapest candidate; a chain-only algorithm on a tree is a compile error naming the
/// branching joint.
///
/// `form = "auto"` (default) emits straight-line code for small models and, above 4,000
/// emitted operations in the unrolled `M + c` (N ≥ 8 with general geometry), compact code:
/// loops over constant tables of the model's numbers (CRBA, RNEA, ABA), which builds in seconds
/// at N = 64 and runs faster there (`docs/codegen.md`, "Compact form"); `form = "unrolled"` and
/// `form = "compact"` force one (compact: fixed base only). The header
/// says which form was emitted and why.
///
/// The path is relative to the calling crate's `CARGO_MANIFEST_DIR`; the crate is rebuilt when
/// the file changes. A missing, malformed or non-physical model is a compile error at the path.
///
/// ```
/// kanegen::dynamics!(TwoLink, "models/two_link.toml");
/// let q = [0.1, 0.2];
/// let m = TwoLink::mass_matrix(&q);
/// assert_eq!(TwoLink::N, 2);
/// assert_eq!(m[0][1], m[1][0]);
/// // M q̈ + c = τ, with c = τ at q̈ = 0.
/// let qd = [0.3, -0.4];
/// let c = TwoLink::nonlinear_effects(&q, &qd);
/// assert_eq!(TwoLink::inverse_dynamics(&q, &qd, &[0.0; 2]), c);
/// ```
#[macro_export]
macro_rules! dynamics {
    ($($input:tt)*) => {
        $crate::__private::dynamics!($crate; $($input)*);
    };
}

/// A simulator specialized at compile time for one scene file (`docs/scenes.md`).
///
/// `scene!(Name, "scenes/x.toml")` reads the scene as `kanegen simulate` does
/// (`kanegen::sim::scene`) and defines:
///
/// - `NameDynamics`, the [`dynamics!`] of the scene's model with the scene's base, gravity and
///   payload (plus one frame `scene_wrench_K` on each body loaded by an inertial-frame wrench,
///   or by any wrench with a computed-torque drive);
/// - `NameState`, the state in fixed-size arrays: `q` and `qd` (`N` each) on a fixed base; on a
///   free-floating base the free-flyer layout `q = [p₀, quaternion x y z w, joints]`,
///   `v = [v_b, ω_b, q̇]` (base coordinates), with `to_array`/`from_array` for the flat vector
///   `[q, v]` of the interpreted simulator;
/// - `pub struct Name;` with `N`, `DIM`, `DURATION`, `STEP`, `TOLERANCE`, `OUTPUT_EVERY`,
///   `initial_state()`, `rhs(t, &state)` (the derivative, same layout; only the effects the
///   scene names: its drives — constant, PD or computed torque —, joint damping, constant or
///   tabulated wrenches in the body or inertial frame, gravity), `step(t, &mut state, h)` (one
///   step of the scene's fixed-step integrator: RK4, the quaternion renormalized, or the implicit
///   midpoint rule; RK4 for a dopri5 scene) and `run(|t, &state| …)`, which integrates over the
///   scene's duration with the scene's integrator — fixed-step RK4, the Lie-group implicit
///   midpoint rule, or for `integrator = "dopri5"` the adaptive Dormand–Prince 5(4) with the
///   scene's tolerance and its dense output ([`ode`]) — calling the observer at the scene's
///   output times.
///
/// The code is allocation-free, panic-free and `no_std`, and agrees with the interpreted
/// simulator to the rounding of the right-hand side (`tests/scene_macro.rs`). The scene's
/// `simulation.algorithm` only selects how the interpreted simulator evaluates the dynamics: the
/// generated functions use the cheapest method (the same values to rounding). A computed-torque
/// drive compensates constant wrenches through the generated Jacobians (`τ −= Jᵀ w`). The one
/// scene feature the generated simulator does not reproduce — a tabulated wrench with a
/// computed-torque drive, which the interpreted controller compensates at its `t = 0` value — and
/// every scene error are compile errors naming the key and the file.
///
/// ```
/// kanegen::scene!(Srms, "scenes/srms.toml");
/// let mut last = Srms::initial_state();
/// let stats = Srms::run(|_t, s| last = *s).unwrap();
/// assert!(stats.steps > 0 && (last.q[0] - 0.4).abs() < 0.05);
/// ```
#[macro_export]
macro_rules! scene {
    ($($input:tt)*) => {
        $crate::__private::scene!($crate; $($input)*);
    };
}

/// The integrators of [`scene!`]'s simulators and of the interpreted simulator
/// (`kanegen-runtime`'s, `no_std`): RK4, Dormand–Prince 5(4), Rodas4, the Lie-group implicit
/// midpoint rule, with their [`Stats`](ode::Stats) and stop reasons ([`Stop`](ode::Stop)).
pub use kanegen_runtime::ode;

/// Support for the code emitted by [`dynamics!`] and [`scene!`]; not a public API.
#[doc(hidden)]
pub mod __private {
    pub use kanegen_macros::{dynamics, scene};
    pub use kanegen_runtime as runtime;
    pub use libm;
}

/// The `no_std` runtime that generated code, the simulator and the run-time path share
/// (`kanegen-runtime`): the scalar trait, integrators, sine–cosine, LDLᵀ, the parallel-axis shift,
/// and the lane types of the generated `NAME_lanes` functions (`runtime::lanes`).
pub use kanegen_runtime as runtime;

#[cfg(feature = "std")]
pub use kanegen_codegen as codegen;
#[cfg(feature = "std")]
pub use kanegen_dynamics as dynamics;
#[cfg(feature = "std")]
pub use kanegen_model as model;
#[cfg(feature = "std")]
pub use kanegen_sim as sim;
#[cfg(feature = "std")]
pub use kanegen_trace as trace;

#[cfg(feature = "cli")]
pub use kanegen_cli as cli;

#[cfg(feature = "nalgebra")]
pub mod nalgebra;
