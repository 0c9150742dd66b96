//! `kanegen count MODEL`: operation counts of A and b for one model, per algorithm and convention.

use kanegen_core::linalg::Vec3;
use kanegen_core::sym::{Convention, Counts, Sym, Trace, Tracer};
use kanegen_core::{Algorithm, Chain, Loads};
use serde::Serialize;

/// One line of the report (the JSON contract).
#[derive(Clone, Debug, Serialize)]
pub struct CountLine {
    /// Algorithm name.
    pub algorithm: String,
    /// `mass_matrix` or `bias`.
    pub function: String,
    /// `paper`, `folded` or `emitted`.
    pub convention: String,
    /// Multiplications.
    pub mul: u64,
    /// Additions and subtractions.
    pub add: u64,
    /// Divisions.
    pub div: u64,
    /// Square roots.
    pub sqrt: u64,
    /// Angles whose sine and/or cosine is taken.
    pub sincos: u64,
}

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct CountReport {
    /// Model name.
    pub model: String,
    /// Degrees of freedom.
    pub n: usize,
    /// Whether gravity was included in `bias`.
    pub gravity: bool,
    /// One line per algorithm, function and convention.
    pub counts: Vec<CountLine>,
}

/// Traces `A(q)` of `alg` for `chain` (model numbers as constants, `q` as inputs); outputs are the
/// upper triangle.
pub fn trace_mass_matrix(chain: &Chain, alg: Algorithm) -> Trace {
    let t = Tracer::new();
    let p = chain.params::<Sym>();
    let q: Vec<Sym> = chain
        .joints()
        .iter()
        .map(|j| t.input(format!("q_{}", j.name)))
        .collect();
    let a = alg.mass_matrix(&p, &q);
    let out: Vec<Sym> = a
        .iter()
        .enumerate()
        .flat_map(|(i, r)| r[i..].to_vec())
        .collect();
    t.finish(&out)
}

/// Traces `b(q, q̇, τ)` of `alg` (gravity when given).
pub fn trace_bias(chain: &Chain, alg: Algorithm, gravity: Option<[f64; 3]>) -> Trace {
    let t = Tracer::new();
    let p = chain.params::<Sym>();
    let names: Vec<&str> = chain.joints().iter().map(|j| j.name.as_str()).collect();
    let q: Vec<Sym> = names.iter().map(|n| t.input(format!("q_{n}"))).collect();
    let qd: Vec<Sym> = names.iter().map(|n| t.input(format!("qd_{n}"))).collect();
    let tau: Vec<Sym> = names.iter().map(|n| t.input(format!("tau_{n}"))).collect();
    let loads = Loads {
        tau: Some(tau),
        gravity: gravity.map(Vec3::from_f64),
        external: Vec::new(),
    };
    let b = alg.bias(&p, &q, &qd, &loads);
    t.finish(&b)
}

fn line(alg: Algorithm, function: &str, conv: Convention, c: Counts) -> CountLine {
    CountLine {
        algorithm: alg.name().into(),
        function: function.into(),
        convention: conv.name().into(),
        mul: c.mul,
        add: c.add,
        div: c.div,
        sqrt: c.sqrt,
        sincos: c.sincos,
    }
}

/// Counts for every requested algorithm.
pub fn count(chain: &Chain, algorithms: &[Algorithm], gravity: Option<[f64; 3]>) -> CountReport {
    let mut counts = Vec::new();
    for &alg in algorithms {
        for (function, trace) in [
            ("mass_matrix", trace_mass_matrix(chain, alg)),
            ("bias", trace_bias(chain, alg, gravity)),
        ] {
            for conv in Convention::ALL {
                counts.push(line(alg, function, conv, trace.counts(conv)));
            }
        }
    }
    CountReport {
        model: chain.name().into(),
        n: chain.dof(),
        gravity: gravity.is_some(),
        counts,
    }
}

/// Appends the table of count lines (header and one row per line) to `s`.
fn write_count_table(s: &mut String, counts: &[CountLine]) {
    use std::fmt::Write;
    let _ = writeln!(
        s,
        "{:<14} {:<12} {:<9} {:>8} {:>8} {:>8} {:>5} {:>5} {:>7}",
        "algorithm", "function", "conv.", "mul", "add", "m+a", "div", "sqrt", "sincos"
    );
    for c in counts {
        let _ = writeln!(
            s,
            "{:<14} {:<12} {:<9} {:>8} {:>8} {:>8} {:>5} {:>5} {:>7}",
            c.algorithm,
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
        "model {} (N = {}), gravity {}\n\n",
        r.model,
        r.n,
        if r.gravity { "on" } else { "off" }
    );
    write_count_table(&mut s, &r.counts);
    s
}

// ---------------------------------------------------------------------------------------------
// `kanegen count SCENE`: the scene's dynamics and the operations each effect adds.

use crate::scene::{BaseSpec, Scene, SceneWrench};
use kanegen_core::algorithms::floating::{
    floating_dynamics, quat_to_matrix, FloatingBase, FloatingState,
};
use kanegen_core::{ExternalWrench, Scalar};
use std::path::Path;

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

/// One effect of a scene: `gravity`, `wrench[i]` (the scene's i-th wrench) or `damping`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effect {
    /// Uniform gravity.
    Gravity,
    /// The i-th external wrench (constant: folded in; tabulated: six runtime inputs).
    Wrench(usize),
    /// Joint viscous damping `−c q̇`, traced as part of the generalized force.
    Damping,
}

impl Effect {
    /// `gravity`, `wrench[i]`, `damping`.
    #[must_use]
    pub fn name(self) -> String {
        match self {
            Effect::Gravity => "gravity".into(),
            Effect::Wrench(i) => format!("wrench[{i}]"),
            Effect::Damping => "damping".into(),
        }
    }
}

/// The effects a scene names, in the order gravity, wrenches, damping.
#[must_use]
pub fn scene_effects(scene: &Scene) -> Vec<Effect> {
    let mut v = Vec::new();
    if scene.gravity.is_some() {
        v.push(Effect::Gravity);
    }
    v.extend((0..scene.wrenches.len()).map(Effect::Wrench));
    if scene.damping.is_some() {
        v.push(Effect::Damping);
    }
    v
}

/// The `i`-th wrench of a scene on the tracer: a constant wrench is folded into the code; a
/// tabulated one becomes the runtime inputs `f{i}_x … m{i}_z` (its value changes with time).
fn sym_wrench(t: &Tracer, i: usize, w: &SceneWrench) -> ExternalWrench<Sym> {
    let (force, moment) = if w.is_tabulated() {
        let v3 = |p: &str| {
            Vec3::new(
                t.input(format!("{p}{i}_x")),
                t.input(format!("{p}{i}_y")),
                t.input(format!("{p}{i}_z")),
            )
        };
        (v3("f"), v3("m"))
    } else {
        let (f, m) = w.value_at(0.0);
        (Vec3::from_f64(f), Vec3::from_f64(m))
    };
    ExternalWrench {
        body: w.body,
        frame: w.frame,
        force,
        moment,
    }
}

/// The symbolic base state of a free-floating scene: `p₀`, the quaternion, `v_b`, `ω_b` inputs.
fn sym_floating_state(t: &Tracer) -> FloatingState<Sym> {
    let v3 = |p: &str| {
        Vec3::new(
            t.input(format!("{p}_x")),
            t.input(format!("{p}_y")),
            t.input(format!("{p}_z")),
        )
    };
    let position = v3("p0");
    let quat = ["x", "y", "z", "w"].map(|c| t.input(format!("quat_{c}")));
    FloatingState {
        position,
        rotation: quat_to_matrix(&quat),
        v_b: v3("v_b"),
        omega_b: v3("omega_b"),
    }
}

/// Traces `b` of the scene's dynamics under `alg` with only the effects in `effects` (drives are
/// the runtime inputs `tau`; damping subtracts `c q̇` from them). Free-floating: `b` of
/// [`floating_dynamics`] (`6 + N` entries) with the base pose and twist as inputs.
pub fn trace_scene_bias(scene: &Scene, alg: Algorithm, effects: &[Effect]) -> Trace {
    let t = Tracer::new();
    let chain = &scene.chain;
    let p = chain.params::<Sym>();
    let names: Vec<&str> = chain.joints().iter().map(|j| j.name.as_str()).collect();
    let q: Vec<Sym> = names.iter().map(|n| t.input(format!("q_{n}"))).collect();
    let qd: Vec<Sym> = names.iter().map(|n| t.input(format!("qd_{n}"))).collect();
    let mut tau: Vec<Sym> = names.iter().map(|n| t.input(format!("tau_{n}"))).collect();
    if effects.contains(&Effect::Damping) {
        if let Some(c) = &scene.damping {
            for (i, ti) in tau.iter_mut().enumerate() {
                *ti = *ti - Sym::constant(c[i]) * qd[i];
            }
        }
    }
    let loads = Loads {
        tau: Some(tau),
        gravity: scene
            .gravity
            .filter(|_| effects.contains(&Effect::Gravity))
            .map(Vec3::from_f64),
        external: scene
            .wrenches
            .iter()
            .enumerate()
            .filter(|(i, _)| effects.contains(&Effect::Wrench(*i)))
            .map(|(i, w)| sym_wrench(&t, i, w))
            .collect(),
    };
    let b = match &scene.base {
        BaseSpec::Fixed => alg.bias(&p, &q, &qd, &loads),
        BaseSpec::FreeFloating { inertial, .. } => {
            let base = FloatingBase::from_inertial(inertial);
            let st = sym_floating_state(&t);
            floating_dynamics(alg, &p, &base, &st, &q, &qd, &loads).b
        }
    };
    t.finish(&b)
}

/// Traces `A` of the scene's dynamics (upper triangle). Free-floating: `A` of
/// [`floating_dynamics`] at zero arm rates with no loads (its `paper` count then also includes the
/// calls of that zero-velocity bias pass; `emitted` is `A` alone).
pub fn trace_scene_mass_matrix(scene: &Scene, alg: Algorithm) -> Trace {
    match &scene.base {
        BaseSpec::Fixed => trace_mass_matrix(&scene.chain, alg),
        BaseSpec::FreeFloating { inertial, .. } => {
            let t = Tracer::new();
            let chain = &scene.chain;
            let p = chain.params::<Sym>();
            let q: Vec<Sym> = chain
                .joints()
                .iter()
                .map(|j| t.input(format!("q_{}", j.name)))
                .collect();
            let base = FloatingBase::from_inertial(inertial);
            let mut st = sym_floating_state(&t);
            st.v_b = Vec3::zero();
            st.omega_b = Vec3::zero();
            let zeros = vec![Sym::zero(); q.len()];
            let a = floating_dynamics(alg, &p, &base, &st, &q, &zeros, &Loads::default()).a;
            let out: Vec<Sym> = a
                .iter()
                .enumerate()
                .flat_map(|(i, r)| r[i..].to_vec())
                .collect();
            t.finish(&out)
        }
    }
}

/// The operations one effect adds to `b`: counts with all effects minus counts without it.
#[derive(Clone, Debug, Serialize)]
pub struct EffectLine {
    /// `gravity`, `wrench[i]` or `damping`.
    pub effect: String,
    /// Algorithm name.
    pub algorithm: String,
    /// `emitted` or `paper`.
    pub convention: String,
    /// Multiplications added.
    pub mul: i64,
    /// Additions and subtractions added.
    pub add: i64,
    /// Divisions added.
    pub div: i64,
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
    /// `A` and `b` (all the scene's effects) per algorithm and convention.
    pub counts: Vec<CountLine>,
    /// Per effect, algorithm and convention (`emitted`, `paper`): the operations it adds.
    pub effects: Vec<EffectLine>,
}

fn diff(a: u64, b: u64) -> i64 {
    i64::try_from(a).unwrap_or(i64::MAX) - i64::try_from(b).unwrap_or(i64::MAX)
}

/// Counts of the scene's `A` and `b` and the cost of each effect, for every requested algorithm.
#[must_use]
pub fn count_scene(scene: &Scene, name: &str, algorithms: &[Algorithm]) -> SceneCountReport {
    let all = scene_effects(scene);
    let mut counts = Vec::new();
    let mut effects = Vec::new();
    for &alg in algorithms {
        let full = trace_scene_bias(scene, alg, &all);
        for (function, trace) in [
            ("mass_matrix", &trace_scene_mass_matrix(scene, alg)),
            ("bias", &full),
        ] {
            for conv in Convention::ALL {
                counts.push(line(alg, function, conv, trace.counts(conv)));
            }
        }
        for &e in &all {
            let rest: Vec<Effect> = all.iter().copied().filter(|x| *x != e).collect();
            let without = trace_scene_bias(scene, alg, &rest);
            for conv in [Convention::Emitted, Convention::Paper] {
                let (w, o) = (full.counts(conv), without.counts(conv));
                effects.push(EffectLine {
                    effect: e.name(),
                    algorithm: alg.name().into(),
                    convention: conv.name().into(),
                    mul: diff(w.mul, o.mul),
                    add: diff(w.add, o.add),
                    div: diff(w.div, o.div),
                });
            }
        }
    }
    SceneCountReport {
        scene: name.into(),
        base: match scene.base {
            BaseSpec::Fixed => "fixed",
            BaseSpec::FreeFloating { .. } => "free-floating",
        }
        .into(),
        n: scene.chain.dof(),
        counts,
        effects,
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
            "effect", "algorithm", "conv.", "mul", "add", "m+a", "div"
        );
        for e in &r.effects {
            let _ = writeln!(
                s,
                "{:<12} {:<14} {:<9} {:>8} {:>8} {:>8} {:>5}",
                e.effect,
                e.algorithm,
                e.convention,
                e.mul,
                e.add,
                e.mul + e.add,
                e.div
            );
        }
    }
    s
}
