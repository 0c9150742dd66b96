//! `kanegen bench`: nanoseconds per call of generated and interpreted dynamics for SSRMS, measured
//! side by side in one process run.
//!
//! These machines are shared and noisy, so absolute numbers mean little; the report is built for
//! ratios. Every candidate runs in each of many short rounds, in rotating order, and the median
//! round is reported: a burst of load on the machine hits every candidate of that round alike.

use kanegen_core::random::{random_vec, rng};
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

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Model measured.
    pub model: String,
    /// Degrees of freedom.
    pub n: usize,
    /// Rounds per candidate.
    pub rounds: usize,
    /// Calls per round.
    pub calls_per_round: usize,
    /// Results.
    pub results: Vec<BenchLine>,
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
    let k = candidates.len();
    let mut samples: Vec<Vec<f64>> = vec![Vec::with_capacity(rounds); k];
    // Warm-up.
    for c in candidates.iter_mut() {
        for (q, qd) in &states {
            black_box((c.2)(black_box(q), black_box(qd)));
        }
    }
    for round in 0..rounds {
        for off in 0..k {
            let i = (round + off) % k;
            let f = &mut candidates[i].2;
            let t0 = Instant::now();
            let mut acc = 0.0;
            for call in 0..calls {
                let (q, qd) = &states[call % states.len()];
                acc += f(black_box(q), black_box(qd));
            }
            black_box(acc);
            samples[i].push(t0.elapsed().as_nanos() as f64 / calls as f64);
        }
    }
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

/// Human-readable table.
pub fn render_text(r: &BenchReport) -> String {
    use std::fmt::Write;
    let mut s = format!(
        "{} (N = {}), {} rounds × {} calls, median ns per call\n\n{:<20} {:<32} {:>12} {:>22} {:>10}\n",
        r.model, r.n, r.rounds, r.calls_per_round, "function", "candidate", "ns/call", "range", "× first"
    );
    for l in &r.results {
        let _ = writeln!(
            s,
            "{:<20} {:<32} {:>12.1} {:>10.1} – {:>9.1} {:>10.2}",
            l.function, l.name, l.ns, l.ns_range[0], l.ns_range[1], l.ratio_to_first
        );
    }
    s
}

/// The SSRMS model the generated code was emitted from (embedded, so the command runs anywhere).
pub const SSRMS_URDF: &str =
    include_str!("../../tests/data/reference/ssrms_nguyen_hughes_1994.urdf");

/// Generated SSRMS code against the interpreted f64 algorithms, side by side.
pub fn bench_ssrms(rounds: usize, calls: usize) -> anyhow::Result<BenchReport> {
    use kanegen_core::{Algorithm, Loads};
    use kanegen_generated::ssrms::Ssrms;
    let chain = kanegen_core::io::parse_urdf(SSRMS_URDF)?;
    let p = chain.params::<f64>();
    let n = chain.dof();
    let arr = |x: &[f64]| -> [f64; 7] { core::array::from_fn(|i| x[i]) };
    let zero = [0.0; 7];
    let mut c: Vec<Candidate<'_>> = Vec::new();
    let sum2 = |a: [[f64; 7]; 7], b: [f64; 7]| a[0][0] + a[6][6] + b[0] + b[6];
    c.push((
        "generated".into(),
        "A+b".into(),
        Box::new(move |q, qd| {
            sum2(
                Ssrms::mass_matrix(&arr(q)),
                Ssrms::bias(&arr(q), &arr(qd), &zero),
            )
        }),
    ));
    for alg in Algorithm::ALL {
        let p = &p;
        c.push((
            format!("interpreted {alg}"),
            "A+b".into(),
            Box::new(move |q, qd| {
                let d = alg.dynamics(p, q, qd, &Loads::default());
                d.a[0][0] + d.a[6][6] + d.b[0] + d.b[6]
            }),
        ));
    }
    c.push((
        "generated".into(),
        "forward_dynamics".into(),
        Box::new(move |q, qd| Ssrms::forward_dynamics(&arr(q), &arr(qd), &zero)[6]),
    ));
    for alg in [
        Algorithm::Recurrent,
        Algorithm::CrbaBase,
        Algorithm::Spatial,
    ] {
        let p = &p;
        c.push((
            format!("interpreted {alg}"),
            "forward_dynamics".into(),
            Box::new(move |q, qd| alg.forward_dynamics(p, q, qd, &Loads::default())[6]),
        ));
    }
    c.push((
        "generated".into(),
        "inverse_dynamics".into(),
        Box::new(move |q, qd| Ssrms::inverse_dynamics(&arr(q), &arr(qd), &arr(qd))[6]),
    ));
    for alg in [
        Algorithm::Recurrent,
        Algorithm::CrbaBase,
        Algorithm::Spatial,
    ] {
        let p = &p;
        c.push((
            format!("interpreted {alg}"),
            "inverse_dynamics".into(),
            Box::new(move |q, qd| alg.inverse_dynamics(p, q, qd, qd, &Loads::default())[6]),
        ));
    }
    Ok(BenchReport {
        model: chain.name().into(),
        n,
        rounds,
        calls_per_round: calls,
        results: measure(n, c, rounds, calls),
    })
}
