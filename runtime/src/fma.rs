//! The fused multiply-add of generated code and [`crate::sincos`]: `a·b + c` in one instruction
//! (one rounding) where the build targets it, two operations (bit-identical to unfused code)
//! elsewhere.
//!
//! `core` has no safe fused multiply-add without `std` (`f64::mul_add` is a `std` method, and
//! `libm::fma` is a call emulating it in software where the build does not target FMA), so
//! these take the instruction's intrinsic under the same `cfg` as the build's target features.
//!
//! ```
//! assert_eq!(kanegen_runtime::fma::mul_add(2.0, 3.0, 1.0), 7.0);
//! assert_eq!(kanegen_runtime::fma::mul_add_f32(2.0, 3.0, 1.0), 7.0);
//! ```

/// One `mul_add` per float type: the intrinsic's names differ, the code is the same.
macro_rules! mul_add {
    ($(#[$doc:meta])* $name:ident, $t:ty, $x86:ident, $set:ident, $get:ident, $dup:ident, $fma:ident, $lane:ident) => {
        $(#[$doc])*
        #[inline(always)]
        #[must_use]
        #[allow(unsafe_code)]
        pub fn $name(a: $t, b: $t, c: $t) -> $t {
            #[cfg(all(target_arch = "x86_64", target_feature = "fma"))]
            {
                use core::arch::x86_64::{$get, $set, $x86};
                // SAFETY: the build targets FMA (the `cfg` above), so the instruction exists.
                unsafe { $get($x86($set(a), $set(b), $set(c))) }
            }
            #[cfg(all(target_arch = "aarch64", target_feature = "neon"))]
            {
                use core::arch::aarch64::{$dup, $fma, $lane};
                // SAFETY: AArch64 with NEON (the `cfg` above) has the fused multiply-add.
                unsafe { $lane::<0>($fma($dup(c), $dup(a), $dup(b))) }
            }
            #[cfg(not(any(
                all(target_arch = "x86_64", target_feature = "fma"),
                all(target_arch = "aarch64", target_feature = "neon")
            )))]
            {
                a * b + c
            }
        }
    };
}

mul_add!(
    /// `a·b + c` in `f64`: one fused multiply-add where the build targets it (x86-64 with
    /// `target_feature = "fma"`, e.g. `-C target-cpu=native`; AArch64), `a * b + c` elsewhere.
    mul_add, f64, _mm_fmadd_sd, _mm_set_sd, _mm_cvtsd_f64, vdup_n_f64, vfma_f64, vget_lane_f64
);
mul_add!(
    /// [`mul_add`] in `f32`.
    mul_add_f32, f32, _mm_fmadd_ss, _mm_set_ss, _mm_cvtss_f32, vdup_n_f32, vfma_f32, vget_lane_f32
);
