//! # kanegen-cli
//!
//! The report stage of kanegen's pipeline: the `kanegen` command line. Each command reads files,
//! calls the library crates (`kanegen-model`, `-dynamics`, `-trace`, `-codegen`, `-sim`) and
//! renders what they return; no library crate depends on this one.
//!
//! - [`commands`]: one module per command, as library functions the tests call directly;
//! - [`reports`]: reports computed from several library calls (the accuracy report);
//! - [`plots`]: SVG figures; [`timing`]: side-by-side timing; [`states`]: state files;
//!   [`scene_spec`]: a scene's effects as a trace spec.
#![warn(missing_docs)]

mod app;
pub mod commands;
pub mod plots;
pub mod reports;
pub mod scene_spec;
pub mod states;
pub mod timing;

/// The `kanegen` binary: runs the command and prints an error chain on failure (exit code 1).
pub fn main() -> std::process::ExitCode {
    match app::run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
