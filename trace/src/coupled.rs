//! Functions of a model with mimic joints, traced in its independent coordinates
//! (`kanegen_dynamics::mimic`): the state is expanded to the full joint list before the
//! algorithms run (`q_full = G q + o`, `q̇_full = G q̇`, `q̈_full = G q̈`, drives on the
//! independent joints), and the results are reduced after: `M = Gᵀ M_full G`,
//! `c = Gᵀ c_full`, a Jacobian `J G`. Forward dynamics cannot be reduced after the fact (the
//! articulated-body algorithm runs on the full tree); it solves `M q̈ = Gᵀ (τ_full − c_full)` by
//! LDLᵀ, and so do its derivatives and `M⁻¹` (`kanegen_dynamics::algorithms::derivatives::coupled`);
//! the inverse-dynamics derivatives are `Gᵀ D G`. `G` is constant, so the trace folds it into the emitted code.

use crate::function::Function;
use crate::sym::Sym;
use kanegen_dynamics::algorithms::derivatives::coupled as derivatives;
use kanegen_dynamics::mimic::Coupling;
use kanegen_dynamics::Scalar;

/// The full symmetric matrix of `n × n` from its upper triangle, row-major.
fn from_upper(upper: &[Sym], n: usize) -> Vec<Vec<Sym>> {
    // Entry (i, j ≥ i) is the upper triangle's `i n − i (i − 1) / 2 + (j − i)`.
    let at = |i: usize, j: usize| {
        let (i, j) = (i.min(j), i.max(j));
        upper
            .get(i * n - i * i.saturating_sub(1) / 2 + (j - i))
            .copied()
            .unwrap_or_else(Sym::zero)
    };
    (0..n).map(|i| (0..n).map(|j| at(i, j)).collect()).collect()
}

/// The upper triangle of a symmetric matrix, row-major.
pub(crate) fn upper(a: &[Vec<Sym>]) -> Vec<Sym> {
    a.iter()
        .enumerate()
        .flat_map(|(i, row)| row[i..].to_vec())
        .collect()
}

/// The outputs `out` of `function` traced on the full joint list, in the independent
/// coordinates of `c` (`offset`: the base's six speeds of a free-floating model, kept).
/// Forward dynamics ([`forward_dynamics`]), its derivatives and `M⁻¹`
/// ([`kanegen_dynamics::algorithms::derivatives::coupled`]) are not reduced after the fact: they
/// come back unchanged.
#[must_use]
pub fn reduce(function: Function, c: &Coupling, offset: usize, out: Vec<Sym>) -> Vec<Sym> {
    let nv = offset + c.full();
    let matrix = |m: &[Sym]| upper(&c.reduce_matrix(&from_upper(m, nv), offset));
    let rows = |m: &[Sym], offset: usize| -> Vec<Sym> {
        let width = m.len() / 6;
        m.chunks(width)
            .flat_map(|row| c.reduce_vector(row, offset))
            .collect()
    };
    match function {
        Function::MassMatrix => matrix(&out),
        Function::MassMatrixAndNonlinearEffects => {
            let (m, v) = out.split_at(nv * (nv + 1) / 2);
            [matrix(m), c.reduce_vector(v, offset)].concat()
        }
        Function::GeneralizedForces
        | Function::NonlinearEffects
        | Function::Gravity
        | Function::InverseDynamics => c.reduce_vector(&out, offset),
        Function::FrameJacobian(_) => rows(&out, offset),
        // Gᵀ (∂τ_full/∂x_full) G for x = q, q̇.
        Function::InverseDynamicsDerivatives => {
            let square = |m: &[Sym]| m.chunks(nv).map(<[Sym]>::to_vec).collect::<Vec<_>>();
            let (dq, dv) = out.split_at(nv * nv);
            let (dq, dv) = derivatives::reduce_pair(c, offset, (square(dq), square(dv)));
            [dq, dv].concat().concat()
        }
        // J* G: the reduced system's coupling columns are A_bm G.
        Function::GeneralizedJacobian(_) => rows(&out, 0),
        Function::Momentum
        | Function::BaseReaction
        | Function::FramePlacement(_)
        | Function::ForwardDynamics
        | Function::ForwardDynamicsWithWrenches
        | Function::ForwardDynamicsDerivatives
        | Function::MassMatrixInverse => out,
    }
}

/// Forward dynamics in the independent coordinates ([`Coupling::forward_dynamics`]: the reduced
/// `M q̈ = Gᵀ (τ_full − c_full)` by LDLᵀ), the full matrix and right-hand side traced.
#[must_use]
pub fn forward_dynamics(
    c: &Coupling,
    offset: usize,
    m_full: &[Vec<Sym>],
    b_full: &[Sym],
) -> Vec<Sym> {
    c.forward_dynamics(offset, m_full, b_full)
}
