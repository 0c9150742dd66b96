//! Mimic joints: the constant coupling of a model's full joint list to its independent
//! coordinates (URDF `<mimic>`), written once over slices for the traced algorithms
//! (`kanegen_dynamics::mimic` wraps it in `Vec`s) and the compact kernels
//! ([`crate::compact::coupled`]; a generated type holds one as `const CX_COUPLING`).
//!
//! Joint `j` mimicking the independent joint `p` has `q_j = k_j q_p + o_j`. With the constant
//! coupling matrix `G` (full × reduced: `G[j][c(j)] = k_j`, `k = 1` on independent joints, `c(j)`
//! the coordinate of `j`'s primary), `q̇_full = G q̇` and `q̈_full = G q̈`. The constraint forces
//! do no work along `G`, so projecting `M_full q̈_full + c_full = τ_full` onto it (Lagrange's
//! equations in the reduced coordinates; Featherstone, RBDA §3.2–3.3, constrained systems with
//! `q̇ = G ẏ` and `Ġ = 0`) gives `M = Gᵀ M_full G`, `c = Gᵀ c_full`, and the drives `τ_full`
//! are the independent joints' own, zero on mimic joints.
//!
//! A free-floating base's six leading speeds map to themselves (`offset = 6`). A multiplier of
//! one and an offset of zero cost no operation (model structure, not data), and every reduced
//! entry starts from its first term, so that a traced reduction counts only what it computes.
//!
//! ```
//! use kanegen_runtime::coupling::{Coupling, Follower};
//! // Joint 1 follows joint 0 at twice its angle plus 0.5.
//! let joints = [
//!     Follower { coordinate: 0, multiplier: 1.0, offset: 0.0, independent: true, first: true },
//!     Follower { coordinate: 0, multiplier: 2.0, offset: 0.5, independent: false, first: false },
//! ];
//! let c = Coupling { joints: &joints, reduced: 1 };
//! let mut q = [0.0_f64; 2];
//! c.expand_positions(&[1.0], &mut q);
//! assert_eq!(q, [1.0, 2.5]);
//! // Gᵀ M G with G = [1, 2]ᵀ.
//! let (m, mut scratch, mut out) = ([1.0_f64, 0.5, 0.5, 3.0], [0.0; 2], [0.0; 1]);
//! c.reduce_matrix(&m, 0, &mut scratch, &mut out);
//! assert_eq!(out, [1.0 + 2.0 * 0.5 * 2.0 + 4.0 * 3.0]);
//! ```

use crate::scalar::Scalar;

/// How one joint of the full joint list moves with the independent coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Follower {
    /// The reduced coordinate it moves with (its own on an independent joint).
    pub coordinate: usize,
    /// `k_j` (1 on independent joints).
    pub multiplier: f64,
    /// `o_j` (0 on independent joints).
    pub offset: f64,
    /// Whether it is independent (mimics none; its drive is the coordinate's).
    pub independent: bool,
    /// Whether it is the first joint of the list that moves with its coordinate (where a
    /// reduction starts that coordinate's sum).
    pub first: bool,
}

/// The constant coupling: one [`Follower`] per joint of the full list.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling<'a> {
    /// Each joint of the full list, in order.
    pub joints: &'a [Follower],
    /// The number of independent coordinates.
    pub reduced: usize,
}

impl Follower {
    /// `k_j x` (no operation when `k_j = 1`).
    #[inline(always)]
    fn scaled<S: Scalar>(&self, x: S) -> S {
        if self.multiplier == 1.0 {
            x
        } else {
            S::constant(self.multiplier) * x
        }
    }
}

impl Coupling<'_> {
    /// Number of joints of the full list.
    #[inline(always)]
    #[must_use]
    pub fn full(&self) -> usize {
        self.joints.len()
    }

    /// `q_full = G q + o` into `out` (one entry per joint; entries past `q` or `out` untouched).
    #[inline]
    pub fn expand_positions<S: Scalar>(&self, q: &[S], out: &mut [S]) {
        for (o, f) in out.iter_mut().zip(self.joints) {
            if let Some(x) = q.get(f.coordinate) {
                let x = f.scaled(x.clone());
                *o = if f.offset == 0.0 {
                    x
                } else {
                    x + S::constant(f.offset)
                };
            }
        }
    }

    /// `x_full = G x` into `out`: the joint rates `q̇` or accelerations `q̈`.
    #[inline]
    pub fn expand_rates<S: Scalar>(&self, x: &[S], out: &mut [S]) {
        for (o, f) in out.iter_mut().zip(self.joints) {
            if let Some(x) = x.get(f.coordinate) {
                *o = f.scaled(x.clone());
            }
        }
    }

    /// `τ_full` into `out`: the drives of the independent joints, zero on mimic joints (they
    /// are driven through the coupling).
    #[inline]
    pub fn expand_drives<S: Scalar>(&self, tau: &[S], out: &mut [S]) {
        for (o, f) in out.iter_mut().zip(self.joints) {
            *o = match (f.independent, tau.get(f.coordinate)) {
                (true, Some(x)) => x.clone(),
                _ => S::zero(),
            };
        }
    }

    /// `Gᵀ v` for a full vector whose first `offset` entries are the base's own (kept), read
    /// as `v[k · v_stride]` and written as `out[r · out_stride]` (`offset + reduced` entries).
    #[inline]
    pub fn reduce_strided<S: Scalar>(
        &self,
        v: &[S],
        v_stride: usize,
        offset: usize,
        out: &mut [S],
        out_stride: usize,
    ) {
        for k in 0..offset {
            if let (Some(x), Some(o)) = (v.get(k * v_stride), out.get_mut(k * out_stride)) {
                *o = x.clone();
            }
        }
        for r in 0..self.reduced {
            if let Some(o) = out.get_mut((offset + r) * out_stride) {
                *o = S::zero();
            }
        }
        for (j, f) in self.joints.iter().enumerate() {
            let (Some(x), Some(o)) = (
                v.get((offset + j) * v_stride),
                out.get_mut((offset + f.coordinate) * out_stride),
            ) else {
                continue;
            };
            let x = f.scaled(x.clone());
            *o = if f.first { x } else { o.clone() + x };
        }
    }

    /// `Gᵀ v` into `out` ([`Coupling::reduce_strided`] on contiguous vectors).
    #[inline]
    pub fn reduce_vector<S: Scalar>(&self, v: &[S], offset: usize, out: &mut [S]) {
        self.reduce_strided(v, 1, offset, out, 1);
    }

    /// `Gᵀ M G` into `out` (`n × n`, rows first, `n = offset + reduced`) for a full square
    /// matrix `m` (`nf × nf`, `nf = offset + full`) whose first `offset` rows and columns are
    /// the base's: the rows first (`M G` into `scratch`, `nf × n`), then its columns.
    #[inline]
    pub fn reduce_matrix<S: Scalar>(
        &self,
        m: &[S],
        offset: usize,
        scratch: &mut [S],
        out: &mut [S],
    ) {
        let (nf, n) = (offset + self.full(), offset + self.reduced);
        for (row, mg) in m.chunks(nf.max(1)).zip(scratch.chunks_mut(n.max(1))) {
            self.reduce_vector(row, offset, mg);
        }
        for c in 0..n {
            if let (Some(col), Some(o)) = (scratch.get(c..), out.get_mut(c..)) {
                self.reduce_strided(col, n, offset, o, n);
            }
        }
    }

    /// `J G` into `out` (`rows × (offset + reduced)`) for a matrix of `rows` rows over the full
    /// speeds (`offset + full` columns each, the first `offset` kept).
    #[inline]
    pub fn reduce_rows<S: Scalar>(&self, m: &[S], offset: usize, out: &mut [S]) {
        let (nf, n) = (offset + self.full(), offset + self.reduced);
        for (row, o) in m.chunks(nf.max(1)).zip(out.chunks_mut(n.max(1))) {
            self.reduce_vector(row, offset, o);
        }
    }
}
