//! What a test does when a precondition it cannot provide itself is absent (`mod precondition;`):
//! it says so, and fails where the precondition is required.
//!
//! `KANEGEN_REQUIRE` lists the preconditions that must hold (comma-separated names, or `all`);
//! `.ci/run` sets it, so a CI run fails instead of passing by skipping. Elsewhere the test prints
//! `SKIPPED (name): why` and appends the same line to `target/test-skips.log`, which `.ci/run`
//! prints after the tests (cargo hides a passing test's output).

use std::io::Write;

/// Reports that precondition `name` is absent (`why`): panics when `KANEGEN_REQUIRE` names it
/// (or says `all`), else records the skip and returns, for the caller to return.
pub fn absent(name: &str, why: &str) {
    let required = std::env::var("KANEGEN_REQUIRE").unwrap_or_default();
    if required
        .split(',')
        .map(str::trim)
        .any(|r| r == name || r == "all")
    {
        panic!("required precondition `{name}` is absent: {why} (KANEGEN_REQUIRE={required})");
    }
    let line = format!("SKIPPED ({name}): {why}");
    eprintln!("{line}");
    let log = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-skips.log");
    if let Ok(mut f) = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(log)
    {
        let _ = writeln!(f, "{line}");
    }
}
