//! `kanegen count MODEL` and `kanegen count SCENE`: operation counts of `A` and `b` per method
//! and convention, and what each of a scene's effects adds (traced by `kanegen_trace::count`).

use crate::scene_spec;
use kanegen_codegen::choose::candidates;
use kanegen_dynamics::{MassMatrixMethod, Methods, NonlinearEffectsMethod};
use kanegen_model::{BaseKind, Model};
use kanegen_sim::scene::{BaseSpec, Scene};
use kanegen_trace::count::{count_lines, derivative_lines, effect_lines, CountLine, EffectLine};
use kanegen_trace::{Base, Function, Spec, TraceError};
use serde::Serialize;
use std::path::Path;

/// The report of `kanegen count MODEL`.
#[derive(Clone, Debug, Serialize)]
pub struct CountReport {
    /// Model name.
    pub model: String,
    /// Degrees of freedom of the joints.
    pub n: usize,
    /// `fixed` or `free-floating`.
    pub base: String,
    /// Whether gravity was included in `tau_minus_c`.
    pub gravity: bool,
    /// One line per function, method and convention.
    pub counts: Vec<CountLine>,
    /// Methods left out by the size rule ([`DIRECT_MAX_N`]); absent when none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub omitted: Vec<String>,
    /// The derivative functions (`inverse_dynamics_derivatives`, `forward_dynamics_derivatives`,
    /// `mass_matrix_inverse`), their one analytical candidate per convention; absent above
    /// `kanegen_codegen::plan::DERIVATIVES_MAX_NV` speeds (their unrolled candidate is not
    /// traced there) and for a model with mimic joints (not traced in its coordinates).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub derivatives: Vec<CountLine>,
}

/// Above this many joints `count` without `--algorithm` leaves out the direct Kane sums
/// (`kane-direct`): their `M` has O(N³) operations, and tracing it needs about 100 bytes per
/// operation (2.3 M operations, 0.23 GB at N = 100; about 30 GB at N = 500). `--algorithm
/// kane-direct` still counts them.
pub const DIRECT_MAX_N: usize = 100;

/// Every pair of methods the generator may emit a function of `model` by
/// ([`kanegen_codegen::choose::candidates`] of `M` and of `c`): on a chain every mass-matrix and
/// every nonlinear-effects method, `newton-euler` included; on a tree the local-frame ones (`crba`; `rnea`,
/// `newton-euler`).
#[must_use]
pub fn emittable(model: &Model) -> Vec<Methods> {
    let chain = model.is_chain();
    let mut all = candidates(Function::MassMatrix, MassMatrixMethod::Crba, chain);
    for m in candidates(Function::NonlinearEffects, MassMatrixMethod::Crba, chain) {
        if !all.contains(&m) {
            all.push(m);
        }
    }
    all
}

/// The methods of a selection of presets, each listed once, in report order.
fn methods_of(presets: &[Methods]) -> (Vec<MassMatrixMethod>, Vec<NonlinearEffectsMethod>) {
    let mass = MassMatrixMethod::ALL
        .into_iter()
        .filter(|m| presets.iter().any(|p| p.mass_matrix == *m))
        .collect();
    let nonlinear_effects = NonlinearEffectsMethod::ALL
        .into_iter()
        .filter(|b| presets.iter().any(|p| p.nonlinear_effects == *b))
        .collect();
    (mass, nonlinear_effects)
}

/// Counts of `A` for every mass-matrix method and of `b` for every nonlinear-effects method of `presets`, on
/// the model's base (free-floating: `6 + N` speeds, the base state as inputs).
///
/// # Errors
/// If a trace is refused (`kanegen_trace::trace`).
pub fn count(
    model: &Model,
    presets: &[Methods],
    gravity: Option<[f64; 3]>,
) -> Result<CountReport, TraceError> {
    count_with_progress(model, presets, gravity, true, &|_, _| {})
}

/// [`count`], tracing one method at a time and calling `progress(done, total)` after each;
/// unless `explicit` (the methods were asked for), the size rule [`DIRECT_MAX_N`] applies.
///
/// # Errors
/// If a trace is refused (`kanegen_trace::trace`).
pub fn count_with_progress(
    model: &Model,
    presets: &[Methods],
    gravity: Option<[f64; 3]>,
    explicit: bool,
    progress: &dyn Fn(usize, usize),
) -> Result<CountReport, TraceError> {
    let (mut mass, mut nonlinear_effects) = methods_of(presets);
    let mut omitted = Vec::new();
    if !explicit && model.dof() > DIRECT_MAX_N {
        mass.retain(|m| *m != MassMatrixMethod::KaneDirect);
        nonlinear_effects.retain(|b| *b != NonlinearEffectsMethod::KaneDirect);
        omitted.push(format!(
            "kane-direct (N = {} > {DIRECT_MAX_N}: O(N³); --algorithm kane-direct counts it)",
            model.dof()
        ));
    }
    let spec = Spec {
        base: match (model.base_kind(), model.base_inertial()) {
            (BaseKind::FreeFloating, Some(i)) => Base::FreeFloating(i.clone()),
            _ => Base::Fixed,
        },
        ..Spec::with_gravity(gravity)
    };
    let total = mass.len() + nonlinear_effects.len();
    let mut counts = Vec::new();
    for (k, m) in mass.iter().enumerate() {
        counts.extend(count_lines(model, &[*m], &[], &spec)?);
        progress(k + 1, total);
    }
    for (k, b) in nonlinear_effects.iter().enumerate() {
        counts.extend(count_lines(model, &[], &[*b], &spec)?);
        progress(mass.len() + k + 1, total);
    }
    let nv = kanegen_codegen::plan::speeds(model);
    let derivatives = if nv <= kanegen_codegen::plan::DERIVATIVES_MAX_NV {
        derivative_lines(model, &spec)?
    } else {
        Vec::new()
    };
    Ok(CountReport {
        model: model.name().into(),
        n: model.coordinate_count(),
        base: model.base_kind().name().into(),
        gravity: gravity.is_some(),
        counts,
        omitted,
        derivatives,
    })
}

/// Appends the table of count lines (header and one row per line) to `s`.
fn write_count_table(s: &mut String, counts: &[CountLine]) {
    use std::fmt::Write;
    let _ = writeln!(
        s,
        "{:<14} {:<12} {:<9} {:>8} {:>8} {:>8} {:>5} {:>5} {:>7}",
        "method", "function", "conv.", "mul", "add", "m+a", "div", "sqrt", "sincos"
    );
    for c in counts {
        let _ = writeln!(
            s,
            "{:<14} {:<12} {:<9} {:>8} {:>8} {:>8} {:>5} {:>5} {:>7}",
            c.method,
            c.function,
            c.convention,
            c.mul,
            c.add,
            c.mul + c.add,
            c.div,
            c.sqrt,
            c.sincos
        );
    }
}

/// Human-readable table.
pub fn render_text(r: &CountReport) -> String {
    let mut s = format!(
        "model {} (N = {}, {} base), gravity {}\n\n",
        r.model,
        r.n,
        r.base,
        if r.gravity { "on" } else { "off" }
    );
    write_count_table(&mut s, &r.counts);
    for o in &r.omitted {
        let _ = std::fmt::Write::write_fmt(&mut s, format_args!("\nomitted: {o}\n"));
    }
    if !r.derivatives.is_empty() {
        s.push_str("\nderivatives\n");
        write_count_table(&mut s, &r.derivatives);
    }
    s
}

/// Whether `path` is a scene file: a `.toml` whose top level has a `model` key (a model TOML has
/// none). Unreadable or unparsable files are not scenes (the model loader reports the error).
#[must_use]
pub fn is_scene_file(path: &Path) -> bool {
    if path.extension().and_then(|e| e.to_str()) != Some("toml") {
        return false;
    }
    std::fs::read_to_string(path)
        .ok()
        .and_then(|s| s.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("model"))
}

/// The report of `kanegen count SCENE`.
#[derive(Clone, Debug, Serialize)]
pub struct SceneCountReport {
    /// The scene file.
    pub scene: String,
    /// `fixed` or `free-floating`.
    pub base: String,
    /// Arm degrees of freedom.
    pub n: usize,
    /// `A` and `b` (all the scene's effects) per method and convention.
    pub counts: Vec<CountLine>,
    /// Per effect, nonlinear-effects method and convention (`emitted`, `paper`): the operations it adds.
    pub effects: Vec<EffectLine>,
    /// Per payload event kind (`capture`, `release`), mass-matrix method and convention: the
    /// operations of one event (`method` is the mass-matrix method; see
    /// [`crate::commands::count_events`]); absent when the scene has no `[[events]]`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<EffectLine>,
}

/// Counts of the scene's `A` and `b` and the cost of each effect, for the methods of `presets`.
///
/// # Errors
/// If a trace is refused (`kanegen_trace::trace`).
pub fn count_scene(
    scene: &Scene,
    name: &str,
    presets: &[Methods],
) -> Result<SceneCountReport, TraceError> {
    let (mass, nonlinear_effects) = methods_of(presets);
    let spec = scene_spec::spec(scene);
    let counts = count_lines(&scene.model, &mass, &nonlinear_effects, &spec)?;
    Ok(SceneCountReport {
        scene: name.into(),
        base: match scene.base {
            BaseSpec::Fixed => "fixed",
            BaseSpec::FreeFloating { .. } => "free-floating",
        }
        .into(),
        n: scene.model.dof(),
        effects: {
            let mut e = effect_lines(&scene.model, &nonlinear_effects, &spec)?;
            e.extend(drive_effect_lines(scene, &nonlinear_effects));
            e
        },
        events: crate::commands::count_events::event_effect_lines(scene, &mass, &counts),
        counts,
    })
}

/// The drive effects outside the traced `A` and `b` (the viscous part of `friction` is
/// `damping`, traced with `b`), counted from their formulas, per nonlinear-effects method (the same for
/// each) and convention: `coulomb` subtracts `τ_c,i tanh(q̇_i · (1/v_s))` from `b` (2 mul,
/// 1 add and one `tanh` per joint); `rotor` adds the constant `I_m,i n_i²` to `A_ii` (1 add per
/// joint) before the solve; `flexible` (Spong's joints) forms the spring-damper torque
/// `K_i (θ_i − q_i) + D_i (θ̇_i − q̇_i)` (2 mul, 3 add; 1 mul, 1 add without `D_i`) and the
/// motor acceleration `(τ_m,i − τ_s,i) / B_i` (1 add, 1 div) per joint. `emitted` leaves out the
/// joints whose coefficient is 0 (folded away), `paper` counts every joint.
fn drive_effect_lines(
    scene: &Scene,
    nonlinear_effects: &[NonlinearEffectsMethod],
) -> Vec<EffectLine> {
    let nonzero = |v: &[f64]| v.iter().filter(|x| **x != 0.0).count() as i64;
    let n = scene.model.dof() as i64;
    let mut lines = Vec::new();
    let effects: Vec<(&str, &[f64], i64)> = [
        scene
            .coulomb
            .as_ref()
            .map(|c| ("coulomb", c.tau_c.as_slice(), 2)),
        scene
            .rotor
            .as_ref()
            .map(|r| ("rotor", r.reflected.as_slice(), 0)),
    ]
    .into_iter()
    .flatten()
    .collect();
    for b in nonlinear_effects {
        for &(effect, coef, mul_per_joint) in &effects {
            for conv in ["emitted", "paper"] {
                let k = if conv == "paper" { n } else { nonzero(coef) };
                lines.push(EffectLine {
                    effect: effect.into(),
                    method: b.name().into(),
                    convention: conv.into(),
                    mul: mul_per_joint * k,
                    add: k,
                    div: 0,
                });
            }
        }
        if let Some(f) = &scene.flexible {
            let damped = nonzero(&f.damping);
            for conv in ["emitted", "paper"] {
                let d = if conv == "paper" { n } else { damped };
                lines.push(EffectLine {
                    effect: "flexible".into(),
                    method: b.name().into(),
                    convention: conv.into(),
                    mul: n + d,
                    add: 2 * n + 2 * d,
                    div: n,
                });
            }
        }
    }
    lines
}

/// Appends one row per effect line to `s`.
fn write_effect_rows(s: &mut String, lines: &[EffectLine]) {
    use std::fmt::Write;
    for e in lines {
        let _ = writeln!(
            s,
            "{:<12} {:<14} {:<9} {:>8} {:>8} {:>8} {:>5}",
            e.effect,
            e.method,
            e.convention,
            e.mul,
            e.add,
            e.mul + e.add,
            e.div
        );
    }
}

/// Human-readable rendering of [`SceneCountReport`].
#[must_use]
pub fn render_scene_text(r: &SceneCountReport) -> String {
    use std::fmt::Write;
    let names: Vec<String> = {
        let mut v: Vec<String> = Vec::new();
        for e in &r.effects {
            if !v.contains(&e.effect) {
                v.push(e.effect.clone());
            }
        }
        v
    };
    let mut s = format!(
        "scene {} ({} base, N = {}), effects: {}\n\n",
        r.scene,
        r.base,
        r.n,
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        }
    );
    write_count_table(&mut s, &r.counts);
    if !r.effects.is_empty() {
        let _ = writeln!(
            s,
            "\noperations each effect adds to b (all effects minus all but that one)\n\n{:<12} {:<14} {:<9} {:>8} {:>8} {:>8} {:>5}",
            "effect", "method", "conv.", "mul", "add", "m+a", "div"
        );
        write_effect_rows(&mut s, &r.effects);
        if names.iter().any(|e| e == "coulomb" || e == "rotor") {
            let _ = writeln!(
                s,
                "\ncoulomb and rotor are counted from their formulas: coulomb also takes one tanh \
                 per joint; rotor adds to A's diagonal (before the solve), not to b"
            );
        }
        if names.iter().any(|e| e == "flexible") {
            let _ = writeln!(
                s,
                "\nflexible is counted from its formulas: the spring-damper torque (the links' τ) \
                 and the motor accelerations (τ_m − τ_s) / B; the drives act on the motors"
            );
        }
    }
    if !r.events.is_empty() {
        let _ = writeln!(
            s,
            "\noperations of one payload event (once per event, not per step: a capture \
             evaluates A before and after and solves the impulse equation; a release switches \
             the model)\n\n{:<12} {:<14} {:<9} {:>8} {:>8} {:>8} {:>5}",
            "event", "A method", "conv.", "mul", "add", "m+a", "div"
        );
        write_effect_rows(&mut s, &r.events);
    }
    s
}
