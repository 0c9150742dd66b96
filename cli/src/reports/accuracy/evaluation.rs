//! The evaluation part of `kanegen accuracy`: `A`, `b` and `q̈` in each precision, their relative
//! error against the double-double reference, and nanoseconds per call — generated code and the
//! interpreted algorithms, measured side by side in one run.
//!
//! The states are random with `f64` entries, so every precision starts from the same numbers
//! (`f32` rounds its inputs: that rounding is part of what an `f32` user gets). The reference runs
//! the same algorithm on [`Wide`] (double-double, ~32 digits), itself checked against exact
//! rational arithmetic at angles with rational sine and cosine ([`wide_vs_exact`]).

use crate::timing::{measure, Candidate};
use kanegen_dynamics::algorithms::floating;
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::metrics::{rel_err, rel_err_mat, rel_err_wide};
use kanegen_dynamics::scalars::compensated::Compensated;
use kanegen_dynamics::scalars::exact::{rational_state, Exact};
use kanegen_dynamics::{ExternalWrench, Loads, Methods, Params, Real, Scalar};
use kanegen_model::random::{random_vec, rng};
use kanegen_model::Model;
use kanegen_sim::scene::{BaseSpec, Scene};
use serde::{Deserialize, Serialize};

pub use kanegen_dynamics::scalars::wide::Wide;

/// What is evaluated: an arm on a fixed base, or on a free-floating base in a given pose and
/// twist, with the scene's gravity and wrenches (at `t = 0`).
#[derive(Clone, Debug)]
pub struct Subject {
    /// The arm.
    pub chain: Model,
    /// The base: fixed, or free-floating with its inertial and initial pose and twist.
    pub base: BaseSpec,
    /// Uniform gravity, if the scene has it.
    pub gravity: Option<[f64; 3]>,
    /// External wrenches (body, frame, force, moment), if the scene has them.
    pub wrenches: Vec<ExternalWrench<f64>>,
}

impl Subject {
    /// An arm on a fixed base with no loads but the joint drives.
    #[must_use]
    pub fn model(chain: Model) -> Self {
        Subject {
            chain,
            base: BaseSpec::Fixed,
            gravity: None,
            wrenches: Vec::new(),
        }
    }

    /// The dynamics of a scene at its initial base state (the arm state is drawn at random).
    #[must_use]
    pub fn scene(scene: &Scene) -> Self {
        Subject {
            chain: scene.model.clone(),
            base: scene.base.clone(),
            gravity: scene.gravity,
            wrenches: scene.wrenches.iter().map(|w| w.at(0.0)).collect(),
        }
    }

    /// Size of `A`: `N`, or `6 + N` on a free-floating base.
    #[must_use]
    pub fn dim(&self) -> usize {
        self.chain.dof()
            + if matches!(self.base, BaseSpec::Fixed) {
                0
            } else {
                6
            }
    }
}

/// One state: joint positions, rates and drive torques (`f64`, exact in every wider type).
#[derive(Clone, Debug)]
pub struct State {
    /// Joint positions.
    pub q: Vec<f64>,
    /// Joint rates.
    pub qd: Vec<f64>,
    /// Joint drive forces/torques.
    pub tau: Vec<f64>,
}

/// `count` random states for an `n`-joint arm: angles in ±π, rates in ±1 rad/s, torques ±100.
#[must_use]
pub fn random_states(n: usize, count: usize, seed: u64) -> Vec<State> {
    let mut r = rng(seed);
    (0..count)
        .map(|_| State {
            q: random_vec(&mut r, n, std::f64::consts::PI),
            qd: random_vec(&mut r, n, 1.0),
            tau: random_vec(&mut r, n, 100.0),
        })
        .collect()
}

/// `A`, `b` and `q̈` (or `ν̇`), read back as `f64`.
#[derive(Clone, Debug)]
pub struct Evaluated {
    /// `M`, the mass matrix.
    pub mass_matrix: Vec<Vec<f64>>,
    /// `τ − c`.
    pub tau_minus_c: Vec<f64>,
    /// `M⁻¹ (τ − c)` by the branch-free LDLᵀ.
    pub qdd: Vec<f64>,
}

/// `A`, `b` and `A⁻¹ b` of `subject` on the scalar `S` with `alg`, at a state given in `S`
/// (so that exact angles can be passed as such).
#[must_use]
pub fn dynamics_on<S: Scalar>(
    subject: &Subject,
    alg: Methods,
    q: &[S],
    qd: &[S],
    tau: Vec<S>,
) -> (Vec<Vec<S>>, Vec<S>, Vec<S>) {
    let p = Params::<S>::new(&subject.chain);
    let loads = Loads {
        tau: Some(tau),
        gravity: subject.gravity.map(Vec3::from_f64),
        external: subject
            .wrenches
            .iter()
            .map(|w| ExternalWrench {
                body: w.body,
                frame: w.frame,
                force: Vec3::from_f64(w.force.clone().into_array()),
                moment: Vec3::from_f64(w.moment.clone().into_array()),
            })
            .collect(),
    };
    let d = match &subject.base {
        BaseSpec::Fixed => alg.dynamics(&p, q, qd, &loads),
        BaseSpec::FreeFloating {
            inertial,
            position,
            quaternion,
            v,
            omega,
        } => {
            let base = FloatingBase::from_inertial(inertial);
            let st = FloatingState {
                position: Vec3::from_f64(*position),
                rotation: quat_to_matrix(&quaternion.map(S::constant)),
                v_b: Vec3::from_f64(*v),
                omega_b: Vec3::from_f64(*omega),
            };
            floating::dynamics(alg, &p, &base, &st, q, qd, &loads)
        }
    };
    let qdd = kanegen_dynamics::ldlt::solve(
        &kanegen_dynamics::ldlt::ldlt(&d.mass_matrix),
        &d.tau_minus_c,
    );
    (d.mass_matrix, d.tau_minus_c, qdd)
}

/// Evaluates `A`, `b` and `A⁻¹ b` of `subject` at `state` on the scalar `S` with `alg`.
#[must_use]
pub fn evaluate<S: Real>(subject: &Subject, alg: Methods, state: &State) -> Evaluated {
    let c = |x: &[f64]| -> Vec<S> { x.iter().map(|&v| S::constant(v)).collect() };
    let (a, b, qdd) = dynamics_on(subject, alg, &c(&state.q), &c(&state.qd), c(&state.tau));
    let f = |v: &[S]| -> Vec<f64> { v.iter().map(Real::to_f64).collect() };
    Evaluated {
        mass_matrix: a.iter().map(|r| f(r)).collect(),
        tau_minus_c: f(&b),
        qdd: f(&qdd),
    }
}

/// [`rel_err_wide`] of a double-double result against the exact one.
fn wide_rel_err(x: &[Wide], y: &[Exact]) -> f64 {
    let y: Vec<Wide> = y.iter().map(Exact::to_wide).collect();
    rel_err_wide(x, &y)
}

/// Number of exact states [`wide_vs_exact`] checks.
pub const EXACT_STATES: i64 = 2;

/// Worst relative errors of `A`, `b`, `q̈` of `alg` on [`Wide`] against the same algorithm on
/// [`Exact`] rationals, over [`EXACT_STATES`] states with rational joint sines and cosines:
/// the measured accuracy of the reference itself. `None` if exactness was lost on the way
/// (it is not for the algorithms of this crate).
#[must_use]
pub fn wide_vs_exact(subject: &Subject, alg: Methods) -> Option<[f64; 3]> {
    let mut worst = [0.0_f64; 3];
    for k in 0..EXACT_STATES {
        let (q, qd, tau) = rational_state(&subject.chain, k);
        let (a, b, qdd) = dynamics_on(subject, alg, &q, &qd, tau.clone());
        if !a
            .iter()
            .flatten()
            .chain(&b)
            .chain(&qdd)
            .all(Exact::is_exact)
        {
            return None;
        }
        let w = |x: &[Exact]| -> Vec<Wide> { x.iter().map(Exact::to_wide).collect() };
        let (aw, bw, qddw) = dynamics_on(subject, alg, &w(&q), &w(&qd), w(&tau));
        let e = [
            wide_rel_err(&aw.concat(), &a.concat()),
            wide_rel_err(&bw, &b),
            wide_rel_err(&qddw, &qdd),
        ];
        for (m, x) in worst.iter_mut().zip(e) {
            *m = m.max(x);
        }
    }
    Some(worst)
}

/// Worst relative errors of `A`, `b`, `q̈` over the states, against `reference`.
#[must_use]
pub fn errors(results: &[Evaluated], reference: &[Evaluated]) -> [f64; 3] {
    results
        .iter()
        .zip(reference)
        .fold([0.0_f64; 3], |m, (x, r)| {
            [
                m[0].max(rel_err_mat(&x.mass_matrix, &r.mass_matrix)),
                m[1].max(rel_err(&x.tau_minus_c, &r.tau_minus_c)),
                m[2].max(rel_err(&x.qdd, &r.qdd)),
            ]
        })
}

/// One precision on one path.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EvalRow {
    /// `f32`, `f64`, `f64-fma` or `wide`.
    pub precision: String,
    /// `generated` or `interpreted`.
    pub path: String,
    /// Worst relative error of `A` (max |x − y| / max |y|) over the states; `null` in JSON
    /// (NaN here) where not measured.
    #[serde(rename = "rel_err_A", with = "nan_as_null")]
    pub rel_err_a: f64,
    /// Worst relative error of `b`.
    #[serde(with = "nan_as_null")]
    pub rel_err_b: f64,
    /// Worst relative error of `q̈` (`A⁻¹ b`).
    #[serde(with = "nan_as_null")]
    pub rel_err_qdd: f64,
    /// Median ns per call of forward dynamics (`A`, `b` and the solve), side by side.
    pub ns: f64,
}

/// NaN (not measured) as JSON `null`, an infinite error (the precision failed: an overflow or a
/// singular solve) as the string `"inf"`, and back: JSON has no non-finite numbers, and
/// `serde_json` would write both as `null`.
mod nan_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_nan() {
            s.serialize_none()
        } else if x.is_infinite() {
            s.serialize_str(if *x > 0.0 { "inf" } else { "-inf" })
        } else {
            s.serialize_f64(*x)
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Value {
        Number(f64),
        Text(String),
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(match Option::<Value>::deserialize(d)? {
            None => f64::NAN,
            Some(Value::Number(x)) => x,
            Some(Value::Text(t)) if t == "inf" => f64::INFINITY,
            Some(Value::Text(t)) if t == "-inf" => f64::NEG_INFINITY,
            Some(Value::Text(t)) => {
                return Err(serde::de::Error::custom(format!(
                    "expected a number, null or \"inf\", got \"{t}\""
                )))
            }
        })
    }
}

/// The evaluation table of a subject.
#[derive(Clone, Debug, Serialize)]
pub struct EvaluationReport {
    /// Number of random states the errors are the worst over.
    pub states: usize,
    /// 2-norm condition number of `A` (largest over the states, from the reference).
    pub cond_a: f64,
    /// The rows: interpreted `f32`, `f64`, `wide`, then the generated variants when the subject
    /// is a model with checked-in generated code.
    pub rows: Vec<EvalRow>,
}

/// 2-norm condition number of a symmetric positive definite matrix.
#[must_use]
pub fn cond(a: &[Vec<f64>]) -> f64 {
    let n = a.len();
    let m = nalgebra::DMatrix::from_fn(n, n, |i, j| a[i][j]);
    let e = nalgebra::SymmetricEigen::new(m).eigenvalues;
    let (lo, hi) = e
        .iter()
        .fold((f64::MAX, 0.0_f64), |(l, h), &v| (l.min(v), h.max(v)));
    hi / lo
}

/// A function of the state `(q, q̇, τ)` giving an `N`-vector.
pub type StateFn = fn(&[f64], &[f64], &[f64]) -> Vec<f64>;

/// A function of `(q, q̇, x)` giving `K` matrices (row = output, column = input).
pub type MatricesFn<const K: usize> = fn(&[f64], &[f64], &[f64]) -> [Vec<Vec<f64>>; K];

/// Generated code of a model in one precision (`f64`, `f32`, `f64-fma`), on `f64` slices
/// (an `f32` variant rounds its inputs and widens its outputs).
#[derive(Clone, Copy, Debug)]
pub struct GeneratedFns {
    /// The precision name of the row.
    pub precision: &'static str,
    /// `M(q)`.
    pub mass_matrix: fn(&[f64]) -> Vec<Vec<f64>>,
    /// `τ − c(q, q̇)`.
    pub tau_minus_c: StateFn,
    /// `q̈ = M⁻¹ (τ − c)` (the generated unrolled LDLᵀ).
    pub forward_dynamics: StateFn,
    /// `(∂τ/∂q, ∂τ/∂q̇)` at `(q, q̇, q̈)`, if the variant was generated with derivatives.
    pub inverse_dynamics_derivatives: Option<MatricesFn<2>>,
    /// `(∂q̈/∂q, ∂q̈/∂q̇, M⁻¹)` at `(q, q̇, τ)`, if the variant was generated with derivatives.
    pub forward_dynamics_derivatives: Option<MatricesFn<3>>,
}

impl GeneratedFns {
    fn evaluate(&self, s: &State) -> Evaluated {
        Evaluated {
            mass_matrix: (self.mass_matrix)(&s.q),
            tau_minus_c: (self.tau_minus_c)(&s.q, &s.qd, &s.tau),
            qdd: (self.forward_dynamics)(&s.q, &s.qd, &s.tau),
        }
    }
}

/// An interpreted precision: the algorithm run on one scalar type.
type EvalFn = fn(&Subject, Methods, &State) -> Evaluated;

/// The interpreted rows, in report order. `wide` is the reference; its own row is measured
/// against exact rationals ([`wide_vs_exact`]).
const INTERPRETED: [(&str, EvalFn); 4] = [
    ("f32", evaluate::<f32>),
    ("f64", evaluate::<f64>),
    ("compensated", evaluate::<Compensated>),
    ("wide", evaluate::<Wide>),
];

/// Errors and times of every precision for `subject`: interpreted `alg` on each scalar of
/// [`INTERPRETED`], plus the `generated` variants given. `timing: false` skips the
/// measurement (`ns` 0), for tests.
#[must_use]
pub fn evaluation_report(
    subject: &Subject,
    alg: Methods,
    generated: &[GeneratedFns],
    states: &[State],
    timing: bool,
) -> EvaluationReport {
    let reference: Vec<Evaluated> = states
        .iter()
        .map(|s| evaluate::<Wide>(subject, alg, s))
        .collect();
    let cond_a = reference
        .iter()
        .map(|r| cond(&r.mass_matrix))
        .fold(0.0, f64::max);
    let mut rows: Vec<(String, String, [f64; 3])> = INTERPRETED
        .iter()
        .map(|&(name, f)| {
            let e = if name == "wide" {
                wide_vs_exact(subject, alg).unwrap_or([f64::NAN; 3])
            } else {
                let r: Vec<Evaluated> = states.iter().map(|s| f(subject, alg, s)).collect();
                errors(&r, &reference)
            };
            (name.to_string(), "interpreted".to_string(), e)
        })
        .collect();
    for g in generated {
        let r: Vec<Evaluated> = states.iter().map(|s| g.evaluate(s)).collect();
        rows.push((
            g.precision.into(),
            "generated".into(),
            errors(&r, &reference),
        ));
    }
    let ns = if timing {
        time_rows(subject, alg, generated, states)
    } else {
        vec![0.0; rows.len()]
    };
    EvaluationReport {
        states: states.len(),
        cond_a,
        rows: rows
            .into_iter()
            .zip(ns)
            .map(|((precision, path, e), ns)| EvalRow {
                precision,
                path,
                rel_err_a: e[0],
                rel_err_b: e[1],
                rel_err_qdd: e[2],
                ns,
            })
            .collect(),
    }
}

/// Median ns per forward-dynamics call of every row ([`INTERPRETED`], then `generated`), side
/// by side in one run.
fn time_rows(
    subject: &Subject,
    alg: Methods,
    generated: &[GeneratedFns],
    states: &[State],
) -> Vec<f64> {
    let tau = &states[0].tau;
    let mut c: Vec<Candidate<'_>> = Vec::new();
    for &(name, f) in &INTERPRETED {
        c.push((
            name.into(),
            "fd".into(),
            Box::new(move |q: &[f64], qd: &[f64]| {
                let s = State {
                    q: q.to_vec(),
                    qd: qd.to_vec(),
                    tau: tau.clone(),
                };
                f(subject, alg, &s).qdd[0]
            }),
        ));
    }
    for g in generated {
        let fd = g.forward_dynamics;
        c.push((
            g.precision.into(),
            "fd".into(),
            Box::new(move |q: &[f64], qd: &[f64]| fd(q, qd, tau)[0]),
        ));
    }
    measure(subject.chain.dof(), c, 15, 40)
        .into_iter()
        .map(|l| l.ns)
        .collect()
}
