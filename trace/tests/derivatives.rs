//! The traced derivative functions (`inverse_dynamics_derivatives`,
//! `forward_dynamics_derivatives`, `mass_matrix_inverse`) evaluate to the f64 algorithms of
//! `kanegen_dynamics::algorithms::derivatives`: random trees and chains with prismatic joints,
//! fixed and free-floating base (the base pose read from Pinocchio's `q = [p₀, quaternion, q]`),
//! gravity, regrouped parameters on and off; damping and wrenches are refused.

use kanegen_dynamics::algorithms::derivatives::{aba as fd, minverse, rnea as id};
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::{LoadFrame, Methods, Params};
use kanegen_model::random::{
    random_chain, random_inertial, random_tree, random_vec, rng, ChainSpec,
};
use kanegen_model::Model;
use kanegen_trace::{trace, Arg, Base, Function, Input, Spec, Subject, Wrench, WrenchValue};

const TOL: f64 = 1e-12;
const FUNCTIONS: [Function; 3] = [
    Function::InverseDynamicsDerivatives,
    Function::ForwardDynamicsDerivatives,
    Function::MassMatrixInverse,
];

fn models() -> Vec<Model> {
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.35,
        ..Default::default()
    };
    vec![
        random_tree(&spec(6), 12),
        random_chain(&spec(5), 21),
        random_chain(&spec(1), 2),
    ]
}

/// The arguments of one state: `q` (with the base pose first when floating), `v`, and `a` or
/// `τ` (the same random numbers serve as both).
struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    x: Vec<f64>,
}

impl State {
    fn new(n: usize, floating: bool, seed: u64) -> Self {
        let mut r = rng(seed);
        let nb = if floating { 6 } else { 0 };
        let mut q = Vec::new();
        if floating {
            q.extend(random_vec(&mut r, 3, 1.0));
            let quat = random_vec(&mut r, 4, 1.0);
            let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
            q.extend(quat.iter().map(|x| x / norm));
        }
        q.extend(random_vec(&mut r, n, 2.0));
        State {
            q,
            v: random_vec(&mut r, n + nb, 1.0),
            x: random_vec(&mut r, n + nb, 3.0),
        }
    }

    fn input(&self, i: &Input, nb: usize) -> f64 {
        match i {
            Input::Joint(Arg::Q, k) => self.q[*k],
            Input::Joint(Arg::Qd | Arg::V, k) => self.v[*k],
            Input::Joint(Arg::Qdd | Arg::A, k) => self.x[*k],
            Input::Joint(Arg::Tau, k) => self.x[nb + *k],
            other => panic!("unexpected input {other}"),
        }
    }
}

/// The f64 algorithm's outputs, as the trace lays them out.
fn expected(
    f: Function,
    p: &Params<f64>,
    base: Option<&FloatingBase<f64>>,
    s: &State,
    g: &Vec3<f64>,
) -> Vec<f64> {
    let upper = |m: Vec<Vec<f64>>| -> Vec<f64> {
        m.iter()
            .enumerate()
            .flat_map(|(i, r)| r[i..].to_vec())
            .collect()
    };
    let Some(base) = base else {
        let (q, qd) = (&s.q, &s.v);
        return match f {
            Function::InverseDynamicsDerivatives => {
                let (a, b) = id::derivatives(p, q, qd, &s.x, Some(g));
                [a, b].concat().concat()
            }
            Function::ForwardDynamicsDerivatives => {
                let (a, b, c) = fd::derivatives(p, q, qd, &s.x, Some(g));
                [a, b, c].concat().concat()
            }
            _ => upper(minverse::mass_matrix_inverse(p, q)),
        };
    };
    let quat = [s.q[3], s.q[4], s.q[5], s.q[6]];
    let state = FloatingState {
        position: Vec3::new(s.q[0], s.q[1], s.q[2]),
        rotation: quat_to_matrix(&quat),
        v_b: Vec3::new(s.v[0], s.v[1], s.v[2]),
        omega_b: Vec3::new(s.v[3], s.v[4], s.v[5]),
    };
    let (q, qd) = (&s.q[7..], &s.v[6..]);
    match f {
        Function::InverseDynamicsDerivatives => {
            let acc: [f64; 6] = core::array::from_fn(|k| s.x[k]);
            let (a, b) = id::floating_derivatives(p, base, &state, q, qd, &acc, &s.x[6..], Some(g));
            [a, b].concat().concat()
        }
        Function::ForwardDynamicsDerivatives => {
            let (a, b, c) = fd::floating_derivatives(p, base, &state, q, qd, &s.x[6..], Some(g));
            [a, b, c].concat().concat()
        }
        _ => upper(minverse::floating_mass_matrix_inverse(p, base, q)),
    }
}

#[test]
fn traced_derivatives_evaluate_to_the_f64_algorithms() {
    let gravity = [0.3, -0.8, -9.81];
    let g = Vec3::from_f64(gravity);
    for (k, m) in models().iter().enumerate() {
        let n = m.dof();
        let p = Params::<f64>::new(m);
        let inertial = random_inertial(&mut rng(40 + k as u64), 60.0, 1.0);
        let base64 = FloatingBase::<f64>::from_inertial(&inertial);
        for floating in [false, true] {
            let nb = if floating { 6 } else { 0 };
            let s = State::new(n, floating, 70 + k as u64);
            for regroup in [false, true] {
                let spec = Spec {
                    base: if floating {
                        Base::FreeFloating(inertial.clone())
                    } else {
                        Base::Fixed
                    },
                    gravity: Some(gravity),
                    regroup,
                    ..Spec::default()
                };
                for f in FUNCTIONS {
                    let t = trace(Subject::Model(m), f, Methods::SPATIAL, &spec).unwrap();
                    let x: Vec<f64> = t.inputs.iter().map(|i| s.input(i, nb)).collect();
                    let got = t.trace.eval(&x);
                    let want = expected(f, &p, floating.then_some(&base64), &s, &g);
                    assert_eq!(got.len(), want.len(), "{f:?}");
                    let scale = want.iter().fold(1.0_f64, |a, b| a.max(b.abs()));
                    let err = got
                        .iter()
                        .zip(&want)
                        .fold(0.0_f64, |a, (x, y)| a.max((x - y).abs()))
                        / scale;
                    assert!(
                        err < TOL,
                        "{} {f:?} floating {floating} regroup {regroup}: {err:e}",
                        m.name()
                    );
                }
            }
        }
    }
}

#[test]
fn derivatives_refuse_wrenches() {
    let m = random_chain(&ChainSpec::default(), 3);
    let spec = Spec {
        wrenches: vec![Wrench {
            body: 0,
            frame: LoadFrame::Body,
            value: WrenchValue::Runtime,
        }],
        ..Spec::default()
    };
    for f in FUNCTIONS {
        let e = trace(Subject::Model(&m), f, Methods::SPATIAL, &spec).unwrap_err();
        assert!(e.reason.contains("not wrenches or damping"), "{e}");
    }
}
