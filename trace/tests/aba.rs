//! The traced articulated-body algorithm (`Methods::ABA`) evaluates to the f64 algorithm: the
//! graph `trace()` records for forward dynamics, fed the same state, equals
//! `kanegen_dynamics::algorithms::aba` on `f64`. Random trees and chains with prismatic joints,
//! fixed and free-floating base, gravity, a constant and a runtime wrench (base and body frame),
//! `f_ext` on every body, regrouped parameters on and off. The traced LDLᵀ on the same inputs
//! agrees too, and the two graphs are different graphs (ABA has no mass matrix: fewer
//! operations on a long chain).

use kanegen_dynamics::algorithms::aba;
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState, BASE_BODY};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::metrics::rel_err;
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads, Methods, Params};
use kanegen_model::random::{
    random_chain, random_inertial, random_tree, random_vec, rng, ChainSpec,
};
use kanegen_model::Model;
use kanegen_trace::{
    trace, Arg, Base, Convention, Function, Input, PayloadField, Spec, Subject, Wrench, WrenchValue,
};

const TOL: f64 = 1e-12;

/// Values for every input of a forward-dynamics trace, from one state.
struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
    f_ext: Vec<[f64; 6]>,
    runtime_wrench: [f64; 6],
}

impl State {
    fn input(&self, i: &Input) -> f64 {
        match i {
            Input::Joint(Arg::Q, k) => self.q[*k],
            Input::Joint(Arg::Qd | Arg::V, k) => self.v[*k],
            Input::Joint(Arg::Tau, k) => self.tau[*k],
            Input::Row(Arg::FExt, r, c) => self.f_ext[*r][*c],
            Input::Wrench { component, .. } => self.runtime_wrench[*component],
            other => panic!("unexpected input {other}"),
        }
    }
}

fn spec(base: Base, n: usize, regroup: bool) -> Spec {
    Spec {
        base,
        gravity: Some([0.3, -0.8, -9.81]),
        wrenches: vec![
            Wrench {
                body: n - 1,
                frame: LoadFrame::Base,
                value: WrenchValue::Constant {
                    force: [1.5, -2.0, 3.0],
                    moment: [0.2, 0.1, -0.4],
                },
            },
            Wrench {
                body: n / 2,
                frame: LoadFrame::Body,
                value: WrenchValue::Runtime,
            },
        ],
        regroup,
        ..Spec::default()
    }
}

fn wrench(body: usize, frame: LoadFrame, w: [f64; 6]) -> ExternalWrench<f64> {
    ExternalWrench {
        body,
        frame,
        force: Vec3::new(w[0], w[1], w[2]),
        moment: Vec3::new(w[3], w[4], w[5]),
    }
}

/// The f64 loads of `spec` and the state (f_ext only for the wrench function).
fn loads(spec: &Spec, s: &State, floating: bool, with_f_ext: bool) -> Loads<f64> {
    let mut external: Vec<ExternalWrench<f64>> = spec
        .wrenches
        .iter()
        .map(|w| {
            let v = match &w.value {
                WrenchValue::Constant { force, moment } => [
                    force[0], force[1], force[2], moment[0], moment[1], moment[2],
                ],
                WrenchValue::Runtime => s.runtime_wrench,
            };
            wrench(w.body, w.frame, v)
        })
        .collect();
    if with_f_ext {
        for (r, row) in s.f_ext.iter().enumerate() {
            let body = match (floating, r) {
                (true, 0) => BASE_BODY,
                (true, r) => r - 1,
                (false, r) => r,
            };
            external.push(wrench(body, LoadFrame::Body, *row));
        }
    }
    Loads {
        tau: Some(s.tau.clone()),
        gravity: spec.gravity.map(Vec3::from_f64),
        external,
    }
}

fn models() -> Vec<Model> {
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.35,
        ..Default::default()
    };
    vec![
        random_tree(&spec(6), 12),
        random_tree(&spec(4), 5),
        random_chain(&spec(5), 21),
        random_chain(&spec(1), 2),
    ]
}

#[test]
fn traced_aba_evaluates_to_the_f64_algorithm() {
    let mut worst = 0.0_f64;
    for (k, m) in models().iter().enumerate() {
        let n = m.dof();
        let p = Params::<f64>::new(m);
        let inertial = random_inertial(&mut rng(40 + k as u64), 60.0, 1.0);
        for floating in [false, true] {
            let base = if floating {
                Base::FreeFloating(inertial.clone())
            } else {
                Base::Fixed
            };
            for regroup in [false, true] {
                let spec = spec(base.clone(), n, regroup);
                for f in [
                    Function::ForwardDynamics,
                    Function::ForwardDynamicsWithWrenches,
                ] {
                    let t = trace(Subject::Model(m), f, Methods::ABA, &spec).unwrap();
                    let ldlt = trace(Subject::Model(m), f, Methods::SPATIAL, &spec).unwrap();
                    for seed in 0..3 {
                        let mut g = rng(100 * k as u64 + seed);
                        let mut q = random_vec(&mut g, n + 7, 2.0);
                        let quat = random_vec(&mut g, 4, 1.0);
                        let norm = quat.iter().map(|x| x * x).sum::<f64>().sqrt();
                        let state = if floating {
                            for (i, x) in quat.iter().enumerate() {
                                q[3 + i] = x / norm;
                            }
                            let v = random_vec(&mut g, n + 6, 1.0);
                            State {
                                q,
                                v,
                                tau: random_vec(&mut g, n, 10.0),
                                f_ext: (0..=n)
                                    .map(|_| random_vec(&mut g, 6, 4.0).try_into().unwrap())
                                    .collect(),
                                runtime_wrench: random_vec(&mut g, 6, 3.0).try_into().unwrap(),
                            }
                        } else {
                            q.truncate(n);
                            State {
                                q,
                                v: random_vec(&mut g, n, 1.0),
                                tau: random_vec(&mut g, n, 10.0),
                                f_ext: (0..n)
                                    .map(|_| random_vec(&mut g, 6, 4.0).try_into().unwrap())
                                    .collect(),
                                runtime_wrench: random_vec(&mut g, 6, 3.0).try_into().unwrap(),
                            }
                        };
                        let values: Vec<f64> = t.inputs.iter().map(|i| state.input(i)).collect();
                        let have = t.trace.eval(&values);
                        let l = loads(
                            &spec,
                            &state,
                            floating,
                            f.args(floating).contains(&Arg::FExt),
                        );
                        let want = if floating {
                            let s = &state;
                            let fs = FloatingState {
                                position: Vec3::new(s.q[0], s.q[1], s.q[2]),
                                rotation: quat_to_matrix(&[s.q[3], s.q[4], s.q[5], s.q[6]]),
                                v_b: Vec3::new(s.v[0], s.v[1], s.v[2]),
                                omega_b: Vec3::new(s.v[3], s.v[4], s.v[5]),
                            };
                            let b = FloatingBase::<f64>::from_inertial(&inertial);
                            aba::floating(&p, &b, &fs, &s.q[7..], &s.v[6..], &l)
                        } else {
                            aba::forward_dynamics(&p, &state.q, &state.v, &l)
                        };
                        let e = rel_err(&have, &want);
                        let what = format!(
                            "{} {} floating={floating} regroup={regroup} seed {seed}",
                            m.name(),
                            f.name()
                        );
                        assert!(e < TOL, "{what}: traced ABA vs f64 {e:e}");
                        worst = worst.max(e);
                        // LDLᵀ reads the same inputs in the same order.
                        assert_eq!(ldlt.inputs, t.inputs);
                        let e = rel_err(&ldlt.trace.eval(&values), &want);
                        assert!(e < TOL, "{what}: traced LDLᵀ vs f64 ABA {e:e}");
                    }
                }
            }
        }
    }
    println!("traced ABA vs f64 ABA: worst {worst:.1e}");
}

/// The two methods are different graphs: on a chain of 24 joints ABA's emitted count is below
/// LDLᵀ's, and it divides once per joint whose `D` is not a model constant.
#[test]
fn aba_traces_a_different_cheaper_graph_on_a_long_chain() {
    let m = random_chain(
        &ChainSpec {
            n: 24,
            ..Default::default()
        },
        3,
    );
    let spec = Spec {
        regroup: true,
        ..Spec::default()
    };
    let f = Function::ForwardDynamics;
    let aba = trace(Subject::Model(&m), f, Methods::ABA, &spec).unwrap();
    let ldlt = trace(Subject::Model(&m), f, Methods::SPATIAL, &spec).unwrap();
    let (a, l) = (
        aba.trace.counts(Convention::Emitted),
        ldlt.trace.counts(Convention::Emitted),
    );
    assert!(a.total() < l.total(), "ABA {a:?} vs LDLᵀ {l:?}");
    // The leaf's D is a constant of the model: N − 1 divisions.
    assert_eq!(a.div, 23);
    assert_eq!(l.div, 24);
}

/// A runtime payload (the last body's mass properties as inputs; regrouping keeps that body):
/// the traced ABA evaluates to the f64 ABA with the payload set, fixed and free-floating.
#[test]
fn traced_aba_with_a_runtime_payload() {
    let m = random_chain(
        &ChainSpec {
            n: 5,
            prismatic_fraction: 0.35,
            ..Default::default()
        },
        8,
    );
    let n = m.dof();
    let payload = random_inertial(&mut rng(3), 40.0, 0.8);
    let mut p = Params::<f64>::new(&m);
    p.joints[n - 1].set_inertial(
        payload.mass,
        Vec3(payload.com),
        kanegen_dynamics::linalg::Mat3(payload.inertia),
    );
    let inertial = random_inertial(&mut rng(4), 60.0, 1.0);
    for floating in [false, true] {
        let spec = Spec {
            base: if floating {
                Base::FreeFloating(inertial.clone())
            } else {
                Base::Fixed
            },
            gravity: Some([0.0, 0.2, -9.81]),
            runtime_payload: true,
            regroup: true,
            ..Spec::default()
        };
        let t = trace(
            Subject::Model(&m),
            Function::ForwardDynamics,
            Methods::ABA,
            &spec,
        )
        .unwrap();
        let mut g = rng(9);
        let mut q = random_vec(&mut g, n + 7, 2.0);
        if floating {
            let norm = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
            for x in &mut q[3..7] {
                *x /= norm;
            }
        }
        let v = random_vec(&mut g, n + 6, 1.0);
        let tau = random_vec(&mut g, n, 10.0);
        let values: Vec<f64> = t
            .inputs
            .iter()
            .map(|i| match i {
                Input::Payload(PayloadField::Mass) => payload.mass,
                Input::Payload(PayloadField::Com(k)) => payload.com[*k],
                Input::Payload(PayloadField::Inertia(r, c)) => payload.inertia[*r][*c],
                Input::Joint(Arg::Q, k) => q[*k],
                Input::Joint(Arg::Qd | Arg::V, k) => v[*k],
                Input::Joint(Arg::Tau, k) => tau[*k],
                other => panic!("unexpected input {other}"),
            })
            .collect();
        let l = Loads {
            tau: Some(tau.clone()),
            gravity: Some(Vec3::new(0.0, 0.2, -9.81)),
            external: Vec::new(),
        };
        let want = if floating {
            let fs = FloatingState {
                position: Vec3::new(q[0], q[1], q[2]),
                rotation: quat_to_matrix(&[q[3], q[4], q[5], q[6]]),
                v_b: Vec3::new(v[0], v[1], v[2]),
                omega_b: Vec3::new(v[3], v[4], v[5]),
            };
            let b = FloatingBase::<f64>::from_inertial(&inertial);
            aba::floating(&p, &b, &fs, &q[7..], &v[6..], &l)
        } else {
            aba::forward_dynamics(&p, &q[..n], &v[..n], &l)
        };
        let e = rel_err(&t.trace.eval(&values), &want);
        assert!(e < TOL, "floating={floating}: {e:e}");
    }
}
