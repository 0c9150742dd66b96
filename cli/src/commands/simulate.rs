//! `kanegen simulate SCENE`: the files of a run.

use anyhow::{Context, Result};
use kanegen_sim::scene::Scene;
use kanegen_sim::simulate::{trajectory_csv, Run};
use std::path::Path;

/// Writes `trajectory.csv`, `summary.json`, `joints.svg`, `end_effector.svg`, (free-floating)
/// `base_attitude.svg` and (when anything is monitored) `drift.svg` into `dir` (created if
/// needed).
pub fn write_outputs(scene: &Scene, run: &Run, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create `{}`", dir.display()))?;
    let w = |name: &str, text: &str| -> Result<()> {
        let p = dir.join(name);
        std::fs::write(&p, text).with_context(|| format!("cannot write `{}`", p.display()))
    };
    w("trajectory.csv", &trajectory_csv(scene, run))?;
    w(
        "summary.json",
        &(serde_json::to_string_pretty(&run.summary)? + "\n"),
    )?;
    crate::plots::simulate::write_plots(scene, run, dir)
}
