//! Operation-count reports: what `A` and `b` cost for one model under each method and counting
//! convention, and what each effect of a spec adds (`kanegen count`). Rendering is the CLI's.

use crate::entry::{trace, TraceError, Traced};
use crate::function::Function;
use crate::spec::{Effect, Spec, Subject};
use crate::sym::{Convention, Counts};
use kanegen_dynamics::{MassMatrixMethod, Methods, NonlinearEffectsMethod};
use kanegen_model::Model;
use serde::Serialize;

/// One line of a count report (the JSON contract).
#[derive(Clone, Debug, Serialize)]
pub struct CountLine {
    /// `mass_matrix` (`M`) or `tau_minus_c` (`τ − c`, with the applied loads).
    pub function: String,
    /// The mass-matrix method (for `mass_matrix`) or the nonlinear-effects method (for `tau_minus_c`).
    pub method: String,
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

impl CountLine {
    fn new(function: &str, method: &str, conv: Convention, c: Counts) -> Self {
        CountLine {
            function: function.into(),
            method: method.into(),
            convention: conv.name().into(),
            mul: c.mul,
            add: c.add,
            div: c.div,
            sqrt: c.sqrt,
            sincos: c.sincos,
        }
    }
}

/// The operations one effect adds to `b`: counts with all effects minus counts without it.
#[derive(Clone, Debug, Serialize)]
pub struct EffectLine {
    /// `gravity`, `wrench[i]` or `damping`.
    pub effect: String,
    /// The nonlinear-effects method.
    pub method: String,
    /// `emitted` or `paper`.
    pub convention: String,
    /// Multiplications added.
    pub mul: i64,
    /// Additions and subtractions added.
    pub add: i64,
    /// Divisions added.
    pub div: i64,
}

/// Any mass-matrix method will do for a function that only uses the nonlinear-effects method.
fn with_nonlinear_effects(nonlinear_effects: NonlinearEffectsMethod) -> Methods {
    Methods {
        mass_matrix: MassMatrixMethod::Crba,
        nonlinear_effects,
        ..Methods::SPATIAL
    }
}

/// Traces `M` of every method in `mass` and `τ − c` of every method in `nonlinear_effects` for `model` under
/// `spec`, and lists their counts under every convention.
///
/// # Errors
/// As [`trace`].
pub fn count_lines(
    model: &Model,
    mass: &[MassMatrixMethod],
    nonlinear_effects: &[NonlinearEffectsMethod],
    spec: &Spec,
) -> Result<Vec<CountLine>, TraceError> {
    let mut lines = Vec::new();
    let mut push = |function: &str, method: &str, t: &Traced| {
        for conv in Convention::ALL {
            lines.push(CountLine::new(function, method, conv, t.trace.counts(conv)));
        }
    };
    for &m in mass {
        let methods = Methods {
            mass_matrix: m,
            ..Methods::SPATIAL
        };
        let t = trace(Subject::Model(model), Function::MassMatrix, methods, spec)?;
        push("mass_matrix", m.name(), &t);
    }
    for &b in nonlinear_effects {
        let t = trace(
            Subject::Model(model),
            Function::GeneralizedForces,
            with_nonlinear_effects(b),
            spec,
        )?;
        push("tau_minus_c", b.name(), &t);
    }
    Ok(lines)
}

/// The derivative functions and the name of their (one, analytical) candidate: Carpentier &
/// Mansard's RNEA derivatives, and `M⁻¹` by LDLᵀ on the CRBA's `M`.
pub const DERIVATIVES: [(Function, &str); 3] = [
    (Function::InverseDynamicsDerivatives, "carpentier-mansard"),
    (Function::ForwardDynamicsDerivatives, "carpentier-mansard"),
    (Function::MassMatrixInverse, "crba-ldlt"),
];

/// Traces the derivative functions ([`DERIVATIVES`]) of `model` under `spec` and lists their
/// counts under every convention.
///
/// # Errors
/// As [`trace`].
pub fn derivative_lines(model: &Model, spec: &Spec) -> Result<Vec<CountLine>, TraceError> {
    let mut lines = Vec::new();
    for (f, method) in DERIVATIVES {
        let t = trace(Subject::Model(model), f, Methods::SPATIAL, spec)?;
        for conv in Convention::ALL {
            lines.push(CountLine::new(f.name(), method, conv, t.trace.counts(conv)));
        }
    }
    Ok(lines)
}

fn diff(a: u64, b: u64) -> i64 {
    i64::try_from(a).unwrap_or(i64::MAX) - i64::try_from(b).unwrap_or(i64::MAX)
}

/// For each effect of `spec` and each nonlinear-effects method, the operations it adds to `b` (emitted and
/// paper conventions): `b` with all of the spec's effects minus `b` with all but that one.
///
/// # Errors
/// As [`trace`].
pub fn effect_lines(
    model: &Model,
    nonlinear_effects: &[NonlinearEffectsMethod],
    spec: &Spec,
) -> Result<Vec<EffectLine>, TraceError> {
    let all = spec.effects();
    let mut lines = Vec::new();
    for &b in nonlinear_effects {
        let methods = with_nonlinear_effects(b);
        let full = trace(
            Subject::Model(model),
            Function::GeneralizedForces,
            methods,
            spec,
        )?;
        for &e in &all {
            let rest: Vec<Effect> = all.iter().copied().filter(|x| *x != e).collect();
            let without = trace(
                Subject::Model(model),
                Function::GeneralizedForces,
                methods,
                &spec.only(&rest),
            )?;
            for conv in [Convention::Emitted, Convention::Paper] {
                let (w, o) = (full.trace.counts(conv), without.trace.counts(conv));
                lines.push(EffectLine {
                    effect: e.name(),
                    method: b.name().into(),
                    convention: conv.name().into(),
                    mul: diff(w.mul, o.mul),
                    add: diff(w.add, o.add),
                    div: diff(w.div, o.div),
                });
            }
        }
    }
    Ok(lines)
}
