//! The paper's recurrent algorithm: `A(q)` by (12)–(16), (20) and `b(q, q̇)` by (17)–(19), (21).
//!
//! Read this file beside `docs/paper.md`, "The recurrent algorithm". Every block cites its equation and opens a tracer
//! section with the same label (`S::section("(14b)")`), so the op-count tracer attributes each
//! operation to a row of the paper's Table 1.
//!
//! **Indices.** The paper numbers bodies `1..N`; here they are `0..n` (paper body `j` is our
//! `j − 1`, the paper's `N` is our `n − 1`). `r_{i,j}` is the vector from `O_i` to `O_j`.
//!
//! **Inputs.** [`mass_matrix_base`] starts from the base-frame quantities of eq. (1), (2), (6)
//! ([`BodyKinematics`]: `r_{j-1,j}`, `a_j`, `m_j`, `c_j`, `I_j`), which is where Table 1 starts
//! counting. Its arithmetic follows the paper's counting convention (docs/paper.md, "Operation counts"):
//! 3×3 products accumulate from zero, skew matrices carry literal zeros, cumulative sums start
//! from zero where the paper's count says so (`m^Σ_{N+1} = 0`).
//!
//! **(14b).** Its printed formula is illegible and its printed cost fits no exact identity
//! (docs/paper.md, R6, I7). [`Variant`] selects an exact form, `R2` or `R1`;
//! [`mass_matrix_paper_bookkeeping`] reproduces the paper's bookkeeping, which is **wrong for
//! N ≥ 3**, on symbolic scalars only.
//!
//! **Prismatic joints.** The paper treats revolute joints only. Pairs with a prismatic joint use
//! the formulas of docs/paper.md, I6 (see [`mass_matrix_base`]); revolute pairs keep (16), (20),
//! which stay exact because `r_{i,k}` includes the joint translations.
//!
//! ```
//! use kanegen_dynamics::algorithms::recurrent::{mass_matrix, Variant};
//! use kanegen_model::random::{random_chain, ChainSpec};
//! use kanegen_dynamics::Params;
//! let chain = random_chain(&ChainSpec { n: 4, ..Default::default() }, 1);
//! let p = Params::<f64>::new(&chain);
//! let q = [0.1, -0.4, 0.7, 1.2];
//! let a2 = mass_matrix(&p, &q, Variant::R2);
//! let a1 = mass_matrix(&p, &q, Variant::R1);
//! for i in 0..4 {
//!     for j in 0..4 {
//!         assert!((a1[i][j] - a2[i][j]).abs() < 1e-9 * a2[0][0].abs());
//!         assert_eq!(a2[i][j], a2[j][i]);
//!     }
//! }
//! ```

use crate::algorithms::kinematics::{base_frame, inertial_external, motion, BodyKinematics};
use crate::linalg::{Mat3, Vec3};
use crate::loads::Loads;
use crate::params::Params;
use crate::scalar::{Scalar, Symbolic};
use kanegen_model::JointKind;

/// The exact forms of (14b) (docs/paper.md, R6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Variant {
    /// Exact: `M^rr,2_{i,j} = S̃_{i,j+1} r̃ᵀ_{j,j+1} + M^rr,2_{i,j+1}` with
    /// `S_{i,j} = Σ_{k≥j} m_k r_{i,k}` (and (14a) as `S̃_{i,N} r̃ᵀ_{N-1,N}`).
    R2,
    /// Exact: the printed scalar form (14a), (14b) with `μ = m^Σ_{j+1}` (the paper's per-matrix
    /// cost, 36 m + 36 a), plus the `i`-independent correction
    /// `Q_j = Σ_{l>j} p̃_l r̃ᵀ_{l-1,l}`, `p_l = Σ_{k>l} m_k r_{l,k}`, folded into `M^rr,1_j`.
    R1,
}

/// The form of (14b) evaluated: an exact [`Variant`], or `P`, the printed scalar form of (14b)
/// without the correction of `R1` — the structure whose operations Table 1 counts. `P` is exact
/// only for `N ≤ 2` (where (14b) is empty); for `N ≥ 3` the relative error of `A` is typically
/// 1e-2 … 1, so it is reachable only on a [`Symbolic`] scalar
/// ([`mass_matrix_paper_bookkeeping`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Form {
    R2,
    R1,
    P,
}

impl From<Variant> for Form {
    fn from(v: Variant) -> Self {
        match v {
            Variant::R2 => Form::R2,
            Variant::R1 => Form::R1,
        }
    }
}

/// Upper-triangular storage `x_{i,j}` for `i ≤ j < n`; reading an entry never written panics,
/// so an index slip in a recursion is caught rather than silently reading a zero.
struct Upper<T> {
    n: usize,
    data: Vec<Option<T>>,
}

impl<T> Upper<T> {
    fn new(n: usize) -> Self {
        Upper {
            n,
            data: (0..n * n).map(|_| None).collect(),
        }
    }
    fn set(&mut self, i: usize, j: usize, x: T) {
        debug_assert!(i <= j && j < self.n);
        self.data[i * self.n + j] = Some(x);
    }
    fn get(&self, i: usize, j: usize) -> &T {
        self.data[i * self.n + j]
            .as_ref()
            .unwrap_or_else(|| panic!("recurrent: entry ({i}, {j}) used before it was computed"))
    }
}

fn skew<S: Scalar>(x: &Vec3<S>) -> Mat3<S> {
    Mat3::skew(x)
}

/// `x̃ ỹᵀ`: the product of a skew matrix and a transposed skew matrix (27 m + 27 a, paper conv.).
fn skew_skew_t<S: Scalar>(x: &Vec3<S>, y: &Vec3<S>) -> Mat3<S> {
    skew(x).mul_mat(&skew(y).transpose())
}

/// The generalized inertia matrix `A` (full symmetric, `a[i][j]`) from base-frame inputs, by
/// (12)–(16) and (20), with (14b) in the form `variant`.
///
/// This is the entry point the Table-1 op-count tracer runs on symbolic inputs, so its operation
/// structure is the paper's: (12) `r_{i,j}`, (12a) `m^Σ_i`, (12b) `C_{i,j}` (computed although
/// revolute pairs never use it, as Table 1 rows 3 + 4 charge it), (13) `M^rr,1`, (14a)/(14b)
/// `M^rr,2`, (15a)/(15b) `M^rr,3`, (16) `M^Σ,rr_{i,j}` for all `i ≤ j`, and (20)
/// `A_ij = a_iᵀ (M^Σ,rr_{i,j} a_j)` for revolute pairs.
///
/// For pairs with a prismatic joint (axis `e`), only computed when the chain has one
/// (section `"I6"`), with `C^Σ_{i,j} = Σ_{k≥j} C_{i,k}` (`C_{j,j} = c_j`):
/// - prismatic `i ≤` prismatic `j`: `A_ij = m^Σ_j e_i·e_j`;
/// - revolute `i <` prismatic `j`: `A_ij = a_i · (C^Σ_{i,j} × e_j)`;
/// - prismatic `i <` revolute `j`: `A_ij = e_i · (a_j × C^Σ_{j,j})`.
///
/// Panics if `kin` is empty.
pub fn mass_matrix_base<S: Scalar>(kin: &[BodyKinematics<S>], variant: Variant) -> Vec<Vec<S>> {
    mass_matrix_form(kin, variant.into())
}

/// **Inexact for `N ≥ 3` — not a dynamics algorithm.** [`mass_matrix_base`] with (14b) in the
/// printed scalar form without the correction of [`Variant::R1`]: the structure whose operations
/// the paper's Table 1 counts, kept only so the op-count tracer can reproduce that bookkeeping.
/// It takes a [`Symbolic`] scalar, so it cannot be evaluated numerically by mistake.
pub fn mass_matrix_paper_bookkeeping<S: Symbolic>(kin: &[BodyKinematics<S>]) -> Vec<Vec<S>> {
    mass_matrix_form(kin, Form::P)
}

fn mass_matrix_form<S: Scalar>(kin: &[BodyKinematics<S>], variant: Form) -> Vec<Vec<S>> {
    let n = kin.len();
    assert!(n > 0, "recurrent: empty chain");
    let last = n - 1; // the paper's N
    let m = |j: usize| &kin[j].m;
    let c = |j: usize| &kin[j].c;

    // ---- Stage 1 ----
    S::section("(12)");
    // (12) r_{i,j} = r_{i,i+1} + r_{i+1,j},  j = N..3, i = j−2..1;  r_{i,i+1} = r_{j-1,j} of (2).
    let mut r: Upper<Vec3<S>> = Upper::new(n);
    for (j, k) in kin.iter().enumerate().skip(1) {
        r.set(j - 1, j, k.r.clone());
    }
    for j in (2..n).rev() {
        for i in (0..j - 1).rev() {
            let rij = r.get(i, i + 1) + r.get(i + 1, j);
            r.set(i, j, rij);
        }
    }

    S::section("(12a)");
    // (12a) m^Σ_i = m_i + m^Σ_{i+1},  m^Σ_{N+1} = 0  (N additions).
    let mut m_sigma = vec![S::zero(); n + 1];
    for i in (0..n).rev() {
        m_sigma[i] = m(i).clone() + m_sigma[i + 1].clone();
    }

    S::section("(12b)");
    // (12b) C_{i,j} = m_j r_{i,j} + c_j,  i = N−1..1, j = N..i+1.
    let mut c_ij: Upper<Vec3<S>> = Upper::new(n);
    for i in (0..last).rev() {
        for j in (i + 1..n).rev() {
            c_ij.set(i, j, r.get(i, j).scale(m(j)) + c(j).clone());
        }
    }

    // ---- 1. Inertia matrices of the sub-chains ----
    S::section("(13)");
    // (13a) M^rr,1_N = I_N;  (13b) M^rr,1_j = I_j + M^rr,1_{j+1}.
    let mut m_rr1: Vec<Mat3<S>> = vec![Mat3::zero(); n];
    m_rr1[last] = kin[last].inertia.clone();
    for j in (0..last).rev() {
        m_rr1[j] = &kin[j].inertia + &m_rr1[j + 1];
    }

    // M^rr,2_{i,j} = Σ_{k>j} m_k r̃_{i,k} r̃ᵀ_{j,k},  i ≤ j ≤ N−1.
    let mut m_rr2: Upper<Mat3<S>> = Upper::new(n);
    if variant == Form::R2 {
        S::section("(14)S");
        // S_{i,N} = m_N r_{i,N};  S_{i,j} = m_j r_{i,j} + S_{i,j+1}  (R2; the cost of (12b)).
        let mut s_ij: Upper<Vec3<S>> = Upper::new(n);
        for i in (0..last).rev() {
            s_ij.set(i, last, r.get(i, last).scale(m(last)));
            for j in (i + 1..last).rev() {
                let s = r.get(i, j).scale(m(j)) + s_ij.get(i, j + 1).clone();
                s_ij.set(i, j, s);
            }
        }
        if n >= 2 {
            S::section("(14a)");
            // (14a) M^rr,2_{i,N−1} = S̃_{i,N} r̃ᵀ_{N−1,N}  (= m_N r̃_{i,N} r̃ᵀ_{N−1,N}).
            for i in 0..last {
                m_rr2.set(
                    i,
                    last - 1,
                    skew_skew_t(s_ij.get(i, last), r.get(last - 1, last)),
                );
            }
        }
        S::section("(14b)");
        // (14b) M^rr,2_{i,j} = S̃_{i,j+1} r̃ᵀ_{j,j+1} + M^rr,2_{i,j+1},  i = N−2..1, j = N−2..i.
        for i in (0..last.saturating_sub(1)).rev() {
            for j in (i..last - 1).rev() {
                let x =
                    skew_skew_t(s_ij.get(i, j + 1), r.get(j, j + 1)) + m_rr2.get(i, j + 1).clone();
                m_rr2.set(i, j, x);
            }
        }
    } else {
        if n >= 2 {
            S::section("(14a)");
            // (14a) M^rr,2_{i,N−1} = m_N r̃_{i,N} r̃ᵀ_{N−1,N}  (36 m + 27 a per matrix).
            for i in 0..last {
                let x = skew_skew_t(r.get(i, last), r.get(last - 1, last)).scale(m(last));
                m_rr2.set(i, last - 1, x);
            }
        }
        S::section("(14b)");
        // (14b) scalar form M^rr,2_{i,j} = m^Σ_{j+1} r̃_{i,j+1} r̃ᵀ_{j,j+1} + M^rr,2_{i,j+1}
        // (36 m + 36 a per matrix). Not an identity: it misses Q_j (see R1-corr below).
        for i in (0..last.saturating_sub(1)).rev() {
            for j in (i..last - 1).rev() {
                let x = skew_skew_t(r.get(i, j + 1), r.get(j, j + 1)).scale(&m_sigma[j + 1])
                    + m_rr2.get(i, j + 1).clone();
                m_rr2.set(i, j, x);
            }
        }
        if variant == Form::R1 && n >= 3 {
            S::section("R1-corr");
            // Σ_{k≥l} m_k r_{i,k} = m^Σ_l r_{i,l} + p_l, so the scalar form misses
            // Q_j = Σ_{l>j} p̃_l r̃ᵀ_{l−1,l}, independent of i; fold it into M^rr,1_j (j ≤ N−2).
            // p_{N−1} = m^Σ_N r_{N−1,N};  p_l = m^Σ_{l+1} r_{l,l+1} + p_{l+1}  (p_N = 0).
            let mut p_l: Vec<Vec3<S>> = vec![Vec3::zero(); n];
            p_l[last - 1] = r.get(last - 1, last).scale(&m_sigma[last]);
            for l in (1..last - 1).rev() {
                p_l[l] = r.get(l, l + 1).scale(&m_sigma[l + 1]) + p_l[l + 1].clone();
            }
            // Q_{N−2} = p̃_{N−1} r̃ᵀ_{N−2,N−1};  Q_j = p̃_{j+1} r̃ᵀ_{j,j+1} + Q_{j+1}.
            let mut q_j = skew_skew_t(&p_l[last - 1], r.get(last - 2, last - 1));
            m_rr1[last - 2] = &m_rr1[last - 2] + &q_j;
            for j in (0..last - 2).rev() {
                q_j = skew_skew_t(&p_l[j + 1], r.get(j, j + 1)) + q_j;
                m_rr1[j] = &m_rr1[j] + &q_j;
            }
        }
    }

    // M^rr,3_{i,j} = Σ_{k>j} c̃_k r̃ᵀ_{i,k},  i ≤ j ≤ N−1  (R7).
    let mut m_rr3: Upper<Mat3<S>> = Upper::new(n);
    if n >= 2 {
        S::section("(15a)");
        // (15a) M^rr,3_{i,N−1} = c̃_N r̃ᵀ_{i,N}.
        for i in 0..last {
            m_rr3.set(i, last - 1, skew_skew_t(c(last), r.get(i, last)));
        }
    }
    S::section("(15b)");
    // (15b) M^rr,3_{i,j} = c̃_{j+1} r̃ᵀ_{i,j+1} + M^rr,3_{i,j+1},  i = N−2..1, j = N−2..i.
    for i in (0..last.saturating_sub(1)).rev() {
        for j in (i..last - 1).rev() {
            let x = skew_skew_t(c(j + 1), r.get(i, j + 1)) + m_rr3.get(i, j + 1).clone();
            m_rr3.set(i, j, x);
        }
    }

    // ---- 2. Resultant inertia matrices about the joints ----
    S::section("(16)");
    let mut m_sig_rr: Upper<Mat3<S>> = Upper::new(n);
    for i in 0..n {
        for j in i..n {
            let x = if j == last {
                if i == last {
                    // M^Σ,rr_{N,N} = M^rr,1_N
                    m_rr1[last].clone()
                } else {
                    // M^Σ,rr_{i,N} = M^rr,1_N + M^rr,3ᵀ_{i,N−1}
                    m_rr1[last].clone() + m_rr3.get(i, last - 1).transpose()
                }
            } else if i == j {
                // M^Σ,rr_{i,i} = M^rr,1_i + M^rr,2_{i,i} + M^rr,3_{i,i} + M^rr,3ᵀ_{i,i}
                m_rr1[i].clone()
                    + m_rr2.get(i, i).clone()
                    + m_rr3.get(i, i).clone()
                    + m_rr3.get(i, i).transpose()
            } else {
                // (R8) M^Σ,rr_{i,j} = M^rr,1_j + M^rr,2_{i,j} + M^rr,3_{j,j} + M^rr,3ᵀ_{i,j−1}
                m_rr1[j].clone()
                    + m_rr2.get(i, j).clone()
                    + m_rr3.get(j, j).clone()
                    + m_rr3.get(i, j - 1).transpose()
            };
            m_sig_rr.set(i, j, x);
        }
    }

    // ---- Pairs with a prismatic joint (docs/paper.md, I6) ----
    let revolute = |j: usize| kin[j].kind == JointKind::Revolute;
    let any_prismatic = kin.iter().any(|k| k.kind == JointKind::Prismatic);
    let mut c_sigma: Upper<Vec3<S>> = Upper::new(n);
    if any_prismatic {
        S::section("I6");
        // C^Σ_{i,j} = Σ_{k≥j} C_{i,k}:  C^Σ_{i,N} = C_{i,N};  C^Σ_{i,j} = C_{i,j} + C^Σ_{i,j+1};
        // on the diagonal C_{j,j} = c_j (r_{j,j} = 0).
        for i in 0..n {
            let mut acc = if i == last {
                c(last).clone()
            } else {
                c_ij.get(i, last).clone()
            };
            c_sigma.set(i, last, acc.clone());
            for j in (i..last).rev() {
                let cij = if i == j {
                    c(j).clone()
                } else {
                    c_ij.get(i, j).clone()
                };
                acc = cij + acc;
                c_sigma.set(i, j, acc.clone());
            }
        }
    }

    // ---- 4. (20) A_ij = a_iᵀ M^Σ,rr_{i,j} a_j ----
    S::section("(20)");
    let mut a = vec![vec![S::zero(); n]; n];
    for i in 0..n {
        for j in i..n {
            let (ai, aj) = (&kin[i].axis, &kin[j].axis);
            let x = match (revolute(i), revolute(j)) {
                (true, true) => ai.dot(&m_sig_rr.get(i, j).mul_vec(aj)),
                // prismatic i ≤ prismatic j: m^Σ_j e_i·e_j
                (false, false) => m_sigma[j].clone() * ai.dot(aj),
                // revolute i < prismatic j: a_i · (C^Σ_{i,j} × e_j)
                (true, false) => ai.dot(&c_sigma.get(i, j).cross(aj)),
                // prismatic i < revolute j: e_i · (a_j × C^Σ_{j,j})
                (false, true) => ai.dot(&aj.cross(c_sigma.get(j, j))),
            };
            a[j][i] = x.clone();
            a[i][j] = x;
        }
    }
    a
}

/// The generalized inertia matrix `A(q)` of the paper's recurrent algorithm: base-frame
/// kinematics (1), (2), (6) ([`base_frame`]) then [`mass_matrix_base`].
///
/// # Panics
/// On a kinematic tree (serial chains only; [`Params::assert_chain`]).
pub fn mass_matrix<S: Scalar>(p: &Params<S>, q: &[S], variant: Variant) -> Vec<Vec<S>> {
    p.assert_chain(match variant {
        Variant::R2 => "recurrent",
        Variant::R1 => "recurrent-r1",
    });
    let kin = base_frame(p, q);
    mass_matrix_base(&kin, variant)
}

/// The generalized forces `b(q, q̇) = Q − h` of `A q̈ = b` (eq. (8)): kinematics (1)–(7),
/// resultants (11), then [`bias_base`] with the joint drives `loads.tau` when given.
///
/// # Panics
/// On a kinematic tree (serial chains only; [`Params::assert_chain`]).
pub fn bias<S: Scalar>(p: &Params<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
    p.assert_chain("recurrent");
    let kin = base_frame(p, q);
    let mot = motion(&kin, qd);
    let f_ie = inertial_external(&kin, &mot, loads);
    bias_base(&kin, &f_ie, loads.tau.as_deref())
}

/// The backward force recursion (17)–(19) and the projection (21), from the resultants
/// `f_ie[j] = (f^IE_j, m^IE_j)` of eq. (11) (force at `O_j`, moment about `O_j`, base frame).
///
/// (19b) is evaluated by the O(N) recursion
/// `m^ΣO_j = m^IE_j + m^ΣO_{j+1} + r_{j,j+1} × f^Σ_{j+1}`, equivalent to the printed double sum
/// `m^Σ_j + Σ_{k>j} r̃_{j,k} f^IE_k` (docs/paper.md, R10); it absorbs (18), so `m^Σ_j` is not
/// formed separately (`m^ΣO_N = m^Σ_N = m^IE_N`, (18a), (19a)).
/// `b_j = a_j · m^ΣO_j` (revolute) or `a_j · f^Σ_j` (prismatic), plus `tau[j]` when given (21).
pub fn bias_base<S: Scalar>(
    kin: &[BodyKinematics<S>],
    f_ie: &[(Vec3<S>, Vec3<S>)],
    tau: Option<&[S]>,
) -> Vec<S> {
    let n = kin.len();
    assert_eq!(f_ie.len(), n, "f_ie has the wrong length");
    if let Some(t) = tau {
        assert_eq!(t.len(), n, "tau has the wrong length");
    }
    if n == 0 {
        return Vec::new();
    }
    let last = n - 1;

    S::section("(17)");
    // (17a) f^Σ_N = f^IE_N;  (17b) f^Σ_j = f^IE_j + f^Σ_{j+1}.
    let mut f_sig: Vec<Vec3<S>> = vec![Vec3::zero(); n];
    f_sig[last] = f_ie[last].0.clone();
    for j in (0..last).rev() {
        f_sig[j] = &f_ie[j].0 + &f_sig[j + 1];
    }

    S::section("(18)-(19)");
    // (18a), (19a) m^ΣO_N = m^Σ_N = m^IE_N;
    // (19b) by R10: m^ΣO_j = m^IE_j + m^ΣO_{j+1} + r_{j,j+1} × f^Σ_{j+1}.
    let mut mom_sig_o: Vec<Vec3<S>> = vec![Vec3::zero(); n];
    mom_sig_o[last] = f_ie[last].1.clone();
    for j in (0..last).rev() {
        mom_sig_o[j] = &f_ie[j].1 + &mom_sig_o[j + 1] + kin[j + 1].r.cross(&f_sig[j + 1]);
    }

    S::section("(21)");
    // (21) b_j = R^relᵀ_j m^ΣO_j (revolute) or T^relᵀ_j f^Σ_j (prismatic), + R^rel(j)ᵀ m^J(j)_j.
    (0..n)
        .map(|j| {
            let k = &kin[j];
            let bj = match k.kind {
                JointKind::Revolute => k.axis.dot(&mom_sig_o[j]),
                JointKind::Prismatic => k.axis.dot(&f_sig[j]),
            };
            match tau {
                Some(t) => bj + t[j].clone(),
                None => bj,
            }
        })
        .collect()
}
