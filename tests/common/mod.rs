//! Helpers shared by the tests (`mod common;`): the project root, scene files and texts, the
//! binary, the comparison of a compiled run (`kanegen::scene!`) with an interpreted one, and the
//! numbers of a reference file.
// Each test crate uses some of them.
#![allow(dead_code)]

pub mod linearize;

use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::Run;
use std::path::PathBuf;

/// The project root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The scene file `file` (relative to the root).
pub fn load(file: &str) -> Scene {
    Scene::load(&root().join(file)).unwrap_or_else(|e| panic!("{file}: {e:#}"))
}

/// A scene from its text (paths relative to the root).
pub fn scene(text: &str) -> Scene {
    Scene::parse(text, &root()).unwrap_or_else(|e| panic!("{e:#}"))
}

/// The error a scene text gives (panics when it is accepted).
pub fn scene_err(text: &str) -> String {
    match Scene::parse(text, &root()) {
        Ok(_) => panic!("scene accepted:\n{text}"),
        Err(e) => format!("{e:#}"),
    }
}

/// Runs the `kanegen` binary with `args` in the project root and returns its output, after
/// checking it succeeded (its stderr is the failure message).
pub fn kanegen(args: &[&str]) -> std::process::Output {
    succeeded(
        std::process::Command::new(env!("CARGO_BIN_EXE_kanegen"))
            .args(args)
            .current_dir(root()),
    )
}

/// Runs `cmd` and returns its output, after checking it succeeded (its stderr is the failure
/// message).
pub fn succeeded(cmd: &mut std::process::Command) -> std::process::Output {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{cmd:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `max |a_i − b_i|`.
pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Worst `|x_c − x_i| / (1 + |x_i|)` over the samples of a compiled (`c`) and an interpreted
/// (`i`) run, after checking they sample at the same times.
pub fn worst<const D: usize>(name: &str, c: &[(f64, [f64; D])], i: &Run) -> f64 {
    assert_eq!(c.len(), i.samples.len(), "{name}: number of samples");
    let mut w: f64 = 0.0;
    for ((tc, xc), s) in c.iter().zip(&i.samples) {
        assert!(
            (tc - s.t).abs() <= 1e-12 * (1.0 + s.t),
            "{name}: t {tc} vs {}",
            s.t
        );
        assert_eq!(s.x.len(), D, "{name}: state length");
        for (a, b) in xc.iter().zip(&s.x) {
            w = w.max((a - b).abs() / (1.0 + b.abs()));
        }
    }
    w
}

/// Every number of a JSON value, nested arrays flattened in order.
pub fn nums(v: &serde_json::Value) -> Vec<f64> {
    match v {
        serde_json::Value::Array(xs) => xs.iter().flat_map(nums).collect(),
        serde_json::Value::Number(n) => vec![n.as_f64().unwrap()],
        other => panic!("not a number: {other}"),
    }
}

/// Items named like every primitive type, prelude item and built-in macro that the expansion of
/// `dynamics!` or `scene!` could name, and `core`, for the module the macro is called in: an
/// expansion that names one of those without its full path means something else there and does
/// not compile (`tests/macro.rs`, `tests/scene_macro.rs`).
#[allow(unused_macros)]
macro_rules! shadowing_items {
    () => {
        pub struct f64;
        pub struct f32;
        pub struct usize;
        pub struct u64;
        pub struct u8;
        pub struct bool;
        pub struct str;
        pub struct Option;
        pub struct Some;
        pub struct None;
        pub struct Result;
        pub struct Ok;
        pub struct Err;
        pub struct Default;
        pub struct TryFrom;
        pub struct Iterator;
        pub struct FnMut;
        pub mod core {}
        // Takes no file: an unqualified `include_bytes!("…")` does not compile.
        #[allow(unused_macros)]
        macro_rules! include_bytes {
            () => {};
        }
    };
}
#[allow(unused_imports)]
pub(crate) use shadowing_items;
