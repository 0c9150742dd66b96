//! The generated-code rows of `kanegen accuracy`: the SSRMS functions emitted by kanegen in each
//! precision, wrapped as [`GeneratedFns`] on `f64` slices, derivatives included.
//!
//! All three are checked-in files of `kanegen-generated` (`ssrms`, `ssrms_f32`, `ssrms_fma`),
//! generated from the same model file (`tests/data/reference/ssrms_nguyen_hughes_1994.urdf`), so
//! they run the same emitted graph and differ only in the arithmetic. The report's `b = τ − c`
//! is formed from the generated `c` in the variant's precision.
//!
//! The fma variant calls `libm::fma`, the faster of the two on the development machine
//! (x86-64 with FMA, built without `-C target-cpu=native`): SSRMS forward dynamics (426 fused
//! operations) took 690 ns with `libm::fma` (which detects the FMA instruction at run time and
//! calls it through a function pointer) against 970–1380 ns with `f64::mul_add` (a call into
//! the C library's `fma`), and 180 ns unfused. Neither call is inlined without the target
//! feature, so fusing costs time here.

use kanegen_generated::{ssrms::Ssrms, ssrms_f32::SsrmsF32, ssrms_fma::SsrmsFma};

use super::evaluation::GeneratedFns;

/// Wraps one generated type (`$ty`, scalar `$t`) as [`GeneratedFns`]: inputs rounded to `$t`,
/// outputs widened to `f64`.
macro_rules! generated_fns {
    ($precision:literal, $ty:ty, $t:ty) => {{
        const N: usize = <$ty>::N;
        fn arr(x: &[f64]) -> [$t; N] {
            core::array::from_fn(|i| x[i] as $t)
        }
        fn mass_matrix(q: &[f64]) -> Vec<Vec<f64>> {
            widen(&<$ty>::mass_matrix(&arr(q)))
        }
        fn tau_minus_c(q: &[f64], qd: &[f64], tau: &[f64]) -> Vec<f64> {
            let c = <$ty>::nonlinear_effects(&arr(q), &arr(qd));
            let tau = arr(tau);
            (0..N).map(|i| f64::from(tau[i] - c[i])).collect()
        }
        fn forward_dynamics(q: &[f64], qd: &[f64], tau: &[f64]) -> Vec<f64> {
            <$ty>::forward_dynamics(&arr(q), &arr(qd), &arr(tau))
                .map(f64::from)
                .to_vec()
        }
        fn widen(m: &[[$t; N]; N]) -> Vec<Vec<f64>> {
            m.iter()
                .map(|r| r.iter().map(|&x| f64::from(x)).collect())
                .collect()
        }
        fn inverse_dynamics_derivatives(q: &[f64], qd: &[f64], qdd: &[f64]) -> [Vec<Vec<f64>>; 2] {
            let (dq, dv) = <$ty>::inverse_dynamics_derivatives(&arr(q), &arr(qd), &arr(qdd));
            [widen(&dq), widen(&dv)]
        }
        fn forward_dynamics_derivatives(q: &[f64], qd: &[f64], tau: &[f64]) -> [Vec<Vec<f64>>; 3] {
            let (dq, dv, minv) = <$ty>::forward_dynamics_derivatives(&arr(q), &arr(qd), &arr(tau));
            [widen(&dq), widen(&dv), widen(&minv)]
        }
        GeneratedFns {
            precision: $precision,
            mass_matrix,
            tau_minus_c,
            forward_dynamics,
            inverse_dynamics_derivatives: Some(inverse_dynamics_derivatives),
            forward_dynamics_derivatives: Some(forward_dynamics_derivatives),
        }
    }};
}

/// The SSRMS variants: the checked-in `f64` code of `kanegen-generated`, `f32` and `f64-fma`.
#[must_use]
pub fn ssrms_variants() -> Vec<GeneratedFns> {
    vec![
        generated_fns!("f32", SsrmsF32, f32),
        generated_fns!("f64", Ssrms, f64),
        generated_fns!("f64-fma", SsrmsFma, f64),
    ]
}

/// The error of the generated `f64` code's own sine–cosine (`Self::sincos`,
/// `kanegen_runtime::sincos`: a table and short polynomials) against libm's `sincos`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SincosError {
    /// Angles compared: a grid on [−4π, 4π] and as many seeded random ones with |x| < 32768.
    pub points: usize,
    /// The largest difference of sin or cos, in ulps of 1 (`f64::EPSILON`).
    pub abs_ulps: f64,
    /// The largest difference in ulps of the value, where it is at least 1/16.
    pub ulps: f64,
}

/// Measures [`SincosError`] on 2 × 10⁶ angles (about 0.1 s).
#[must_use]
pub fn sincos_error() -> SincosError {
    const HALF: u32 = 1_000_000;
    let span = 4.0 * core::f64::consts::PI;
    let grid = (0..HALF).map(|k| -span + 2.0 * span * f64::from(k) / f64::from(HALF - 1));
    // splitmix64: seeded uniform angles in (−32768, 32768).
    let mut state = 0x005E_ED0F_5C05_u64;
    let random = (0..HALF).map(move |_| {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * 32767.9
    });
    let mut e = SincosError {
        points: 2 * HALF as usize,
        abs_ulps: 0.0,
        ulps: 0.0,
    };
    for x in grid.chain(random) {
        let (s, c) = Ssrms::sincos(x);
        let (s0, c0) = libm::sincos(x);
        for (got, want) in [(s, s0), (c, c0)] {
            let d = (got - want).abs() / f64::EPSILON;
            e.abs_ulps = e.abs_ulps.max(d);
            if want.abs() >= 1.0 / 16.0 {
                e.ulps = e.ulps.max(d / want.abs());
            }
        }
    }
    e
}
