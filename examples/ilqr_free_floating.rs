//! iLQR (Li & Todorov 2004; Tassa, Erez & Todorov 2012) on a generated free-floating space
//! manipulator with the step Jacobians of `scene!` in the tangent space of the base's pose:
//! the 7-dof arm on its 1000 kg base, at rest in orbit (no gravity, zero momentum), is taken to
//! a goal configuration at rest in 1 s by joint torques, while the base's attitude, which
//! turns as the arm moves (the momentum stays zero), is held near its start.
//!
//! The state has 27 numbers (`[p₀, quat, q, v_b, ω_b, q̇]`) and 26 directions:
//! `FreeFloating::step_jacobians` returns `A` (26 × 26) and `B` (26 × 7) in the tangent space
//! of Pinocchio's `integrate` (the pose as `[δp; δθ]` in base coordinates), so the feedback
//! acts on the tangent difference `x ⊖ x̄`
//! (`kanegen::runtime::ode::quaternion::floating_difference`) and the cost on the attitude is
//! that of `2 vec(quat₀* ⊗ quat)`. The iLQR itself is `examples/support/ilqr.rs`, shared with
//! `--example ilqr`.
//!
//! Run: `cargo run --release --example ilqr_free_floating`

use kanegen::runtime::ode::quaternion::floating_difference;
use nalgebra::{SMatrix, SVector};
use std::time::Instant;

#[path = "support/ilqr.rs"]
mod ilqr;
use ilqr::Problem;

kanegen::scene!(FreeFloating, "scenes/free_floating_torque_input.toml");

/// Numbers of the state.
const DIM: usize = FreeFloating::DIM;
/// Directions of the state (the tangent space).
const D: usize = DIM - 1;
const N: usize = FreeFloating::N;
/// Knots of the horizon (1 s at the scene's step of 0.01 s).
const K: usize = 100;

type X = [f64; DIM];
type Dx = SVector<f64, D>;
type A = SMatrix<f64, D, D>;

/// The goal joint angles (at rest); the base attitude's goal is its start.
const Q_GOAL: [f64; N] = [0.6, -0.2, 0.5, -1.1, 0.4, 0.6, -0.3];

fn weights() -> ilqr::Weights<D, N> {
    // (attitude, joints, speeds) weights; the base's position is free.
    let diag = |att: f64, joint: f64, speed: f64| {
        A::from_fn(|i, j| match (i == j, i) {
            (false, _) | (true, 0..=2) => 0.0,
            (true, 3..=5) => att,
            (true, i) if i < 6 + N => joint,
            _ => speed,
        })
    };
    ilqr::Weights {
        q: diag(50.0, 1.0, 0.01),
        r: SMatrix::<f64, N, N>::identity() * 1e-6,
        qf: diag(2000.0, 2000.0, 500.0),
    }
}

/// The space manipulator's steps, in the tangent space of its base's pose.
struct SpaceArm;

impl Problem<D, N> for SpaceArm {
    type X = X;

    fn initial(&self) -> X {
        FreeFloating::initial_state().to_array()
    }

    fn step(&self, k: usize, x: &X, u: &SVector<f64, N>) -> (X, A, SMatrix<f64, D, N>) {
        let (s, h) = (FreeFloatingState::from_array(x), FreeFloating::STEP);
        let (next, a, b) =
            FreeFloating::step_jacobians(k as f64 * h, &s, &(*u).into(), h).expect("a finite step");
        (
            next.to_array(),
            A::from_fn(|i, j| a[i][j]),
            SMatrix::from_fn(|i, j| b[i][j]),
        )
    }

    fn difference(&self, x: &X, y: &X) -> Dx {
        let mut d = Dx::zeros();
        floating_difference(x, y, d.as_mut_slice());
        d
    }

    /// The attitude from the start's, the joints from `Q_GOAL`, every speed from zero.
    fn error(&self, x: &X) -> Dx {
        let mut goal = self.initial();
        goal[7..7 + N].copy_from_slice(&Q_GOAL);
        self.difference(&goal, x)
    }
}

fn main() {
    let start = Instant::now();
    let (t, rollouts) = ilqr::optimize(&SpaceArm, &weights(), K);
    let secs = start.elapsed().as_secs_f64();
    let e = SpaceArm.error(&t.x[K]);
    let worst_attitude =
        t.x.iter()
            .map(|x| SpaceArm.error(x).rows(3, 3).norm())
            .fold(0.0_f64, f64::max);
    println!(
        "final |q − q_goal| = {:.2e} rad, |q̇| = {:.2e} rad/s, base attitude {:.2e} rad from its start (at most {:.2e} on the way), |ω_b| = {:.2e} rad/s, after {:.1} s of motion",
        e.rows(6, N).norm(),
        e.rows(12 + N, N).norm(),
        e.rows(3, 3).norm(),
        worst_attitude,
        e.rows(9 + N, 3).norm(),
        K as f64 * FreeFloating::STEP
    );
    println!(
        "{rollouts} rollouts of {K} linearized steps in {:.3} s ({:.2} µs a step with its (A, B), backward passes included)",
        secs,
        secs * 1e6 / (rollouts * K) as f64
    );
}
