//! The generated-code rows of `kanegen accuracy`: the SSRMS functions emitted by kanegen in each
//! precision, wrapped as [`GeneratedFns`] on `f64` slices.

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
            <$ty>::mass_matrix(&arr(q))
                .iter()
                .map(|r| r.iter().map(|&x| f64::from(x)).collect())
                .collect()
        }
        fn bias(q: &[f64], qd: &[f64], tau: &[f64]) -> Vec<f64> {
            <$ty>::bias(&arr(q), &arr(qd), &arr(tau))
                .map(f64::from)
                .to_vec()
        }
        fn forward_dynamics(q: &[f64], qd: &[f64], tau: &[f64]) -> Vec<f64> {
            <$ty>::forward_dynamics(&arr(q), &arr(qd), &arr(tau))
                .map(f64::from)
                .to_vec()
        }
        GeneratedFns {
            precision: $precision,
            mass_matrix,
            bias,
            forward_dynamics,
        }
    }};
}

/// The SSRMS variants: the checked-in `f64` code of `kanegen-generated`.
#[must_use]
pub fn ssrms_variants() -> Vec<GeneratedFns> {
    vec![generated_fns!("f64", kanegen_generated::ssrms::Ssrms, f64)]
}
