//! `kanegen accuracy`: what accuracy costs in time.
//!
//! For a model or a scene, three tables (a fourth, **derivatives**, for a model: `∂τ/∂x`,
//! `∂q̈/∂x` and `M⁻¹` per precision, [`derivatives`]) (four for a scene with Coulomb friction): **evaluation** (`A`, `b`, `q̈` in `f32`, `f64`, fused
//! multiply-add and double-double, generated and interpreted: error against the wide reference
//! and ns per call), **integration** (every integrator over a ladder of steps or tolerances:
//! final-state error against a tight reference and wall time, the work–precision diagram), and
//! **effects** (for each effect a scene enables: operations added and how far the trajectory
//! moves without it), and **friction** (the regularization speed of Coulomb friction: error
//! against a finer one and steps, [`friction`]). Each row carries a sentence on what its next digit costs.

pub mod derivatives;
pub mod effects;
pub mod evaluation;
pub mod friction;
pub mod generated;
pub mod integration;

use anyhow::Result;
use derivatives::{derivative_rows, DerivativeRow};
use effects::{effects_report, EffectRow};
use evaluation::{evaluation_report, random_states, EvalRow, GeneratedFns, Subject};
use friction::{friction_report, friction_sentences, FrictionRow};
use integration::{integration_report, IntegrationRow};
use serde::{Deserialize, Serialize};

/// The report on one model or scene: the JSON contract of `kanegen accuracy`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AccuracyReport {
    /// The model or scene file, as given.
    pub subject: String,
    /// `model` or `scene`.
    pub kind: String,
    /// `fixed` or `free-floating`.
    pub base: String,
    /// Arm degrees of freedom.
    pub n: usize,
    /// Methods of the interpreted rows and of the scene's simulation.
    pub algorithm: String,
    /// Largest 2-norm condition number of `A` over the evaluation states.
    pub cond_a: f64,
    /// Evaluation rows.
    pub evaluation: Vec<EvalRow>,
    /// Derivative rows (models only: `∂τ/∂x`, `∂q̈/∂x`, `M⁻¹`, [`derivatives`]).
    #[serde(default)]
    pub derivatives: Vec<DerivativeRow>,
    /// Integration rows (scenes only).
    pub integration: Vec<IntegrationRow>,
    /// Simulated time of the integration rows, s.
    pub duration: Option<f64>,
    /// Estimated error of the integration reference (dopri5 at 1e-13 against 1e-11).
    pub integration_reference_error: Option<f64>,
    /// Effects rows (scenes only).
    pub effects: Vec<EffectRow>,
    /// The Coulomb-friction regularization ladder (scenes with `friction.coulomb` only),
    /// coarse to fine ([`friction`]).
    #[serde(default)]
    pub friction: Vec<FrictionRow>,
    /// One sentence per friction row.
    #[serde(default)]
    pub friction_sentences: Vec<String>,
    /// One sentence per evaluation row, then per integration row: what the next digit costs.
    pub sentences: Vec<String>,
    /// How the double-double reference was checked against exact rational arithmetic.
    pub reference_check: String,
}

/// Number of random states the evaluation errors are the worst over.
pub const STATES: usize = 8;

/// Decimal digits of a relative error (`−log10`). A zero error means the result, delivered in
/// `f64`, rounds to the reference in every entry: the ≈16 digits of an `f64`; an error of 1 or
/// more, or a non-finite one, means no correct digit (0).
#[must_use]
pub fn digits(err: f64) -> f64 {
    if !err.is_finite() || err >= 1.0 {
        0.0
    } else if err > 0.0 {
        -err.log10()
    } else {
        -(f64::EPSILON / 2.0).log10()
    }
}

/// What one evaluation row's digits cost against the `f64` row of the same path (interpreted
/// `f64` for the interpreted rows and for itself).
fn eval_sentence(r: &EvalRow, base: &EvalRow, timing: bool) -> String {
    let (d, d0) = (digits(r.rel_err_qdd), digits(base.rel_err_qdd));
    let dd = d - d0;
    let what = format!("{} {}", r.path, r.precision);
    let ratio = r.ns / base.ns;
    if std::ptr::eq(r, base) {
        return if timing {
            format!(
                "{what}: the baseline, {d:.1} digits of q̈ in {:.0} ns.",
                r.ns
            )
        } else {
            format!("{what}: the baseline, {d:.1} digits of q̈.")
        };
    }
    let against = format!("{} {}", base.path, base.precision);
    if !timing || !ratio.is_finite() {
        return format!("{what}: {d:.1} digits of q̈ ({dd:+.1} against {against}).");
    }
    if dd > 0.5 {
        format!(
            "{what}: {d:.1} digits of q̈, {dd:+.1} over {against}, for {ratio:.2}× its time: \
             each extra digit costs {:.2}× the time.",
            ratio.powf(1.0 / dd)
        )
    } else if dd < -0.5 {
        format!(
            "{what}: {d:.1} digits of q̈, {:.1} fewer than {against}, at {ratio:.2}× its time: \
             each digit given up {}.",
            -dd,
            if ratio < 1.0 {
                format!(
                    "saves {:.0}% of the time",
                    100.0 * (1.0 - ratio.powf(1.0 / -dd))
                )
            } else {
                "saves nothing".into()
            }
        )
    } else {
        format!("{what}: the same digits as {against} ({d:.1}) at {ratio:.2}× its time.")
    }
}

fn integration_sentences(rows: &[IntegrationRow]) -> Vec<String> {
    let mut out = Vec::new();
    for (k, r) in rows.iter().enumerate() {
        let prev = (k > 0 && rows[k - 1].integrator == r.integrator).then(|| &rows[k - 1]);
        let s = match (
            r.final_error,
            prev.and_then(|p| p.final_error.map(|e| (p, e))),
        ) {
            (None, _) => format!(
                "{} {}: no digits at any price ({}): the step is beyond what the scene allows.",
                r.integrator,
                r.setting,
                r.failure.as_deref().unwrap_or("failed")
            ),
            (Some(e), None) => format!(
                "{} {}: {:.1} digits in {} steps, {:.2e} s.",
                r.integrator,
                r.setting,
                digits(e),
                r.steps,
                r.wall_s
            ),
            (Some(e), Some((p, pe))) => {
                let gained = digits(e) - digits(pe);
                let ratio = r.wall_s / p.wall_s.max(1e-12);
                let per = if gained > 0.05 {
                    format!(
                        "one more digit costs {:.2}× the time",
                        ratio.powf(1.0 / gained)
                    )
                } else {
                    "no digit gained (at the reference's or round-off's floor)".into()
                };
                format!(
                    "{} {}: {:.1} digits ({gained:+.1}) for {ratio:.2}× the time of {}: {per}.",
                    r.integrator,
                    r.setting,
                    digits(e),
                    p.setting
                )
            }
        };
        out.push(s);
    }
    out
}

/// How the report is built: with timing (the CLI) or without (tests compare the
/// deterministic parts).
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Measure ns per call (evaluation). Integration wall times are always measured.
    pub timing: bool,
}

/// Report on a bare model (fixed base, evaluation only).
pub fn model_report(
    name: &str,
    chain: &kanegen_model::Model,
    generated: &[GeneratedFns],
    opts: Options,
) -> AccuracyReport {
    let alg = kanegen_dynamics::Methods::RECURRENT;
    let subject = Subject::model(chain.clone());
    let states = random_states(chain.dof(), STATES, 6);
    let ev = evaluation_report(&subject, alg, generated, &states, opts.timing);
    let sentences = eval_sentences(&ev.rows, opts.timing);
    let reference_check = reference_sentence(&ev.rows);
    AccuracyReport {
        subject: name.into(),
        kind: "model".into(),
        base: "fixed".into(),
        n: chain.dof(),
        algorithm: alg.name(),
        cond_a: ev.cond_a,
        evaluation: ev.rows,
        derivatives: derivative_rows(chain, generated, &states, opts.timing),
        integration: Vec::new(),
        duration: None,
        integration_reference_error: None,
        effects: Vec::new(),
        friction: Vec::new(),
        friction_sentences: Vec::new(),
        sentences,
        reference_check,
    }
}

fn eval_sentences(rows: &[EvalRow], timing: bool) -> Vec<String> {
    let f64_of = |path: &str| rows.iter().find(|r| r.precision == "f64" && r.path == path);
    let interpreted = f64_of("interpreted").expect("an interpreted f64 row");
    rows.iter()
        .map(|r| {
            let base = if r.precision == "f64" {
                interpreted
            } else {
                f64_of(&r.path).unwrap_or(interpreted)
            };
            eval_sentence(r, base, timing)
        })
        .collect()
}

/// The sentence on the reference's own accuracy (the `wide` row: double-double against exact
/// rationals).
fn reference_sentence(rows: &[EvalRow]) -> String {
    // An error that overflowed (q̈ itself beyond f64, as with a mass of 5e-324) says so, as the
    // tables do.
    let e = |x: f64| {
        if x.is_finite() {
            format!("{x:.1e}")
        } else {
            "overflow".into()
        }
    };
    match rows.iter().find(|r| r.precision == "wide") {
        Some(w) if !w.rel_err_qdd.is_nan() => format!(
            "double-double against exact rationals at {} states with rational joint sines and \
             cosines: A {}, b {}, q̈ {}",
            evaluation::EXACT_STATES,
            e(w.rel_err_a),
            e(w.rel_err_b),
            e(w.rel_err_qdd)
        ),
        _ => "double-double not checked against exact rationals (exactness lost)".into(),
    }
}

/// Report on a scene: evaluation at its base state and effects, integration ladder, effects.
pub fn scene_report(
    name: &str,
    scene: &kanegen_sim::scene::Scene,
    opts: Options,
) -> Result<AccuracyReport> {
    let alg = scene.simulation.algorithm;
    let subject = Subject::scene(scene);
    let states = random_states(scene.model.dof(), STATES, 6);
    let ev = evaluation_report(&subject, alg, &[], &states, opts.timing);
    let repeats = if opts.timing { 5 } else { 1 };
    let integ = integration_report(scene, repeats)?;
    let friction = friction_report(scene, repeats)?;
    let mut sentences = eval_sentences(&ev.rows, opts.timing);
    let reference_check = reference_sentence(&ev.rows);
    sentences.extend(integration_sentences(&integ.rows));
    Ok(AccuracyReport {
        subject: name.into(),
        kind: "scene".into(),
        base: if scene.is_floating() {
            "free-floating"
        } else {
            "fixed"
        }
        .into(),
        n: scene.model.dof(),
        algorithm: alg.name(),
        cond_a: ev.cond_a,
        evaluation: ev.rows,
        derivatives: Vec::new(),
        integration: integ.rows,
        duration: Some(integ.duration),
        integration_reference_error: Some(integ.reference_error),
        effects: effects_report(scene)?,
        friction_sentences: friction_sentences(&friction),
        friction,
        sentences,
        reference_check,
    })
}
