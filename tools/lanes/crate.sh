# Sourced by tools/lanes/measure.sh and tools/lanes/grid.sh: `lanes_crate DIR PREFIX FEATURES
# MODEL` writes a crate under DIR/<model stem> that depends on this repository's `kanegen`
# (default features off, FEATURES on: a TOML list such as `"rayon"` or empty) and whose
# `src/main.rs` starts with `kanegen::dynamics!(R, MODEL)`, `N` and `B` (`LANES_BATCH`, default
# 256), followed by the
# program read from standard input; it builds the crate in release into DIR/target, runs it and
# prints `<stem> <its output>` (`LANES_CRATE_SEP` between them, a space unless set).
lanes_crate() {
  local dir="$1" prefix="$2" features="$3" model="$4"
  local root stem name crate
  root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
  stem="$(basename "${model%.*}")"
  name="${prefix}_${stem//[^a-zA-Z0-9_]/_}"
  crate="$dir/${stem}"
  mkdir -p "$crate/src"
  cat > "$crate/Cargo.toml" <<TOML
[package]
name = "$name"
version = "0.0.0"
edition = "2021"
publish = false
[dependencies]
kanegen = { path = "$root", default-features = false, features = [$features] }
[profile.release]
debug = false
[workspace]
TOML
  {
    printf 'kanegen::dynamics!(R, "%s");\nconst N: usize = R::N;\nconst B: usize = %s;\n' "$(realpath "$model")" "${LANES_BATCH:-256}"
    cat
  } > "$crate/src/main.rs"
  (cd "$crate" && CARGO_TARGET_DIR="$dir/target" cargo build --release -q)
  echo "$stem${LANES_CRATE_SEP:- }$("$dir/target/release/$name")"
}
