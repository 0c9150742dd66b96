//! `kanegen simulate SCENE`: the run, streamed to the files of `--out`.

use super::simulate_text::{csv_header, csv_row, trajectory_csv};
use crate::output::OutputDir;
use anyhow::{Context, Result};
use kanegen_sim::scene::Scene;
use kanegen_sim::simulate::{simulate_to, Control, Decimated, Run, Sample, Sink, Summary};
use std::io::Write;
use std::path::Path;

/// Every file `simulate --out DIR` may write.
pub const FILES: [&str; 6] = [
    "trajectory.csv",
    "summary.json",
    "joints.svg",
    "end_effector.svg",
    "base_attitude.svg",
    "drift.svg",
];

/// Samples kept for the plots (evenly decimated over the run, [`Decimated`]).
pub const PLOT_SAMPLES: usize = 4000;

/// Runs `scene`; with `out`, streams `trajectory.csv` into a temporary file there as samples are
/// produced (memory does not grow with the duration) and, when the run ends — complete,
/// stopped by Ctrl-C ([`Control::stop`]) or by an integrator failure — renames it into place
/// and writes `summary.json` (with `"complete"`, `"t_end"`, `"stopped"`) and the plots (from
/// [`PLOT_SAMPLES`] decimated samples). The summary is returned checked finite.
///
/// # Errors
/// A file that cannot be written (nothing is then renamed into place), or a non-finite
/// summary.
pub fn run(scene: &Scene, out: Option<&OutputDir>, control: Control<'_>) -> Result<Summary> {
    let mut plot = Decimated::new(PLOT_SAMPLES);
    let mut csv = match out {
        Some(d) => {
            let mut w = std::io::BufWriter::new(d.stream("trajectory.csv")?);
            writeln!(w, "{}", csv_header(scene).join(","))
                .context("cannot write trajectory.csv")?;
            Some(w)
        }
        None => None,
    };
    let mut sink = |s: &Sample| -> Result<()> {
        if let Some(w) = csv.as_mut() {
            w.write_all(csv_row(scene, s).as_bytes())
                .context("cannot write trajectory.csv")?;
        }
        if out.is_some() {
            plot.sample(s)?;
        }
        Ok(())
    };
    let summary = simulate_to(scene, &mut sink, control)?;
    summary.check_finite()?;
    if let (Some(d), Some(w)) = (out, csv) {
        let f = w
            .into_inner()
            .map_err(|e| anyhow::Error::new(e.into_error()))
            .context("cannot write trajectory.csv")?;
        let run = Run {
            summary: summary.clone(),
            samples: plot.into_samples(),
        };
        let mut files = vec![(
            "summary.json",
            (serde_json::to_string_pretty(&summary)? + "\n").into_bytes(),
        )];
        for (name, svg) in crate::plots::simulate::render_plots(scene, &run)? {
            files.push((name, svg.into_bytes()));
        }
        d.commit_stream(f, "trajectory.csv")?;
        d.write_all(&files)?;
        let mut written: Vec<&str> = files.iter().map(|(n, _)| *n).collect();
        written.push("trajectory.csv");
        d.remove_stale(&written)?;
    }
    Ok(summary)
}

/// Writes `trajectory.csv`, `summary.json`, `joints.svg`, `end_effector.svg`, (free-floating)
/// `base_attitude.svg` and (when anything is monitored) `drift.svg` of a finished in-memory run
/// into `dir` (created if needed, files replaced).
pub fn write_outputs(scene: &Scene, run: &Run, dir: &Path) -> Result<()> {
    let d = OutputDir::plan(dir, &FILES, true, &[])?;
    let mut files = vec![
        ("trajectory.csv", trajectory_csv(scene, run).into_bytes()),
        (
            "summary.json",
            (serde_json::to_string_pretty(&run.summary)? + "\n").into_bytes(),
        ),
    ];
    for (name, svg) in crate::plots::simulate::render_plots(scene, run)? {
        files.push((name, svg.into_bytes()));
    }
    d.write_all(&files)?;
    let written: Vec<&str> = files.iter().map(|(n, _)| *n).collect();
    d.remove_stale(&written)
}
