//! What handing half a batch to another thread costs: two chunks of spinning work (`US`
//! microseconds each, from the command line; default 0.5, 2 and 10) run one after the other, by
//! `par`'s split called from an outside thread, and by the same split called from a thread of
//! the pool (`par::install`), 2,000 calls each, median and 10th/90th percentile µs per call.
//!
//! ```sh
//! taskset -c 0,1 cargo run --release -p kanegen-runtime --features rayon --example handoff
//! ```

use kanegen_runtime::par;
use std::time::Instant;

/// Spins for `us` microseconds.
fn work(us: f64) {
    let t = Instant::now();
    while t.elapsed().as_secs_f64() * 1e6 < us {
        std::hint::spin_loop();
    }
}

/// Two chunks of `us` µs through `par::batch` (two states, one per thread on 2 CPUs).
fn split(us: f64) {
    let mut out = [0u8; 2 * par::CHUNK_MULTIPLE];
    par::batch(&mut out, |_, _| work(us));
}

/// Median, 10th and 90th percentile µs per call of `f` over 2,000 calls.
fn time(label: &str, f: &dyn Fn()) {
    let mut v: Vec<f64> = (0..2000)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    v.sort_by(f64::total_cmp);
    println!(
        "  {label:<34} median {:>6.2} µs   p10 {:>6.2}   p90 {:>6.2}",
        v[1000], v[200], v[1800]
    );
}

fn main() {
    let sizes: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![0.5, 2.0, 10.0]
    } else {
        sizes
    };
    println!("{} threads", par::threads());
    for us in sizes {
        println!("two chunks of {us} µs:");
        time("one after the other", &|| {
            work(us);
            work(us);
        });
        time("par::batch from an outside thread", &|| split(us));
        par::install(|| time("par::batch inside par::install", &|| split(us)));
    }
}
