//! The joint torques of an external wrench and their derivative with respect to the joint
//! positions: what an external wrench adds to the step Jacobians ([`super::linearize`]).
//!
//! A wrench (force `F`, moment `n`, base axes) at the origin `p` of body `i` loads the joints by
//! `τ_ext = Jᵀ [F; n]`, `J` the Jacobian of `p` (rows `[v; ω]`, base axes, Pinocchio's
//! `LOCAL_WORLD_ALIGNED`): `τ_k = v_k · F + ω_k · n`, where column `k` is `(v_k, ω_k)`, nonzero
//! only for the joints that support body `i`. Joints `j`, `k` that support the same body are
//! ordered along its path, `j` an ancestor of `k` exactly when `j < k` (parents come first).
//! Moving joint `j` turns everything outboard of it about its axis `ω_j` (RBDA §2.9; a
//! prismatic joint translates it, `ω_j = 0`), so
//!
//! - `∂ω_k/∂q_j = ω_j × ω_k` and `∂v_k/∂q_j = ω_j × v_k` for `j < k` (joint `k` moves with `j`);
//! - `∂ω_k/∂q_j = 0` and `∂v_k/∂q_j = ω_k × v_j` for `j ≥ k` (the point `p` moves by
//!   `v_j`, the axis of `k` does not: `v_k = ω_k × (p − o_k)` for a revolute joint, and
//!   `ω_k = 0` for a prismatic one);
//! - a wrench fixed in the base frame has `∂F/∂q = ∂n/∂q = 0`; one fixed in the body turns with
//!   it, `∂F/∂q_j = ω_j × F`, `∂n/∂q_j = ω_j × n` for every supporting `j`.
//!
//! A free-floating base enters as six more columns before the joints', its speeds in base
//! coordinates (`[e_m; 0]` and `[e_m × p; e_m]`, the columns of a fixed root with three
//! prismatic and three revolute joints at the base origin): the same formulas give the base's
//! rows; its own columns (the pose) are not these (the step Jacobians take the attitude through
//! `R(quat)`).
//!
//! Together, for `j < k`: `∂τ_k/∂q_j = (ω_j × v_k) · F + (ω_j × ω_k) · n` in the base frame,
//! and `0` in the body (the turn of the wrench cancels that of the columns); for `j ≥ k`:
//! `∂τ_k/∂q_j = (ω_k × v_j) · F`, plus `v_k · (ω_j × F) + ω_k · (ω_j × n)` in the body.

/// `a × b`.
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a · b`.
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `R x`.
#[must_use]
pub fn rotate(r: &[[f64; 3]; 3], x: &[f64; 3]) -> [f64; 3] {
    core::array::from_fn(|i| dot(&r[i], x))
}

/// `Rᵀ x`.
#[must_use]
pub fn rotate_back(r: &[[f64; 3]; 3], x: &[f64; 3]) -> [f64; 3] {
    core::array::from_fn(|i| r[0][i] * x[0] + r[1][i] * x[1] + r[2][i] * x[2])
}

/// Adds `∂τ_ext/∂q` (module doc) of the wrench `(force, moment)` (base axes) at the origin of a
/// body to `out` (`n × n`, row-major, row `k` = `τ_k`, column `j` = `∂/∂q_j`): `jac` the
/// Jacobian of that origin (`6 × n`, row-major, rows `[v; ω]`, base axes), `body_fixed` whether
/// the wrench turns with the body (fixed in its frame) or stays fixed in the base frame.
/// Slices of the wrong length leave `out` as it is.
pub fn add_wrench_torque_derivatives(
    jac: &[f64],
    force: &[f64; 3],
    moment: &[f64; 3],
    body_fixed: bool,
    out: &mut [f64],
) {
    let n = jac.len() / 6;
    if jac.len() != 6 * n || out.len() != n * n {
        return;
    }
    let column = |c: usize| -> ([f64; 3], [f64; 3]) {
        (
            core::array::from_fn(|r| jac[r * n + c]),
            core::array::from_fn(|r| jac[(3 + r) * n + c]),
        )
    };
    for k in 0..n {
        let (vk, wk) = column(k);
        for j in 0..n {
            let (vj, wj) = column(j);
            out[k * n + j] += if j < k {
                if body_fixed {
                    0.0
                } else {
                    dot(&cross(&wj, &vk), force) + dot(&cross(&wj, &wk), moment)
                }
            } else {
                let point = dot(&cross(&wk, &vj), force);
                if body_fixed {
                    point + dot(&vk, &cross(&wj, force)) + dot(&wk, &cross(&wj, moment))
                } else {
                    point
                }
            };
        }
    }
}
