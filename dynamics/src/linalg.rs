//! 3-vectors and 3×3 matrices over any [`Scalar`], with the paper's operation conventions.
//!
//! Every product accumulates from zero (`0 + a₀b₀ + a₁b₁ + a₂b₂`: 3 m + 3 a under the paper's
//! convention) and skew matrices carry literal zeros that are multiplied like any other entry. On
//! numbers this costs nothing measurable; on the tracer it makes the raw count equal the paper's
//! bookkeeping, and folding then removes the zeros (see `docs/paper.md`, "Operation counts").
//!
//! ```
//! use kanegen_dynamics::linalg::{Mat3, Vec3};
//! let x = Vec3::new(1.0, 2.0, 3.0);
//! let y = Vec3::new(-1.0, 0.5, 2.0);
//! // skew(x) y = x × y
//! assert_eq!(Mat3::skew(&x).mul_vec(&y), x.cross(&y));
//! ```

use crate::scalar::Scalar;
use core::ops::{Add, Mul, Neg, Sub};

/// A column 3-vector.
#[derive(Clone, Debug, PartialEq)]
pub struct Vec3<S>(pub [S; 3]);

/// A 3×3 matrix, row-major: `self.0[row][col]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Mat3<S>(pub [[S; 3]; 3]);

impl<S: Scalar> Vec3<S> {
    /// The vector `(x, y, z)`.
    pub fn new(x: S, y: S, z: S) -> Self {
        Vec3([x, y, z])
    }
    /// The vector turned by the angle of sine `s` and cosine `c` about the coordinate axis `e_k`:
    /// with `(a, b) = (k + 1, k + 2) mod 3`, `(c x_a − s x_b, s x_a + c x_b)`, four products
    /// where a rotation matrix takes nine.
    #[must_use]
    pub fn turned_about_axis(&self, k: usize, s: &S, c: &S) -> Self {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        let (xa, xb) = (self.at(a), self.at(b));
        let mut out = self.clone();
        out.0[a] = c.clone() * xa.clone() - s.clone() * xb.clone();
        out.0[b] = s.clone() * xa + c.clone() * xb;
        out
    }
    /// The zero vector.
    pub fn zero() -> Self {
        Vec3([S::zero(), S::zero(), S::zero()])
    }
    /// Constants from an `f64` array.
    pub fn from_f64(x: [f64; 3]) -> Self {
        Vec3(x.map(S::constant))
    }
    /// Component `i`.
    #[must_use]
    pub fn at(&self, i: usize) -> S {
        self.0[i].clone()
    }
    /// Dot product, accumulated from zero (3 m + 3 a).
    #[must_use]
    pub fn dot(&self, o: &Self) -> S {
        S::zero() + self.at(0) * o.at(0) + self.at(1) * o.at(1) + self.at(2) * o.at(2)
    }
    /// Cross product `self × o`, written as `skew(self) · o` (the paper's `ã b`: 9 m + 9 a raw,
    /// 6 m + 3 a after folding).
    #[must_use]
    pub fn cross(&self, o: &Self) -> Self {
        Mat3::skew(self).mul_vec(o)
    }
    /// Scalar multiple `s · self` (3 m).
    #[must_use]
    pub fn scale(&self, s: &S) -> Self {
        Vec3(core::array::from_fn(|i| s.clone() * self.at(i)))
    }
    /// Outer product `self oᵀ` (9 m).
    #[must_use]
    pub fn outer(&self, o: &Self) -> Mat3<S> {
        Mat3(core::array::from_fn(|r| {
            core::array::from_fn(|c| self.at(r) * o.at(c))
        }))
    }
    /// Components as an array.
    pub fn into_array(self) -> [S; 3] {
        self.0
    }
}

impl<S: Scalar> Mat3<S> {
    /// The zero matrix.
    pub fn zero() -> Self {
        Mat3(core::array::from_fn(|_| {
            core::array::from_fn(|_| S::zero())
        }))
    }
    /// The identity.
    pub fn identity() -> Self {
        Mat3(core::array::from_fn(|r| {
            core::array::from_fn(|c| if r == c { S::one() } else { S::zero() })
        }))
    }
    /// Constants from an `f64` row-major array.
    pub fn from_f64(m: [[f64; 3]; 3]) -> Self {
        Mat3(m.map(|row| row.map(S::constant)))
    }
    /// Entry `(r, c)`.
    #[must_use]
    pub fn at(&self, r: usize, c: usize) -> S {
        self.0[r][c].clone()
    }
    /// The skew-symmetric matrix `x̃` with `x̃ b = x × b`; its zeros are literal zeros.
    pub fn skew(x: &Vec3<S>) -> Self {
        let z = S::zero;
        Mat3([
            [z(), -x.at(2), x.at(1)],
            [x.at(2), z(), -x.at(0)],
            [-x.at(1), x.at(0), z()],
        ])
    }
    /// Transpose (free).
    #[must_use]
    pub fn transpose(&self) -> Self {
        Mat3(core::array::from_fn(|r| {
            core::array::from_fn(|c| self.at(c, r))
        }))
    }
    /// Row `r` as a vector.
    #[must_use]
    pub fn row(&self, r: usize) -> Vec3<S> {
        Vec3(self.0[r].clone())
    }
    /// Column `c` as a vector.
    #[must_use]
    pub fn col(&self, c: usize) -> Vec3<S> {
        Vec3(core::array::from_fn(|r| self.at(r, c)))
    }
    /// `self · v`, each entry accumulated from zero (9 m + 9 a).
    #[must_use]
    pub fn mul_vec(&self, v: &Vec3<S>) -> Vec3<S> {
        Vec3(core::array::from_fn(|r| self.row(r).dot(v)))
    }
    /// `selfᵀ · v` (9 m + 9 a).
    #[must_use]
    pub fn tr_mul_vec(&self, v: &Vec3<S>) -> Vec3<S> {
        Vec3(core::array::from_fn(|c| self.col(c).dot(v)))
    }
    /// `self · o`, each entry accumulated from zero (27 m + 27 a: the paper's `(3m+3a)·9`).
    #[must_use]
    pub fn mul_mat(&self, o: &Self) -> Self {
        Mat3(core::array::from_fn(|r| {
            core::array::from_fn(|c| self.row(r).dot(&o.col(c)))
        }))
    }
    /// Scalar multiple (9 m).
    #[must_use]
    pub fn scale(&self, s: &S) -> Self {
        Mat3(core::array::from_fn(|r| {
            core::array::from_fn(|c| s.clone() * self.at(r, c))
        }))
    }
    /// `self · D · selfᵀ` for a rotation `self` (used for `I = τ I⁽ʲ⁾ τᵀ`, eq. (6)).
    #[must_use]
    pub fn congruence(&self, d: &Self) -> Self {
        self.mul_mat(d).mul_mat(&self.transpose())
    }
    /// Rows as arrays.
    pub fn into_array(self) -> [[S; 3]; 3] {
        self.0
    }
}

impl<S: Scalar> Add for Vec3<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        let [a0, a1, a2] = self.0;
        let [b0, b1, b2] = o.0;
        Vec3([a0 + b0, a1 + b1, a2 + b2])
    }
}
impl<S: Scalar> Sub for Vec3<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        let [a0, a1, a2] = self.0;
        let [b0, b1, b2] = o.0;
        Vec3([a0 - b0, a1 - b1, a2 - b2])
    }
}
impl<S: Scalar> Neg for Vec3<S> {
    type Output = Self;
    fn neg(self) -> Self {
        Vec3(self.0.map(|x| -x))
    }
}
impl<S: Scalar> Add for &Vec3<S> {
    type Output = Vec3<S>;
    fn add(self, o: Self) -> Vec3<S> {
        self.clone() + o.clone()
    }
}
impl<S: Scalar> Sub for &Vec3<S> {
    type Output = Vec3<S>;
    fn sub(self, o: Self) -> Vec3<S> {
        self.clone() - o.clone()
    }
}
impl<S: Scalar> Mul<&Vec3<S>> for &Mat3<S> {
    type Output = Vec3<S>;
    fn mul(self, v: &Vec3<S>) -> Vec3<S> {
        self.mul_vec(v)
    }
}
impl<S: Scalar> Mul for &Mat3<S> {
    type Output = Mat3<S>;
    fn mul(self, o: Self) -> Mat3<S> {
        self.mul_mat(o)
    }
}
impl<S: Scalar> Add for Mat3<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        let mut rows = self.0;
        for (row, orow) in rows.iter_mut().zip(o.0) {
            for (x, y) in row.iter_mut().zip(orow) {
                *x = x.clone() + y;
            }
        }
        Mat3(rows)
    }
}
impl<S: Scalar> Sub for Mat3<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self + (-o)
    }
}
impl<S: Scalar> Neg for Mat3<S> {
    type Output = Self;
    fn neg(self) -> Self {
        Mat3(self.0.map(|row| row.map(|x| -x)))
    }
}
impl<S: Scalar> Add for &Mat3<S> {
    type Output = Mat3<S>;
    fn add(self, o: Self) -> Mat3<S> {
        self.clone() + o.clone()
    }
}

/// Rotation about the unit axis `u` by the angle with sine `s` and cosine `c` (Rodrigues:
/// `R = c·1 + s·ũ + (1 − c)·u uᵀ`); this is the joint rotation `Θ_j` of eq. (1).
///
/// The diagonal is written `u_i² + (1 − u_i²) c`, the same number, so that a constant
/// coordinate axis folds to the sparse rotation (`R_zz = 1 + 0·c = 1` for `u = e_z`, where
/// `c + (1 − c)·1` would be two operations that fold cannot remove).
pub fn axis_rotation<S: Scalar>(u: &Vec3<S>, s: &S, c: &S) -> Mat3<S> {
    let k = S::one() - c.clone();
    let su = Mat3::skew(u).scale(s);
    Mat3(core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            let ui = u.at(i);
            if i == j {
                let uu = ui.clone() * ui;
                uu.clone() + (S::one() - uu) * c.clone()
            } else {
                ui * u.at(j) * k.clone() + su.at(i, j)
            }
        })
    }))
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    #[test]
    fn skew_products_match_cross_products() {
        let x = Vec3::<f64>::new(0.3, -1.2, 2.5);
        let y = Vec3::new(1.1, 0.7, -0.4);
        let c = x.cross(&y);
        assert!((c.at(0) - (x.at(1) * y.at(2) - x.at(2) * y.at(1))).abs() < 1e-15);
        assert!((c.dot(&x)).abs() < 1e-14 && (c.dot(&y)).abs() < 1e-14);
        // x̃ ỹᵀ = (x·y) 1 − y xᵀ
        let p = Mat3::skew(&x).mul_mat(&Mat3::skew(&y).transpose());
        let q = Mat3::<f64>::identity().scale(&x.dot(&y)) - y.outer(&x);
        for r in 0..3 {
            for k in 0..3 {
                assert!((p.at(r, k) - q.at(r, k)).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn axis_rotation_is_orthonormal_and_fixes_axis() {
        let n: f64 = (0.2f64 * 0.2 + 0.5 * 0.5 + 0.8 * 0.8).sqrt();
        let u = Vec3::<f64>::new(0.2 / n, 0.5 / n, -0.8 / n);
        let (s, c) = 0.7f64.sin_cos();
        let r = axis_rotation(&u, &s, &c);
        let rrt = r.mul_mat(&r.transpose());
        for i in 0..3 {
            for j in 0..3 {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((rrt.at(i, j) - e).abs() < 1e-14);
            }
        }
        let ru = r.mul_vec(&u);
        for i in 0..3 {
            assert!((ru.at(i) - u.at(i)).abs() < 1e-14);
        }
    }
}
