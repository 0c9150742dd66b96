//! The `kanegen` command line: arguments and dispatch to [`crate::commands`].

use crate::commands;
use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use kanegen_dynamics::Methods;
use kanegen_model::{BaseKind, Model};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "kanegen",
    version,
    about = "Equations of motion of space manipulators: evaluate, count, reproduce the paper's Table 1"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
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
        /// Output file (stdout when absent).
        #[arg(short, long)]
        output: Option<PathBuf>,
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
        /// Accept inertia tensors that violate the triangle inequality.
        #[arg(long)]
        allow_nonphysical: bool,
    },
    /// ns per call of the generated SSRMS code against the interpreted algorithms, measured side
    /// by side in one run (report ratios: the machine is shared and noisy).
    Bench {
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Measurement rounds per candidate (the median is reported).
        #[arg(long, default_value_t = 31)]
        rounds: usize,
        /// Calls per round.
        #[arg(long, default_value_t = 2000)]
        calls: usize,
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
        /// Print JSON (one input: the report; several: {"subjects": [...]}).
        #[arg(long)]
        json: bool,
        /// Accept inertia tensors that violate the triangle inequality (models only).
        #[arg(long)]
        allow_nonphysical: bool,
    },
    /// Simulate a scene file (TOML, README.md "Simulation scenes"): write trajectory.csv,
    /// summary.json and SVG plots into --out, print a summary.
    Simulate {
        /// Scene file (.toml).
        scene: PathBuf,
        /// Write trajectory.csv, summary.json, joints.svg, drift.svg into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print the JSON summary to stdout (and no progress bar).
        #[arg(long)]
        json: bool,
    },
}

fn load(model: &std::path::Path, allow_nonphysical: bool) -> Result<Model> {
    let v = kanegen_model::Validation {
        allow_nonphysical_inertia: allow_nonphysical,
    };
    kanegen_model::io::load_model_with(model, v)
        .with_context(|| format!("model `{}`", model.display()))
}

/// Parses the command line and runs the command.
///
/// # Errors
/// Any error of the command, with its context chain.
pub fn run() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Eval {
            model,
            states,
            algorithm,
            base,
            gravity,
            json,
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
            let g = gravity
                .map(|s| crate::states::parse_vec3(&s).context("--gravity"))
                .transpose()?;
            let results = commands::eval::eval_states(&chain, &text, algorithm, g)
                .with_context(|| format!("states file `{}`", states.display()))?;
            if json {
                let joints: Vec<&str> = chain.joints().iter().map(|j| j.name.as_str()).collect();
                println!(
                    "{}",
                    serde_json::json!({
                        "joints": joints,
                        "base": chain.base_kind().name(),
                        "results": results
                    })
                );
            } else {
                print!(
                    "{}",
                    commands::eval::render_text(&chain, algorithm, &results)
                );
            }
        }
        Command::Table1 { json, out } => {
            let t = kanegen_trace::table1::build(&kanegen_trace::table1::trace_all());
            if let Some(dir) = &out {
                commands::table1::write_all(&t, dir)?;
                eprintln!(
                    "wrote table1.md, table1.json, fig2.svg to {}",
                    dir.display()
                );
            }
            if json {
                println!("{}", serde_json::to_string_pretty(&t)?);
            } else if out.is_none() {
                print!("{}", commands::table1::render_markdown(&t)?);
            }
        }
        Command::Count {
            model,
            algorithm,
            base,
            gravity,
            json,
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
                let r = commands::count::count_scene(&scene, &model.display().to_string(), &algs)?;
                if json {
                    println!("{}", serde_json::to_string_pretty(&r)?);
                } else {
                    print!("{}", commands::count::render_scene_text(&r));
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
                None if chain.is_chain() => Methods::ALL.to_vec(),
                None => vec![Methods::SPATIAL],
            };
            let g = gravity
                .map(|s| crate::states::parse_vec3(&s).context("--gravity"))
                .transpose()?;
            let r = commands::count::count(&chain, &algs, g)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&r)?);
            } else {
                print!("{}", commands::count::render_text(&r));
            }
        }
        Command::Generate {
            model,
            output,
            gravity,
            base,
            runtime_payload,
            name,
            lock,
            scalar,
            fma,
            allow_nonphysical,
        } => {
            let mut chain = load(&model, allow_nonphysical)?;
            for l in &lock {
                let (i, v) = l
                    .split_once('=')
                    .with_context(|| format!("--lock `{l}`: expected INDEX=VALUE"))?;
                let i: usize = i.trim().parse().with_context(|| format!("--lock `{l}`"))?;
                let v: f64 = v.trim().parse().with_context(|| format!("--lock `{l}`"))?;
                chain = chain.lock_joint(i, v)?;
            }
            let g = gravity
                .map(|s| crate::states::parse_vec3(&s).context("--gravity"))
                .transpose()?;
            let name = name.unwrap_or_else(|| commands::generate::type_name(chain.name()));
            let mut opts = kanegen_codegen::Options::new(name);
            opts.gravity = g;
            opts.base = base;
            opts.runtime_payload = runtime_payload;
            opts.float = scalar;
            opts.fma = fma;
            let code = commands::generate::generate(&chain, &opts)?;
            match output {
                Some(path) => std::fs::write(&path, code)
                    .with_context(|| format!("cannot write `{}`", path.display()))?,
                None => print!("{code}"),
            }
        }
        Command::Bench {
            json,
            rounds,
            calls,
        } => {
            let r = commands::bench::bench_ssrms(rounds, calls)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&r)?);
            } else {
                print!("{}", commands::bench::render_text(&r));
            }
        }
        Command::Accuracy {
            inputs,
            out,
            json,
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
            let opts = crate::reports::accuracy::Options { timing: true };
            let reports = commands::accuracy::run(&inputs, allow_nonphysical, opts)?;
            if let Some(dir) = &out {
                commands::accuracy::write_all(&reports, dir)?;
                eprintln!(
                    "wrote accuracy.md, accuracy.json, work-precision SVGs to {}",
                    dir.display()
                );
            }
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&commands::accuracy::to_json(&reports))?
                );
            } else if out.is_none() {
                print!("{}", commands::accuracy::render_markdown(&reports, true)?);
            }
        }
        Command::Simulate { scene, out, json } => {
            let sc = kanegen_sim::scene::Scene::load(&scene)?;
            let pb = if json {
                indicatif::ProgressBar::hidden()
            } else {
                indicatif::ProgressBar::new((sc.simulation.duration * 1000.0) as u64)
            };
            let run = kanegen_sim::simulate::simulate(&sc, Some(&pb))?;
            pb.finish_and_clear();
            if let Some(dir) = &out {
                commands::simulate::write_outputs(&sc, &run, dir)?;
            }
            if json {
                println!("{}", serde_json::to_string_pretty(&run.summary)?);
            } else {
                println!("{}", kanegen_sim::simulate::render_text(&run.summary));
                if let Some(dir) = &out {
                    eprintln!(
                        "wrote trajectory.csv, summary.json, plots to {}",
                        dir.display()
                    );
                }
            }
        }
    }
    Ok(())
}
