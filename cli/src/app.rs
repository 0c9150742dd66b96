//! The `kanegen` command line: arguments and dispatch to [`crate::commands`].

use crate::commands;
use crate::output::{print, OutputDir, OutputFile};
use crate::progress::Progress;
use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use kanegen_dynamics::Methods;
use kanegen_model::{BaseKind, Model};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

#[derive(Parser)]
#[command(
    name = "kanegen",
    version,
    about = "Equations of motion of space manipulators: evaluate, count, reproduce the paper's Table 1",
    long_about = None
)]
/// The command line: a command and the global `--verbose` flag.
pub struct Cli {
    /// On an error, print the whole chain with a backtrace (also `KANEGEN_BACKTRACE=1`).
    #[arg(short, long, global = true)]
    pub verbose: bool,
    #[command(subcommand)]
    command: Command,
}

fn parse_forced(s: &str) -> Result<Methods, String> {
    kanegen_codegen::forced_algorithm(s).map_err(|e| e.0)
}

fn parse_algorithm(s: &str) -> Result<Methods, String> {
    Methods::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Methods::PRESETS.iter().map(|(n, _)| *n).collect();
        format!("unknown algorithm `{s}`; known: {}", names.join(", "))
    })
}

fn parse_base(s: &str) -> Result<BaseKind, String> {
    BaseKind::from_name(s).ok_or_else(|| format!("unknown base `{s}`: fixed or free-floating"))
}

/// The methods to use on `model`: the given ones, which must suit it, or the default
/// (`recurrent` for a chain, `spatial` for a tree).
fn checked_methods(model: &Model, given: Option<Methods>) -> Result<Methods> {
    let methods = given.unwrap_or_else(|| commands::eval::default_methods(model));
    if let Some(j) = model.first_branch() {
        anyhow::ensure!(
            methods == Methods::SPATIAL,
            "--algorithm {methods}: the paper's base-frame algorithms handle serial chains only, \
             and `{}` is a tree (joint `{}` does not hang from the joint before it); use \
             --algorithm spatial",
            model.name(),
            j.name
        );
    }
    Ok(methods)
}

fn parse_scalar(s: &str) -> Result<kanegen_codegen::Float, String> {
    kanegen_codegen::Float::from_name(s).ok_or_else(|| format!("unknown scalar `{s}`: f64 or f32"))
}

/// The commands.
#[derive(Subcommand)]
enum Command {
    /// Evaluate A(q) and b(q, q̇) at the states of a JSON file.
    Eval {
        /// Model file (.urdf or .toml).
        model: PathBuf,
        /// States file: {"states":[{"q":[…],"qd":[…],"tau":[…]}]}; free-floating: each state
        /// also with "base": {"position", "quaternion" [x, y, z, w], "v", "omega"} (base frame).
        #[arg(long)]
        states: PathBuf,
        /// Algorithm: recurrent, recurrent-r1, kane-direct, crba-base (serial chains), spatial
        /// (any tree). Default: recurrent for a chain, spatial for a tree.
        #[arg(long, value_parser = parse_algorithm)]
        algorithm: Option<Methods>,
        /// The base: fixed or free-floating (default: the model's; a URDF's is fixed, and its
        /// root link's inertial is the free-floating base's).
        #[arg(long, value_parser = parse_base)]
        base: Option<BaseKind>,
        /// Gravity X,Y,Z, m/s², in the base frame (fixed base) or the inertial frame
        /// (free-floating base); zero unless given.
        #[arg(long, allow_hyphen_values = true)]
        gravity: Option<String>,
        /// Print JSON: {"joints": [names in the order of q], "base": "fixed" | "free-floating",
        /// "results": [{"A": [[…]], "b": […]}]}.
        #[arg(long)]
        json: bool,
        /// Accept inertia tensors that violate the triangle inequality (published but not
        /// physically realisable parameter sets); other checks stay.
        #[arg(long)]
        allow_nonphysical: bool,
    },
    /// Reproduce the paper's Table 1 by tracing; print it, or write table1.md, table1.json and
    /// fig2.svg into --out.
    Table1 {
        /// Print the JSON report.
        #[arg(long)]
        json: bool,
        /// Write table1.md, table1.json and fig2.svg into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Replace existing files in --out.
        #[arg(long)]
        force: bool,
    },
    /// Operation counts of A and b for a model, per algorithm and convention.
    Count {
        /// Model file (.urdf or .toml), or a scene file (.toml with a `model` key).
        model: PathBuf,
        /// Only the methods of this algorithm (default: every method that suits the model).
        #[arg(long, value_parser = parse_algorithm)]
        algorithm: Option<Methods>,
        /// The base: fixed or free-floating (default: the model's).
        #[arg(long, value_parser = parse_base)]
        base: Option<BaseKind>,
        /// Include gravity X,Y,Z in b.
        #[arg(long, allow_hyphen_values = true)]
        gravity: Option<String>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Accept inertia tensors that violate the triangle inequality.
        #[arg(long)]
        allow_nonphysical: bool,
    },
    /// Emit unrolled, allocation-free, no_std Rust for a model (stdout, or -o FILE).
    Generate {
        /// Model file (.urdf or .toml).
        model: PathBuf,
        /// Output file (stdout when absent); never the model file itself.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Replace an existing output file.
        #[arg(long)]
        force: bool,
        /// Gravity X,Y,Z, m/s², in the base frame (fixed) or the inertial frame (free-floating);
        /// none: space, no gravity code.
        #[arg(long, allow_hyphen_values = true)]
        gravity: Option<String>,
        /// The base: fixed or free-floating (default: the model's; a URDF's is fixed, and its
        /// root link's inertial is the free-floating base's).
        #[arg(long, value_parser = parse_base)]
        base: Option<BaseKind>,
        /// Make the last body's mass, centre of mass and inertia a runtime `payload` argument.
        #[arg(long)]
        runtime_payload: bool,
        /// Name of the generated struct (default: from the model name, in CamelCase).
        #[arg(long)]
        name: Option<String>,
        /// Lock joint INDEX at VALUE (rad or m) before generating: `--lock 1=0`.
        #[arg(long)]
        lock: Vec<String>,
        /// Floating-point type of the code: f64 (default) or f32.
        #[arg(long, default_value = "f64", value_parser = parse_scalar)]
        scalar: kanegen_codegen::Float,
        /// Fuse each single-use product into its sum as one `libm::fma` call.
        #[arg(long)]
        fma: bool,
        /// Snap float noise below TOL to exact 0 or ±1 before tracing (0: off; 1e-9 also catches
        /// `rpy = 1.570796325`); the header says what was snapped.
        #[arg(long, default_value_t = kanegen_model::canonical::DEFAULT_SNAP, value_name = "TOL")]
        snap: f64,
        /// Force one algorithm (recurrent, recurrent-r1, kane-direct, crba-base, spatial, aba)
        /// instead of the cheapest candidate per function.
        #[arg(long, value_parser = parse_forced)]
        algorithm: Option<Methods>,
        /// Accept inertia tensors that violate the triangle inequality.
        #[arg(long)]
        allow_nonphysical: bool,
        /// Generate for more than 1000 joints (the generated functions keep O(N) arrays on the
        /// caller's stack, and the frame functions stay straight-line).
        #[arg(long)]
        allow_large: bool,
    },
    /// ns per call of the generated SSRMS code against the interpreted algorithms, measured side
    /// by side in one run (report ratios: the machine is shared and noisy).
    Bench {
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Measurement rounds per candidate (the median is reported), 1 to 100000.
        #[arg(long, default_value_t = 31, value_parser = clap::value_parser!(u32).range(1..=100_000))]
        rounds: u32,
        /// Calls per round, 1 to 100000000.
        #[arg(long, default_value_t = 2000, value_parser = clap::value_parser!(u32).range(1..=100_000_000))]
        calls: u32,
    },
    /// What accuracy costs in time: errors of A, b, q̈ per precision against a double-double
    /// reference with ns per call; integrators' work–precision; each scene effect's cost and
    /// trajectory change. Without inputs: the four subjects of docs/accuracy.md.
    Accuracy {
        /// Model (.urdf/.toml) or scene files (default: SSRMS model and three example scenes).
        inputs: Vec<PathBuf>,
        /// Write accuracy.md, accuracy.json and work-precision SVGs into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Replace existing files in --out.
        #[arg(long)]
        force: bool,
        /// Print JSON (one input: the report; several: {"subjects": [...]}).
        #[arg(long)]
        json: bool,
        /// Accept inertia tensors that violate the triangle inequality (models only).
        #[arg(long)]
        allow_nonphysical: bool,
    },
    /// Simulate a scene file (TOML, docs/scenes.md): write trajectory.csv,
    /// summary.json and SVG plots into --out, print a summary.
    Simulate {
        /// Scene file (.toml).
        scene: PathBuf,
        /// Write trajectory.csv, summary.json, joints.svg, drift.svg into this directory
        /// (the trajectory as it is computed; Ctrl-C keeps what was computed).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print the JSON summary to stdout (and no progress bar).
        #[arg(long)]
        json: bool,
        /// Replace existing files in --out.
        #[arg(long)]
        force: bool,
        /// Allow more than 1e8 steps or output samples (as `allow_long = true` in [simulation]).
        #[arg(long)]
        allow_long: bool,
    },
}

fn load(model: &std::path::Path, allow_nonphysical: bool) -> Result<Model> {
    let v = kanegen_model::Validation {
        allow_nonphysical_inertia: allow_nonphysical,
    };
    kanegen_model::io::load_model_with(model, v)
        .with_context(|| format!("model `{}`", model.display()))
}

/// How a run is attached to the world: whether progress bars may be drawn (on a terminal's
/// stderr, after a second) and Ctrl-C stops a simulation.
#[derive(Clone, Copy, Debug)]
pub struct Interactive(pub bool);

/// A simulation stopped by Ctrl-C (exit code 130 after its partial outputs are written).
#[derive(Debug)]
pub struct Interrupted;

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("interrupted")
    }
}

impl std::error::Error for Interrupted {}

/// Set by Ctrl-C during `simulate`.
static STOP: AtomicBool = AtomicBool::new(false);

/// Installs the Ctrl-C handler once: the first Ctrl-C stops the simulation at its next step,
/// a second one exits at once.
fn install_ctrlc() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            if STOP.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        });
    });
}

/// Gravity `X,Y,Z` within [`GRAVITY`](kanegen_model::bounds::GRAVITY).
fn gravity_arg(g: Option<String>) -> Result<Option<[f64; 3]>> {
    g.map(|s| crate::states::parse_gravity(&s).context("--gravity"))
        .transpose()
}

fn json(value: &impl serde::Serialize) -> Result<String> {
    Ok(serde_json::to_string_pretty(value)? + "\n")
}

/// Parses `args` (the first is the program name) and runs the command, writing its results to
/// `out`; what the binary does, callable in-process (tests).
///
/// # Errors
/// A usage error, or any error of the command with its context chain.
pub fn run_args<I, T>(args: I, out: &mut dyn Write) -> Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = Cli::try_parse_from(args)?;
    run(cli, out, Interactive(false))
}

/// Runs a parsed command line.
///
/// # Errors
/// Any error of the command, with its context chain.
#[allow(clippy::too_many_lines)]
pub fn run(cli: Cli, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    let say = |msg: &str| {
        let _ = writeln!(std::io::stderr(), "{msg}");
    };
    match cli.command {
        Command::Eval {
            model,
            states,
            algorithm,
            base,
            gravity,
            json: as_json,
            allow_nonphysical,
        } => {
            let mut chain = load(&model, allow_nonphysical)?;
            if let Some(kind) = base {
                chain = chain
                    .with_base_kind(kind)
                    .with_context(|| format!("model `{}`: --base", model.display()))?;
            }
            let algorithm = checked_methods(&chain, algorithm)?;
            let text = std::fs::read_to_string(&states)
                .with_context(|| format!("cannot read states file `{}`", states.display()))?;
            let g = gravity_arg(gravity)?;
            let results = commands::eval::eval_states(&chain, &text, algorithm, g)
                .with_context(|| format!("states file `{}`", states.display()))?;
            if as_json {
                let joints: Vec<&str> = chain.joints().iter().map(|j| j.name.as_str()).collect();
                let v = serde_json::json!({
                    "joints": joints,
                    "base": chain.base_kind().name(),
                    "results": results
                });
                print(out, &format!("{v}\n"))?;
            } else {
                print(
                    out,
                    &commands::eval::render_text(&chain, algorithm, &results),
                )?;
            }
        }
        Command::Table1 {
            json: as_json,
            out: dir,
            force,
        } => {
            let planned = dir
                .as_deref()
                .map(|d| OutputDir::plan(d, &commands::table1::FILES, force, &[]))
                .transpose()?;
            let progress = Progress::spinner(interactive.0, "table1: tracing every algorithm");
            let t = kanegen_trace::table1::build(&kanegen_trace::table1::trace_all());
            progress.finish();
            if let Some(d) = &planned {
                commands::table1::write_planned(&t, d)?;
                say(&format!(
                    "wrote table1.md, table1.json, fig2.svg to {}",
                    d.dir().display()
                ));
            }
            if as_json {
                print(out, &json(&t)?)?;
            } else if planned.is_none() {
                print(out, &commands::table1::render_markdown(&t)?)?;
            }
        }
        Command::Count {
            model,
            algorithm,
            base,
            gravity,
            json: as_json,
            allow_nonphysical,
        } => {
            if commands::count::is_scene_file(&model) {
                anyhow::ensure!(base.is_none(), "--base: a scene's [base] decides");
                anyhow::ensure!(gravity.is_none(), "--gravity: a scene's [effects] decide");
                let scene = kanegen_sim::scene::Scene::load(&model)?;
                let algs = match algorithm {
                    Some(a) => vec![checked_methods(&scene.model, Some(a))?],
                    None if scene.model.is_chain() => Methods::ALL.to_vec(),
                    None => vec![Methods::SPATIAL],
                };
                let progress = Progress::spinner(
                    interactive.0,
                    &format!(
                        "count: tracing the scene's A and b (N = {})",
                        scene.model.dof()
                    ),
                );
                let r = commands::count::count_scene(&scene, &model.display().to_string(), &algs)?;
                progress.finish();
                if as_json {
                    print(out, &json(&r)?)?;
                } else {
                    print(out, &commands::count::render_scene_text(&r))?;
                }
                return Ok(());
            }
            let mut chain = load(&model, allow_nonphysical)?;
            if let Some(kind) = base {
                chain = chain
                    .with_base_kind(kind)
                    .with_context(|| format!("model `{}`: --base", model.display()))?;
            }
            let algs = match algorithm {
                Some(a) => vec![checked_methods(&chain, Some(a))?],
                None => commands::count::emittable(&chain),
            };
            let g = gravity_arg(gravity)?;
            let explicit = algorithm.is_some();
            let progress = Progress::bar(interactive.0, "count: tracing");
            let r = commands::count::count_with_progress(&chain, &algs, g, explicit, &|k, n| {
                progress.set(k, n);
            })?;
            progress.finish();
            if as_json {
                print(out, &json(&r)?)?;
            } else {
                print(out, &commands::count::render_text(&r))?;
            }
        }
        Command::Generate {
            model,
            output,
            force,
            gravity,
            base,
            runtime_payload,
            name,
            lock,
            scalar,
            fma,
            snap,
            algorithm,
            allow_nonphysical,
            allow_large,
        } => {
            let target = output
                .as_deref()
                .map(|p| OutputFile::plan(p, force, std::slice::from_ref(&model)))
                .transpose()?;
            let mut chain = load(&model, allow_nonphysical)?;
            for l in &lock {
                let (i, v) = l
                    .split_once('=')
                    .with_context(|| format!("--lock `{l}`: expected INDEX=VALUE"))?;
                let i: usize = i.trim().parse().with_context(|| format!("--lock `{l}`"))?;
                let v: f64 = v.trim().parse().with_context(|| format!("--lock `{l}`"))?;
                chain = chain
                    .lock_joint(i, v)
                    .with_context(|| format!("--lock `{l}`"))?;
            }
            let n = chain.dof();
            anyhow::ensure!(
                allow_large || n <= commands::generate::MAX_N,
                "`{}` has {n} joints, more than {}: the generated functions would keep O(N) arrays \
                 on the caller's stack and straight-line frame functions of 6·N Jacobian entries; \
                 pass --allow-large to generate it anyway",
                model.display(),
                commands::generate::MAX_N
            );
            let g = gravity_arg(gravity)?;
            let name = name.unwrap_or_else(|| commands::generate::type_name(chain.name()));
            let mut opts = kanegen_codegen::Options::new(name);
            opts.gravity = g;
            opts.base = base;
            opts.runtime_payload = runtime_payload;
            opts.float = scalar;
            opts.fma = fma;
            opts.snap = snap;
            opts.algorithm = algorithm;
            let progress = Progress::spinner(
                interactive.0,
                &format!(
                    "generate: tracing and emitting every function of `{}` (N = {})",
                    chain.name(),
                    chain.dof()
                ),
            );
            let code = commands::generate::generate_checked(&chain, &opts)?;
            progress.finish();
            match target {
                Some(f) => f.write(code.as_bytes())?,
                None => print(out, &code)?,
            }
        }
        Command::Bench {
            json: as_json,
            rounds,
            calls,
        } => {
            let r = commands::bench::bench_ssrms(rounds as usize, calls as usize)?;
            if as_json {
                print(out, &json(&r)?)?;
            } else {
                print(out, &commands::bench::render_text(&r))?;
            }
        }
        Command::Accuracy {
            inputs,
            out: dir,
            force,
            json: as_json,
            allow_nonphysical,
        } => {
            let inputs: Vec<PathBuf> = if inputs.is_empty() {
                commands::accuracy::DEFAULT_INPUTS
                    .iter()
                    .map(PathBuf::from)
                    .collect()
            } else {
                inputs
            };
            let planned = dir
                .as_deref()
                .map(|d| {
                    let names = commands::accuracy::file_names(&inputs);
                    let names: Vec<&str> = names.iter().map(String::as_str).collect();
                    OutputDir::plan(d, &names, force, &inputs)
                })
                .transpose()?;
            let opts = crate::reports::accuracy::Options { timing: true };
            let progress = Progress::bar(interactive.0, "accuracy");
            let reports = commands::accuracy::run_with_progress(
                &inputs,
                allow_nonphysical,
                opts,
                &|k, n| {
                    progress.set(k, n);
                },
            )?;
            progress.finish();
            if let Some(d) = &planned {
                commands::accuracy::write_planned(&reports, d)?;
                say(&format!(
                    "wrote accuracy.md, accuracy.json, work-precision SVGs to {}",
                    d.dir().display()
                ));
            }
            if as_json {
                print(out, &json(&commands::accuracy::to_json(&reports))?)?;
            } else if planned.is_none() {
                print(out, &commands::accuracy::render_markdown(&reports, true)?)?;
            }
        }
        Command::Simulate {
            scene,
            out: dir,
            json: as_json,
            force,
            allow_long,
        } => {
            let options = kanegen_sim::scene::SceneOptions { allow_long };
            let sc = kanegen_sim::scene::Scene::load_with(&scene, options)?;
            let mut inputs = vec![scene.clone()];
            if let Some(m) = std::fs::read_to_string(&scene).ok().and_then(|t| {
                kanegen_sim::scene::Scene::model_path(&t, scene.parent().unwrap_or(Path::new(".")))
            }) {
                inputs.push(m);
            }
            let planned = dir
                .as_deref()
                .map(|d| OutputDir::plan(d, &commands::simulate::FILES, force, &inputs))
                .transpose()?;
            let pb = if as_json || !interactive.0 {
                indicatif::ProgressBar::hidden()
            } else {
                indicatif::ProgressBar::new((sc.simulation.duration * 1000.0) as u64)
            };
            if interactive.0 {
                STOP.store(false, Ordering::SeqCst);
                install_ctrlc();
            }
            let control = kanegen_sim::simulate::Control {
                progress: Some(&pb),
                stop: interactive.0.then_some(&STOP),
            };
            let summary = commands::simulate::run(&sc, planned.as_ref(), control)?;
            pb.finish_and_clear();
            if as_json {
                print(out, &json(&summary)?)?;
            } else {
                print(
                    out,
                    &format!("{}\n", kanegen_sim::simulate::render_text(&summary)),
                )?;
            }
            if let Some(d) = &planned {
                say(&format!(
                    "wrote trajectory.csv, summary.json, plots to {}{}",
                    d.dir().display(),
                    if summary.complete {
                        ""
                    } else {
                        " (incomplete run)"
                    }
                ));
            }
            match summary.stopped.as_deref() {
                None => {}
                Some("interrupted") => return Err(Interrupted.into()),
                Some(why) => anyhow::bail!(
                    "the simulation stopped at t = {}: {why}{}",
                    summary.t_end,
                    if planned.is_some() {
                        "; the trajectory up to there and a summary with \"complete\": false \
                         were written"
                    } else {
                        ""
                    }
                ),
            }
        }
    }
    Ok(())
}
