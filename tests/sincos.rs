//! The generated code's own sine–cosine (`Self::sincos`, forwarding to `kanegen_runtime::sincos`) against
//! libm's: a dense sweep of joint angles, seeded random angles up to the fast path's limit, the
//! exact values it must keep, its symmetries, and the fallback beyond the limit.

use kanegen_generated::srms::Srms;

/// The error in units of `f64::EPSILON · max(|want|, floor)`: with floor 1, absolute (in ulps
/// of 1); with floor 1/16, in ulps of the result wherever it is at least 1/16 (near a zero of sin
/// or cos the angle sum cancels, and libm's own answer carries the rounding of `x`, up to
/// 3.6e-12 at x = 32768).
fn err(got: f64, want: f64, floor: f64) -> f64 {
    (got - want).abs() / (f64::EPSILON * want.abs().max(floor))
}

/// The largest error over `xs` (absolute, relative), each with its angle.
fn worst(xs: impl Iterator<Item = f64>) -> [(f64, f64); 2] {
    let mut w = [(0.0, 0.0); 2];
    for x in xs {
        let (s, c) = Srms::sincos(x);
        let (s0, c0) = libm::sincos(x);
        for (k, floor) in [1.0, 1.0 / 16.0].into_iter().enumerate() {
            let e = err(s, s0, floor).max(err(c, c0, floor));
            if e > w[k].0 {
                w[k] = (e, x);
            }
        }
    }
    w
}

/// Measured 1.0 and 1.98 without FMA; the bounds leave room for a fused build.
fn check([(abs, xa), (rel, xr)]: [(f64, f64); 2]) {
    assert!(abs <= 1.5, "{abs} ulp of 1 at x = {xa}");
    assert!(rel <= 2.5, "{rel} ulp at x = {xr}");
}

/// Every angle of [−4π, 4π] on a grid of 10⁶ points, and 10⁶ seeded random angles up to
/// |x| < 32768: within 1.5 ulp of 1 of libm's, and 2.5 ulp of the result where it is at least
/// 1/16.
#[test]
fn within_ulps_of_libm() {
    let span = 4.0 * core::f64::consts::PI;
    check(worst(
        (0..=1_000_000).map(|k| -span + 2.0 * span * f64::from(k) / 1e6),
    ));
    // xorshift64*: seeded, no dependency.
    let mut state = 0x9E37_79B9_7F4A_7C15_u64;
    let mut next = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    check(worst(
        (0..1_000_000).map(|_| (2.0 * next() - 1.0) * 32767.9),
    ));
}

/// sin 0 = 0 and cos 0 = 1 exactly, sin is odd and cos even bit for bit, and sin(π/2) = 1.
#[test]
fn exact_values_and_symmetry() {
    assert_eq!(Srms::sincos(0.0), (0.0, 1.0));
    let (s, c) = Srms::sincos(core::f64::consts::FRAC_PI_2);
    assert_eq!(s, 1.0);
    assert!(c.abs() < 1e-16);
    for k in 0..10_000 {
        let x = 1e-3 + f64::from(k) * 6.3e-4;
        let (s, c) = Srms::sincos(x);
        let (sm, cm) = Srms::sincos(-x);
        assert_eq!(sm.to_bits(), (-s).to_bits(), "x = {x}");
        assert_eq!(cm.to_bits(), c.to_bits(), "x = {x}");
    }
}

/// Beyond the fast path, and for NaN and the infinities, it is libm's, bit for bit.
#[test]
fn libm_beyond_the_limit() {
    for x in [
        32768.0,
        -32768.0,
        1e6,
        -3.5e9,
        1e300,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ] {
        let (s, c) = Srms::sincos(x);
        let (s0, c0) = libm::sincos(x);
        assert_eq!(
            (s.to_bits(), c.to_bits()),
            (s0.to_bits(), c0.to_bits()),
            "x = {x}"
        );
    }
    check(worst([32767.99, -32767.99].into_iter()));
}
