//! `kanegen eval MODEL --states STATES.json`: `A` and `b` of `A q̈ = b` at each state, on a fixed
//! base (`N × N`) or a free-floating one (`(6+N) × (6+N)`, order base linear, base angular,
//! joints; conventions of `kanegen_dynamics::base`).

use crate::states::{parse_states, State};
use anyhow::Result;
use kanegen_dynamics::algorithms::floating;
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen_dynamics::mimic::Coupling;
use kanegen_dynamics::{linalg::Vec3, Dynamics, Loads, Methods, Params};
use kanegen_model::{BaseKind, Model};
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

/// The methods `eval` and `count` use when none is given: the paper's recurrent algorithm on a
/// serial chain, the local-frame CRBA and RNEA on a tree (the paper's algorithms are chain-only).
#[must_use]
pub fn default_methods(model: &Model) -> Methods {
    if model.is_chain() {
        Methods::RECURRENT
    } else {
        Methods::SPATIAL
    }
}

/// The names of the model's coordinates, in the order of `q`: its joints without the mimic
/// joints.
#[must_use]
pub fn coordinate_names(model: &Model) -> Vec<&str> {
    model
        .coordinates()
        .into_iter()
        .map(|j| model.joints()[j].name.as_str())
        .collect()
}

/// Evaluates `A` and `b` in f64 at every state of a states file; `gravity` is in the base frame
/// (fixed base) or the inertial frame (free-floating base). With mimic joints, in the
/// independent coordinates ([`kanegen_dynamics::mimic`]).
///
/// # Errors
/// A malformed states file, naming the state and field.
pub fn eval_states(
    model: &Model,
    states_json: &str,
    methods: Methods,
    gravity: Option<[f64; 3]>,
) -> Result<Vec<EvalResult>> {
    let floating = model.base_kind() == BaseKind::FreeFloating;
    let states = parse_states(states_json, &coordinate_names(model), floating)?;
    let params = Params::<f64>::new(model);
    let base = model
        .base_inertial()
        .map(FloatingBase::<f64>::from_inertial);
    let coupling = Coupling::new(model.mimics());
    let offset = if floating { 6 } else { 0 };
    let results: Vec<EvalResult> = states
        .iter()
        .map(|s: &State| {
            let loads = Loads {
                tau: s.tau.as_deref().map(|t| coupling.full_drives(t)),
                gravity: gravity.map(Vec3),
                external: Vec::new(),
            };
            let (q, qd) = (coupling.full_positions(&s.q), coupling.full_rates(&s.qd));
            let (q, qd) = (&q, &qd);
            let Dynamics {
                mass_matrix: a,
                tau_minus_c: b,
            } = match (&s.base, &base) {
                (Some(bs), Some(base)) => {
                    let state = FloatingState {
                        position: Vec3(bs.position),
                        rotation: quat_to_matrix(&bs.quaternion),
                        v_b: Vec3(bs.v),
                        omega_b: Vec3(bs.omega),
                    };
                    floating::dynamics(methods, &params, base, &state, q, qd, &loads)
                }
                _ => methods.dynamics(&params, q, qd, &loads),
            };
            EvalResult {
                a: coupling.reduce_matrix(&a, offset),
                b: coupling.reduce_vector(&b, offset),
            }
        })
        .collect();
    for (k, (r, s)) in results.iter().zip(&states).enumerate() {
        check_finite(k, r, s)?;
    }
    Ok(results)
}

/// Every entry of `A` and `b` of state `k` is finite, or an error naming the entry and the
/// state's largest magnitudes.
fn check_finite(k: usize, r: &EvalResult, s: &State) -> Result<()> {
    let bad =
        r.a.iter()
            .enumerate()
            .flat_map(|(i, row)| {
                row.iter()
                    .enumerate()
                    .map(move |(j, v)| (format!("A[{i}][{j}]"), *v))
            })
            .chain(r.b.iter().enumerate().map(|(i, v)| (format!("b[{i}]"), *v)))
            .find(|(_, v)| !v.is_finite());
    if let Some((entry, v)) = bad {
        let max = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        anyhow::bail!(
            "states[{k}]: {entry} = {v} is not finite: the computation overflowed (largest |q| = \
             {:e}, |qd| = {:e}, |tau| = {:e}; the model's lengths, masses and inertias, or the \
             gravity, are too large together)",
            max(&s.q),
            max(&s.qd),
            s.tau.as_deref().map_or(0.0, max)
        );
    }
    Ok(())
}

/// Human-readable rendering of the results.
#[must_use]
pub fn render_text(model: &Model, methods: Methods, results: &[EvalResult]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "model {} ({} coordinates, {} base), algorithm {methods}",
        model.name(),
        model.coordinates().len(),
        model.base_kind().name()
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
