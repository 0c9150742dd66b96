//! Forward dynamics with reflected rotor inertia (the armature model): `(M + diag(I_m n²)) a =
//! τ + Jᵀ f − c`, the armature on the joint diagonal of `M` (`M[6+i][6+i]` on a free-floating
//! base; Featherstone, RBDA Sec. 9.1, and Pinocchio's `armature`).

use super::SceneDynamics;
use crate::ldlt::{factor_in_place, solve_in_place};

/// The accelerations `acc` with `armature` from any provider: the right-hand side
/// `τ + Jᵀ f − c = M a_w`, `a_w` the provider's forward dynamics without armature, then the
/// LDLᵀ solve ([`crate::ldlt`]) of `M + diag(armature)`. `work` holds at least `nv² + 2 nv`;
/// a shorter one, or a pivot that is not positive, gives a NaN acceleration (the integrator
/// then stops with a non-finite state).
#[allow(clippy::too_many_arguments)]
pub fn forward_with_armature<D: SceneDynamics + ?Sized>(
    dynamics: &mut D,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    wrenches: &[f64],
    armature: &[f64],
    acc: &mut [f64],
    work: &mut [f64],
) {
    let nv = acc.len();
    let Some((m, rest)) = work.split_at_mut_checked(nv * nv) else {
        return acc.fill(f64::NAN);
    };
    let Some((b, rest)) = rest.split_at_mut_checked(nv) else {
        return acc.fill(f64::NAN);
    };
    let Some(d_inv) = rest.get_mut(..nv) else {
        return acc.fill(f64::NAN);
    };
    dynamics.forward(q, v, tau, wrenches, acc);
    dynamics.mass_matrix(q, m);
    for (i, bi) in b.iter_mut().enumerate() {
        *bi = m[i * nv..(i + 1) * nv]
            .iter()
            .zip(acc.iter())
            .map(|(mij, aj)| mij * aj)
            .sum();
    }
    let off = nv.saturating_sub(armature.len());
    for (i, a) in armature.iter().enumerate() {
        m[(off + i) * nv + off + i] += a;
    }
    let solved = factor_in_place(m, nv, d_inv).is_ok()
        && d_inv.iter().all(|d| *d > 0.0 && d.is_finite())
        && solve_in_place(m, nv, d_inv, b).is_ok();
    if solved {
        acc.copy_from_slice(b);
    } else {
        acc.fill(f64::NAN);
    }
}
