//! `kanegen eval MODEL --states STATES.json`: A and b of `A q̈ = b` at each state.

use crate::states::{parse_states, State};
use anyhow::Result;
use kanegen_dynamics::{linalg::Vec3, Dynamics, Loads, Methods, Params};
use kanegen_model::Model;
use serde::Serialize;

/// One evaluated state, as written by `--json`.
#[derive(Serialize)]
pub struct EvalResult {
    /// Generalized inertia matrix.
    #[serde(rename = "A")]
    pub a: Vec<Vec<f64>>,
    /// Generalized forces `b = Q − h`.
    pub b: Vec<f64>,
}

/// Evaluates `A` and `b` in f64 at every state of a states file.
pub fn eval_states(
    chain: &Model,
    states_json: &str,
    algorithm: Methods,
    gravity: Option<[f64; 3]>,
) -> Result<Vec<EvalResult>> {
    let states = parse_states(states_json, chain.dof())?;
    let params = Params::<f64>::new(chain);
    Ok(states
        .iter()
        .map(|s: &State| {
            let loads = Loads {
                tau: s.tau.clone(),
                gravity: gravity.map(Vec3),
                external: Vec::new(),
            };
            let Dynamics { a, b } = algorithm.dynamics(&params, &s.q, &s.qd, &loads);
            EvalResult { a, b }
        })
        .collect())
}

/// Human-readable rendering of the results.
pub fn render_text(chain: &Model, algorithm: Methods, results: &[EvalResult]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "model {} ({} joints), algorithm {algorithm}",
        chain.name(),
        chain.dof()
    );
    for (k, r) in results.iter().enumerate() {
        let _ = writeln!(s, "\nstate {k}\nA =");
        for row in &r.a {
            let cells: Vec<String> = row.iter().map(|x| format!("{x:>14.6e}")).collect();
            let _ = writeln!(s, "  [{}]", cells.join(" "));
        }
        let cells: Vec<String> = r.b.iter().map(|x| format!("{x:>14.6e}")).collect();
        let _ = writeln!(s, "b =\n  [{}]", cells.join(" "));
    }
    s
}
