//! `kanegen sweep SWEEP [--shard i/n]` and `kanegen merge DIR…`: a sweep's runs as one CSV
//! row each (`runs.csv`) and its report (`sweep.json`: what was swept, which runs failed and
//! why, statistics over the complete runs). Shards merge into exactly the files of the
//! unsharded sweep: the rows are the same numbers, printed so that they read back bit for bit,
//! and the statistics are computed from those numbers in run order either way.

use super::simulate_text::{csv_header, csv_values};
use anyhow::{bail, ensure, Context, Result};
use kanegen_sim::scene::Scene;
use kanegen_sim::sweep::{Draw, Outcome, Shard, Sweep, SweepRun};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

/// The files a sweep or a merge writes.
pub const FILES: [&str; 2] = ["runs.csv", "sweep.json"];

/// A sweep's runs as a table: `run`, `status`, then [`Table::columns`].
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// The numeric columns: the parameters (by key), the run's summary, its final state.
    pub columns: Vec<String>,
    /// How many leading columns are parameters and summary (the rest: the final state).
    pub summary_columns: usize,
    /// One row per run, in run order.
    pub rows: Vec<Row>,
}

/// One run's row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The run's index.
    pub run: u64,
    /// `complete`, `stopped` or `invalid`.
    pub status: String,
    /// One cell per column; `None` prints empty (a quantity the run does not have).
    pub cells: Vec<Option<f64>>,
}

/// A failed run in `sweep.json`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Failure {
    /// Its index.
    pub run: u64,
    /// `stopped` or `invalid`.
    pub status: String,
    /// Why: the integrator's error or the scene's validation error.
    pub reason: String,
}

/// Statistics of one column over the complete runs.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Statistic {
    /// The column.
    pub column: String,
    /// Complete runs with a finite value.
    pub count: u64,
    /// Mean.
    pub mean: Option<f64>,
    /// Sample standard deviation (n − 1; 0 for one value).
    pub std: Option<f64>,
    /// Smallest value.
    pub min: Option<f64>,
    /// Largest value.
    pub max: Option<f64>,
}

/// `sweep.json`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Report {
    /// The sweep file, as given.
    pub sweep: String,
    /// The scene file it names.
    pub scene: String,
    /// FNV-1a of the sweep, scene and model files (hex): equal on every shard of one sweep.
    pub fingerprint: String,
    /// The seed.
    pub seed: u64,
    /// Runs of the whole sweep.
    pub runs: u64,
    /// Grid points (`values` parameters).
    pub grid_points: u64,
    /// Random draws per grid point.
    pub runs_per_point: u64,
    /// The parameters: `key` and its draw.
    pub parameters: Vec<serde_json::Value>,
    /// This file's shard (`count` 1: the whole sweep).
    pub shard: ShardJson,
    /// The first run of the file.
    pub first_run: u64,
    /// One past its last run.
    pub end_run: u64,
    /// Runs that reached the scene's duration.
    pub complete: u64,
    /// Runs the integrator stopped.
    pub stopped: u64,
    /// Runs whose numbers make an invalid scene.
    pub invalid: u64,
    /// How many leading statistics are parameters and summary (the rest: the final state).
    pub summary_columns: usize,
    /// The runs that did not complete.
    pub failures: Vec<Failure>,
    /// Per column, over the complete runs.
    pub statistics: Vec<Statistic>,
}

/// A shard in `sweep.json`.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub struct ShardJson {
    /// 0-based index.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
}

/// The table of `runs` of `sweep` (its nominal `scene` names the columns), and the runs that
/// failed.
#[must_use]
pub fn table(sweep: &Sweep, scene: &Scene, runs: &[SweepRun]) -> (Table, Vec<Failure>) {
    let (columns, summary_columns) = columns(sweep, scene);
    let (rows, failures) = runs
        .iter()
        .map(|r| row(sweep, scene, r, columns.len()))
        .unzip::<_, _, Vec<Row>, Vec<Option<Failure>>>();
    let table = Table {
        columns,
        summary_columns,
        rows,
    };
    (table, failures.into_iter().flatten().collect())
}

/// The columns: the parameters, the run's summary, then the final state under the names of
/// `trajectory.csv`; and how many come before the final state.
fn columns(sweep: &Sweep, scene: &Scene) -> (Vec<String>, usize) {
    let mut columns: Vec<String> = sweep.parameters.iter().map(|p| p.key.clone()).collect();
    columns.extend(SUMMARY.map(String::from));
    for i in 0..scene.events.len() {
        for q in [
            "energy_change",
            "linear_momentum_error",
            "angular_momentum_error",
        ] {
            columns.push(format!("event{i}_{q}"));
        }
    }
    if scene.is_floating() {
        columns.extend(["sigma_min", "sigma_min_t"].map(String::from));
    }
    let summary_columns = columns.len();
    columns.extend(csv_header(scene).into_iter().skip(1));
    (columns, summary_columns)
}

/// The summary columns every run has.
const SUMMARY: [&str; 7] = [
    "t_end",
    "steps",
    "rejected_steps",
    "evals",
    "energy_drift",
    "linear_momentum_drift",
    "angular_momentum_drift",
];

/// One run's row of `width` cells (empty where the run has no value), and its failure.
fn row(sweep: &Sweep, scene: &Scene, r: &SweepRun, width: usize) -> (Row, Option<Failure>) {
    let mut cells: Vec<Option<f64>> = r.values.iter().copied().map(Some).collect();
    let failure = |status: &str, reason: String| Failure {
        run: r.index,
        status: status.into(),
        reason,
    };
    let (status, failure) = match &r.outcome {
        Outcome::Invalid(why) => ("invalid", Some(failure("invalid", why.clone()))),
        Outcome::Ran { summary: s, last } => {
            cells.extend(
                [
                    s.t_end,
                    s.steps as f64,
                    s.rejected_steps as f64,
                    s.evals as f64,
                ]
                .map(Some),
            );
            cells.extend([
                s.max_energy_drift_rel,
                s.max_linear_momentum_drift_rel,
                s.max_angular_momentum_drift_rel,
            ]);
            for e in &s.events {
                let errors = [e.linear_momentum_error_rel, e.angular_momentum_error_rel];
                cells.extend([e.energy_change, errors[0], errors[1]].map(Some));
            }
            // A run stopped before an event has no numbers for it.
            cells.resize(
                sweep.parameters.len() + SUMMARY.len() + 3 * scene.events.len(),
                None,
            );
            if scene.is_floating() {
                let sigma = s.singularity.as_ref();
                cells.extend([sigma.map(|m| m.sigma_min), sigma.map(|m| m.t)]);
            }
            cells.extend(csv_values(scene, last).into_iter().skip(1).map(Some));
            match &s.stopped {
                None => ("complete", None),
                Some(why) => (
                    "stopped",
                    Some(failure("stopped", format!("at t = {}: {why}", s.t_end))),
                ),
            }
        }
    };
    cells.resize(width, None);
    let row = Row {
        run: r.index,
        status: status.into(),
        cells,
    };
    (row, failure)
}

/// The report of `table` (the runs `first..end` of `sweep`, shard `shard`).
#[must_use]
pub fn report(
    sweep: &Sweep,
    shard: Shard,
    table: &Table,
    failures: Vec<Failure>,
    sweep_arg: &Path,
) -> Report {
    let runs = shard.runs(sweep.runs());
    let parameters = sweep
        .parameters
        .iter()
        .map(|p| match &p.draw {
            Draw::Uniform { lo, hi } => serde_json::json!({"key": p.key, "uniform": [lo, hi]}),
            Draw::Normal { mean, std } => {
                serde_json::json!({"key": p.key, "normal": {"mean": mean, "std": std}})
            }
            Draw::Values(v) => serde_json::json!({"key": p.key, "values": v}),
        })
        .collect();
    let mut r = Report {
        sweep: sweep_arg.display().to_string(),
        scene: sweep.scene_path.display().to_string(),
        fingerprint: format!("{:016x}", sweep.fingerprint),
        seed: sweep.seed,
        runs: sweep.runs(),
        grid_points: sweep.grid_points(),
        runs_per_point: sweep.runs_per_point,
        parameters,
        shard: ShardJson {
            index: shard.index,
            count: shard.count,
        },
        first_run: runs.start,
        end_run: runs.end,
        complete: 0,
        stopped: 0,
        invalid: 0,
        summary_columns: table.summary_columns,
        failures,
        statistics: Vec::new(),
    };
    tally(&mut r, table);
    r
}

/// The status counts and statistics of `r` from `table`.
fn tally(r: &mut Report, table: &Table) {
    let count = |s: &str| table.rows.iter().filter(|row| row.status == s).count() as u64;
    r.complete = count("complete");
    r.stopped = count("stopped");
    r.invalid = count("invalid");
    r.summary_columns = table.summary_columns;
    r.statistics = table
        .columns
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let v: Vec<f64> = table
                .rows
                .iter()
                .filter(|row| row.status == "complete")
                .filter_map(|row| row.cells[c])
                .filter(|x| x.is_finite())
                .collect();
            statistic(name, &v)
        })
        .collect();
}

fn statistic(column: &str, v: &[f64]) -> Statistic {
    let n = v.len();
    let mean = (n > 0).then(|| v.iter().sum::<f64>() / n as f64);
    let std = mean.map(|m| {
        if n < 2 {
            0.0
        } else {
            (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1) as f64).sqrt()
        }
    });
    Statistic {
        column: column.to_string(),
        count: n as u64,
        mean,
        std,
        min: v.iter().copied().reduce(f64::min),
        max: v.iter().copied().reduce(f64::max),
    }
}

/// `runs.csv`: a header, then one row per run; numbers in Rust's shortest round-trip `{:e}`.
#[must_use]
pub fn csv(table: &Table) -> String {
    let mut out = format!("run,status,{}\n", table.columns.join(","));
    for row in &table.rows {
        let _ = write!(out, "{},{}", row.run, row.status);
        for c in &row.cells {
            match c {
                Some(x) => {
                    let _ = write!(out, ",{x:e}");
                }
                None => out.push(','),
            }
        }
        out.push('\n');
    }
    out
}

/// Reads a `runs.csv` (`name` in errors).
fn parse_csv(text: &str, name: &str, summary_columns: usize) -> Result<Table> {
    let mut lines = text.lines();
    let header = lines.next().with_context(|| format!("{name}: empty"))?;
    let columns: Vec<String> = match header.strip_prefix("run,status,") {
        Some(c) => c.split(',').map(String::from).collect(),
        None => bail!("{name} line 1: expected a header `run,status,…`"),
    };
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let at = || format!("{name} line {}", i + 2);
        let cells: Vec<&str> = line.split(',').collect();
        ensure!(
            cells.len() == columns.len() + 2,
            "{}: {} cells, the header has {}",
            at(),
            cells.len(),
            columns.len() + 2
        );
        let run = cells[0]
            .parse()
            .with_context(|| format!("{}: run `{}`", at(), cells[0]))?;
        let status = cells[1].to_string();
        ensure!(
            ["complete", "stopped", "invalid"].contains(&status.as_str()),
            "{}: status `{status}`",
            at()
        );
        let values = cells[2..]
            .iter()
            .map(|c| {
                if c.is_empty() {
                    Ok(None)
                } else {
                    c.parse::<f64>()
                        .map(Some)
                        .with_context(|| format!("{}: `{c}` is not a number", at()))
                }
            })
            .collect::<Result<_>>()?;
        rows.push(Row {
            run,
            status,
            cells: values,
        });
    }
    Ok(Table {
        columns,
        summary_columns,
        rows,
    })
}

/// The files of a table and its report.
///
/// # Errors
/// Only JSON serialization's.
pub fn files(table: &Table, report: &Report) -> Result<Vec<(&'static str, Vec<u8>)>> {
    Ok(vec![
        ("runs.csv", csv(table).into_bytes()),
        (
            "sweep.json",
            (serde_json::to_string_pretty(report)? + "\n").into_bytes(),
        ),
    ])
}

/// Merges the output directories of shards into the whole sweep's table and report: the same
/// sweep (fingerprint, seed, runs, shard count), every shard exactly once, each with its runs.
///
/// # Errors
/// A missing or unreadable file, shards of different sweeps, a shard twice or missing (named
/// with the runs it holds), or rows that are not the shard's runs.
pub fn merge(dirs: &[&Path]) -> Result<(Table, Report)> {
    let mut shards = Vec::new();
    for d in dirs {
        let read = |f: &str| {
            let p = d.join(f);
            std::fs::read_to_string(&p).with_context(|| format!("cannot read `{}`", p.display()))
        };
        let report: Report = serde_json::from_str(&read("sweep.json")?)
            .with_context(|| format!("`{}`", d.join("sweep.json").display()))?;
        let name = d.join("runs.csv").display().to_string();
        let table = parse_csv(&read("runs.csv")?, &name, report.summary_columns)?;
        shards.push((d, report, table));
    }
    let Some((d0, first, _)) = shards.first() else {
        bail!("no shard directories given");
    };
    let (d0, first) = (d0.to_path_buf(), first.clone());
    let same = |r: &Report| {
        (&r.fingerprint, r.seed, r.runs, r.shard.count)
            == (
                &first.fingerprint,
                first.seed,
                first.runs,
                first.shard.count,
            )
    };
    for (d, r, _) in &shards {
        ensure!(
            same(r),
            "`{}` is not a shard of the sweep of `{}` (fingerprint {} seed {} runs {} shards {} \
             against {} {} {} {})",
            d.display(),
            d0.display(),
            r.fingerprint,
            r.seed,
            r.runs,
            r.shard.count,
            first.fingerprint,
            first.seed,
            first.runs,
            first.shard.count
        );
    }
    let count = first.shard.count;
    shards.sort_by_key(|(_, r, _)| r.shard.index);
    for w in shards.windows(2) {
        ensure!(
            w[0].1.shard.index != w[1].1.shard.index,
            "shard {}/{count} given twice: `{}` and `{}`",
            w[0].1.shard.index,
            w[0].0.display(),
            w[1].0.display()
        );
    }
    let missing: Vec<String> = (0..count)
        .filter(|i| !shards.iter().any(|(_, r, _)| r.shard.index == *i))
        .map(|i| {
            let runs = Shard { index: i, count }.runs(first.runs);
            format!("{i} (runs {}..{})", runs.start, runs.end)
        })
        .collect();
    ensure!(
        missing.is_empty(),
        "shards missing, of {count}: {}",
        missing.join(", ")
    );
    let mut whole = first.clone();
    let mut table = Table {
        columns: shards[0].2.columns.clone(),
        summary_columns: first.summary_columns,
        rows: Vec::new(),
    };
    whole.failures.clear();
    for (d, r, t) in shards {
        ensure!(
            t.columns == table.columns,
            "`{}`: runs.csv has other columns than the first shard's",
            d.display()
        );
        let runs = Shard {
            index: r.shard.index,
            count,
        }
        .runs(first.runs);
        let got: Vec<u64> = t.rows.iter().map(|row| row.run).collect();
        ensure!(
            got.iter().copied().eq(runs.clone()),
            "`{}`: runs.csv does not hold runs {}..{} in order (shard {}/{count})",
            d.display(),
            runs.start,
            runs.end,
            r.shard.index
        );
        whole.failures.extend(r.failures);
        table.rows.extend(t.rows);
    }
    whole.shard = ShardJson { index: 0, count: 1 };
    whole.first_run = 0;
    whole.end_run = whole.runs;
    tally(&mut whole, &table);
    Ok((table, whole))
}

/// The text of a report: counts, failures, and the statistics of the parameters and the
/// summary columns.
#[must_use]
pub fn render_text(r: &Report) -> String {
    let mut out = format!(
        "sweep {}: runs {}..{} of {} (shard {}/{}): {} complete, {} stopped, {} invalid\n",
        r.sweep,
        r.first_run,
        r.end_run,
        r.runs,
        r.shard.index,
        r.shard.count,
        r.complete,
        r.stopped,
        r.invalid
    );
    for f in r.failures.iter().take(10) {
        let _ = writeln!(out, "  run {} {}: {}", f.run, f.status, f.reason);
    }
    if r.failures.len() > 10 {
        let _ = writeln!(out, "  … {} more in sweep.json", r.failures.len() - 10);
    }
    let _ = writeln!(
        out,
        "{:<32} {:>6} {:>12} {:>12} {:>12} {:>12}",
        "over the complete runs", "count", "mean", "std", "min", "max"
    );
    let f = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.5e}"));
    for s in r.statistics.iter().take(r.summary_columns) {
        let _ = writeln!(
            out,
            "{:<32} {:>6} {:>12} {:>12} {:>12} {:>12}",
            s.column,
            s.count,
            f(s.mean),
            f(s.std),
            f(s.min),
            f(s.max)
        );
    }
    out
}
