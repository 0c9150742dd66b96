#!/usr/bin/env bash
# `kanegen bench`'s throughput table for any model: states per second (millions) of `M`, `c`,
# `(M, c)`, inverse and forward dynamics, their derivatives and `M⁻¹` over a batch of
# random states, in six ways side by side: one state per call, `NAME_batch::<f64x2>`, `::<f64x4>`
# and `::<f64x8>` on one core, and the last two over all cores (`par::batch`), every way
# called back to back for about 200 µs per sample, the whole loop on a thread of the pool
# (`par::install`), ROUNDS rounds (default 21) in rotating order, the median round printed, for
# each batch size of BATCHES (default "64 256 4096"), the functions of FUNCTIONS (names, default
# all). It first checks that every way gives the
# one-state results bit for bit.
#   tools/lanes/throughput.sh MODEL [MODEL...]
# e.g., on the two CPUs of the machine:
#   RUSTFLAGS="-C target-cpu=native" taskset -c 0,1 bash tools/lanes/throughput.sh tests/data/erd/ur5_robot.urdf
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
dir="$root/target/lanes-throughput"
source "$root/tools/lanes/crate.sh"
export LANES_CRATE_SEP=$'\n'
for model in "$@"; do
  lanes_crate "$dir" throughput '"rayon"' "$model" <<'RS'
use kanegen::runtime::lanes::{f64x2, f64x4, f64x8};
use kanegen::runtime::par;
use std::hint::black_box;
use std::time::Instant;

/// One way of evaluating the batch, writing its results into its own output.
type Way<'a> = Box<dyn FnMut() + Send + 'a>;

/// The ways of evaluating a batch.
const WAYS: usize = 6;

/// The six ways of function `$f` (batch form `$batch`) over the argument slices, and a check
/// that they agree with the first bit for bit.
macro_rules! ways {
    ($f:ident / $batch:ident ($($a:ident),*), $zero:expr) => {{
        let b = [$($a.len()),*][0];
        let outs: Vec<std::sync::Arc<std::sync::Mutex<Vec<_>>>> =
            (0..WAYS).map(|_| std::sync::Arc::new(std::sync::Mutex::new(vec![$zero; b]))).collect();
        let o = outs.clone();
        let check = move || {
            let first = format!("{:?}", o[0].lock().unwrap());
            assert!(o.iter().all(|x| format!("{:?}", x.lock().unwrap()) == first), "{} differs", stringify!($f));
        };
        let ways: Vec<Way<'_>> = outs
            .into_iter()
            .enumerate()
            .map(|(w, out)| -> Way<'_> {
                Box::new(move || {
                    let o = &mut out.lock().unwrap()[..];
                    match w {
                        0 => o.iter_mut().enumerate().for_each(|(k, o)| *o = R::$f($(&$a[k]),*)),
                        1 => R::$batch::<f64x2>($($a,)* o),
                        2 => R::$batch::<f64x4>($($a,)* o),
                        3 => R::$batch::<f64x8>($($a,)* o),
                        4 => par::batch(o, |r, o| R::$batch::<f64x4>($(&$a[r.clone()],)* o)),
                        _ => par::batch(o, |r, o| R::$batch::<f64x8>($(&$a[r.clone()],)* o)),
                    }
                    black_box(o);
                })
            })
            .collect();
        (stringify!($f), ways, Box::new(check) as Box<dyn Fn()>)
    }};
}

fn main() {
    let rounds: usize = std::env::var("ROUNDS").map_or(21, |r| r.parse().expect("ROUNDS"));
    let batches: Vec<usize> = std::env::var("BATCHES")
        .unwrap_or_else(|_| "64 256 4096".into())
        .split_whitespace()
        .map(|b| b.parse().expect("BATCHES"))
        .collect();
    let _ = B;
    println!("N = {N}, {} threads, {rounds} rounds, median states per second (millions)", par::threads());
    println!("{:<30} {:>6} {:>8} {:>8} {:>8} {:>8} {:>12} {:>12} {:>8} {:>8}", "function", "batch", "1 state", "f64x2", "f64x4", "f64x8", "cores f64x4", "cores f64x8", "lanes ×", "cores ×");
    for batch in batches {
        let mut seed = 1u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
        };
        let mut states = || -> Vec<[f64; N]> { (0..batch).map(|_| core::array::from_fn(|_| rnd())).collect() };
        let (q, qd, tau) = (states(), states(), states());
        let (q, qd, tau) = (&q[..], &qd[..], &tau[..]);
        let (z, m) = ([0.0; N], [[0.0; N]; N]);
        let mut groups = vec![
            ways!(mass_matrix / mass_matrix_batch(q), m),
            ways!(nonlinear_effects / nonlinear_effects_batch(q, qd), z),
            ways!(mass_matrix_and_nonlinear_effects / mass_matrix_and_nonlinear_effects_batch(q, qd), (m, z)),
            ways!(inverse_dynamics / inverse_dynamics_batch(q, qd, tau), z),
            ways!(forward_dynamics / forward_dynamics_batch(q, qd, tau), z),
            ways!(inverse_dynamics_derivatives / inverse_dynamics_derivatives_batch(q, qd, tau), (m, m)),
            ways!(forward_dynamics_derivatives / forward_dynamics_derivatives_batch(q, qd, tau), (m, m, m)),
            ways!(mass_matrix_inverse / mass_matrix_inverse_batch(q), m),
        ];
        if let Ok(only) = std::env::var("FUNCTIONS") {
            groups.retain(|g| only.split_whitespace().any(|f| f == g.0));
        }
        let mut all: Vec<&mut Way<'_>> = groups.iter_mut().flat_map(|g| g.1.iter_mut()).collect();
        let rates = par::install(|| {
            // Calls per sample: back to back for about 200 µs.
            let calls: Vec<u32> = all
                .iter_mut()
                .map(|w| {
                    w();
                    let t0 = Instant::now();
                    w();
                    (200e-6 / t0.elapsed().as_secs_f64().max(1e-9)).ceil().clamp(1.0, 1e6) as u32
                })
                .collect();
            let mut samples = vec![Vec::with_capacity(rounds); all.len()];
            for round in 0..rounds {
                for off in 0..all.len() {
                    let i = (round + off) % all.len();
                    // One call untimed: the pool's threads, asleep while other ways ran, are
                    // awake when the sample starts, as they are in a loop of batches.
                    (all[i])();
                    let t0 = Instant::now();
                    for _ in 0..calls[i] {
                        (all[i])();
                    }
                    samples[i].push(f64::from(calls[i]) * batch as f64 / t0.elapsed().as_secs_f64());
                }
            }
            samples
                .into_iter()
                .map(|mut s| {
                    s.sort_by(f64::total_cmp);
                    s[s.len() / 2]
                })
                .collect::<Vec<f64>>()
        });
        for (g, r) in groups.iter().zip(rates.chunks(WAYS)) {
            (g.2)();
            let lanes = r[1].max(r[2]).max(r[3]);
            println!(
                "{:<30} {:>6} {:>8.2} {:>8.2} {:>8.2} {:>8.2} {:>12.2} {:>12.2} {:>8.2} {:>8.2}",
                g.0, batch, r[0] / 1e6, r[1] / 1e6, r[2] / 1e6, r[3] / 1e6, r[4] / 1e6, r[5] / 1e6,
                lanes / r[0], r[4].max(r[5]) / lanes
            );
        }
    }
}
RS
done
