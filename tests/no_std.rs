//! The `kanegen` facade without default features is `no_std`: its normal dependencies are only
//! the macro crate, the runtime and `libm`, the macro crates build none of the library's
//! optional parts (random chains, research scalars, Table 1, the simulator), and a `#![no_std]`
//! crate with one `dynamics!` and one `scene!` builds — for the host, and for `thumbv7em-none-eabihf` (no standard library exists there) when that target is
//! installed (`.ci/run` installs it; without it the cross build is skipped with a printed reason,
//! and fails where `KANEGEN_REQUIRE` requires it).

mod precondition;

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

/// `cargo tree -p kanegen --no-default-features -e normal --format {p}` with `args` after it.
fn tree_without_default_features(args: &[&str]) -> String {
    let out = cargo()
        .current_dir(root())
        .args([
            "tree",
            "-p",
            "kanegen",
            "--no-default-features",
            "-e",
            "normal",
            "--format",
            "{p}",
        ])
        .args(args)
        .output()
        .expect("run cargo tree");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The crates directly under `kanegen` in `cargo tree -e normal` without default features.
#[test]
fn facade_without_default_features_depends_on_the_macro_the_runtime_and_libm_only() {
    let text = tree_without_default_features(&["--depth", "1", "--prefix", "depth"]);
    let deps: Vec<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix('1'))
        .map(|l| l.split_whitespace().next().unwrap_or("").to_string())
        .collect();
    assert_eq!(
        deps,
        ["kanegen-macros", "kanegen-runtime", "libm"],
        "cargo tree:\n{text}"
    );
    // With the defaults, the CLI and the library crates come in.
    let out = cargo()
        .current_dir(root())
        .args(["tree", "-p", "kanegen", "-e", "normal", "--depth", "1"])
        .output()
        .expect("run cargo tree");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("kanegen-cli") && text.contains("kanegen-dynamics"));
}

/// Crates that `dynamics!` and `scene!` do without: the model's random chains (`rand`), the
/// research scalars (`qd`, `num-bigint`), Table 1 (`serde_json`), the simulator and what only it
/// uses (`nalgebra`, `anyhow`, `indicatif`). `docs/build.md` measures what leaving them out saves.
const NOT_IN_THE_MACRO: [&str; 9] = [
    "rand",
    "rand_chacha",
    "qd",
    "num-bigint",
    "serde_json",
    "kanegen-sim",
    "nalgebra",
    "anyhow",
    "indicatif",
];

/// Every crate that the facade without default features builds, macro crates included.
#[test]
fn facade_without_default_features_builds_only_what_the_macros_use() {
    let text = tree_without_default_features(&["--prefix", "none"]);
    let crates: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(crates.contains(&"kanegen-scene"), "cargo tree:\n{text}");
    for name in NOT_IN_THE_MACRO {
        assert!(
            !crates.contains(&name),
            "`{name}` is in the facade's graph without default features; the proc-macros do \
             not use it (cargo tree:\n{text})"
        );
    }
}

fn build_no_std_crate(target: Option<&str>) {
    let dir = root().join("tests/no_std_crate");
    let target_dir: PathBuf = root().join("target/no_std_crate");
    let mut cmd = cargo();
    cmd.current_dir(&dir)
        .env("CARGO_TARGET_DIR", &target_dir)
        .env_remove("RUSTFLAGS")
        .args(["build", "--release", "--locked", "--offline"]);
    if let Some(t) = target {
        cmd.args(["--target", t]);
    }
    let out = cmd.output().expect("run cargo build");
    assert!(
        out.status.success(),
        "no_std crate ({}) does not build:\n{}",
        target.unwrap_or("host"),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn no_std_crate_with_dynamics_builds() {
    build_no_std_crate(None);
    const TARGET: &str = "thumbv7em-none-eabihf";
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .map(|o| {
            String::from_utf8_lossy(&o.stdout)
                .lines()
                .any(|l| l.trim() == TARGET)
        })
        .unwrap_or(false);
    if installed {
        build_no_std_crate(Some(TARGET));
        eprintln!("built the no_std crate for {TARGET}");
    } else {
        precondition::absent(
            "no_std_target",
            &format!("the {TARGET} target is not installed (`rustup target add {TARGET}`)"),
        );
    }
}
