//! The `kanegen` command line (feature `cli`): see `kanegen --help` and README.md.

fn main() -> std::process::ExitCode {
    kanegen::cli::main()
}
