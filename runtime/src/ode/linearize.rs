//! The Jacobians of one integrator step, `x⁺ = Φ(t, x, u)`: `A = ∂x⁺/∂x` and `B = ∂x⁺/∂u`,
//! what a model-predictive controller, iLQR/DDP or an extended Kalman filter linearizes about.
//!
//! They are exact for the scheme (the chain rule through its stages, not a finite difference),
//! from the Jacobians `F = ∂f/∂x`, `G = ∂f/∂u` of the right-hand side `ẋ = f(t, x, u)` at the
//! stage points ([`ControlledSystem::jacobians`]):
//!
//! - [`rk4_step_jacobians`], classical RK4 (HNW I, Table 1.2) with stages `k₁ = f(x)`,
//!   `k₂ = f(x + h/2 k₁)`, `k₃ = f(x + h/2 k₂)`, `k₄ = f(x + h k₃)`:
//!   `∂k₁ = F₁`, `∂k_i = F_i (I + c_i ∂k_{i−1})` (`c = h/2, h/2, h`), the `u` columns with
//!   `G_i + c_i F_i ∂_u k_{i−1}`, and `A = I + h/6 (∂k₁ + 2∂k₂ + 2∂k₃ + ∂k₄)`, `B` alike.
//! - [`midpoint_step_jacobians`], the implicit midpoint rule `x_m = x + h/2 f(x_m)`,
//!   `x⁺ = 2 x_m − x`: differentiating the (solved) implicit equation,
//!   `(I − h/2 F) ∂x_m = ∂x + h/2 G ∂u`, so `A = 2 (I − h/2 F)⁻¹ − I` and
//!   `B = h (I − h/2 F)⁻¹ G` with `F`, `G` at the midpoint.
//!
//! - [`floating_rk4_step_jacobians`], the RK4 step of a free-floating state
//!   `[p₀, quat, q, v_b, ω_b, q̇]` (the quaternion advanced additively, then renormalized, as
//!   [`rk4_step`](super::rk4_step) with the projection of a free-floating scene does it), with
//!   `A` and `B` in the tangent space of Pinocchio's `integrate`/`difference`
//!   (`d − 1` directions, the base's `[δp; δθ]` in base coordinates): the additive Jacobians
//!   of the step over the quaternion's four numbers, between the state's tangent directions
//!   and the tangent coordinates of the renormalized new state
//!   ([`floating_tangent_in`], [`floating_tangent_out`]): `A = T_out A₄ T_in`, `B = T_out B₄`.
//!
//! [`rk4_step_jacobians`] and [`midpoint_step_jacobians`] take additive states. The new state
//! is the one [`rk4_step`](super::rk4_step) and [`midpoint_step`](super::midpoint_step) give
//! for the same input (projected, for a free-floating state), bit for bit.
//! Matrices are row-major slices: `A` is `d × d`, `B` is `d × m` (`d − 1` rows and columns for
//! a free-floating state).

// Index loops over matrix entries.
#![allow(clippy::needless_range_loop)]

use super::lu::{lu_factor, lu_solve};
use super::quaternion::{
    exp_map_jacobian, floating_tangent_in, floating_tangent_out, left_product_matrix,
    normalize_quaternion, right_product_matrix,
};
use super::{midpoint, non_finite, Scratch, Stats, Stop, System};

/// A first-order system with inputs, `ẋ = f(t, x, u)`, and its Jacobians.
pub trait ControlledSystem {
    /// Dimension `d` of the state.
    fn dim(&self) -> usize;
    /// Number `m` of inputs.
    fn inputs(&self) -> usize;
    /// Writes `f(t, x, u)` into `dx`.
    fn deriv(&mut self, t: f64, x: &[f64], u: &[f64], dx: &mut [f64]);
    /// Writes `f(t, x, u)` into `dx` (the value [`ControlledSystem::deriv`] gives), `∂f/∂x`
    /// into `fx` (`d × d`, row-major) and `∂f/∂u` into `fu` (`d × m`).
    fn jacobians(
        &mut self,
        t: f64,
        x: &[f64],
        u: &[f64],
        dx: &mut [f64],
        fx: &mut [f64],
        fu: &mut [f64],
    );
}

/// The scratch floats of [`rk4_step_jacobians`] for `d` states and `m` inputs: the stage point,
/// the four stages, and three pairs of `(d × d, d × m)` matrices.
#[must_use]
pub const fn rk4_scratch_len(d: usize, m: usize) -> usize {
    5 * d + 3 * (d * d + d * m)
}

/// The scratch floats of [`midpoint_step_jacobians`] for `d` states and `m` inputs (the
/// step's own, the start and the midpoint, `F`, `G` and a column); [`midpoint_pivots`] pivots.
#[must_use]
pub const fn midpoint_scratch_len(d: usize, m: usize) -> usize {
    midpoint::scratch_len(d) + 3 * d + d * d + d * m
}

/// The pivots of [`midpoint_step_jacobians`]: `d`.
#[must_use]
pub const fn midpoint_pivots(d: usize) -> usize {
    d
}

/// `Ok` when `x`, `u`, `a`, `b` have the lengths of the system's `d`, `m`.
fn check<S: ControlledSystem + ?Sized>(
    sys: &S,
    t: f64,
    x: &[f64],
    u: &[f64],
    a: &[f64],
    b: &[f64],
) -> Result<(usize, usize), Stop> {
    let (d, m) = (sys.dim(), sys.inputs());
    if x.len() != d || u.len() != m || a.len() != d * d || b.len() != d * m {
        return Err(Stop::Invalid {
            t,
            what: "the state, input or Jacobian lengths do not match the system's dimensions",
        });
    }
    Ok((d, m))
}

/// `out = base + c · F · X` for `F` (`d × d`) and `X` (`d × cols`), all row-major ([`matmul`],
/// then the affine part row by row).
fn affine_product(out: &mut [f64], base: &[f64], c: f64, f: &[f64], x: &[f64], cols: usize) {
    let d = out.len() / cols.max(1);
    matmul(out, f, x, (d, d, cols));
    for (o, b) in out.iter_mut().zip(base) {
        *o = b + c * *o;
    }
}

/// One RK4 step of size `h` from `(t, x)` under the held input `u`, in place, with its
/// Jacobians `A = ∂x⁺/∂x` (`d × d`) and `B = ∂x⁺/∂u` (`d × m`) (module doc). `scratch`: at
/// least [`rk4_scratch_len`]`(d, m)` floats. Four evaluations of the Jacobians.
///
/// # Errors
/// [`Stop::NonFinite`] at `t + h` when the new state is not finite (`x` unchanged),
/// [`Stop::Invalid`] for lengths that do not match or too little scratch.
#[allow(clippy::too_many_arguments)]
pub fn rk4_step_jacobians<S: ControlledSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    u: &[f64],
    a: &mut [f64],
    b: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
) -> Result<Stats, Stop> {
    let (d, m) = check(sys, t, x, u, a, b)?;
    let (work, _) = super::take(scratch, t, rk4_scratch_len(d, m), 0)?;
    let (xs, work) = work.split_at_mut(d);
    let (k, work) = work.split_at_mut(4 * d);
    let (f, work) = work.split_at_mut(d * d);
    let (g, work) = work.split_at_mut(d * m);
    let (mut dk, work) = work.split_at_mut(d * d);
    let (mut ek, work) = work.split_at_mut(d * m);
    let (mut dn, en) = work.split_at_mut(d * d);
    let mut en = &mut en[..d * m];
    a.fill(0.0);
    for i in 0..d {
        a[i * d + i] = 1.0;
    }
    b.fill(0.0);
    // (time offset, stage-point coefficient of the previous stage, weight) of each stage.
    let stages = [(0.0, 0.0, h / 6.0), (0.5 * h, 0.5 * h, h / 3.0)];
    let stages = [stages[0], stages[1], stages[1], (h, h, h / 6.0)];
    for (s, &(dt, c, w)) in stages.iter().enumerate() {
        let (done, rest) = k.split_at_mut(s * d);
        let ks = &mut rest[..d];
        if s == 0 {
            xs.copy_from_slice(x);
        } else {
            let prev = &done[(s - 1) * d..];
            for ((o, xi), ki) in xs.iter_mut().zip(x.iter()).zip(prev) {
                *o = xi + c * ki;
            }
        }
        sys.jacobians(t + dt, xs, u, ks, f, g);
        if s == 0 {
            dk.copy_from_slice(f);
            ek.copy_from_slice(g);
        } else {
            affine_product(dn, f, c, f, dk, d);
            affine_product(en, g, c, f, ek, m);
            core::mem::swap(&mut dk, &mut dn);
            core::mem::swap(&mut ek, &mut en);
        }
        for (ai, di) in a.iter_mut().zip(dk.iter()) {
            *ai += w * di;
        }
        for (bi, ei) in b.iter_mut().zip(ek.iter()) {
            *bi += w * ei;
        }
    }
    // The new state, as `rk4_step` forms it.
    let (h6, h3) = (h / 6.0, h / 3.0);
    let (k1, rest) = k.split_at(d);
    let (k2, rest) = rest.split_at(d);
    let (k3, k4) = rest.split_at(d);
    for i in 0..d {
        xs[i] = x[i] + (h6 * k1[i] + h3 * k2[i] + h3 * k3[i] + h6 * k4[i]);
    }
    let stats = Stats {
        steps: 1,
        rejected_steps: 0,
        evals: 4,
    };
    accept(t + h, x, xs, stats)
}

/// The scratch floats of [`floating_rk4_step_jacobians`] for a free-floating state of `d`
/// numbers and `m` inputs: [`rk4_scratch_len`]`(d, m)`, the additive `A₄`, `B₄`, the two
/// tangent maps and one product.
#[must_use]
pub const fn floating_rk4_scratch_len(d: usize, m: usize) -> usize {
    rk4_scratch_len(d, m) + d * d + d * m + 3 * d * (d - 1)
}

/// One RK4 step of size `h` of a free-floating state `x = [p₀, quat, q, v_b, ω_b, q̇]` (`d ≥ 13`
/// numbers) under the held input `u`, in place and renormalized (as `rk4_step` with the
/// projection of a free-floating scene), with its Jacobians in the tangent space (module doc):
/// `A` (`(d − 1) × (d − 1)`) and `B` (`(d − 1) × m`). `x` holds a unit quaternion. `scratch`:
/// at least [`floating_rk4_scratch_len`]`(d, m)` floats. Four evaluations of the Jacobians.
///
/// # Errors
/// [`Stop::NonFinite`] at `t + h` when the new state is not finite (`x` unchanged),
/// [`Stop::Invalid`] for a state that is not free-floating, lengths that do not match or too
/// little scratch.
#[allow(clippy::too_many_arguments)]
pub fn floating_rk4_step_jacobians<S: ControlledSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    u: &[f64],
    a: &mut [f64],
    b: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
) -> Result<Stats, Stop> {
    let (d, m, tn) = check_floating(sys, t, x, u, a, b)?;
    let (work, _) = super::take(scratch, t, floating_rk4_scratch_len(d, m), 0)?;
    let (step_work, work) = work.split_at_mut(rk4_scratch_len(d, m));
    let (a4, work) = work.split_at_mut(d * d);
    let (b4, work) = work.split_at_mut(d * m);
    let (t_in, work) = work.split_at_mut(d * tn);
    let (t_out, prod) = work.split_at_mut(tn * d);
    floating_tangent_in(x, t_in);
    let stats = rk4_step_jacobians(sys, t, h, x, u, a4, b4, &mut Slices(step_work))?;
    floating_tangent_out(x, t_out);
    normalize_quaternion(x);
    // A = T_out (A₄ T_in), B = T_out B₄.
    matmul(&mut prod[..d * tn], a4, t_in, (d, d, tn));
    matmul(a, t_out, &prod[..d * tn], (tn, d, tn));
    matmul(b, t_out, b4, (tn, d, m));
    Ok(stats)
}

/// `Ok((d, m, d − 1))` when the system's state is free-floating (`d = 13 + 2N` numbers) and `x`,
/// `u`, `a`, `b` have the lengths of it, its `m` inputs and its tangent space.
fn check_floating<S: ControlledSystem + ?Sized>(
    sys: &S,
    t: f64,
    x: &[f64],
    u: &[f64],
    a: &[f64],
    b: &[f64],
) -> Result<(usize, usize, usize), Stop> {
    let (d, m) = (sys.dim(), sys.inputs());
    let tn = d.saturating_sub(1);
    let lengths = x.len() == d && u.len() == m && a.len() == tn * tn && b.len() == tn * m;
    if d < 13 || (d - 13) % 2 != 0 || !lengths {
        return Err(Stop::Invalid {
            t,
            what: "a free-floating state of 13 + 2N numbers, with matching input and Jacobian (tangent space) lengths",
        });
    }
    Ok((d, m, tn))
}

/// `out = P Q` for `P` (`r × k`) and `Q` (`k × c`), row-major: each row of `out` the sum over
/// `l` of `P[i][l]` times row `l` of `Q` (contiguous rows, which the compiler vectorizes), the
/// zeros of `P` skipped (the right-hand side's Jacobians and the tangent maps are mostly zeros).
/// Each entry is summed in the order of `l`, as the dot product of row and column would be.
fn matmul(out: &mut [f64], p: &[f64], q: &[f64], (r, k, c): (usize, usize, usize)) {
    for (prow, orow) in p.chunks_exact(k).zip(out.chunks_exact_mut(c)).take(r) {
        orow.fill(0.0);
        for (pil, qrow) in prow.iter().zip(q.chunks_exact(c)) {
            if *pil != 0.0 {
                for (o, qv) in orow.iter_mut().zip(qrow) {
                    *o += pil * qv;
                }
            }
        }
    }
}

/// `x` takes `new` when it is finite.
fn accept(t: f64, x: &mut [f64], new: &[f64], stats: Stats) -> Result<Stats, Stop> {
    if let Some(index) = non_finite(new) {
        return Err(Stop::NonFinite { t, index, stats });
    }
    x.copy_from_slice(new);
    Ok(stats)
}

/// A [`ControlledSystem`] with its input held, as a [`System`] (for the midpoint step), with
/// the exponential-map update of a free-floating state when `floating`.
struct Held<'a, S: ?Sized> {
    sys: &'a mut S,
    u: &'a [f64],
    floating: bool,
}

impl<S: ControlledSystem + ?Sized> System for Held<'_, S> {
    fn dim(&self) -> usize {
        self.sys.dim()
    }

    fn deriv(&mut self, t: f64, x: &[f64], dx: &mut [f64]) {
        self.sys.deriv(t, x, self.u, dx);
    }

    fn advance(&self, x: &[f64], h: f64, at: &[f64], f: &[f64], out: &mut [f64]) {
        if self.floating {
            super::quaternion::advance_floating(x, h, at, f, out);
        } else {
            super::quaternion::advance_additive(x, h, f, out);
        }
    }
}

/// One implicit midpoint step of size `h` from `(t, x)` under the held input `u`, in place
/// (exactly [`midpoint_step`](super::midpoint_step) of `f(·, ·, u)`), with its Jacobians
/// `A` (`d × d`) and `B` (`d × m`) at the solved midpoint (module doc). `scratch`: at least
/// [`midpoint_scratch_len`]`(d, m)` floats and [`midpoint_pivots`]`(d)` pivots.
///
/// # Errors
/// The step's [`Stop`] (`x` unchanged); [`Stop::NonFinite`] when `I − h/2 F` is singular or
/// not finite; [`Stop::Invalid`] for lengths that do not match or too little scratch.
#[allow(clippy::too_many_arguments)]
pub fn midpoint_step_jacobians<S: ControlledSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    u: &[f64],
    a: &mut [f64],
    b: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
) -> Result<Stats, Stop> {
    let (d, m) = check(sys, t, x, u, a, b)?;
    let floats = midpoint_scratch_len(d, m);
    let (work, piv) = super::take(scratch, t, floats, midpoint_pivots(d))?;
    let (step_work, work) = work.split_at_mut(midpoint::scratch_len(d));
    let (x0, work) = work.split_at_mut(d);
    let (xm, work) = work.split_at_mut(d);
    let (col, work) = work.split_at_mut(d);
    let (f, g) = work.split_at_mut(d * d);
    x0.copy_from_slice(x);
    let mut step_scratch = Slices(step_work);
    let mut held = Held {
        sys: &mut *sys,
        u,
        floating: false,
    };
    let stats = midpoint::midpoint_step(&mut held, t, h, x, &mut step_scratch)?;
    // The midpoint the step solved for: x_m = (x + x⁺)/2.
    for i in 0..d {
        xm[i] = 0.5 * (x0[i] + x[i]);
    }
    sys.jacobians(t + 0.5 * h, xm, u, col, f, g);
    // K = I − h/2 F, factored in place.
    for i in 0..d {
        for j in 0..d {
            f[i * d + j] = f64::from(u8::from(i == j)) - 0.5 * h * f[i * d + j];
        }
    }
    if !lu_factor(f, piv, d) {
        x.copy_from_slice(x0);
        let index = non_finite(f).unwrap_or(0);
        return Err(Stop::NonFinite { t, index, stats });
    }
    // A = 2 K⁻¹ − I, column by column.
    for j in 0..d {
        col.fill(0.0);
        col[j] = 1.0;
        lu_solve(f, piv, col, d);
        for i in 0..d {
            a[i * d + j] = 2.0 * col[i] - f64::from(u8::from(i == j));
        }
    }
    // B = h K⁻¹ G, column by column.
    for gi in g.iter_mut() {
        *gi *= h;
    }
    solve_columns(f, piv, g, b, col, m);
    Ok(stats)
}

/// The scratch floats of [`floating_midpoint_step_jacobians`] for a free-floating state of `d`
/// numbers and `m` inputs; [`midpoint_pivots`]`(d)` pivots.
#[must_use]
pub const fn floating_midpoint_scratch_len(d: usize, m: usize) -> usize {
    midpoint::scratch_len(d) + 3 * d + 2 * d * d + 2 * d * m + 5 * d * (d - 1) + d * m
}

/// One implicit midpoint step of size `h` of a free-floating state `x = [p₀, quat, q, v_b, ω_b,
/// q̇]` (`d = 13 + 2N` numbers) under the held input `u`, in place (exactly
/// [`midpoint_step`](super::midpoint_step) of `f(·, ·, u)` with the exponential-map update of
/// the quaternion, [`advance_floating`](super::quaternion::advance_floating)), with its
/// Jacobians in the tangent space (`A`: `(d − 1)²`, `B`: `(d − 1) × m`, as
/// [`floating_rk4_step_jacobians`]). The step is `x_m = Ψ_{h/2}(x, x_m)`,
/// `x⁺ = Ψ_h(x, x_m)` with `Ψ_c(x, y)` additive `x + c f(y)` but for the quaternion,
/// `quat ⊗ E(c, ω(y))`; differentiating the solved equation over the quaternion's four numbers,
/// `(1 − ∂_y Ψ_{h/2}) ∂x_m = ∂_x Ψ_{h/2} ∂x + ∂_u Ψ_{h/2} ∂u` and
/// `∂x⁺ = ∂_x Ψ_h ∂x + ∂_y Ψ_h ∂x_m + ∂_u Ψ_h ∂u`, where `∂_y Ψ_c` is `c F` on the additive rows
/// and `∂(quat ⊗ E)/∂E · ∂E/∂ω` on the quaternion's ([`exp_map_jacobian`]), and `∂_x Ψ_c` the
/// identity but for `∂(quat ⊗ E)/∂quat`; then the tangent maps at `x` and `x⁺`
/// ([`floating_tangent_in`], [`floating_tangent_out`]). `scratch`: at least
/// [`floating_midpoint_scratch_len`]`(d, m)` floats and [`midpoint_pivots`]`(d)` pivots.
///
/// # Errors
/// The step's [`Stop`] (`x` unchanged); [`Stop::NonFinite`] when `1 − ∂_y Ψ_{h/2}` is singular
/// or not finite; [`Stop::Invalid`] for a state that is not free-floating, lengths that do not
/// match or too little scratch.
///
/// [`exp_map_jacobian`]: super::quaternion::exp_map_jacobian
#[allow(clippy::too_many_arguments, clippy::many_single_char_names)]
pub fn floating_midpoint_step_jacobians<S: ControlledSystem + ?Sized>(
    sys: &mut S,
    t: f64,
    h: f64,
    x: &mut [f64],
    u: &[f64],
    a: &mut [f64],
    b: &mut [f64],
    scratch: &mut (impl Scratch + ?Sized),
) -> Result<Stats, Stop> {
    let (d, m, tn) = check_floating(sys, t, x, u, a, b)?;
    // ω_b, the speeds the quaternion turns with.
    let w0 = 10 + (d - 13) / 2;
    let floats = floating_midpoint_scratch_len(d, m);
    let (work, piv) = super::take(scratch, t, floats, midpoint_pivots(d))?;
    let (step_work, work) = work.split_at_mut(midpoint::scratch_len(d));
    let (x0, work) = work.split_at_mut(d);
    let (xm, work) = work.split_at_mut(d);
    let (col, work) = work.split_at_mut(d);
    let (f, work) = work.split_at_mut(d * d);
    let (k, work) = work.split_at_mut(d * d);
    let (g, work) = work.split_at_mut(d * m);
    let (wm, work) = work.split_at_mut(d * m);
    let (dup, work) = work.split_at_mut(d * m);
    let (t_in, work) = work.split_at_mut(d * tn);
    let (t_out, work) = work.split_at_mut(tn * d);
    let (z, work) = work.split_at_mut(d * tn);
    let (dxp, work) = work.split_at_mut(d * tn);
    let psi = &mut work[..d * tn];
    x0.copy_from_slice(x);
    floating_tangent_in(x0, t_in);
    let mut held = Held {
        sys: &mut *sys,
        u,
        floating: true,
    };
    let stats = midpoint::midpoint_step(&mut held, t, h, x, &mut Slices(step_work))?;
    // The midpoint the step solved for: additive (x + x⁺)/2, the quaternion quat ⊗ E(h/2, ω_m).
    for i in 0..d {
        xm[i] = 0.5 * (x0[i] + x[i]);
    }
    let om = [xm[w0], xm[w0 + 1], xm[w0 + 2]];
    let quat0 = [x0[3], x0[4], x0[5], x0[6]];
    let lq = left_product_matrix(&quat0);
    let (e_half, de_half) = exp_map_jacobian(0.5 * h, &om);
    let (e_full, de_full) = exp_map_jacobian(h, &om);
    for r in 0..4 {
        xm[3 + r] = (0..4).map(|c| lq[r][c] * e_half[c]).sum();
    }
    sys.jacobians(t + 0.5 * h, xm, u, col, f, g);
    // ∂_y Ψ_c on the quaternion rows: ∂(quat ⊗ E)/∂E ∂E/∂ω, at the ω columns.
    let quat_rows = |de: &[[f64; 3]; 4]| -> [[f64; 3]; 4] {
        core::array::from_fn(|r| {
            core::array::from_fn(|j| (0..4).map(|c| lq[r][c] * de[c][j]).sum())
        })
    };
    let (q_half, q_full) = (quat_rows(&de_half), quat_rows(&de_full));
    // K = 1 − ∂_y Ψ_{h/2}, factored in place.
    for i in 0..d {
        for j in 0..d {
            let dy = if (3..7).contains(&i) {
                if (w0..w0 + 3).contains(&j) {
                    q_half[i - 3][j - w0]
                } else {
                    0.0
                }
            } else {
                0.5 * h * f[i * d + j]
            };
            k[i * d + j] = f64::from(u8::from(i == j)) - dy;
        }
    }
    if !lu_factor(k, piv, d) {
        x.copy_from_slice(x0);
        let index = non_finite(k).unwrap_or(0);
        return Err(Stop::NonFinite { t, index, stats });
    }
    // ∂_x Ψ_c T_in: T_in with its quaternion rows turned by ∂(quat ⊗ E)/∂quat.
    let psi_x = |e: &[f64; 4], out: &mut [f64]| {
        out.copy_from_slice(t_in);
        let rq = right_product_matrix(e);
        for r in 0..4 {
            for j in 0..tn {
                out[(3 + r) * tn + j] = (0..4).map(|c| rq[r][c] * t_in[(3 + c) * tn + j]).sum();
            }
        }
    };
    // Z = ∂x_m/∂δ = K⁻¹ ∂_x Ψ_{h/2} T_in, column by column.
    psi_x(&e_half, psi);
    solve_columns(k, piv, psi, z, col, tn);
    // W = ∂x_m/∂u = K⁻¹ (h/2) G (no input on the quaternion rows).
    for i in 0..d {
        for j in 0..m {
            dup[i * m + j] = if (3..7).contains(&i) {
                0.0
            } else {
                0.5 * h * g[i * m + j]
            };
        }
    }
    solve_columns(k, piv, dup, wm, col, m);
    // ∂x⁺ = ∂_x Ψ_h T_in + ∂_y Ψ_h Z, and ∂x⁺/∂u = h G + ∂_y Ψ_h W.
    psi_x(&e_full, dxp);
    let phi_y = |i: usize, src: &[f64], cols: usize, jcol: usize| -> f64 {
        if (3..7).contains(&i) {
            (0..3)
                .map(|l| q_full[i - 3][l] * src[(w0 + l) * cols + jcol])
                .sum()
        } else {
            h * (0..d)
                .map(|l| f[i * d + l] * src[l * cols + jcol])
                .sum::<f64>()
        }
    };
    for i in 0..d {
        for j in 0..tn {
            dxp[i * tn + j] += phi_y(i, z, tn, j);
        }
        for j in 0..m {
            let direct = if (3..7).contains(&i) {
                0.0
            } else {
                h * g[i * m + j]
            };
            dup[i * m + j] = direct + phi_y(i, wm, m, j);
        }
    }
    floating_tangent_out(x, t_out);
    matmul(a, t_out, dxp, (tn, d, tn));
    matmul(b, t_out, dup, (tn, d, m));
    Ok(stats)
}

/// `out = K⁻¹ rhs` column by column (`d × cols`, row-major), `K` LU-factored with `piv`.
fn solve_columns(
    k: &[f64],
    piv: &[usize],
    rhs: &[f64],
    out: &mut [f64],
    col: &mut [f64],
    cols: usize,
) {
    let d = col.len();
    for j in 0..cols {
        for i in 0..d {
            col[i] = rhs[i * cols + j];
        }
        lu_solve(k, piv, col, d);
        for i in 0..d {
            out[i * cols + j] = col[i];
        }
    }
}

/// Scratch over a borrowed slice (the midpoint step's part of the caller's scratch).
struct Slices<'a>(&'a mut [f64]);

impl Scratch for Slices<'_> {
    fn get(&mut self, floats: usize, pivots: usize) -> Option<(&mut [f64], &mut [usize])> {
        if pivots > 0 {
            return None;
        }
        Some((self.0.get_mut(..floats)?, &mut []))
    }
}

#[cfg(test)]
mod tests {
    //! The step Jacobians against central differences of the step itself, on a pendulum with
    //! Coulomb-like friction and a torque input (`f` nonlinear in `x` and time-varying); the new
    //! state against [`rk4_step`](super::super::rk4_step) and
    //! [`midpoint_step`](super::super::midpoint_step).

    use super::*;
    use crate::ode::{midpoint_step, rk4_step, ArrayScratch};

    /// `θ̈ = −sin θ − 0.3 tanh(θ̇) + (1 + 0.5 cos t) u₀ + 0.2 u₁` as `[θ, θ̇]`.
    struct Pendulum;

    impl ControlledSystem for Pendulum {
        fn dim(&self) -> usize {
            2
        }
        fn inputs(&self) -> usize {
            2
        }
        fn deriv(&mut self, t: f64, x: &[f64], u: &[f64], dx: &mut [f64]) {
            dx[0] = x[1];
            dx[1] = -libm::sin(x[0]) - 0.3 * libm::tanh(x[1])
                + (1.0 + 0.5 * libm::cos(t)) * u[0]
                + 0.2 * u[1];
        }
        fn jacobians(
            &mut self,
            t: f64,
            x: &[f64],
            u: &[f64],
            dx: &mut [f64],
            fx: &mut [f64],
            fu: &mut [f64],
        ) {
            self.deriv(t, x, u, dx);
            let th = libm::tanh(x[1]);
            fx.copy_from_slice(&[0.0, 1.0, -libm::cos(x[0]), -0.3 * (1.0 - th * th)]);
            fu.copy_from_slice(&[0.0, 0.0, 1.0 + 0.5 * libm::cos(t), 0.2]);
        }
    }

    type Step = fn(&mut Pendulum, f64, f64, &mut [f64], &[f64], &mut [f64], &mut [f64]) -> Stats;

    fn rk4(
        sys: &mut Pendulum,
        t: f64,
        h: f64,
        x: &mut [f64],
        u: &[f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Stats {
        let mut s = ArrayScratch::<{ rk4_scratch_len(2, 2) }>::new();
        rk4_step_jacobians(sys, t, h, x, u, a, b, &mut s).unwrap()
    }

    fn mid(
        sys: &mut Pendulum,
        t: f64,
        h: f64,
        x: &mut [f64],
        u: &[f64],
        a: &mut [f64],
        b: &mut [f64],
    ) -> Stats {
        let mut s = ArrayScratch::<{ midpoint_scratch_len(2, 2) }, 2>::new();
        midpoint_step_jacobians(sys, t, h, x, u, a, b, &mut s).unwrap()
    }

    /// The largest difference between the step Jacobians and central differences (step `e`
    /// and `2e`), and the differences' own error estimate `|D(e) − D(2e)|`.
    fn check(step: Step) -> (f64, f64) {
        let (t, h, x0, u0) = (0.3, 0.1, [0.7, -1.2], [0.4, -0.9]);
        let (mut a, mut b) = ([0.0; 4], [0.0; 4]);
        let mut x = x0;
        step(&mut Pendulum, t, h, &mut x, &u0, &mut a, &mut b);
        let plus = |dx: [f64; 2], du: [f64; 2]| {
            let mut x = [x0[0] + dx[0], x0[1] + dx[1]];
            let u = [u0[0] + du[0], u0[1] + du[1]];
            step(
                &mut Pendulum,
                t,
                h,
                &mut x,
                &u,
                &mut [0.0; 4],
                &mut [0.0; 4],
            );
            x
        };
        let (mut worst, mut own) = (0.0_f64, 0.0_f64);
        for j in 0..4 {
            let diff = |e: f64| {
                let mut d = [[0.0; 2]; 2];
                d[j / 2][j % 2] = e;
                let (p, m) = (plus(d[0], d[1]), plus(d[0].map(|v| -v), d[1].map(|v| -v)));
                [(p[0] - m[0]) / (2.0 * e), (p[1] - m[1]) / (2.0 * e)]
            };
            let (d1, d2) = (diff(1e-5), diff(2e-5));
            for i in 0..2 {
                let exact = if j < 2 {
                    a[i * 2 + j]
                } else {
                    b[i * 2 + j - 2]
                };
                worst = worst.max(libm::fabs(exact - d1[i]));
                own = own.max(libm::fabs(d1[i] - d2[i]));
            }
        }
        (worst, own)
    }

    #[test]
    fn rk4_jacobians_match_central_differences() {
        let (worst, own) = check(rk4);
        assert!(
            worst < 1e-9 && worst <= 4.0 * own + 1e-10,
            "{worst:e} (differences' own {own:e})"
        );
    }

    #[test]
    fn midpoint_jacobians_match_central_differences() {
        let (worst, own) = check(mid);
        assert!(
            worst < 1e-8 && worst <= 4.0 * own + 1e-9,
            "{worst:e} (differences' own {own:e})"
        );
    }

    /// The new state is the one the plain steps give under the held input, bit for bit.
    #[test]
    fn the_new_state_is_the_steps() {
        let (t, h, u) = (0.3, 0.1, [0.4, -0.9]);
        for (jac, plain) in [(rk4 as Step, true), (mid as Step, false)] {
            let mut x = [0.7, -1.2];
            jac(
                &mut Pendulum,
                t,
                h,
                &mut x,
                &u,
                &mut [0.0; 4],
                &mut [0.0; 4],
            );
            let mut y = [0.7, -1.2];
            let mut held = Held {
                sys: &mut Pendulum,
                u: &u,
                floating: false,
            };
            if plain {
                let mut s = ArrayScratch::<{ crate::ode::rk4::scratch_len(2) }>::new();
                rk4_step(&mut held, t, h, &mut y, &mut s).unwrap();
            } else {
                let mut s = ArrayScratch::<{ midpoint::scratch_len(2) }>::new();
                midpoint_step(&mut held, t, h, &mut y, &mut s).unwrap();
            }
            assert_eq!(x, y);
        }
    }

    #[test]
    fn wrong_lengths_are_refused() {
        let mut x = [0.0; 3];
        let mut s = ArrayScratch::<{ rk4_scratch_len(3, 2) }>::new();
        let r = rk4_step_jacobians(
            &mut Pendulum,
            0.0,
            0.1,
            &mut x,
            &[0.0; 2],
            &mut [0.0; 9],
            &mut [0.0; 6],
            &mut s,
        );
        assert!(matches!(r, Err(Stop::Invalid { .. })));
    }
}
