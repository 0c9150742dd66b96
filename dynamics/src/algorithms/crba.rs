//! The composite-rigid-body algorithm in local body coordinates (RBDA Table 6.2; spatial_v2
//! `HandC`, the `H` part): an independent cross-check of the paper's inertial-frame algorithms (it
//! does not use `kinematics.rs`), and the fixed- and floating-base mass matrix of choice for
//! generated code.
//!
//! Any kinematic tree (`λ(i)` = [`crate::JointParams::parent`]): composite inertias `IC` in a
//! backward loop carried to `λ(i)`, then `H_ij = S_jᵀ F` with `F = IC_i S_i` carried up the
//! ancestors `j` of `i` by `Xupᵀ`; entries of joints on different branches stay zero. On a serial
//! chain (`λ(i) = i − 1`) the operations are exactly those of the chain algorithm. Spatial algebra
//! and conventions: [`crate::spatial`].
//!
//! ```
//! use kanegen_dynamics::algorithms::crba;
//! use kanegen_dynamics::Params;
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let model = random_chain(&ChainSpec { n: 3, ..Default::default() }, 1);
//! let p = Params::<f64>::new(&model);
//! let h = crba::mass_matrix(&p, &[0.1, -0.4, 0.9]);
//! assert!((h[0][2] - h[2][0]).abs() < 1e-12 && h[1][1] > 0.0);
//! ```

use crate::base::{FloatingBase, FLOATING_BASE_DOF};
use crate::joint::{carry_force, carry_inertia, inertia_s, s_tr, xup_trig, XupTrig};
use crate::linalg::Vec3;
use crate::params::Params;
use crate::scalar::Scalar;
use crate::spatial::{base_rows, Motion, RbInertia};

/// `Xup_j` of every joint, with its sine and cosine (one `sin_cos` per revolute joint).
fn transforms<S: Scalar>(p: &Params<S>, q: &[S]) -> Vec<XupTrig<S>> {
    assert_eq!(q.len(), p.dof(), "q has the wrong length");
    p.joints
        .iter()
        .zip(q)
        .map(|(jp, qj)| xup_trig(jp, qj))
        .collect()
}

/// Composite inertias `IC_i` of the subtrees (RBDA Table 6.2 backward loop):
/// `IC_i = I_i`, then, for `i = N−1 … 0` with a parent body, `IC_λ(i) += Xup_iᵀ IC_i Xup_i`.
/// The subtrees hanging from the base are left to the caller.
/// Each carry by [`carry_inertia`].
fn composite<S: Scalar>(p: &Params<S>, xup: &[XupTrig<S>]) -> Vec<RbInertia<S>> {
    let mut ic: Vec<RbInertia<S>> = p.joints.iter().map(|jp| jp.inertia.clone()).collect();
    for (i, jp) in p.joints.iter().enumerate().rev() {
        if let Some(lambda) = jp.parent {
            let carried = carry_inertia(jp, &xup[i], &ic[i]);
            let parent = ic[lambda].clone();
            ic[lambda] = parent + carried;
        }
    }
    ic
}

/// The joint-space inertia matrix `H(q)` (= the paper's `A(q)`), full and symmetric.
///
/// `p`: the model's parameters; `q`: joint positions (rad or m), length `N`. Returns `H` as `N`
/// rows of `N` entries; the upper triangle is computed and mirrored. Section `"spatial:crba"`.
pub fn mass_matrix<S: Scalar>(p: &Params<S>, q: &[S]) -> Vec<Vec<S>> {
    let n = p.dof();
    S::section("spatial:crba");
    let xup = transforms(p, q);
    let ic = composite(p, &xup);
    // Fill loop: F = IC_i S_i, H_ii = S_iᵀ F; over the ancestors j = λ(i), λ(λ(i)), …:
    // F = Xup_jᵀ F (carried from the child to j), H_ij = H_ji = S_jᵀ F.
    let mut h = vec![vec![S::zero(); n]; n];
    for i in 0..n {
        let mut f = inertia_s(&ic[i], &p.joints[i]);
        h[i][i] = s_tr(&p.joints[i], &f);
        let mut j = i;
        while let Some(lambda) = p.joints[j].parent {
            f = carry_force(&p.joints[j], &xup[j], &f);
            j = lambda;
            let hij = s_tr(&p.joints[j], &f);
            h[j][i] = hij.clone();
            h[i][j] = hij;
        }
    }
    h
}

/// The `(6+N)×(6+N)` mass matrix of the arm `p` on the free-floating base `base` (RBDA §9.3,
/// Table 9.6 / spatial_v2 `HandC` with a floating base), with the conventions of
/// [`crate::base`]: independent of the virtual-joint extension of
/// [`crate::algorithms::floating`].
///
/// The base is body 0 with a 6-dof joint whose motion subspace is `1₆` in base coordinates, so
/// the base speeds of `ν = [v_b; ω_b; q̇]` are the base joint's speeds reordered. The base block
/// is the composite inertia of the whole tree `IC_0 = I_base + Σ_{λ(i) = base} Xup_iᵀ IC_i Xup_i`
/// applied to unit motions; the arm columns `F = IC_i S_i` are carried down the ancestors to the
/// base, `A_bi = F` (rows `[f; n]`). Any kinematic tree. `A` does not depend on the base pose. Section `"spatial:floating"`.
pub fn floating_mass_matrix<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    q: &[S],
) -> Vec<Vec<S>> {
    let n = p.dof();
    S::section("spatial:floating");
    let nb = FLOATING_BASE_DOF;
    let xup = transforms(p, q);
    let i_base = base.inertia.clone();
    let ic = composite(p, &xup);
    // IC_0 = I_base + Σ over the joints on the base Xup_iᵀ IC_i Xup_i.
    let mut ic0 = i_base;
    for (i, jp) in p.joints.iter().enumerate() {
        if jp.parent.is_none() {
            ic0 = ic0 + carry_inertia(jp, &xup[i], &ic[i]);
        }
    }
    let mut a = vec![vec![S::zero(); nb + n]; nb + n];
    // Base block: column m of ν_b is the unit motion [0; e_m] (m < 3) or [e_{m−3}; 0].
    let unit = |m: usize| {
        let mut e = Vec3::zero();
        e.0[m % 3] = S::one();
        if m < 3 {
            Motion {
                ang: Vec3::zero(),
                lin: e,
            }
        } else {
            Motion {
                ang: e,
                lin: Vec3::zero(),
            }
        }
    };
    #[allow(clippy::needless_range_loop)] // a[i][m] and a[m][i] are both written
    for m in 0..nb {
        let col = base_rows(&ic0.mul(&unit(m)));
        // Upper triangle, mirrored (IC_0 is symmetric; mirroring makes A exactly so).
        for (i, x) in col.into_iter().enumerate().take(m + 1) {
            a[m][i] = x.clone();
            a[i][m] = x;
        }
    }
    for i in 0..n {
        let mut f = inertia_s(&ic[i], &p.joints[i]);
        a[nb + i][nb + i] = s_tr(&p.joints[i], &f);
        // Over the ancestors as in `mass_matrix`, then from the subtree's root onto the base.
        let mut j = i;
        loop {
            f = carry_force(&p.joints[j], &xup[j], &f);
            let Some(lambda) = p.joints[j].parent else {
                break;
            };
            j = lambda;
            let hij = s_tr(&p.joints[j], &f);
            a[nb + j][nb + i] = hij.clone();
            a[nb + i][nb + j] = hij;
        }
        for (r, x) in base_rows(&f).into_iter().enumerate() {
            a[r][nb + i] = x.clone();
            a[nb + i][r] = x;
        }
    }
    a
}
