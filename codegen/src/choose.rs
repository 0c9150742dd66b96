//! Which methods a generated function uses: every candidate is traced and the one with the
//! fewest emitted operations (`mul + add`) wins, the first in report order on ties.

use crate::options::Options;
use kanegen_dynamics::{BiasMethod, MassMatrixMethod, Methods};
use kanegen_model::Model;
use kanegen_trace::{trace, Convention, Counts, Function, Spec, Subject, TraceError, Traced};

/// The candidates of one function, their emitted counts, and the winner.
#[derive(Clone, Debug)]
pub struct Choice {
    /// The function.
    pub function: Function,
    /// `(methods, emitted counts)` of every candidate traced.
    pub candidates: Vec<(Methods, Counts)>,
    /// The cheapest candidate.
    pub chosen: Methods,
}

impl Choice {
    /// Emitted counts of the chosen candidate.
    #[must_use]
    pub fn counts(&self) -> Counts {
        self.candidates
            .iter()
            .find(|(m, _)| *m == self.chosen)
            .map(|(_, c)| *c)
            .unwrap_or_default()
    }

    /// The mass-matrix method's name when the function uses one.
    #[must_use]
    pub fn mass_matrix_method(&self, m: Methods) -> Option<&'static str> {
        self.function
            .uses_mass_matrix()
            .then(|| m.mass_matrix.name())
    }

    /// The bias method's name when the function uses one.
    #[must_use]
    pub fn bias_method(&self, m: Methods) -> Option<&'static str> {
        self.function.uses_bias().then(|| m.bias.name())
    }
}

/// The spec of the generated code: gravity and the runtime payload of `opts`.
#[must_use]
pub fn spec(opts: &Options) -> Spec {
    Spec {
        gravity: opts.gravity,
        runtime_payload: opts.runtime_payload,
        ..Spec::default()
    }
}

/// The candidates of `f`: every mass-matrix method for `M`; every bias method (with the chosen
/// mass-matrix method `mass`) for the others.
#[must_use]
pub fn candidates(f: Function, mass: MassMatrixMethod) -> Vec<Methods> {
    if f == Function::MassMatrix {
        MassMatrixMethod::ALL
            .iter()
            .map(|&mass_matrix| Methods {
                mass_matrix,
                bias: BiasMethod::Rnea,
            })
            .collect()
    } else {
        BiasMethod::ALL
            .iter()
            .map(|&bias| Methods {
                mass_matrix: mass,
                bias,
            })
            .collect()
    }
}

/// Traces every candidate of `f` and keeps the cheapest.
///
/// # Errors
/// As [`trace`].
pub fn choose(
    model: &Model,
    f: Function,
    mass: MassMatrixMethod,
    opts: &Options,
) -> Result<(Choice, Traced), TraceError> {
    let spec = spec(opts);
    let mut best: Option<(u64, Methods, Traced)> = None;
    let mut traced = Vec::new();
    for m in candidates(f, mass) {
        let t = trace(Subject::Model(model), f, m, &spec)?;
        let c = t.trace.counts(Convention::Emitted);
        traced.push((m, c));
        if best.as_ref().is_none_or(|(b, _, _)| c.total() < *b) {
            best = Some((c.total(), m, t));
        }
    }
    let (_, chosen, winner) = best.expect("every function has a candidate");
    Ok((
        Choice {
            function: f,
            candidates: traced,
            chosen,
        },
        winner,
    ))
}
