//! Sweeps: one scene run many times, some of its numbers drawn at random or stepped through a
//! grid ([`spec`]: the sweep file), and a sweep cut into shards that run anywhere.
//!
//! Run `k`'s numbers depend on the sweep's seed, `k` and the parameters only: the grid point
//! `k / runs_per_point`, and the draws of stream `k` of a ChaCha8 generator seeded by the seed,
//! one per random parameter in file order. So any subset of the runs — a [`Shard`] — gives each
//! run exactly what the whole sweep gives it, and the runs of all shards are the runs of the
//! sweep, bit for bit (the same build on every machine: the simulation is IEEE arithmetic with
//! no run-time dispatch).

pub mod spec;

use crate::simulate::{simulate_to, Control, Summary};
use crate::sinks::Sample;
use anyhow::{bail, Result};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use rayon::prelude::*;
pub use spec::{Draw, Parameter, Sweep};
use std::ops::Range;
use std::sync::atomic::AtomicBool;

/// Shard `index` of `count`: the runs `⌊total·index/count⌋ .. ⌊total·(index+1)/count⌋`, a
/// contiguous block, the blocks of `0..count` covering the sweep once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// 0-based (a Slurm array's `SLURM_ARRAY_TASK_ID` with `--array=0-(count-1)`).
    pub index: u64,
    /// The number of shards.
    pub count: u64,
}

impl Shard {
    /// The whole sweep.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Parses `i/n` (`0 ≤ i < n`).
    ///
    /// # Errors
    /// Anything else, saying what is expected.
    pub fn parse(s: &str) -> Result<Shard> {
        let parsed = s
            .split_once('/')
            .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)));
        match parsed {
            Some((index, count)) if index < count => Ok(Shard { index, count }),
            _ => bail!("`{s}`: expected INDEX/COUNT with 0 <= INDEX < COUNT, as `3/16`"),
        }
    }

    /// This shard's runs of a sweep of `total` runs.
    #[must_use]
    pub fn runs(self, total: u64) -> Range<u64> {
        let at = |i: u64| (u128::from(total) * u128::from(i) / u128::from(self.count)) as u64;
        at(self.index)..at(self.index + 1)
    }
}

/// What became of one run.
#[derive(Clone, Debug)]
pub enum Outcome {
    /// The drawn numbers make an invalid scene: the scene's error, naming its key.
    Invalid(String),
    /// It ran (complete, or stopped: [`Summary::stopped`]); with its last output sample.
    Ran {
        /// The run's summary.
        summary: Box<Summary>,
        /// The last output sample (the final state).
        last: Sample,
    },
}

/// One run of a sweep.
#[derive(Clone, Debug)]
pub struct SweepRun {
    /// Its index in the sweep.
    pub index: u64,
    /// Its parameter values, in the sweep's order.
    pub values: Vec<f64>,
    /// What became of it.
    pub outcome: Outcome,
}

impl Sweep {
    /// The parameter values of run `k`: its grid point's `values`, and the draws of stream `k`.
    #[must_use]
    pub fn values(&self, k: u64) -> Vec<f64> {
        let mut point = k / self.runs_per_point;
        let mut grid = vec![0.0; self.parameters.len()];
        for (i, p) in self.parameters.iter().enumerate().rev() {
            if let Draw::Values(v) = &p.draw {
                let n = v.len() as u64;
                grid[i] = v[(point % n) as usize];
                point /= n;
            }
        }
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(k);
        self.parameters
            .iter()
            .zip(grid)
            .map(|(p, g)| match p.draw {
                Draw::Uniform { lo, hi } => rng.random_range(lo..hi),
                Draw::Normal { mean, std } => match Normal::new(mean, std) {
                    Ok(d) => d.sample(&mut rng),
                    Err(_) => f64::NAN,
                },
                Draw::Values(_) => g,
            })
            .collect()
    }

    /// Runs run `k` (no progress, stopped through `stop`).
    #[must_use]
    pub fn run(&self, k: u64, stop: Option<&AtomicBool>) -> SweepRun {
        let values = self.values(k);
        let scene = self
            .scene_text_for(&values)
            .and_then(|text| self.parse_scene(&text));
        let outcome = match scene {
            Err(e) => Outcome::Invalid(format!("{e:#}")),
            Ok(scene) => {
                let mut last = None;
                let mut sink = |s: &Sample| -> Result<()> {
                    last = Some(s.clone());
                    Ok(())
                };
                let control = Control {
                    progress: None,
                    stop,
                };
                match simulate_to(&scene, &mut sink, control) {
                    Ok(summary) => match last {
                        Some(last) => Outcome::Ran {
                            summary: Box::new(summary),
                            last,
                        },
                        None => Outcome::Invalid("the run gave no sample".into()),
                    },
                    Err(e) => Outcome::Invalid(format!("{e:#}")),
                }
            }
        };
        SweepRun {
            index: k,
            values,
            outcome,
        }
    }

    /// Runs `shard`'s runs on the threads of rayon's pool, in index order; `done` is called
    /// after each run.
    #[must_use]
    pub fn run_shard(
        &self,
        shard: Shard,
        stop: Option<&AtomicBool>,
        done: &(dyn Fn() + Sync),
    ) -> Vec<SweepRun> {
        let runs = shard.runs(self.runs());
        let first = runs.start;
        let len = usize::try_from(runs.end - runs.start).unwrap_or(usize::MAX);
        (0..len)
            .into_par_iter()
            .map(|i| {
                let r = self.run(first + i as u64, stop);
                done();
                r
            })
            .collect()
    }
}
