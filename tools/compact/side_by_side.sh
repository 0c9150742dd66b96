#!/usr/bin/env bash
# The compact form of this tree against the compact form of another revision, side by side:
#   tools/compact/side_by_side.sh [REV] [RUNS]        REV: default e3f5187, RUNS: default 9
# A copy of REV (git archive) and two scratch crates (one per tree, the same source: one
# `dynamics!(…, form = "compact")` per random chain N = 16, 32, 64 of benches/data) under
# target/compact-side-by-side/, built with $RUSTFLAGS (e.g. RUSTFLAGS="-C target-cpu=native");
# then RUNS alternating runs of the two binaries, pinned to one CPU when taskset exists. Each run
# prints, per function, the lowest ns per call over 41 rounds (each result passed whole to
# black_box); the table is the median over the runs of those minima, and new / old.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
rev="${1:-e3f5187}"
runs="${2:-9}"
dir="$root/target/compact-side-by-side"
mkdir -p "$dir"
if [ ! -d "$dir/old" ]; then
  mkdir -p "$dir/old"
  git -C "$root" archive "$rev" | tar -x -C "$dir/old"
fi
for side in old new; do
  tree="$root"; [ "$side" = old ] && tree="$dir/old"
  crate="$dir/bench_$side"
  mkdir -p "$crate/src"
  cat > "$crate/Cargo.toml" <<TOML
[package]
name = "side_$side"
version = "0.0.0"
edition = "2021"
publish = false
[dependencies]
kanegen = { path = "$tree", default-features = false }
[workspace]
TOML
  cp "$tree/Cargo.lock" "$crate/Cargo.lock"
  cat > "$crate/src/main.rs" <<RS
kanegen::dynamics!(C16, "$root/benches/data/random_n16.toml", form = "compact");
kanegen::dynamics!(C32, "$root/benches/data/random_n32.toml", form = "compact");
kanegen::dynamics!(C64, "$root/benches/data/random_n64.toml", form = "compact");
use std::hint::black_box;

/// The lowest mean ns per call over 41 rounds of \`calls\` calls.
fn time(calls: usize, mut f: impl FnMut() -> f64) -> f64 {
    let (mut best, mut acc) = (f64::MAX, 0.0);
    for _ in 0..41 {
        let t = std::time::Instant::now();
        for _ in 0..calls {
            acc += f();
        }
        best = best.min(t.elapsed().as_nanos() as f64 / calls as f64);
    }
    black_box(acc);
    best
}

macro_rules! model {
    (\$c:ident) => {{
        const N: usize = \$c::N;
        let q: [f64; N] = core::array::from_fn(|i| (i as f64 * 0.7).sin() * 2.0);
        let qd: [f64; N] = core::array::from_fn(|i| (i as f64 * 1.3).cos() * 0.5);
        let tau: [f64; N] = core::array::from_fn(|i| (i as f64 * 0.3).cos() * 3.0);
        let calls = (600_000 / (N * N)).max(100);
        let m = time(calls, || black_box(&\$c::mass_matrix(black_box(&q)))[N - 1][0]);
        println!("{N} M {m:.1}");
        let mc = time(calls, || {
            let mc = \$c::mass_matrix_and_nonlinear_effects(black_box(&q), black_box(&qd));
            let (m, c) = black_box(&mc);
            m[N - 1][0] + c[0]
        });
        println!("{N} M+c {mc:.1}");
        let fd = time(calls, || {
            black_box(&\$c::forward_dynamics(black_box(&q), black_box(&qd), black_box(&tau)))[0]
        });
        println!("{N} FD {fd:.1}");
    }};
}

fn main() {
    model!(C16);
    model!(C32);
    model!(C64);
}
RS
  (cd "$crate" && CARGO_TARGET_DIR="$dir/target_$side" cargo build --release -q)
done
pin=""; command -v taskset >/dev/null && pin="taskset -c 1"
python3 - "$runs" "$pin" "$dir/target_old/release/side_old" "$dir/target_new/release/side_new" <<'PY'
import collections, statistics, subprocess, sys
runs, pin, old, new = int(sys.argv[1]), sys.argv[2].split(), sys.argv[3], sys.argv[4]
res = {"old": collections.defaultdict(list), "new": collections.defaultdict(list)}
for r in range(runs):
    for side in (["old", "new"] if r % 2 == 0 else ["new", "old"]):
        out = subprocess.run(pin + [old if side == "old" else new], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            n, f, ns = line.split()
            res[side][(int(n), f)].append(float(ns))
print("| N | function | old ns | new ns | new / old |")
print("|---:|---|---:|---:|---:|")
for key in sorted(res["old"], key=lambda k: (k[0], ["M", "M+c", "FD"].index(k[1]))):
    o, n = statistics.median(res["old"][key]), statistics.median(res["new"][key])
    print(f"| {key[0]} | {key[1]} | {o:.0f} | {n:.0f} | {n / o:.3f} |")
PY
