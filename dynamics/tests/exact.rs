//! Exact rational arithmetic as the oracle.
//!
//! At joint angles with rational sine and cosine ([`Exact::pythagorean`]) every algorithm
//! computes `A` and `b` of the stored model with no rounding at all, so:
//!
//! - the five algorithms (three of them sharing no recursion) give *identical* rationals;
//! - `A` is exactly symmetric, its LDLᵀ pivots are positive, and `A q̈ − b` is exactly zero;
//! - on a free-floating base, `½ νᵀ A ν` equals the bodies' kinetic energy exactly;
//! - the double-double ([`Wide`]) and `f64` runs of the same algorithm are measured against the
//!   exact values: this is what makes `Wide` a trusted reference for general angles.
//!
//! Run with `--nocapture` to see the measured errors and the size of the rationals.

use kanegen_dynamics::algorithms::floating::{self, kinetic_energy};
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen_dynamics::ldlt::{ldlt, solve};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::metrics::{rel_err, rel_err_mat, rel_err_wide};
use kanegen_dynamics::scalars::exact::{rational_state, Exact};
use kanegen_dynamics::scalars::wide::Wide;
use kanegen_dynamics::Params;
use kanegen_dynamics::{Dynamics, ExternalWrench, LoadFrame, Loads, Methods, Real, Scalar};
use kanegen_model::random::{random_chain, ChainSpec};
use kanegen_model::Model;
use std::path::PathBuf;

/// A random chain whose joint frames and axes are exactly orthonormal in rational arithmetic:
/// signed permutation rotations and coordinate axes (an `f64` unit vector off the coordinate
/// axes is never exactly unit, and then algorithms that use `Rᵀ` for `R⁻¹` legitimately
/// differ in the last bits). Lengths, masses and inertias stay random.
fn lattice_chain(n: usize, prismatic_fraction: f64, seed: u64) -> Model {
    let general = random_chain(
        &ChainSpec {
            n,
            prismatic_fraction,
            ..Default::default()
        },
        seed,
    );
    let rotations: [[[f64; 3]; 3]; 4] = [
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
        [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]],
        [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
    ];
    let axes = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];
    let joints = general
        .joints()
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let mut joint = joint.clone();
            joint.origin.rotation = rotations[(j * 3 + seed as usize) % 4];
            joint.axis = axes[(j + seed as usize) % 3];
            joint
        })
        .collect();
    Model::new(format!("lattice_n{n}"), "base", None, joints).unwrap()
}

fn ssrms() -> Model {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/reference/ssrms_nguyen_hughes_1994.urdf");
    kanegen_model::io::load_model(&p).unwrap()
}

fn loads<S: Scalar>(tau: Vec<S>, n: usize) -> Loads<S> {
    Loads {
        tau: Some(tau),
        gravity: Some(Vec3::from_f64([0.25, -0.5, -9.75])),
        external: vec![ExternalWrench {
            body: n - 1,
            frame: LoadFrame::Body,
            force: Vec3::from_f64([1.5, -2.0, 0.75]),
            moment: Vec3::from_f64([0.5, 0.25, -1.0]),
        }],
    }
}

fn to_f64_mat<S: Real>(a: &[Vec<S>]) -> Vec<Vec<f64>> {
    a.iter()
        .map(|r| r.iter().map(Real::to_f64).collect())
        .collect()
}

fn to_f64_vec<S: Real>(b: &[S]) -> Vec<f64> {
    b.iter().map(Real::to_f64).collect()
}

/// Error of a `Wide` result against the exact one, in double-double.
fn wide_rel(x: &[Wide], y: &[Exact]) -> f64 {
    let y: Vec<Wide> = y.iter().map(Exact::to_wide).collect();
    rel_err_wide(x, &y)
}

fn all_exact(d: &Dynamics<Exact>) -> bool {
    d.a.iter().flatten().chain(&d.b).all(Exact::is_exact)
}

#[test]
fn all_algorithms_agree_exactly_and_wide_is_within_1e_30() {
    let chains = [
        ("ssrms", ssrms()),
        ("random6 with prismatic joints", lattice_chain(6, 0.4, 21)),
    ];
    for (name, chain) in &chains {
        let n = chain.dof();
        let (q, qd, tau) = rational_state(chain, 3);
        let pe = Params::<Exact>::new(chain);
        let le = loads(tau.clone(), n);
        let reference = Methods::RECURRENT.dynamics(&pe, &q, &qd, &le);
        assert!(all_exact(&reference), "{name}: exactness lost");
        let bits = reference
            .a
            .iter()
            .flatten()
            .map(Exact::bits)
            .max()
            .unwrap_or(0);
        for alg in Methods::ALL {
            let d = alg.dynamics(&pe, &q, &qd, &le);
            assert!(all_exact(&d), "{name} {alg}: exactness lost");
            assert_eq!(
                d.a, reference.a,
                "{name} {alg}: A differs from recurrent's, exactly"
            );
            assert_eq!(
                d.b, reference.b,
                "{name} {alg}: b differs from recurrent's, exactly"
            );
        }
        for i in 0..n {
            for j in 0..n {
                assert_eq!(
                    reference.a[i][j], reference.a[j][i],
                    "{name}: A not symmetric"
                );
            }
        }
        // Exact LDLᵀ: positive pivots, and A q̈ = b with no residual at all.
        let f = ldlt(&reference.a);
        assert!(f
            .d
            .iter()
            .all(|d| d.is_exact() && d.value() > &Default::default()));
        let qdd = solve(&f, &reference.b);
        for i in 0..n {
            let r = (0..n).fold(Exact::zero(), |s, j| {
                s + reference.a[i][j].clone() * qdd[j].clone()
            }) - reference.b[i].clone();
            assert!(r.is_zero(), "{name}: residual of A q̈ = b in row {i}");
        }

        // Wide and f64, same algorithm, same (rounded) inputs.
        let qw: Vec<Wide> = q.iter().map(Exact::to_wide).collect();
        let qdw: Vec<Wide> = qd.iter().map(Exact::to_wide).collect();
        let lw = loads(tau.iter().map(Exact::to_wide).collect(), n);
        let dw = Methods::RECURRENT.dynamics(&Params::<Wide>::new(chain), &qw, &qdw, &lw);
        let qddw = solve(&ldlt(&dw.a), &dw.b);
        let ea = wide_rel(&dw.a.concat(), &reference.a.concat());
        let eb = wide_rel(&dw.b, &reference.b);
        let eq = wide_rel(&qddw, &qdd);
        let qf: Vec<f64> = qw.iter().map(Real::to_f64).collect();
        let qdf: Vec<f64> = qdw.iter().map(Real::to_f64).collect();
        let lf = loads(tau.iter().map(Real::to_f64).collect(), n);
        let df = Methods::RECURRENT.dynamics(&Params::<f64>::new(chain), &qf, &qdf, &lf);
        let qddf = solve(&ldlt(&df.a), &df.b);
        let fa = rel_err_mat(&df.a, &to_f64_mat(&reference.a));
        let fq = rel_err(&qddf, &to_f64_vec(&qdd));
        println!(
            "{name}: rationals up to {bits} bits; wide vs exact: A {ea:.2e}, b {eb:.2e}, \
             q̈ {eq:.2e}; f64 vs exact: A {fa:.2e}, q̈ {fq:.2e}"
        );
        // Measured: A ≤ 3.4e-32, b ≤ 3.2e-32, q̈ ≤ 4.3e-31 (the solve adds cond(A)·ε_dd); the
        // bounds leave a factor of about 25.
        assert!(
            ea < 1e-30 && eb < 1e-30 && eq < 1e-29,
            "{name}: wide {ea:e} {eb:e} {eq:e}"
        );
        assert!(fa < 1e-14 && fq < 1e-12, "{name}: f64 {fa:e} {fq:e}");
        // Wide is better than f64 by more than ten digits: it is a reference for f64.
        assert!(
            eq < 1e-10 * fq.max(1e-17),
            "{name}: wide {eq:e} vs f64 {fq:e}"
        );
    }
}

#[test]
fn free_floating_energy_is_exactly_half_nu_a_nu() {
    let chain = lattice_chain(4, 0.3, 5);
    let base_inertial = kanegen_model::Inertial {
        mass: 300.0,
        com: [0.125, -0.25, 0.5],
        inertia: [[40.0, 1.5, -2.0], [1.5, 55.0, 0.75], [-2.0, 0.75, 60.0]],
    };
    let base = FloatingBase::<Exact>::from_inertial(&base_inertial);
    // A unit quaternion with dyadic components: exactly a rotation.
    let quat = [0.5, -0.5, 0.5, 0.5].map(Exact::constant);
    let state = FloatingState {
        position: Vec3::from_f64([1.0, -2.0, 0.5]),
        rotation: quat_to_matrix(&quat),
        v_b: Vec3::from_f64([0.125, 0.25, -0.5]),
        omega_b: Vec3::from_f64([0.0625, -0.125, 0.25]),
    };
    let (q, qd, _) = rational_state(&chain, 1);
    let p = Params::<Exact>::new(&chain);
    let nu: Vec<Exact> = state
        .v_b
        .0
        .iter()
        .chain(&state.omega_b.0)
        .chain(&qd)
        .cloned()
        .collect();
    let t = kinetic_energy(&p, &base, &state, &q, &qd);
    for alg in Methods::ALL {
        let d = floating::dynamics(alg, &p, &base, &state, &q, &qd, &Loads::default());
        assert!(all_exact(&d), "{alg}: exactness lost");
        let m = nu.len();
        let quad = (0..m).fold(Exact::zero(), |s, i| {
            (0..m).fold(s, |s, j| {
                s + nu[i].clone() * d.a[i][j].clone() * nu[j].clone()
            })
        });
        let diff = quad * Exact::constant(0.5) - t.clone();
        assert!(
            t.is_exact() && diff.is_zero(),
            "{alg}: ½νᵀAν − T = {:e}",
            diff.to_f64()
        );
    }
}
