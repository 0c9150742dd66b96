//! Analytical derivatives of inverse dynamics, `∂τ/∂q` and `∂τ/∂q̇` of `τ = RNEA(q, q̇, q̈)`:
//! J. Carpentier and N. Mansard, "Analytical Derivatives of Rigid Body Dynamics Algorithms",
//! *Robotics: Science and Systems* (RSS) 2018, Algorithm 1 (Pinocchio's
//! `computeRNEADerivatives`), in O(N²) after one O(N) forward pass.
//!
//! Every spatial quantity is written in one fixed frame (the paper's world frame `o`; here the
//! base frame, which for a free-floating base is the inertial frame momentarily aligned with the
//! base). In it, moving joint `j` turns its whole subtree about `S_j`, so the derivative of a
//! quantity of a body in that subtree is `S_j ×` it (the paper's eq. (7)) plus what the
//! subtree's velocity and acceleration gain beyond that turn (eqs. (9)–(12)):
//!
//! - forward, body `i` on joint `i` (RBDA Table 5.1 in the fixed frame):
//!   `v_i = v_λ + S_i q̇_i`, `a_i = a_λ + S_i q̈_i + (v_i ×ₘ S_i) q̇_i` (`a_0 = −a_grav`),
//!   `h_i = I_i v_i`, `f_i = I_i a_i + v_i ×* h_i`;
//! - per column (eqs. (9)–(12)): `∂v/∂q_i = v_λ ×ₘ S_i`, `∂a/∂q_i = a_λ ×ₘ S_i + v_λ ×ₘ ∂v/∂q_i`,
//!   `∂a/∂q̇_i = v_i ×ₘ S_i + ∂v/∂q_i`;
//! - per body, the variation of the bias force with the velocity (the paper's `B_i`, Pinocchio's
//!   `doYcrb`): `B_i δ = δ ×* h_i + v_i ×* I_i δ − I_i (v_i ×ₘ δ) = δ ×* h_i + İ_i δ`, where
//!   `İ_i = v_i ×* I_i − I_i v_i ×ₘ` is the rate of the body's inertia in the fixed frame
//!   (RBDA eq. (2.73)). It is itself of the rigid-body form, with no mass: first moment
//!   `ḣ = m v_O + ω × h` and rotational part `Ī̇ = ω̃ Ī − Ī ω̃ + 2 (h·v_O) 1 − v_O hᵀ − h v_Oᵀ`
//!   (symmetric) for `v_i = [ω; v_O]` ([`InertiaRate`]). So `B` is never formed as a 6×6
//!   matrix, as Pinocchio forms it: its composite is `B^C_i δ = δ ×* H_i + İ^C_i δ` with the
//!   composite momentum `H_i = Σ h_k` and `İ^C_i = Σ İ_k` (9 numbers), and
//!   `B^Cᵀ_i S = İ^C_i S − S ×* H_i` (`δ ↦ δ ×* h` is skew-symmetric, `İ` symmetric);
//! - backward, composites over the subtree: `Y_i = Σ I_k`, `H_i`, `İ^C_i`, `F_i = Σ f_k`,
//!   `τ_i = S_iᵀ F_i`, and
//!   `∂F_j/∂q_j = S_j ×* F_j + Y_j ∂a/∂q_j + B^C_j ∂v/∂q_j`,
//!   `∂F_j/∂q̇_j = Y_j ∂a/∂q̇_j + B^C_j S_j`;
//! - rows (eq. (13)): for `i` in the subtree of `j` (itself included),
//!   `∂τ_i/∂q_j = (Y_i S_i)ᵀ ∂a/∂q_j + (B^C_iᵀ S_i)ᵀ ∂v/∂q_j` and
//!   `∂τ_i/∂q̇_j = (Y_i S_i)ᵀ ∂a/∂q̇_j + (B^C_iᵀ S_i)ᵀ S_j`; for `i` a strict ancestor of `j`,
//!   `∂τ_i/∂q_j = S_iᵀ ∂F_j/∂q_j` and `∂τ_i/∂q̇_j = S_iᵀ ∂F_j/∂q̇_j`; zero otherwise.
//!
//! A free-floating base is body 0 with six columns `S = 1₆` in base coordinates (linear first,
//! as in `ν = [v_b; ω_b; q̇]`) on the fixed root (`v_λ = 0`, `a_λ = −a_grav`), its
//! configuration perturbed by `M₀ exp(δ)` (Pinocchio's `integrate`): the same equations, the
//! base's own rows and columns by the subtree rule (its columns turn with it).

use super::{base_unit, compose, motion_back, motion_scale, power, Matrix};
use crate::base::{FloatingBase, FloatingState, FLOATING_BASE_DOF};
use crate::joint::{s_times, xup};
use crate::linalg::{Mat3, Vec3};
use crate::params::Params;
use crate::scalar::Scalar;
use crate::spatial::{Force, Motion, RbInertia, Xform};

/// The rate `İ = v ×* I − I v ×ₘ` of a rigid body's inertia `I` moving with `v` in a fixed
/// frame: of the rigid-body form with no mass (module docs), symmetric as a 6×6 matrix.
#[derive(Clone, Debug)]
struct InertiaRate<S> {
    /// `ḣ = m v_O + ω × h`.
    h: Vec3<S>,
    /// `Ī̇ = ω̃ Ī − Ī ω̃ + 2 (h·v_O) 1 − v_O hᵀ − h v_Oᵀ` (symmetric).
    ibar: Mat3<S>,
}

impl<S: Scalar> InertiaRate<S> {
    /// `İ` of inertia `i` moving with `v = [ω; v_O]`.
    fn new(i: &RbInertia<S>, v: &Motion<S>) -> Self {
        let (w, vo) = (&v.ang, &v.lin);
        // A = ω̃ Ī column by column; ω̃ Ī − Ī ω̃ = A + Aᵀ.
        let a: [Vec3<S>; 3] = core::array::from_fn(|c| w.cross(&i.ibar.col(c)));
        let hv = i.h.dot(vo);
        let two_hv = hv.clone() + hv;
        let entry = |r: usize, c: usize| {
            let x = a[c].at(r) + a[r].at(c) - vo.at(r) * i.h.at(c) - i.h.at(r) * vo.at(c);
            if r == c {
                x + two_hv.clone()
            } else {
                x
            }
        };
        InertiaRate {
            h: vo.scale(&i.m) + w.cross(&i.h),
            ibar: symmetric(entry),
        }
    }

    /// `İ δ = [Ī̇ ω + ḣ × v; −ḣ × ω]`.
    fn mul(&self, d: &Motion<S>) -> Force<S> {
        Force {
            ang: self.ibar.mul_vec(&d.ang) + self.h.cross(&d.lin),
            lin: -self.h.cross(&d.ang),
        }
    }

    /// `İ_a + İ_b`.
    fn add(&self, o: &Self) -> Self {
        InertiaRate {
            h: self.h.clone() + o.h.clone(),
            ibar: symmetric(|r, c| self.ibar.at(r, c) + o.ibar.at(r, c)),
        }
    }
}

/// The symmetric 3×3 matrix of upper-triangle entries `entry(r, c ≥ r)` (six evaluations).
fn symmetric<S: Scalar>(entry: impl Fn(usize, usize) -> S) -> Mat3<S> {
    let upper: [[Option<S>; 3]; 3] =
        core::array::from_fn(|r| core::array::from_fn(|c| (c >= r).then(|| entry(r, c))));
    Mat3(core::array::from_fn(|r| {
        core::array::from_fn(|c| upper[r.min(c)][r.max(c)].clone().expect("upper triangle"))
    }))
}

/// A body of the passes, in base coordinates: its parent body, its inertia, velocity and
/// acceleration (`a_0 = −a_grav` included), and the subtree composites `Y`, `H`, `İ^C`, `F`
/// (initialized with the body's own `I`, `h`, `İ`, `f`, completed by the backward pass).
struct Body<S> {
    parent: Option<usize>,
    v: Motion<S>,
    a: Motion<S>,
    yc: RbInertia<S>,
    hc: Force<S>,
    idc: InertiaRate<S>,
    fc: Force<S>,
}

/// A column (speed) of the passes: its body, `S`, `∂v/∂q`, `∂a/∂q`, `∂a/∂q̇` (eqs. (9)–(12)).
struct Column<S> {
    body: usize,
    s: Motion<S>,
    dvdq: Motion<S>,
    dadq: Motion<S>,
    dadv: Motion<S>,
}

/// The root of the passes: `a_λ = −a_grav` for the bodies on it, and a free-floating base's
/// inertia, twist `[ω_b; v_b]` and acceleration `[ω̇_b; v̇_b]` (body 0 with six columns).
struct Root<'a, S> {
    a_grav: Motion<S>,
    floating: Option<(&'a RbInertia<S>, Motion<S>, Motion<S>)>,
}

impl<S: Scalar> Body<S> {
    /// A body of inertia `i` (base coordinates) in motion `(v, a)`: `h = I v`,
    /// `f = I a + v ×* h`, `İ` ([`InertiaRate`]).
    fn new(parent: Option<usize>, i: RbInertia<S>, v: Motion<S>, a: Motion<S>) -> Self {
        let h = i.mul(&v);
        let f = i.mul(&a) + v.crf(&h);
        let idc = InertiaRate::new(&i, &v);
        Body {
            parent,
            v,
            a,
            yc: i,
            hc: h,
            idc,
            fc: f,
        }
    }

    /// `B^C δ = δ ×* H + İ^C δ`.
    fn bias_variation(&self, d: &Motion<S>) -> Force<S> {
        d.crf(&self.hc) + self.idc.mul(d)
    }

    /// `B^Cᵀ s = İ^C s − s ×* H`, as a force (paired with motions by [`power`]).
    fn bias_variation_transposed(&self, s: &Motion<S>) -> Force<S> {
        self.idc.mul(s) - s.crf(&self.hc)
    }
}

/// Column `S` of a body moving with `v`, on a parent moving with `(v_λ, a_λ)`: eqs. (9)–(11).
fn column<S: Scalar>(
    body: usize,
    s: Motion<S>,
    v: &Motion<S>,
    v_parent: &Motion<S>,
    a_parent: &Motion<S>,
) -> Column<S> {
    // ∂v/∂q = v_λ ×ₘ S
    let dvdq = v_parent.crm(&s);
    // ∂a/∂q = a_λ ×ₘ S + v_λ ×ₘ ∂v/∂q
    let dadq = a_parent.crm(&s) + v_parent.crm(&dvdq);
    // ∂a/∂q̇ = v ×ₘ S + ∂v/∂q
    let dadv = v.crm(&s) + dvdq.clone();
    Column {
        body,
        s,
        dvdq,
        dadq,
        dadv,
    }
}

/// The forward pass: bodies and columns in base coordinates (the module's forward equations).
fn forward<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    qd: &[S],
    qdd: &[S],
    root: Root<'_, S>,
) -> (Vec<Body<S>>, Vec<Column<S>>) {
    let n = p.dof();
    assert!(
        q.len() == n && qd.len() == n && qdd.len() == n,
        "q, qd, qdd must have one entry per joint"
    );
    let mut bodies: Vec<Body<S>> = Vec::with_capacity(n + 1);
    let mut cols: Vec<Column<S>> = Vec::with_capacity(n + FLOATING_BASE_DOF);
    let mut x0s: Vec<Xform<S>> = Vec::with_capacity(n + 1);
    let zero = Motion::zero();
    let arm_root = match root.floating {
        Some((i0, v0, a0)) => {
            // Body 0, the base: v_0 = [ω_b; v_b], a_0 = ν̇_b − a_grav, S = 1₆.
            let a = a0 + root.a_grav.clone();
            for c in 0..FLOATING_BASE_DOF {
                cols.push(column(0, base_unit(c), &v0, &zero, &root.a_grav));
            }
            bodies.push(Body::new(None, i0.clone(), v0, a));
            x0s.push(Xform::identity());
            Some(0)
        }
        None => None,
    };
    let offset = bodies.len();
    for (j, jp) in p.joints.iter().enumerate() {
        let parent = jp.parent.map(|l| l + offset).or(arm_root);
        let (v_parent, a_parent) = match parent {
            Some(l) => (bodies[l].v.clone(), bodies[l].a.clone()),
            None => (zero.clone(), root.a_grav.clone()),
        };
        // ⁰X_j = Xup_j ⁰X_λ; S_j and I_j in base coordinates.
        let up = xup(jp, &q[j]);
        let x0 = match parent {
            Some(l) => compose(&up, &x0s[l]),
            None => up,
        };
        let s = motion_back(&x0, &s_times(jp, &S::one()));
        let inertia = x0.tr_inertia(&jp.inertia);
        // v_j = v_λ + S_j q̇_j; a_j = a_λ + S_j q̈_j + (v_j ×ₘ S_j) q̇_j
        let v = v_parent.clone() + motion_scale(&s, &qd[j]);
        let a = a_parent.clone() + motion_scale(&s, &qdd[j]) + motion_scale(&v.crm(&s), &qd[j]);
        cols.push(column(j + offset, s, &v, &v_parent, &a_parent));
        bodies.push(Body::new(parent, inertia, v, a));
        x0s.push(x0);
    }
    (bodies, cols)
}

/// Whether body `a` is `d` or one of its ancestors (a property of the tree, not of the data).
fn is_ancestor_or_self<S>(bodies: &[Body<S>], a: usize, d: usize) -> bool {
    let mut k = Some(d);
    while let Some(b) = k {
        if b == a {
            return true;
        }
        k = bodies[b].parent;
    }
    false
}

/// The backward pass: composites, then the rows of each column (eq. (13)).
fn backward<S: Scalar>(mut bodies: Vec<Body<S>>, cols: &[Column<S>]) -> (Matrix<S>, Matrix<S>) {
    let nv = cols.len();
    let mut dq = vec![vec![S::zero(); nv]; nv];
    let mut dv = vec![vec![S::zero(); nv]; nv];
    // (Y_i S_i, B^C_iᵀ S_i) of every column, filled as its body is reached.
    let mut u: Vec<(Force<S>, Force<S>)> = vec![(Force::zero(), Force::zero()); nv];
    for b in (0..bodies.len()).rev() {
        let own: Vec<usize> = (0..nv).filter(|&c| cols[c].body == b).collect();
        let body = &bodies[b];
        for &c in &own {
            u[c] = (
                body.yc.mul(&cols[c].s),
                body.bias_variation_transposed(&cols[c].s),
            );
        }
        for &c in &own {
            let col = &cols[c];
            // ∂F/∂q = S ×* F + Y ∂a/∂q + B^C ∂v/∂q; ∂F/∂q̇ = Y ∂a/∂q̇ + B^C S
            let dfdq =
                col.s.crf(&body.fc) + body.yc.mul(&col.dadq) + body.bias_variation(&col.dvdq);
            let dfdv = body.yc.mul(&col.dadv) + body.bias_variation(&col.s);
            for r in 0..nv {
                let br = cols[r].body;
                if is_ancestor_or_self(&bodies, b, br) {
                    let (u1, u2) = &u[r];
                    dq[r][c] = power(u1, &col.dadq) + power(u2, &col.dvdq);
                    dv[r][c] = power(u1, &col.dadv) + power(u2, &col.s);
                } else if is_ancestor_or_self(&bodies, br, b) {
                    dq[r][c] = power(&dfdq, &cols[r].s);
                    dv[r][c] = power(&dfdv, &cols[r].s);
                }
            }
        }
        // Y_λ += Y_i, H_λ += H_i, İ^C_λ += İ^C_i, F_λ += F_i
        if let Some(l) = bodies[b].parent {
            let (yc, hc, idc, fc) = (
                bodies[b].yc.clone(),
                bodies[b].hc.clone(),
                bodies[b].idc.clone(),
                bodies[b].fc.clone(),
            );
            let parent = &mut bodies[l];
            parent.yc = parent.yc.clone() + yc;
            parent.hc = parent.hc.clone() + hc;
            parent.idc = parent.idc.add(&idc);
            parent.fc = parent.fc.clone() + fc;
        }
    }
    (dq, dv)
}

/// `−a_grav = [0; −g]` (RBDA §5.3), `g` in the frame of the passes.
fn minus_gravity<S: Scalar>(g: Option<Vec3<S>>) -> Motion<S> {
    Motion {
        ang: Vec3::zero(),
        lin: g.map_or_else(Vec3::zero, |g| -g),
    }
}

/// `(∂τ/∂q, ∂τ/∂q̇)` of fixed-base inverse dynamics `τ = M(q) q̈ + c(q, q̇)` (Pinocchio's
/// `computeRNEADerivatives`), `N × N` each, row `i` = `τ_i`, column `j` = `∂/∂q_j` (`∂/∂q̇_j`).
///
/// `p`: any tree; `q`, `q̇`, `q̈`: length `N`; `gravity`: `g` in the base frame (none: no
/// gravity). `∂τ/∂q̈ = M(q)`. Section `"derivatives:rnea"`.
pub fn derivatives<S: Scalar>(
    p: &Params<S>,
    q: &[S],
    qd: &[S],
    qdd: &[S],
    gravity: Option<&Vec3<S>>,
) -> (Matrix<S>, Matrix<S>) {
    S::section("derivatives:rnea");
    let root = Root {
        a_grav: minus_gravity(gravity.cloned()),
        floating: None,
    };
    let (bodies, cols) = forward(p, q, qd, qdd, root);
    backward(bodies, &cols)
}

/// `(∂τ/∂q, ∂τ/∂ν)` of free-floating inverse dynamics
/// ([`crate::algorithms::rnea::floating_inverse_dynamics`]: `τ = [w_b (6); τ (N)]`),
/// `(6 + N) × (6 + N)` each, the base columns of `∂/∂q` in the tangent space (Pinocchio's
/// `integrate(q, δν)`, module docs), those of `∂/∂ν` along `[v_b; ω_b]`.
///
/// `state`: the base's pose and twist ([`crate::base`]); `base_acc = [v̇_b; ω̇_b]`; `gravity`:
/// `g` in the inertial frame. Section `"derivatives:rnea"`.
#[allow(clippy::too_many_arguments)] // the state of a free-floating system, as in Pinocchio
pub fn floating_derivatives<S: Scalar>(
    p: &Params<S>,
    base: &FloatingBase<S>,
    state: &FloatingState<S>,
    q: &[S],
    qd: &[S],
    base_acc: &[S; 6],
    qdd: &[S],
    gravity: Option<&Vec3<S>>,
) -> (Matrix<S>, Matrix<S>) {
    S::section("derivatives:rnea");
    let v0 = Motion {
        ang: state.omega_b.clone(),
        lin: state.v_b.clone(),
    };
    let [x, y, z, wx, wy, wz] = base_acc.clone();
    let a0 = Motion {
        ang: Vec3::new(wx, wy, wz),
        lin: Vec3::new(x, y, z),
    };
    let root = Root {
        a_grav: minus_gravity(gravity.map(|g| state.rotation.tr_mul_vec(g))),
        floating: Some((&base.inertia, v0, a0)),
    };
    let (bodies, cols) = forward(p, q, qd, qdd, root);
    backward(bodies, &cols)
}
