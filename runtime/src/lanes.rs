//! Lanes: `L` states at once on SIMD vector types, from one body of generated code.
//!
//! Every straight-line function `NAME` of a generated type has a twin `NAME_lanes<S:
//! Lanes<F>>` (`F`: the generated code's `f64` or `f32`) with the same arguments and results
//! over `S` in place of `F`: the scalar function is its instantiation at `S = F`, and on a
//! vector type (`wide::f64x4`: four `f64` states side by side) each lane computes exactly what
//! the scalar function computes for that lane's state, bit for bit. [`Lanes`] is what the body
//! needs of `S`: arithmetic, constants ([`Lanes::splat`]), the generated code's fused
//! multiply-adds, square roots and sines and cosines, each applied lane by lane with the scalar
//! routine's rounding: the table sine–cosine of `f64` code ([`crate::sincos`]) is one routine,
//! generic over the lane type, run as vector arithmetic on `f64x2`, `f64x4` and `f64x8`; libm's
//! sines and cosines (and `f32`'s) are the scalar routines applied to each lane.
//!
//! Implemented for `f64` and `f32` (one lane) and for `wide`'s [`f64x2`], [`f64x4`], [`f64x8`]
//! (one AVX-512 register where the build targets AVX-512, two AVX ones elsewhere), [`f32x4`],
//! [`f32x8`] and [`f32x16`]. Negation is [`Lanes::neg`], a sign flip, `-0.0` of `0.0`.
//!
//! ```
//! use kanegen_runtime::lanes::{Lanes, f64x4};
//! let x = f64x4::from_fn(|i| i as f64);
//! let y = Lanes::mul_add(x, f64x4::splat(2.0), f64x4::splat(1.0));
//! assert_eq!([0, 1, 2, 3].map(|i| y.lane(i)), [1.0, 3.0, 5.0, 7.0]);
//! ```

use core::ops::{Add, Div, Mul, Sub};

pub use wide::{f32x16, f32x4, f32x8, f64x2, f64x4, f64x8};

mod lane;
pub use lane::{wrap, wrap_rows, Lane, Unlane};

/// `L` values of the element type `F` (`f64` or `f32`) side by side, with the operations of
/// generated code, each lane computed as the scalar operation computes it (bit for bit).
pub trait Lanes<F: Copy>:
    crate::scalar::Ring
    + core::fmt::Debug
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
{
    /// Number of lanes `L`.
    const LANES: usize;
    /// Every lane `x`.
    fn splat(x: F) -> Self;
    /// Lane `i` (`i < LANES`).
    fn lane(self, i: usize) -> F;
    /// Lane `i` is `f(i)`.
    fn from_fn(f: impl FnMut(usize) -> F) -> Self;
    /// `-x`: the sign flipped (`-0.0` of `0.0`).
    #[must_use]
    fn neg(self) -> Self;
    /// `a·b + c`, fused exactly where [`crate::fma::mul_add`] fuses (one rounding where the
    /// build targets FMA, `a * b + c` elsewhere).
    #[must_use]
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// `a·b + c` with one rounding always (libm's `fma`).
    #[must_use]
    fn fma(self, b: Self, c: Self) -> Self;
    /// `a·b + c` by the scalar function `f` on each lane (a fused multiply-add of the caller's
    /// choice, e.g. `f64::mul_add`).
    #[must_use]
    #[inline(always)]
    fn fma_with(self, b: Self, c: Self, f: impl Fn(F, F, F) -> F) -> Self {
        Self::from_fn(|i| f(self.lane(i), b.lane(i), c.lane(i)))
    }
    /// Square root, correctly rounded (libm's `sqrt`).
    #[must_use]
    fn sqrt(self) -> Self;
    /// Sine (libm's).
    #[must_use]
    fn sin(self) -> Self;
    /// Cosine (libm's).
    #[must_use]
    fn cos(self) -> Self;
    /// `(sin x, cos x)` (libm's `sincos`).
    fn sincos(self) -> (Self, Self);
    /// `(sin x, cos x)` of `K` angles by the table sine–cosine of generated `f64` code,
    /// products fused where the build targets FMA ([`crate::sincos::sincos_n`]); `f32` has no
    /// table sine–cosine and takes libm's `sincosf`, as generated `f32` code does.
    fn sincos_n<const K: usize>(x: [Self; K]) -> [(Self, Self); K];
    /// [`Lanes::sincos_n`] never fused ([`crate::sincos::sincos_n_unfused`]).
    fn sincos_n_unfused<const K: usize>(x: [Self; K]) -> [(Self, Self); K];

    /// Lane `l` of `vs[k]` written to `at(&mut out[l])[k]` for each `l < out.len()` (at most
    /// [`Lanes::LANES`]) and `k < K`: a batch's scatter of `K` numbers a state. Number by number
    /// here; the vector types store a whole chunk's rows `LANES` numbers at a time
    /// ([`write_rows_blocked`]).
    #[inline(always)]
    fn write_rows<R: 'static, const K: usize>(
        vs: &[Self; K],
        out: &mut [R],
        at: impl Fn(&mut R) -> &mut [F; K] + Copy,
    ) {
        write_numbers(vs, out, at);
    }
}

/// [`Lanes::write_rows`] number by number.
#[inline(always)]
fn write_numbers<F: Copy, S: Lanes<F>, R: 'static, const K: usize>(
    vs: &[S; K],
    out: &mut [R],
    at: impl Fn(&mut R) -> &mut [F; K] + Copy,
) {
    for (k, v) in vs.iter().enumerate() {
        for (l, o) in out.iter_mut().enumerate() {
            at(o)[k] = v.lane(l);
        }
    }
}

/// [`Lanes::write_rows`] of `f64x4` on a target with AVX: [`write_rows_blocked`] with each
/// `4 × 4` block transposed by AVX's unpacks and 128-bit permutes, in 256-bit registers. Left to
/// itself the compiler transposes with 512-bit permutes on an AVX-512 target, which slow the
/// whole batch, as the sine–cosine's 512-bit code did (SSRMS `M`, batch 256: `f64x4` 35.5
/// million states per second, 42.8 with AVX-512 off). The same values land in the same places.
#[inline(always)]
fn write_rows_f64x4<R: 'static, const K: usize>(
    vs: &[f64x4; K],
    out: &mut [R],
    at: impl Fn(&mut R) -> &mut [f64; K] + Copy,
) {
    #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
    if let Ok(chunk) = <&mut [R; 4]>::try_from(&mut *out) {
        use core::arch::x86_64::{
            _mm256_loadu_pd, _mm256_permute2f128_pd, _mm256_storeu_pd, _mm256_unpackhi_pd,
            _mm256_unpacklo_pd,
        };
        let mut rows: [&mut [f64; K]; 4] = chunk.each_mut().map(at);
        let full = K / 4 * 4;
        for k in (0..full).step_by(4) {
            let [a, b, c, d] = [&vs[k], &vs[k + 1], &vs[k + 2], &vs[k + 3]].map(f64x4::as_array);
            #[allow(unsafe_code)]
            // SAFETY: AVX is enabled for the whole build (the `cfg` above); each load reads the
            // four `f64` of a lane vector's array, each store writes four into `row[k..k + 4]`
            // of a row of `K ≥ k + 4` numbers.
            unsafe {
                let (a, b) = (_mm256_loadu_pd(a.as_ptr()), _mm256_loadu_pd(b.as_ptr()));
                let (c, d) = (_mm256_loadu_pd(c.as_ptr()), _mm256_loadu_pd(d.as_ptr()));
                // [a0 b0 a2 b2], [a1 b1 a3 b3], [c0 d0 c2 d2], [c1 d1 c3 d3]
                let (ab_lo, ab_hi) = (_mm256_unpacklo_pd(a, b), _mm256_unpackhi_pd(a, b));
                let (cd_lo, cd_hi) = (_mm256_unpacklo_pd(c, d), _mm256_unpackhi_pd(c, d));
                let t = [
                    _mm256_permute2f128_pd::<0x20>(ab_lo, cd_lo),
                    _mm256_permute2f128_pd::<0x20>(ab_hi, cd_hi),
                    _mm256_permute2f128_pd::<0x31>(ab_lo, cd_lo),
                    _mm256_permute2f128_pd::<0x31>(ab_hi, cd_hi),
                ];
                for (row, t) in rows.iter_mut().zip(t) {
                    _mm256_storeu_pd(row[k..k + 4].as_mut_ptr(), t);
                }
            }
        }
        for k in full..K {
            for (l, row) in rows.iter_mut().enumerate() {
                row[k] = vs[k].lane(l);
            }
        }
        return;
    }
    write_rows_blocked::<f64, f64x4, R, K, 4>(vs, out, at);
}

/// [`Lanes::write_rows`] of a vector type of `L` lanes: a whole chunk of `L` rows as `L × L`
/// blocks, lane `l` of `L` consecutive numbers stored together into row `l` (one vector store
/// where the compiler transposes the block in registers, instead of `L` scalar ones), the rest
/// and a partial chunk number by number. The same values land in the same places.
#[inline(always)]
fn write_rows_blocked<F: Copy, S: Lanes<F>, R: 'static, const K: usize, const L: usize>(
    vs: &[S; K],
    out: &mut [R],
    at: impl Fn(&mut R) -> &mut [F; K] + Copy,
) {
    let Ok(chunk) = <&mut [R; L]>::try_from(&mut *out) else {
        return write_numbers(vs, out, at);
    };
    let mut rows: [&mut [F; K]; L] = chunk.each_mut().map(at);
    let full = K / L * L;
    for k in (0..full).step_by(L) {
        let block: [[F; L]; L] =
            core::array::from_fn(|j| core::array::from_fn(|l| vs[k + j].lane(l)));
        for (l, row) in rows.iter_mut().enumerate() {
            let t: [F; L] = core::array::from_fn(|j| block[j][l]);
            row[k..k + L].copy_from_slice(&t);
        }
    }
    for k in full..K {
        for (l, row) in rows.iter_mut().enumerate() {
            row[k] = vs[k].lane(l);
        }
    }
}

/// The one-lane implementations: the scalar routines themselves.
macro_rules! scalar_lanes {
    ($t:ident, $mul_add:path, $fma:path, $sqrt:path, $sin:path, $cos:path, $sincos:path,
     $table:expr, $table_unfused:expr) => {
        impl Lanes<$t> for $t {
            const LANES: usize = 1;
            #[inline(always)]
            fn splat(x: $t) -> Self {
                x
            }
            #[inline(always)]
            fn lane(self, i: usize) -> $t {
                debug_assert_eq!(i, 0);
                self
            }
            #[inline(always)]
            fn from_fn(mut f: impl FnMut(usize) -> $t) -> Self {
                f(0)
            }
            #[inline(always)]
            fn neg(self) -> Self {
                -self
            }
            #[inline(always)]
            fn mul_add(self, b: Self, c: Self) -> Self {
                $mul_add(self, b, c)
            }
            #[inline(always)]
            fn fma(self, b: Self, c: Self) -> Self {
                $fma(self, b, c)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline(always)]
            fn sin(self) -> Self {
                $sin(self)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                $cos(self)
            }
            #[inline(always)]
            fn sincos(self) -> (Self, Self) {
                $sincos(self)
            }
            #[inline(always)]
            fn sincos_n<const K: usize>(x: [Self; K]) -> [(Self, Self); K] {
                $table(x)
            }
            #[inline(always)]
            fn sincos_n_unfused<const K: usize>(x: [Self; K]) -> [(Self, Self); K] {
                $table_unfused(x)
            }
        }
    };
}

scalar_lanes!(
    f64,
    crate::fma::mul_add,
    libm::fma,
    libm::sqrt,
    libm::sin,
    libm::cos,
    libm::sincos,
    crate::sincos::sincos_n,
    crate::sincos::sincos_n_unfused
);
scalar_lanes!(
    f32,
    crate::fma::mul_add_f32,
    libm::fmaf,
    libm::sqrtf,
    libm::sinf,
    libm::cosf,
    libm::sincosf,
    |x: [f32; K]| x.map(libm::sincosf),
    |x: [f32; K]| x.map(libm::sincosf)
);

/// Whether `wide`'s `mul_add` is one fused instruction in this build (x86-64 with FMA), where
/// [`crate::fma::mul_add`] is one too.
const WIDE_FUSES: bool = cfg!(all(target_arch = "x86_64", target_feature = "fma"));
/// Whether [`crate::fma::mul_add`] fuses in this build.
const RUNTIME_FUSES: bool = cfg!(any(
    all(target_arch = "x86_64", target_feature = "fma"),
    all(target_arch = "aarch64", target_feature = "neon")
));
/// Whether `wide`'s `sqrt` is the correctly rounded instruction in this build.
const WIDE_SQRT: bool = cfg!(any(
    target_arch = "x86_64",
    all(target_arch = "aarch64", target_feature = "neon")
));

/// The `wide` implementations: vector arithmetic where `wide`'s equals the scalar routine lane
/// by lane, the scalar routine on each lane elsewhere.
macro_rules! wide_lanes {
    ($v:ident, $t:ident, $l:literal, $sincos_n:expr, $sincos_n_unfused:expr) => {
        wide_lanes!(
            $v,
            $t,
            $l,
            $sincos_n,
            $sincos_n_unfused,
            write_rows_blocked::<$t, Self, R, K, $l>
        );
    };
    ($v:ident, $t:ident, $l:literal, $sincos_n:expr, $sincos_n_unfused:expr, $write_rows:expr) => {
        impl crate::scalar::Ring for $v {
            #[inline(always)]
            fn zero() -> Self {
                $v::splat(0.0)
            }
        }

        impl Lanes<$t> for $v {
            const LANES: usize = $l;
            #[inline(always)]
            fn splat(x: $t) -> Self {
                $v::splat(x)
            }
            #[inline(always)]
            fn lane(self, i: usize) -> $t {
                self.as_array()[i]
            }
            #[inline(always)]
            fn from_fn(f: impl FnMut(usize) -> $t) -> Self {
                $v::new(core::array::from_fn(f))
            }
            #[inline(always)]
            fn neg(self) -> Self {
                self ^ $v::splat(-0.0)
            }
            #[inline(always)]
            fn mul_add(self, b: Self, c: Self) -> Self {
                if WIDE_FUSES {
                    $v::mul_add(self, b, c)
                } else if RUNTIME_FUSES {
                    self.map3(b, c, <$t as Lanes<$t>>::mul_add)
                } else {
                    self * b + c
                }
            }
            #[inline(always)]
            fn fma(self, b: Self, c: Self) -> Self {
                if WIDE_FUSES {
                    $v::mul_add(self, b, c)
                } else {
                    self.map3(b, c, <$t as Lanes<$t>>::fma)
                }
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                if WIDE_SQRT {
                    $v::sqrt(self)
                } else {
                    self.map(<$t as Lanes<$t>>::sqrt)
                }
            }
            #[inline(always)]
            fn sin(self) -> Self {
                self.map(<$t as Lanes<$t>>::sin)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                self.map(<$t as Lanes<$t>>::cos)
            }
            #[inline(always)]
            fn sincos(self) -> (Self, Self) {
                let r = self.to_array().map(<$t as Lanes<$t>>::sincos);
                ($v::new(r.map(|r| r.0)), $v::new(r.map(|r| r.1)))
            }
            #[inline(always)]
            fn sincos_n<const K: usize>(x: [Self; K]) -> [(Self, Self); K] {
                $sincos_n(x)
            }
            #[inline(always)]
            fn sincos_n_unfused<const K: usize>(x: [Self; K]) -> [(Self, Self); K] {
                $sincos_n_unfused(x)
            }
            #[inline(always)]
            fn write_rows<R: 'static, const K: usize>(
                vs: &[Self; K],
                out: &mut [R],
                at: impl Fn(&mut R) -> &mut [$t; K] + Copy,
            ) {
                $write_rows(vs, out, at);
            }
        }
    };
}

/// Lane-by-lane maps of a vector type.
trait Map<F: Copy>: Lanes<F> {
    #[inline(always)]
    fn map(self, f: impl Fn(F) -> F) -> Self {
        Self::from_fn(|i| f(self.lane(i)))
    }
    #[inline(always)]
    fn map3(self, b: Self, c: Self, f: impl Fn(F, F, F) -> F) -> Self {
        Self::from_fn(|i| f(self.lane(i), b.lane(i), c.lane(i)))
    }
}

impl<F: Copy, S: Lanes<F>> Map<F> for S {}

/// The sine–cosine `f` of `K` angles of one state applied to each lane's angles (`L =
/// S::LANES`): `K` pairs of vectors.
#[inline(always)]
pub(crate) fn per_lane<F: Copy, S: Lanes<F>, const K: usize, const L: usize>(
    x: [S; K],
    f: impl Fn([F; K]) -> [(F, F); K],
) -> [(S, S); K] {
    let r: [[(F, F); K]; L] = core::array::from_fn(|i| f(x.map(|v| v.lane(i))));
    core::array::from_fn(|k| (S::from_fn(|i| r[i][k].0), S::from_fn(|i| r[i][k].1)))
}

/// Setting one lane.
trait Replace<F: Copy>: Lanes<F> {
    #[inline(always)]
    fn replace(self, i: usize, x: F) -> Self {
        Self::from_fn(|j| if j == i { x } else { self.lane(j) })
    }
}

impl<F: Copy, S: Lanes<F>> Replace<F> for S {}

wide_lanes!(
    f64x2,
    f64,
    2,
    crate::sincos::lanes::<f64x2, K, true>,
    crate::sincos::lanes::<f64x2, K, false>
);
wide_lanes!(
    f64x4,
    f64,
    4,
    crate::sincos::lanes::<f64x4, K, true>,
    crate::sincos::lanes::<f64x4, K, false>,
    write_rows_f64x4::<R, K>
);
wide_lanes!(
    f64x8,
    f64,
    8,
    crate::sincos::lanes::<f64x8, K, true>,
    crate::sincos::lanes::<f64x8, K, false>
);
wide_lanes!(
    f32x4,
    f32,
    4,
    |x| per_lane::<_, _, K, 4>(x, |x: [f32; K]| x.map(libm::sincosf)),
    |x| per_lane::<_, _, K, 4>(x, |x: [f32; K]| x.map(libm::sincosf))
);
wide_lanes!(
    f32x8,
    f32,
    8,
    |x| per_lane::<_, _, K, 8>(x, |x: [f32; K]| x.map(libm::sincosf)),
    |x| per_lane::<_, _, K, 8>(x, |x: [f32; K]| x.map(libm::sincosf))
);
wide_lanes!(
    f32x16,
    f32,
    16,
    |x| per_lane::<_, _, K, 16>(x, |x: [f32; K]| x.map(libm::sincosf)),
    |x| per_lane::<_, _, K, 16>(x, |x: [f32; K]| x.map(libm::sincosf))
);

/// A value of the element type `F` (a number, an array of them, a tuple of those) and its form
/// over the lane type `S` (each number a lane vector): how functions without a lane body (the
/// compact form's kernels) evaluate `L` states, one lane at a time ([`lanewise`]).
pub trait LaneValue<F, S>: Sized + 'static {
    /// The value over `S`: `[S; N]` for `[F; N]`.
    type Lanes;
    /// Every lane `self`.
    fn splat(&self) -> Self::Lanes;
    /// Lane `i` of `lanes`.
    fn lane(lanes: &Self::Lanes, i: usize) -> Self;
    /// Sets lane `i` of `lanes` to `self`.
    fn set_lane(&self, lanes: &mut Self::Lanes, i: usize);
    /// The value over `S` whose lane `l` is `*f(l)`, each number read once (a batch's gather).
    fn from_lanes<'a>(f: impl Fn(usize) -> &'a Self + Copy) -> Self::Lanes
    where
        Self: 'a;
    /// Lane `l` of `lanes` written into `at(&mut out[l])` for each `l < out.len()` (a batch's
    /// scatter): number by number, each lane vector read once and its lanes stored where they
    /// go, in place.
    fn write_lanes<R: 'static>(
        lanes: &Self::Lanes,
        out: &mut [R],
        at: impl Fn(&mut R) -> &mut Self + Copy,
    );

    /// [`LaneValue::write_lanes`] of an array of `N` values: element by element, but a number's
    /// rows whole ([`Lanes::write_rows`]).
    #[inline(always)]
    fn write_lanes_array<R: 'static, const N: usize>(
        lanes: &[Self::Lanes; N],
        out: &mut [R],
        at: impl Fn(&mut R) -> &mut [Self; N] + Copy,
    ) {
        for (k, l) in lanes.iter().enumerate() {
            Self::write_lanes(l, out, element(at, k));
        }
    }
}

/// `at` followed by the field `f` of what it gives.
#[inline(always)]
fn field<R: 'static, T: 'static, U: 'static>(
    at: impl Fn(&mut R) -> &mut T + Copy,
    f: impl Fn(&mut T) -> &mut U + Copy,
) -> impl Fn(&mut R) -> &mut U + Copy {
    move |r| f(at(r))
}

/// `at` followed by element `k` of the array it gives.
#[inline(always)]
fn element<R: 'static, T: 'static, const N: usize>(
    at: impl Fn(&mut R) -> &mut [T; N] + Copy,
    k: usize,
) -> impl Fn(&mut R) -> &mut T + Copy {
    move |r| &mut at(r)[k]
}

macro_rules! number_value {
    ($t:ident) => {
        impl<S: Lanes<$t>> LaneValue<$t, S> for $t {
            type Lanes = S;
            #[inline(always)]
            fn splat(&self) -> S {
                S::splat(*self)
            }
            #[inline(always)]
            fn lane(lanes: &S, i: usize) -> Self {
                lanes.lane(i)
            }
            #[inline(always)]
            fn set_lane(&self, lanes: &mut S, i: usize) {
                *lanes = lanes.replace(i, *self);
            }
            #[inline(always)]
            fn from_lanes<'a>(f: impl Fn(usize) -> &'a Self + Copy) -> S {
                S::from_fn(|l| *f(l))
            }
            #[inline(always)]
            fn write_lanes<R: 'static>(
                lanes: &S,
                out: &mut [R],
                at: impl Fn(&mut R) -> &mut Self + Copy,
            ) {
                for (l, o) in out.iter_mut().enumerate() {
                    *at(o) = lanes.lane(l);
                }
            }
            #[inline(always)]
            fn write_lanes_array<R: 'static, const N: usize>(
                lanes: &[S; N],
                out: &mut [R],
                at: impl Fn(&mut R) -> &mut [Self; N] + Copy,
            ) {
                S::write_rows(lanes, out, at);
            }
        }
    };
}

number_value!(f64);
number_value!(f32);

impl<F, S, T: LaneValue<F, S>, const N: usize> LaneValue<F, S> for [T; N] {
    type Lanes = [T::Lanes; N];
    #[inline(always)]
    fn splat(&self) -> Self::Lanes {
        core::array::from_fn(|k| self[k].splat())
    }
    #[inline(always)]
    fn lane(lanes: &Self::Lanes, i: usize) -> Self {
        core::array::from_fn(|k| T::lane(&lanes[k], i))
    }
    #[inline(always)]
    fn set_lane(&self, lanes: &mut Self::Lanes, i: usize) {
        for (v, l) in self.iter().zip(lanes.iter_mut()) {
            v.set_lane(l, i);
        }
    }
    #[inline(always)]
    fn from_lanes<'a>(f: impl Fn(usize) -> &'a Self + Copy) -> Self::Lanes
    where
        Self: 'a,
    {
        core::array::from_fn(|k| T::from_lanes(move |l| &f(l)[k]))
    }
    #[inline(always)]
    fn write_lanes<R: 'static>(
        lanes: &Self::Lanes,
        out: &mut [R],
        at: impl Fn(&mut R) -> &mut Self + Copy,
    ) {
        T::write_lanes_array(lanes, out, at);
    }
}

macro_rules! tuple_value {
    ($($t:ident $k:tt),+) => {
        impl<F, S, $($t: LaneValue<F, S>),+> LaneValue<F, S> for ($($t,)+) {
            type Lanes = ($($t::Lanes,)+);
            #[inline(always)]
            fn splat(&self) -> Self::Lanes {
                ($(self.$k.splat(),)+)
            }
            #[inline(always)]
            fn lane(lanes: &Self::Lanes, i: usize) -> Self {
                ($($t::lane(&lanes.$k, i),)+)
            }
            #[inline(always)]
            fn set_lane(&self, lanes: &mut Self::Lanes, i: usize) {
                $(self.$k.set_lane(&mut lanes.$k, i);)+
            }
            #[inline(always)]
            fn from_lanes<'a>(f: impl Fn(usize) -> &'a Self + Copy) -> Self::Lanes
            where
                Self: 'a,
            {
                ($($t::from_lanes(move |l| &f(l).$k),)+)
            }
            #[inline(always)]
            fn write_lanes<R: 'static>(
                lanes: &Self::Lanes,
                out: &mut [R],
                at: impl Fn(&mut R) -> &mut Self + Copy,
            ) {
                $($t::write_lanes(&lanes.$k, out, field::<R, Self, $t>(at, |x| &mut x.$k));)+
            }
        }
    };
}

tuple_value!(A 0, B 1);
tuple_value!(A 0, B 1, C 2);
tuple_value!(A 0, B 1, C 2, D 3);

/// Lane `i` of an argument over `S`, as the scalar function takes it.
#[inline(always)]
pub fn lane<F: Copy, S: Lanes<F>, T: LaneValue<F, S>>(lanes: &T::Lanes, i: usize) -> T {
    T::lane(lanes, i)
}

/// `f(i)` of every lane `i`, as one value over `S`: a function without a lane body evaluated
/// one lane at a time.
#[inline(always)]
pub fn lanewise<F: Copy, S: Lanes<F>, R: LaneValue<F, S>>(
    mut f: impl FnMut(usize) -> R,
) -> R::Lanes {
    let mut out = f(0).splat();
    for i in 1..S::LANES {
        f(i).set_lane(&mut out, i);
    }
    out
}

/// Lanes `start..start + S::LANES` of the first `n` states as one argument over `S`, states past
/// `n` replaced by state `n − 1` (the padding of a batch's last chunk). `start < n ≤
/// states.len()`.
#[inline(always)]
pub fn gather<F: Copy, S: Lanes<F>, T: LaneValue<F, S>>(
    states: &[T],
    start: usize,
    n: usize,
) -> T::Lanes {
    let last = n - 1;
    T::from_lanes(|l| &states[(start + l).min(last)])
}

/// `out[k]` for the first `n` states (`n ≤ out.len()`), `S::LANES` at a time: `f(start)` gives
/// the results of states `start..start + S::LANES` as one value over `S` (the last chunk padded,
/// its padding lanes discarded).
#[inline(always)]
pub fn batch<F: Copy, S: Lanes<F>, R: LaneValue<F, S>>(
    out: &mut [R],
    n: usize,
    mut f: impl FnMut(usize) -> R::Lanes,
) {
    for (c, chunk) in out[..n].chunks_mut(S::LANES).enumerate() {
        let r = f(c * S::LANES);
        R::write_lanes(&r, chunk, |o| o);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic values spanning signs, zeros, large angles (past the table's fast path)
    /// and non-finite numbers.
    fn values() -> [f64; 16] {
        [
            0.0,
            -0.0,
            1.0,
            -2.5,
            0.1,
            3.7,
            -1e-300,
            1e300,
            40000.0,
            -1.234_567_89,
            7.5,
            1e-3,
            f64::NAN,
            f64::INFINITY,
            -0.75,
            2.0,
        ]
    }

    fn same64(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    fn same32(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// Every method of a lane type, lane by lane against the scalar type's, on groups of
    /// `values()` rotated into the lanes.
    macro_rules! check {
        ($v:ident, $t:ident, $same:ident) => {{
            let vals = values().map(|x| x as $t);
            let n = vals.len();
            for shift in 0..n {
                let pick = |k: usize| $v::from_fn(|i| vals[(shift + 3 * i + k) % n]);
                let (a, b, c) = (pick(0), pick(5), pick(11));
                for i in 0..<$v as Lanes<$t>>::LANES {
                    let (x, y, z) = (a.lane(i), b.lane(i), c.lane(i));
                    let s = |l: $v| l.lane(i);
                    assert!($same(s(a + b), x + y));
                    assert!($same(s(a - b), x - y));
                    assert!($same(s(a * b), x * y));
                    assert!($same(s(a / b), x / y));
                    assert!($same(s(Lanes::neg(a)), Lanes::neg(x)));
                    assert!($same(s(Lanes::mul_add(a, b, c)), Lanes::mul_add(x, y, z)));
                    assert!($same(s(Lanes::fma(a, b, c)), Lanes::fma(x, y, z)));
                    let f = |x: $t, y: $t, z: $t| x * y - z;
                    assert!($same(s(Lanes::fma_with(a, b, c, f)), f(x, y, z)));
                    assert!($same(s(Lanes::sqrt(a)), Lanes::sqrt(x)));
                    assert!($same(s(Lanes::sin(a)), Lanes::sin(x)));
                    assert!($same(s(Lanes::cos(a)), Lanes::cos(x)));
                    let ((vs, vc), (xs, xc)) = (Lanes::sincos(a), Lanes::sincos(x));
                    assert!($same(s(vs), xs) && $same(s(vc), xc));
                    let sc = <$v as Lanes<$t>>::sincos_n([a, b, c]);
                    let xc = <$t as Lanes<$t>>::sincos_n([x, y, z]);
                    let sc_u = <$v as Lanes<$t>>::sincos_n_unfused([a, b, c]);
                    let xc_u = <$t as Lanes<$t>>::sincos_n_unfused([x, y, z]);
                    for k in 0..3 {
                        assert!($same(s(sc[k].0), xc[k].0) && $same(s(sc[k].1), xc[k].1));
                        assert!($same(s(sc_u[k].0), xc_u[k].0) && $same(s(sc_u[k].1), xc_u[k].1));
                    }
                    assert!($same(s(<$v as Lanes<$t>>::splat(x)), x));
                }
            }
        }};
    }

    #[test]
    fn f64x2_lanes_are_the_scalar() {
        check!(f64x2, f64, same64);
    }

    #[test]
    fn f64x4_lanes_are_the_scalar() {
        check!(f64x4, f64, same64);
    }

    #[test]
    fn f64x8_lanes_are_the_scalar() {
        check!(f64x8, f64, same64);
    }

    #[test]
    fn f32x16_lanes_are_the_scalar() {
        check!(f32x16, f32, same32);
    }

    #[test]
    fn f32x4_lanes_are_the_scalar() {
        check!(f32x4, f32, same32);
    }

    #[test]
    fn f32x8_lanes_are_the_scalar() {
        check!(f32x8, f32, same32);
    }

    /// The one-lane types are the scalar routines: fused where the runtime fuses, libm's
    /// correctly rounded `fma` always fused, the sign of zero flipped.
    #[test]
    fn scalar_lanes_are_the_routines() {
        let (a, b, c) = (0.1_f64, 0.2, -0.02);
        assert_eq!(Lanes::mul_add(a, b, c), crate::fma::mul_add(a, b, c));
        assert_eq!(Lanes::fma(a, b, c), libm::fma(a, b, c));
        assert_ne!(Lanes::fma(a, b, c), a * b + c, "one rounding");
        assert!(Lanes::neg(0.0_f64).is_sign_negative());
        assert!(Lanes::neg(f64x4::splat(0.0)).lane(3).is_sign_negative());
        assert_eq!(
            <f64 as Lanes<f64>>::sincos_n([0.3]),
            crate::sincos::sincos_n([0.3])
        );
        assert_eq!(Lanes::sincos(0.3_f32), libm::sincosf(0.3));
    }

    /// `lanewise` evaluates each lane once and gathers nested results; `lane` reads them back.
    #[test]
    fn lanewise_gathers_each_lane() {
        let mut calls = 0;
        let r: ([[f64x4; 2]; 2], [f64x4; 3]) = lanewise::<f64, f64x4, _>(|i| {
            calls += 1;
            let x = i as f64;
            ([[x, 2.0 * x], [3.0 * x, -x]], [x + 0.5, 1.0, -1.0])
        });
        assert_eq!(calls, 4);
        for i in 0..4 {
            let x = i as f64;
            let back: ([[f64; 2]; 2], [f64; 3]) = lane::<f64, f64x4, _>(&r, i);
            assert_eq!(back, ([[x, 2.0 * x], [3.0 * x, -x]], [x + 0.5, 1.0, -1.0]));
        }
    }
}
