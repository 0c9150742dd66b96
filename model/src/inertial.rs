//! Mass properties of a rigid body, their validation, and the one place where two bodies are
//! welded together (parallel-axis theorem): readers merging fixed links, [`crate::Model::lock_joint`]
//! and scene payloads all call [`Inertial::merge`].
//!
//! ```
//! use kanegen_model::Inertial;
//! let point = |m: f64, x: f64| Inertial { mass: m, com: [x, 0.0, 0.0], inertia: [[0.0; 3]; 3] };
//! let both = point(1.0, 0.0).merge(&point(3.0, 4.0));
//! assert_eq!(both.mass, 4.0);
//! assert_eq!(both.com, [3.0, 0.0, 0.0]);
//! // m₁ d₁² + m₂ d₂² = 1·9 + 3·1 about the y and z axes.
//! assert_eq!(both.inertia[1][1], 12.0);
//! ```

use crate::bounds::{Bound, INERTIA, LENGTH, MASS};
use crate::placement::{mat_mul, transpose, Placement, M3, V3};
use crate::{ModelError, Validation};
use serde::Serialize;

/// Mass properties of a rigid body.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Inertial {
    /// Mass, kg (> 0).
    pub mass: f64,
    /// Centre of mass in the body frame, m.
    pub com: V3,
    /// Inertia tensor about the centre of mass, in body-frame axes, kg·m² (symmetric positive
    /// definite, satisfying the triangle inequality).
    pub inertia: M3,
}

/// `m (|c|² 1 − c cᵀ)`: the parallel-axis term of a point mass `m` at `c` (Steiner's theorem),
/// the model's one, in `f64` ([`Inertial::merge`]; the traced algorithms shift by
/// `kanegen_runtime::inertia::parallel_axis`, in the operations of `m c̃ c̃ᵀ`).
#[must_use]
pub fn steiner(m: f64, c: &V3) -> M3 {
    let n2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| m * (if i == j { n2 } else { 0.0 } - c[i] * c[j])))
}

/// `R I Rᵀ`: an inertia tensor re-expressed in rotated axes.
#[must_use]
pub fn rotate_inertia(r: &M3, i: &M3) -> M3 {
    mat_mul(&mat_mul(r, i), &transpose(r))
}

impl Inertial {
    /// The same body seen from a frame in which its own frame is placed at `p`: centre of mass
    /// `p(com)`, inertia `R I Rᵀ`.
    #[must_use]
    pub fn moved(&self, p: &Placement) -> Inertial {
        Inertial {
            mass: self.mass,
            com: p.point(&self.com),
            inertia: rotate_inertia(&p.rotation, &self.inertia),
        }
    }

    /// Two bodies given in the same frame, welded into one: total mass, combined centre of mass,
    /// and the inertia about it by the parallel-axis theorem. The masses must not sum to zero.
    #[must_use]
    pub fn merge(&self, other: &Inertial) -> Inertial {
        let (a, b) = (self, other);
        let m = a.mass + b.mass;
        let c: V3 = core::array::from_fn(|k| (a.mass * a.com[k] + b.mass * b.com[k]) / m);
        let mut inertia = [[0.0; 3]; 3];
        for part in [a, b] {
            let d: V3 = core::array::from_fn(|k| part.com[k] - c[k]);
            let shift = steiner(part.mass, &d);
            for r in 0..3 {
                for s in 0..3 {
                    inertia[r][s] += part.inertia[r][s] + shift[r][s];
                }
            }
        }
        Inertial {
            mass: m,
            com: c,
            inertia,
        }
    }

    /// [`Inertial::merge`] of optional bodies, where `None` is massless.
    #[must_use]
    pub fn merge_opt(a: Option<Inertial>, b: Option<Inertial>) -> Option<Inertial> {
        match (a, b) {
            (Some(a), Some(b)) => Some(a.merge(&b)),
            (a, None) => a,
            (None, b) => b,
        }
    }
}

pub(crate) fn finite(owner: &str, field: &str, xs: &[f64]) -> Result<(), ModelError> {
    match xs.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(ModelError::invalid(
            owner,
            field,
            format!("value {x} is not finite"),
        )),
        None => Ok(()),
    }
}

/// Checks `xs` against a magnitude [`Bound`] (finite, `|x| ≤ max`), naming `owner` and `field`.
pub(crate) fn bounded(owner: &str, field: &str, xs: &[f64], b: Bound) -> Result<(), ModelError> {
    b.check(xs)
        .map_err(|reason| ModelError::invalid(owner, field, reason))
}

/// Checks a body's mass properties strictly; `owner` names the joint (or body) in the message.
pub fn validate_inertial(owner: &str, field: &str, b: &Inertial) -> Result<(), ModelError> {
    validate_inertial_with(owner, field, b, Validation::default())
}

/// Checks a body's mass properties under the given [`Validation`]: finite, mass > 0, inertia
/// symmetric, positive definite and (unless allowed) satisfying the triangle inequality.
pub fn validate_inertial_with(
    owner: &str,
    field: &str,
    b: &Inertial,
    validation: Validation,
) -> Result<(), ModelError> {
    bounded(owner, &format!("{field}.mass"), &[b.mass], MASS)?;
    if b.mass <= 0.0 {
        return Err(ModelError::invalid(
            owner,
            &format!("{field}.mass"),
            format!("mass must be > 0, got {}", b.mass),
        ));
    }
    bounded(owner, &format!("{field}.com"), &b.com, LENGTH)?;
    let i = &b.inertia;
    let flat: Vec<f64> = i.iter().flatten().copied().collect();
    bounded(owner, &format!("{field}.inertia"), &flat, INERTIA)?;
    let scale = flat
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()))
        .max(f64::MIN_POSITIVE);
    for (r, c) in [(0, 1), (0, 2), (1, 2)] {
        if (i[r][c] - i[c][r]).abs() > 1e-9 * scale {
            return Err(ModelError::invalid(
                owner,
                &format!("{field}.inertia"),
                format!(
                    "not symmetric: I[{r}][{c}] = {} but I[{c}][{r}] = {}",
                    i[r][c], i[c][r]
                ),
            ));
        }
    }
    // Positive definiteness by Sylvester's criterion (leading principal minors).
    let m1 = i[0][0];
    let m2 = i[0][0] * i[1][1] - i[0][1] * i[1][0];
    let m3 = i[0][0] * (i[1][1] * i[2][2] - i[1][2] * i[2][1])
        - i[0][1] * (i[1][0] * i[2][2] - i[1][2] * i[2][0])
        + i[0][2] * (i[1][0] * i[2][1] - i[1][1] * i[2][0]);
    if !(m1 > 0.0 && m2 > 0.0 && m3 > 0.0) {
        return Err(ModelError::invalid(
            owner,
            &format!("{field}.inertia"),
            format!(
                "not positive definite (leading minors {m1:.6e}, {m2:.6e}, {m3:.6e}); the inertia tensor about the centre of mass must be SPD"
            ),
        ));
    }
    // Triangle inequality on the principal moments: each ≤ the sum of the other two.
    let ev = sym3_eigenvalues(i);
    let tol = 1e-9 * (ev[0] + ev[1] + ev[2]);
    for k in 0..3 {
        let (a, b2, c) = (ev[k], ev[(k + 1) % 3], ev[(k + 2) % 3]);
        if a > b2 + c + tol && !validation.allow_nonphysical_inertia {
            return Err(ModelError::invalid(
                owner,
                &format!("{field}.inertia"),
                format!(
                    "violates the triangle inequality: principal moments {:.6e}, {:.6e}, {:.6e} (not physically realisable; --allow-nonphysical accepts it)",
                    ev[0], ev[1], ev[2]
                ),
            ));
        }
    }
    Ok(())
}

/// Eigenvalues of a symmetric 3×3 matrix, ascending: the cyclic Jacobi method (Golub and Van
/// Loan, *Matrix Computations*, Algorithm 8.5.3). Each rotation zeroes one off-diagonal pair
/// and keeps the matrix symmetric with the same eigenvalues; the sweeps converge quadratically
/// (four to six in practice) and stop once the off-diagonal part is below rounding of the whole,
/// so every eigenvalue is within a few ulps of the matrix norm.
fn sym3_eigenvalues(m: &M3) -> [f64; 3] {
    let mut a = *m;
    let norm2: f64 = a.iter().flatten().map(|x| x * x).sum();
    for _ in 0..MAX_JACOBI_SWEEPS {
        let off2 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        if off2 <= f64::EPSILON * f64::EPSILON * norm2 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            // The rotation J (c at pp and qq, s at pq, −s at qp) with (JᵀAJ)_pq = 0, its
            // tangent the smaller root of t² + 2τt − 1 = 0.
            let tau = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = tau.signum() / (tau.abs() + tau.hypot(1.0));
            let c = 1.0 / t.hypot(1.0);
            let s = t * c;
            for row in &mut a {
                let (kp, kq) = (row[p], row[q]);
                row[p] = c * kp - s * kq;
                row[q] = s * kp + c * kq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * rp[k] - s * rq[k]);
            a[q] = std::array::from_fn(|k| s * rp[k] + c * rq[k]);
        }
    }
    let mut ev = [a[0][0], a[1][1], a[2][2]];
    ev.sort_by(f64::total_cmp);
    ev
}

/// Most Jacobi sweeps [`sym3_eigenvalues`] makes (it needs at most six on a finite matrix).
const MAX_JACOBI_SWEEPS: usize = 32;

#[cfg(test)]
mod tests {
    use super::sym3_eigenvalues;
    use proptest::prelude::*;

    /// `R diag(d) Rᵀ` for the rotation by `angle` about the (unnormalized) `axis`.
    fn with_eigenvalues(d: [f64; 3], axis: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
        let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let [x, y, z] = axis.map(|v| v / n);
        let (s, c) = angle.sin_cos();
        let k = 1.0 - c;
        let r = [
            [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
            [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
            [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
        ];
        std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum())
        })
    }

    #[test]
    fn diagonal_and_repeated() {
        assert_eq!(
            sym3_eigenvalues(&[[3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]),
            [1.0, 2.0, 3.0]
        );
        let ev = sym3_eigenvalues(&with_eigenvalues([2.0, 2.0, 2.0], [1.0, 2.0, 3.0], 0.7));
        for e in ev {
            assert!((e - 2.0).abs() < 1e-14, "{ev:?}");
        }
    }

    proptest! {
        /// The eigenvalues of a turned diagonal matrix, to a few ulps of its trace, and the
        /// same as nalgebra's symmetric eigen-solver.
        #[test]
        fn recovers_eigenvalues(
            d in prop::array::uniform3(1e-3f64..1e3),
            axis in prop::array::uniform3(-1.0f64..1.0),
            angle in -3.0f64..3.0,
        ) {
            prop_assume!(axis.iter().map(|v| v * v).sum::<f64>() > 1e-6);
            let m = with_eigenvalues(d, axis, angle);
            let got = sym3_eigenvalues(&m);
            let mut want = d;
            want.sort_by(f64::total_cmp);
            let tol = 1e-13 * (d[0] + d[1] + d[2]);
            let mut na: Vec<f64> =
                nalgebra::Matrix3::from_fn(|r, c| m[r][c]).symmetric_eigenvalues().iter().copied().collect();
            na.sort_by(f64::total_cmp);
            for k in 0..3 {
                prop_assert!((got[k] - want[k]).abs() <= tol, "{got:?} vs {want:?}");
                prop_assert!((got[k] - na[k]).abs() <= tol, "{got:?} vs nalgebra {na:?}");
            }
        }
    }
}
