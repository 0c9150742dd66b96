//! Spatial-vector algebra in local body coordinates (R. Featherstone, *Rigid Body Dynamics
//! Algorithms*, Springer 2008, "RBDA", ch. 2; spatial_v2's names in brackets), shared by the
//! local-frame algorithms [`crate::algorithms::crba`] and [`crate::algorithms::rnea`].
//!
//! Conventions (RBDA ch. 2): motion vectors `[ω; v]` with `v` the velocity of the body-frame
//! origin; force vectors `[n; f]` with `n` the moment about the origin; the Plücker transform from
//! frame A to frame B is `X = [E 0; −E r̃ E]` (RBDA eq. (2.24)), `E` the rotation from A to B
//! coordinates and `r` the position of B's origin in A coordinates, stored as the pair `(E, r)`
//! (RBDA §2.8, Table 2.5). A rigid-body inertia is stored as `(m, h = m c, Ī)`, `Ī` about the
//! frame origin (RBDA eq. (2.62)–(2.63), spatial_v2 `mcI`).
//!
//! The joints' transforms and motion subspaces are in [`crate::joint`].

use crate::linalg::{Mat3, Vec3};
use crate::scalar::Scalar;

/// A spatial motion vector `[ω; v]` (RBDA §2.2).
#[derive(Clone, Debug)]
pub struct Motion<S> {
    /// Angular part `ω`.
    pub ang: Vec3<S>,
    /// Linear part `v` (velocity of the frame origin).
    pub lin: Vec3<S>,
}

/// A spatial force vector `[n; f]`, `n` about the frame origin (RBDA §2.3).
#[derive(Clone, Debug)]
pub struct Force<S> {
    /// Moment `n` about the frame origin.
    pub ang: Vec3<S>,
    /// Force `f`.
    pub lin: Vec3<S>,
}

impl<S: Scalar> Force<S> {
    /// The zero force.
    #[must_use]
    pub fn zero() -> Self {
        Force {
            ang: Vec3::zero(),
            lin: Vec3::zero(),
        }
    }
}

impl<S: Scalar> Motion<S> {
    /// The zero motion.
    pub fn zero() -> Self {
        Motion {
            ang: Vec3::zero(),
            lin: Vec3::zero(),
        }
    }
    /// `self ×ₘ m = [ω × ω₂; ω × v₂ + v × ω₂]` (RBDA eq. (2.31), spatial_v2 `crm`).
    pub fn crm(&self, m: &Motion<S>) -> Motion<S> {
        Motion {
            ang: self.ang.cross(&m.ang),
            lin: self.ang.cross(&m.lin) + self.lin.cross(&m.ang),
        }
    }
    /// `self ×* f = [ω × n + v × f; ω × f]` (RBDA eq. (2.32), spatial_v2 `crf`).
    pub fn crf(&self, f: &Force<S>) -> Force<S> {
        Force {
            ang: self.ang.cross(&f.ang) + self.lin.cross(&f.lin),
            lin: self.ang.cross(&f.lin),
        }
    }
}

impl<S: Scalar> core::ops::Add for Motion<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Motion {
            ang: self.ang + o.ang,
            lin: self.lin + o.lin,
        }
    }
}

impl<S: Scalar> core::ops::Add for Force<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Force {
            ang: self.ang + o.ang,
            lin: self.lin + o.lin,
        }
    }
}

impl<S: Scalar> core::ops::Sub for Force<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Force {
            ang: self.ang - o.ang,
            lin: self.lin - o.lin,
        }
    }
}

/// A Plücker transform `(E, r)` from frame A to frame B (RBDA §2.8, Table 2.5).
#[derive(Clone, Debug)]
pub struct Xform<S> {
    /// `E`: rotation from A to B coordinates.
    pub e: Mat3<S>,
    /// `r`: B's origin in A coordinates.
    pub r: Vec3<S>,
}

impl<S: Scalar> Xform<S> {
    /// The identity transform.
    #[must_use]
    pub fn identity() -> Self {
        Xform {
            e: Mat3::identity(),
            r: Vec3::zero(),
        }
    }
    /// `X m = [E ω; E (v − r × ω)]`.
    pub fn apply(&self, m: &Motion<S>) -> Motion<S> {
        Motion {
            ang: self.e.mul_vec(&m.ang),
            lin: self.e.mul_vec(&(&m.lin - &self.r.cross(&m.ang))),
        }
    }
    /// `Xᵀ f = [Eᵀ n + r × Eᵀ f; Eᵀ f]`: a force from frame B coordinates back to frame A
    /// (`ᴬX_B* = Xᵀ`, spatial_v2's `Xup' * f`).
    pub fn tr_apply(&self, f: &Force<S>) -> Force<S> {
        let lin = self.e.tr_mul_vec(&f.lin);
        Force {
            ang: self.e.tr_mul_vec(&f.ang) + self.r.cross(&lin),
            lin,
        }
    }
    /// `Xᵀ I X`: a rigid-body inertia from frame B coordinates to frame A coordinates
    /// (RBDA Table 2.5): `(m, Eᵀh + m r, EᵀĪE − r̃ (Eᵀh)~ − (Eᵀh + m r)~ r̃)`.
    pub fn tr_inertia(&self, i: &RbInertia<S>) -> RbInertia<S> {
        let h_rot = self.e.tr_mul_vec(&i.h);
        let h = &h_rot + &self.r.scale(&i.m);
        let rt = Mat3::skew(&self.r);
        let ibar = self.e.transpose().congruence(&i.ibar)
            - rt.mul_mat(&Mat3::skew(&h_rot))
            - Mat3::skew(&h).mul_mat(&rt);
        RbInertia {
            m: i.m.clone(),
            h,
            ibar,
        }
    }
}

impl<S: Scalar> RbInertia<S> {
    /// `(m, Θ h, Θ Ī Θᵀ)`: the inertia turned by `Θ`, the rotation by the angle whose sine and
    /// cosine are `s` and `c` about the coordinate axis `e_k` (RBDA Table 2.5 with `E = Θᵀ`,
    /// `r = 0`; `−e_k` is `e_k` with `−s`). The axes `(a, b) = (k + 1, k + 2) mod 3` turn; the
    /// planar block of `Ī` is written in double-angle form, as in Khalil and Kleinfinger's
    /// customized symbolic models: with `u = s²`, `w = c s`, `d = Ī_aa − Ī_bb`, `e = 2 Ī_ab` and
    /// `t = u d + w e`, `Ī'_aa = Ī_aa − t`, `Ī'_bb = Ī_bb + t` and `Ī'_ab = Ī_ab + w d − u e`
    /// (by `c² = 1 − u`): four products where the congruence `Θ Ī Θᵀ` takes twelve, and none
    /// when the block is isotropic (`d = e = 0`), where the congruence still computes
    /// `k c² + k s²`.
    #[must_use]
    pub fn turned_about_axis(&self, k: usize, s: &S, c: &S) -> RbInertia<S> {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        let i = &self.ibar;
        let u = s.clone() * s.clone();
        let w = c.clone() * s.clone();
        let d = i.at(a, a) - i.at(b, b);
        let e = i.at(a, b) + i.at(a, b);
        let t = u.clone() * d.clone() + w.clone() * e.clone();
        let mut ibar = i.clone();
        ibar.0[a][a] = i.at(a, a) - t.clone();
        ibar.0[b][b] = i.at(b, b) + t;
        let ab = i.at(a, b) + (w * d - u * e);
        ibar.0[a][b] = ab.clone();
        ibar.0[b][a] = ab;
        // Column k turns as a vector (its k entry stays).
        let col = i.col(k).turned_about_axis(k, s, c);
        let (ak, bk) = (col.at(a), col.at(b));
        ibar.0[a][k] = ak.clone();
        ibar.0[k][a] = ak;
        ibar.0[b][k] = bk.clone();
        ibar.0[k][b] = bk;
        RbInertia {
            m: self.m.clone(),
            h: self.h.turned_about_axis(k, s, c),
            ibar,
        }
    }
}

/// A rigid-body spatial inertia about the frame origin: mass `m`, first moment `h = m c` and
/// rotational inertia `Ī` about the origin (RBDA eq. (2.63)).
#[derive(Clone, Debug)]
pub struct RbInertia<S> {
    /// Mass.
    pub m: S,
    /// First moment `m c` about the frame origin.
    pub h: Vec3<S>,
    /// Rotational inertia about the frame origin.
    pub ibar: Mat3<S>,
}

impl<S: Scalar> RbInertia<S> {
    /// spatial_v2 `mcI(m, c, I_c)`: `h = m c`, `Ī = I_c + m c̃ c̃ᵀ` (parallel axes).
    pub fn from_com(m: &S, c: &Vec3<S>, inertia_com: &Mat3<S>) -> Self {
        RbInertia {
            m: m.clone(),
            h: c.scale(m),
            ibar: Mat3(kanegen_runtime::inertia::parallel_axis(
                m,
                &c.0,
                &inertia_com.0,
            )),
        }
    }
    /// `I [ω; v] = [Ī ω + h × v; m v − h × ω]`.
    pub fn mul(&self, v: &Motion<S>) -> Force<S> {
        Force {
            ang: self.ibar.mul_vec(&v.ang) + self.h.cross(&v.lin),
            lin: v.lin.scale(&self.m) - self.h.cross(&v.ang),
        }
    }
}

/// The rows `[f; n]` of a force (linear part first: the base rows of `ν = [v_b; ω_b; q̇]`).
pub fn base_rows<S: Scalar>(f: &Force<S>) -> [S; 6] {
    [
        f.lin.at(0),
        f.lin.at(1),
        f.lin.at(2),
        f.ang.at(0),
        f.ang.at(1),
        f.ang.at(2),
    ]
}

/// Two bodies' inertias in the same frame, welded together.
impl<S: Scalar> core::ops::Add for RbInertia<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        RbInertia {
            m: self.m + o.m,
            h: self.h + o.h,
            ibar: self.ibar + o.ibar,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::axis_rotation;

    /// The double-angle turn equals the congruence it replaces, about every coordinate axis and
    /// both signs, on a general inertia (all products of inertia non-zero).
    #[test]
    fn turned_about_axis_is_the_congruence() {
        let i = RbInertia {
            m: 3.7,
            h: Vec3::new(0.4, -1.1, 0.9),
            ibar: Mat3([[2.0, 0.3, -0.7], [0.3, 1.4, 0.25], [-0.7, 0.25, 3.1]]),
        };
        for k in 0..3 {
            for sign in [1.0, -1.0] {
                for q in [0.0, 0.3, -2.2, 3.0] {
                    let (s, c) = f64::sin_cos(q);
                    let mut u = Vec3::zero();
                    u.0[k] = sign;
                    let theta = axis_rotation(&u, &s, &c);
                    // (m, Θ h, Θ Ī Θᵀ) is Xᵀ I X with E = Θᵀ, r = 0.
                    let want = Xform {
                        e: theta.transpose(),
                        r: Vec3::zero(),
                    }
                    .tr_inertia(&i);
                    let have = i.turned_about_axis(k, &(sign * s), &c);
                    for r in 0..3 {
                        assert!((have.h.at(r) - want.h.at(r)).abs() < 1e-14, "k {k} q {q}");
                        for col in 0..3 {
                            let (a, b) = (have.ibar.at(r, col), want.ibar.at(r, col));
                            assert!((a - b).abs() < 1e-14, "k {k} sign {sign} q {q}: {a} {b}");
                        }
                    }
                    assert_eq!(have.m, i.m);
                }
            }
        }
    }
}
