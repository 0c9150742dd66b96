//! # kanegen-cli
//!
//! The report stage of kanegen's pipeline: the `kanegen` command line. Each command reads files,
//! calls the library crates (`kanegen-model`, `-dynamics`, `-trace`, `-codegen`, `-sim`) and
//! renders what they return; no library crate depends on this one.
//!
//! - [`commands`]: one module per command, as library functions the tests call directly;
//! - [`reports`]: reports computed from several library calls (the accuracy report);
//! - [`plots`]: SVG figures; [`timing`]: side-by-side timing; [`states`]: state files;
//!   [`scene_spec`]: a scene's effects as a trace spec;
//! - [`app`]: the command line; [`output`]: standard output and output files (checked before
//!   work, atomic, never overwritten without `--force`); [`progress`]: progress bars.
#![warn(missing_docs)]

pub mod app;
pub mod commands;
pub mod output;
pub mod plots;
pub mod progress;
pub mod reports;
pub mod scene_spec;
pub mod states;
pub mod timing;

use std::io::Write;
use std::process::ExitCode;

/// The `kanegen` binary: runs the command; on failure prints `Error: ` and the error chain on
/// one line (with `-v`/`--verbose` or `KANEGEN_BACKTRACE=1`: the chain and a backtrace) and exits
/// with 1. A closed standard output exits 0 quietly; a simulation stopped by Ctrl-C exits 130
/// after writing its partial outputs.
pub fn main() -> ExitCode {
    use clap::Parser;
    let cli = match app::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => e.exit(),
    };
    let verbose = cli.verbose
        || std::env::var_os("KANEGEN_BACKTRACE").is_some_and(|v| !v.is_empty() && v != "0");
    if verbose {
        // anyhow captures a backtrace when an error is created with this set.
        std::env::set_var("RUST_LIB_BACKTRACE", "1");
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match app::run(cli, &mut out, app::Interactive(true)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if output::is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) if e.is::<app::Interrupted>() => {
            let _ = writeln!(std::io::stderr(), "interrupted");
            ExitCode::from(130)
        }
        Err(e) => {
            let _ = if verbose {
                writeln!(std::io::stderr(), "Error: {e:?}")
            } else {
                writeln!(std::io::stderr(), "Error: {e:#}")
            };
            ExitCode::FAILURE
        }
    }
}
