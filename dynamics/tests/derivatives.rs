//! The analytical derivatives of the dynamics (`algorithms::derivatives`: Carpentier & Mansard's
//! RNEA derivatives, `M⁻¹`, the forward-dynamics derivatives) against independent oracles:
//!
//! - forward-mode dual numbers (`Dual<f64>`, one direction per column) through the existing RNEA
//!   and ABA, fixed and free-floating bases (the base pose perturbed along Pinocchio's
//!   `integrate`: `R₀ ← R₀ (1 + ε δ̃ω)`, exact to first order in `ε`), agreeing to 1e-12
//!   relative;
//! - central differences of the `f64` algorithms, whose truncation error `h² |f'''| / 6` is
//!   bounded at `h = 1e-4` well below the tolerance;
//! - `M⁻¹ M = 1`.
//!
//! Errors are relative to the largest entry of the oracle's matrix (at least 1),
//! `max|x − y| / max|y|`.

#![allow(clippy::needless_range_loop)]

use kanegen_dynamics::algorithms::derivatives::{aba as fd_deriv, minverse, rnea as id_deriv};
use kanegen_dynamics::algorithms::{aba, crba, rnea};
use kanegen_dynamics::base::{FloatingBase, FloatingState};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::scalars::dual::Dual;
use kanegen_dynamics::{Loads, Params};
use kanegen_model::random::{
    random_chain, random_inertial, random_rotation, random_tree, random_vec, rng, ChainSpec,
};
use kanegen_model::{Inertial, Model};

type D = Dual<f64>;

/// `max|x − y| / max(max|y|, 1)` (the floor for matrices that vanish, such as `∂τ/∂q̇` of a
/// single joint).
fn rel_mat(x: &[Vec<f64>], y: &[Vec<f64>]) -> f64 {
    let scale = y.iter().flatten().fold(1.0_f64, |m, v| m.max(v.abs()));
    let err = x
        .iter()
        .flatten()
        .zip(y.iter().flatten())
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    err / scale
}

/// The test models: chains with prismatic joints and branching trees.
fn models() -> Vec<Model> {
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.3,
        ..Default::default()
    };
    vec![
        random_chain(&spec(1), 11),
        random_chain(&spec(4), 12),
        random_chain(&spec(7), 13),
        random_tree(&spec(6), 14),
        random_tree(&spec(9), 15),
    ]
}

/// A state of the model: q, q̇, a second vector (q̈ or τ), gravity.
struct State {
    q: Vec<f64>,
    qd: Vec<f64>,
    x: Vec<f64>,
    g: Vec3<f64>,
}

fn state(n: usize, seed: u64) -> State {
    let mut r = rng(seed);
    let g = random_vec(&mut r, 3, 9.81);
    State {
        q: random_vec(&mut r, n, 2.0),
        qd: random_vec(&mut r, n, 1.5),
        x: random_vec(&mut r, n, 5.0),
        g: Vec3::new(g[0], g[1], g[2]),
    }
}

fn lift(x: &[f64]) -> Vec<D> {
    x.iter().map(|&v| D::lift(v)).collect()
}

fn lift3(v: &Vec3<f64>) -> Vec3<D> {
    Vec3(v.0.map(D::lift))
}

/// `x` with the derivative direction `e_k` (none when `k` is out of range).
fn seeded(x: &[f64], k: usize) -> Vec<D> {
    x.iter()
        .enumerate()
        .map(|(i, &v)| D::new(v, if i == k { 1.0 } else { 0.0 }))
        .collect()
}

/// Column by column: `cols[j]` is the derivative of the output along direction `j`; as rows.
fn transpose(cols: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let rows = cols.first().map_or(0, Vec::len);
    (0..rows)
        .map(|i| cols.iter().map(|c| c[i]).collect())
        .collect()
}

fn eps(v: &[D]) -> Vec<f64> {
    v.iter().map(|d| d.eps).collect()
}

const DUAL_TOL: f64 = 1e-12;

#[test]
fn fixed_base_rnea_derivatives_match_dual_numbers() {
    for (m, model) in models().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let pd = Params::<D>::new(model);
        let s = state(n, 100 + m as u64);
        let (dq, dv) = id_deriv::derivatives(&p, &s.q, &s.qd, &s.x, Some(&s.g));
        let loads = Loads {
            gravity: Some(lift3(&s.g)),
            ..Loads::default()
        };
        let by_q: Vec<Vec<f64>> = (0..n)
            .map(|j| {
                eps(&rnea::inverse_dynamics(
                    &pd,
                    &seeded(&s.q, j),
                    &lift(&s.qd),
                    &lift(&s.x),
                    &loads,
                ))
            })
            .collect();
        let by_v: Vec<Vec<f64>> = (0..n)
            .map(|j| {
                eps(&rnea::inverse_dynamics(
                    &pd,
                    &lift(&s.q),
                    &seeded(&s.qd, j),
                    &lift(&s.x),
                    &loads,
                ))
            })
            .collect();
        let (eq, ev) = (
            rel_mat(&dq, &transpose(&by_q)),
            rel_mat(&dv, &transpose(&by_v)),
        );
        println!("{}: ∂τ/∂q {eq:.1e}, ∂τ/∂q̇ {ev:.1e}", model.name());
        assert!(
            eq < DUAL_TOL && ev < DUAL_TOL,
            "{}: {eq:e} {ev:e}",
            model.name()
        );
    }
}

#[test]
fn fixed_base_aba_derivatives_match_dual_numbers() {
    for (m, model) in models().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let pd = Params::<D>::new(model);
        let s = state(n, 200 + m as u64);
        let (dq, dv, minv) = fd_deriv::derivatives(&p, &s.q, &s.qd, &s.x, Some(&s.g));
        let fd = |q: &[D], qd: &[D], tau: &[D]| {
            let loads = Loads {
                tau: Some(tau.to_vec()),
                gravity: Some(lift3(&s.g)),
                ..Loads::default()
            };
            eps(&aba::forward_dynamics(&pd, q, qd, &loads))
        };
        let (q, qd, tau) = (lift(&s.q), lift(&s.qd), lift(&s.x));
        let by_q: Vec<Vec<f64>> = (0..n).map(|j| fd(&seeded(&s.q, j), &qd, &tau)).collect();
        let by_v: Vec<Vec<f64>> = (0..n).map(|j| fd(&q, &seeded(&s.qd, j), &tau)).collect();
        let by_t: Vec<Vec<f64>> = (0..n).map(|j| fd(&q, &qd, &seeded(&s.x, j))).collect();
        let e = [
            rel_mat(&dq, &transpose(&by_q)),
            rel_mat(&dv, &transpose(&by_v)),
            rel_mat(&minv, &transpose(&by_t)),
        ];
        println!("{}: ∂q̈/∂q, ∂q̈/∂q̇, M⁻¹: {e:?}", model.name());
        assert!(e.iter().all(|&x| x < DUAL_TOL), "{}: {e:?}", model.name());
    }
}

/// A random free-floating system.
struct Floating {
    base: Inertial,
    rotation: [[f64; 3]; 3],
    nu_b: Vec<f64>,
    acc_b: Vec<f64>,
}

fn floating(seed: u64) -> Floating {
    let mut r = rng(seed);
    Floating {
        base: random_inertial(&mut r, 50.0, 1.0),
        rotation: random_rotation(&mut r),
        nu_b: random_vec(&mut r, 6, 1.0),
        acc_b: random_vec(&mut r, 6, 2.0),
    }
}

/// The base state as dual numbers, perturbed along base direction `k` of `[δp; δθ]` (Pinocchio's
/// `integrate`: `R₀ ← R₀ exp(δθ̃)`, `= R₀ (1 + ε δθ̃)` to first order; `p₀` does not enter) when
/// `pose`, else along `ν_b` direction `k`; no direction when `k ≥ 6`.
fn dual_state(f: &Floating, k: usize, pose: bool) -> FloatingState<D> {
    let mut w = [0.0; 3];
    if pose && (3..6).contains(&k) {
        w[k - 3] = 1.0;
    }
    let skew = [[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]];
    let rotation = Mat3(core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            let d: f64 = (0..3).map(|l| f.rotation[i][l] * skew[l][j]).sum();
            D::new(f.rotation[i][j], d)
        })
    }));
    let nu = if pose {
        lift(&f.nu_b)
    } else {
        seeded(&f.nu_b, k)
    };
    FloatingState {
        position: Vec3::zero(),
        rotation,
        v_b: Vec3::new(nu[0].clone(), nu[1].clone(), nu[2].clone()),
        omega_b: Vec3::new(nu[3].clone(), nu[4].clone(), nu[5].clone()),
    }
}

fn f64_state(f: &Floating) -> FloatingState<f64> {
    FloatingState {
        position: Vec3::zero(),
        rotation: Mat3(f.rotation),
        v_b: Vec3::new(f.nu_b[0], f.nu_b[1], f.nu_b[2]),
        omega_b: Vec3::new(f.nu_b[3], f.nu_b[4], f.nu_b[5]),
    }
}

/// A free-floating function of `(state, q, q̇)`.
type FloatingFn<'a> = dyn Fn(&FloatingState<D>, &[D], &[D]) -> Vec<D> + 'a;

/// Dual derivatives of a floating function `run(state, q, qd)` along every tangent direction
/// of the configuration (`pose`) or of the speeds.
fn floating_columns(
    f: &Floating,
    s: &State,
    n: usize,
    pose: bool,
    run: &FloatingFn,
) -> Vec<Vec<f64>> {
    (0..6 + n)
        .map(|k| {
            let st = dual_state(f, k, pose);
            let arm = k.wrapping_sub(6);
            let (q, qd) = if pose {
                (seeded(&s.q, arm), lift(&s.qd))
            } else {
                (lift(&s.q), seeded(&s.qd, arm))
            };
            eps(&run(&st, &q, &qd))
        })
        .collect()
}

#[test]
fn floating_base_derivatives_match_dual_numbers() {
    for (m, model) in models().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let pd = Params::<D>::new(model);
        let s = state(n, 300 + m as u64);
        let f = floating(400 + m as u64);
        let base = FloatingBase::<f64>::from_inertial(&f.base);
        let based = FloatingBase::<D>::from_inertial(&f.base);
        let st = f64_state(&f);
        let acc: [f64; 6] = core::array::from_fn(|k| f.acc_b[k]);
        let acc_d: [D; 6] = acc.map(D::lift);
        let g_d = lift3(&s.g);
        // Inverse dynamics with ν̇ = [acc; x].
        let (dq, dv) =
            id_deriv::floating_derivatives(&p, &base, &st, &s.q, &s.qd, &acc, &s.x, Some(&s.g));
        let id = |st: &FloatingState<D>, q: &[D], qd: &[D]| {
            let loads = Loads {
                gravity: Some(g_d.clone()),
                ..Loads::default()
            };
            rnea::floating_inverse_dynamics(&pd, &based, st, q, qd, &acc_d, &lift(&s.x), &loads)
        };
        let eq = rel_mat(&dq, &transpose(&floating_columns(&f, &s, n, true, &id)));
        let ev = rel_mat(&dv, &transpose(&floating_columns(&f, &s, n, false, &id)));
        // Forward dynamics with drives x.
        let (fq, fv, minv) =
            fd_deriv::floating_derivatives(&p, &base, &st, &s.q, &s.qd, &s.x, Some(&s.g));
        let fd = |st: &FloatingState<D>, q: &[D], qd: &[D]| {
            let loads = Loads {
                tau: Some(lift(&s.x)),
                gravity: Some(g_d.clone()),
                ..Loads::default()
            };
            aba::floating(&pd, &based, st, q, qd, &loads)
        };
        let fq_err = rel_mat(&fq, &transpose(&floating_columns(&f, &s, n, true, &fd)));
        let fv_err = rel_mat(&fv, &transpose(&floating_columns(&f, &s, n, false, &fd)));
        let mass = crba::floating_mass_matrix(&p, &base, &s.q);
        let minv_err = identity_error(&minv, &mass);
        println!(
            "{} floating: ∂τ/∂q {eq:.1e}, ∂τ/∂ν {ev:.1e}, ∂ν̇/∂q {fq_err:.1e}, ∂ν̇/∂ν {fv_err:.1e}, M⁻¹M − 1 {minv_err:.1e}",
            model.name()
        );
        for e in [eq, ev, fq_err, fv_err, minv_err] {
            assert!(e < DUAL_TOL, "{}: {e:e}", model.name());
        }
    }
}

/// `max |M⁻¹ M − 1|`.
fn identity_error(minv: &[Vec<f64>], m: &[Vec<f64>]) -> f64 {
    let n = m.len();
    let mut err = 0.0_f64;
    for i in 0..n {
        for j in 0..n {
            let x: f64 = (0..n).map(|k| minv[i][k] * m[k][j]).sum();
            err = err.max((x - if i == j { 1.0 } else { 0.0 }).abs());
        }
    }
    err
}

#[test]
fn mass_matrix_inverse_times_mass_matrix_is_identity() {
    for (m, model) in models().iter().enumerate() {
        let p = Params::<f64>::new(model);
        let s = state(model.dof(), 500 + m as u64);
        let e = identity_error(
            &minverse::mass_matrix_inverse(&p, &s.q),
            &crba::mass_matrix(&p, &s.q),
        );
        println!("{}: M⁻¹M − 1 {e:.1e}", model.name());
        assert!(e < 1e-12, "{}: {e:e}", model.name());
    }
}

/// Central differences `(f(x + h e_j) − f(x − h e_j)) / 2h`, truncation `h² |f'''| / 6`: with
/// `h = 1e-4` and the models' third derivatives of order 10² relative to the entries, the error
/// stays below 1e-6 relative (rounding `ε |f| / h` is 1e-12).
#[test]
fn fixed_base_rnea_derivatives_match_central_differences() {
    let h = 1e-4;
    for (m, model) in models().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let s = state(n, 600 + m as u64);
        let (dq, dv) = id_deriv::derivatives(&p, &s.q, &s.qd, &s.x, Some(&s.g));
        let loads = Loads {
            gravity: Some(s.g.clone()),
            ..Loads::default()
        };
        let diff = |which: usize| -> Vec<Vec<f64>> {
            let cols: Vec<Vec<f64>> = (0..n)
                .map(|j| {
                    let at = |t: f64| {
                        let (mut q, mut qd) = (s.q.clone(), s.qd.clone());
                        if which == 0 {
                            q[j] += t;
                        } else {
                            qd[j] += t;
                        }
                        rnea::inverse_dynamics(&p, &q, &qd, &s.x, &loads)
                    };
                    let (a, b) = (at(h), at(-h));
                    a.iter().zip(&b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
                })
                .collect();
            transpose(&cols)
        };
        let (eq, ev) = (rel_mat(&dq, &diff(0)), rel_mat(&dv, &diff(1)));
        println!(
            "{}: central differences ∂τ/∂q {eq:.1e}, ∂τ/∂q̇ {ev:.1e}",
            model.name()
        );
        assert!(eq < 1e-6 && ev < 1e-6, "{}: {eq:e} {ev:e}", model.name());
    }
}
