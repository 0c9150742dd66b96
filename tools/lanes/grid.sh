#!/usr/bin/env bash
# 256 forward dynamics and 256 forward-dynamics derivatives of one model (GRiD's benchmark:
# 256 states of a 7-dof arm), µs per 256 states, side by side in one run: one state per call on
# one core, `NAME_batch::<f64x4>` / `::<f64x8>` on one core, and the same batches split over all
# cores by `kanegen::runtime::par::batch` (feature `rayon`; the rounds inside `par::install`,
# on a thread of the pool). ROUNDS rounds (default 400), each
# running every candidate once in rotating order; the least and the median round are printed.
# The program first checks that the batches, serial and parallel, are the one-state results bit
# for bit.
#   tools/lanes/grid.sh MODEL [MODEL...]
# e.g., on the two CPUs of the machine:
#   RUSTFLAGS="-C target-cpu=native" taskset -c 0,1 bash tools/lanes/grid.sh tests/data/erd/xarm7.urdf
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
dir="$root/target/lanes-grid"
source "$root/tools/lanes/crate.sh"
export LANES_CRATE_SEP=$'\n'
for model in "$@"; do
  lanes_crate "$dir" grid '"rayon"' "$model" <<'RS'
use kanegen::runtime::lanes::{f64x4, f64x8};
use kanegen::runtime::par;
use std::hint::black_box;
use std::time::Instant;
type D = ([[f64; N]; N], [[f64; N]; N], [[f64; N]; N]);

fn main() {
    let rounds: usize = std::env::var("ROUNDS").map_or(400, |r| r.parse().expect("ROUNDS"));
    let mut seed = 1u64;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
    };
    let mut states = || -> Vec<[f64; N]> { (0..B).map(|_| core::array::from_fn(|_| rnd())).collect() };
    let (q, qd, tau) = (states(), states(), states());
    let (q, qd, tau) = (&q[..], &qd[..], &tau[..]);
    let mut fd = [(); 5].map(|()| vec![[0.0; N]; B]);
    let mut dd: [Vec<D>; 5] = [(); 5].map(|()| vec![([[0.0; N]; N], [[0.0; N]; N], [[0.0; N]; N]); B]);
    let names = ["1 state, 1 core", "f64x4, 1 core", "f64x8, 1 core", "f64x4, all cores", "f64x8, all cores"];
    // One run of candidate i: 0..5 forward dynamics, 5..10 its derivatives.
    let mut run = |i: usize| {
        let (w, fd, dd) = (i % 5, &mut fd[i % 5], &mut dd[i % 5]);
        match (i / 5, w) {
            (0, 0) => fd.iter_mut().enumerate().for_each(|(k, o)| *o = R::forward_dynamics(&q[k], &qd[k], &tau[k])),
            (0, 1) => R::forward_dynamics_batch::<f64x4>(q, qd, tau, fd),
            (0, 2) => R::forward_dynamics_batch::<f64x8>(q, qd, tau, fd),
            (0, 3) => par::batch(fd, |r, o| R::forward_dynamics_batch::<f64x4>(&q[r.clone()], &qd[r.clone()], &tau[r], o)),
            (0, 4) => par::batch(fd, |r, o| R::forward_dynamics_batch::<f64x8>(&q[r.clone()], &qd[r.clone()], &tau[r], o)),
            (1, 0) => dd.iter_mut().enumerate().for_each(|(k, o)| *o = R::forward_dynamics_derivatives(&q[k], &qd[k], &tau[k])),
            (1, 1) => R::forward_dynamics_derivatives_batch::<f64x4>(q, qd, tau, dd),
            (1, 2) => R::forward_dynamics_derivatives_batch::<f64x8>(q, qd, tau, dd),
            (1, 3) => par::batch(dd, |r, o| R::forward_dynamics_derivatives_batch::<f64x4>(&q[r.clone()], &qd[r.clone()], &tau[r], o)),
            _ => par::batch(dd, |r, o| R::forward_dynamics_derivatives_batch::<f64x8>(&q[r.clone()], &qd[r.clone()], &tau[r], o)),
        }
        black_box((&fd, &dd));
    };
    // On a thread of the pool, as a sampler's loop of batches runs (`par::install`).
    let us = par::install(|| {
        for i in 0..10 {
            run(i); // warm-up
        }
        let mut us = vec![Vec::with_capacity(rounds); 10];
        for round in 0..rounds {
            for off in 0..10 {
                let i = (round + off) % 10;
                let t0 = Instant::now();
                run(i);
                us[i].push(t0.elapsed().as_secs_f64() * 1e6);
            }
        }
        us
    });
    let mut us = us;
    // Every way's results are the one-state results, bit for bit.
    let bits = |x: &dyn std::fmt::Debug| format!("{x:?}");
    assert!(fd.iter().all(|o| bits(o) == bits(&fd[0])), "forward dynamics differ");
    assert!(dd.iter().all(|o| bits(o) == bits(&dd[0])), "derivatives differ");
    println!("N = {N}, {B} states, {rounds} rounds, {} threads; µs per {B} states, least / median round", par::threads());
    for (f, label) in ["forward_dynamics", "forward_dynamics_derivatives"].iter().enumerate() {
        for (w, name) in names.iter().enumerate() {
            let s = &mut us[5 * f + w];
            s.sort_by(f64::total_cmp);
            println!("{label:<30} {name:<18} {:>9.1} {:>9.1}", s[0], s[s.len() / 2]);
        }
    }
}
RS
done
