//! Dynamic singularities of a free-floating arm: the smallest singular value of the generalized
//! Jacobian `J*` (Umetani & Yoshida 1989; [`frames::generalized_jacobian`]) of a frame, watched
//! along a run.
//!
//! A free-floating arm is dynamically singular where `J*` (6 × N) loses rank: there the frame
//! cannot move in some direction by joint motion alone, whatever the joint rates, because the
//! base reacts (Papadopoulos & Dubowsky 1993: the singularities depend on the mass properties,
//! not only on the kinematics). The equations of motion themselves stay regular there (the mass
//! matrix is positive definite everywhere), so a simulation with joint-space drives passes
//! through a singular configuration without harm; what fails is a controller that inverts `J*`.
//! [`SingularityWatch`] reports it instead: `σ_min(J*)` at every observed state (the square
//! root of the smallest eigenvalue of the 6 × 6 `J* J*ᵀ`, by cyclic Jacobi rotations, Golub &
//! Van Loan §8.5), its minimum over the run, and the intervals where it is below a threshold.
//! Through `J* J*ᵀ`, `σ²` is resolved to the rounding of that product, `|Δσ²| ≲ ε σ_max²`: a
//! `σ_min` below about `1e-8 σ_max` reads as some value of that size (still far below any useful
//! threshold).

use crate::simulate::SceneSystem;
use kanegen_dynamics::algorithms::frames;
use kanegen_dynamics::FrameParams;

/// Eigenvalues of a symmetric matrix by cyclic Jacobi rotations (Golub & Van Loan, Alg. 8.5.3),
/// to a relative off-diagonal norm of 1e-15 or 50 sweeps.
#[must_use]
pub fn symmetric_eigenvalues(a: &[Vec<f64>]) -> Vec<f64> {
    let n = a.len();
    let mut a: Vec<Vec<f64>> = a.to_vec();
    let norm: f64 = a.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    for _ in 0..50 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |j| *j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum::<f64>()
            .sqrt();
        if off <= 1e-15 * norm {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q] == 0.0 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for row in a.iter_mut() {
                    let (akp, akq) = (row[p], row[q]);
                    row[p] = c * akp - s * akq;
                    row[q] = s * akp + c * akq;
                }
                let (rp, rq) = (a[p].clone(), a[q].clone());
                for (k, (apk, aqk)) in rp.iter().zip(&rq).enumerate() {
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
            }
        }
    }
    (0..n).map(|i| a[i][i]).collect()
}

/// `σ_min(J*)` of `frame` at state `x` of a free-floating scene system (`None` on a fixed base,
/// or with more rows than joints, where `J* J*ᵀ` is singular by construction).
#[must_use]
pub fn sigma_min(sys: &SceneSystem<'_>, x: &[f64], frame: &FrameParams<f64>) -> Option<f64> {
    let (q, _, st) = sys.split(x);
    let (st, base) = (st?, sys.floating_base()?);
    if q.len() < 6 {
        return None;
    }
    let j = frames::generalized_jacobian(sys.params(), base, &st, q, frame);
    let jjt: Vec<Vec<f64>> = j
        .iter()
        .map(|a| {
            j.iter()
                .map(|b| a.iter().zip(b).map(|(x, y)| x * y).sum())
                .collect()
        })
        .collect();
    let lo = symmetric_eigenvalues(&jjt)
        .into_iter()
        .fold(f64::INFINITY, f64::min);
    Some(lo.max(0.0).sqrt())
}

/// Watches `σ_min(J*)` of a frame along a run (feed it the samples) and reports where it falls
/// below `threshold`.
#[derive(Clone, Debug)]
pub struct SingularityWatch {
    frame: FrameParams<f64>,
    threshold: f64,
    /// Smallest `σ_min(J*)` seen and its time.
    pub min: (f64, f64),
    /// `[t_enter, t_leave]` intervals with `σ_min < threshold` (`t_leave` the last sample's
    /// time while still inside).
    pub below: Vec<(f64, f64)>,
    inside: bool,
}

impl SingularityWatch {
    /// A watch of `frame` with `threshold`.
    #[must_use]
    pub fn new(frame: FrameParams<f64>, threshold: f64) -> Self {
        SingularityWatch {
            frame,
            threshold,
            min: (f64::INFINITY, f64::NAN),
            below: Vec::new(),
            inside: false,
        }
    }

    /// Takes the state `x` at `t`; returns `σ_min(J*)` there.
    pub fn observe(&mut self, sys: &SceneSystem<'_>, t: f64, x: &[f64]) -> Option<f64> {
        let s = sigma_min(sys, x, &self.frame)?;
        if s < self.min.0 {
            self.min = (s, t);
        }
        if s < self.threshold {
            if self.inside {
                if let Some(last) = self.below.last_mut() {
                    last.1 = t;
                }
            } else {
                self.below.push((t, t));
            }
        }
        self.inside = s < self.threshold;
        Some(s)
    }

    /// A sentence for the summary: where `σ_min(J*)` went below the threshold, or `None`.
    #[must_use]
    pub fn report(&self) -> Option<String> {
        if self.below.is_empty() {
            return None;
        }
        let spans: Vec<String> = self
            .below
            .iter()
            .map(|(a, b)| format!("[{a}, {b}] s"))
            .collect();
        Some(format!(
            "dynamic singularity: σ_min(J*) below {:e} during {}; smallest {:.3e} at t = {} s",
            self.threshold,
            spans.join(", "),
            self.min.0,
            self.min.1
        ))
    }
}
