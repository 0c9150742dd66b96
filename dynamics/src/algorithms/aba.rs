//! The articulated-body algorithm in local body coordinates (R. Featherstone, *Rigid Body
//! Dynamics Algorithms*, 2008, "RBDA", §7.3, Table 7.1; spatial_v2 `FDab`): forward dynamics
//! `q̈ = H⁻¹ (τ − C(q, q̇, f_ext))` in three O(N) passes, with no mass matrix and no
//! factorization. On a free-floating base (RBDA ch. 9; spatial_v2 `FDfb`), [`floating`] returns
//! `ν̇ = [v̇_b; ω̇_b; q̈]` for the same loads as [`crate::algorithms::floating::forward_dynamics`].
//! Spatial algebra and conventions: [`crate::spatial`]; joints: [`crate::joint`].
//!
//! Any kinematic tree (`λ(i)` = [`crate::JointParams::parent`]), revolute and prismatic joints.
//!
//! - **Pass 1** (root to leaves): `Xup_i`, `v_i = Xup_i v_λ(i) + vJ_i`, the velocity-product
//!   acceleration `c_i = v_i ×ₘ vJ_i` (`cJ = 0`), and `I^A_i = I_i`,
//!   `p^A_i = v_i ×* I_i v_i − f^x_i`.
//! - **Pass 2** (leaves to root): `U_i = I^A_i S_i`, `D_i = S_iᵀ U_i`, `u_i = τ_i − S_iᵀ p^A_i`,
//!   then `I^a_i = I^A_i − U_i D_i⁻¹ U_iᵀ` and `p^a_i = p^A_i + I^a_i c_i + U_i D_i⁻¹ u_i`
//!   carried to the parent: `I^A_λ += Xup_iᵀ I^a_i Xup_i`, `p^A_λ += Xup_iᵀ p^a_i`.
//! - **Pass 3** (root to leaves): `a'_i = Xup_i a_λ(i) + c_i`,
//!   `q̈_i = D_i⁻¹ (u_i − U_iᵀ a'_i)`, `a_i = a'_i + S_i q̈_i`.
//!
//! **Loads** exactly as [`crate::algorithms::rnea`] takes them: gravity as the fictitious base
//! acceleration `a_0 = −a_grav = [0; −g]` (RBDA §5.3), external wrenches as `−f^x_i` in `p^A_i`
//! (base-frame ones rotated by `E_0i = E_i E_0λ(i)` along the body's own path), `τ` the drives.
//!
//! **Inertias** are read only as the local-frame algorithms read them: the body's spatial inertia
//! about its origin, [`crate::JointParams::inertia`] (and [`FloatingBase::inertia`]). Regrouped
//! parameters ([`crate::regroup`]) give the same `H` and `C`, hence the same `q̈`: the
//! articulated inertias differ, the joint-space result does not (`dynamics/tests/aba.rs`).
//!
//! # Articulated inertias: three 3×3 blocks
//!
//! `I^A = [A B; Bᵀ C]` (moment rows first, like [`crate::spatial::Force`]) with `A`, `C`
//! symmetric: 21 numbers, of which only the upper triangles of `A` and `C` are computed (the
//! lower ones are the same values). A rigid body is `A = Ī`, `B = h̃`, `C = m 1`, so its
//! literal zeros fold away in a trace, and a leaf body's `I^a` is a constant of the model.
//! `Xup_iᵀ I^a Xup_i` is a rotation of the three blocks by `E` (`EᵀAE`, `EᵀBE`, `EᵀCE`), then a
//! shift by `r`: `C'' = C'`, `B'' = B' + r̃ C'`, `A'' = A' + r̃ B''ᵀ + (r̃ B'ᵀ)ᵀ`
//! (`= A' − B' r̃ + r̃ B'ᵀ − r̃ C' r̃`). A joint on a fixed base carries nothing to it, so its
//! `I^a`, `p^a` are not formed, nor is `S_i q̈_i` added to a leaf's acceleration. One division
//! per joint (`D_i⁻¹`, a constant for a leaf), and on a free-floating base six more in the
//! LDLᵀ of the base's `6×6` articulated inertia ([`crate::ldlt`]).
//!
//! # Cost against LDLᵀ on the mass matrix
//!
//! Emitted operations (`mul + add` after folding, common-subexpression and dead-code
//! elimination; divisions apart) of the generated `forward_dynamics`: fixed base, no gravity,
//! regrouped parameters, in the body frames the generator chose (`kanegen_codegen`'s defaults:
//! the random chains in canonical frames, every joint axis z). LDLᵀ on the CRBA's `M` and the
//! RNEA's `c`; LDLᵀ as the generator pairs it, with its cheapest mass-matrix method and its
//! cheapest bias method (on the random chains up to N = 9 the CRBA and the classical
//! Newton–Euler); this algorithm. The random chains are `random_chain(N, seed 1000 + N)` of
//! `benches/data` (general geometry: dense rotations, skew axes). `codegen/tests/aba.rs` measures
//! them again and fails when this table is stale.
//!
//! | model | N | LDLᵀ, CRBA + RNEA | LDLᵀ, cheapest | ABA | div (cheapest LDLᵀ / ABA) | emitted |
//! |---|---:|---:|---:|---:|---:|---|
//! | SSRMS (Nguyen & Hughes 1994) | 7 | 871 | 791 | 943 | 7 / 5 | LDLᵀ |
//! | random chain | 4 | 907 | 798 | 1322 | 4 / 3 | LDLᵀ |
//! | random chain | 8 | 3037 | 2728 | 3502 | 8 / 7 | LDLᵀ |
//! | random chain | 16 | 10161 | 9452 | 7863 | 16 / 15 | ABA |
//! | random chain | 32 | 42249 | 34889 | 16582 | 32 / 31 | ABA |
//! | random chain | 64 | 194617 | 158121 | 34023 | 64 / 63 | ABA |
//!
//! On the random chains ABA costs `545 N − 858` (within one operation; in the chains' own
//! frames, with dense rotations and skew axes, it was `823 N − 874`), LDLᵀ grows like `N³/6` on
//! top of the mass matrix's `O(N²)`. **Crossovers** (every N from 4 to 24 measured): ABA is
//! cheaper than LDLᵀ on the CRBA and the RNEA from **N = 11** (5137 against 5226), and than the
//! generator's cheapest LDLᵀ from **N = 13** (6227 against 6438), which is where generated code
//! switches to it (N = 9 and 10 before the CRBA and the Newton–Euler bias carried through
//! canonical frames' placements in two turns, `JointParams::split_placement`; from N = 25 the
//! mass matrix is traced without them, `codegen::choose`); at N = 64 it needs 4.6× fewer
//! operations. On SSRMS (N = 7) ABA costs 943 against 871 for LDLᵀ
//! on the CRBA and the RNEA, and LDLᵀ with the classical Newton–Euler bias costs 791 and is
//! emitted: its axes are coordinate axes (`I^a S = 0` gives zero rows and columns)
//! and its joint placements signed permutations and offsets along one axis, which fold. A
//! free-floating base makes LDLᵀ factor `6 + N` speeds while ABA adds one 6×6 solve: on the
//! 7-dof free-flyer of `kanegen-generated` the two are close (ABA 2869; LDLᵀ 2948, and 2735
//! with the two-step carries through its placements, which it emits). The
//! leaf's `D` is a constant of the model, hence `N − 1` divisions.
//!
//! # The run-time path: a workspace
//!
//! [`Workspace`] holds every per-body quantity of the passes (Pinocchio's `Data`; [`Params`] is
//! its `Model`), allocated once; [`forward_dynamics_in`] and [`floating_in`] overwrite it and the
//! caller's output and allocate nothing. The allocating [`forward_dynamics`] and [`floating`]
//! make a workspace and call them, so the symbolic trace is that of one algorithm. An
//! `armature` (the reflected rotor inertia `I_m n²` of a geared motor, Pinocchio's
//! `Model::armature`) adds `a_i q̈_i` to joint `i`'s torque: `D_i = S_iᵀ U_i + a_i`, all else
//! unchanged, so `q̈ = (H + diag(a))⁻¹ (τ − C)` with no mass matrix (`dynamics/tests/aba.rs`).
//! This is what `kanegen simulate` evaluates per right-hand side when the scene names no
//! algorithm. Measured side by side with numeric Pinocchio 4.1 (`benches/peers`, `CASADI_SIDE=0
//! RANDOM_N="7 8 16 32 64"`, 3 passes, thread CPU time, default `RUSTFLAGS` against g++ -O3
//! -march=native): SSRMS 1215 ns against 2049 ns for Pinocchio's faster `aba` (WORLD), random
//! chains N = 7, 16, 64: 1223, 2924, 12127 ns against 2098, 5118, 19913: 1.64–1.75× faster from
//! N = 6 to 64 on all ten models. Generated code is 1.6–1.7× faster still on the random chains
//! and 4–8× on the robots. An ABA in base coordinates (Pinocchio's WORLD convention: nothing
//! carried child to parent, each body's inertia turned into base coordinates instead) measured
//! 1.08–1.15× slower than this one in the same run, and evaluating the model's own trace as a
//! flat tape of `f64` registers 4× slower on SSRMS and about 20× on the random chains
//! (`examples/runtime_fd.rs`); neither is kept.
//!
//! ```
//! use kanegen_dynamics::algorithms::aba;
//! use kanegen_dynamics::{Loads, Methods, Params};
//! use kanegen_model::random::{random_tree, ChainSpec};
//! let tree = random_tree(&ChainSpec { n: 5, prismatic_fraction: 0.4, ..Default::default() }, 3);
//! let p = Params::<f64>::new(&tree);
//! let (q, qd) = ([0.1, -0.4, 0.9, 0.3, -1.2], [0.5, 0.2, -0.3, 0.1, 0.7]);
//! let loads = Loads { tau: Some(vec![1.0, -2.0, 0.5, 0.0, 3.0]), ..Loads::default() };
//! // The same q̈ as LDLᵀ on the CRBA mass matrix and the RNEA bias.
//! let qdd = aba::forward_dynamics(&p, &q, &qd, &loads);
//! let want = Methods::SPATIAL.forward_dynamics(&p, &q, &qd, &loads);
//! assert!(qdd.iter().zip(&want).all(|(x, y)| (x - y).abs() < 1e-9 * (1.0 + y.abs())));
//! ```

use crate::algorithms::rnea::subtract_external;
use crate::base::{FloatingBase, FloatingState, BASE_BODY, FLOATING_BASE_DOF};
use crate::joint::{s_times, s_tr, xup};
use crate::linalg::{Mat3, Vec3};
use crate::loads::{LoadFrame, Loads};
use crate::params::{JointParams, Params};
use crate::scalar::Scalar;
use crate::spatial::{Force, Motion, RbInertia, Xform};
use kanegen_model::JointKind;

/// A symmetric 3×3 matrix from its upper triangle `f(r, c)`, `r ≤ c` (mirrored, not recomputed).
fn symmetric<S: Scalar>(f: impl Fn(usize, usize) -> S) -> Mat3<S> {
    let mut m = Mat3::zero();
    for r in 0..3 {
        for c in r..3 {
            let x = f(r, c);
            m.0[c][r] = x.clone();
            m.0[r][c] = x;
        }
    }
    m
}

/// An articulated-body inertia `[A B; Bᵀ C]` (`A`, `C` symmetric), acting on a motion `[ω; v]`
/// as `[A ω + B v; Bᵀ ω + C v]` (RBDA §7.1).
#[derive(Clone, Debug)]
struct Articulated<S> {
    a: Mat3<S>,
    b: Mat3<S>,
    c: Mat3<S>,
}

impl<S: Scalar> Articulated<S> {
    /// A rigid body's inertia: `A = Ī`, `B = h̃`, `C = m 1` (RBDA eq. (2.63)).
    fn rigid(i: &RbInertia<S>) -> Self {
        Articulated {
            a: i.ibar.clone(),
            b: Mat3::skew(&i.h),
            c: Mat3::identity().scale(&i.m),
        }
    }

    /// `I^A m`.
    fn mul(&self, m: &Motion<S>) -> Force<S> {
        Force {
            ang: self.a.mul_vec(&m.ang) + self.b.mul_vec(&m.lin),
            lin: self.b.tr_mul_vec(&m.ang) + self.c.mul_vec(&m.lin),
        }
    }

    /// `I^A S_j` (only the non-zero half of `S_j` is multiplied).
    fn times_s(&self, jp: &JointParams<S>) -> Force<S> {
        let x = &jp.axis;
        match jp.kind {
            JointKind::Revolute => Force {
                ang: self.a.mul_vec(x),
                lin: self.b.tr_mul_vec(x),
            },
            JointKind::Prismatic => Force {
                ang: self.b.mul_vec(x),
                lin: self.c.mul_vec(x),
            },
        }
    }

    /// `I^a = I^A − U Wᵀ` for `W = U D⁻¹` (symmetric: `U Wᵀ = U Uᵀ D⁻¹`). `I^a S = 0`
    /// exactly; when `S` is a coordinate axis `e_k` of `[ω; v]` (`k` of 0..6:
    /// [`crate::JointParams::coordinate_axis`], `+ 3` for a prismatic joint), its row and
    /// column are those zeros, written as such.
    fn minus_outer(&self, u: &Force<S>, w: &Force<S>, zero: Option<usize>) -> Self {
        let z = |r: usize, c: usize| zero.is_some_and(|k| k == r || k == c);
        let entry = |z: bool, x: &S, ur: S, wc: S| if z { S::zero() } else { x.clone() - ur * wc };
        Articulated {
            a: symmetric(|r, c| entry(z(r, c), &self.a.0[r][c], u.ang.at(r), w.ang.at(c))),
            b: Mat3(core::array::from_fn(|r| {
                core::array::from_fn(|c| {
                    entry(z(r, c + 3), &self.b.0[r][c], u.ang.at(r), w.lin.at(c))
                })
            })),
            c: symmetric(|r, c| entry(z(r + 3, c + 3), &self.c.0[r][c], u.lin.at(r), w.lin.at(c))),
        }
    }

    /// `Xᵀ I^A X`: from the child's coordinates to the parent's, `X = Xup = [E 0; −E r̃ E]`.
    /// Rotation `M' = Eᵀ M E` of each block, then the shift by `r` (module docs).
    fn carried(&self, x: &Xform<S>) -> Self {
        let e = &x.e;
        let ae = self.a.mul_mat(e);
        let a1 = symmetric(|r, c| e.col(r).dot(&ae.col(c)));
        let be = self.b.mul_mat(e);
        let b1 = Mat3(core::array::from_fn(|r| {
            core::array::from_fn(|c| e.col(r).dot(&be.col(c)))
        }));
        let ce = self.c.mul_mat(e);
        let c1 = symmetric(|r, c| e.col(r).dot(&ce.col(c)));
        // B'' = B' + r̃ C' (column by column: r × C'_c).
        let rc: [Vec3<S>; 3] = core::array::from_fn(|c| x.r.cross(&c1.col(c)));
        let b2 = Mat3(core::array::from_fn(|r| {
            core::array::from_fn(|c| b1.at(r, c) + rc[c].at(r))
        }));
        // A'' = A' + r̃ B''ᵀ + (r̃ B'ᵀ)ᵀ: entry (r, c) = A'_rc + (r × B''_row c)_r + (r × B'_row r)_c.
        let rb2: [Vec3<S>; 3] = core::array::from_fn(|k| x.r.cross(&b2.row(k)));
        let rb1: [Vec3<S>; 3] = core::array::from_fn(|k| x.r.cross(&b1.row(k)));
        let a2 = symmetric(|r, c| a1.at(r, c) + rb2[c].at(r) + rb1[r].at(c));
        Articulated {
            a: a2,
            b: b2,
            c: c1,
        }
    }
}

impl<S: Scalar> core::ops::Add for Articulated<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        // Symmetric blocks: add the upper triangles, mirror.
        Articulated {
            a: symmetric(|r, c| self.a.at(r, c) + o.a.at(r, c)),
            b: self.b + o.b,
            c: symmetric(|r, c| self.c.at(r, c) + o.c.at(r, c)),
        }
    }
}

/// `Fᵀ m`: a force's power on a motion (`U_iᵀ a'_i`).
fn power<S: Scalar>(f: &Force<S>, m: &Motion<S>) -> S {
    f.ang.dot(&m.ang) + f.lin.dot(&m.lin)
}

/// A floating base's articulated inertia and bias force `(I^A_0, p^A_0)`.
type Body0<S> = (Articulated<S>, Force<S>);

/// What "body −1" (the fixed or floating base) hands the passes: its velocity, the rotation
/// `E_0` of base-frame wrenches into its coordinates, and, on a floating base, its own
/// articulated inertia and bias force (which the joints on the base are added to).
struct Root<S> {
    v: Motion<S>,
    e0: Mat3<S>,
    floating: Option<Body0<S>>,
}

/// The data of the articulated-body algorithm for one model: every per-body quantity of the
/// three passes, allocated once by [`Workspace::new`] and overwritten by each call of
/// [`forward_dynamics_in`] or [`floating_in`], which then allocate nothing (Pinocchio's
/// `Model`/`Data` split: [`Params`] is the model, this is the data). A workspace fits the models
/// with its number of joints; the allocating [`forward_dynamics`] and [`floating`] make one per
/// call.
#[derive(Clone, Debug)]
pub struct Workspace<S> {
    /// `Xup_i`.
    xup: Vec<Xform<S>>,
    /// `v_i`.
    v: Vec<Motion<S>>,
    /// `c_i`.
    c: Vec<Motion<S>>,
    /// `E_0i` (when some wrench is in the base frame).
    e0: Vec<Mat3<S>>,
    /// `I^A_i`.
    ia: Vec<Articulated<S>>,
    /// `p^A_i`.
    pa: Vec<Force<S>>,
    /// `U_i`.
    u_vec: Vec<Force<S>>,
    /// `D_i⁻¹`.
    d_inv: Vec<S>,
    /// `u_i`.
    u: Vec<S>,
    /// `a_i`.
    acc: Vec<Motion<S>>,
    /// Whether body `i` has a child (its `a_i` is read).
    has_child: Vec<bool>,
}

impl<S: Scalar> Workspace<S> {
    /// The workspace of `p` (any model with `p.dof()` joints).
    #[must_use]
    pub fn new(p: &Params<S>) -> Self {
        let n = p.dof();
        let (motion, force) = (Motion::zero(), Force::zero());
        Workspace {
            xup: vec![Xform::identity(); n],
            v: vec![motion.clone(); n],
            c: vec![motion.clone(); n],
            e0: vec![Mat3::identity(); n],
            ia: vec![
                Articulated {
                    a: Mat3::zero(),
                    b: Mat3::zero(),
                    c: Mat3::zero(),
                };
                n
            ],
            pa: vec![force.clone(); n],
            u_vec: vec![force; n],
            d_inv: vec![S::zero(); n],
            u: vec![S::zero(); n],
            acc: vec![motion; n],
            has_child: vec![false; n],
        }
    }

    /// The number of joints it fits.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.xup.len()
    }
}

/// Checks the lengths of a call's arguments against the model (panics naming the argument).
fn check_args<S: Scalar>(
    p: &Params<S>,
    ws: &Workspace<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
    armature: Option<&[S]>,
) {
    let n = p.dof();
    assert_eq!(ws.dof(), n, "the workspace was made for another model");
    assert_eq!(q.len(), n, "q has the wrong length");
    assert_eq!(qd.len(), n, "qd has the wrong length");
    if let Some(tau) = &loads.tau {
        assert_eq!(tau.len(), n, "loads.tau has the wrong length");
    }
    if let Some(a) = armature {
        assert_eq!(a.len(), n, "armature has the wrong length");
    }
    assert!(
        loads
            .external
            .iter()
            .all(|e| e.body < n || e.body == BASE_BODY),
        "an external wrench names a body past the end of the chain"
    );
}

/// Passes 1 and 2 over the tree into `ws` (per joint `Xup, c, U, D⁻¹, u`); the root's
/// articulated inertia and bias force when it is floating. `armature` (Pinocchio's name; the
/// reflected rotor inertia `I_m n²` of a geared motor) adds `a_i q̈_i` to joint `i`'s
/// generalized force: `D_i = S_iᵀ U_i + a_i`, everything else as without it.
fn backward<S: Scalar>(
    p: &Params<S>,
    ws: &mut Workspace<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
    armature: Option<&[S]>,
    root: Root<S>,
) -> Option<Body0<S>> {
    let n = p.dof();
    let need_rot = loads.external.iter().any(|e| e.frame == LoadFrame::Base);
    // Pass 1 (RBDA Table 7.1, first loop).
    for (j, (jp, (qj, qdj))) in p.joints.iter().zip(q.iter().zip(qd)).enumerate() {
        let v_parent = jp.parent.map_or(&root.v, |l| &ws.v[l]);
        // Xup_j = XJ(q_j) Xtree_j (RBDA §4.4, `jcalc`)
        let x = xup(jp, qj);
        // vJ = S_j q̇_j
        let vj = s_times(jp, qdj);
        // v_j = Xup_j v_λ + vJ (RBDA eq. (7.34))
        let carried = x.apply(v_parent);
        // c_j = cJ + v_j ×ₘ vJ with cJ = 0 (RBDA eq. (7.35)), as (Xup_j v_λ) ×ₘ vJ: vJ ×ₘ vJ = 0
        ws.c[j] = carried.crm(&vj);
        let v = carried + vj;
        // I^A_j = I_j, p^A_j = v_j ×* I_j v_j − f^x_j (RBDA Table 7.1)
        let inertia = &jp.inertia;
        let pj = v.crf(&inertia.mul(&v));
        if need_rot {
            // E_0j = E_j E_0λ
            let e0 = x.e.mul_mat(jp.parent.map_or(&root.e0, |l| &ws.e0[l]));
            ws.e0[j] = e0;
        }
        let e0 = if need_rot { &ws.e0[j] } else { &root.e0 };
        ws.pa[j] = if loads.external.is_empty() {
            pj
        } else {
            subtract_external(pj, loads, j, e0)
        };
        ws.ia[j] = Articulated::rigid(inertia);
        ws.v[j] = v;
        ws.xup[j] = x;
    }
    let mut base = root.floating;
    // Pass 2 (RBDA Table 7.1, second loop), leaves first.
    for j in (0..n).rev() {
        let jp = &p.joints[j];
        // U_j = I^A_j S_j (RBDA eq. (7.43))
        let u_vec = ws.ia[j].times_s(jp);
        // D_j = S_jᵀ U_j (RBDA eq. (7.44)), plus the armature, inverted once.
        let d = s_tr(jp, &u_vec);
        let d = match armature {
            Some(a) => d + a[j].clone(),
            None => d,
        };
        let d_inv = S::one() / d;
        // u_j = τ_j − S_jᵀ p^A_j (RBDA eq. (7.45))
        let spa = s_tr(jp, &ws.pa[j]);
        let u = match &loads.tau {
            Some(tau) => tau[j].clone() - spa,
            None => -spa,
        };
        if jp.parent.is_some() || base.is_some() {
            // W = U_j D_j⁻¹
            let w = Force {
                ang: u_vec.ang.scale(&d_inv),
                lin: u_vec.lin.scale(&d_inv),
            };
            // I^a_j = I^A_j − U_j D_j⁻¹ U_jᵀ (RBDA eq. (7.47)); its zero row and column
            // `I^a S = U (1 − SᵀU / D) = 0` hold without armature only.
            let zero = jp
                .coordinate_axis
                .filter(|_| armature.is_none())
                .map(|k| match jp.kind {
                    JointKind::Revolute => k,
                    JointKind::Prismatic => k + 3,
                });
            let i_small = ws.ia[j].minus_outer(&u_vec, &w, zero);
            // p^a_j = p^A_j + I^a_j c_j + U_j D_j⁻¹ u_j (RBDA eq. (7.48))
            let p_small = ws.pa[j].clone()
                + i_small.mul(&ws.c[j])
                + Force {
                    ang: w.ang.scale(&u),
                    lin: w.lin.scale(&u),
                };
            // I^A_λ += Xup_jᵀ I^a_j Xup_j, p^A_λ += Xup_jᵀ p^a_j (RBDA eq. (7.47), (7.48))
            let x = &ws.xup[j];
            let (i_up, p_up) = (i_small.carried(x), x.tr_apply(&p_small));
            match jp.parent {
                Some(l) => {
                    ws.ia[l] = ws.ia[l].clone() + i_up;
                    ws.pa[l] = ws.pa[l].clone() + p_up;
                }
                None => {
                    let (i0, p0) = base.take().expect("a floating root");
                    base = Some((i0 + i_up, p0 + p_up));
                }
            }
        }
        ws.u_vec[j] = u_vec;
        ws.d_inv[j] = d_inv;
        ws.u[j] = u;
    }
    base
}

/// Pass 3 (RBDA Table 7.1, third loop): `q̈` from the roots' acceleration `a_root`, into `qdd`.
fn accelerations<S: Scalar>(
    p: &Params<S>,
    ws: &mut Workspace<S>,
    a_root: &Motion<S>,
    qdd: &mut [S],
) {
    ws.has_child.iter_mut().for_each(|h| *h = false);
    for jp in &p.joints {
        if let Some(l) = jp.parent {
            ws.has_child[l] = true;
        }
    }
    for (j, jp) in p.joints.iter().enumerate() {
        let a_parent = jp.parent.map_or(a_root, |l| &ws.acc[l]);
        // a'_j = Xup_j a_λ + c_j
        let a = ws.xup[j].apply(a_parent) + ws.c[j].clone();
        // q̈_j = D_j⁻¹ (u_j − U_jᵀ a'_j) (RBDA eq. (7.46))
        let qj = ws.d_inv[j].clone() * (ws.u[j].clone() - power(&ws.u_vec[j], &a));
        // a_j = a'_j + S_j q̈_j (only where a child reads it)
        ws.acc[j] = if ws.has_child[j] {
            a + s_times(jp, &qj)
        } else {
            a
        };
        qdd[j] = qj;
    }
}

/// Forward dynamics on a fixed base by the articulated-body algorithm: the joint accelerations
/// `q̈ = H⁻¹ (τ − C(q, q̇, f_ext))` (the paper's `A⁻¹ b`).
///
/// `p`: the model's parameters (any tree; the bodies' [`crate::JointParams::inertia`] is read);
/// `q`, `q̇`: joint positions and velocities, length `N`; `loads`: the drives `τ` (zero when
/// absent), gravity `g` in the base frame (the base acceleration `a_0 = [0; −g]`) and external
/// wrenches (force at `O_j`, moment about `O_j`, in the body's or the base frame), as
/// [`crate::algorithms::rnea::bias`] takes them. One division per joint. Section `"spatial:aba"`.
/// Allocates a [`Workspace`] and calls [`forward_dynamics_in`].
pub fn forward_dynamics<S: Scalar>(p: &Params<S>, q: &[S], qd: &[S], loads: &Loads<S>) -> Vec<S> {
    let mut ws = Workspace::new(p);
    let mut qdd: Vec<S> = (0..p.dof()).map(|_| S::zero()).collect();
    forward_dynamics_in(p, &mut ws, q, qd, loads, None, &mut qdd);
    qdd
}

/// [`forward_dynamics`] into `qdd` (length `N`) with the workspace `ws` of the model, allocating
/// nothing; `armature`: `a_i ≥ 0` per joint (the reflected rotor inertia `I_m n²`), solving
/// `(H + diag(a)) q̈ = τ − C` (Pinocchio's `Model::armature`). Section `"spatial:aba"`.
///
/// # Panics
/// When a length disagrees with the model (`q`, `qd`, `loads.tau`, `armature`, `qdd`, the
/// workspace's) or a wrench names a body past the end of the chain.
pub fn forward_dynamics_in<S: Scalar>(
    p: &Params<S>,
    ws: &mut Workspace<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
    armature: Option<&[S]>,
    qdd: &mut [S],
) {
    S::section("spatial:aba");
    check_args(p, ws, q, qd, loads, armature);
    assert_eq!(qdd.len(), p.dof(), "qdd has the wrong length");
    let root = Root {
        v: Motion::zero(),
        e0: Mat3::identity(),
        floating: None,
    };
    backward(p, ws, q, qd, loads, armature, root);
    // a_0 = −a_grav (RBDA §5.3)
    let a0 = match &loads.gravity {
        Some(g) => Motion {
            ang: Vec3::zero(),
            lin: -g.clone(),
        },
        None => Motion::zero(),
    };
    accelerations(p, ws, &a0, qdd);
}

/// Forward dynamics of the tree `p` on the free-floating base `base` by the articulated-body
/// algorithm (RBDA ch. 9; spatial_v2 `FDfb`): `ν̇ = [v̇_b (3); ω̇_b (3); q̈ (N)] = A⁻¹ b`, the
/// same layout and conventions as [`crate::algorithms::floating::forward_dynamics`]
/// ([`crate::base`]: `v̇_b`, `ω̇_b` are the time derivatives of the base-coordinate components
/// of `v_b` and `ω_b`, i.e. the base's spatial acceleration in base coordinates).
///
/// The base is body 0 with a 6-dof joint: `v_0 = [ω_b; v_b]`, `I^A_0 = I_0` (its
/// [`FloatingBase::inertia`]), `p^A_0 = v_0 ×* I_0 v_0 − f^x_0`; the joints on the base carry
/// their `I^a`, `p^a` onto it, and `a'_0 = −(I^A_0)⁻¹ p^A_0` by a 6×6 LDLᵀ. Gravity is left
/// out of the passes (every `a'_i = a_i − a_grav` obeys the same recursion) and put back on the
/// base: `a_0 = a'_0 + [0; R₀ᵀ g]`. Loads as [`crate::algorithms::rnea::floating_bias`] takes
/// them (inertial-frame wrenches rotated into body coordinates with `E_0j R₀ᵀ`).
/// Section `"spatial:aba"`. Allocates a [`Workspace`] and calls [`floating_in`].
pub fn floating<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
) -> Vec<S> {
    let mut ws = Workspace::new(p);
    let mut out: Vec<S> = (0..FLOATING_BASE_DOF + p.dof())
        .map(|_| S::zero())
        .collect();
    floating_in(p, &mut ws, base, state, q, qd, loads, None, &mut out);
    out
}

/// [`floating`] into `nu_dot` (length `6 + N`) with the workspace `ws` of the model, allocating
/// nothing; `armature` as in [`forward_dynamics_in`] (joints only). Section `"spatial:aba"`.
///
/// # Panics
/// As [`forward_dynamics_in`].
#[allow(clippy::too_many_arguments)]
pub fn floating_in<S: Scalar>(
    p: &Params<S>,
    ws: &mut Workspace<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    loads: &Loads<S>,
    armature: Option<&[S]>,
    nu_dot: &mut [S],
) {
    S::section("spatial:aba");
    check_args(p, ws, q, qd, loads, armature);
    assert_eq!(
        nu_dot.len(),
        FLOATING_BASE_DOF + p.dof(),
        "nu_dot has the wrong length"
    );
    let e0 = state.rotation.transpose();
    let v0 = Motion {
        ang: state.omega_b.clone(),
        lin: state.v_b.clone(),
    };
    let i0 = base.inertia.clone();
    // p^A_0 = v_0 ×* I_0 v_0 − f^x_0
    let p0 = subtract_external(v0.crf(&i0.mul(&v0)), loads, BASE_BODY, &e0);
    let root = Root {
        v: v0,
        e0: e0.clone(),
        floating: Some((Articulated::rigid(&i0), p0)),
    };
    let (ia0, pa0) = backward(p, ws, q, qd, loads, armature, root).expect("a floating root");
    // I^A_0 a'_0 = −p^A_0, rows and columns in the order [lin; ang] of ν_b.
    let ang_lin = |r: usize, c: usize| -> S {
        match (r < 3, c < 3) {
            (true, true) => ia0.c.at(r, c),
            (true, false) => ia0.b.at(c - 3, r),
            (false, true) => ia0.b.at(r - 3, c),
            (false, false) => ia0.a.at(r - 3, c - 3),
        }
    };
    const B: usize = FLOATING_BASE_DOF;
    let mut m6: [S; B * B] = core::array::from_fn(|k| ang_lin(k / B, k % B));
    let mut d_inv: [S; B] = core::array::from_fn(|_| S::zero());
    crate::ldlt::factor_in_place(&mut m6, B, &mut d_inv).expect("6 × 6 buffers");
    let mut x = crate::spatial::base_rows(&pa0).map(|x| -x);
    crate::ldlt::solve_in_place(&m6, B, &d_inv, &mut x).expect("6 × 6 buffers");
    let [x0, x1, x2, x3, x4, x5] = x;
    let a0 = Motion {
        ang: Vec3::new(x3, x4, x5),
        lin: Vec3::new(x0, x1, x2),
    };
    let (head, qdd) = nu_dot.split_at_mut(B);
    accelerations(p, ws, &a0, qdd);
    // a_0 = a'_0 + a_grav, a_grav = [0; R₀ᵀ g] in base coordinates.
    let lin = match &loads.gravity {
        Some(g) => a0.lin + e0.mul_vec(g),
        None => a0.lin,
    };
    for (o, x) in head.iter_mut().zip(lin.0.into_iter().chain(a0.ang.0)) {
        *o = x;
    }
}
