//! Oracles for `A(q)` and `b(q, q̇, loads)` that share no code path with the algorithms' Newton–Euler
//! recursions:
//!
//! - **Lagrange**: the kinetic energy `T(q, q̇)` is computed body by body from a forward-kinematics
//!   function written here (compose placements and joint motions); velocities come from
//!   differentiating the poses along `q + t q̇` with [`Dual`] numbers. Then, all by nested duals
//!   (exact to rounding), `A = ∂²T/∂q̇²` and `b = Q − (Ȧ q̇ − ∂T/∂q + ∂V/∂q)` with
//!   `V = −Σ m g·p_com`.
//! - **Virtual power** for external wrenches: the generalized force of a wrench `(f at O_j, m)` is
//!   `f·∂v_{O_j}/∂q̇ + m·∂ω_j/∂q̇`, again by differentiating the forward kinematics.
//! - **Energy**: `½ q̇ᵀ A q̇` equals the sum of the bodies' kinetic energies.
//! - **SPD**: `A` has a Cholesky factor.
//! - **Agreement**: the direct Kane sums (9)–(11) equal the spatial CRBA/RNEA.
//!
//! Errors are relative: `max|x − y| / max|y|`. Run with `--nocapture` to see the measured maxima.

// Matrix identities read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use kanegen_dynamics::algorithms::{crba, kane_direct, rnea};
use kanegen_dynamics::linalg::{axis_rotation, Mat3, Vec3};
use kanegen_dynamics::metrics::{flatten as flat, rel_err};
use kanegen_dynamics::scalars::dual::Dual;
use kanegen_dynamics::Params;
use kanegen_dynamics::Scalar;
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads};
use kanegen_model::random::{random_chain, random_vec, rng, ChainSpec};
use kanegen_model::{JointKind, Model};
use proptest::prelude::*;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

type D1 = Dual<f64>;
type D2 = Dual<D1>;
type BiasFn = fn(&Params<f64>, &[f64], &[f64], &Loads<f64>) -> Vec<f64>;

// ---------------------------------------------------------------------------------------------
// Forward kinematics and energies, independent of `kinematics.rs` and `spatial.rs`.
// ---------------------------------------------------------------------------------------------

/// World pose of a body frame: `x_world = rot · x_body + origin`.
struct Pose<S> {
    rot: Mat3<S>,
    origin: Vec3<S>,
}

/// Body poses by composing, per joint, the placement `(l, Υ)` and the joint motion (rotation about
/// the axis by `q`, or translation `q · axis`).
fn poses<S: Scalar>(chain: &Model, q: &[S]) -> Vec<Pose<S>> {
    let mut rot = Mat3::<S>::identity();
    let mut origin = Vec3::<S>::zero();
    let mut out = Vec::new();
    for (j, qj) in chain.joints().iter().zip(q) {
        let axis = Vec3::<S>::from_f64(j.axis);
        origin = origin + rot.mul_vec(&Vec3::from_f64(j.origin.translation));
        rot = rot.mul_mat(&Mat3::from_f64(j.origin.rotation));
        match j.kind {
            JointKind::Revolute => {
                let (s, c) = qj.clone().sin_cos();
                rot = rot.mul_mat(&axis_rotation(&axis, &s, &c));
            }
            JointKind::Prismatic => origin = origin + rot.mul_vec(&axis.scale(qj)),
        }
        out.push(Pose {
            rot: rot.clone(),
            origin: origin.clone(),
        });
    }
    out
}

/// Per body: pose, velocity of the frame origin, angular velocity, velocity of the centre of mass
/// (all in the world frame), from `d/dt poses(q + t q̇)` at `t = 0` (ω from `Ṙ Rᵀ = ω̃`).
struct BodyVel<S> {
    pose: Pose<S>,
    v_origin: Vec3<S>,
    omega: Vec3<S>,
    v_com: Vec3<S>,
}

fn velocities<S: Scalar>(chain: &Model, q: &[S], qd: &[S]) -> Vec<BodyVel<S>> {
    let qt: Vec<Dual<S>> = q
        .iter()
        .zip(qd)
        .map(|(a, b)| Dual::new(a.clone(), b.clone()))
        .collect();
    poses(chain, &qt)
        .into_iter()
        .zip(chain.joints())
        .map(|(p, j)| {
            let com = &p.origin + &p.rot.mul_vec(&Vec3::from_f64(j.inertial.com));
            let re = |m: &Mat3<Dual<S>>| Mat3(m.0.clone().map(|r| r.map(|x| x.re)));
            let de = |m: &Mat3<Dual<S>>| Mat3(m.0.clone().map(|r| r.map(|x| x.eps)));
            let rot = re(&p.rot);
            let w = de(&p.rot).mul_mat(&rot.transpose());
            let half = S::constant(0.5);
            let omega = Vec3::new(
                half.clone() * (w.at(2, 1) - w.at(1, 2)),
                half.clone() * (w.at(0, 2) - w.at(2, 0)),
                half * (w.at(1, 0) - w.at(0, 1)),
            );
            BodyVel {
                pose: Pose {
                    rot,
                    origin: Vec3(p.origin.0.clone().map(|x| x.re)),
                },
                v_origin: Vec3(p.origin.0.map(|x| x.eps)),
                omega,
                v_com: Vec3(com.0.map(|x| x.eps)),
            }
        })
        .collect()
}

/// Kinetic energy per body: `½ m |v_com|² + ½ ωᵀ (R I_c Rᵀ) ω`.
fn body_energies<S: Scalar>(chain: &Model, q: &[S], qd: &[S]) -> Vec<S> {
    velocities(chain, q, qd)
        .into_iter()
        .zip(chain.joints())
        .map(|(bv, j)| {
            let m = S::constant(j.inertial.mass);
            let i_world = bv.pose.rot.congruence(&Mat3::from_f64(j.inertial.inertia));
            let half = S::constant(0.5);
            half.clone() * m * bv.v_com.dot(&bv.v_com)
                + half * bv.omega.dot(&i_world.mul_vec(&bv.omega))
        })
        .collect()
}

fn kinetic<S: Scalar>(chain: &Model, q: &[S], qd: &[S]) -> S {
    body_energies(chain, q, qd)
        .into_iter()
        .fold(S::zero(), |a, b| a + b)
}

/// `V = −Σ m g·p_com`.
fn potential<S: Scalar>(chain: &Model, q: &[S], g: &[f64; 3]) -> S {
    let g = Vec3::<S>::from_f64(*g);
    poses(chain, q)
        .into_iter()
        .zip(chain.joints())
        .fold(S::zero(), |acc, (p, j)| {
            let com = &p.origin + &p.rot.mul_vec(&Vec3::from_f64(j.inertial.com));
            acc - S::constant(j.inertial.mass) * g.dot(&com)
        })
}

fn lift<S: Scalar>(x: &[f64]) -> Vec<S> {
    x.iter().map(|&v| S::constant(v)).collect()
}

/// `A_ik = ∂²T/∂q̇_i∂q̇_k` by `Dual<Dual<f64>>` (and a third level inside for `d/dt`).
fn lagrange_mass_matrix(chain: &Model, q: &[f64], qd: &[f64]) -> Vec<Vec<f64>> {
    let n = chain.dof();
    let qs: Vec<D2> = lift(q);
    let mut a = vec![vec![0.0; n]; n];
    for i in 0..n {
        for k in i..n {
            let qds: Vec<D2> = (0..n)
                .map(|l| {
                    let e_i = if l == i { 1.0 } else { 0.0 };
                    let e_k = if l == k { 1.0 } else { 0.0 };
                    Dual::new(Dual::new(qd[l], e_k), Dual::new(e_i, 0.0))
                })
                .collect();
            let t = kinetic(chain, &qs, &qds);
            a[i][k] = t.eps.eps;
            a[k][i] = t.eps.eps;
        }
    }
    a
}

/// `h = d/dt(∂T/∂q̇) − ∂T/∂q + ∂V/∂q` at `q̈ = 0`, i.e. `Ȧ q̇ − ∂T/∂q + ∂V/∂q`.
fn lagrange_h(chain: &Model, q: &[f64], qd: &[f64], g: Option<&[f64; 3]>) -> Vec<f64> {
    let n = chain.dof();
    (0..n)
        .map(|i| {
            let e = |l: usize| if l == i { 1.0 } else { 0.0 };
            // Σ_k ∂²T/∂q̇_i∂q_k q̇_k: q = q0 + σ q̇ (outer), q̇ = q̇0 + ε e_i (inner).
            let q2: Vec<D2> = (0..n)
                .map(|l| Dual::new(Dual::lift(q[l]), Dual::lift(qd[l])))
                .collect();
            let qd2: Vec<D2> = (0..n).map(|l| Dual::lift(Dual::new(qd[l], e(l)))).collect();
            let ddt_dtdqd = kinetic(chain, &q2, &qd2).eps.eps;
            // ∂T/∂q_i and ∂V/∂q_i.
            let q1: Vec<D1> = (0..n).map(|l| Dual::new(q[l], e(l))).collect();
            let dtdq = kinetic(chain, &q1, &lift::<D1>(qd)).eps;
            let dvdq = g.map_or(0.0, |g| potential(chain, &q1, g).eps);
            ddt_dtdqd - dtdq + dvdq
        })
        .collect()
}

/// Generalized force of the external wrenches by virtual power:
/// `Q_i = Σ f_world·∂v_{O_j}/∂q̇_i + m_world·∂ω_j/∂q̇_i`.
fn virtual_power_forces(chain: &Model, q: &[f64], ext: &[ExternalWrench<f64>]) -> Vec<f64> {
    let n = chain.dof();
    (0..n)
        .map(|i| {
            let qd: Vec<f64> = (0..n).map(|l| if l == i { 1.0 } else { 0.0 }).collect();
            let vel = velocities(chain, q, &qd);
            ext.iter()
                .map(|w| {
                    let bv = &vel[w.body];
                    let (f, m) = match w.frame {
                        LoadFrame::Base => (w.force.clone(), w.moment.clone()),
                        LoadFrame::Body => (
                            bv.pose.rot.mul_vec(&w.force),
                            bv.pose.rot.mul_vec(&w.moment),
                        ),
                    };
                    f.dot(&bv.v_origin) + m.dot(&bv.omega)
                })
                .sum()
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Helpers.
// ---------------------------------------------------------------------------------------------

fn chain(n: usize, seed: u64) -> Model {
    random_chain(
        &ChainSpec {
            n,
            prismatic_fraction: 0.3,
            ..Default::default()
        },
        seed,
    )
}

struct State {
    q: Vec<f64>,
    qd: Vec<f64>,
    tau: Vec<f64>,
    g: [f64; 3],
}

fn state(r: &mut ChaCha8Rng, n: usize) -> State {
    let g = random_vec(r, 3, 10.0);
    State {
        q: random_vec(r, n, 3.0),
        qd: random_vec(r, n, 2.0),
        tau: random_vec(r, n, 20.0),
        g: [g[0], g[1], g[2]],
    }
}

fn random_wrenches(r: &mut ChaCha8Rng, n: usize) -> Vec<ExternalWrench<f64>> {
    let count = r.random_range(1..=3);
    (0..count)
        .map(|k| ExternalWrench {
            body: r.random_range(0..n),
            frame: if k % 2 == 0 {
                LoadFrame::Body
            } else {
                LoadFrame::Base
            },
            force: Vec3::from_f64(std::array::from_fn(|_| r.random_range(-50.0..50.0))),
            moment: Vec3::from_f64(std::array::from_fn(|_| r.random_range(-20.0..20.0))),
        })
        .collect()
}

fn loads(s: &State, ext: Vec<ExternalWrench<f64>>) -> Loads<f64> {
    Loads {
        tau: Some(s.tau.clone()),
        gravity: Some(Vec3::from_f64(s.g)),
        external: ext,
    }
}

fn no_loads() -> Loads<f64> {
    Loads::default()
}

// ---------------------------------------------------------------------------------------------
// The identities.
// ---------------------------------------------------------------------------------------------

#[test]
fn lagrange_oracle_matches_spatial_a_and_b() {
    let (mut worst_a, mut worst_b) = (0.0f64, 0.0f64);
    let (mut prismatic, mut joints) = (0usize, 0usize);
    for n in 1..=10 {
        for seed in 0..3u64 {
            let c = chain(n, 100 * n as u64 + seed);
            joints += n;
            prismatic += c
                .joints()
                .iter()
                .filter(|j| j.kind == JointKind::Prismatic)
                .count();
            let p = Params::<f64>::new(&c);
            let s = state(&mut rng(seed + 7 * n as u64), n);
            let a_ref = lagrange_mass_matrix(&c, &s.q, &s.qd);
            let h = lagrange_h(&c, &s.q, &s.qd, Some(&s.g));
            let b_ref: Vec<f64> = s.tau.iter().zip(&h).map(|(t, h)| t - h).collect();
            let a = crba::mass_matrix(&p, &s.q);
            let b = rnea::tau_minus_c(&p, &s.q, &s.qd, &loads(&s, vec![]));
            let (ea, eb) = (rel_err(&flat(&a), &flat(&a_ref)), rel_err(&b, &b_ref));
            assert!(ea < 1e-10, "A: N={n} seed={seed}: rel err {ea:e}");
            assert!(eb < 1e-10, "b: N={n} seed={seed}: rel err {eb:e}");
            worst_a = worst_a.max(ea);
            worst_b = worst_b.max(eb);
            // Velocity products alone (no gravity, no drives) — a sharper test of the Coriolis terms.
            let h0 = lagrange_h(&c, &s.q, &s.qd, None);
            let b0 = rnea::tau_minus_c(&p, &s.q, &s.qd, &no_loads());
            // (Scaled by the full b: for N = 1 the velocity products vanish identically.)
            let scale = b_ref.iter().chain(&h0).map(|x| x.abs()).fold(0.0, f64::max);
            let e0 = b0
                .iter()
                .zip(&h0)
                .map(|(x, y)| (x + y).abs())
                .fold(0.0, f64::max)
                / scale;
            assert!(
                e0 < 1e-10,
                "b (velocity only): N={n} seed={seed}: rel err {e0:e}"
            );
            worst_b = worst_b.max(e0);
        }
    }
    assert!(
        prismatic > 0 && prismatic < joints,
        "both joint kinds must be exercised"
    );
    eprintln!(
        "Lagrange vs spatial ({prismatic} prismatic of {joints} joints): \
         max rel err A {worst_a:.2e}, b {worst_b:.2e}"
    );
}

#[test]
fn lagrange_oracle_discriminates() {
    // The oracle must be able to fail: dropping the velocity terms (b at q̇ = 0) or perturbing a
    // mass is far outside the tolerance.
    let c = chain(5, 11);
    let p = Params::<f64>::new(&c);
    let s = state(&mut rng(3), 5);
    let h = lagrange_h(&c, &s.q, &s.qd, Some(&s.g));
    let b_ref: Vec<f64> = s.tau.iter().zip(&h).map(|(t, h)| t - h).collect();
    let zero = vec![0.0; 5];
    let b_static = rnea::tau_minus_c(&p, &s.q, &zero, &loads(&s, vec![]));
    assert!(rel_err(&b_static, &b_ref) > 1e-3);
    let mut p2 = p.clone();
    let j2 = p2.joints[2].clone();
    p2.joints[2].set_inertial(j2.mass * 1.001, j2.com, j2.inertia_com);
    let a_ref = lagrange_mass_matrix(&c, &s.q, &s.qd);
    assert!(rel_err(&flat(&crba::mass_matrix(&p2, &s.q)), &flat(&a_ref)) > 1e-6);
}

#[test]
fn external_wrenches_by_virtual_power() {
    let mut worst = 0.0f64;
    for n in 1..=10 {
        for seed in 0..3u64 {
            let c = chain(n, 300 + 10 * n as u64 + seed);
            let p = Params::<f64>::new(&c);
            let mut r = rng(1000 + seed + n as u64);
            let s = state(&mut r, n);
            let ext = random_wrenches(&mut r, n);
            let q_ref = virtual_power_forces(&c, &s.q, &ext);
            for (name, bias) in [
                ("spatial", rnea::tau_minus_c::<f64> as BiasFn),
                ("kane-direct", kane_direct::tau_minus_c::<f64>),
            ] {
                let with = bias(&p, &s.q, &s.qd, &loads(&s, ext.clone()));
                let without = bias(&p, &s.q, &s.qd, &loads(&s, vec![]));
                let diff: Vec<f64> = with.iter().zip(&without).map(|(a, b)| a - b).collect();
                let e = rel_err(&diff, &q_ref);
                assert!(e < 1e-10, "{name}: N={n} seed={seed}: rel err {e:e}");
                worst = worst.max(e);
            }
        }
    }
    eprintln!("external wrenches vs virtual power: max rel err {worst:.2e}");
}

#[test]
fn half_qd_a_qd_is_the_kinetic_energy() {
    let mut worst = 0.0f64;
    for n in 1..=16 {
        for seed in 0..3u64 {
            let c = chain(n, 500 + 10 * n as u64 + seed);
            let p = Params::<f64>::new(&c);
            let s = state(&mut rng(2000 + seed + n as u64), n);
            let t_ref: f64 = kinetic(&c, &s.q, &s.qd);
            for a in [
                crba::mass_matrix(&p, &s.q),
                kane_direct::mass_matrix(&p, &s.q),
            ] {
                let t: f64 = 0.5
                    * (0..n)
                        .map(|i| (0..n).map(|k| s.qd[i] * a[i][k] * s.qd[k]).sum::<f64>())
                        .sum::<f64>();
                let e = (t - t_ref).abs() / t_ref.abs();
                assert!(
                    e < 1e-12,
                    "N={n} seed={seed}: T {t} vs {t_ref}, rel err {e:e}"
                );
                worst = worst.max(e);
            }
        }
    }
    eprintln!("½ q̇ᵀAq̇ vs Σ body energies: max rel err {worst:.2e}");
}

/// The two-step inertia carry through placements that turn about one coordinate axis
/// (`JointParams::placement_turn`: xArm7's `rpy = "±1.5708 0 0"`) gives the Lagrange mass matrix,
/// as the one-step carry does.
#[test]
fn two_step_carry_through_turned_placements_matches_lagrange() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/erd/xarm7.urdf");
    let model = kanegen_model::io::parse_urdf(&std::fs::read_to_string(path).unwrap()).unwrap();
    let one_step = Params::<f64>::new(&model);
    let mut two_step = one_step.clone();
    let mut turned = 0;
    for jp in &mut two_step.joints {
        if jp.placement_turn.is_some() {
            jp.placement_permutation = true;
            turned += 1;
        }
    }
    assert_eq!(turned, 6, "xArm7 places joints 2 to 7 by a turn about x");
    let mut r = rng(41);
    let mut worst = 0.0f64;
    for _ in 0..20 {
        let n = model.dof();
        let (q, qd) = (random_vec(&mut r, n, 3.0), random_vec(&mut r, n, 2.0));
        let reference = lagrange_mass_matrix(&model, &q, &qd);
        let a1 = crba::mass_matrix(&one_step, &q);
        let a2 = crba::mass_matrix(&two_step, &q);
        assert!(rel_err(&flat(&a1), &flat(&reference)) < 1e-12);
        worst = worst.max(rel_err(&flat(&a2), &flat(&reference)));
    }
    println!("two-step carry through turned placements against Lagrange: {worst:.2e}");
    assert!(worst < 1e-12, "{worst:e}");
}

/// Canonical frames place every joint but the first by `Θ_x(α) Θ_z(θ₀)`: split
/// (`JointParams::split_placement`, `θ₀` into the joint angle and the carries in two turns), the
/// CRBA, the Newton–Euler bias, the spatial RNEA, ABA and the paper's inertial-frame algorithm still
/// give the Lagrange `A`, `b` and `q̈` of the canonical model.
#[test]
fn split_placements_match_lagrange() {
    use kanegen_dynamics::algorithms::{aba, newton_euler, recurrent};
    use kanegen_dynamics::ldlt;
    let (mut splits, mut revolute, mut worst) = (0, 0, 0.0f64);
    for n in [2, 5, 8] {
        for seed in 0..3u64 {
            let c = chain(n, 700 + 10 * n as u64 + seed)
                .canonical()
                .unwrap()
                .model;
            let mut p = Params::<f64>::new(&c);
            for (jp, j) in p.joints.iter_mut().zip(c.joints()) {
                revolute += usize::from(j.kind == JointKind::Revolute);
                splits += usize::from(jp.split_placement(j));
            }
            let s = state(&mut rng(seed + 31 * n as u64), n);
            let a_ref = lagrange_mass_matrix(&c, &s.q, &s.qd);
            let h = lagrange_h(&c, &s.q, &s.qd, Some(&s.g));
            let b_ref: Vec<f64> = s.tau.iter().zip(&h).map(|(t, h)| t - h).collect();
            let l = loads(&s, vec![]);
            let errs = [
                rel_err(&flat(&crba::mass_matrix(&p, &s.q)), &flat(&a_ref)),
                rel_err(
                    &flat(&recurrent::mass_matrix(&p, &s.q, recurrent::Variant::R2)),
                    &flat(&a_ref),
                ),
                rel_err(&newton_euler::tau_minus_c(&p, &s.q, &s.qd, &l), &b_ref),
                rel_err(&rnea::tau_minus_c(&p, &s.q, &s.qd, &l), &b_ref),
            ];
            let qdd_ref = ldlt::solve(&ldlt::ldlt(&a_ref), &b_ref);
            let e_aba = rel_err(&aba::forward_dynamics(&p, &s.q, &s.qd, &l), &qdd_ref);
            for (k, e) in errs.into_iter().chain([e_aba]).enumerate() {
                assert!(e < 1e-10, "N={n} seed={seed} #{k}: rel err {e:e}");
                worst = worst.max(e);
            }
        }
    }
    // Every revolute joint past the first of each chain (the first is placed on the base, whose
    // frame canonical frames leave).
    assert!(
        splits * 10 >= revolute * 6,
        "{splits} of {revolute} revolute joints split"
    );
    eprintln!("split placements against Lagrange: {splits} of {revolute} revolute joints split, max rel err {worst:.2e}");
}

/// `axis_turn` recognises a turn about each coordinate axis, and nothing else.
#[test]
fn axis_turn_reads_single_axis_rotations() {
    use kanegen_dynamics::params::axis_turn;
    let (s, c) = 1.2f64.sin_cos();
    for k in 0..3 {
        let mut r = Mat3::<f64>::identity().0;
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        (r[a][a], r[a][b], r[b][a], r[b][b]) = (c, -s, s, c);
        assert_eq!(axis_turn(&r), Some((k, s, c)));
        // Transposed: the turn by −α.
        let t = Mat3(r).transpose().0;
        assert_eq!(axis_turn(&t), Some((k, -s, c)));
        // Not a turn: a scaled block, or an off-axis entry.
        let mut scaled = r;
        scaled[b][b] = 0.5 * c;
        assert_eq!(axis_turn(&scaled), None);
        let mut off = r;
        off[k][a] = 1e-9;
        assert_eq!(axis_turn(&off), None);
    }
    // Signed permutations and the identity are no turn (their carry is already free).
    assert_eq!(axis_turn(&Mat3::<f64>::identity().0), None);
    assert_eq!(
        axis_turn(&[[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
        None
    );
}

#[test]
fn mass_matrix_is_symmetric_positive_definite() {
    for n in 1..=32 {
        let c = chain(n, 700 + n as u64);
        let p = Params::<f64>::new(&c);
        let q = random_vec(&mut rng(n as u64), n, 3.0);
        for (name, a) in [
            ("spatial", crba::mass_matrix(&p, &q)),
            ("kane-direct", kane_direct::mass_matrix(&p, &q)),
        ] {
            for i in 0..n {
                for k in 0..n {
                    assert_eq!(
                        a[i][k], a[k][i],
                        "{name}: N={n}: A not symmetric at ({i},{k})"
                    );
                }
            }
            let m = nalgebra::DMatrix::from_fn(n, n, |i, k| a[i][k]);
            assert!(
                nalgebra::Cholesky::new(m).is_some(),
                "{name}: N={n}: A not positive definite"
            );
        }
    }
}

/// `(rel err A, rel err b)` of kane-direct against spatial, all loads present.
fn kane_vs_spatial(n: usize, seed: u64) -> (f64, f64) {
    let c = chain(n, seed);
    let p = Params::<f64>::new(&c);
    let mut r = rng(seed ^ 0x5eed);
    let s = state(&mut r, n);
    let l = loads(&s, random_wrenches(&mut r, n));
    let ea = rel_err(
        &flat(&kane_direct::mass_matrix(&p, &s.q)),
        &flat(&crba::mass_matrix(&p, &s.q)),
    );
    let eb = rel_err(
        &kane_direct::tau_minus_c(&p, &s.q, &s.qd, &l),
        &rnea::tau_minus_c(&p, &s.q, &s.qd, &l),
    );
    (ea, eb)
}

#[test]
fn kane_direct_agrees_with_spatial() {
    let (mut wa, mut wb) = (0.0f64, 0.0f64);
    for n in 1..=16 {
        for seed in 0..4u64 {
            let (ea, eb) = kane_vs_spatial(n, 900 + 10 * n as u64 + seed);
            assert!(ea < 1e-12, "A: N={n} seed={seed}: rel err {ea:e}");
            assert!(eb < 1e-12, "b: N={n} seed={seed}: rel err {eb:e}");
            wa = wa.max(ea);
            wb = wb.max(eb);
        }
    }
    eprintln!("kane-direct vs spatial: max rel err A {wa:.2e}, b {wb:.2e}");
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 32,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn prop_kane_direct_agrees_with_spatial(n in 1usize..=32, seed in any::<u64>()) {
        let (ea, eb) = kane_vs_spatial(n, seed);
        prop_assert!(ea < 1e-12, "A: rel err {:e}", ea);
        prop_assert!(eb < 1e-12, "b: rel err {:e}", eb);
    }
}
