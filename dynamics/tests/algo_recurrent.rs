//! Tests of the recurrent algorithm (variants R1, R2, P) and the base-frame CRBA against oracles
//! written here, independent of the recursions:
//! - poses of every body composed directly from the model with nalgebra (checks eq. (1), (2), (6));
//! - velocities (3) against central differences of those poses;
//! - `A` from the kinetic energy by polarization, `T(q̇) = ½ q̇ᵀ A q̇`;
//! - `b` from Lagrange's equations by central differences, gravity from the potential, external
//!   wrenches from virtual work.

use kanegen_dynamics::algorithms::crba_base;
use kanegen_dynamics::algorithms::kinematics::{base_frame, motion};
use kanegen_dynamics::algorithms::recurrent::{self, Variant};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::metrics::rel_err_mat as rel_err;
use kanegen_dynamics::Params;
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads, Methods};
use kanegen_model::random::{random_chain, random_vec, rng, ChainSpec};
use kanegen_model::{JointKind, Model};
use nalgebra::{DMatrix, Matrix3, Vector3};

type Mat = Vec<Vec<f64>>;

/// max |x − y| / max(max |y|, 1): `b` vanishes identically for some chains (one body, no loads),
/// where a purely relative error would compare rounding noise; typical entries here are 10–1000.
fn rel_err_vec(x: &[f64], y: &[f64]) -> f64 {
    let num = x
        .iter()
        .zip(y)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let den = y.iter().fold(1.0f64, |m, b| m.max(b.abs()));
    assert_eq!(x.len(), y.len());
    num / den
}

fn chain(n: usize, prismatic_fraction: f64, seed: u64) -> Model {
    random_chain(
        &ChainSpec {
            n,
            prismatic_fraction,
            ..Default::default()
        },
        seed,
    )
}

fn state(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut g = rng(seed ^ 0x5eed);
    (random_vec(&mut g, n, 2.0), random_vec(&mut g, n, 1.5))
}

fn v3(x: [f64; 3]) -> Vector3<f64> {
    Vector3::from(x)
}

fn m3(x: [[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| x[r][c])
}

/// Body-frame poses `(R_j, O_j)` in the base frame, composed from the model with nalgebra:
/// `X_j = X_{j−1} · origin_j · joint_j(q_j)`.
fn poses(ch: &Model, q: &[f64]) -> Vec<(Matrix3<f64>, Vector3<f64>)> {
    let mut rot = Matrix3::identity();
    let mut pos = Vector3::zeros();
    ch.joints()
        .iter()
        .zip(q)
        .map(|(j, &qj)| {
            pos += rot * v3(j.origin.translation);
            rot *= m3(j.origin.rotation);
            let axis = nalgebra::Unit::new_normalize(v3(j.axis));
            match j.kind {
                JointKind::Revolute => {
                    rot *= *nalgebra::Rotation3::from_axis_angle(&axis, qj).matrix();
                }
                JointKind::Prismatic => pos += rot * axis.into_inner() * qj,
            }
            (rot, pos)
        })
        .collect()
}

/// Joint axes in the base frame, from the model.
fn axes(ch: &Model, q: &[f64]) -> Vec<Vector3<f64>> {
    let ps = poses(ch, q);
    ch.joints()
        .iter()
        .zip(&ps)
        .map(|(j, (rot, _))| {
            // The axis is fixed in the joint frame, which equals the body frame up to the joint
            // rotation about that same axis: R_j axis = R_joint axis.
            rot * v3(j.axis).normalize()
        })
        .collect()
}

/// Kinetic energy `Σ ½ m v·v + v·(ω × c) + ½ ω·I ω` with `v, ω` from eq. (3).
fn kinetic_energy(ch: &Model, q: &[f64], qd: &[f64]) -> f64 {
    let p = Params::<f64>::new(ch);
    let kin = base_frame(&p, q);
    let mot = motion(&kin, qd);
    kin.iter()
        .zip(&mot)
        .map(|(k, m)| {
            0.5 * k.m * m.v.dot(&m.v)
                + m.v.dot(&m.omega.cross(&k.c))
                + 0.5 * m.omega.dot(&k.inertia.mul_vec(&m.omega))
        })
        .sum()
}

/// `A` from the kinetic energy: `A_kk = 2 T(e_k)`, `A_kl = T(e_k + e_l) − T(e_k) − T(e_l)`.
fn a_oracle(ch: &Model, q: &[f64]) -> Mat {
    let n = ch.dof();
    let e = |ks: &[usize]| {
        let mut v = vec![0.0; n];
        for &k in ks {
            v[k] = 1.0;
        }
        v
    };
    let t1: Vec<f64> = (0..n).map(|k| kinetic_energy(ch, q, &e(&[k]))).collect();
    let mut a = vec![vec![0.0; n]; n];
    for k in 0..n {
        a[k][k] = 2.0 * t1[k];
        for l in k + 1..n {
            let x = kinetic_energy(ch, q, &e(&[k, l])) - t1[k] - t1[l];
            a[k][l] = x;
            a[l][k] = x;
        }
    }
    a
}

fn all_mass_matrices(ch: &Model, q: &[f64]) -> Vec<(&'static str, Mat)> {
    let p = Params::<f64>::new(ch);
    vec![
        ("R2", recurrent::mass_matrix(&p, q, Variant::R2)),
        ("R1", recurrent::mass_matrix(&p, q, Variant::R1)),
        ("crba-base", crba_base::mass_matrix(&p, q)),
        (
            "dispatch recurrent",
            Methods::RECURRENT.mass_matrix.mass_matrix(&p, q),
        ),
        (
            "dispatch recurrent-r1",
            Methods::RECURRENT_R1.mass_matrix.mass_matrix(&p, q),
        ),
        (
            "dispatch crba-base",
            Methods::CRBA_BASE.mass_matrix.mass_matrix(&p, q),
        ),
    ]
}

const SEEDS: std::ops::Range<u64> = 0..6;

#[test]
fn base_frame_matches_poses_composed_with_nalgebra() {
    let mut worst: f64 = 0.0;
    for n in 1..=8 {
        for seed in SEEDS {
            let ch = chain(n, 0.3, seed);
            let (q, _) = state(n, seed);
            let kin = base_frame(&Params::<f64>::new(&ch), &q);
            let ps = poses(&ch, &q);
            let ax = axes(&ch, &q);
            let mut o_prev = Vector3::zeros();
            for (j, (k, (rot, pos))) in kin.iter().zip(&ps).enumerate() {
                let b = &ch.joints()[j].inertial;
                let d = v3(b.com);
                let c = rot * d * b.mass;
                let i_o = rot
                    * (m3(b.inertia)
                        + b.mass * (d.dot(&d) * Matrix3::identity() - d * d.transpose()))
                    * rot.transpose();
                for r in 0..3 {
                    worst = worst.max((k.r.at(r) - (pos - o_prev)[r]).abs());
                    worst = worst.max((k.axis.at(r) - ax[j][r]).abs());
                    worst = worst.max((k.c.at(r) - c[r]).abs() / b.mass);
                    for s in 0..3 {
                        worst = worst.max((k.orientation.at(r, s) - rot[(r, s)]).abs());
                        worst = worst.max((k.inertia.at(r, s) - i_o[(r, s)]).abs() / b.mass);
                    }
                }
                o_prev = *pos;
            }
        }
    }
    println!("base_frame vs nalgebra poses: max abs err {worst:.2e}");
    assert!(
        worst < 1e-12,
        "base_frame disagrees with composed poses: {worst:e}"
    );
}

#[test]
fn motion_velocities_match_pose_differences() {
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for n in 1..=8 {
        for seed in SEEDS {
            let ch = chain(n, 0.3, seed);
            let (q, qd) = state(n, seed);
            let kin = base_frame(&Params::<f64>::new(&ch), &q);
            let mot = motion(&kin, &qd);
            let qp: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + h * b).collect();
            let qm: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a - h * b).collect();
            let (pp, pm, p0) = (poses(&ch, &qp), poses(&ch, &qm), poses(&ch, &q));
            for j in 0..n {
                let v = (pp[j].1 - pm[j].1) / (2.0 * h);
                let w = (pp[j].0 - pm[j].0) / (2.0 * h) * p0[j].0.transpose();
                let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
                for r in 0..3 {
                    worst = worst.max((mot[j].v.at(r) - v[r]).abs());
                    worst = worst.max((mot[j].omega.at(r) - omega[r]).abs());
                }
            }
        }
    }
    println!("motion vs pose differences: max abs err {worst:.2e}");
    assert!(
        worst < 1e-7,
        "motion (3) disagrees with pose differences: {worst:e}"
    );
}

#[test]
fn mass_matrices_agree_with_kinetic_energy_oracle() {
    let mut worst: f64 = 0.0;
    let mut prismatic_seen = 0;
    for fraction in [0.0, 0.3, 1.0] {
        for n in 1..=12 {
            for seed in SEEDS {
                let ch = chain(n, fraction, seed + 100 * n as u64);
                prismatic_seen += ch
                    .joints()
                    .iter()
                    .filter(|j| j.kind == JointKind::Prismatic)
                    .count();
                let (q, _) = state(n, seed);
                let oracle = a_oracle(&ch, &q);
                let results = all_mass_matrices(&ch, &q);
                for (name, a) in &results {
                    let e = rel_err(a, &oracle);
                    worst = worst.max(e);
                    assert!(
                        e < 1e-12,
                        "{name}: N = {n}, fraction {fraction}, seed {seed}: rel err {e:e}"
                    );
                    for (i, row) in a.iter().enumerate() {
                        for (j, x) in row.iter().enumerate() {
                            assert_eq!(*x, a[j][i], "{name}: not symmetric");
                        }
                    }
                }
                // And with each other.
                for (name, a) in &results[1..] {
                    let e = rel_err(a, &results[0].1);
                    assert!(e < 1e-12, "{name} vs R2: N = {n}: rel err {e:e}");
                }
            }
        }
    }
    assert!(prismatic_seen > 100, "too few prismatic joints exercised");
    println!("A vs kinetic-energy oracle (R1, R2, crba-base): max rel err {worst:.2e}");
}

#[test]
fn mass_matrix_is_positive_definite() {
    for n in 1..=12 {
        for seed in SEEDS {
            let ch = chain(n, 0.3, seed);
            let (q, _) = state(n, seed);
            for (name, a) in all_mass_matrices(&ch, &q) {
                let m = DMatrix::from_fn(n, n, |i, j| a[i][j]);
                assert!(
                    m.cholesky().is_some(),
                    "{name}: A not SPD, N = {n}, seed {seed}"
                );
            }
        }
    }
}

/// `b` with zero loads from Lagrange: `b = ∂T/∂q − Ȧ q̇`, by central differences of the oracle.
fn b_lagrange(ch: &Model, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let n = q.len();
    let h = 1e-5;
    let shift =
        |dir: &[f64], s: f64| -> Vec<f64> { q.iter().zip(dir).map(|(a, d)| a + s * d).collect() };
    let (ap, am) = (a_oracle(ch, &shift(qd, h)), a_oracle(ch, &shift(qd, -h)));
    (0..n)
        .map(|k| {
            let mut ek = vec![0.0; n];
            ek[k] = 1.0;
            let dt_dq = (kinetic_energy(ch, &shift(&ek, h), qd)
                - kinetic_energy(ch, &shift(&ek, -h), qd))
                / (2.0 * h);
            let adot_qd: f64 = (0..n)
                .map(|l| (ap[k][l] - am[k][l]) / (2.0 * h) * qd[l])
                .sum();
            dt_dq - adot_qd
        })
        .collect()
}

fn all_biases(
    ch: &Model,
    q: &[f64],
    qd: &[f64],
    loads: &Loads<f64>,
) -> Vec<(&'static str, Vec<f64>)> {
    let p = Params::<f64>::new(ch);
    vec![
        ("recurrent", recurrent::bias(&p, q, qd, loads)),
        ("crba-base", crba_base::bias(&p, q, qd, loads)),
        (
            "dispatch recurrent-r1",
            Methods::RECURRENT_R1.bias.bias(&p, q, qd, loads),
        ),
    ]
}

#[test]
fn bias_matches_lagrange_finite_differences() {
    let mut worst: f64 = 0.0;
    for n in 1..=8 {
        for seed in 0..3 {
            let ch = chain(n, 0.3, seed + 7);
            let (q, qd) = state(n, seed);
            let expected = b_lagrange(&ch, &q, &qd);
            for (name, b) in all_biases(&ch, &q, &qd, &Loads::default()) {
                let e = rel_err_vec(&b, &expected);
                worst = worst.max(e);
                assert!(e < 1e-6, "{name}: N = {n}, seed {seed}: rel err {e:e}");
            }
        }
    }
    println!("b vs Lagrange central differences: max rel err {worst:.2e}");
}

/// Generalized force of gravity `−∂V/∂q`, `V = −Σ m_k g·p_com,k`, by central differences of the
/// nalgebra poses.
fn gravity_force(ch: &Model, q: &[f64], g: Vector3<f64>) -> Vec<f64> {
    let v = |q: &[f64]| -> f64 {
        poses(ch, q)
            .iter()
            .zip(ch.joints())
            .map(|((rot, pos), j)| -j.inertial.mass * g.dot(&(pos + rot * v3(j.inertial.com))))
            .sum()
    };
    let h = 1e-5;
    (0..q.len())
        .map(|k| {
            let mut qp = q.to_vec();
            let mut qm = q.to_vec();
            qp[k] += h;
            qm[k] -= h;
            -(v(&qp) - v(&qm)) / (2.0 * h)
        })
        .collect()
}

/// Generalized force of a wrench (force at `O_j`, moment) in the base frame, by virtual work with
/// the partial velocities from central differences of the nalgebra poses.
fn wrench_force(ch: &Model, q: &[f64], body: usize, f: Vector3<f64>, m: Vector3<f64>) -> Vec<f64> {
    let h = 1e-6;
    let p0 = poses(ch, q);
    (0..q.len())
        .map(|k| {
            let mut qp = q.to_vec();
            let mut qm = q.to_vec();
            qp[k] += h;
            qm[k] -= h;
            let (pp, pm) = (poses(ch, &qp), poses(ch, &qm));
            let v = (pp[body].1 - pm[body].1) / (2.0 * h);
            let w = (pp[body].0 - pm[body].0) / (2.0 * h) * p0[body].0.transpose();
            let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
            f.dot(&v) + m.dot(&omega)
        })
        .collect()
}

#[test]
fn gravity_external_wrenches_and_drives_enter_b_correctly() {
    let g = Vector3::new(0.4, -9.81, 1.3);
    for n in 1..=8 {
        for seed in 0..4 {
            let ch = chain(n, 0.3, seed + 31);
            let (q, qd) = state(n, seed);
            let mut gen = rng(seed + 1000);
            let zero = vec![0.0; n];

            // Static configuration with gravity: b = −∂V/∂q.
            let loads = Loads {
                gravity: Some(Vec3::new(g.x, g.y, g.z)),
                ..Default::default()
            };
            let expected = gravity_force(&ch, &q, g);
            for (name, b) in all_biases(&ch, &q, &zero, &loads) {
                let e = rel_err_vec(&b, &expected);
                assert!(
                    e < 1e-7,
                    "{name} gravity: N = {n}, seed {seed}: rel err {e:e}"
                );
            }

            // External wrenches in the body frame and in the base frame: virtual work.
            let body = (seed as usize) % n;
            let fl = random_vec(&mut gen, 3, 20.0);
            let ml = random_vec(&mut gen, 3, 5.0);
            let rot = poses(&ch, &q)[body].0;
            let (f_base, m_base) = (
                rot * v3([fl[0], fl[1], fl[2]]),
                rot * v3([ml[0], ml[1], ml[2]]),
            );
            let fb = random_vec(&mut gen, 3, 20.0);
            let mb = random_vec(&mut gen, 3, 5.0);
            let other = n - 1 - body;
            let ext = vec![
                ExternalWrench {
                    body,
                    frame: LoadFrame::Body,
                    force: Vec3::new(fl[0], fl[1], fl[2]),
                    moment: Vec3::new(ml[0], ml[1], ml[2]),
                },
                ExternalWrench {
                    body: other,
                    frame: LoadFrame::Base,
                    force: Vec3::new(fb[0], fb[1], fb[2]),
                    moment: Vec3::new(mb[0], mb[1], mb[2]),
                },
            ];
            let w1 = wrench_force(&ch, &q, body, f_base, m_base);
            let w2 = wrench_force(
                &ch,
                &q,
                other,
                v3([fb[0], fb[1], fb[2]]),
                v3([mb[0], mb[1], mb[2]]),
            );
            let expected: Vec<f64> = w1.iter().zip(&w2).map(|(a, b)| a + b).collect();
            let loads = Loads {
                external: ext.clone(),
                ..Default::default()
            };
            for (name, b) in all_biases(&ch, &q, &zero, &loads) {
                let e = rel_err_vec(&b, &expected);
                assert!(
                    e < 1e-7,
                    "{name} wrench: N = {n}, seed {seed}: rel err {e:e}"
                );
            }

            // Everything together, with velocities and drives: the effects add up.
            let tau = random_vec(&mut gen, n, 10.0);
            let all = Loads {
                tau: Some(tau.clone()),
                gravity: Some(Vec3::new(g.x, g.y, g.z)),
                external: ext,
            };
            let p = Params::<f64>::new(&ch);
            let b_vel = recurrent::bias(&p, &q, &qd, &Loads::default());
            let b_grav = gravity_force(&ch, &q, g);
            let expected: Vec<f64> = (0..n)
                .map(|k| b_vel[k] + b_grav[k] + w1[k] + w2[k] + tau[k])
                .collect();
            for (name, b) in all_biases(&ch, &q, &qd, &all) {
                let e = rel_err_vec(&b, &expected);
                assert!(
                    e < 1e-7,
                    "{name} all loads: N = {n}, seed {seed}: rel err {e:e}"
                );
            }
        }
    }
}

/// A scalar that counts operations in the paper's convention (every `+ − × ÷` counts, sign
/// changes and constants are free), per section label.
mod count {
    use kanegen_dynamics::scalar::Scalar;
    use std::cell::RefCell;
    use std::collections::BTreeMap;

    thread_local! {
        static SECTION: RefCell<&'static str> = const { RefCell::new("") };
        static COUNTS: RefCell<BTreeMap<&'static str, (u64, u64)>> = const { RefCell::new(BTreeMap::new()) };
    }

    fn tick(mul: bool) {
        let s = SECTION.with(|s| *s.borrow());
        COUNTS.with(|c| {
            let mut c = c.borrow_mut();
            let e = c.entry(s).or_default();
            if mul {
                e.0 += 1;
            } else {
                e.1 += 1;
            }
        });
    }

    /// Resets the counters.
    pub fn reset() {
        COUNTS.with(|c| c.borrow_mut().clear());
    }

    /// (mult, add) per section since the last reset.
    pub fn take() -> BTreeMap<&'static str, (u64, u64)> {
        COUNTS.with(|c| std::mem::take(&mut *c.borrow_mut()))
    }

    #[derive(Clone, Debug)]
    pub struct C(pub f64);

    /// `C` counts operations like the tracer, so it may run the paper's (14b) bookkeeping.
    impl kanegen_dynamics::Symbolic for C {}

    impl core::ops::Add for C {
        type Output = C;
        fn add(self, o: C) -> C {
            tick(false);
            C(self.0 + o.0)
        }
    }
    impl core::ops::Sub for C {
        type Output = C;
        fn sub(self, o: C) -> C {
            tick(false);
            C(self.0 - o.0)
        }
    }
    impl core::ops::Mul for C {
        type Output = C;
        fn mul(self, o: C) -> C {
            tick(true);
            C(self.0 * o.0)
        }
    }
    impl core::ops::Div for C {
        type Output = C;
        fn div(self, o: C) -> C {
            tick(true);
            C(self.0 / o.0)
        }
    }
    impl core::ops::Neg for C {
        type Output = C;
        fn neg(self) -> C {
            C(-self.0)
        }
    }
    impl Scalar for C {
        fn constant(x: f64) -> Self {
            C(x)
        }
        fn sin(self) -> Self {
            C(self.0.sin())
        }
        fn cos(self) -> Self {
            C(self.0.cos())
        }
        fn sqrt(self) -> Self {
            C(self.0.sqrt())
        }
        fn section(label: &'static str) {
            SECTION.with(|s| *s.borrow_mut() = label);
        }
    }
}

/// Raw counts (paper convention) of `A` from base-frame inputs equal the exact polynomial fits of
/// the corrected Table 1 and its baselines (`docs/paper.md`, "Operation counts"; revolute chains).
#[test]
fn paper_convention_counts_match_the_corrected_table() {
    use count::C;
    for n in 2..=10_i64 {
        let ch = chain(n as usize, 0.0, 3);
        let (q, _) = state(n as usize, 3);
        let qc: Vec<C> = q.iter().map(|&x| C(x)).collect();
        let kin = base_frame(&Params::<C>::new(&ch), &qc);
        let total = |f: &dyn Fn() -> Vec<Vec<C>>| {
            count::reset();
            f();
            let per = count::take();
            let t = per.values().fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
            (t, per)
        };
        let n2 = n * n;
        let ((pm, pa), _) = total(&|| recurrent::mass_matrix_paper_bookkeeping(&kin));
        assert_eq!(
            (2 * pm as i64, 2 * pa as i64),
            (78 * n2 - 54 * n, 117 * n2 - 97 * n + 6),
            "P, N = {n}"
        );
        let ((rm, ra), _) = total(&|| recurrent::mass_matrix_base(&kin, Variant::R2));
        assert_eq!(
            (rm as i64, ra as i64),
            (36 * n2 - 24 * n, 60 * n2 - 53 * n + 6),
            "R2, N = {n}"
        );
        let ((cm, ca), _) = total(&|| crba_base::mass_matrix_base(&kin));
        assert_eq!(
            (2 * cm as i64, 2 * ca as i64),
            (12 * n2 + 144 * n - 114, 15 * n2 + 203 * n - 176),
            "crba-base, N = {n}"
        );
        let ((m1, a1), per) = total(&|| recurrent::mass_matrix_base(&kin, Variant::R1));
        let corr = per.get("R1-corr").copied().unwrap_or((0, 0));
        if n >= 3 {
            assert_eq!(
                (corr.0 as i64, corr.1 as i64),
                (30 * n - 60, 48 * n - 108),
                "R1-corr, N = {n}"
            );
            assert_eq!(
                (2 * m1 as i64, 2 * a1 as i64),
                (78 * n2 + 6 * n - 120, 117 * n2 - n - 210),
                "R1, N = {n}"
            );
        } else {
            assert_eq!(corr, (0, 0));
        }
    }
}
