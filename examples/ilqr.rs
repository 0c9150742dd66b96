//! iLQR (Li & Todorov 2004; Tassa, Erez & Todorov 2012) on a generated UR5 with the step
//! Jacobians of `scene!`: the arm, under gravity and joint damping with no drive, is taken from
//! its initial state to a goal at rest in 0.6 s by joint torques, the whole optimization
//! running on `Ur5::step_jacobians` (one RK4 step and its exact `(A, B)`, from the generated
//! derivatives of forward and inverse dynamics).
//!
//! Run: `cargo run --release --example ilqr`

use nalgebra::{SMatrix, SVector};
use std::time::Instant;

kanegen::scene!(Ur5, "scenes/ur5_torque_input.toml");

const D: usize = Ur5::DIM;
const N: usize = Ur5::N;
/// Knots of the horizon (0.6 s at the scene's step of 0.01 s).
const K: usize = 60;

type X = SVector<f64, D>;
type U = SVector<f64, N>;
type A = SMatrix<f64, D, D>;
type B = SMatrix<f64, D, N>;

/// The goal: these joint angles, at rest.
fn goal() -> X {
    let q = [0.6, -0.6, 0.9, -0.8, 0.9, 0.4];
    X::from_fn(|i, _| if i < N { q[i] } else { 0.0 })
}

/// Running and terminal weights: `½ (x − x_g)ᵀ Q (x − x_g) + ½ uᵀ R u`, `½ (x − x_g)ᵀ Q_f (…)`.
struct Weights {
    q: A,
    r: SMatrix<f64, N, N>,
    qf: A,
}

fn weights() -> Weights {
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
    Weights {
        q: diag(1.0, 0.01),
        r: SMatrix::<f64, N, N>::identity() * 1e-4,
        qf: diag(2000.0, 50.0),
    }
}

/// A trajectory: states `x_0 … x_K`, torques `u_0 … u_{K−1}`, the step Jacobians at each knot.
struct Trajectory {
    x: Vec<X>,
    u: Vec<U>,
    a: Vec<A>,
    b: Vec<B>,
    cost: f64,
}

/// Rolls out `u_k = ū_k + α k_k + K_k (x_k − x̄_k)` from the initial state with the step
/// Jacobians at every knot (`gains` empty: the torques `ū` as they are).
fn rollout(
    w: &Weights,
    nominal: &Trajectory,
    gains: &[(U, SMatrix<f64, N, D>)],
    alpha: f64,
) -> Trajectory {
    let g = goal();
    let mut x = X::from_column_slice(&Ur5::initial_state().to_array());
    let mut t = Trajectory {
        x: vec![x],
        u: Vec::with_capacity(K),
        a: Vec::with_capacity(K),
        b: Vec::with_capacity(K),
        cost: 0.0,
    };
    for k in 0..K {
        let mut u = nominal.u[k];
        if let Some((kf, kb)) = gains.get(k) {
            u += alpha * kf + kb * (x - nominal.x[k]);
        }
        let e = x - g;
        t.cost += 0.5 * (e.dot(&(w.q * e)) + u.dot(&(w.r * u)));
        let s = kanegen_state(&x);
        let (next, a, b) = Ur5::step_jacobians(k as f64 * Ur5::STEP, &s, &u.into(), Ur5::STEP)
            .expect("a finite step");
        x = X::from_column_slice(&next.to_array());
        t.u.push(u);
        t.a.push(A::from_fn(|i, j| a[i][j]));
        t.b.push(B::from_fn(|i, j| b[i][j]));
        t.x.push(x);
    }
    let e = x - g;
    t.cost += 0.5 * e.dot(&(w.qf * e));
    t
}

fn kanegen_state(x: &X) -> Ur5State {
    Ur5State::from_array(&core::array::from_fn(|i| x[i]))
}

/// The backward pass (Riccati recursion on the local quadratic model, Levenberg–Marquardt
/// regularization `μ` on `Q_uu`): the feedforward and feedback gains of every knot.
fn backward(w: &Weights, t: &Trajectory, mu: f64) -> Option<Vec<(U, SMatrix<f64, N, D>)>> {
    let g = goal();
    let mut vx = w.qf * (t.x[K] - g);
    let mut vxx = w.qf;
    let mut gains = vec![(U::zeros(), SMatrix::<f64, N, D>::zeros()); K];
    for k in (0..K).rev() {
        let (a, b, u) = (&t.a[k], &t.b[k], &t.u[k]);
        let qx = w.q * (t.x[k] - g) + a.transpose() * vx;
        let qu = w.r * u + b.transpose() * vx;
        let qxx = w.q + a.transpose() * vxx * a;
        let quu = w.r + b.transpose() * vxx * b + SMatrix::<f64, N, N>::identity() * mu;
        let qux = b.transpose() * vxx * a;
        let chol = quu.cholesky()?;
        let kf = -chol.solve(&qu);
        let kb = -chol.solve(&qux);
        vx = qx + kb.transpose() * quu * kf + kb.transpose() * qu + qux.transpose() * kf;
        vxx = qxx + kb.transpose() * quu * kb + kb.transpose() * qux + qux.transpose() * kb;
        vxx = 0.5 * (vxx + vxx.transpose());
        gains[k] = (kf, kb);
    }
    Some(gains)
}

fn main() {
    let w = weights();
    let zero = Trajectory {
        x: vec![X::zeros(); K + 1],
        u: vec![U::zeros(); K],
        a: Vec::new(),
        b: Vec::new(),
        cost: 0.0,
    };
    let start = Instant::now();
    let mut t = rollout(&w, &zero, &[], 0.0);
    let mut rollouts = 1;
    println!("iter  cost          step α   μ");
    println!("{:>4}  {:<12.6e}", 0, t.cost);
    let mut mu = 1e-6;
    for iter in 1..=100 {
        let Some(gains) = backward(&w, &t, mu) else {
            mu *= 10.0;
            continue;
        };
        let mut accepted = None;
        for alpha in [1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125] {
            let cand = rollout(&w, &t, &gains, alpha);
            rollouts += 1;
            if cand.cost < t.cost {
                accepted = Some((cand, alpha));
                break;
            }
        }
        let Some((cand, alpha)) = accepted else {
            mu *= 10.0;
            if mu > 1e6 {
                break;
            }
            continue;
        };
        let gain = (t.cost - cand.cost) / t.cost;
        t = cand;
        mu = (mu / 10.0).max(1e-9);
        println!("{iter:>4}  {:<12.6e}  {alpha:<7}  {mu:.0e}", t.cost);
        if gain < 1e-7 {
            break;
        }
    }
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
