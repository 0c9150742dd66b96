//! `kanegen accuracy`: run the work–precision report ([`crate::reports::accuracy`]) on models and scenes,
//! render it as Markdown (tera template `templates/accuracy.md.tera`), JSON and SVG.

use crate::plots::accuracy::{work_precision_chart, Curve};
use crate::reports::accuracy::evaluation::GeneratedFns;
use crate::reports::accuracy::{model_report, scene_report, AccuracyReport, Options};
use anyhow::{Context, Result};

use std::path::{Path, PathBuf};

/// What `kanegen accuracy` reports on when given no input (and what `docs/accuracy.md` holds):
/// SSRMS as a model (with its generated code), SSRMS slewing 116 t, the free-floating 7-dof arm,
/// SSRMS with every traced effect kind, and SSRMS with its drives modelled (rotor inertia and
/// friction).
pub const DEFAULT_INPUTS: [&str; 5] = [
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
    "scenes/ssrms_payload_fixed.toml",
    "scenes/free_floating_7dof.toml",
    "scenes/ssrms_effects.toml",
    "scenes/ssrms_drives.toml",
];

/// Generated variants of a chain that has checked-in generated code (SSRMS).
fn generated_for(chain: &kanegen_model::Model) -> Result<Vec<GeneratedFns>> {
    let ssrms = kanegen_model::io::parse_urdf(super::bench::SSRMS_URDF)?;
    Ok(if *chain == ssrms {
        crate::reports::accuracy::generated::ssrms_variants()
    } else {
        Vec::new()
    })
}

/// Reports on every input (a `.urdf` or `.toml` model, or a scene file).
pub fn run(
    inputs: &[PathBuf],
    allow_nonphysical: bool,
    opts: Options,
) -> Result<Vec<AccuracyReport>> {
    run_with_progress(inputs, allow_nonphysical, opts, &|_, _| {})
}

/// [`run`], calling `progress(done, total)` after each input. A subject whose `A` is singular
/// or not finite at the evaluation states (condition number not a finite number ≥ 1) is an
/// error: its errors and digits would mean nothing.
pub fn run_with_progress(
    inputs: &[PathBuf],
    allow_nonphysical: bool,
    opts: Options,
    progress: &dyn Fn(usize, usize),
) -> Result<Vec<AccuracyReport>> {
    let mut out = Vec::new();
    for (k, path) in inputs.iter().enumerate() {
        progress(k, inputs.len());
        let name = path.display().to_string();
        let r = if super::count::is_scene_file(path) {
            let scene = kanegen_sim::scene::Scene::load(path)?;
            scene_report(&name, &scene, opts).with_context(|| format!("scene `{name}`"))?
        } else {
            let v = kanegen_model::Validation {
                allow_nonphysical_inertia: allow_nonphysical,
            };
            let chain = kanegen_model::io::load_model_with(path, v)
                .with_context(|| format!("model `{name}`"))?;
            model_report(&name, &chain, &generated_for(&chain)?, opts)
        };
        if !(r.cond_a.is_finite() && r.cond_a >= 1.0) {
            anyhow::bail!(
                "`{name}`: the condition number of A is {}: A is singular or not finite at the \
                 evaluation states (a model quantity or the state overflowed), so no error or \
                 digit of the report would mean anything",
                r.cond_a
            );
        }
        out.push(r);
        progress(k + 1, inputs.len());
    }
    Ok(out)
}

/// Every file `accuracy --out DIR` may write for `inputs`: `accuracy.md`, `accuracy.json` and
/// two work–precision figures per input (written for scenes).
#[must_use]
pub fn file_names(inputs: &[PathBuf]) -> Vec<String> {
    let mut v = vec!["accuracy.md".to_string(), "accuracy.json".to_string()];
    for p in inputs {
        let stem = p
            .file_stem()
            .map_or("subject".into(), |s| s.to_string_lossy().into_owned());
        v.push(format!("work_precision_{stem}.svg"));
        v.push(format!("work_precision_{stem}_evals.svg"));
    }
    v
}

fn sci(x: f64) -> String {
    if x.is_nan() {
        "—".into()
    } else if x.is_infinite() {
        "overflow".into()
    } else if x == 0.0 {
        "0 (rounds to the reference)".into()
    } else {
        format!("{x:.2e}")
    }
}

/// What a work–precision figure puts on its cost axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cost {
    /// Wall time (median of repeats; noisy on a shared machine).
    Wall,
    /// Right-hand-side evaluations (deterministic).
    Evals,
}

/// File name of a subject's work–precision figure.
#[must_use]
pub fn figure_name(r: &AccuracyReport, cost: Cost) -> String {
    let stem = Path::new(&r.subject)
        .file_stem()
        .map_or("subject".into(), |s| s.to_string_lossy().into_owned());
    match cost {
        Cost::Wall => format!("work_precision_{stem}.svg"),
        Cost::Evals => format!("work_precision_{stem}_evals.svg"),
    }
}

/// The work–precision chart of a scene's integration rows: final error against wall time or
/// against right-hand-side evaluations.
pub fn render_figure(r: &AccuracyReport, cost: Cost) -> Result<String> {
    let mut curves: Vec<Curve> = Vec::new();
    for row in &r.integration {
        if curves.last().is_none_or(|c| c.0 != row.integrator) {
            curves.push((row.integrator.clone(), Vec::new()));
        }
        if let (Some(e), Some(c)) = (row.final_error, curves.last_mut()) {
            let x = match cost {
                Cost::Wall => row.wall_s,
                Cost::Evals => row.evals as f64,
            };
            c.1.push((x, e));
        }
    }
    let x_desc = match cost {
        Cost::Wall => "wall time (s), median of 5 runs",
        Cost::Evals => "right-hand-side evaluations (A, b and the solve)",
    };
    work_precision_chart(
        &format!(
            "{}: work–precision over {} s",
            r.subject,
            r.duration.unwrap_or(0.0)
        ),
        x_desc,
        "final-state relative error",
        &curves,
    )
}

/// Renders the Markdown report. `timing: false` prints no times (tests compare the rest).
pub fn render_markdown(reports: &[AccuracyReport], timing: bool) -> Result<String> {
    let mut tera = tera::Tera::default();
    tera.add_raw_template(
        "accuracy.md",
        include_str!("../../templates/accuracy.md.tera"),
    )?;
    let mut ctx = tera::Context::new();
    ctx.insert("version", env!("CARGO_PKG_VERSION"));
    ctx.insert("states", &crate::reports::accuracy::STATES);
    let sc = crate::reports::accuracy::generated::sincos_error();
    ctx.insert(
        "sincos",
        &serde_json::json!({"points": sc.points, "abs": format!("{:.2}", sc.abs_ulps),
            "ulps": format!("{:.2}", sc.ulps)}),
    );
    let time = |s: String| if timing { s } else { "—".into() };
    let subjects: Vec<serde_json::Value> = reports
        .iter()
        .map(|r| {
            let nev = r.evaluation.len();
            let evaluation: Vec<serde_json::Value> = r
                .evaluation
                .iter()
                .zip(&r.sentences)
                .map(|(e, s)| {
                    serde_json::json!({"precision": e.precision, "path": e.path,
                        "a": sci(e.rel_err_a), "b": sci(e.rel_err_b), "qdd": sci(e.rel_err_qdd),
                        "ns": time(format!("{:.0}", e.ns)), "sentence": if timing { s.clone() } else { "—".into() }})
                })
                .collect();
            let derivatives: Vec<serde_json::Value> = r
                .derivatives
                .iter()
                .map(|d| {
                    serde_json::json!({"precision": d.precision, "path": d.path,
                        "dtau": sci(d.rel_err_dtau), "dqdd": sci(d.rel_err_dqdd),
                        "minv": sci(d.rel_err_minv), "ns": time(format!("{:.0}", d.ns))})
                })
                .collect();
            let integration: Vec<serde_json::Value> = r
                .integration
                .iter()
                .zip(r.sentences.iter().skip(nev))
                .map(|(i, s)| {
                    serde_json::json!({"integrator": i.integrator, "setting": i.setting,
                        "error": i.final_error.map_or("failed".into(), sci),
                        "wall": time(format!("{:.2e}", i.wall_s)), "steps": i.steps,
                        "sentence": if timing { s.clone() } else { "—".into() }})
                })
                .collect();
            let effects: Vec<serde_json::Value> = r
                .effects
                .iter()
                .map(|e| serde_json::json!({"effect": e.effect, "ops": e.ops, "change": sci(e.trajectory_change)}))
                .collect();
            let friction: Vec<serde_json::Value> = r
                .friction
                .iter()
                .zip(&r.friction_sentences)
                .map(|(f, s)| {
                    serde_json::json!({"v_s": format!("{:e}", f.v_s), "scene": f.scene,
                        "error": f.run.final_error.map_or("failed".into(), sci),
                        "wall": time(format!("{:.2e}", f.run.wall_s)), "steps": f.run.steps,
                        "evals": f.run.evals, "sentence": if timing { s.clone() } else { "—".into() }})
                })
                .collect();
            serde_json::json!({"subject": r.subject, "kind": r.kind, "base": r.base, "n": r.n,
                "algorithm": r.algorithm, "cond_a": format!("{:.3e}", r.cond_a),
                "reference_check": r.reference_check,
                "evaluation": evaluation, "derivatives": derivatives, "integration": integration, "effects": effects,
                "friction": friction, "friction_tolerance": sci(crate::reports::accuracy::friction::TOLERANCE),
                "duration": r.duration, "reference_error": r.integration_reference_error.map_or("—".into(), sci),
                "figure": figure_name(r, Cost::Wall), "figure_evals": figure_name(r, Cost::Evals)})
        })
        .collect();
    ctx.insert("subjects", &subjects);
    Ok(tera.render("accuracy.md", &ctx)?)
}

/// The JSON of one report (the contract) or, for several, `{"subjects": [...]}`.
#[must_use]
pub fn to_json(reports: &[AccuracyReport]) -> serde_json::Value {
    if let [one] = reports {
        serde_json::to_value(one).unwrap_or_default()
    } else {
        serde_json::json!({ "subjects": reports })
    }
}

/// Writes `accuracy.md`, `accuracy.json` and one work–precision SVG per scene into `dir`
/// (created if needed, files replaced).
pub fn write_all(reports: &[AccuracyReport], dir: &Path) -> Result<()> {
    let inputs: Vec<PathBuf> = reports.iter().map(|r| PathBuf::from(&r.subject)).collect();
    let names = file_names(&inputs);
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    write_planned(
        reports,
        &crate::output::OutputDir::plan(dir, &names, true, &[])?,
    )
}

/// Writes the files into a planned output directory, atomically.
pub fn write_planned(reports: &[AccuracyReport], dir: &crate::output::OutputDir) -> Result<()> {
    let mut files: Vec<(String, Vec<u8>)> = vec![
        (
            "accuracy.md".into(),
            render_markdown(reports, true)?.into_bytes(),
        ),
        (
            "accuracy.json".into(),
            (serde_json::to_string_pretty(&to_json(reports))? + "\n").into_bytes(),
        ),
    ];
    for r in reports.iter().filter(|r| !r.integration.is_empty()) {
        for cost in [Cost::Wall, Cost::Evals] {
            files.push((figure_name(r, cost), render_figure(r, cost)?.into_bytes()));
        }
    }
    let files: Vec<(&str, Vec<u8>)> = files.iter().map(|(n, c)| (n.as_str(), c.clone())).collect();
    dir.write_all(&files)?;
    let written: Vec<&str> = files.iter().map(|(n, _)| *n).collect();
    dir.remove_stale(&written)
}
