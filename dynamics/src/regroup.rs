//! Regrouped inertial parameters (W. Khalil and F. Bennis, "Symbolic calculation of the base
//! inertial parameters of closed-loop robots", and Khalil & Dombre, *Modeling, Identification and
//! Control of Robots*, 2002, §9.5: the "base inertial parameters"): the part of a body's inertia
//! that its joint cannot move relative to the parent is carried by the parent instead, which
//! leaves fewer non-zero numbers for the local-frame algorithms to multiply.
//!
//! - **Revolute joint** `j` (unit axis `u` through the body origin): the mass on the axis — mass
//!   `m_j`, first moment `(h·u) u`, rotational inertia `Y (1 − u uᵀ)` — moves with body `j` and
//!   with its parent alike (a point on the axis does not move when the joint turns), so it is
//!   welded to the parent (`Xtree_jᵀ I Xtree_j`, the transform at `q_j = 0`). `Y = pᵀ Ī p` for a
//!   unit `p ⊥ u` (for `u = e_z`, `p = e_x`: Khalil's `XXR = XX − YY` with one of the two
//!   moments left at 0). Body `j` keeps mass 0, first moment `h − (h·u) u` and `Ī − Y (1 − uuᵀ)`.
//!   With `XX = YY` (a body symmetric about its axis) the rotation-invariant moment moves out and
//!   the products `c·(I c) + s·(I s)` the joint rotation would spend on it vanish.
//! - **Prismatic joint** `j`: the body does not turn relative to its parent, so its rotational
//!   inertia about its centre of mass (no mass, no first moment) moves to the parent; body `j`
//!   keeps a point mass at its centre of mass.
//!
//! Bodies are processed leaves first, so what a body receives from its children moves on with
//! it. What reaches a fixed base is dropped (it never moves); what reaches a free-floating base is
//! added to it. The result is **equivalent in joint space only**: `M`, `c`, `τ`, forward dynamics,
//! the base rows of a floating base and the total momentum are unchanged; per-body quantities (the
//! wrench a joint transmits, the arm's reaction on its base) are not. Only the local-frame
//! algorithms read the regrouped numbers ([`crate::JointParams::inertia`],
//! [`crate::base::FloatingBase::inertia`]); the paper's algorithms read the untouched
//! `mass`, `com`, `inertia_com`, so every method stays correct on regrouped parameters.

use crate::base::FloatingBase;
use crate::joint::xup;
use crate::linalg::{Mat3, Vec3};
use crate::params::Params;
use crate::scalar::Scalar;
use crate::spatial::RbInertia;
use kanegen_model::{Inertial, JointKind, Model};

/// What [`regrouped`] moved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegroupReport {
    /// Bodies that gave part of their inertia to their parent.
    pub moved: usize,
    /// Non-zero numbers in the bodies' (and a floating base's) spatial inertias, `(m, h, Ī)`
    /// with `Ī`'s upper triangle: 10 per body at most.
    pub nonzero_before: usize,
    /// The same after regrouping.
    pub nonzero_after: usize,
}

/// A model's parameters with regrouped spatial inertias, and a floating base's.
#[derive(Clone, Debug)]
pub struct Regrouped<S> {
    /// The joints' parameters; `inertia` regrouped, everything else as [`Params::new`].
    pub params: Params<S>,
    /// The free-floating base with what its children gave it (`None` for a fixed base).
    pub base: Option<FloatingBase<S>>,
    /// What moved.
    pub report: RegroupReport,
}

fn nonzero(i: &RbInertia<f64>) -> usize {
    let ibar = (0..3).flat_map(|r| (r..3).map(move |c| (r, c)));
    usize::from(i.m != 0.0)
        + i.h.0.iter().filter(|x| **x != 0.0).count()
        + ibar.filter(|(r, c)| i.ibar.at(*r, *c) != 0.0).count()
}

fn constant<S: Scalar>(i: &RbInertia<f64>) -> RbInertia<S> {
    RbInertia {
        m: S::constant(i.m),
        h: Vec3::from_f64(i.h.0),
        ibar: Mat3::from_f64(i.ibar.0),
    }
}

/// A unit vector perpendicular to the unit `u`: the next coordinate axis when `u` is one (so
/// `Y` is one of `Ī`'s diagonal entries), else `u × e` normalized for the coordinate axis `e`
/// least aligned with `u`.
fn perpendicular(u: &Vec3<f64>) -> Vec3<f64> {
    let k = (0..3)
        .min_by(|a, b| u.at(*a).abs().total_cmp(&u.at(*b).abs()))
        .expect("three axes");
    let coordinate = u.0.iter().filter(|x| **x == 0.0).count() == 2;
    let mut e = Vec3::zero();
    if coordinate {
        let axis = (0..3).find(|i| u.at(*i) != 0.0).expect("a unit axis");
        e.0[(axis + 1) % 3] = 1.0;
        return e;
    }
    e.0[k] = 1.0;
    let p = u.cross(&e);
    let n = p.dot(&p).sqrt();
    p.scale(&(1.0 / n))
}

/// Splits `i` (body frame) into `(kept, moved)` for a joint of `kind` about/along `u`.
fn split(i: &RbInertia<f64>, kind: JointKind, u: &Vec3<f64>) -> (RbInertia<f64>, RbInertia<f64>) {
    match kind {
        JointKind::Revolute => {
            let eta = i.h.dot(u);
            let p = perpendicular(u);
            let y = p.dot(&i.ibar.mul_vec(&p));
            let line = RbInertia {
                m: i.m,
                h: u.scale(&eta),
                ibar: (Mat3::identity() - u.outer(u)).scale(&y),
            };
            let kept = RbInertia {
                m: 0.0,
                h: &i.h - &line.h,
                ibar: i.ibar.clone() - line.ibar.clone(),
            };
            (kept, line)
        }
        JointKind::Prismatic => {
            if i.m == 0.0 {
                // No mass: all of Ī is rotational inertia when there is no first moment either.
                let none = RbInertia {
                    m: 0.0,
                    h: Vec3::zero(),
                    ibar: Mat3::zero(),
                };
                return if i.h.0.iter().all(|x| *x == 0.0) {
                    (none, i.clone())
                } else {
                    (i.clone(), none)
                };
            }
            // Ī = I_c + m c̃ c̃ᵀ with c = h / m: the point mass stays, I_c moves.
            let c = i.h.scale(&(1.0 / i.m));
            let ct = Mat3::skew(&c);
            let point = ct.mul_mat(&ct.transpose()).scale(&i.m);
            let moved = RbInertia {
                m: 0.0,
                h: Vec3::zero(),
                ibar: i.ibar.clone() - point.clone(),
            };
            (
                RbInertia {
                    m: i.m,
                    h: i.h.clone(),
                    ibar: point,
                },
                moved,
            )
        }
    }
}

/// `model`'s parameters with regrouped inertias ([module docs](self)), on the free-floating base
/// `base` (`None`: a fixed base, which drops what reaches it); the bodies listed in `keep`
/// neither give nor receive (a body whose inertia becomes a runtime input).
#[must_use]
pub fn regrouped<S: Scalar>(
    model: &Model,
    base: Option<&Inertial>,
    keep: &[usize],
) -> Regrouped<S> {
    let p = Params::<f64>::new(model);
    let mut inertia: Vec<RbInertia<f64>> = p.joints.iter().map(|j| j.inertia.clone()).collect();
    let base_inertial = base;
    let base0 = base.map(FloatingBase::<f64>::from_inertial);
    let mut base = base0.as_ref().map(|b| b.inertia.clone());
    let before = inertia.iter().map(nonzero).sum::<usize>() + base.as_ref().map_or(0, nonzero);
    let mut moved = 0;
    for j in (0..p.dof()).rev() {
        let jp = &p.joints[j];
        if keep.contains(&j) || jp.parent.is_some_and(|l| keep.contains(&l)) {
            continue;
        }
        let (kept, give) = split(&inertia[j], jp.kind, &jp.axis);
        if nonzero(&give) == 0 {
            continue;
        }
        moved += 1;
        inertia[j] = kept;
        let carried = xup(jp, &0.0).tr_inertia(&give);
        match jp.parent {
            Some(l) => inertia[l] = inertia[l].clone() + carried,
            None => {
                if let Some(b) = base.as_mut() {
                    *b = b.clone() + carried;
                }
            }
        }
    }
    let after = inertia.iter().map(nonzero).sum::<usize>() + base.as_ref().map_or(0, nonzero);
    let mut params = Params::<S>::new(model);
    for (jp, i) in params.joints.iter_mut().zip(&inertia) {
        jp.inertia = constant(i);
    }
    let base = base_inertial.zip(base).map(|(orig, b)| FloatingBase {
        inertia: constant(&b),
        ..FloatingBase::from_inertial(orig)
    });
    Regrouped {
        params,
        base,
        report: RegroupReport {
            moved,
            nonzero_before: before,
            nonzero_after: after,
        },
    }
}
