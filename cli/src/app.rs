//! The `kanegen` command line: arguments and dispatch to [`crate::commands`].

use crate::commands;
use crate::output::{print, OutputDir, OutputFile};
use crate::progress::Progress;
use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
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
            "--algorithm {methods}: the paper's inertial-frame algorithms handle serial chains only, \
             and `{}` is a tree (joint `{}` does not hang from the joint before it); use \
             --algorithm spatial",
            model.name(),
            j.name
        );
    }
    Ok(methods)
}

fn parse_lang(s: &str) -> Result<commands::generate::Lang, String> {
    commands::generate::Lang::from_name(s)
        .ok_or_else(|| format!("unknown language `{s}`: rust or c"))
}

fn parse_scalar(s: &str) -> Result<kanegen_codegen::Float, String> {
    kanegen_codegen::Float::from_name(s).ok_or_else(|| format!("unknown scalar `{s}`: f64 or f32"))
}

/// The commands.
#[derive(Subcommand)]
enum Command {
    /// Evaluate A(q) and b(q, q̇) at the states of a JSON file.
    Eval(EvalArgs),
    /// The joints in the order of q (type, parent, axis, limits, mimic), the frames, the base,
    /// the total mass, and what the URDF reader ignored and merged.
    Info(InfoArgs),
    /// Reproduce the paper's Table 1 by tracing; print it, or write table1.md, table1.json and
    /// fig2.svg into --out.
    Table1(Table1Args),
    /// Operation counts of A and b for a model, per algorithm and convention.
    Count(CountArgs),
    /// Emit unrolled, allocation-free, no_std Rust for a model (stdout, or -o FILE).
    Generate(GenerateArgs),
    /// ns per call of the generated SSRMS code against the interpreted algorithms, and states per
    /// second of the generated functions (one state, lanes, all cores), measured side by side in
    /// one run (report ratios: the machine is shared and noisy).
    Bench(BenchArgs),
    /// What accuracy costs in time: errors of A, b, q̈ per precision against a double-double
    /// reference with ns per call; integrators' work–precision; each scene effect's cost and
    /// trajectory change. Without inputs: the four subjects of docs/accuracy.md.
    Accuracy(AccuracyArgs),
    /// Simulate a scene file (TOML, docs/scenes.md): write trajectory.csv,
    /// summary.json and SVG plots into --out, print a summary.
    Simulate(SimulateArgs),
    /// Run a sweep file (a scene over drawn or gridded numbers, docs/scenes.md#sweeps), whole
    /// or one shard (--shard INDEX/COUNT): write runs.csv and sweep.json into --out, print the
    /// statistics over the complete runs.
    Sweep(SweepArgs),
    /// Merge the --out directories of every shard of a sweep into the whole sweep's runs.csv
    /// and sweep.json (the files the unsharded sweep writes, byte for byte).
    Merge(MergeArgs),
}

// The arguments of `kanegen eval` (its help is the variant's doc).
#[derive(Args)]
struct EvalArgs {
    /// Model file (.urdf or .toml).
    model: PathBuf,
    /// States file: {"states":[{"q":[…],"qd":[…],"tau":[…]}]}; free-floating: each state
    /// also with "base": {"position", "quaternion" [x, y, z, w], "v", "omega"} (base frame).
    #[arg(long)]
    states: PathBuf,
    /// Algorithm: recurrent, recurrent-r1, kane-direct, crba-inertial (serial chains;
    /// `crba-base` is its earlier name, still accepted), spatial
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
    /// Accept inertias that are not physically realisable (a negative principal moment, the
    /// triangle inequality violated, rotational inertia without mass); other checks stay.
    #[arg(long)]
    allow_nonphysical: bool,
}

// The arguments of `kanegen info` (its help is the variant's doc).
#[derive(Args)]
struct InfoArgs {
    /// Model file (.urdf or .toml).
    model: PathBuf,
    /// The base: fixed or free-floating (default: the model's).
    #[arg(long, value_parser = parse_base)]
    base: Option<BaseKind>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Accept inertias that are not physically realisable (docs/models.md).
    #[arg(long)]
    allow_nonphysical: bool,
}

// The arguments of `kanegen table1` (its help is the variant's doc).
#[derive(Args)]
struct Table1Args {
    /// Print the JSON report.
    #[arg(long)]
    json: bool,
    /// Write table1.md, table1.json and fig2.svg into this directory.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace existing files in --out.
    #[arg(long)]
    force: bool,
}

// The arguments of `kanegen count` (its help is the variant's doc).
#[derive(Args)]
struct CountArgs {
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
    /// Accept inertias that are not physically realisable (a negative principal moment, the
    /// triangle inequality violated, rotational inertia without mass); other checks stay.
    #[arg(long)]
    allow_nonphysical: bool,
}

// The arguments of `kanegen generate` (its help is the variant's doc).
#[derive(Args)]
struct GenerateArgs {
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
    /// Force one algorithm (recurrent, recurrent-r1, kane-direct, crba-inertial, spatial, aba;
    /// crba-base is accepted for crba-inertial)
    /// instead of the cheapest candidate per function.
    #[arg(long, value_parser = parse_forced)]
    algorithm: Option<Methods>,
    /// Leave out the derivative functions (`inverse_dynamics_derivatives`,
    /// `forward_dynamics_derivatives`, `mass_matrix_inverse`): a smaller file that compiles faster.
    #[arg(long)]
    no_derivatives: bool,
    /// Accept inertias that are not physically realisable (a negative principal moment, the
    /// triangle inequality violated, rotational inertia without mass); other checks stay.
    #[arg(long)]
    allow_nonphysical: bool,
    /// Generate every URDF mimic joint as an independent joint (Pinocchio's mimic=False).
    #[arg(long)]
    ignore_mimic: bool,
    /// Generate for more than 1000 joints (the generated functions keep O(N) arrays on the
    /// caller's stack, and the frame functions stay straight-line); with --lang c, for more than
    /// 64 joints (straight-line).
    #[arg(long)]
    allow_large: bool,
    /// Output language: rust (default: a module file) or c (a C99 header of `static inline`
    /// functions named from --name in snake_case, `ur5_mass_matrix`; straight-line for every
    /// model; docs/codegen.md).
    #[arg(long, default_value = "rust", value_parser = parse_lang)]
    lang: commands::generate::Lang,
}

// The arguments of `kanegen bench` (its help is the variant's doc).
#[derive(Args)]
struct BenchArgs {
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Measurement rounds per candidate (the median is reported), 1 to 100000.
    #[arg(long, default_value_t = 31, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    rounds: u32,
    /// Calls per round, 1 to 100000000.
    #[arg(long, default_value_t = 2000, value_parser = clap::value_parser!(u32).range(1..=100_000_000))]
    calls: u32,
    /// States per batch of the throughput table (one state, lanes, all cores), 1 to 1000000.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    batch: u32,
}

// The arguments of `kanegen accuracy` (its help is the variant's doc).
#[derive(Args)]
struct AccuracyArgs {
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
    /// Accept inertias that are not physically realisable (models only; docs/models.md).
    #[arg(long)]
    allow_nonphysical: bool,
}

// The arguments of `kanegen simulate` (its help is the variant's doc).
#[derive(Args)]
struct SimulateArgs {
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
    /// Instead of running: print the Jacobians (A, B) of one step of the scene's integrator
    /// from its initial state (t = 0, no added torque u, the scene's step), exact for the scheme
    /// (RK4 for rk4 and dopri5 scenes, implicit midpoint; not rosenbrock); with --json as JSON.
    #[arg(long, conflicts_with_all = ["out", "force"])]
    linearize: bool,
}

// The arguments of `kanegen sweep` (its help is the variant's doc).
#[derive(Args)]
struct SweepArgs {
    /// Sweep file (.toml: a scene, runs, seed and [[parameter]]s).
    sweep: PathBuf,
    /// Run only shard INDEX of COUNT (0 <= INDEX < COUNT), a contiguous block of the runs, as
    /// a Slurm array task: `--shard $SLURM_ARRAY_TASK_ID/16`.
    #[arg(long)]
    shard: Option<String>,
    /// Write runs.csv and sweep.json into this directory.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print sweep.json to stdout (and no progress bar).
    #[arg(long)]
    json: bool,
    /// Replace existing files in --out.
    #[arg(long)]
    force: bool,
}

// The arguments of `kanegen merge` (its help is the variant's doc).
#[derive(Args)]
struct MergeArgs {
    /// The shards' --out directories (any order; each shard once).
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Write the merged runs.csv and sweep.json into this directory.
    #[arg(long)]
    out: PathBuf,
    /// Print the merged sweep.json to stdout.
    #[arg(long)]
    json: bool,
    /// Replace existing files in --out.
    #[arg(long)]
    force: bool,
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
pub fn run(cli: Cli, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    match cli.command {
        Command::Eval(a) => eval(a, out),
        Command::Info(a) => commands::info::run(&a.model, a.base, a.allow_nonphysical, a.json, out),
        Command::Table1(a) => table1(a, out, interactive),
        Command::Count(a) if commands::count::is_scene_file(&a.model) => {
            count_scene(a, out, interactive)
        }
        Command::Count(a) => count(a, out, interactive),
        Command::Generate(a) => generate(a, out, interactive),
        Command::Bench(a) => bench(a, out),
        Command::Accuracy(a) => accuracy(a, out, interactive),
        Command::Simulate(a) => simulate(a, out, interactive),
        Command::Sweep(a) => sweep(a, out, interactive),
        Command::Merge(a) => merge(a, out),
    }
}

/// A line on stderr (what a command wrote where).
fn say(msg: &str) {
    let _ = writeln!(std::io::stderr(), "{msg}");
}

/// The model at `model` with the base `--base` gives (the model's own when `None`), with the
/// error context every command puts on a model ("model `PATH`", then "--base").
///
/// # Errors
/// A file that cannot be read or parsed, an invalid model, or a base it cannot take.
pub fn load_with_base(
    model: &Path,
    allow_nonphysical: bool,
    base: Option<BaseKind>,
) -> Result<Model> {
    let chain = load(model, allow_nonphysical)?;
    match base {
        None => Ok(chain),
        Some(kind) => chain
            .with_base_kind(kind)
            .with_context(|| format!("model `{}`: --base", model.display())),
    }
}

/// `kanegen eval`: A and b at each state of the states file, as text or JSON.
fn eval(a: EvalArgs, out: &mut dyn Write) -> Result<()> {
    let chain = load_with_base(&a.model, a.allow_nonphysical, a.base)?;
    let algorithm = checked_methods(&chain, a.algorithm)?;
    let text = std::fs::read_to_string(&a.states)
        .with_context(|| format!("cannot read states file `{}`", a.states.display()))?;
    let g = gravity_arg(a.gravity)?;
    let results = commands::eval::eval_states(&chain, &text, algorithm, g)
        .with_context(|| format!("states file `{}`", a.states.display()))?;
    if a.json {
        let joints = commands::eval::coordinate_names(&chain);
        let v = serde_json::json!({
            "joints": joints,
            "base": chain.base_kind().name(),
            "results": results
        });
        print(out, &format!("{v}\n"))
    } else {
        print(
            out,
            &commands::eval::render_text(&chain, algorithm, &results),
        )
    }
}

/// `kanegen table1`: the paper's Table 1 by tracing, printed or written into `--out`.
fn table1(a: Table1Args, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    let planned = a
        .out
        .as_deref()
        .map(|d| OutputDir::plan(d, &commands::table1::FILES, a.force, &[]))
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
    if a.json {
        print(out, &json(&t)?)?;
    } else if planned.is_none() {
        print(out, &commands::table1::render_markdown(&t)?)?;
    }
    Ok(())
}

/// `kanegen count` on a scene file: the counts of the scene's A and b (its base and gravity).
fn count_scene(a: CountArgs, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    anyhow::ensure!(a.base.is_none(), "--base: a scene's [base] decides");
    anyhow::ensure!(a.gravity.is_none(), "--gravity: a scene's [effects] decide");
    let scene = kanegen_sim::scene::Scene::load(&a.model)?;
    let algs = match a.algorithm {
        Some(m) => vec![checked_methods(&scene.model, Some(m))?],
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
    let r = commands::count::count_scene(&scene, &a.model.display().to_string(), &algs)?;
    progress.finish();
    if a.json {
        print(out, &json(&r)?)
    } else {
        print(out, &commands::count::render_scene_text(&r))
    }
}

/// `kanegen count` on a model file: the counts of each method that suits it (or the one named).
fn count(a: CountArgs, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    let chain = load_with_base(&a.model, a.allow_nonphysical, a.base)?;
    let algs = match a.algorithm {
        Some(m) => vec![checked_methods(&chain, Some(m))?],
        None => commands::count::emittable(&chain),
    };
    let g = gravity_arg(a.gravity)?;
    let explicit = a.algorithm.is_some();
    let progress = Progress::bar(interactive.0, "count: tracing");
    let r = commands::count::count_with_progress(&chain, &algs, g, explicit, &|k, n| {
        progress.set(k, n);
    })?;
    progress.finish();
    if a.json {
        print(out, &json(&r)?)
    } else {
        print(out, &commands::count::render_text(&r))
    }
}

/// `kanegen generate`: the model (mimics ignored, joints locked as asked) emitted as Rust, to
/// stdout or `-o`.
fn generate(a: GenerateArgs, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    let target = a
        .output
        .as_deref()
        .map(|p| OutputFile::plan(p, a.force, std::slice::from_ref(&a.model)))
        .transpose()?;
    let mut chain = load(&a.model, a.allow_nonphysical)?;
    if a.ignore_mimic {
        chain = chain.without_mimics();
    }
    for l in &a.lock {
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
        a.allow_large || n <= commands::generate::MAX_N,
        "`{}` has {n} joints, more than {}: the generated functions would keep O(N) arrays \
         on the caller's stack and straight-line frame functions of 6·N Jacobian entries; \
         pass --allow-large to generate it anyway",
        a.model.display(),
        commands::generate::MAX_N
    );
    let name = a
        .name
        .unwrap_or_else(|| commands::generate::type_name(chain.name()));
    let mut opts = kanegen_codegen::Options::new(name);
    opts.gravity = gravity_arg(a.gravity)?;
    opts.base = a.base;
    opts.runtime_payload = a.runtime_payload;
    opts.float = a.scalar;
    opts.fma = a.fma;
    opts.snap = a.snap;
    opts.algorithm = a.algorithm;
    opts.derivatives = !a.no_derivatives;
    let progress = Progress::spinner(
        interactive.0,
        &format!(
            "generate: tracing and emitting every function of `{}` (N = {})",
            chain.name(),
            chain.dof()
        ),
    );
    let code = match a.lang {
        commands::generate::Lang::Rust => commands::generate::generate_checked(&chain, &opts)?,
        commands::generate::Lang::C => {
            // Past `c::MAX_JOINTS`, straight-line all the same when asked.
            if a.allow_large {
                opts.form = kanegen_codegen::Form::Unrolled;
            }
            commands::generate::generate_c_checked(&chain, &opts)?
        }
    };
    progress.finish();
    match target {
        Some(f) => f.write(code.as_bytes()),
        None => print(out, &code),
    }
}

/// `kanegen bench`: the generated SSRMS code against the interpreted algorithms, and the
/// generated functions' states per second.
fn bench(a: BenchArgs, out: &mut dyn Write) -> Result<()> {
    let r = commands::bench::bench_ssrms(a.rounds as usize, a.calls as usize, a.batch as usize)?;
    if a.json {
        print(out, &json(&r)?)
    } else {
        print(out, &commands::bench::render_text(&r))
    }
}

/// `kanegen accuracy`: the accuracy reports of the inputs (the default subjects without any),
/// printed or written into `--out`.
fn accuracy(a: AccuracyArgs, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    let inputs: Vec<PathBuf> = if a.inputs.is_empty() {
        commands::accuracy::DEFAULT_INPUTS
            .iter()
            .map(PathBuf::from)
            .collect()
    } else {
        a.inputs
    };
    let planned = a
        .out
        .as_deref()
        .map(|d| {
            let names = commands::accuracy::file_names(&inputs);
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            OutputDir::plan(d, &names, a.force, &inputs)
        })
        .transpose()?;
    let opts = crate::reports::accuracy::Options { timing: true };
    let progress = Progress::bar(interactive.0, "accuracy");
    let reports =
        commands::accuracy::run_with_progress(&inputs, a.allow_nonphysical, opts, &|k, n| {
            progress.set(k, n);
        })?;
    progress.finish();
    if let Some(d) = &planned {
        commands::accuracy::write_planned(&reports, d)?;
        say(&format!(
            "wrote accuracy.md, accuracy.json, work-precision SVGs to {}",
            d.dir().display()
        ));
    }
    if a.json {
        print(out, &json(&commands::accuracy::to_json(&reports))?)?;
    } else if planned.is_none() {
        print(out, &commands::accuracy::render_markdown(&reports, true)?)?;
    }
    Ok(())
}

/// `kanegen simulate`: runs the scene (Ctrl-C stops it when interactive), writes its outputs
/// into `--out`, prints its summary; an error when it stopped early.
fn simulate(a: SimulateArgs, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    let options = kanegen_sim::scene::SceneOptions {
        allow_long: a.allow_long,
    };
    let sc = kanegen_sim::scene::Scene::load_with(&a.scene, options)?;
    if a.linearize {
        let j = commands::linearize::at_initial_state(&sc)
            .with_context(|| format!("scene `{}`: --linearize", a.scene.display()))?;
        return if a.json {
            print(out, &json(&commands::linearize::to_json(&sc, &j))?)
        } else {
            print(out, &commands::linearize::render_text(&sc, &j))
        };
    }
    let mut inputs = vec![a.scene.clone()];
    if let Some(m) = std::fs::read_to_string(&a.scene).ok().and_then(|t| {
        kanegen_sim::scene::Scene::model_path(&t, a.scene.parent().unwrap_or(Path::new(".")))
    }) {
        inputs.push(m);
    }
    let planned = a
        .out
        .as_deref()
        .map(|d| OutputDir::plan(d, &commands::simulate::FILES, a.force, &inputs))
        .transpose()?;
    let pb = if a.json || !interactive.0 {
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
    if a.json {
        print(out, &json(&summary)?)?;
    } else {
        print(
            out,
            &format!("{}\n", commands::simulate_text::render_text(&summary)),
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
        None => Ok(()),
        Some("interrupted") => Err(Interrupted.into()),
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

/// `kanegen sweep`: runs the sweep's runs of `--shard` on every core (Ctrl-C stops them and
/// writes nothing), writes runs.csv and sweep.json, prints the statistics.
fn sweep(a: SweepArgs, out: &mut dyn Write, interactive: Interactive) -> Result<()> {
    use kanegen_sim::sweep::{Shard, Sweep};
    let shard = match &a.shard {
        Some(s) => Shard::parse(s).context("--shard")?,
        None => Shard::WHOLE,
    };
    let sw = Sweep::load(&a.sweep)?;
    let scene = sw
        .scene_text_for(&[])
        .and_then(|t| sw.parse_scene(&t))
        .with_context(|| format!("scene `{}`", sw.scene_path.display()))?;
    let planned = a
        .out
        .as_deref()
        .map(|d| {
            OutputDir::plan(
                d,
                &commands::sweep::FILES,
                a.force,
                &[a.sweep.clone(), sw.scene_path.clone()],
            )
        })
        .transpose()?;
    let total = shard.runs(sw.runs());
    let n = usize::try_from(total.end - total.start).unwrap_or(usize::MAX);
    let progress = crate::progress::Progress::bar(interactive.0 && !a.json, "sweep");
    let done = std::sync::atomic::AtomicUsize::new(0);
    if interactive.0 {
        STOP.store(false, Ordering::SeqCst);
        install_ctrlc();
    }
    let started = std::time::Instant::now();
    let runs = sw.run_shard(shard, interactive.0.then_some(&STOP), &|| {
        progress.set(done.fetch_add(1, Ordering::Relaxed) + 1, n);
    });
    progress.finish();
    if interactive.0 && STOP.load(Ordering::SeqCst) {
        return Err(Interrupted.into());
    }
    let (table, failures) = commands::sweep::table(&sw, &scene, &runs);
    let report = commands::sweep::report(&sw, shard, &table, failures, &a.sweep);
    if let Some(d) = &planned {
        d.write_all(&commands::sweep::files(&table, &report)?)?;
        say(&format!(
            "wrote runs.csv, sweep.json to {} ({n} run{} in {:.1} s)",
            d.dir().display(),
            if n == 1 { "" } else { "s" },
            started.elapsed().as_secs_f64()
        ));
    }
    if a.json {
        print(out, &json(&report)?)
    } else {
        print(out, &commands::sweep::render_text(&report))
    }
}

/// `kanegen merge`: the shards' runs.csv and sweep.json merged into `--out`.
fn merge(a: MergeArgs, out: &mut dyn Write) -> Result<()> {
    let dirs: Vec<&Path> = a.shards.iter().map(PathBuf::as_path).collect();
    let mut inputs = Vec::new();
    for d in &dirs {
        for f in commands::sweep::FILES {
            inputs.push(d.join(f));
        }
    }
    let planned = OutputDir::plan(&a.out, &commands::sweep::FILES, a.force, &inputs)?;
    let (table, report) = commands::sweep::merge(&dirs)?;
    planned.write_all(&commands::sweep::files(&table, &report)?)?;
    say(&format!(
        "merged {} shards ({} runs) into {}",
        dirs.len(),
        report.runs,
        planned.dir().display()
    ));
    if a.json {
        print(out, &json(&report)?)
    } else {
        print(out, &commands::sweep::render_text(&report))
    }
}
