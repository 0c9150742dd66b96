//! The `_lanes` form of every generated function (`NAME_lanes<S: Lanes<F>>`): on SIMD vectors
//! (`f64x2`, `f64x4`, `f64x8`; `f32x4`, `f32x8`, `f32x16` for `f32` code) each lane's results are bit for bit the
//! scalar function's at that lane's state, for random states, on the checked-in files (SSRMS
//! plain, `f32`, `fma`; the free-floating 7-dof arm) and on `dynamics!` code (UR5 with gravity,
//! straight-line and compact; a random chain with a runtime payload, compact with libm's and with fused products; libm's sine–cosine; the
//! `f64::mul_add` fma path).

use kanegen::runtime::lanes::{f32x16, f32x4, f32x8, f64x2, f64x4, f64x8, LaneValue, Lanes};
use kanegen_generated::{
    free_floating_7dof::FreeFloating7, ssrms::Ssrms, ssrms_f32::SsrmsF32, ssrms_fma::SsrmsFma,
};
use std::fmt::Debug;

kanegen::dynamics!(
    Ur5,
    "tests/data/erd/ur5_robot.urdf",
    gravity = [0.0, 0.0, -9.81]
);
kanegen::dynamics!(
    Ur5Compact,
    "tests/data/erd/ur5_robot.urdf",
    gravity = [0.0, 0.0, -9.81],
    form = "compact"
);
kanegen::dynamics!(
    Random5CompactLibm,
    "tests/data/codegen/random5.toml",
    form = "compact",
    libm_trig = true
);
kanegen::dynamics!(
    Random5CompactFma,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    form = "compact",
    fma = true
);
kanegen::dynamics!(
    Random5Payload,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    runtime_payload = true,
);
kanegen::dynamics!(
    Random5Libm,
    "tests/data/codegen/random5.toml",
    libm_trig = true
);
kanegen::dynamics!(
    Random5MulAdd,
    "tests/data/codegen/random5.toml",
    fma = true,
    fma_path = f64::mul_add,
);
kanegen::dynamics!(
    Random5F32Payload,
    "tests/data/codegen/random5.toml",
    gravity = [0.3, -1.2, -9.81],
    runtime_payload = true,
    scalar = f32,
    fma = true,
);

/// A small deterministic generator (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        // Uniform in [-3, 3): angles past ±π, rates and torques of either sign.
        ((z >> 11) as f64 / (1u64 << 53) as f64) * 6.0 - 3.0
    }
}

/// A random argument: a number, or an array of them.
trait Random {
    fn random(rng: &mut Rng) -> Self;
}

impl Random for f64 {
    fn random(rng: &mut Rng) -> Self {
        rng.next()
    }
}

impl Random for f32 {
    fn random(rng: &mut Rng) -> Self {
        rng.next() as f32
    }
}

impl<T: Random, const N: usize> Random for [T; N] {
    fn random(rng: &mut Rng) -> Self {
        core::array::from_fn(|_| T::random(rng))
    }
}

/// The lanes' states packed into one argument over `S`: lane `i` is `states[i]`.
fn pack<F: Copy, S: Lanes<F>, T: LaneValue<F, S>>(states: &[T]) -> T::Lanes {
    assert_eq!(states.len(), S::LANES);
    let mut out = states[0].splat();
    for (i, s) in states.iter().enumerate().skip(1) {
        s.set_lane(&mut out, i);
    }
    out
}

/// Lane `i` of `lanes` is `scalar[i]`, bit for bit (`Debug` prints the shortest decimal that
/// rounds to the bits, and the sign of zero).
fn same<F: Copy, S: Lanes<F>, R: LaneValue<F, S> + Debug>(lanes: &R::Lanes, scalar: &[R], f: &str) {
    assert_eq!(scalar.len(), S::LANES);
    for (i, want) in scalar.iter().enumerate() {
        let have = R::lane(lanes, i);
        assert_eq!(format!("{have:?}"), format!("{want:?}"), "{f}, lane {i}");
    }
}

/// States per function and lane type.
const ROUNDS: usize = 16;

/// For each function `name / name_lanes (args)`: `ROUNDS` rounds of `S::LANES` random states,
/// the lanes function on them packed against the scalar function on each; `extra`: trailing
/// arguments shared by the lanes (the payload).
/// `f(args…, extra…)`.
macro_rules! call {
    ($f:expr; $($a:expr),*; [$($e:expr),*]) => {
        $f($($a,)* $($e),*)
    };
}

macro_rules! lanes_equal_scalar {
    ($t:ty, $f:ty, $s:ty, $seed:expr, $extra:tt;
     $($name:ident / $lanes:ident ($($arg:ident),*)),* $(,)?) => {{
        const L: usize = <$s as Lanes<$f>>::LANES;
        let mut rng = Rng($seed);
        let mut checked = 0;
        $(
            for _ in 0..ROUNDS {
                $(let $arg: [_; L] = core::array::from_fn(|_| Random::random(&mut rng));)*
                let lanes = call!(<$t>::$lanes::<$s>; $(&pack::<$f, $s, _>(&$arg)),*; $extra);
                let scalar: [_; L] =
                    core::array::from_fn(|i| call!(<$t>::$name; $(&$arg[i]),*; $extra));
                same::<$f, $s, _>(&lanes, &scalar, stringify!($name));
            }
            checked += 1;
        )*
        checked
    }};
}

/// The functions of a fixed-base type with gravity, derivatives and frames
/// `base_link`, `ee_link`, `tool0`, `base` (UR5).
macro_rules! ur5_functions {
    ($t:ty, $f:ty, $s:ty, $seed:expr) => {
        lanes_equal_scalar!($t, $f, $s, $seed, [];
            mass_matrix / mass_matrix_lanes(q),
            nonlinear_effects / nonlinear_effects_lanes(q, qd),
            gravity / gravity_lanes(q),
            inverse_dynamics / inverse_dynamics_lanes(q, qd, qdd),
            forward_dynamics / forward_dynamics_lanes(q, qd, tau),
            mass_matrix_and_nonlinear_effects / mass_matrix_and_nonlinear_effects_lanes(q, qd),
            forward_dynamics_with_wrenches / forward_dynamics_with_wrenches_lanes(q, qd, tau, f_ext),
            inverse_dynamics_derivatives / inverse_dynamics_derivatives_lanes(q, qd, qdd),
            forward_dynamics_derivatives / forward_dynamics_derivatives_lanes(q, qd, tau),
            mass_matrix_inverse / mass_matrix_inverse_lanes(q),
            base_link_placement / base_link_placement_lanes(q),
            base_link_jacobian / base_link_jacobian_lanes(q),
            ee_link_placement / ee_link_placement_lanes(q),
            ee_link_jacobian / ee_link_jacobian_lanes(q),
            tool0_placement / tool0_placement_lanes(q),
            tool0_jacobian / tool0_jacobian_lanes(q),
            base_placement / base_placement_lanes(q),
            base_jacobian / base_jacobian_lanes(q),
        )
    };
}

/// The functions of SSRMS (no gravity, no frames) with derivatives.
macro_rules! ssrms_functions {
    ($t:ty, $f:ty, $s:ty, $seed:expr) => {
        lanes_equal_scalar!($t, $f, $s, $seed, [];
            mass_matrix / mass_matrix_lanes(q),
            nonlinear_effects / nonlinear_effects_lanes(q, qd),
            inverse_dynamics / inverse_dynamics_lanes(q, qd, qdd),
            forward_dynamics / forward_dynamics_lanes(q, qd, tau),
            mass_matrix_and_nonlinear_effects / mass_matrix_and_nonlinear_effects_lanes(q, qd),
            forward_dynamics_with_wrenches / forward_dynamics_with_wrenches_lanes(q, qd, tau, f_ext),
            inverse_dynamics_derivatives / inverse_dynamics_derivatives_lanes(q, qd, qdd),
            forward_dynamics_derivatives / forward_dynamics_derivatives_lanes(q, qd, tau),
            mass_matrix_inverse / mass_matrix_inverse_lanes(q),
        )
    };
}

/// The functions of the random 5-dof chain with gravity and a payload (`extra`).
macro_rules! random5_functions {
    ($t:ty, $f:ty, $s:ty, $seed:expr, $extra:tt) => {
        lanes_equal_scalar!($t, $f, $s, $seed, $extra;
            mass_matrix / mass_matrix_lanes(q),
            nonlinear_effects / nonlinear_effects_lanes(q, qd),
            gravity / gravity_lanes(q),
            inverse_dynamics / inverse_dynamics_lanes(q, qd, qdd),
            forward_dynamics / forward_dynamics_lanes(q, qd, tau),
            mass_matrix_and_nonlinear_effects / mass_matrix_and_nonlinear_effects_lanes(q, qd),
            forward_dynamics_with_wrenches / forward_dynamics_with_wrenches_lanes(q, qd, tau, f_ext),
            inverse_dynamics_derivatives / inverse_dynamics_derivatives_lanes(q, qd, qdd),
            forward_dynamics_derivatives / forward_dynamics_derivatives_lanes(q, qd, tau),
            mass_matrix_inverse / mass_matrix_inverse_lanes(q),
        )
    };
}

#[test]
fn ssrms_lanes_are_the_scalar_functions() {
    assert_eq!(ssrms_functions!(Ssrms, f64, f64x4, 1), 9);
    assert_eq!(ssrms_functions!(Ssrms, f64, f64x2, 2), 9);
    assert_eq!(ssrms_functions!(Ssrms, f64, f64x8, 22), 9);
    assert_eq!(ssrms_functions!(Ssrms, f64, f64, 3), 9);
}

#[test]
fn ssrms_fma_lanes_are_the_scalar_functions() {
    assert_eq!(ssrms_functions!(SsrmsFma, f64, f64x4, 4), 9);
    assert_eq!(ssrms_functions!(SsrmsFma, f64, f64x2, 5), 9);
    assert_eq!(ssrms_functions!(SsrmsFma, f64, f64x8, 23), 9);
}

#[test]
fn ssrms_f32_lanes_are_the_scalar_functions() {
    assert_eq!(ssrms_functions!(SsrmsF32, f32, f32x8, 6), 9);
    assert_eq!(ssrms_functions!(SsrmsF32, f32, f32x4, 7), 9);
    assert_eq!(ssrms_functions!(SsrmsF32, f32, f32x16, 24), 9);
}

#[test]
fn free_floating_lanes_are_the_scalar_functions() {
    for (s, seed) in [(4, 8), (2, 9)] {
        let n = if s == 4 {
            lanes_equal_scalar!(FreeFloating7, f64, f64x4, seed, [];
                mass_matrix / mass_matrix_lanes(q),
                nonlinear_effects / nonlinear_effects_lanes(q, v),
                inverse_dynamics / inverse_dynamics_lanes(q, v, a),
                forward_dynamics / forward_dynamics_lanes(q, v, tau),
                mass_matrix_and_nonlinear_effects / mass_matrix_and_nonlinear_effects_lanes(q, v),
                forward_dynamics_with_wrenches / forward_dynamics_with_wrenches_lanes(q, v, tau, f_ext),
                momentum / momentum_lanes(q, v),
                base_reaction / base_reaction_lanes(q, v, a),
            )
        } else {
            lanes_equal_scalar!(FreeFloating7, f64, f64x2, seed, [];
                forward_dynamics / forward_dynamics_lanes(q, v, tau),
                base_reaction / base_reaction_lanes(q, v, a),
            )
        };
        assert!(n >= 2);
    }
}

#[test]
fn ur5_lanes_are_the_scalar_functions() {
    assert_eq!(ur5_functions!(Ur5, f64, f64x4, 10), 18);
    assert_eq!(ur5_functions!(Ur5, f64, f64x2, 11), 18);
    assert_eq!(ur5_functions!(Ur5, f64, f64x8, 25), 18);
}

/// The compact form's `_lanes` run its kernels on `Lane<S>` (the tables' numbers splat over the
/// lanes), each lane bit for bit the scalar function; `M`, `(M, c)` and the named frames'
/// evaluate the scalar function lane by lane. Also with libm's sine–cosine and with fused products (whose
/// sine–cosine is never fused).
#[test]
fn compact_lanes_are_the_scalar_functions() {
    // Only emitted code fuses products: the compact mass matrix is a kernel's call.
    let unrolled = Ur5::OP_COUNTS.iter().find(|e| e.function == "mass_matrix");
    let compact = Ur5Compact::OP_COUNTS
        .iter()
        .find(|e| e.function == "mass_matrix");
    assert!(unrolled.unwrap().fma > 0);
    assert_eq!(compact.unwrap().fma, 0);
    assert_eq!(ur5_functions!(Ur5Compact, f64, f64x4, 12), 18);
    assert_eq!(ur5_functions!(Ur5Compact, f64, f64x2, 19), 18);
    assert_eq!(ur5_functions!(Ur5Compact, f64, f64x8, 26), 18);
    let n = lanes_equal_scalar!(Random5CompactLibm, f64, f64x4, 20, [];
        inverse_dynamics / inverse_dynamics_lanes(q, qd, qdd),
        forward_dynamics / forward_dynamics_lanes(q, qd, tau),
        forward_dynamics_derivatives / forward_dynamics_derivatives_lanes(q, qd, tau),
    );
    assert_eq!(n, 3);
    let n = lanes_equal_scalar!(Random5CompactFma, f64, f64x4, 21, [];
        nonlinear_effects / nonlinear_effects_lanes(q, qd),
        gravity / gravity_lanes(q),
        forward_dynamics_with_wrenches / forward_dynamics_with_wrenches_lanes(q, qd, tau, f_ext),
        inverse_dynamics_derivatives / inverse_dynamics_derivatives_lanes(q, qd, qdd),
    );
    assert_eq!(n, 4);
}

#[test]
fn payload_lanes_share_the_payload() {
    let mut p = Random5PayloadPayload::NOMINAL;
    p.mass *= 1.7;
    p.com[1] += 0.05;
    p.inertia[0][2] += 0.01;
    assert_eq!(random5_functions!(Random5Payload, f64, f64x4, 13, [&p]), 10);
    let p = Random5F32PayloadPayload::NOMINAL;
    assert_eq!(
        random5_functions!(Random5F32Payload, f32, f32x8, 14, [&p]),
        10
    );
}

/// libm's sine–cosine, and a custom fma path (`f64::mul_add`, called on each lane).
#[test]
fn libm_trig_and_fma_path_lanes_are_the_scalar_functions() {
    let n = lanes_equal_scalar!(Random5Libm, f64, f64x4, 15, [];
        mass_matrix / mass_matrix_lanes(q),
        forward_dynamics / forward_dynamics_lanes(q, qd, tau),
        forward_dynamics_derivatives / forward_dynamics_derivatives_lanes(q, qd, tau),
    );
    assert_eq!(n, 3);
    let n = lanes_equal_scalar!(Random5MulAdd, f64, f64x4, 16, [];
        mass_matrix / mass_matrix_lanes(q),
        forward_dynamics / forward_dynamics_lanes(q, qd, tau),
        inverse_dynamics_derivatives / inverse_dynamics_derivatives_lanes(q, qd, qdd),
    );
    assert_eq!(n, 3);
}

/// The check can fail: a lane whose state differs from the scalar call's gives other bits.
#[test]
#[should_panic(expected = "lane 2")]
fn a_wrong_lane_is_caught() {
    let mut rng = Rng(17);
    let q: [[f64; 7]; 4] = Random::random(&mut rng);
    let lanes = Ssrms::mass_matrix_lanes::<f64x4>(&pack::<f64, f64x4, _>(&q));
    let mut scalar = q.map(|q| Ssrms::mass_matrix(&q));
    scalar[2] = Ssrms::mass_matrix(&q[1]);
    same::<f64, f64x4, _>(&lanes, &scalar, "mass_matrix");
}

/// `NAME_batch` over slices equals the scalar calls state by state, bit for bit, for batch
/// lengths around the lane count (a padded last chunk, an empty batch), with a payload and
/// on `f32`; `out` past the shortest slice is left as it was.
#[test]
fn batches_are_the_scalar_calls() {
    let mut rng = Rng(18);
    for n in [0, 1, 3, 4, 5, 8, 11] {
        let q: Vec<[f64; 7]> = (0..n).map(|_| Random::random(&mut rng)).collect();
        let qd: Vec<[f64; 7]> = (0..n).map(|_| Random::random(&mut rng)).collect();
        let tau: Vec<[f64; 7]> = (0..n).map(|_| Random::random(&mut rng)).collect();
        let mut out = vec![[f64::NAN; 7]; n + 2];
        Ssrms::forward_dynamics_batch::<f64x4>(&q, &qd, &tau, &mut out);
        for k in 0..n {
            let want = Ssrms::forward_dynamics(&q[k], &qd[k], &tau[k]);
            assert_eq!(
                format!("{:?}", out[k]),
                format!("{want:?}"),
                "n = {n}, k = {k}"
            );
        }
        assert!(out[n..].iter().flatten().all(|x| x.is_nan()), "n = {n}");
        let mut mc = vec![([[0.0; 7]; 7], [0.0; 7]); n];
        Ssrms::mass_matrix_and_nonlinear_effects_batch::<f64x2>(&q, &qd, &mut mc);
        for k in 0..n {
            let want = Ssrms::mass_matrix_and_nonlinear_effects(&q[k], &qd[k]);
            assert_eq!(
                format!("{:?}", mc[k]),
                format!("{want:?}"),
                "n = {n}, k = {k}"
            );
        }
    }
    let p = Random5F32PayloadPayload::NOMINAL;
    let q: Vec<[f32; 5]> = (0..13).map(|_| Random::random(&mut rng)).collect();
    let mut out = vec![[0.0_f32; 5]; 13];
    Random5F32Payload::gravity_batch::<f32x8>(&q, &p, &mut out);
    for k in 0..13 {
        let want = Random5F32Payload::gravity(&q[k], &p);
        assert_eq!(format!("{:?}", out[k]), format!("{want:?}"), "k = {k}");
    }
    // A compact function's batch (the mass matrix: one state per call whatever `S` is).
    let q: Vec<[f64; 6]> = (0..6).map(|_| Random::random(&mut rng)).collect();
    let mut out = vec![[[0.0; 6]; 6]; 6];
    Ur5Compact::mass_matrix_batch::<f64x4>(&q, &mut out);
    for k in 0..6 {
        assert_eq!(out[k], Ur5Compact::mass_matrix(&q[k]));
    }
    // And one whose kernel runs on lanes (a padded last chunk of 2 states).
    let qd: Vec<[f64; 6]> = (0..6).map(|_| Random::random(&mut rng)).collect();
    let mut out = vec![[0.0; 6]; 6];
    Ur5Compact::forward_dynamics_batch::<f64x4>(&q, &qd, &qd, &mut out);
    for k in 0..6 {
        let want = Ur5Compact::forward_dynamics(&q[k], &qd[k], &qd[k]);
        assert_eq!(format!("{:?}", out[k]), format!("{want:?}"), "k = {k}");
    }
}

/// Angles for the table sine–cosine: zeros of both signs, multiples of π/2 and π, the table's
/// steps `kπ/128` and the points halfway between (where the rounded step changes), tiny and
/// subnormal values, the fast path's limit ±32768 and its neighbours, NaN and the infinities,
/// and seeded random angles over [−3, 3), [−200, 200) and up to ±32768.
fn sincos_angles() -> Vec<f64> {
    use core::f64::consts::PI;
    let below = |x: f64| f64::from_bits(x.to_bits() - 1);
    let mut a = vec![
        0.0,
        -0.0,
        1e-300,
        -1e-300,
        5e-324,
        f64::MIN_POSITIVE,
        32768.0,
        -32768.0,
        below(32768.0),
        -below(32768.0),
        32767.99,
        -32767.99,
        1e6,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for k in -300..=300 {
        let k = f64::from(k);
        a.extend([k * PI, k * PI / 2.0, k * PI / 128.0, (k + 0.5) * PI / 128.0]);
        a.extend([below(((k + 0.5) * PI / 128.0).abs()), 1e4 * k * PI]);
    }
    let mut rng = Rng(19);
    for _ in 0..2000 {
        let x = rng.next();
        a.extend([x, x * 200.0 / 3.0, x * 32767.0 / 3.0]);
    }
    a
}

/// `S::sincos_n` and `S::sincos_n_unfused` of `K` angles per lane against the scalar routine
/// on each lane's `K` angles, bit for bit, over `angles` rotated through the lanes (so some
/// lanes take the path beyond the limit while others do not); returns the number of calls.
fn sincos_lanes_are_the_scalar<S: Lanes<f64>, const K: usize>(angles: &[f64]) -> usize {
    let n = angles.len();
    let mut calls = 0;
    for start in (0..n).step_by(3) {
        let pick = |i: usize, k: usize| angles[(start + 7 * i + 13 * k) % n];
        let x: [S; K] = core::array::from_fn(|k| S::from_fn(|i| pick(i, k)));
        let (fused, unfused) = (S::sincos_n(x), S::sincos_n_unfused(x));
        for i in 0..S::LANES {
            let xi: [f64; K] = core::array::from_fn(|k| pick(i, k));
            let (want, want_u) = (f64::sincos_n(xi), f64::sincos_n_unfused(xi));
            for k in 0..K {
                let bits = |(s, c): (f64, f64)| (s.to_bits(), c.to_bits());
                let lane = |(s, c): (S, S)| (s.lane(i), c.lane(i));
                assert_eq!(bits(lane(fused[k])), bits(want[k]), "{xi:?}, lane {i}");
                assert_eq!(bits(lane(unfused[k])), bits(want_u[k]), "{xi:?}, lane {i}");
            }
        }
        calls += 1;
    }
    calls
}

/// The table sine–cosine on `f64x2`, `f64x4` and `f64x8` (vector arithmetic, the table read per lane) is
/// the scalar routine on each lane, fused and unfused, for one and several angles per lane.
#[test]
fn table_sincos_lanes_are_the_scalar() {
    let angles = sincos_angles();
    let n = angles.len().div_ceil(3);
    assert_eq!(sincos_lanes_are_the_scalar::<f64x2, 1>(&angles), n);
    assert_eq!(sincos_lanes_are_the_scalar::<f64x4, 1>(&angles), n);
    assert_eq!(sincos_lanes_are_the_scalar::<f64x2, 3>(&angles), n);
    assert_eq!(sincos_lanes_are_the_scalar::<f64x4, 7>(&angles), n);
    assert_eq!(sincos_lanes_are_the_scalar::<f64x8, 1>(&angles), n);
    assert_eq!(sincos_lanes_are_the_scalar::<f64x8, 7>(&angles), n);
}

/// `runtime::par::batch` over a generated batch (feature `rayon`) equals the serial batch bit
/// for bit, on pools of one, two and three threads, for batch lengths around the chunk sizes.
#[cfg(feature = "rayon")]
#[test]
fn parallel_batches_are_the_serial_batch() {
    use kanegen::runtime::par;
    let mut rng = Rng(20);
    let pools = [1, 2, 3].map(|t| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
    });
    for n in [0, 1, 5, 8, 17, 64, 203] {
        let q: Vec<[f64; 6]> = (0..n).map(|_| Random::random(&mut rng)).collect();
        let qd: Vec<[f64; 6]> = (0..n).map(|_| Random::random(&mut rng)).collect();
        let tau: Vec<[f64; 6]> = (0..n).map(|_| Random::random(&mut rng)).collect();
        let mut serial = vec![[0.0; 6]; n];
        Ur5::forward_dynamics_batch::<f64x4>(&q, &qd, &tau, &mut serial);
        let mut serial_mc = vec![([[0.0; 6]; 6], [0.0; 6]); n];
        Ur5::mass_matrix_and_nonlinear_effects_batch::<f64x2>(&q, &qd, &mut serial_mc);
        for pool in &pools {
            let mut out = vec![[f64::NAN; 6]; n];
            pool.install(|| {
                par::batch(&mut out, |r, out| {
                    Ur5::forward_dynamics_batch::<f64x4>(
                        &q[r.clone()],
                        &qd[r.clone()],
                        &tau[r],
                        out,
                    );
                });
            });
            assert_eq!(format!("{out:?}"), format!("{serial:?}"), "n = {n}");
            let mut mc = vec![([[f64::NAN; 6]; 6], [f64::NAN; 6]); n];
            pool.install(|| {
                par::batch(&mut mc, |r, out| {
                    Ur5::mass_matrix_and_nonlinear_effects_batch::<f64x2>(
                        &q[r.clone()],
                        &qd[r],
                        out,
                    );
                });
            });
            assert_eq!(format!("{mc:?}"), format!("{serial_mc:?}"), "n = {n}");
        }
    }
}
