//! The sine–cosine of the generated `f64` code: `Self::sincos(x)` and `Self::sincos_n([…])`,
//! emitted into every generated type that takes a sine or a cosine ([`item`]) in place of
//! `libm::sincos`, one line each forwarding to the runtime's (`kanegen_runtime::sincos`: a table
//! of 128 sines and short polynomials, branch-free and inlined for `|x| < 32768` rad,
//! `libm::sincos` beyond), which holds the table and the algorithm.
//!
//! The functions take all joint angles' in one `S::sincos_n([q[0], …])` at the top (the same
//! runtime routine on each lane of the lane type `S`, `kanegen_runtime::lanes`), whose steps the
//! compiler vectorizes. The error against `libm::sincos` is measured by `kanegen
//! accuracy` (`docs/accuracy.md`) and bounded by `tests/sincos.rs`: 1 ulp of 1 at most, and 2 ulp
//! of the value wherever it is at least 1/16.
//!
//! `f32` code keeps libm's `sincosf` (itself cheap), as does [`Options::libm_trig`](crate::Options).

use proc_macro2::TokenStream;
use quote::quote;

/// The emitted `pub fn sincos(x: f64) -> (f64, f64)` and `pub fn sincos_n<const N: usize>(x:
/// [f64; N]) -> [(f64, f64); N]` of a generated type: `runtime` is the path of the
/// `kanegen-runtime` crate; with `mul_add`, the products are fused where the build targets FMA
/// (`sincos::sincos_n`, like the functions' `S::mul_add`), else never
/// (`sincos::sincos_n_unfused`).
#[must_use]
pub fn item(runtime: &TokenStream, mul_add: bool) -> TokenStream {
    let batched = if mul_add {
        quote!(#runtime::sincos::sincos_n)
    } else {
        quote!(#runtime::sincos::sincos_n_unfused)
    };
    let (f64, usize) = (
        crate::paths::primitive("f64"),
        crate::paths::primitive("usize"),
    );
    quote! {
        /// `(sin x, cos x)`, as this type's functions take them: [`Self::sincos_n`] of one angle.
        #[inline(always)]
        #[must_use]
        pub fn sincos(x: #f64) -> (#f64, #f64) {
            let [sc] = Self::sincos_n([x]);
            sc
        }

        /// `(sin x, cos x)` of `N` angles at once (the functions take every joint angle's in one
        /// call), by the runtime's table sine–cosine: branch-free for `|x| < 32768`,
        /// `libm::sincos` beyond; within 1 ulp of 1 of libm's (`kanegen accuracy` measures it).
        #[inline(always)]
        #[must_use]
        pub fn sincos_n<const N: #usize>(x: [#f64; N]) -> [(#f64, #f64); N] {
            #batched(x)
        }
    }
}
