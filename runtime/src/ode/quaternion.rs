//! The unit quaternion of a free-floating base's state `[p₀, quat (x y z w), q, v_b, ω_b, q̇]`
//! (`13 + 2n` long with `n` joints): its projection back to unit length, its exponential-map
//! update (the Lie-group part of [`midpoint`](super::midpoint())) and its rotation matrix.

use crate::scalar::Scalar;

/// Renormalizes the unit quaternion `x[3..7]` of a free-floating state (the projection after
/// an accepted step); a shorter state is left alone.
#[inline]
pub fn normalize_quaternion(x: &mut [f64]) {
    if let Some(quat) = x.get_mut(3..7) {
        let norm = Scalar::sqrt(
            quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3],
        );
        for v in quat {
            *v /= norm;
        }
    }
}

/// The additive update `out = x + h f` (the [`System::advance`](super::System::advance) of a
/// state without a Lie-group part).
#[inline]
pub fn advance_additive(x: &[f64], h: f64, f: &[f64], out: &mut [f64]) {
    for ((o, xi), fi) in out.iter_mut().zip(x).zip(f) {
        *o = xi + h * fi;
    }
}

/// The update of a free-floating state `[p₀, quat, q, v_b, ω_b, q̇]` with `n` joints
/// (`13 + 2n` long): additive ([`advance_additive`]), except the quaternion `x[3..7]`, which
/// becomes `quat ⊗ exp(h ω_b(at) / 2)` (exponential map, unit by construction, symmetric in
/// `h`; `sin(|ω| h/2)/|ω|` by its Taylor series below `|ω| h/2 = 1e-8`). A state shorter than
/// 13 has no base: additive.
pub fn advance_floating(x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
    advance_additive(x, h, f, out);
    let d = x.len().min(at.len()).min(out.len());
    if d < 13 {
        return;
    }
    // ω_b at 10 + n.
    let n = (d - 13) / 2;
    let om = [at[10 + n], at[11 + n], at[12 + n]];
    let w_norm = Scalar::sqrt(om[0] * om[0] + om[1] * om[1] + om[2] * om[2]);
    let half = 0.5 * h * w_norm;
    let s = if libm::fabs(half) < 1e-8 {
        0.5 * h * (1.0 - half * half / 6.0)
    } else {
        Scalar::sin(half) / w_norm
    };
    let (rho, rw) = ([s * om[0], s * om[1], s * om[2]], Scalar::cos(half));
    let (u, w) = ([x[3], x[4], x[5]], x[6]);
    let cross = [
        u[1] * rho[2] - u[2] * rho[1],
        u[2] * rho[0] - u[0] * rho[2],
        u[0] * rho[1] - u[1] * rho[0],
    ];
    for i in 0..3 {
        out[3 + i] = w * rho[i] + rw * u[i] + cross[i];
    }
    out[6] = w * rw - (u[0] * rho[0] + u[1] * rho[1] + u[2] * rho[2]);
}

/// The rotation matrix (row-major, body to inertial axes) of a quaternion `[x, y, z, w]`:
/// `I + 2w [u]× + 2 [u]×²`, not normalized (as `kanegen::dynamics::base::quat_to_matrix`).
#[must_use]
pub fn quat_to_matrix(q: &[f64; 4]) -> [[f64; 3]; 3] {
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// `∂(R(quat) v)/∂quat` (3 × 4, columns `x, y, z, w`) of the rotation formula of
/// [`quat_to_matrix`], `R v = v + 2w (u × v) + 2 u × (u × v)`, at any quaternion (unit or not):
/// `∂/∂u = −2w [v]× − 2 [u × v]× − 2 [u]× [v]×`, `∂/∂w = 2 u × v`. With `transpose`, of
/// `R(quat)ᵀ v` (the same formula with `−w`).
#[must_use]
pub fn rotation_jacobian(quat: &[f64; 4], v: &[f64; 3], transpose: bool) -> [[f64; 4]; 3] {
    let u = [quat[0], quat[1], quat[2]];
    let w = if transpose { -quat[3] } else { quat[3] };
    let uxv = cross(&u, v);
    let (sv, suxv, su) = (skew(v), skew(&uxv), skew(&u));
    core::array::from_fn(|r| {
        core::array::from_fn(|c| {
            if c == 3 {
                let d = 2.0 * uxv[r];
                if transpose {
                    -d
                } else {
                    d
                }
            } else {
                let su_sv = su[r][0] * sv[0][c] + su[r][1] * sv[1][c] + su[r][2] * sv[2][c];
                -2.0 * (w * sv[r][c] + suxv[r][c] + su_sv)
            }
        })
    })
}

/// The tangent directions of a free-floating state `x = [p₀, quat, q, v_b, ω_b, q̇]` (`d`
/// numbers, `d − 1` directions): the first-order change of `x` along each direction `δ` of
/// Pinocchio's `integrate(x, δ)` (`M₀ ← M₀ exp(δ_b)`, `δ_b = [δp; δθ]` in base coordinates), as
/// a `d × (d − 1)` row-major matrix into `m`: `dp₀ = R₀ δp`, `dquat = ½ quat ⊗ (δθ, 0)`
/// (`du = ½ (w δθ + u × δθ)`, `dw = −½ u · δθ`), every other number its own direction.
pub fn floating_tangent_in(x: &[f64], m: &mut [f64]) {
    let d = x.len();
    let t = d - 1;
    m.fill(0.0);
    let (u, w) = ([x[3], x[4], x[5]], x[6]);
    let r = quat_to_matrix(&[u[0], u[1], u[2], w]);
    let su = skew(&u);
    for i in 0..3 {
        for j in 0..3 {
            m[i * t + j] = r[i][j];
            let diag = if i == j { w } else { 0.0 };
            m[(3 + i) * t + 3 + j] = 0.5 * (diag + su[i][j]);
        }
        m[6 * t + 3 + i] = -0.5 * u[i];
    }
    for i in 7..d {
        m[i * t + i - 1] = 1.0;
    }
}

/// The tangent coordinates of a first-order change of the free-floating state `r` (`d`
/// numbers) that [`normalize_quaternion`] takes to `x⁺`: Pinocchio's `difference(x⁺, ·)` to
/// first order through the normalization, a `(d − 1) × d` row-major matrix into `m`:
/// `δp = R⁺ᵀ dp₀`, `δθ = 2 vec(q̂* ⊗ dquat) / |quat| = 2 ((ŵ 1 − [û]×) du − û dw) / |quat|`
/// (`q̂ = quat / |quat| = (û, ŵ)`: the radial part of `dquat` has no rotation), every other
/// number its own coordinate.
pub fn floating_tangent_out(r: &[f64], m: &mut [f64]) {
    let d = r.len();
    m.fill(0.0);
    let norm = Scalar::sqrt(r[3] * r[3] + r[4] * r[4] + r[5] * r[5] + r[6] * r[6]);
    let (u, w) = ([r[3] / norm, r[4] / norm, r[5] / norm], r[6] / norm);
    let rot = quat_to_matrix(&[u[0], u[1], u[2], w]);
    let su = skew(&u);
    let k = 2.0 / norm;
    for i in 0..3 {
        for j in 0..3 {
            m[i * d + j] = rot[j][i];
            let diag = if i == j { w } else { 0.0 };
            m[(3 + i) * d + 3 + j] = k * (diag - su[i][j]);
        }
        m[(3 + i) * d + 6] = -k * u[i];
    }
    for i in 6..d - 1 {
        m[i * d + i + 1] = 1.0;
    }
}

/// `y ⊖ x` of two free-floating states `[p₀, quat, q, v_b, ω_b, q̇]` (`d` numbers each) in the
/// tangent space at `x` (`d − 1` numbers into `out`), the coordinates in which
/// [`floating_rk4_step_jacobians`](super::floating_rk4_step_jacobians) gives `A` and `B`:
/// `[R(x)ᵀ (p_y − p_x); 2 vec(quat_x* ⊗ quat_y); the rest subtracted]` for unit quaternions.
/// Pinocchio's `difference(x, y)` to first order in `y − x` (its derivative in `y` at `y = x`
/// is [`floating_tangent_out`]'s), what a controller's feedback and cost take of a state.
pub fn floating_difference(x: &[f64], y: &[f64], out: &mut [f64]) {
    let (u, w) = ([x[3], x[4], x[5]], x[6]);
    let (uy, wy) = ([y[3], y[4], y[5]], y[6]);
    let r = quat_to_matrix(&[u[0], u[1], u[2], w]);
    // vec(quat_x* ⊗ quat_y) = w u_y − w_y u − u × u_y.
    let c = cross(&u, &uy);
    for i in 0..3 {
        out[i] = (0..3).map(|j| r[j][i] * (y[j] - x[j])).sum();
        out[3 + i] = 2.0 * (w * uy[i] - wy * u[i] - c[i]);
    }
    for i in 6..out.len().min(x.len() - 1).min(y.len() - 1) {
        out[i] = y[i + 1] - x[i + 1];
    }
}

/// The unit quaternion `E = [sin(|ω| h/2) ω/|ω|; cos(|ω| h/2)]` of [`advance_floating`]'s
/// exponential map (`quat ⊗ E`), and its derivative `∂E/∂ω` (4 × 3):
/// `∂E_vec/∂ω = s 1 + (h/2 cos(|ω| h/2) − s)/|ω|² ω ωᵀ`, `∂E_w/∂ω = −(h/2) s ωᵀ` with
/// `s = sin(|ω| h/2)/|ω|` (below `|ω| h/2 = 1e-8` their Taylor series, as the map's).
#[must_use]
pub fn exp_map_jacobian(h: f64, om: &[f64; 3]) -> ([f64; 4], [[f64; 3]; 4]) {
    let a = Scalar::sqrt(om[0] * om[0] + om[1] * om[1] + om[2] * om[2]);
    let half = 0.5 * h * a;
    let small = libm::fabs(half) < 1e-8;
    let s = if small {
        0.5 * h * (1.0 - half * half / 6.0)
    } else {
        Scalar::sin(half) / a
    };
    let c = Scalar::cos(half);
    let k = if small {
        -h * h * h / 24.0
    } else {
        (0.5 * h * c - s) / (a * a)
    };
    let e = [s * om[0], s * om[1], s * om[2], c];
    let de = core::array::from_fn(|r| {
        core::array::from_fn(|j| {
            if r == 3 {
                -0.5 * h * s * om[j]
            } else {
                let diag = if r == j { s } else { 0.0 };
                diag + k * om[r] * om[j]
            }
        })
    });
    (e, de)
}

/// `∂(q ⊗ e)/∂q` (4 × 4) for quaternions `[x, y, z, w]`: `[e_w 1 − [e_v]×, e_v; −e_vᵀ, e_w]`.
#[must_use]
pub fn right_product_matrix(e: &[f64; 4]) -> [[f64; 4]; 4] {
    let (ev, ew) = ([e[0], e[1], e[2]], e[3]);
    let se = skew(&ev);
    core::array::from_fn(|r| {
        core::array::from_fn(|c| match (r, c) {
            (3, 3) => ew,
            (3, c) => -ev[c],
            (r, 3) => ev[r],
            (r, c) => (if r == c { ew } else { 0.0 }) - se[r][c],
        })
    })
}

/// `∂(q ⊗ e)/∂e` (4 × 4) for quaternions `[x, y, z, w]`: `[q_w 1 + [q_v]×, q_v; −q_vᵀ, q_w]`.
#[must_use]
pub fn left_product_matrix(q: &[f64; 4]) -> [[f64; 4]; 4] {
    let (qv, qw) = ([q[0], q[1], q[2]], q[3]);
    let sq = skew(&qv);
    core::array::from_fn(|r| {
        core::array::from_fn(|c| match (r, c) {
            (3, 3) => qw,
            (3, c) => -qv[c],
            (r, 3) => qv[r],
            (r, c) => (if r == c { qw } else { 0.0 }) + sq[r][c],
        })
    })
}

/// `a × b`.
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `[a]×`, the matrix of `b ↦ a × b`.
pub(crate) fn skew(a: &[f64; 3]) -> [[f64; 3]; 3] {
    [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]]
}

#[cfg(test)]
mod tests {
    //! The Jacobians here against central differences of the formulas they differentiate, and
    //! the tangent maps against each other.

    use super::*;

    /// `(R(quat) v, R(quat)ᵀ v)` by [`quat_to_matrix`].
    fn rotated(quat: &[f64; 4], v: &[f64; 3]) -> ([f64; 3], [f64; 3]) {
        let r = quat_to_matrix(quat);
        (
            core::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2]),
            core::array::from_fn(|i| r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2]),
        )
    }

    #[test]
    fn rotation_jacobian_matches_central_differences() {
        // Not a unit quaternion: the RK4 stages are not either.
        let (quat, v) = ([0.3, -0.5, 0.2, 0.9], [1.5, -0.7, 2.2]);
        for transpose in [false, true] {
            let j = rotation_jacobian(&quat, &v, transpose);
            for c in 0..4 {
                let e = 1e-6;
                let (mut p, mut m) = (quat, quat);
                p[c] += e;
                m[c] -= e;
                let pick = |q: &[f64; 4]| {
                    let (a, b) = rotated(q, &v);
                    if transpose {
                        b
                    } else {
                        a
                    }
                };
                let (fp, fm) = (pick(&p), pick(&m));
                for r in 0..3 {
                    let d = (fp[r] - fm[r]) / (2.0 * e);
                    assert!(
                        (d - j[r][c]).abs() < 1e-8,
                        "{transpose} {r} {c}: {d} {}",
                        j[r][c]
                    );
                }
            }
        }
    }

    /// At a unit quaternion the tangent coordinates of the tangent directions are the identity.
    #[test]
    fn tangent_out_inverts_tangent_in() {
        const D: usize = 13 + 2 * 2;
        let d = D;
        let mut x: [f64; D] = core::array::from_fn(|i| 0.1 * i as f64 - 0.4);
        x[3..7].copy_from_slice(&[0.1, -0.2, 0.3, 0.9]);
        normalize_quaternion(&mut x);
        let (mut tin, mut tout) = ([0.0; D * (D - 1)], [0.0; (D - 1) * D]);
        floating_tangent_in(&x, &mut tin);
        floating_tangent_out(&x, &mut tout);
        for i in 0..d - 1 {
            for j in 0..d - 1 {
                let s: f64 = (0..d).map(|k| tout[i * d + k] * tin[k * (d - 1) + j]).sum();
                let want = f64::from(u8::from(i == j));
                assert!((s - want).abs() < 1e-15, "{i} {j}: {s}");
            }
        }
    }

    /// `q ⊗ E(h, ω)` against central differences in `q` and `ω`, by the two product matrices
    /// and `∂E/∂ω`, at an ordinary and at a tiny `ω` (the series branch).
    #[test]
    fn exp_map_jacobians_match_central_differences() {
        let q = [0.3, -0.2, 0.4, 0.8];
        let h = 0.05;
        for om in [[0.7, -1.1, 0.4], [1e-9, -2e-9, 5e-10]] {
            let (e, de) = exp_map_jacobian(h, &om);
            let (rq, lq) = (right_product_matrix(&e), left_product_matrix(&q));
            let prod = |q: [f64; 4], om: [f64; 3]| {
                let x = [
                    0.0, 0.0, 0.0, q[0], q[1], q[2], q[3], 0.0, 0.0, 0.0, om[0], om[1], om[2],
                ];
                let mut out = [0.0; 13];
                advance_floating(&x, h, &x, &[0.0; 13], &mut out);
                [out[3], out[4], out[5], out[6]]
            };
            let eps = 1e-6;
            for c in 0..7 {
                let (mut qp, mut qm, mut op, mut omm) = (q, q, om, om);
                if c < 4 {
                    qp[c] += eps;
                    qm[c] -= eps;
                } else {
                    op[c - 4] += eps;
                    omm[c - 4] -= eps;
                }
                let (fp, fm) = (prod(qp, op), prod(qm, omm));
                for r in 0..4 {
                    let d = (fp[r] - fm[r]) / (2.0 * eps);
                    let exact = if c < 4 {
                        rq[r][c]
                    } else {
                        (0..4).map(|k| lq[r][k] * de[k][c - 4]).sum::<f64>()
                    };
                    assert!((d - exact).abs() < 1e-9, "{om:?} {r} {c}: {d} {exact}");
                }
            }
        }
    }

    /// `floating_difference(x, ·)` has the derivative `floating_tangent_out(x)` at `x`, and
    /// `floating_difference(x, x) = 0`.
    #[test]
    fn difference_is_the_tangent_chart() {
        const D: usize = 15;
        let mut x: [f64; D] = core::array::from_fn(|i| 0.2 * i as f64 - 0.7);
        x[3..7].copy_from_slice(&[0.3, 0.1, -0.2, 0.9]);
        normalize_quaternion(&mut x);
        let mut zero = [1.0; D - 1];
        floating_difference(&x, &x, &mut zero);
        assert!(zero.iter().all(|z| z.abs() < 1e-16), "{zero:?}");
        let mut m = [0.0; (D - 1) * D];
        floating_tangent_out(&x, &mut m);
        let e = 1e-6;
        for c in 0..D {
            let (mut p, mut n) = (x, x);
            p[c] += e;
            n[c] -= e;
            let (mut dp, mut dn) = ([0.0; D - 1], [0.0; D - 1]);
            floating_difference(&x, &p, &mut dp);
            floating_difference(&x, &n, &mut dn);
            for r in 0..D - 1 {
                let d = (dp[r] - dn[r]) / (2.0 * e);
                assert!(
                    (d - m[r * D + c]).abs() < 1e-9,
                    "{r} {c}: {d} {}",
                    m[r * D + c]
                );
            }
        }
    }

    /// The tangent coordinates see a rotation of the new state's quaternion, not its length.
    #[test]
    fn tangent_out_ignores_the_length() {
        let d = 13;
        let mut r = [0.0; 13];
        r[3..7].copy_from_slice(&[0.2, 0.1, -0.4, 1.3]);
        let mut m = [0.0; 12 * 13];
        floating_tangent_out(&r, &mut m);
        for i in 3..6 {
            let radial: f64 = (3..7).map(|k| m[i * d + k] * r[k]).sum();
            assert!(radial.abs() < 1e-15, "{radial}");
        }
    }
}
