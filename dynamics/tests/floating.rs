//! Free-floating base: the `(6+N)` equations of motion `A ν̇ = b` of every algorithm
//! against Pinocchio's free-flyer mass matrices in `models/space_arms.json`, against each other,
//! against kinetic energy and momentum computed body by body, momentum conservation under RK4
//! integration, and the generalized Jacobian identity.
//!
//! Errors are relative, `max|x − y| / max|y|`. Run with `--nocapture` to see the measured maxima.

// Matrix identities read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use kanegen_dynamics::algorithms::floating::{
    self, kinetic_energy, kinetic_energy_by_bodies, momentum, momentum_by_bodies,
};
use kanegen_dynamics::algorithms::frames::{floating_jacobian, generalized_jacobian};
use kanegen_dynamics::algorithms::kinematics::{floating_base_frame, floating_motion};
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState, BASE_BODY};
use kanegen_dynamics::ldlt::{ldlt, solve};
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads, Methods};
use kanegen_dynamics::{FrameParams, Params};
use kanegen_model::io::load_model_with;
use kanegen_model::random::ChainSpec;
use kanegen_model::random::{random_chain, random_inertial, random_rotation, random_vec, rng};
use kanegen_model::Inertial;
use kanegen_model::Validation;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;

/// The base-frame algorithms (virtual-joint extension) and the independent spatial one.
const ALGS: [Methods; 5] = Methods::ALL;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn rel_vec(x: &[f64], y: &[f64]) -> f64 {
    assert_eq!(x.len(), y.len());
    let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
    x.iter()
        .zip(y)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
        / scale
}

fn rel_mat(x: &[Vec<f64>], y: &[Vec<f64>]) -> f64 {
    let fx: Vec<f64> = x.iter().flatten().copied().collect();
    let fy: Vec<f64> = y.iter().flatten().copied().collect();
    rel_vec(&fx, &fy)
}

fn v3(x: &[f64]) -> Vec3<f64> {
    Vec3::new(x[0], x[1], x[2])
}

/// A random free-floating system: arm, base, base state, q, q̇, loads (gravity, drives, wrenches
/// on arm bodies and on the base, in both frames).
struct Case {
    p: Params<f64>,
    base: FloatingBase<f64>,
    state: FloatingState<f64>,
    q: Vec<f64>,
    qd: Vec<f64>,
    loads: Loads<f64>,
}

fn random_state(r: &mut ChaCha8Rng, scale: f64) -> FloatingState<f64> {
    FloatingState {
        position: v3(&random_vec(r, 3, 2.0)),
        rotation: Mat3(random_rotation(r)),
        v_b: v3(&random_vec(r, 3, scale)),
        omega_b: v3(&random_vec(r, 3, scale)),
    }
}

fn random_case(n: usize, seed: u64, prismatic: f64, with_loads: bool) -> Case {
    let chain = random_chain(
        &ChainSpec {
            n,
            prismatic_fraction: prismatic,
            ..Default::default()
        },
        seed,
    );
    let mut r = rng(seed ^ 0x5eed);
    let base = FloatingBase::from_inertial(&random_inertial(&mut r, 200.0, 2.0));
    let state = random_state(&mut r, 1.0);
    let q = random_vec(&mut r, n, 2.0);
    let qd = random_vec(&mut r, n, 1.0);
    let loads = if with_loads {
        let mut external = Vec::new();
        for k in 0..3 {
            let body = if k == 0 {
                BASE_BODY
            } else {
                r.random_range(0..n)
            };
            external.push(ExternalWrench {
                body,
                frame: if r.random_bool(0.5) {
                    LoadFrame::Body
                } else {
                    LoadFrame::Base
                },
                force: v3(&random_vec(&mut r, 3, 20.0)),
                moment: v3(&random_vec(&mut r, 3, 5.0)),
            });
        }
        Loads {
            tau: Some(random_vec(&mut r, n, 10.0)),
            gravity: Some(v3(&random_vec(&mut r, 3, 9.81))),
            external,
        }
    } else {
        Loads::default()
    };
    Case {
        p: Params::new(&chain),
        base,
        state,
        q,
        qd,
        loads,
    }
}

fn dynamics(alg: Methods, c: &Case) -> (Vec<Vec<f64>>, Vec<f64>) {
    let d = floating::dynamics(alg, &c.p, &c.base, &c.state, &c.q, &c.qd, &c.loads);
    (d.a, d.b)
}

fn nu(state: &FloatingState<f64>, qd: &[f64]) -> Vec<f64> {
    let mut v = state.nu_base().to_vec();
    v.extend_from_slice(qd);
    v
}

fn mat_vec(a: &[Vec<f64>], x: &[f64]) -> Vec<f64> {
    a.iter()
        .map(|row| row.iter().zip(x).map(|(p, q)| p * q).sum())
        .collect()
}

// ---------------------------------------------------------------------------------------------
// 1. Pinocchio free-flyer mass matrices.
// ---------------------------------------------------------------------------------------------

fn inertia_from_json(v: &serde_json::Value) -> [[f64; 3]; 3] {
    let g = |k: &str| v[k].as_f64().unwrap();
    [
        [g("ixx"), g("ixy"), g("ixz")],
        [g("ixy"), g("iyy"), g("iyz")],
        [g("ixz"), g("iyz"), g("izz")],
    ]
}

fn f64s(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn free_floating_mass_matrix_matches_pinocchio() {
    let text = std::fs::read_to_string(repo().join("models/space_arms.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut checked = 0;
    for m in json["models"].as_array().unwrap() {
        let rv = &m["reference_values"];
        if rv.get("free_floating_mass_matrix").is_none() {
            continue;
        }
        let id = m["id"].as_str().unwrap();
        let urdf = repo().join(format!("tests/data/reference/{id}.urdf"));
        if !urdf.exists() {
            println!("{id}: no URDF, skipped");
            continue;
        }
        let conv = rv["free_floating_convention"].as_str().unwrap();
        assert!(conv.contains("Pinocchio free-flyer") && conv.contains("identity"));
        let chain = load_model_with(
            &urdf,
            Validation {
                allow_nonphysical_inertia: true,
            },
        )
        .unwrap();
        // The URDF's root link inertial is the JSON's composite base.
        let bi = chain.base_inertial().expect("root link inertial").clone();
        let comp = &m["base"]["composite"];
        let want = Inertial {
            mass: comp["mass"].as_f64().unwrap(),
            com: f64s(&comp["com"]).try_into().unwrap(),
            inertia: inertia_from_json(&comp["inertia"]),
        };
        assert!(
            (bi.mass - want.mass).abs() < 1e-9 * want.mass,
            "{id} base mass"
        );
        for i in 0..3 {
            assert!((bi.com[i] - want.com[i]).abs() < 1e-9, "{id} base com");
            for j in 0..3 {
                assert!(
                    (bi.inertia[i][j] - want.inertia[i][j]).abs() < 1e-9 * want.inertia[0][0],
                    "{id} base inertia {:?} vs {:?}",
                    bi.inertia,
                    want.inertia
                );
            }
        }
        let q = f64s(&rv["q"]);
        let reference: Vec<Vec<f64>> = rv["free_floating_mass_matrix"]
            .as_array()
            .unwrap()
            .iter()
            .map(f64s)
            .collect();
        assert_eq!(reference.len(), 6 + chain.dof());
        let p = Params::<f64>::new(&chain);
        let base = FloatingBase::from_inertial(&bi);
        let state = FloatingState::at_rest();
        let zeros = vec![0.0; chain.dof()];
        for alg in ALGS {
            let d = floating::dynamics(alg, &p, &base, &state, &q, &zeros, &Loads::default());
            let e = rel_mat(&d.a, &reference);
            println!("{id:28} {alg:13} A rel err vs Pinocchio {e:.2e}");
            assert!(e < 1e-9, "{id} {alg}: {e:e}");
        }
        checked += 1;
    }
    assert_eq!(checked, 5, "expected five free-floating models with URDFs");
}

// ---------------------------------------------------------------------------------------------
// 2. Agreement of all algorithms.
// ---------------------------------------------------------------------------------------------

#[test]
fn all_algorithms_agree_on_random_floating_chains() {
    let (mut worst_a, mut worst_b) = (0.0_f64, 0.0_f64);
    for n in 1..=16 {
        for (s, prismatic) in [(0_u64, 0.0), (1, 0.4)] {
            let c = random_case(n, 100 * n as u64 + s, prismatic, true);
            let (a_ref, b_ref) = dynamics(Methods::SPATIAL, &c);
            // Without loads and at rest, the velocity-product terms alone.
            for alg in ALGS {
                let (a, b) = dynamics(alg, &c);
                let (ea, eb) = (rel_mat(&a, &a_ref), rel_vec(&b, &b_ref));
                worst_a = worst_a.max(ea);
                worst_b = worst_b.max(eb);
                assert!(ea < 1e-12, "n={n} {alg}: A {ea:e}");
                assert!(eb < 1e-12, "n={n} {alg}: b {eb:e}");
                for i in 0..a.len() {
                    for j in 0..a.len() {
                        assert_eq!(a[i][j], a[j][i], "A symmetric");
                    }
                }
            }
            // Each load separately, so a wrong sign in one cannot hide behind another.
            for k in 0..4 {
                let mut c2 = random_case(n, 100 * n as u64 + s, prismatic, true);
                let l = &c.loads;
                c2.loads = match k {
                    0 => Loads::default(),
                    1 => Loads {
                        gravity: l.gravity.clone(),
                        ..Loads::default()
                    },
                    2 => Loads {
                        external: vec![l.external[0].clone()],
                        ..Loads::default()
                    },
                    _ => Loads {
                        external: l.external[1..].to_vec(),
                        ..Loads::default()
                    },
                };
                let (_, b_ref) = dynamics(Methods::SPATIAL, &c2);
                for alg in ALGS {
                    let eb = rel_vec(&dynamics(alg, &c2).1, &b_ref);
                    worst_b = worst_b.max(eb);
                    assert!(eb < 1e-12, "n={n} {alg} load set {k}: b {eb:e}");
                }
            }
        }
    }
    println!("max rel. disagreement with spatial: A {worst_a:.2e}, b {worst_b:.2e}");
}

#[test]
fn arm_block_is_the_fixed_base_mass_matrix() {
    for n in [1, 4, 9] {
        let c = random_case(n, 7 + n as u64, 0.3, false);
        for alg in ALGS {
            let (a, _) = dynamics(alg, &c);
            let fixed = alg.mass_matrix.mass_matrix(&c.p, &c.q);
            let block: Vec<Vec<f64>> = a[6..].iter().map(|r| r[6..].to_vec()).collect();
            let e = rel_mat(&block, &fixed);
            assert!(e < 1e-12, "n={n} {alg}: {e:e}");
        }
    }
}

#[test]
fn base_wrench_and_gravity_enter_the_base_rows() {
    // At rest, no arm velocity: b_base = [R₀ᵀ(F + M g); R₀ᵀ(moment about p₀)].
    let c = random_case(5, 42, 0.0, false);
    let mut r = rng(9);
    let f = v3(&random_vec(&mut r, 3, 10.0));
    let m = v3(&random_vec(&mut r, 3, 10.0));
    let state = FloatingState {
        v_b: Vec3::zero(),
        omega_b: Vec3::zero(),
        ..c.state.clone()
    };
    let loads = Loads {
        external: vec![ExternalWrench {
            body: BASE_BODY,
            frame: LoadFrame::Base,
            force: f.clone(),
            moment: m.clone(),
        }],
        ..Loads::default()
    };
    let zeros = vec![0.0; 5];
    for alg in ALGS {
        let d = floating::dynamics(alg, &c.p, &c.base, &state, &c.q, &zeros, &loads);
        let fb = state.rotation.tr_mul_vec(&f);
        let mb = state.rotation.tr_mul_vec(&m);
        let want: Vec<f64> = fb.0.iter().chain(mb.0.iter()).copied().collect();
        let e = rel_vec(&d.b[..6], &want);
        assert!(e < 1e-12, "{alg}: {e:e}");
        assert!(d.b[6..].iter().all(|x| x.abs() < 1e-12), "{alg}: arm rows");
    }
}

// ---------------------------------------------------------------------------------------------
// 3. Energy, momentum, conservation.
// ---------------------------------------------------------------------------------------------

#[test]
fn kinetic_energy_and_momentum_from_a() {
    let (mut worst_t, mut worst_p) = (0.0_f64, 0.0_f64);
    for n in 1..=12 {
        let c = random_case(n, 500 + n as u64, 0.3, false);
        let v = nu(&c.state, &c.qd);
        let t = kinetic_energy(&c.p, &c.base, &c.state, &c.q, &c.qd);
        let (lin, ang) = momentum(&c.p, &c.base, &c.state, &c.q, &c.qd);
        // The spatial sums (any tree) against the body-by-body sums of the virtual-joint
        // extension (chains).
        let t_bodies = kinetic_energy_by_bodies(&c.p, &c.base, &c.state, &c.q, &c.qd);
        let (lin_b, ang_b) = momentum_by_bodies(&c.p, &c.base, &c.state, &c.q, &c.qd);
        assert!(
            (t - t_bodies).abs() < 1e-12 * t,
            "n={n}: T {t} vs {t_bodies}"
        );
        let pl: Vec<f64> = lin.0.iter().chain(ang.0.iter()).copied().collect();
        let pb: Vec<f64> = lin_b.0.iter().chain(ang_b.0.iter()).copied().collect();
        assert!(
            rel_vec(&pl, &pb) < 1e-12,
            "n={n}: momentum {pl:?} vs {pb:?}"
        );
        // Momentum about the base origin, base coordinates.
        let lin_b = c.state.rotation.tr_mul_vec(&lin);
        let ang_o = &ang - &c.state.position.cross(&lin);
        let ang_b = c.state.rotation.tr_mul_vec(&ang_o);
        let want: Vec<f64> = lin_b.0.iter().chain(ang_b.0.iter()).copied().collect();
        for alg in ALGS {
            let (a, _) = dynamics(alg, &c);
            let av = mat_vec(&a, &v);
            let ta = 0.5 * v.iter().zip(&av).map(|(x, y)| x * y).sum::<f64>();
            let et = (ta - t).abs() / t;
            let ep = rel_vec(&av[..6], &want);
            worst_t = worst_t.max(et);
            worst_p = worst_p.max(ep);
            assert!(et < 1e-12, "n={n} {alg}: T {et:e}");
            assert!(ep < 1e-12, "n={n} {alg}: momentum {ep:e}");
        }
    }
    println!("½νᵀAν vs Σ T_k: {worst_t:.2e}; A_b ν vs momentum: {worst_p:.2e}");
}

/// Integration state: p₀, quaternion [x, y, z, w], q, ν.
#[derive(Clone)]
struct Y {
    p0: [f64; 3],
    quat: [f64; 4],
    q: Vec<f64>,
    nu: Vec<f64>,
}

fn state_of(y: &Y) -> FloatingState<f64> {
    FloatingState {
        position: v3(&y.p0),
        rotation: quat_to_matrix(&y.quat),
        v_b: v3(&y.nu[0..3]),
        omega_b: v3(&y.nu[3..6]),
    }
}

fn deriv(alg: Methods, c: &Case, y: &Y) -> Y {
    let s = state_of(y);
    let n = y.q.len();
    let qd = &y.nu[6..];
    let p0d = s.rotation.mul_vec(&s.v_b).0;
    // q̇uat = ½ quat ⊗ (ω_b, 0): u̇ = ½(w ω + u × ω), ẇ = −½ u·ω.
    let u = v3(&y.quat[..3]);
    let w = y.quat[3];
    let om = &s.omega_b;
    let ud = (om.scale(&w) + u.cross(om)).scale(&0.5);
    let wd = -0.5 * u.dot(om);
    let nud = floating::forward_dynamics(alg, &c.p, &c.base, &s, &y.q, qd, &c.loads);
    assert_eq!(nud.len(), 6 + n);
    Y {
        p0: p0d,
        quat: [ud.at(0), ud.at(1), ud.at(2), wd],
        q: qd.to_vec(),
        nu: nud,
    }
}

fn axpy(y: &Y, h: f64, d: &Y) -> Y {
    let add =
        |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, v)| x + h * v).collect() };
    Y {
        p0: add(&y.p0, &d.p0).try_into().unwrap(),
        quat: add(&y.quat, &d.quat).try_into().unwrap(),
        q: add(&y.q, &d.q),
        nu: add(&y.nu, &d.nu),
    }
}

fn rk4(alg: Methods, c: &Case, y: &Y, h: f64) -> Y {
    let k1 = deriv(alg, c, y);
    let k2 = deriv(alg, c, &axpy(y, h / 2.0, &k1));
    let k3 = deriv(alg, c, &axpy(y, h / 2.0, &k2));
    let k4 = deriv(alg, c, &axpy(y, h, &k3));
    let mut out = y.clone();
    for (k, wgt) in [(k1, 1.0), (k2, 2.0), (k3, 2.0), (k4, 1.0)] {
        out = axpy(&out, h * wgt / 6.0, &k);
    }
    let norm = out.quat.iter().map(|x| x * x).sum::<f64>().sqrt();
    out.quat = out.quat.map(|x| x / norm);
    out
}

fn random_quat(r: &mut ChaCha8Rng) -> [f64; 4] {
    let v = random_vec(r, 4, 1.0);
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    [v[0] / n, v[1] / n, v[2] / n, v[3] / n]
}

#[test]
fn quat_to_matrix_is_a_rotation_and_matches_axis_angle() {
    // 90° about z: quat (0, 0, sin 45°, cos 45°) maps x to y.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let r = quat_to_matrix(&[0.0, 0.0, h, h]);
    let y = r.mul_vec(&Vec3::new(1.0, 0.0, 0.0));
    assert!((y.at(0)).abs() < 1e-15 && (y.at(1) - 1.0).abs() < 1e-15);
    let mut g = rng(3);
    for _ in 0..10 {
        let r = quat_to_matrix(&random_quat(&mut g));
        let rtr = r.transpose().mul_mat(&r);
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((rtr.at(i, j) - want).abs() < 1e-14);
            }
        }
    }
}

#[test]
fn momentum_is_conserved_under_integration() {
    let mut worst = (0.0_f64, 0.0_f64, 0.0_f64);
    for (k, n) in (3..=7).enumerate() {
        for driven in [false, true] {
            let mut c = random_case(n, 900 + n as u64, 0.2, false);
            let mut r = rng(77 + n as u64);
            if driven {
                c.loads.tau = Some(random_vec(&mut r, n, 5.0));
            }
            let alg = ALGS[k % ALGS.len()];
            let mut y = Y {
                p0: random_vec(&mut r, 3, 1.0).try_into().unwrap(),
                quat: random_quat(&mut r),
                q: c.q.clone(),
                nu: {
                    let mut v = random_vec(&mut r, 6, 0.3);
                    v.extend(random_vec(&mut r, n, 0.5));
                    v
                },
            };
            let measure = |y: &Y| {
                let s = state_of(y);
                let (l, a) = momentum(&c.p, &c.base, &s, &y.q, &y.nu[6..]);
                let t = kinetic_energy(&c.p, &c.base, &s, &y.q, &y.nu[6..]);
                (l, a, t)
            };
            let (l0, a0, t0) = measure(&y);
            let (mut dl, mut da, mut dt) = (0.0_f64, 0.0_f64, 0.0_f64);
            let h = 1e-3;
            for _ in 0..2000 {
                y = rk4(alg, &c, &y, h);
                let (l, a, t) = measure(&y);
                let ln = l0.dot(&l0).sqrt();
                let an = a0.dot(&a0).sqrt();
                let dlv = &l - &l0;
                let dav = &a - &a0;
                dl = dl.max(dlv.dot(&dlv).sqrt() / ln);
                da = da.max(dav.dot(&dav).sqrt() / an);
                dt = dt.max((t - t0).abs() / t0);
            }
            // The arm actually moved.
            let moved = y.q.iter().zip(&c.q).any(|(a, b)| (a - b).abs() > 0.1);
            assert!(moved, "n={n}: the arm did not move");
            println!(
                "n={n} {alg:13} tau={driven}: drift P {dl:.2e}, L {da:.2e}, T {dt:.2e} (T0 {t0:.3})"
            );
            assert!(dl < 1e-9, "n={n} {alg}: linear momentum drift {dl:e}");
            assert!(da < 1e-9, "n={n} {alg}: angular momentum drift {da:e}");
            worst.0 = worst.0.max(dl);
            worst.1 = worst.1.max(da);
            if !driven {
                assert!(dt < 1e-9, "n={n} {alg}: energy drift {dt:e}");
                worst.2 = worst.2.max(dt);
            }
        }
    }
    println!(
        "worst drift over 2 s: P {:.2e}, L {:.2e}, T (τ = 0) {:.2e}",
        worst.0, worst.1, worst.2
    );
}

// ---------------------------------------------------------------------------------------------
// 4. Generalized Jacobian.
// ---------------------------------------------------------------------------------------------

#[test]
fn generalized_jacobian_gives_the_end_effector_motion_at_zero_momentum() {
    let mut worst = 0.0_f64;
    for n in 1..=10 {
        let c = random_case(n, 1300 + n as u64, 0.3, false);
        let mut r = rng(n as u64);
        let point = v3(&random_vec(&mut r, 3, 0.5));
        let (a, _) = dynamics(Methods::RECURRENT, &c);
        // Zero momentum: ν_b = −A_bb⁻¹ A_bm q̇.
        let a_bb: Vec<Vec<f64>> = a[..6].iter().map(|row| row[..6].to_vec()).collect();
        let rhs: Vec<f64> = (0..6)
            .map(|i| -(0..n).map(|j| a[i][6 + j] * c.qd[j]).sum::<f64>())
            .collect();
        let nub = solve(&ldlt(&a_bb), &rhs);
        let state = FloatingState {
            v_b: v3(&nub[..3]),
            omega_b: v3(&nub[3..]),
            ..c.state.clone()
        };
        let (lin, ang) = momentum(&c.p, &c.base, &state, &c.q, &c.qd);
        let scale = c.qd.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(
            lin.dot(&lin).sqrt() < 1e-10 * scale * 1e3,
            "n={n}: momentum not zero"
        );
        assert!(
            ang.dot(&ang).sqrt() < 1e-10 * scale * 1e4,
            "n={n}: momentum not zero"
        );
        // End-effector velocity from the body motion recursion.
        let kin = floating_base_frame(&c.p, &c.base, &state, &c.q);
        let mot = floating_motion(&kin, &state, &c.qd);
        let (kl, ml) = (kin.last().unwrap(), mot.last().unwrap());
        let ve = &ml.v + &ml.omega.cross(&kl.orientation.mul_vec(&point));
        let want: Vec<f64> = ve.0.iter().chain(ml.omega.0.iter()).copied().collect();
        let frame = FrameParams {
            parent: Some(n - 1),
            translation: point.clone(),
            rotation: Mat3(random_rotation(&mut r)),
        };
        let j = generalized_jacobian(&c.p, &c.base, &c.state, &c.q, &frame);
        assert_eq!((j.len(), j[0].len()), (6, n));
        let got = mat_vec(&j, &c.qd);
        let e = rel_vec(&got, &want);
        worst = worst.max(e);
        assert!(e < 1e-10, "n={n}: {e:e}");
    }
    println!("J* q̇ vs end-effector motion at zero momentum: {worst:.2e}");
}

// ---------------------------------------------------------------------------------------------
// Gravity, and tracing on `Sym`.
// ---------------------------------------------------------------------------------------------

#[test]
fn uniform_gravity_is_a_base_acceleration() {
    // A uniform field g is indistinguishable from accelerating the base by g: the generalized
    // gravity force is b(g) − b(0) = A[:, 0..3] R₀ᵀ g in every state, so at rest
    // ν̇ = [R₀ᵀ g; 0; 0].
    for n in [1, 3, 8] {
        let c = random_case(n, 2000 + n as u64, 0.3, false);
        let g = Vec3::new(0.3, -1.2, -9.81);
        let with_g = Loads {
            gravity: Some(g.clone()),
            ..Loads::default()
        };
        let gb = c.state.rotation.tr_mul_vec(&g);
        for alg in ALGS {
            let d0 = floating::dynamics(alg, &c.p, &c.base, &c.state, &c.q, &c.qd, &c.loads);
            let d1 = floating::dynamics(alg, &c.p, &c.base, &c.state, &c.q, &c.qd, &with_g);
            let diff: Vec<f64> = d1.b.iter().zip(&d0.b).map(|(x, y)| x - y).collect();
            let want: Vec<f64> =
                d0.a.iter()
                    .map(|row| (0..3).map(|m| row[m] * gb.at(m)).sum())
                    .collect();
            let e = rel_vec(&diff, &want);
            assert!(e < 1e-12, "n={n} {alg}: {e:e}");
            let rest = FloatingState {
                v_b: Vec3::zero(),
                omega_b: Vec3::zero(),
                ..c.state.clone()
            };
            let zeros = vec![0.0; n];
            let acc = floating::forward_dynamics(alg, &c.p, &c.base, &rest, &c.q, &zeros, &with_g);
            let mut want = gb.0.to_vec();
            want.extend(vec![0.0; 3 + n]);
            let e = acc
                .iter()
                .zip(&want)
                .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(e < 1e-11, "n={n} {alg}: at rest {e:e}");
        }
    }
}

#[test]
fn floating_dynamics_traces_on_sym() {
    use kanegen_dynamics::Scalar;
    use kanegen_trace::sym::{record as trace, Convention, Sym};
    let n = 6;
    let c = random_case(n, 31, 0.0, true);
    let (a_num, b_num) = dynamics(Methods::RECURRENT, &c);
    for alg in ALGS {
        let mut inputs: Vec<f64> = Vec::new();
        let t = trace(|t| {
            let mut inp = |name: String, x: f64| {
                inputs.push(x);
                t.input(name)
            };
            let q: Vec<Sym> = (0..n).map(|i| inp(format!("q{i}"), c.q[i])).collect();
            let qd: Vec<Sym> = (0..n).map(|i| inp(format!("qd{i}"), c.qd[i])).collect();
            let vec_in = |name: &str, v: &Vec3<f64>, inp: &mut dyn FnMut(String, f64) -> Sym| {
                Vec3(core::array::from_fn(|i| inp(format!("{name}{i}"), v.at(i))))
            };
            let position = vec_in("p", &c.state.position, &mut inp);
            let v_b = vec_in("v", &c.state.v_b, &mut inp);
            let omega_b = vec_in("w", &c.state.omega_b, &mut inp);
            let rotation = Mat3(core::array::from_fn(|r| {
                core::array::from_fn(|k| inp(format!("R{r}{k}"), c.state.rotation.at(r, k)))
            }));
            let state = FloatingState {
                position,
                rotation,
                v_b,
                omega_b,
            };
            let base = FloatingBase::new(
                Sym::constant(c.base.mass),
                Vec3(c.base.com.0.map(Sym::constant)),
                Mat3(c.base.inertia_com.0.map(|r| r.map(Sym::constant))),
            );
            let p = Params {
                joints: c
                    .p
                    .joints
                    .iter()
                    .map(|j| {
                        let mass = Sym::constant(j.mass);
                        let com = Vec3(j.com.0.map(Sym::constant));
                        let inertia_com = Mat3(j.inertia_com.0.map(|r| r.map(Sym::constant)));
                        kanegen_dynamics::JointParams {
                            kind: j.kind,
                            parent: j.parent,
                            l: Vec3(j.l.0.map(Sym::constant)),
                            upsilon: Mat3(j.upsilon.0.map(|r| r.map(Sym::constant))),
                            axis: Vec3(j.axis.0.map(Sym::constant)),
                            coordinate_axis: j.coordinate_axis,
                            placement_permutation: j.placement_permutation,
                            placement_turn: j
                                .placement_turn
                                .map(|(k, s, c)| (k, Sym::constant(s), Sym::constant(c))),
                            angle_offset: j.angle_offset.map(Sym::constant),
                            inertia: kanegen_dynamics::spatial::RbInertia::from_com(
                                &mass,
                                &com,
                                &inertia_com,
                            ),
                            mass,
                            com,
                            inertia_com,
                        }
                    })
                    .collect(),
                frames: Vec::new(),
            };
            let loads = Loads {
                tau: c
                    .loads
                    .tau
                    .as_ref()
                    .map(|t| t.iter().map(|x| Sym::constant(*x)).collect()),
                gravity: c
                    .loads
                    .gravity
                    .as_ref()
                    .map(|g| Vec3(g.0.map(Sym::constant))),
                external: c
                    .loads
                    .external
                    .iter()
                    .map(|e| ExternalWrench {
                        body: e.body,
                        frame: e.frame,
                        force: Vec3(e.force.0.map(Sym::constant)),
                        moment: Vec3(e.moment.0.map(Sym::constant)),
                    })
                    .collect(),
            };
            let d = floating::dynamics(alg, &p, &base, &state, &q, &qd, &loads);
            d.a.into_iter().flatten().chain(d.b).collect()
        });
        let out = t.eval(&inputs);
        let m = 6 + n;
        let a: Vec<Vec<f64>> = (0..m).map(|i| out[i * m..(i + 1) * m].to_vec()).collect();
        let b = &out[m * m..];
        assert!(
            rel_mat(&a, &a_num) < 1e-12 && rel_vec(b, &b_num) < 1e-12,
            "{alg}"
        );
        let k = t.counts(Convention::ALL[1]);
        println!(
            "N = {n} floating, {alg:13}: {} m + {} a ({})",
            k.mul,
            k.add,
            Convention::ALL[1].name()
        );
    }
}

#[test]
fn wrench_on_the_last_body_is_its_jacobian_transpose() {
    // Virtual power: a wrench (f at a point of the last body, moment m), inertial frame, adds
    // Jᵀ [f; m] to b, J the point's (6+N)-column Jacobian.
    for n in [1, 2, 5, 9] {
        let c = random_case(n, 3000 + n as u64, 0.3, false);
        let mut r = rng(n as u64 + 11);
        let f = v3(&random_vec(&mut r, 3, 10.0));
        let m = v3(&random_vec(&mut r, 3, 10.0));
        // Force at O_last (point 0).
        let origin = FrameParams {
            parent: Some(n - 1),
            translation: Vec3::zero(),
            rotation: Mat3::identity(),
        };
        let j = floating_jacobian(&c.p, &c.state, &c.q, &origin);
        let w: Vec<f64> = f.0.iter().chain(m.0.iter()).copied().collect();
        let want: Vec<f64> = (0..6 + n)
            .map(|col| (0..6).map(|row| j[row][col] * w[row]).sum())
            .collect();
        let loads = Loads {
            external: vec![ExternalWrench {
                body: n - 1,
                frame: LoadFrame::Base,
                force: f.clone(),
                moment: m.clone(),
            }],
            ..Loads::default()
        };
        for alg in ALGS {
            let d0 = floating::dynamics(alg, &c.p, &c.base, &c.state, &c.q, &c.qd, &c.loads);
            let d1 = floating::dynamics(alg, &c.p, &c.base, &c.state, &c.q, &c.qd, &loads);
            let diff: Vec<f64> = d1.b.iter().zip(&d0.b).map(|(x, y)| x - y).collect();
            let e = rel_vec(&diff, &want);
            assert!(e < 1e-11, "n={n} {alg}: {e:e}");
        }
    }
}
