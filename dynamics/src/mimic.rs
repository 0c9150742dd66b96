//! Mimic joints: the one place that maps the independent coordinates to the full joint list and
//! the full dynamics back (URDF `<mimic>`, Pinocchio's mimic joints).
//!
//! Joint `j` mimicking the independent joint `p` has `q_j = k_j q_p + o_j`. With the constant
//! coupling matrix `G` (full × reduced: `G[j][c(j)] = k_j`, `k = 1` on independent joints, `c(j)`
//! the coordinate of `j`'s primary), `q̇_full = G q̇` and `q̈_full = G q̈`. The constraint forces
//! do no work along `G`, so projecting `M_full q̈_full + c_full = τ_full` onto it (Lagrange's
//! equations in the reduced coordinates; Featherstone, RBDA §3.2–3.3, constrained systems with
//! `q̇ = G ẏ` and `Ġ = 0`) gives
//!
//! ```text
//! M = Gᵀ M_full(q_full) G,   c = Gᵀ c_full(q_full, G q̇),   τ_full = τ on independent joints, 0 elsewhere
//! ```
//!
//! Every algorithm keeps computing the full model; [`Coupling`] expands the state before and
//! reduces `M` and the right-hand side after, generic over the scalar (so a trace records it too).
//! A free-floating base's six leading speeds map to themselves (`offset = 6`). The arithmetic is
//! `kanegen_runtime::coupling`'s (the compact kernels run the same); this type owns its table
//! and wraps it in `Vec`s.
//!
//! ```
//! use kanegen_dynamics::mimic::Coupling;
//! use kanegen_model::Mimic;
//! // Joint 1 follows joint 0 at twice its angle plus 0.5.
//! let c = Coupling::new(&[None, Some(Mimic { primary: 0, multiplier: 2.0, offset: 0.5 })]);
//! assert_eq!(c.full_positions(&[1.0_f64]), [1.0, 2.5]);
//! assert_eq!(c.full_rates(&[1.0_f64]), [1.0, 2.0]);
//! // Gᵀ M G with G = [1, 2]ᵀ.
//! let m = vec![vec![1.0_f64, 0.5], vec![0.5, 3.0]];
//! assert_eq!(c.reduce_matrix(&m, 0), [[1.0 + 2.0 * 0.5 * 2.0 + 4.0 * 3.0]]);
//! ```

use crate::scalar::Scalar;
use kanegen_model::Mimic;
use kanegen_runtime::coupling::{self, Follower};

/// The constant coupling of the full joint list to the independent coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Coupling {
    /// One entry per joint of the full list.
    joints: Vec<Follower>,
    /// The number of independent coordinates.
    reduced: usize,
}

impl Coupling {
    /// The coupling of a model's [`kanegen_model::Model::mimics`] (one entry per joint, primaries
    /// already resolved to independent joints).
    #[must_use]
    pub fn new(mimics: &[Option<Mimic>]) -> Self {
        let mut index = vec![usize::MAX; mimics.len()];
        let mut reduced = 0;
        for (j, m) in mimics.iter().enumerate() {
            if m.is_none() {
                index[j] = reduced;
                reduced += 1;
            }
        }
        let mut seen = vec![false; reduced];
        let joints = mimics
            .iter()
            .enumerate()
            .map(|(j, m)| {
                let coordinate = m.map_or(index[j], |m| index[m.primary]);
                let first = !std::mem::replace(&mut seen[coordinate], true);
                Follower {
                    coordinate,
                    multiplier: m.map_or(1.0, |m| m.multiplier),
                    offset: m.map_or(0.0, |m| m.offset),
                    independent: m.is_none(),
                    first,
                }
            })
            .collect();
        Coupling { joints, reduced }
    }

    /// The table as the runtime reads it (what a compact generated type holds as a constant).
    #[must_use]
    pub fn table(&self) -> coupling::Coupling<'_> {
        coupling::Coupling {
            joints: &self.joints,
            reduced: self.reduced,
        }
    }

    /// The joints of the full list, in order.
    #[must_use]
    pub fn joints(&self) -> &[Follower] {
        &self.joints
    }

    /// Number of independent coordinates.
    #[must_use]
    pub fn reduced(&self) -> usize {
        self.reduced
    }

    /// Number of joints of the full list.
    #[must_use]
    pub fn full(&self) -> usize {
        self.joints.len()
    }

    /// `q_full = G q + o`.
    #[must_use]
    pub fn full_positions<S: Scalar>(&self, q: &[S]) -> Vec<S> {
        let mut out = vec![S::zero(); self.full()];
        self.table().expand_positions(q, &mut out);
        out
    }

    /// `q̇_full = G q̇` (also `q̈_full = G q̈`).
    #[must_use]
    pub fn full_rates<S: Scalar>(&self, qd: &[S]) -> Vec<S> {
        let mut out = vec![S::zero(); self.full()];
        self.table().expand_rates(qd, &mut out);
        out
    }

    /// `τ_full`: the drives of the independent joints, zero on mimic joints (they are driven
    /// through the coupling).
    #[must_use]
    pub fn full_drives<S: Scalar>(&self, tau: &[S]) -> Vec<S> {
        let mut out = vec![S::zero(); self.full()];
        self.table().expand_drives(tau, &mut out);
        out
    }

    /// `Gᵀ v` for a full vector whose first `offset` entries are the base's own (kept).
    #[must_use]
    pub fn reduce_vector<S: Scalar>(&self, v: &[S], offset: usize) -> Vec<S> {
        let mut out = vec![S::zero(); offset + self.reduced];
        self.table().reduce_vector(v, offset, &mut out);
        out
    }

    /// `Gᵀ M G` for a full square matrix whose first `offset` rows and columns are the base's.
    #[must_use]
    pub fn reduce_matrix<S: Scalar>(&self, m: &[Vec<S>], offset: usize) -> Vec<Vec<S>> {
        let n = offset + self.reduced;
        let mut scratch = vec![S::zero(); m.len() * n];
        let mut out = vec![S::zero(); n * n];
        self.table()
            .reduce_matrix(&m.concat(), offset, &mut scratch, &mut out);
        out.chunks(n.max(1)).map(<[S]>::to_vec).collect()
    }

    /// Forward dynamics in the independent coordinates: `M q̈ = b` with `M = Gᵀ M_full G` and
    /// `b = Gᵀ (τ_full − c_full)` (the full matrix and right-hand side, `offset` base speeds
    /// first), by LDLᵀ ([`crate::ldlt`]).
    #[must_use]
    pub fn forward_dynamics<S: Scalar>(
        &self,
        offset: usize,
        m_full: &[Vec<S>],
        b_full: &[S],
    ) -> Vec<S> {
        let m = self.reduce_matrix(m_full, offset);
        let b = self.reduce_vector(b_full, offset);
        crate::ldlt::solve(&crate::ldlt::ldlt(&m), &b)
    }
}
