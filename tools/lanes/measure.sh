#!/usr/bin/env bash
# Throughput of the `_lanes` functions: ns per state of `forward_dynamics` and
# `mass_matrix_and_nonlinear_effects` of one `kanegen::dynamics!` crate per model, one state
# per call (f64) and L states per call (`f64x2`, `f64x4`), over 256 random states (median of 5
# rounds; packing the lanes and unpacking the results included):
#   tools/lanes/measure.sh MODEL [MODEL...]
# Pin it to one core and let it use the build's vector width, e.g.
#   RUSTFLAGS="-C target-cpu=native" taskset -c 0 bash tools/lanes/measure.sh tests/data/erd/ur5_robot.urdf
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
dir="$root/target/lanes-measure"
source "$root/tools/lanes/crate.sh"
for model in "$@"; do
  lanes_crate "$dir" lanes "" "$model" <<'RS'
use kanegen::runtime::lanes::{f64x2, f64x4, Lanes};

/// Lanes `i..i + L` of `x` as one argument over `S`.
#[inline(always)]
fn pack<S: Lanes<f64>>(x: &[[f64; N]], i: usize) -> [S; N] {
    core::array::from_fn(|j| S::from_fn(|l| x[i + l][j]))
}

/// ns per state of `f` over the B states, the median of 5 rounds.
fn time(mut f: impl FnMut() -> f64) -> f64 {
    let reps = (20_000 / (N * N)).max(20);
    let mut t: Vec<f64> = (0..5)
        .map(|_| {
            let start = std::time::Instant::now();
            let mut acc = 0.0;
            for _ in 0..reps {
                acc += f();
            }
            std::hint::black_box(acc);
            start.elapsed().as_nanos() as f64 / (reps * B) as f64
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[2]
}

fn main() {
    let mut seed = 1u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
    };
    let q: Vec<[f64; N]> = (0..B).map(|_| core::array::from_fn(|_| rnd())).collect();
    let qd: Vec<[f64; N]> = (0..B).map(|_| core::array::from_fn(|_| rnd())).collect();
    let tau: Vec<[f64; N]> = (0..B).map(|_| core::array::from_fn(|_| rnd())).collect();
    // The lanes are the scalar function, bit for bit, in this build (fused or not).
    for i in (0..B).step_by(4) {
        let r = R::forward_dynamics_lanes::<f64x4>(&pack(&q, i), &pack(&qd, i), &pack(&tau, i));
        let (m, c) = R::mass_matrix_and_nonlinear_effects_lanes::<f64x4>(&pack(&q, i), &pack(&qd, i));
        for l in 0..4 {
            let want = R::forward_dynamics(&q[i + l], &qd[i + l], &tau[i + l]);
            assert!((0..N).all(|j| r[j].lane(l).to_bits() == want[j].to_bits()));
            let (wm, wc) = R::mass_matrix_and_nonlinear_effects(&q[i + l], &qd[i + l]);
            assert!((0..N).all(|j| c[j].lane(l).to_bits() == wc[j].to_bits()
                && (0..N).all(|k| m[j][k].lane(l).to_bits() == wm[j][k].to_bits())));
        }
    }
    let fd1 = time(|| {
        let q = std::hint::black_box(&q);
        (0..B).map(|i| R::forward_dynamics(&q[i], &qd[i], &tau[i]).iter().sum::<f64>()).sum()
    });
    fn fd<S: Lanes<f64>>(q: &[[f64; N]], qd: &[[f64; N]], tau: &[[f64; N]]) -> f64 {
        let q = std::hint::black_box(q);
        (0..B)
            .step_by(S::LANES)
            .map(|i| {
                let r = R::forward_dynamics_lanes::<S>(&pack(q, i), &pack(qd, i), &pack(tau, i));
                (0..S::LANES).map(|l| r.iter().map(|x| x.lane(l)).sum::<f64>()).sum::<f64>()
            })
            .sum()
    }
    let fd2 = time(|| fd::<f64x2>(&q, &qd, &tau));
    let fd4 = time(|| fd::<f64x4>(&q, &qd, &tau));
    let mc1 = time(|| {
        let q = std::hint::black_box(&q);
        (0..B)
            .map(|i| {
                let (m, c) = R::mass_matrix_and_nonlinear_effects(&q[i], &qd[i]);
                m.iter().flatten().sum::<f64>() + c.iter().sum::<f64>()
            })
            .sum()
    });
    fn mc<S: Lanes<f64>>(q: &[[f64; N]], qd: &[[f64; N]]) -> f64 {
        let q = std::hint::black_box(q);
        (0..B)
            .step_by(S::LANES)
            .map(|i| {
                let (m, c) = R::mass_matrix_and_nonlinear_effects_lanes::<S>(&pack(q, i), &pack(qd, i));
                (0..S::LANES)
                    .map(|l| m.iter().flatten().chain(&c).map(|x| x.lane(l)).sum::<f64>())
                    .sum::<f64>()
            })
            .sum()
    }
    let mc2 = time(|| mc::<f64x2>(&q, &qd));
    let mc4 = time(|| mc::<f64x4>(&q, &qd));
    println!("ns/state FD f64 {fd1:.1} f64x2 {fd2:.1} f64x4 {fd4:.1}; M+c f64 {mc1:.1} f64x2 {mc2:.1} f64x4 {mc4:.1}");
}
RS
done
