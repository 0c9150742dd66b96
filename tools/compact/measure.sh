#!/usr/bin/env bash
# Compile time and time per call of one `kanegen::dynamics!` crate per (form, model):
#   tools/compact/measure.sh FORM MODEL [MODEL...]    FORM: unrolled | compact | auto | default
# For each model, a scratch crate under target/compact-measure/ is built once (dependencies),
# then its own source touched and rebuilt with `cargo build --release`: the wall and user CPU
# seconds of that rebuild (the proc-macro run, type checking and LLVM) are printed, then the
# binary's ns per call of M+c and forward dynamics (median of 5 rounds); with DERIVS=1 also of
# inverse_dynamics_derivatives, forward_dynamics_derivatives and mass_matrix_inverse.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
form="$1"; shift
dir="$root/target/compact-measure"
mkdir -p "$dir"
for model in "$@"; do
  stem="$(basename "${model%.*}")"
  crate="$dir/${form}_${stem}"
  mkdir -p "$crate/src"
  cat > "$crate/Cargo.toml" <<TOML
[package]
name = "m_${form}_${stem//[^a-zA-Z0-9_]/_}"
version = "0.0.0"
edition = "2021"
publish = false
[dependencies]
kanegen = { path = "$root", default-features = false }
[profile.release]
debug = false
[workspace]
TOML
  key=""
  if [ "$form" != default ]; then key=", form = \"$form\""; fi
  derivs=""
  if [ "${DERIVS:-0}" = 1 ]; then
    derivs='
    let mut acc = 0.0f64;
    let calls = (calls / N).max(50);
    let mut t3 = Vec::new();
    for _ in 0..5 {
        let t = std::time::Instant::now();
        for k in 0..calls {
            q[k % N] += 1e-9;
            let (a, b) = R::inverse_dynamics_derivatives(std::hint::black_box(&q), std::hint::black_box(&qd), std::hint::black_box(&qd));
            acc += a.iter().chain(&b).flatten().sum::<f64>();
        }
        let id = t.elapsed().as_nanos() as f64 / calls as f64;
        let t = std::time::Instant::now();
        for k in 0..calls {
            q[k % N] += 1e-9;
            let (a, b, c) = R::forward_dynamics_derivatives(std::hint::black_box(&q), std::hint::black_box(&qd), std::hint::black_box(&qd));
            acc += a.iter().chain(&b).chain(&c).flatten().sum::<f64>();
        }
        let fdd = t.elapsed().as_nanos() as f64 / calls as f64;
        let t = std::time::Instant::now();
        for k in 0..calls {
            q[k % N] += 1e-9;
            acc += R::mass_matrix_inverse(std::hint::black_box(&q)).iter().flatten().sum::<f64>();
        }
        t3.push((id, fdd, t.elapsed().as_nanos() as f64 / calls as f64));
    }
    std::hint::black_box(acc);
    let med = |k: usize| { let mut v: Vec<f64> = t3.iter().map(|t| [t.0, t.1, t.2][k]).collect(); v.sort_by(f64::total_cmp); v[2] };
    print!(" ID-derivs {:.0} FD-derivs {:.0} Minv {:.0}", med(0), med(1), med(2));'
  fi
  cat > "$crate/src/main.rs" <<RS
kanegen::dynamics!(R, "$(realpath "$model")"$key);
fn main() {
    const N: usize = R::N;
    let mut q = [0.0f64; N];
    let mut qd = [0.0f64; N];
    for i in 0..N {
        q[i] = (i as f64 * 0.7).sin() * 2.0;
        qd[i] = (i as f64 * 1.3).cos() * 0.5;
    }
    let calls = (2_000_000 / (N * N)).max(200);
    let mut best = (f64::MAX, f64::MAX);
    let mut rounds = Vec::new();
    for _ in 0..5 {
        let t = std::time::Instant::now();
        let mut acc = 0.0;
        for k in 0..calls {
            q[k % N] += 1e-9;
            let (m, c) = R::mass_matrix_and_nonlinear_effects(std::hint::black_box(&q), std::hint::black_box(&qd));
            acc += m.iter().flatten().sum::<f64>() + c.iter().sum::<f64>();
        }
        let mc = t.elapsed().as_nanos() as f64 / calls as f64;
        let t = std::time::Instant::now();
        for k in 0..calls {
            q[k % N] += 1e-9;
            let a = R::forward_dynamics(std::hint::black_box(&q), std::hint::black_box(&qd), std::hint::black_box(&qd));
            acc += a.iter().sum::<f64>();
        }
        let fd = t.elapsed().as_nanos() as f64 / calls as f64;
        std::hint::black_box(acc);
        rounds.push((mc, fd));
        best = (best.0.min(mc), best.1.min(fd));
    }
    rounds.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mc = rounds[2].0;
    rounds.sort_by(|a, b| a.1.total_cmp(&b.1));
    let fd = rounds[2].1;
    print!("ns/call M+c {mc:.0} FD {fd:.0}");
    $derivs
    println!();
}
RS
  export CARGO_TARGET_DIR="$dir/target"
  (cd "$crate" && cargo build --release -q -p kanegen 2>/dev/null || true)
  (cd "$crate" && touch src/main.rs && /usr/bin/time -f "%e %U" -o "$crate/time" cargo build --release -q)
  read -r wall user < "$crate/time"
  bin="$CARGO_TARGET_DIR/release/m_${form}_${stem//[^a-zA-Z0-9_]/_}"
  echo "$form $stem compile wall ${wall}s user ${user}s $("$bin")"
done
# Re-timing without rebuilding: run the built binaries in alternation, e.g.
#   for p in 1 2 3; do for b in target/compact-measure/target/release/m_*; do echo "$b $($b)"; done; done
