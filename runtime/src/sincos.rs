//! The sine–cosine of generated `f64` code: [`sincos`] and the batched [`sincos_n`], which every
//! generated type's `Self::sincos` / `Self::sincos_n` forward to, in place of `libm::sincos`.
//!
//! A joint angle's sine and cosine are the first thing every generated function computes, and
//! with `libm` they cost as much as the rest of a 6-dof mass matrix: a call each, and branches on
//! the argument's range and quadrant that a benchmark of random states mispredicts. These are
//! inlined and branch-free on `|x| < 32768` rad:
//!
//! 1. `x = k·π/128 + r`, `|r| ≤ π/256`: `k` rounded by the 1.5·2⁵² shift, `r` by Cody and
//!    Waite's two-part `π/128` (the first part has 32 significant bits, so `k·STEP_HI` is exact for
//!    `|k| < 2²¹`, and `x − k·P1` is exact by Sterbenz' lemma);
//! 2. `sin r`, `cos r` by their Taylor polynomials to `r⁵` and `r⁶`: the first terms left out,
//!    `r⁷/7!` and `r⁸/8!`, are below 8.3e-18 and 1.3e-20 at `|r| = π/256`;
//! 3. `sin(kπ/128)` and `cos(kπ/128) = sin((k + 64)π/128)` from [`SIN_TABLE`], 128 correctly
//!    rounded sines of `[0, π)`, the sign flipped by bit 7 of the index (`sin(a + π) = −sin a`);
//! 4. the angle sums: `sin x = sin a·cos r + cos a·sin r`, `cos x = cos a·cos r − sin a·sin r`.
//!
//! Beyond `|x| < 32768` (and for NaN and infinities) it is `libm::sincos`, a branch a joint
//! angle never takes. Generated functions take all joint angles' in one `sincos_n([q[0], …])` at
//! the top, each step a loop over the angles, which the compiler vectorizes: on SRMS that made
//! `M` 1.2× faster than one `sincos` per angle. The error against `libm::sincos` is measured by
//! `kanegen accuracy` (`docs/accuracy.md`) and bounded by `tests/sincos.rs`: 1 ulp of 1 at most,
//! and 2 ulp of the value wherever it is at least 1/16.
//!
//! The steps are written once, generic over the lane type: [`sincos_n`] is their `f64` case, and
//! `Lanes::sincos_n` of `f64x2`, `f64x4` and `f64x8` ([`crate::lanes`]) runs the same operations on
//! vectors, the table read lane by lane, so each lane is bit for bit [`sincos_n`] of its angles;
//! where some lane's angle is beyond the range (or NaN), each lane runs [`sincos_n`] on its own.
//!
//! [`sincos_n`] fuses its products by [`crate::fma::mul_add`] (one instruction where the build
//! targets FMA, else `a·b + c`); [`sincos_n_unfused`] never fuses (code generated with
//! `fma = true` or `target_fma = false`).
//!
//! ```
//! use kanegen_runtime::sincos::{sincos, sincos_n};
//! assert_eq!(sincos(0.0), (0.0, 1.0));
//! let [(s, c), _] = sincos_n([1.0, 2.0]);
//! assert!((s - libm::sin(1.0)).abs() < 1e-15 && (c - libm::cos(1.0)).abs() < 1e-15);
//! ```

use crate::lanes::{f64x2, f64x4, f64x8, Lanes};

/// `sin(kπ/128)`, `k = 0, …, 127`, correctly rounded (computed in 300-bit arithmetic by
/// `mpmath`; `tests` checks them against `libm::sin` and each other).
#[allow(clippy::approx_constant)] // sin(π/4) and sin(3π/4), written as the table's other entries
pub const SIN_TABLE: [f64; 128] = [
    0.0,
    0.024541228522912288,
    0.049067674327418015,
    0.07356456359966743,
    0.0980171403295606,
    0.1224106751992162,
    0.14673047445536175,
    0.17096188876030122,
    0.19509032201612828,
    0.2191012401568698,
    0.2429801799032639,
    0.26671275747489837,
    0.2902846772544624,
    0.31368174039889146,
    0.33688985339222005,
    0.35989503653498817,
    0.3826834323650898,
    0.40524131400498986,
    0.4275550934302821,
    0.4496113296546066,
    0.47139673682599764,
    0.49289819222978404,
    0.5141027441932218,
    0.5349976198870973,
    0.5555702330196022,
    0.5758081914178453,
    0.5956993044924334,
    0.6152315905806268,
    0.6343932841636455,
    0.6531728429537768,
    0.6715589548470184,
    0.6895405447370669,
    0.7071067811865476,
    0.7242470829514669,
    0.7409511253549591,
    0.7572088465064846,
    0.773010453362737,
    0.7883464276266062,
    0.8032075314806449,
    0.8175848131515837,
    0.8314696123025452,
    0.8448535652497071,
    0.8577286100002721,
    0.8700869911087115,
    0.881921264348355,
    0.8932243011955153,
    0.9039892931234433,
    0.9142097557035307,
    0.9238795325112867,
    0.9329927988347388,
    0.9415440651830208,
    0.9495281805930367,
    0.9569403357322088,
    0.9637760657954398,
    0.970031253194544,
    0.9757021300385286,
    0.9807852804032304,
    0.9852776423889412,
    0.989176509964781,
    0.99247953459871,
    0.9951847266721969,
    0.9972904566786902,
    0.9987954562051724,
    0.9996988186962042,
    1.0,
    0.9996988186962042,
    0.9987954562051724,
    0.9972904566786902,
    0.9951847266721969,
    0.99247953459871,
    0.989176509964781,
    0.9852776423889412,
    0.9807852804032304,
    0.9757021300385286,
    0.970031253194544,
    0.9637760657954398,
    0.9569403357322088,
    0.9495281805930367,
    0.9415440651830208,
    0.9329927988347388,
    0.9238795325112867,
    0.9142097557035307,
    0.9039892931234433,
    0.8932243011955153,
    0.881921264348355,
    0.8700869911087115,
    0.8577286100002721,
    0.8448535652497071,
    0.8314696123025452,
    0.8175848131515837,
    0.8032075314806449,
    0.7883464276266062,
    0.773010453362737,
    0.7572088465064846,
    0.7409511253549591,
    0.7242470829514669,
    0.7071067811865476,
    0.6895405447370669,
    0.6715589548470184,
    0.6531728429537768,
    0.6343932841636455,
    0.6152315905806268,
    0.5956993044924334,
    0.5758081914178453,
    0.5555702330196022,
    0.5349976198870973,
    0.5141027441932218,
    0.49289819222978404,
    0.47139673682599764,
    0.4496113296546066,
    0.4275550934302821,
    0.40524131400498986,
    0.3826834323650898,
    0.35989503653498817,
    0.33688985339222005,
    0.31368174039889146,
    0.2902846772544624,
    0.26671275747489837,
    0.2429801799032639,
    0.2191012401568698,
    0.19509032201612828,
    0.17096188876030122,
    0.14673047445536175,
    0.1224106751992162,
    0.0980171403295606,
    0.07356456359966743,
    0.049067674327418015,
    0.024541228522912288,
];

/// `128/π`: angles to table steps.
pub const STEPS_PER_RAD: f64 = 40.74366543152521;
/// `π/128` to 32 significant bits (`k·STEP_HI` is exact for `|k| < 2²¹`).
pub const STEP_HI: f64 = 0.024543692605220713;
/// `π/128 − STEP_HI` (the two parts sum to `π/128` within 5.5e-29).
pub const STEP_LO: f64 = 9.495469541415925e-13;
/// `1.5·2⁵²`: adding and subtracting it rounds to an integer, whose low bits are left in the
/// sum's mantissa.
pub const ROUND_SHIFT: f64 = 6_755_399_441_055_744.0;
/// The fast path's range: `|x| < LIMIT` (`|k| ≤ 1.34e6 < 2²¹`).
pub const LIMIT: f64 = 32768.0;

/// Taylor coefficient of `r³` in `sin r`: `−1/3!`.
pub const S3: f64 = -1.0 / 6.0;
/// Taylor coefficient of `r⁵` in `sin r`: `1/5!`.
pub const S5: f64 = 1.0 / 120.0;
/// Taylor coefficient of `r²` in `cos r`: `−1/2!`.
pub const C2: f64 = -0.5;
/// Taylor coefficient of `r⁴` in `cos r`: `1/4!`.
pub const C4: f64 = 1.0 / 24.0;
/// Taylor coefficient of `r⁶` in `cos r`: `−1/6!`.
pub const C6: f64 = -1.0 / 720.0;

/// `(sin x, cos x)`: [`sincos_n`] of one angle.
#[inline(always)]
#[must_use]
pub fn sincos(x: f64) -> (f64, f64) {
    let [sc] = sincos_n([x]);
    sc
}

/// `(sin x, cos x)` of `K` angles at once, products fused where the build targets FMA
/// ([`crate::fma::mul_add`]): branch-free and inlined for `|x| < 32768` (the module's steps 1–4),
/// `libm::sincos` for all `K` if one is beyond. Within 1 ulp of 1 of libm's.
#[inline(always)]
#[must_use]
pub fn sincos_n<const K: usize>(x: [f64; K]) -> [(f64, f64); K] {
    chunks::<K, true>(x)
}

/// [`sincos_n`] with every product rounded on its own (`a·b + c`, never fused), for code whose
/// sums are not fused either.
#[inline(always)]
#[must_use]
pub fn sincos_n_unfused<const K: usize>(x: [f64; K]) -> [(f64, f64); K] {
    chunks::<K, false>(x)
}

/// [`lanes`] on all `K` angles at once, or on a target with AVX-512 at most [`CHUNK`] at a time
/// (the last chunk padded with zeros): each angle's result that of `lanes` on all `K` at once,
/// bit for bit, and `libm::sincos` for all of them if any is out of the fast range, as `lanes`
/// does.
///
/// Why chunks: on all `K` angles at once the compiler vectorizes the steps as wide as the target
/// allows, and on an AVX-512 target (`-C target-cpu=native` on a Sapphire Rapids Xeon) a
/// generated function whose sine–cosine ran in 512-bit registers was slowed down whole, not
/// only its sine–cosine: the scalar arithmetic after it ran at half its rate (measured on UR5,
/// side by side: `mass_matrix` 89 → 48 ns, `nonlinear_effects` 96 → 50,
/// `inverse_dynamics_derivatives` 302 → 222, `mass_matrix_inverse` 151 → 92; docs/performance.md).
/// Four `f64` fill a 256-bit register, which every x86-64 vector target runs at full rate.
#[inline(always)]
fn chunks<const K: usize, const FUSE: bool>(x: [f64; K]) -> [(f64, f64); K] {
    if !cfg!(target_feature = "avx512f") || K <= CHUNK {
        return lanes::<f64, K, FUSE>(x);
    }
    in_chunks::<K, FUSE>(x)
}

/// [`chunks`]' chunked path, on any target (tested against [`lanes`] everywhere).
#[inline(always)]
fn in_chunks<const K: usize, const FUSE: bool>(x: [f64; K]) -> [(f64, f64); K] {
    if !<f64 as TableLanes>::within(&x) {
        return <f64 as TableLanes>::beyond::<K, FUSE>(x);
    }
    let mut out = [(0.0, 0.0); K];
    let mut i = 0;
    while i < K {
        let m = (K - i).min(CHUNK);
        let mut chunk = [0.0; CHUNK];
        chunk[..m].copy_from_slice(&x[i..i + m]);
        let r = lanes::<f64, CHUNK, FUSE>(chunk);
        out[i..i + m].copy_from_slice(&r[..m]);
        i += CHUNK;
    }
    out
}

/// The most angles [`chunks`] hands [`lanes`] at once: one 256-bit register of `f64`.
const CHUNK: usize = 4;

/// What steps 1–4 need of a lane type ([`Lanes`]) beyond its arithmetic: the range test, the
/// table lookup and the path beyond the range. Implemented for `f64` (the scalar routine) and
/// `wide`'s `f64x2`, `f64x4` and `f64x8`, whose [`Lanes::sincos_n`] runs the steps as vector arithmetic,
/// each lane bit for bit the scalar routine on that lane's angles.
pub(crate) trait TableLanes: Lanes<f64> {
    /// Whether every lane of every angle is within `(−LIMIT, LIMIT)` (not NaN).
    fn within<const K: usize>(x: &[Self; K]) -> bool;
    /// `(sin(k·π/128), cos(k·π/128))` of each lane, `k` in the low 8 bits of `t`'s lane (the
    /// rounding shift's sum).
    fn table(t: Self) -> (Self, Self);
    /// The sine–cosine where some lane is beyond the range: `libm::sincos` for `f64`, and lane
    /// by lane the scalar routine (fast or not per lane) for vectors.
    fn beyond<const K: usize, const FUSE: bool>(x: [Self; K]) -> [(Self, Self); K];
}

/// `(sin(jπ/128), cos(jπ/128))` of the low 8 bits `j` of `t`'s bits (bit 7 of the index: the
/// half turn, a sign).
#[inline(always)]
fn table_pair(t: f64) -> (f64, f64) {
    let table =
        |j: usize| f64::from_bits(SIN_TABLE[j & 127].to_bits() ^ (((j & 128) as u64) << 56));
    let j = (t.to_bits() & 255) as usize;
    (table(j), table(j + 64))
}

impl TableLanes for f64 {
    #[inline(always)]
    fn within<const K: usize>(x: &[f64; K]) -> bool {
        let mut fast = true;
        for &v in x {
            fast &= v > -LIMIT && v < LIMIT;
        }
        fast
    }
    #[inline(always)]
    fn table(t: f64) -> (f64, f64) {
        table_pair(t)
    }
    #[inline(always)]
    fn beyond<const K: usize, const FUSE: bool>(x: [f64; K]) -> [(f64, f64); K] {
        x.map(libm::sincos)
    }
}

/// [`TableLanes`] of a `wide` vector of `f64`.
macro_rules! table_lanes {
    ($v:ident, $l:literal) => {
        impl TableLanes for $v {
            #[inline(always)]
            fn within<const K: usize>(x: &[$v; K]) -> bool {
                let (lo, hi) = ($v::splat(-LIMIT), $v::splat(LIMIT));
                let mut fast = $v::splat(f64::from_bits(u64::MAX));
                for &v in x {
                    fast = fast & v.simd_gt(lo) & v.simd_lt(hi);
                }
                fast.all()
            }
            #[inline(always)]
            fn table(t: $v) -> ($v, $v) {
                let p = t.to_array().map(table_pair);
                ($v::new(p.map(|p| p.0)), $v::new(p.map(|p| p.1)))
            }
            #[inline(always)]
            fn beyond<const K: usize, const FUSE: bool>(x: [$v; K]) -> [($v, $v); K] {
                crate::lanes::per_lane::<f64, $v, K, $l>(x, lanes::<f64, K, FUSE>)
            }
        }
    };
}

table_lanes!(f64x2, 2);
table_lanes!(f64x4, 4);
table_lanes!(f64x8, 8);

/// `a·b + c`: [`Lanes::mul_add`] (fused as [`crate::fma::mul_add`]) with `FUSE`, two roundings
/// without.
#[inline(always)]
fn ma<S: Lanes<f64>, const FUSE: bool>(a: S, b: S, c: S) -> S {
    if FUSE {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// Steps 1–4 of the module for `K` angles of `S` (one state each lane), products fused by
/// [`ma`]; each step is a loop over the angles, so the compiler runs them side by side in vector
/// registers. The scalar routine is `S = f64`; a vector type's lanes are each that routine.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // the angles' loops are what the compiler vectorizes
pub(crate) fn lanes<S: TableLanes, const K: usize, const FUSE: bool>(x: [S; K]) -> [(S, S); K] {
    // Taylor coefficients of sin r (r³, r⁵) and cos r (r², r⁴, r⁶).
    let c = S::splat;
    let (s3, s5) = (c(S3), c(S5));
    let (c2, c4, c6) = (c(C2), c(C4), c(C6));
    if !S::within(&x) {
        return S::beyond::<K, FUSE>(x);
    }
    // 1. x = k·π/128 + r, |r| ≤ π/256: k rounded by the 1.5·2⁵² shift, r by Cody and Waite's
    // two-part π/128.
    let (shift, steps, hi, lo) = (c(ROUND_SHIFT), c(STEPS_PER_RAD), c(STEP_HI), c(STEP_LO));
    let (mut t, mut r) = ([c(0.0); K], [c(0.0); K]);
    for i in 0..K {
        t[i] = ma::<S, FUSE>(x[i], steps, shift);
        let k = t[i] - shift;
        let r_hi = ma::<S, FUSE>(k.neg(), hi, x[i]);
        r[i] = ma::<S, FUSE>(k.neg(), lo, r_hi);
    }
    // 2. sin r and cos r by their Taylor polynomials.
    let (mut sin_r, mut cos_r) = ([c(0.0); K], [c(0.0); K]);
    for i in 0..K {
        let r2 = r[i] * r[i];
        let r3 = r[i] * r2;
        let p_s = ma::<S, FUSE>(r2, s5, s3);
        sin_r[i] = ma::<S, FUSE>(r3, p_s, r[i]);
        let p_c6 = ma::<S, FUSE>(r2, c6, c4);
        let p_c = ma::<S, FUSE>(r2, p_c6, c2);
        cos_r[i] = ma::<S, FUSE>(r2, p_c, c(1.0));
    }
    // 3. sin and cos of k·π/128; 4. the angle sums.
    let mut out = [(c(0.0), c(0.0)); K];
    for i in 0..K {
        let (sin_a, cos_a) = S::table(t[i]);
        out[i] = (
            ma::<S, FUSE>(sin_a, cos_r[i], cos_a * sin_r[i]),
            ma::<S, FUSE>(cos_a, cos_r[i], (sin_a * sin_r[i]).neg()),
        )
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table against libm's `sin` at the rounded angle, corrected by the rounding
    /// (`sin(a + e) ≈ sin a + e·cos a`): within 1 ulp each; exactly symmetric about π/2.
    #[test]
    fn table_holds_the_sines() {
        for (k, &v) in SIN_TABLE.iter().enumerate() {
            let kf = k as f64;
            let a = kf * core::f64::consts::PI / 128.0;
            let e = (kf * STEP_HI - a) + kf * STEP_LO;
            let want = libm::sin(a) + e * libm::cos(a);
            let ulp = f64::EPSILON * want.abs().max(f64::MIN_POSITIVE);
            assert!((v - want).abs() <= ulp, "k = {k}: {v} against {want}");
            if k > 0 {
                assert_eq!(v.to_bits(), SIN_TABLE[128 - k].to_bits(), "k = {k}");
            }
        }
        assert_eq!(SIN_TABLE[0], 0.0);
        assert_eq!(SIN_TABLE[64], 1.0);
    }

    /// The two parts of π/128: the first has 32 significant bits, the sum is π/128.
    /// The chunked path equals all angles at once bit for bit, fused and unfused, for every
    /// count of angles across the chunk boundaries, and falls back to libm for all of them when
    /// one is out of range.
    #[test]
    fn chunks_equal_all_at_once() {
        fn check<const K: usize>(x: [f64; K]) {
            let bits = |r: [(f64, f64); K]| r.map(|(s, c)| (s.to_bits(), c.to_bits()));
            assert_eq!(
                bits(in_chunks::<K, true>(x)),
                bits(lanes::<f64, K, true>(x)),
                "{x:?}"
            );
            assert_eq!(
                bits(in_chunks::<K, false>(x)),
                bits(lanes::<f64, K, false>(x)),
                "{x:?}"
            );
        }
        let x: [f64; 13] = core::array::from_fn(|i| (i as f64 * 1.37 - 6.0) * 0.9);
        check::<1>([x[0]]);
        check::<4>([x[0], x[1], x[2], x[3]]);
        check::<5>([x[0], x[1], x[2], x[3], x[4]]);
        check::<8>(core::array::from_fn(|i| x[i]));
        check::<13>(x);
        let mut far = x;
        far[9] = 4.0e5;
        check::<13>(far);
        assert_eq!(in_chunks::<13, true>(far)[9], libm::sincos(4.0e5));
        assert_eq!(in_chunks::<13, true>(far)[0], libm::sincos(far[0]));
    }

    #[test]
    fn step_split() {
        assert_eq!(STEP_HI.to_bits() & ((1 << 21) - 1), 0);
        assert!(((STEP_HI + STEP_LO) - core::f64::consts::PI / 128.0).abs() < 1e-18);
        assert!((STEPS_PER_RAD * (STEP_HI + STEP_LO) - 1.0).abs() < 2.0 * f64::EPSILON);
        assert!(LIMIT * STEPS_PER_RAD < f64::from(1u32 << 21));
    }
}
