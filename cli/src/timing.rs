//! Side-by-side timing: every candidate runs in each of many short rounds, in rotating order,
//! and the median round is reported. These machines are shared and noisy, so absolute numbers
//! mean little; the results are built for ratios (a burst of load hits every candidate of that
//! round alike). Used by `kanegen bench` and the accuracy report.

use kanegen_model::random::{random_vec, rng};
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

/// One measured candidate.
#[derive(Clone, Debug, Serialize)]
pub struct BenchLine {
    /// What was called, e.g. `generated` or `interpreted recurrent`.
    pub name: String,
    /// Which computation (`A+b`, `forward_dynamics`, …).
    pub function: String,
    /// Median nanoseconds per call over the rounds.
    pub ns: f64,
    /// Smallest and largest round, ns per call.
    pub ns_range: [f64; 2],
    /// `ns / ns of the baseline of this function` (the first candidate of the function).
    pub ratio_to_first: f64,
}

/// A candidate: a name, a function label and a closure computing something from `(q, qd)`.
pub type Candidate<'a> = (String, String, Box<dyn FnMut(&[f64], &[f64]) -> f64 + 'a>);

/// Measures candidates side by side: `rounds` rounds, each calling every candidate `calls` times
/// on a fixed set of random states, candidates in rotating order.
pub fn measure(
    n: usize,
    mut candidates: Vec<Candidate<'_>>,
    rounds: usize,
    calls: usize,
) -> Vec<BenchLine> {
    let mut r = rng(2026);
    let states: Vec<(Vec<f64>, Vec<f64>)> = (0..16)
        .map(|_| (random_vec(&mut r, n, 3.0), random_vec(&mut r, n, 0.1)))
        .collect();
    // Warm-up.
    for c in candidates.iter_mut() {
        for (q, qd) in &states {
            black_box((c.2)(black_box(q), black_box(qd)));
        }
    }
    let samples = rounds_side_by_side(candidates.len(), rounds, |i| {
        let f = &mut candidates[i].2;
        let t0 = Instant::now();
        let mut acc = 0.0;
        for call in 0..calls {
            let (q, qd) = &states[call % states.len()];
            acc += f(black_box(q), black_box(qd));
        }
        black_box(acc);
        t0.elapsed().as_nanos() as f64 / calls as f64
    });
    let mut lines: Vec<BenchLine> = candidates
        .iter()
        .zip(samples)
        .map(|(c, mut s)| {
            s.sort_by(f64::total_cmp);
            BenchLine {
                name: c.0.clone(),
                function: c.1.clone(),
                ns: s[s.len() / 2],
                ns_range: [s[0], s[s.len() - 1]],
                ratio_to_first: 1.0,
            }
        })
        .collect();
    let firsts: Vec<(String, f64)> = {
        let mut seen: Vec<(String, f64)> = Vec::new();
        for l in &lines {
            if !seen.iter().any(|(f, _)| f == &l.function) {
                seen.push((l.function.clone(), l.ns));
            }
        }
        seen
    };
    for l in &mut lines {
        let base = firsts
            .iter()
            .find(|(f, _)| f == &l.function)
            .map_or(l.ns, |x| x.1);
        l.ratio_to_first = l.ns / base;
    }
    lines
}

/// `rounds` rounds of `k` candidates in rotating order (round `r` starts at candidate `r mod k`):
/// `run(i)` runs candidate `i` once and returns its measure; the measures per candidate.
pub fn rounds_side_by_side(
    k: usize,
    rounds: usize,
    mut run: impl FnMut(usize) -> f64,
) -> Vec<Vec<f64>> {
    let mut samples: Vec<Vec<f64>> = vec![Vec::with_capacity(rounds); k];
    for round in 0..rounds {
        for off in 0..k {
            let i = (round + off) % k;
            samples[i].push(run(i));
        }
    }
    samples
}
