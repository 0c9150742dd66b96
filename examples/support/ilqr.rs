//! The iLQR of the examples (Li & Todorov 2004; Tassa, Erez & Todorov 2012), written once over
//! a [`Problem`]: rollouts with the step Jacobians at every knot, the backward pass (a Riccati
//! recursion on the local quadratic model, Levenberg–Marquardt regularization `μ` on `Q_uu`),
//! and a line search on the feedforward step. States live in a space of `D` directions: the
//! feedback acts on `x ⊖ x̄` ([`Problem::difference`]) and the cost on an error `e(x)`
//! ([`Problem::error`]), whose Jacobian the backward pass takes as the identity.

use nalgebra::{SMatrix, SVector};

/// A knot's feedforward and feedback gains.
pub type Gain<const D: usize, const N: usize> = (SVector<f64, N>, SMatrix<f64, N, D>);

/// What an example optimizes: its states, steps and goal.
pub trait Problem<const D: usize, const N: usize> {
    /// A state.
    type X: Clone;
    /// The initial state.
    fn initial(&self) -> Self::X;
    /// One step from knot `k` under `u`, with its Jacobians `(A, B)`.
    fn step(
        &self,
        k: usize,
        x: &Self::X,
        u: &SVector<f64, N>,
    ) -> (Self::X, SMatrix<f64, D, D>, SMatrix<f64, D, N>);
    /// `y ⊖ x`.
    fn difference(&self, x: &Self::X, y: &Self::X) -> SVector<f64, D>;
    /// The error of `x` from the goal.
    fn error(&self, x: &Self::X) -> SVector<f64, D>;
}

/// Running and terminal weights: `½ eᵀ Q e + ½ uᵀ R u`, `½ eᵀ Q_f e` of the error `e`.
pub struct Weights<const D: usize, const N: usize> {
    /// Running weight of the error.
    pub q: SMatrix<f64, D, D>,
    /// Weight of the torques.
    pub r: SMatrix<f64, N, N>,
    /// Terminal weight of the error.
    pub qf: SMatrix<f64, D, D>,
}

/// A trajectory: states `x_0 … x_K`, torques `u_0 … u_{K−1}`, the step Jacobians at each
/// knot, and its cost.
pub struct Trajectory<X, const D: usize, const N: usize> {
    /// The states.
    pub x: Vec<X>,
    /// The torques.
    pub u: Vec<SVector<f64, N>>,
    a: Vec<SMatrix<f64, D, D>>,
    b: Vec<SMatrix<f64, D, N>>,
    /// The cost.
    pub cost: f64,
}

/// Rolls out `u_k = ū_k + α k_k + K_k (x_k ⊖ x̄_k)` over `u_bar.len()` knots from the initial
/// state (`gains` empty: the torques `ū` as they are).
fn rollout<P: Problem<D, N>, const D: usize, const N: usize>(
    p: &P,
    w: &Weights<D, N>,
    (x_bar, u_bar): (&[P::X], &[SVector<f64, N>]),
    gains: &[Gain<D, N>],
    alpha: f64,
) -> Trajectory<P::X, D, N> {
    let knots = u_bar.len();
    let mut x = p.initial();
    let mut t = Trajectory {
        x: vec![x.clone()],
        u: Vec::with_capacity(knots),
        a: Vec::with_capacity(knots),
        b: Vec::with_capacity(knots),
        cost: 0.0,
    };
    for k in 0..knots {
        let mut u = u_bar[k];
        if let Some((kf, kb)) = gains.get(k) {
            u += alpha * kf + kb * p.difference(&x_bar[k], &x);
        }
        let e = p.error(&x);
        t.cost += 0.5 * (e.dot(&(w.q * e)) + u.dot(&(w.r * u)));
        let (next, a, b) = p.step(k, &x, &u);
        x = next;
        t.u.push(u);
        t.a.push(a);
        t.b.push(b);
        t.x.push(x.clone());
    }
    let e = p.error(&x);
    t.cost += 0.5 * e.dot(&(w.qf * e));
    t
}

/// The backward pass: the gains of every knot, or `None` when `Q_uu` is not positive definite.
fn backward<P: Problem<D, N>, const D: usize, const N: usize>(
    p: &P,
    w: &Weights<D, N>,
    t: &Trajectory<P::X, D, N>,
    mu: f64,
) -> Option<Vec<Gain<D, N>>> {
    let knots = t.u.len();
    let mut vx = w.qf * p.error(&t.x[knots]);
    let mut vxx = w.qf;
    let mut gains = vec![(SVector::zeros(), SMatrix::zeros()); knots];
    for k in (0..knots).rev() {
        let (a, b, u) = (&t.a[k], &t.b[k], &t.u[k]);
        let qx = w.q * p.error(&t.x[k]) + a.transpose() * vx;
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

/// iLQR over `knots` knots from zero torques, printing each accepted iteration; the optimized
/// trajectory and the number of rollouts.
pub fn optimize<P: Problem<D, N>, const D: usize, const N: usize>(
    p: &P,
    w: &Weights<D, N>,
    knots: usize,
) -> (Trajectory<P::X, D, N>, usize) {
    let zero_u = vec![SVector::zeros(); knots];
    let mut t = rollout(p, w, (&[], &zero_u), &[], 0.0);
    let mut rollouts = 1;
    println!("iter  cost          step α   μ");
    println!("{:>4}  {:<12.6e}", 0, t.cost);
    let mut mu = 1e-6;
    for iter in 1..=100 {
        let Some(gains) = backward(p, w, &t, mu) else {
            mu *= 10.0;
            continue;
        };
        let mut accepted = None;
        for alpha in [1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125] {
            let cand = rollout(p, w, (&t.x, &t.u), &gains, alpha);
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
    (t, rollouts)
}
