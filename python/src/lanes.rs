//! Forward dynamics of four fixed-base states at once: the run-time path's kernels
//! (`kanegen_runtime::compact`: `transforms`, `world`, `aba_on_world`, the sequence
//! `kanegen_dynamics::kernels::forward_dynamics` runs) instantiated on [`L4`], four `f64`
//! states side by side in a `wide::f64x4`. Each lane computes what the `f64` kernels compute
//! for its state, bit for bit: the same IEEE operations in the same order, sines and cosines
//! and square roots by the `f64` routines lane by lane.

use kanegen_dynamics::kernels::{ArticulatedVecs, BodyVecs, KernelTables, TablesIn};
use kanegen_runtime::compact::aba::aba_on_world;
use kanegen_runtime::compact::spatial::{transforms, world};
use kanegen_runtime::compact::Rates;
use kanegen_runtime::lanes::{f64x4, Lane, Lanes};
use kanegen_runtime::Scalar;

/// The number of states per call.
pub const LANES: usize = 4;

/// Four `f64` values side by side, a [`Scalar`] for the kernels (the runtime's [`Lane`]).
pub type L4 = Lane<f64x4>;

/// Lane `i` is `f(i)`.
fn from_fn(f: impl FnMut(usize) -> f64) -> L4 {
    Lane(<f64x4 as Lanes<f64>>::from_fn(f))
}

/// The tables on lanes: every number splat over the four.
pub type LaneTables = TablesIn<L4>;

/// [`LaneTables`] of `t`.
pub fn lane_tables(t: &KernelTables) -> LaneTables {
    TablesIn::new(t, L4::constant)
}

/// One worker's scratch: the kernels' per-body storage and the lanes of the arguments.
pub struct LaneData {
    bodies: BodyVecs<L4>,
    articulated: ArticulatedVecs<L4>,
    /// `q`, `q̇`, `τ`, `q̈`, one entry per joint.
    rows: [Vec<L4>; 4],
}

impl LaneData {
    /// Scratch for `n` joints.
    pub fn new(n: usize) -> LaneData {
        LaneData {
            bodies: BodyVecs::new(n),
            articulated: ArticulatedVecs::new(n),
            rows: core::array::from_fn(|_| vec![L4::constant(0.0); n]),
        }
    }
}

/// `q̈` of `m ≤ 4` fixed-base states (rows of `q`, `qd`, `tau`, `n` entries each) into the rows
/// of `out`; the missing lanes repeat the last state.
pub fn forward_dynamics(
    lt: &LaneTables,
    t: &KernelTables,
    d: &mut LaneData,
    [q, qd, tau]: [&[f64]; 3],
    out: &mut [f64],
) {
    let n = t.dof();
    let m = q.len() / n.max(1);
    let [ql, qdl, taul, qddl] = &mut d.rows;
    for (x, rows) in [(&mut *ql, q), (&mut *qdl, qd), (&mut *taul, tau)] {
        for (j, xj) in x.iter_mut().enumerate() {
            *xj = from_fn(|i| rows[i.min(m - 1) * n + j]);
        }
    }
    let tables = lt.tables(t);
    let mut b = d.bodies.bodies();
    let mut ab = d.articulated.articulated();
    transforms(&tables, ql, L4::sin_cos, b.x);
    world(&tables, tables.inertia, &mut b);
    let rates = Rates {
        qd: qdl,
        tau: taul,
        f_ext: None,
        armature: None,
    };
    aba_on_world(&tables, rates, &b, &mut ab, qddl);
    for (i, row) in out.chunks_mut(n).enumerate() {
        for (o, x) in row.iter_mut().zip(qddl.iter()) {
            *o = x.0.lane(i);
        }
    }
}
