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
//! A free-floating base's six leading speeds map to themselves (`offset = 6`).
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

/// The constant coupling of the full joint list to the independent coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Coupling {
    /// For each joint of the full list, the reduced coordinate it moves with.
    coordinate: Vec<usize>,
    /// `k_j` (1 on independent joints).
    multiplier: Vec<f64>,
    /// `o_j` (0 on independent joints).
    offset: Vec<f64>,
    /// Whether each joint is independent (mimics none).
    independent: Vec<bool>,
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
        let coordinate = mimics
            .iter()
            .enumerate()
            .map(|(j, m)| m.map_or(index[j], |m| index[m.primary]))
            .collect();
        Coupling {
            coordinate,
            multiplier: mimics
                .iter()
                .map(|m| m.map_or(1.0, |m| m.multiplier))
                .collect(),
            offset: mimics.iter().map(|m| m.map_or(0.0, |m| m.offset)).collect(),
            independent: mimics.iter().map(Option::is_none).collect(),
            reduced,
        }
    }

    /// Number of independent coordinates.
    #[must_use]
    pub fn reduced(&self) -> usize {
        self.reduced
    }

    /// Number of joints of the full list.
    #[must_use]
    pub fn full(&self) -> usize {
        self.coordinate.len()
    }

    /// `k_j x` (no operation when `k_j = 1`: model structure, not data).
    fn scaled<S: Scalar>(&self, j: usize, x: S) -> S {
        if self.multiplier[j] == 1.0 {
            x
        } else {
            S::constant(self.multiplier[j]) * x
        }
    }

    /// `q_full = G q + o`.
    #[must_use]
    pub fn full_positions<S: Scalar>(&self, q: &[S]) -> Vec<S> {
        (0..self.full())
            .map(|j| {
                let x = self.scaled(j, q[self.coordinate[j]].clone());
                if self.offset[j] == 0.0 {
                    x
                } else {
                    x + S::constant(self.offset[j])
                }
            })
            .collect()
    }

    /// `q̇_full = G q̇` (also `q̈_full = G q̈`).
    #[must_use]
    pub fn full_rates<S: Scalar>(&self, qd: &[S]) -> Vec<S> {
        (0..self.full())
            .map(|j| self.scaled(j, qd[self.coordinate[j]].clone()))
            .collect()
    }

    /// `τ_full`: the drives of the independent joints, zero on mimic joints (they are driven
    /// through the coupling).
    #[must_use]
    pub fn full_drives<S: Scalar>(&self, tau: &[S]) -> Vec<S> {
        (0..self.full())
            .map(|j| match self.independent[j] {
                true => tau[self.coordinate[j]].clone(),
                false => S::zero(),
            })
            .collect()
    }

    /// `Gᵀ v` for a full vector whose first `offset` entries are the base's own (kept).
    #[must_use]
    pub fn reduce_vector<S: Scalar>(&self, v: &[S], offset: usize) -> Vec<S> {
        let mut out: Vec<Option<S>> = vec![None; offset + self.reduced];
        for (k, x) in v.iter().take(offset).enumerate() {
            out[k] = Some(x.clone());
        }
        for j in 0..self.full() {
            let r = offset + self.coordinate[j];
            let x = self.scaled(j, v[offset + j].clone());
            out[r] = Some(match out[r].take() {
                None => x,
                Some(acc) => acc + x,
            });
        }
        out.into_iter().map(|x| x.unwrap_or_else(S::zero)).collect()
    }

    /// `Gᵀ M G` for a full square matrix whose first `offset` rows and columns are the base's.
    #[must_use]
    pub fn reduce_matrix<S: Scalar>(&self, m: &[Vec<S>], offset: usize) -> Vec<Vec<S>> {
        // Columns first (M G), then rows (Gᵀ (M G)), each by `reduce_vector`.
        let mg: Vec<Vec<S>> = m
            .iter()
            .map(|row| self.reduce_vector(row, offset))
            .collect();
        let n = offset + self.reduced;
        let columns: Vec<Vec<S>> = (0..n)
            .map(|c| {
                let col: Vec<S> = mg.iter().map(|row| row[c].clone()).collect();
                self.reduce_vector(&col, offset)
            })
            .collect();
        (0..n)
            .map(|r| (0..n).map(|c| columns[c][r].clone()).collect())
            .collect()
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
