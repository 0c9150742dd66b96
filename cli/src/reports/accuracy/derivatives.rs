//! The derivative part of `kanegen accuracy`: `∂τ/∂x` (inverse dynamics), `∂q̈/∂x` and `M⁻¹`
//! (forward dynamics) in each precision, their relative error against the double-double
//! reference, and nanoseconds per forward-dynamics-derivatives call — generated code and the
//! interpreted algorithms ([`kanegen_dynamics::algorithms::derivatives`]), side by side in one run.
//!
//! The states are those of the evaluation table ([`super::evaluation::random_states`]); inverse
//! dynamics is differentiated at `q̈ = τ / 100` (accelerations of ±1 rad/s², formed in `f64` so
//! that every precision starts from the same numbers), forward dynamics at the state's drives
//! `τ`. Fixed base, no gravity: what a bare model's generated functions compute.

use super::evaluation::{GeneratedFns, State, Wide};
use crate::timing::{measure, Candidate};
use kanegen_dynamics::algorithms::derivatives::{aba, rnea, Matrix};
use kanegen_dynamics::metrics::{rel_err, rel_err_wide};
use kanegen_dynamics::scalars::exact::{rational_state, Exact};
use kanegen_dynamics::{Params, Real, Scalar};
use kanegen_model::Model;
use serde::{Deserialize, Serialize};

/// The derivatives at one state, read back as `f64`: `∂τ/∂q`, `∂τ/∂q̇` (at `q̈ = τ / 100`),
/// `∂q̈/∂q`, `∂q̈/∂q̇` and `M⁻¹` (at the drives `τ`).
pub type Derivatives = [Matrix<f64>; 5];

/// `q̈ = τ / 100`: the acceleration inverse dynamics is differentiated at.
fn acceleration(tau: &[f64]) -> Vec<f64> {
    tau.iter().map(|t| t / 100.0).collect()
}

/// The five matrices of `chain` on the scalar `S` at a state given in `S`.
fn derivatives_on<S: Scalar>(
    chain: &Model,
    q: &[S],
    qd: &[S],
    qdd: &[S],
    tau: &[S],
) -> [Matrix<S>; 5] {
    let p = Params::<S>::new(chain);
    let (dtau_dq, dtau_dv) = rnea::derivatives(&p, q, qd, qdd, None);
    let (dqdd_dq, dqdd_dv, minv) = aba::derivatives(&p, q, qd, tau, None);
    [dtau_dq, dtau_dv, dqdd_dq, dqdd_dv, minv]
}

/// [`derivatives_on`] at `state`, on `S`, read back as `f64`.
fn interpreted<S: Real>(chain: &Model, state: &State) -> Derivatives {
    let c = |x: &[f64]| -> Vec<S> { x.iter().map(|&v| S::constant(v)).collect() };
    let qdd = acceleration(&state.tau);
    derivatives_on(chain, &c(&state.q), &c(&state.qd), &c(&qdd), &c(&state.tau)).map(|m| {
        m.iter()
            .map(|r| r.iter().map(Real::to_f64).collect())
            .collect()
    })
}

/// The generated functions of `g` at `state` (`None` if it has no derivatives).
fn generated(g: &GeneratedFns, state: &State) -> Option<Derivatives> {
    let (id, fd) = (
        g.inverse_dynamics_derivatives?,
        g.forward_dynamics_derivatives?,
    );
    let [dtau_dq, dtau_dv] = id(&state.q, &state.qd, &acceleration(&state.tau));
    let [dqdd_dq, dqdd_dv, minv] = fd(&state.q, &state.qd, &state.tau);
    Some([dtau_dq, dtau_dv, dqdd_dq, dqdd_dv, minv])
}

/// Relative errors of one result against the reference, each quantity's matrices as one block:
/// `[∂τ/∂x, ∂q̈/∂x, M⁻¹]`.
fn block_errors(x: &Derivatives, r: &Derivatives) -> [f64; 3] {
    let flat =
        |ms: &[Matrix<f64>]| -> Vec<f64> { ms.iter().flatten().flatten().copied().collect() };
    [
        rel_err(&flat(&x[0..2]), &flat(&r[0..2])),
        rel_err(&flat(&x[2..4]), &flat(&r[2..4])),
        rel_err(&flat(&x[4..5]), &flat(&r[4..5])),
    ]
}

/// Worst [`block_errors`] over the states.
fn worst(results: &[Derivatives], reference: &[Derivatives]) -> [f64; 3] {
    results
        .iter()
        .zip(reference)
        .fold([0.0_f64; 3], |m, (x, r)| {
            let e = block_errors(x, r);
            [m[0].max(e[0]), m[1].max(e[1]), m[2].max(e[2])]
        })
}

/// Worst errors of the double-double derivatives against exact rationals, over
/// [`super::evaluation::EXACT_STATES`] states with rational joint sines and cosines (`None` if
/// exactness was lost).
fn wide_vs_exact(chain: &Model) -> Option<[f64; 3]> {
    let mut m = [0.0_f64; 3];
    for k in 0..super::evaluation::EXACT_STATES {
        let (q, qd, tau) = rational_state(chain, k);
        let qdd: Vec<Exact> = tau
            .iter()
            .map(|t| t.clone() / Exact::constant(100.0))
            .collect();
        let exact = derivatives_on(chain, &q, &qd, &qdd, &tau);
        if !exact.iter().flatten().flatten().all(Exact::is_exact) {
            return None;
        }
        let w = |x: &[Exact]| -> Vec<Wide> { x.iter().map(Exact::to_wide).collect() };
        let wide = derivatives_on(chain, &w(&q), &w(&qd), &w(&qdd), &w(&tau));
        let block = |ms: &[Matrix<Wide>], es: &[Matrix<Exact>]| {
            let x: Vec<Wide> = ms.iter().flatten().flatten().copied().collect();
            let y: Vec<Wide> = es.iter().flatten().flatten().map(Exact::to_wide).collect();
            rel_err_wide(&x, &y)
        };
        let e = [
            block(&wide[0..2], &exact[0..2]),
            block(&wide[2..4], &exact[2..4]),
            block(&wide[4..5], &exact[4..5]),
        ];
        for (m, e) in m.iter_mut().zip(e) {
            *m = m.max(e);
        }
    }
    Some(m)
}

/// One precision on one path.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DerivativeRow {
    /// `f32`, `f64`, `f64-fma` or `wide`.
    pub precision: String,
    /// `generated` or `interpreted`.
    pub path: String,
    /// Worst relative error of `(∂τ/∂q, ∂τ/∂q̇)` together (max |x − y| / max |y|).
    pub rel_err_dtau: f64,
    /// Worst relative error of `(∂q̈/∂q, ∂q̈/∂q̇)` together.
    pub rel_err_dqdd: f64,
    /// Worst relative error of `M⁻¹`.
    pub rel_err_minv: f64,
    /// Median ns per forward-dynamics-derivatives call (all three matrices), side by side.
    pub ns: f64,
}

/// An interpreted precision: all five matrices at a state.
type DerivFn = fn(&Model, &State) -> Derivatives;

/// An interpreted precision's forward-dynamics derivatives alone (what the rows time), returning
/// one entry so that the call is not optimized away.
type TimedFn = fn(&Model, &[f64], &[f64], &[f64]) -> f64;

/// [`aba::derivatives`] on `S` at `(q, q̇, τ)`, the parameters converted in the call as the
/// evaluation rows do.
fn forward_derivatives_entry<S: Real>(chain: &Model, q: &[f64], qd: &[f64], tau: &[f64]) -> f64 {
    let c = |x: &[f64]| -> Vec<S> { x.iter().map(|&v| S::constant(v)).collect() };
    let p = Params::<S>::new(chain);
    aba::derivatives(&p, &c(q), &c(qd), &c(tau), None).0[0][0].to_f64()
}

/// The interpreted rows, in report order; `wide` is the reference, its own row measured against
/// exact rationals.
const INTERPRETED: [(&str, DerivFn, TimedFn); 3] = [
    ("f32", interpreted::<f32>, forward_derivatives_entry::<f32>),
    ("f64", interpreted::<f64>, forward_derivatives_entry::<f64>),
    (
        "wide",
        interpreted::<Wide>,
        forward_derivatives_entry::<Wide>,
    ),
];

/// Errors and times of every precision of the derivatives of `chain` (fixed base, no gravity):
/// the interpreted algorithms on each scalar of [`INTERPRETED`], then the `generated` variants
/// that have derivatives. `timing: false` skips the measurement (`ns` 0), for tests.
#[must_use]
pub fn derivative_rows(
    chain: &Model,
    generated_fns: &[GeneratedFns],
    states: &[State],
    timing: bool,
) -> Vec<DerivativeRow> {
    let reference: Vec<Derivatives> = states
        .iter()
        .map(|s| interpreted::<Wide>(chain, s))
        .collect();
    let mut rows: Vec<(String, String, [f64; 3])> = INTERPRETED
        .iter()
        .map(|&(name, f, _)| {
            let e = if name == "wide" {
                wide_vs_exact(chain).unwrap_or([f64::NAN; 3])
            } else {
                let r: Vec<Derivatives> = states.iter().map(|s| f(chain, s)).collect();
                worst(&r, &reference)
            };
            (name.to_string(), "interpreted".to_string(), e)
        })
        .collect();
    let with_derivatives: Vec<&GeneratedFns> = generated_fns
        .iter()
        .filter(|g| g.forward_dynamics_derivatives.is_some())
        .collect();
    for g in &with_derivatives {
        let r: Vec<Derivatives> = states.iter().filter_map(|s| generated(g, s)).collect();
        rows.push((
            g.precision.into(),
            "generated".into(),
            worst(&r, &reference),
        ));
    }
    let ns = if timing {
        time_rows(chain, &with_derivatives, states)
    } else {
        vec![0.0; rows.len()]
    };
    rows.into_iter()
        .zip(ns)
        .map(|((precision, path, e), ns)| DerivativeRow {
            precision,
            path,
            rel_err_dtau: e[0],
            rel_err_dqdd: e[1],
            rel_err_minv: e[2],
            ns,
        })
        .collect()
}

/// Median ns per forward-dynamics-derivatives call of every row, side by side in one run.
fn time_rows(chain: &Model, generated_fns: &[&GeneratedFns], states: &[State]) -> Vec<f64> {
    let tau = &states[0].tau;
    let mut c: Vec<Candidate<'_>> = Vec::new();
    for &(name, _, fd) in &INTERPRETED {
        c.push((
            name.into(),
            "fd-derivatives".into(),
            Box::new(move |q: &[f64], qd: &[f64]| fd(chain, q, qd, tau)),
        ));
    }
    for g in generated_fns {
        let fd = g
            .forward_dynamics_derivatives
            .expect("filtered on derivatives");
        c.push((
            g.precision.into(),
            "fd-derivatives".into(),
            Box::new(move |q: &[f64], qd: &[f64]| fd(q, qd, tau)[0][0][0]),
        ));
    }
    measure(chain.dof(), c, 15, 40)
        .into_iter()
        .map(|l| l.ns)
        .collect()
}
