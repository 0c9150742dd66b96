//! Where a run's samples go: the [`Sample`], the [`Sink`] trait, and [`Decimated`], a bounded
//! copy for plots.

use anyhow::Result;

/// One output sample.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Time.
    pub t: f64,
    /// The state vector (see the module doc).
    pub x: Vec<f64>,
    /// Energy drift (relative) at `t`, when monitored.
    pub energy_drift: Option<f64>,
    /// Linear and angular momentum drift (relative) at `t`, when monitored.
    pub momentum_drift: Option<(f64, f64)>,
}

/// Where the output samples of a run go, one at a time, as they are produced (the CLI's CSV
/// writer and plot buffer, [`Decimated`], or a closure).
pub trait Sink {
    /// Takes one sample. An error stops the run; [`simulate_to`] returns it.
    ///
    /// # Errors
    /// Whatever the sink cannot do (a full disk).
    fn sample(&mut self, s: &Sample) -> Result<()>;
}

impl<F: FnMut(&Sample) -> Result<()>> Sink for F {
    fn sample(&mut self, s: &Sample) -> Result<()> {
        self(s)
    }
}

/// A bounded, evenly decimated copy of a run's samples, for plots: at most `cap` samples (every
/// `stride`-th; when full, every other one is dropped and the stride doubles), plus the last
/// sample seen. Memory stays `O(cap)` however long the run.
#[derive(Clone, Debug)]
pub struct Decimated {
    cap: usize,
    stride: usize,
    seen: usize,
    kept: Vec<Sample>,
    last: Option<Sample>,
}

impl Decimated {
    /// An empty buffer of at most `cap` (≥ 2) samples.
    #[must_use]
    pub fn new(cap: usize) -> Self {
        Decimated {
            cap: cap.max(2),
            stride: 1,
            seen: 0,
            kept: Vec::new(),
            last: None,
        }
    }

    /// The kept samples in time order, the last sample seen at the end.
    #[must_use]
    pub fn into_samples(self) -> Vec<Sample> {
        let mut v = self.kept;
        if let Some(l) = self.last {
            if v.last().is_none_or(|k| k.t != l.t) {
                v.push(l);
            }
        }
        v
    }
}

impl Sink for Decimated {
    fn sample(&mut self, s: &Sample) -> Result<()> {
        // `stride` is a power of two.
        if self.seen & (self.stride - 1) == 0 {
            if self.kept.len() == self.cap {
                let mut i = 0;
                self.kept.retain(|_| {
                    i += 1;
                    i % 2 == 1
                });
                self.stride *= 2;
            }
            if self.seen & (self.stride - 1) == 0 {
                self.kept.push(s.clone());
            }
        }
        self.seen += 1;
        self.last = Some(s.clone());
        Ok(())
    }
}
