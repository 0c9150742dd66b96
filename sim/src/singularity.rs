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
//! [`SingularityWatch`] reports it instead: `σ_min(J*)` at every observed state ([`sigma_min`]:
//! nalgebra's SVD of `J*`), its minimum over the run, and the intervals where it is below a
//! threshold. `kanegen simulate` reports the smallest `σ_min(J*)` of the last body's frame in
//! its summary (`singularity`) for every free-floating scene with at least 6 joints.

use kanegen_dynamics::algorithms::frames;
use kanegen_dynamics::base::{FloatingBase, FloatingState};
use kanegen_dynamics::mimic::Coupling;
use kanegen_dynamics::{FrameParams, Params};

/// `σ_min(J*)` of `frame` at the positions `q` of the full joint list and base state `state`
/// (nalgebra's SVD of the 6 × N `J*`, Golub–Kahan: no squaring, so `σ_min` is resolved to about
/// `ε σ_max`); with mimic joints (`coupling`) of `J* G`, the 6 × N Jacobian of the coordinates;
/// `None` with fewer than 6 coordinates, where `J*` has a null row space by construction.
#[must_use]
pub fn sigma_min(
    params: &Params<f64>,
    base: &FloatingBase<f64>,
    state: &FloatingState<f64>,
    (q, coupling): (&[f64], Option<&Coupling>),
    frame: &FrameParams<f64>,
) -> Option<f64> {
    let n = coupling.map_or(q.len(), Coupling::reduced);
    if n < 6 {
        return None;
    }
    let mut j = frames::generalized_jacobian(params, base, state, q, frame);
    if let Some(c) = coupling {
        j = j.iter().map(|row| c.reduce_vector(row, 0)).collect();
    }
    let m = nalgebra::DMatrix::from_fn(6, n, |r, c| j[r][c]);
    Some(
        m.singular_values()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min),
    )
}

/// Watches `σ_min(J*)` of a frame along a run (feed it `σ_min` at the samples) and reports where it falls
/// below `threshold`.
#[derive(Clone, Debug)]
pub struct SingularityWatch {
    threshold: f64,
    /// Smallest `σ_min(J*)` seen and its time.
    pub min: (f64, f64),
    /// `[t_enter, t_leave]` intervals with `σ_min < threshold` (`t_leave` the last sample's
    /// time while still inside).
    pub below: Vec<(f64, f64)>,
    inside: bool,
}

impl SingularityWatch {
    /// A watch with `threshold`.
    #[must_use]
    pub fn new(threshold: f64) -> Self {
        SingularityWatch {
            threshold,
            min: (f64::INFINITY, f64::NAN),
            below: Vec::new(),
            inside: false,
        }
    }

    /// Takes `σ_min(J*)` at `t` (e.g. [`sigma_min`], or `SceneSystem::sigma_min` of a state).
    pub fn observe(&mut self, t: f64, s: f64) {
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
