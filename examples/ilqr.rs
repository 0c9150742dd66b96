//! iLQR (Li & Todorov 2004; Tassa, Erez & Todorov 2012) on a generated UR5 with the step
//! Jacobians of `scene!`: the arm, under gravity and joint damping with no drive, is taken from
//! its initial state to a goal at rest in 0.6 s by joint torques, the whole optimization
//! running on `Ur5::step_jacobians` (one RK4 step and its exact `(A, B)`, from the generated
//! derivatives of forward and inverse dynamics).
//!
//! Run: `cargo run --release --example ilqr`

use nalgebra::{SMatrix, SVector};
use std::time::Instant;

#[path = "support/ilqr.rs"]
mod ilqr;

kanegen::scene!(Ur5, "scenes/ur5_torque_input.toml");

const D: usize = Ur5::DIM;
const N: usize = Ur5::N;
/// Knots of the horizon (0.6 s at the scene's step of 0.01 s).
const K: usize = 60;

type X = SVector<f64, D>;
type A = SMatrix<f64, D, D>;

/// The goal: these joint angles, at rest.
fn goal() -> X {
    let q = [0.6, -0.6, 0.9, -0.8, 0.9, 0.4];
    X::from_fn(|i, _| if i < N { q[i] } else { 0.0 })
}

fn weights() -> ilqr::Weights<D, N> {
    let diag = |p: f64, v: f64| {
        A::from_fn(|i, j| {
            if i != j {
                0.0
            } else if i < N {
                p
            } else {
                v
            }
        })
    };
    ilqr::Weights {
        q: diag(1.0, 0.01),
        r: SMatrix::<f64, N, N>::identity() * 1e-4,
        qf: diag(2000.0, 50.0),
    }
}

/// The UR5's steps: `[q, q̇]` additive.
struct Arm;

impl ilqr::Problem<D, N> for Arm {
    type X = X;

    fn initial(&self) -> X {
        X::from_column_slice(&Ur5::initial_state().to_array())
    }

    fn step(&self, k: usize, x: &X, u: &SVector<f64, N>) -> (X, A, SMatrix<f64, D, N>) {
        let s = Ur5State::from_array(&core::array::from_fn(|i| x[i]));
        let (next, a, b) = Ur5::step_jacobians(k as f64 * Ur5::STEP, &s, &(*u).into(), Ur5::STEP)
            .expect("a finite step");
        (
            X::from_column_slice(&next.to_array()),
            A::from_fn(|i, j| a[i][j]),
            SMatrix::from_fn(|i, j| b[i][j]),
        )
    }

    fn difference(&self, x: &X, y: &X) -> X {
        y - x
    }

    fn error(&self, x: &X) -> X {
        x - goal()
    }
}

fn main() {
    let start = Instant::now();
    let (t, rollouts) = ilqr::optimize(&Arm, &weights(), K);
    let secs = start.elapsed().as_secs_f64();
    let e = t.x[K] - goal();
    println!(
        "final |q − q_goal| = {:.2e} rad, |q̇| = {:.2e} rad/s after {:.1} s of motion",
        e.rows(0, N).norm(),
        e.rows(N, N).norm(),
        K as f64 * Ur5::STEP
    );
    println!(
        "{rollouts} rollouts of {K} linearized steps in {:.3} s ({:.2} µs a step with its (A, B), backward passes included)",
        secs,
        secs * 1e6 / (rollouts * K) as f64
    );
}
