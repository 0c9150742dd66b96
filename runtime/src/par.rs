//! Batches across threads (feature `rayon`; a target with the standard library): one generic helper that splits a batch's
//! output into one chunk per thread of `rayon`'s pool and runs a serial batch — a generated
//! `NAME_batch::<S>` — on each chunk, on the matching ranges of the input slices.
//!
//! Every chunk but the last holds a multiple of [`CHUNK_MULTIPLE`] states, so each thread's
//! batch runs full chunks of lanes for every lane type (1, 2, 4 or 8 lanes); nothing is allocated
//! per state (the split is one `rayon` job per chunk but the caller's, in a scope in place over
//! the output slice). Each state's result is
//! computed by the same code as in the serial batch, so the results equal the serial batch's bit
//! for bit, for any number of threads. A loop of batches runs inside [`install`], on a thread of
//! the pool, so that no batch waits for the operating system to wake a thread.
//!
//! ```
//! use kanegen_runtime::par;
//! let x: Vec<f64> = (0..1000).map(f64::from).collect();
//! let mut out = vec![0.0; x.len()];
//! // A serial batch: out[k] = f(x[k]) over the slices it is given.
//! let square = |x: &[f64], out: &mut [f64]| {
//!     for (o, x) in out.iter_mut().zip(x) {
//!         *o = x * x;
//!     }
//! };
//! par::batch(&mut out, |range, out| square(&x[range], out));
//! assert!(out.iter().zip(&x).all(|(o, x)| *o == x * x));
//! ```

use core::ops::Range;

/// The states of every chunk but the last are a multiple of this: the widest lane type's lane
/// count (`f32x8`), so every lane type's batch runs full chunks of lanes within a thread's chunk.
pub const CHUNK_MULTIPLE: usize = 8;

/// The states per thread's chunk for a batch of `n` states over `threads` threads: `n / threads`
/// rounded up to a multiple of [`CHUNK_MULTIPLE`] (0 for an empty batch).
#[must_use]
pub fn chunk_len(n: usize, threads: usize) -> usize {
    n.div_ceil(threads.max(1)).div_ceil(CHUNK_MULTIPLE) * CHUNK_MULTIPLE
}

/// The threads of the current `rayon` pool, over which [`batch`] splits (the global pool: one
/// per CPU unless `RAYON_NUM_THREADS` says otherwise).
#[must_use]
pub fn threads() -> usize {
    rayon::current_num_threads()
}

/// `f(range, chunk)` for chunks of `out` on the threads of the current `rayon` pool, one chunk per
/// thread ([`chunk_len`] states each), the first on the calling thread: `chunk` is
/// `&mut out[range]`. `f` runs a serial batch on
/// the inputs' `range`, e.g. for a generated `Ur5`
/// `|r, out| Ur5::forward_dynamics_batch::<f64x4>(&q[r.clone()], &qd[r.clone()], &tau[r], out)`
/// (the inputs at least as long as `out`).
pub fn batch<R: Send>(out: &mut [R], f: impl Fn(Range<usize>, &mut [R]) + Sync) {
    let len = chunk_len(out.len(), threads());
    if len == 0 {
        return;
    }
    let f = &f;
    let mut chunks = out.chunks_mut(len).enumerate();
    let first = chunks.next();
    // The calling thread runs the first chunk itself while the pool's threads take the others
    // (a scope in place: the caller does not hand its own share to the pool and wait).
    rayon::in_place_scope(|s| {
        for (c, chunk) in chunks {
            s.spawn(move |_| f(c * len..c * len + chunk.len(), chunk));
        }
        if let Some((c, chunk)) = first {
            f(c * len..c * len + chunk.len(), chunk);
        }
    });
}

/// `f()` on a thread of the current `rayon` pool (the global pool unless the caller is already on
/// one of a pool's threads, where `f` runs at once): the loop that calls [`batch`] after batch —
/// a sampler's rollouts, a horizon's knots tick after tick — belongs inside it.
///
/// Called from one of the pool's threads, [`batch`] waits for the other threads' chunks as the
/// pool's threads wait, taking work and spinning for a while before sleeping, and the threads that
/// finished their chunks are still awake when the next batch comes. Called from any other thread,
/// each [`batch`] puts the caller to sleep until the last chunk is done and wakes it through
/// the operating system: 10–60 µs per call on a 2-CPU virtual machine (docs/performance.md), more
/// than a batch of 256 states takes.
pub fn install<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    rayon::scope(|_| f())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chunks are multiples of 8 states covering the batch with one chunk per thread at most.
    #[test]
    fn chunks_cover_the_batch() {
        assert_eq!(chunk_len(0, 2), 0);
        assert_eq!(chunk_len(1, 2), 8);
        assert_eq!(chunk_len(256, 2), 128);
        assert_eq!(chunk_len(257, 2), 136);
        assert_eq!(chunk_len(100, 3), 40);
        assert_eq!(chunk_len(5, 0), 8);
        for n in 0..200 {
            for threads in 1..5 {
                let len = chunk_len(n, threads);
                assert_eq!(len % CHUNK_MULTIPLE, 0);
                assert!(n == 0 || len * threads >= n);
            }
        }
    }

    /// Every state's result is written once, at its own index, on a pool of three threads.
    #[test]
    fn each_state_once_at_its_index() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        for n in [0, 1, 7, 8, 9, 64, 101] {
            let mut all = [usize::MAX; 101];
            let out = &mut all[..n];
            pool.install(|| {
                batch(out, |r, out| {
                    assert_eq!(r.len(), out.len());
                    for (o, k) in out.iter_mut().zip(r) {
                        assert_eq!(*o, usize::MAX);
                        *o = k;
                    }
                });
            });
            assert!(out.iter().enumerate().all(|(k, o)| *o == k), "n = {n}");
        }
    }

    /// `install` runs its closure on a thread of a pool (here from the test's own thread, which
    /// is on none), and a batch inside it gives every state once, at its index.
    #[test]
    fn install_runs_on_a_pool_thread() {
        assert!(rayon::current_thread_index().is_none());
        let mut out = [usize::MAX; 37];
        let on_pool = install(|| {
            batch(&mut out, |r, out| {
                for (o, k) in out.iter_mut().zip(r) {
                    *o = k;
                }
            });
            rayon::current_thread_index().is_some()
        });
        assert!(on_pool);
        assert!(out.iter().enumerate().all(|(k, o)| *o == k));
    }
}
