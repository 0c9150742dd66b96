//! Which methods a generated function uses: every candidate is traced and the one with the
//! fewest emitted operations (`mul + add`) wins, the first in report order on ties. Forward
//! dynamics has two kinds of candidate: LDLᵀ on `M` and `c` (one per bias method) and the
//! articulated-body algorithm ([`Methods::ABA`], which uses neither), last.

use crate::options::Options;
use kanegen_dynamics::{BiasMethod, ForwardMethod, MassMatrixMethod, Methods};
use kanegen_model::{BaseKind, Model};
use kanegen_trace::{trace, Base, Convention, Counts, Function, Spec, Subject, TraceError, Traced};

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

    /// The mass-matrix method's name when the candidate `m` uses one (forward dynamics by the
    /// articulated-body algorithm does not).
    #[must_use]
    pub fn mass_matrix_method(&self, m: Methods) -> Option<&'static str> {
        (self.function.uses_mass_matrix() && !self.is_aba(m)).then(|| m.mass_matrix.name())
    }

    /// The bias method's name when the candidate `m` uses one (forward dynamics by the
    /// articulated-body algorithm does not).
    #[must_use]
    pub fn bias_method(&self, m: Methods) -> Option<&'static str> {
        (self.function.uses_bias() && !self.is_aba(m)).then(|| m.bias.name())
    }

    /// The forward method's name (`ldlt`, `aba`) for forward dynamics, `None` otherwise.
    #[must_use]
    pub fn forward_method(&self, m: Methods) -> Option<&'static str> {
        self.function
            .is_forward_dynamics()
            .then(|| m.forward.name())
    }

    fn is_aba(&self, m: Methods) -> bool {
        self.function.is_forward_dynamics() && m.forward == ForwardMethod::Aba
    }
}

/// The spec of the generated code: the model's base, and gravity and the runtime payload of
/// `opts`.
#[must_use]
pub fn spec(model: &Model, opts: &Options) -> Spec {
    Spec {
        base: match (model.base_kind(), model.base_inertial()) {
            (BaseKind::FreeFloating, Some(i)) => Base::FreeFloating(i.clone()),
            _ => Base::Fixed,
        },
        gravity: opts.gravity,
        runtime_payload: opts.runtime_payload,
        ..Spec::default()
    }
}

/// The candidates of `f`: every mass-matrix method for `M`; every bias method (with the chosen
/// mass-matrix method `mass`) for a function with a bias, and for forward dynamics then the
/// articulated-body algorithm ([`Methods::ABA`]); the chosen method alone for the others.
/// On a tree only the local-frame methods (`crba`, `rnea`, `aba`) are candidates: the paper's
/// base-frame algorithms handle serial chains only.
#[must_use]
pub fn candidates(f: Function, mass: MassMatrixMethod, chain: bool) -> Vec<Methods> {
    let mass_methods: &[MassMatrixMethod] = if chain {
        &MassMatrixMethod::ALL
    } else {
        &[MassMatrixMethod::Crba]
    };
    let bias_methods: &[BiasMethod] = if chain {
        &BiasMethod::ALL
    } else {
        &[BiasMethod::Rnea]
    };
    if f == Function::MassMatrix {
        mass_methods
            .iter()
            .map(|&mass_matrix| Methods {
                mass_matrix,
                bias: BiasMethod::Rnea,
                forward: ForwardMethod::Ldlt,
            })
            .collect()
    } else if f.uses_bias() {
        let mut c: Vec<Methods> = bias_methods
            .iter()
            .map(|&bias| Methods {
                mass_matrix: mass,
                bias,
                forward: ForwardMethod::Ldlt,
            })
            .collect();
        if f.is_forward_dynamics() {
            c.push(Methods::ABA);
        }
        c
    } else {
        vec![Methods {
            mass_matrix: mass,
            bias: BiasMethod::Rnea,
            forward: ForwardMethod::Ldlt,
        }]
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
    let spec = Spec {
        regroup: opts.regroup && f != Function::BaseReaction,
        ..spec(model, opts)
    };
    let mut best: Option<(u64, Methods, Traced)> = None;
    let mut traced = Vec::new();
    for m in candidates(f, mass, model.is_chain()) {
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
