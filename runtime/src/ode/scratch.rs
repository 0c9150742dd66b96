//! Caller-provided scratch memory of the integrators, so that no run allocates: on the stack
//! ([`ArrayScratch`], sized by the `*_scratch` functions of each method at compile time) or,
//! with `std`, a growing heap buffer ([`VecScratch`]) allocated on a run's first use.

/// Scratch memory: `f64`s for stage vectors and matrices, `usize`s for LU pivots.
pub trait Scratch {
    /// The first `floats` floats and `pivots` indices, or `None` when the storage holds fewer.
    fn get(&mut self, floats: usize, pivots: usize) -> Option<(&mut [f64], &mut [usize])>;
}

/// Scratch of a fixed size on the stack: `F` floats, `P` pivots (`P = 0` except for
/// [`rosenbrock`](super::rosenbrock())). Sized, e.g. for a state of dimension 14, as
/// `ArrayScratch<{ kanegen_runtime::ode::rk4::scratch_len(14) }>`.
#[derive(Clone, Debug)]
pub struct ArrayScratch<const F: usize, const P: usize = 0> {
    floats: [f64; F],
    pivots: [usize; P],
}

impl<const F: usize, const P: usize> ArrayScratch<F, P> {
    /// Zeroed scratch.
    #[must_use]
    pub const fn new() -> Self {
        ArrayScratch {
            floats: [0.0; F],
            pivots: [0; P],
        }
    }
}

impl<const F: usize, const P: usize> Default for ArrayScratch<F, P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const F: usize, const P: usize> Scratch for ArrayScratch<F, P> {
    fn get(&mut self, floats: usize, pivots: usize) -> Option<(&mut [f64], &mut [usize])> {
        Some((
            self.floats.get_mut(..floats)?,
            self.pivots.get_mut(..pivots)?,
        ))
    }
}

/// Scratch on the heap that grows to what a run asks for (once per size: a run of the
/// interpreted simulator allocates it at its start, not per step).
#[cfg(feature = "std")]
#[derive(Clone, Debug, Default)]
pub struct VecScratch {
    floats: std::vec::Vec<f64>,
    pivots: std::vec::Vec<usize>,
}

#[cfg(feature = "std")]
impl Scratch for VecScratch {
    fn get(&mut self, floats: usize, pivots: usize) -> Option<(&mut [f64], &mut [usize])> {
        if self.floats.len() < floats {
            self.floats.resize(floats, 0.0);
        }
        if self.pivots.len() < pivots {
            self.pivots.resize(pivots, 0);
        }
        Some((&mut self.floats[..floats], &mut self.pivots[..pivots]))
    }
}
