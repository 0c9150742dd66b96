//! Kinematic trees (seeded `random_tree`s, revolute and prismatic joints, several subtrees on the
//! base), against oracles that share no code with the recursions under test:
//!
//! - **Jacobian sums**: `A = Σ_k (m_k J_c,kᵀ J_c,k + J_ω,kᵀ I_k J_ω,k)` over the bodies, with the
//!   centre-of-mass Jacobians of [`frames`] (fixed and free-floating base), and the gravity
//!   forces `Σ_k J_c,kᵀ m_k g`;
//! - **Lagrange**: `b = −(Ȧ q̇ − ½ ∂(q̇ᵀ A q̇)/∂q)`, both derivatives exact by dual numbers;
//! - **virtual power** for external wrenches: `Jᵀ [f; m]`;
//! - **finite differences**: frame Jacobians against placements, the base-row wrench of the
//!   floating inverse dynamics and the arm's reaction on the base against the rates of the total
//!   and the arm's momentum (`ḣ_O = Σ external wrenches about O`);
//! - **identities**: the CRBA's columns are RNEA with unit accelerations, `A` symmetric and
//!   positive definite, `½ νᵀ A ν = T`, momentum `= A_b ν`, floating inverse dynamics
//!   `= A ν̇ − b`, `J* q̇` = the frame's motion at zero momentum.
//!
//! Errors are relative, `max|x − y| / max|y|`; run with `--nocapture` for the measured maxima.

// Matrix identities read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use kanegen_dynamics::algorithms::{
    crba, crba_inertial, floating, frames, kane_direct, kinematics, momentum, recurrent, rnea,
};
use kanegen_dynamics::base::{FloatingBase, FloatingState, BASE_BODY};
use kanegen_dynamics::ldlt::{ldlt, solve};
use kanegen_dynamics::linalg::{axis_rotation, Mat3, Vec3};
use kanegen_dynamics::metrics::{rel_err, rel_err_mat};
use kanegen_dynamics::scalars::dual::Dual;
use kanegen_dynamics::{
    ExternalWrench, FrameParams, LoadFrame, Loads, MassMatrixMethod, Methods,
    NonlinearEffectsMethod, Params,
};
use kanegen_model::random::{
    random_chain, random_inertial, random_rotation, random_tree, random_vec, rng, ChainSpec,
};
use kanegen_model::Model;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

// ---------------------------------------------------------------------------------------------
// Cases.
// ---------------------------------------------------------------------------------------------

fn tree(n: usize, seed: u64) -> Model {
    random_tree(
        &ChainSpec {
            n,
            prismatic_fraction: 0.3,
            ..Default::default()
        },
        seed,
    )
}

/// The seeds used everywhere: sizes 1..=12, two seeds each; most of them branch.
fn trees() -> Vec<Model> {
    let all: Vec<Model> = (1..=12)
        .flat_map(|n| [tree(n, 40 + n as u64), tree(n, 900 + n as u64)])
        .collect();
    let branching = all.iter().filter(|m| !m.is_chain()).count();
    assert!(
        branching >= 18,
        "only {branching} of the random trees branch"
    );
    all
}

fn v3(x: &[f64]) -> Vec3<f64> {
    Vec3::new(x[0], x[1], x[2])
}

/// Joint state and base state of one case.
struct State {
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    base: FloatingBase<f64>,
    floating: FloatingState<f64>,
    base_acc: [f64; 6],
}

fn state(r: &mut ChaCha8Rng, n: usize) -> State {
    State {
        q: random_vec(r, n, 2.0),
        qd: random_vec(r, n, 1.0),
        qdd: random_vec(r, n, 2.0),
        base: FloatingBase::from_inertial(&random_inertial(r, 100.0, 1.5)),
        floating: FloatingState {
            position: v3(&random_vec(r, 3, 2.0)),
            rotation: Mat3(random_rotation(r)),
            v_b: v3(&random_vec(r, 3, 1.0)),
            omega_b: v3(&random_vec(r, 3, 1.0)),
        },
        base_acc: random_vec(r, 6, 1.0).try_into().unwrap(),
    }
}

/// Wrenches on random arm bodies (both frames) and, for a floating base, on the base.
fn wrenches(r: &mut ChaCha8Rng, n: usize, on_base: bool) -> Vec<ExternalWrench<f64>> {
    let mut out: Vec<ExternalWrench<f64>> = (0..3)
        .map(|_| ExternalWrench {
            body: r.random_range(0..n),
            frame: if r.random_bool(0.5) {
                LoadFrame::Body
            } else {
                LoadFrame::Base
            },
            force: v3(&random_vec(r, 3, 20.0)),
            moment: v3(&random_vec(r, 3, 5.0)),
        })
        .collect();
    if on_base {
        out.push(ExternalWrench {
            body: BASE_BODY,
            frame: LoadFrame::Base,
            force: v3(&random_vec(r, 3, 20.0)),
            moment: v3(&random_vec(r, 3, 5.0)),
        });
    }
    out
}

fn mat_vec(a: &[Vec<f64>], x: &[f64]) -> Vec<f64> {
    a.iter()
        .map(|row| row.iter().zip(x).map(|(p, q)| p * q).sum())
        .collect()
}

fn tr_mat_vec(a: &[Vec<f64>], x: &[f64]) -> Vec<f64> {
    (0..a[0].len())
        .map(|c| (0..a.len()).map(|r| a[r][c] * x[r]).sum())
        .collect()
}

fn sub(x: &[f64], y: &[f64]) -> Vec<f64> {
    x.iter().zip(y).map(|(a, b)| a - b).collect()
}

fn nu(s: &State) -> Vec<f64> {
    let mut v = s.floating.nu_base().to_vec();
    v.extend(&s.qd);
    v
}

/// The frame at body `k`'s centre of mass (`None`: the base's, at `com`), body axes.
fn com_frame(p: &Params<f64>, k: Option<usize>, base_com: &Vec3<f64>) -> FrameParams<f64> {
    FrameParams {
        parent: k,
        translation: k.map_or_else(|| base_com.clone(), |k| p.joints[k].com.clone()),
        rotation: Mat3::identity(),
    }
}

/// `Jᵀ M J` accumulated into `a` for the 3 rows `rows` of `j` (6 × m) and a 3×3 `m`.
fn add_jt_m_j(a: &mut [Vec<f64>], j: &[Vec<f64>], rows: usize, m: &Mat3<f64>) {
    let cols = j[0].len();
    for c1 in 0..cols {
        let col1 = Vec3::new(j[rows][c1], j[rows + 1][c1], j[rows + 2][c1]);
        let mc1 = m.mul_vec(&col1);
        for c2 in 0..cols {
            let col2 = Vec3::new(j[rows][c2], j[rows + 1][c2], j[rows + 2][c2]);
            a[c2][c1] += col2.dot(&mc1);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 1. Fixed base: CRBA, RNEA.
// ---------------------------------------------------------------------------------------------

#[test]
fn crba_columns_are_rnea_with_unit_accelerations_and_a_is_spd() {
    let mut worst = 0.0_f64;
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let s = state(&mut rng(k as u64), n);
        let h = crba::mass_matrix(&p, &s.q);
        // Column j: τ(q̈ = e_j) − τ(q̈ = 0) at the same q̇ (RNEA is affine in q̈).
        let none = Loads::default();
        let tau0 = rnea::inverse_dynamics(&p, &s.q, &s.qd, &vec![0.0; n], &none);
        let mut cols = vec![vec![0.0; n]; n];
        for j in 0..n {
            let mut e = vec![0.0; n];
            e[j] = 1.0;
            let tau = rnea::inverse_dynamics(&p, &s.q, &s.qd, &e, &none);
            for i in 0..n {
                cols[i][j] = tau[i] - tau0[i];
            }
        }
        let e = rel_err_mat(&cols, &h);
        worst = worst.max(e);
        assert!(e < 1e-12, "{}: CRBA vs RNEA {e:e}", model.name());
        for i in 0..n {
            for j in 0..n {
                assert_eq!(h[i][j], h[j][i], "{}: symmetric", model.name());
            }
        }
        let f = ldlt(&h);
        assert!(
            f.d.iter().all(|d| *d > 0.0),
            "{}: positive definite",
            model.name()
        );
        // Joints on different branches do not couple.
        for i in 0..n {
            for j in 0..i {
                let mut a = Some(i);
                let mut related = false;
                while let Some(b) = a {
                    related |= b == j;
                    a = model.joints()[b].parent;
                }
                if !related {
                    assert_eq!(
                        h[i][j],
                        0.0,
                        "{}: H[{i}][{j}] across branches",
                        model.name()
                    );
                }
            }
        }
    }
    println!("CRBA vs RNEA columns on random trees: {worst:.2e}");
}

#[test]
fn mass_matrix_and_gravity_are_jacobian_sums() {
    let mut worst = (0.0_f64, 0.0_f64);
    let g = Vec3::new(0.4, -1.1, -9.81);
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let s = state(&mut rng(100 + k as u64), n);
        let mut a = vec![vec![0.0; n]; n];
        let mut gen_g = vec![0.0; n];
        for b in 0..n {
            let f = com_frame(&p, Some(b), &Vec3::zero());
            let j = frames::jacobian(&p, &s.q, &f);
            let (_, rot) = frames::placement(&p, &s.q, &f);
            let m = p.joints[b].mass;
            add_jt_m_j(&mut a, &j, 0, &Mat3::identity().scale(&m));
            add_jt_m_j(&mut a, &j, 3, &rot.congruence(&p.joints[b].inertia_com));
            // Generalized gravity: J_cᵀ m g.
            let w = [g.at(0) * m, g.at(1) * m, g.at(2) * m, 0.0, 0.0, 0.0];
            for (x, y) in gen_g.iter_mut().zip(tr_mat_vec(&j, &w)) {
                *x += y;
            }
        }
        let h = crba::mass_matrix(&p, &s.q);
        let ea = rel_err_mat(&h, &a);
        let with_g = Loads {
            gravity: Some(g.clone()),
            ..Loads::default()
        };
        let bg = sub(
            &rnea::tau_minus_c(&p, &s.q, &s.qd, &with_g),
            &rnea::tau_minus_c(&p, &s.q, &s.qd, &Loads::default()),
        );
        let eg = rel_err(&bg, &gen_g);
        worst = (worst.0.max(ea), worst.1.max(eg));
        assert!(ea < 1e-12, "{}: A {ea:e}", model.name());
        assert!(eg < 1e-12, "{}: gravity {eg:e}", model.name());
    }
    println!(
        "A vs Σ JᵀMJ: {:.2e}; gravity vs Σ J_cᵀ m g: {:.2e}",
        worst.0, worst.1
    );
}

/// `b(q, q̇) = −(Ȧ q̇ − ½ ∂(q̇ᵀ A q̇)/∂q)` with `A` from the CRBA on dual numbers.
fn lagrange_bias(model: &Model, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let n = q.len();
    let pd = Params::<Dual<f64>>::new(model);
    let along = |dir: &[f64]| -> Vec<Vec<f64>> {
        let qx: Vec<Dual<f64>> = q.iter().zip(dir).map(|(a, d)| Dual::new(*a, *d)).collect();
        crba::mass_matrix(&pd, &qx)
            .into_iter()
            .map(|row| row.into_iter().map(|x| x.eps).collect())
            .collect()
    };
    let a_dot = along(qd);
    let mut c = mat_vec(&a_dot, qd);
    for k in 0..n {
        let mut e = vec![0.0; n];
        e[k] = 1.0;
        let dk = along(&e);
        let quad: f64 = (0..n)
            .map(|i| (0..n).map(|j| qd[i] * dk[i][j] * qd[j]).sum::<f64>())
            .sum();
        c[k] -= 0.5 * quad;
    }
    c.into_iter().map(|x| -x).collect()
}

#[test]
fn rnea_bias_is_lagrange_on_trees() {
    let mut worst = 0.0_f64;
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let s = state(&mut rng(200 + k as u64), n);
        let b = rnea::tau_minus_c(&p, &s.q, &s.qd, &Loads::default());
        let want = lagrange_bias(model, &s.q, &s.qd);
        let e = rel_err(&b, &want);
        worst = worst.max(e);
        assert!(e < 1e-11, "{}: {e:e}", model.name());
    }
    println!("RNEA b vs Lagrange on random trees: {worst:.2e}");
}

#[test]
fn external_wrenches_by_virtual_power_on_trees() {
    let mut worst = 0.0_f64;
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let mut r = rng(300 + k as u64);
        let s = state(&mut r, n);
        let ext = wrenches(&mut r, n, false);
        let mut want = vec![0.0; n];
        for w in &ext {
            let origin = FrameParams {
                parent: Some(w.body),
                translation: Vec3::zero(),
                rotation: Mat3::identity(),
            };
            let j = frames::jacobian(&p, &s.q, &origin);
            let (_, rot) = frames::placement(&p, &s.q, &origin);
            let (f, m) = match w.frame {
                LoadFrame::Base => (w.force.clone(), w.moment.clone()),
                LoadFrame::Body => (rot.mul_vec(&w.force), rot.mul_vec(&w.moment)),
            };
            let fm: Vec<f64> = f.0.iter().chain(m.0.iter()).copied().collect();
            for (x, y) in want.iter_mut().zip(tr_mat_vec(&j, &fm)) {
                *x += y;
            }
        }
        let loads = Loads {
            external: ext,
            ..Loads::default()
        };
        let got = sub(
            &rnea::tau_minus_c(&p, &s.q, &s.qd, &loads),
            &rnea::tau_minus_c(&p, &s.q, &s.qd, &Loads::default()),
        );
        let e = rel_err(&got, &want);
        worst = worst.max(e);
        assert!(e < 1e-12, "{}: {e:e}", model.name());
    }
    println!("external wrenches vs Jᵀ w on random trees: {worst:.2e}");
}

// ---------------------------------------------------------------------------------------------
// 2. Frames: Jacobians against finite differences of the placements.
// ---------------------------------------------------------------------------------------------

fn random_frame(r: &mut ChaCha8Rng, n: usize) -> FrameParams<f64> {
    let k = r.random_range(0..=n);
    FrameParams {
        parent: (k < n).then_some(k),
        translation: v3(&random_vec(r, 3, 0.5)),
        rotation: Mat3(random_rotation(r)),
    }
}

/// `ω` (world axes) from two orientations `h` apart on either side: `vee(skew(R₊ R₋ᵀ)) / 2h`.
fn omega_fd(rp: &Mat3<f64>, rm: &Mat3<f64>, h: f64) -> Vec3<f64> {
    let d = rp.mul_mat(&rm.transpose());
    Vec3::new(
        d.at(2, 1) - d.at(1, 2),
        d.at(0, 2) - d.at(2, 0),
        d.at(1, 0) - d.at(0, 1),
    )
    .scale(&(0.25 / h))
}

/// `[v; ω]` from placements at `∓h` along a motion.
fn twist_fd(plus: &(Vec3<f64>, Mat3<f64>), minus: &(Vec3<f64>, Mat3<f64>), h: f64) -> Vec<f64> {
    let v = (&plus.0 - &minus.0).scale(&(0.5 / h));
    let w = omega_fd(&plus.1, &minus.1, h);
    v.0.iter().chain(w.0.iter()).copied().collect()
}

/// The free-floating pose after `t` along the twist `(v_b, ω_b)` (exact to first order, which
/// central differences need).
fn moved(s: &FloatingState<f64>, t: f64) -> FloatingState<f64> {
    let w = &s.omega_b;
    let angle = w.dot(w).sqrt() * t;
    let u = w.scale(&(1.0 / w.dot(w).sqrt()));
    FloatingState {
        position: &s.position + &s.rotation.mul_vec(&s.v_b.scale(&t)),
        rotation: s
            .rotation
            .mul_mat(&axis_rotation(&u, &angle.sin(), &angle.cos())),
        ..s.clone()
    }
}

fn shifted(q: &[f64], qd: &[f64], t: f64) -> Vec<f64> {
    q.iter().zip(qd).map(|(a, b)| a + t * b).collect()
}

#[test]
fn frame_jacobians_are_derivatives_of_placements() {
    let h = 1e-5;
    let mut worst = (0.0_f64, 0.0_f64);
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let mut r = rng(400 + k as u64);
        let s = state(&mut r, n);
        for _ in 0..3 {
            let f = random_frame(&mut r, n);
            // Fixed base.
            let j = frames::jacobian(&p, &s.q, &f);
            assert_eq!((j.len(), j[0].len()), (6, n));
            let plus = frames::placement(&p, &shifted(&s.q, &s.qd, h), &f);
            let minus = frames::placement(&p, &shifted(&s.q, &s.qd, -h), &f);
            let want = twist_fd(&plus, &minus, h);
            let e = rel_err(&mat_vec(&j, &s.qd), &want);
            worst.0 = worst.0.max(e);
            assert!(e < 1e-8, "{} fixed: {e:e}", model.name());
            // Free-floating base: the base moves with (v_b, ω_b) too.
            let jf = frames::floating_jacobian(&p, &s.floating, &s.q, &f);
            assert_eq!((jf.len(), jf[0].len()), (6, 6 + n));
            let plus = frames::floating_placement(
                &p,
                &moved(&s.floating, h),
                &shifted(&s.q, &s.qd, h),
                &f,
            );
            let minus = frames::floating_placement(
                &p,
                &moved(&s.floating, -h),
                &shifted(&s.q, &s.qd, -h),
                &f,
            );
            let want = twist_fd(&plus, &minus, h);
            let e = rel_err(&mat_vec(&jf, &nu(&s)), &want);
            worst.1 = worst.1.max(e);
            assert!(e < 1e-8, "{} floating: {e:e}", model.name());
        }
    }
    println!(
        "J vs finite differences: fixed {:.2e}, floating {:.2e}",
        worst.0, worst.1
    );
}

#[test]
fn frame_placements_compose_along_the_tree() {
    // A frame on body k at the child joint's origin, rotated by the child's Υ, is the child
    // body's frame at q_child = 0.
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let s = state(&mut rng(500 + k as u64), n);
        for c in 0..n {
            let jp = &p.joints[c];
            let at_joint = FrameParams {
                parent: jp.parent,
                translation: jp.l.clone(),
                rotation: jp.upsilon.clone(),
            };
            let body = FrameParams {
                parent: Some(c),
                translation: Vec3::zero(),
                rotation: Mat3::identity(),
            };
            let mut q0 = s.q.clone();
            q0[c] = 0.0;
            let (xa, ra) = frames::placement(&p, &q0, &at_joint);
            let (xb, rb) = frames::placement(&p, &q0, &body);
            let mut a: Vec<f64> = xa.0.to_vec();
            a.extend(ra.0.iter().flatten());
            let mut b: Vec<f64> = xb.0.to_vec();
            b.extend(rb.0.iter().flatten());
            assert!(rel_err(&a, &b) < 1e-14, "{} joint {c}", model.name());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// 3. Free-floating base.
// ---------------------------------------------------------------------------------------------

#[test]
fn floating_mass_matrix_is_a_jacobian_sum_and_gives_energy_and_momentum() {
    let mut worst = (0.0_f64, 0.0_f64, 0.0_f64);
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let s = state(&mut rng(600 + k as u64), n);
        let a = floating::mass_matrix(MassMatrixMethod::Crba, &p, &s.base, &s.floating, &s.q);
        // Σ over the base and the bodies of the tree, inertial axes.
        let mut want = vec![vec![0.0; 6 + n]; 6 + n];
        let bodies = std::iter::once(None).chain((0..n).map(Some));
        for b in bodies {
            let f = com_frame(&p, b, &s.base.com);
            let j = frames::floating_jacobian(&p, &s.floating, &s.q, &f);
            let (_, rot) = frames::floating_placement(&p, &s.floating, &s.q, &f);
            let (m, ic) = match b {
                None => (s.base.mass, s.base.inertia_com.clone()),
                Some(b) => (p.joints[b].mass, p.joints[b].inertia_com.clone()),
            };
            add_jt_m_j(&mut want, &j, 0, &Mat3::identity().scale(&m));
            add_jt_m_j(&mut want, &j, 3, &rot.congruence(&ic));
        }
        let ea = rel_err_mat(&a, &want);
        assert!(ea < 1e-12, "{}: A {ea:e}", model.name());
        for i in 0..6 + n {
            for j in 0..6 + n {
                assert_eq!(a[i][j], a[j][i], "{}: symmetric", model.name());
            }
        }
        assert!(ldlt(&a).d.iter().all(|d| *d > 0.0), "{}: SPD", model.name());
        // ½ νᵀ A ν = T; A_b ν = momentum about the base origin; about the inertial origin.
        let v = nu(&s);
        let av = mat_vec(&a, &v);
        let t_a = 0.5 * v.iter().zip(&av).map(|(x, y)| x * y).sum::<f64>();
        let t = momentum::kinetic_energy(&p, &s.base, &s.floating, &s.q, &s.qd);
        let et = (t - t_a).abs() / t_a;
        let hb = momentum::momentum_base(&p, &s.base, &s.floating, &s.q, &s.qd);
        let (lin, ang) = momentum::momentum(&p, &s.base, &s.floating, &s.q, &s.qd);
        let r0 = &s.floating.rotation;
        let lin_want = r0.mul_vec(&v3(&av[..3]));
        let ang_want = &r0.mul_vec(&v3(&av[3..6])) + &s.floating.position.cross(&lin_want);
        let h_want: Vec<f64> = lin_want
            .0
            .iter()
            .chain(ang_want.0.iter())
            .copied()
            .collect();
        let h: Vec<f64> = lin.0.iter().chain(ang.0.iter()).copied().collect();
        let ep = rel_err(&hb, &av[..6]).max(rel_err(&h, &h_want));
        worst = (worst.0.max(ea), worst.1.max(et), worst.2.max(ep));
        assert!(et < 1e-12, "{}: T {et:e}", model.name());
        assert!(ep < 1e-12, "{}: momentum {ep:e}", model.name());
    }
    println!(
        "floating A vs Σ JᵀMJ {:.2e}; ½νᵀAν vs T {:.2e}; A_b ν vs momentum {:.2e}",
        worst.0, worst.1, worst.2
    );
}

fn floating_loads(r: &mut ChaCha8Rng, n: usize) -> Loads<f64> {
    Loads {
        tau: None,
        gravity: Some(v3(&random_vec(r, 3, 9.81))),
        external: wrenches(r, n, true),
    }
}

#[test]
fn floating_inverse_dynamics_is_a_nudot_minus_b() {
    let mut worst = 0.0_f64;
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let mut r = rng(700 + k as u64);
        let s = state(&mut r, n);
        for loads in [Loads::default(), floating_loads(&mut r, n)] {
            let d = floating::dynamics(
                Methods::SPATIAL,
                &p,
                &s.base,
                &s.floating,
                &s.q,
                &s.qd,
                &loads,
            );
            let mut nud = s.base_acc.to_vec();
            nud.extend(&s.qdd);
            let want = sub(&mat_vec(&d.mass_matrix, &nud), &d.tau_minus_c);
            let id = rnea::floating_inverse_dynamics(
                &p,
                &s.base,
                &s.floating,
                &s.q,
                &s.qd,
                &s.base_acc,
                &s.qdd,
                &loads,
            );
            let e = rel_err(&id, &want);
            worst = worst.max(e);
            assert!(e < 1e-12, "{}: {e:e}", model.name());
            // Forward dynamics inverts it: with τ = id[6..] and the base wrench applied as an
            // external base wrench, ν̇ comes back.
            let mut driven = loads.clone();
            driven.tau = Some(id[6..].to_vec());
            let r0 = &s.floating.rotation;
            driven.external.push(ExternalWrench {
                body: BASE_BODY,
                frame: LoadFrame::Base,
                force: r0.mul_vec(&v3(&id[..3])),
                moment: r0.mul_vec(&v3(&id[3..6])),
            });
            let back = floating::forward_dynamics(
                Methods::SPATIAL,
                &p,
                &s.base,
                &s.floating,
                &s.q,
                &s.qd,
                &driven,
            );
            let e = rel_err(&back, &nud);
            assert!(e < 1e-9, "{}: forward ∘ inverse {e:e}", model.name());
        }
    }
    println!("floating ID vs A ν̇ − b on random trees: {worst:.2e}");
}

/// Second-order motion from `s` for a time `t`: joints `q + t q̇ + ½t² q̈`, base pose
/// `p₀ + t R₀v_b + ½t² R₀(ω_b × v_b + v̇_b)`, `R₀ exp((t ω_b + ½t² ω̇_b)~)`, base twist
/// `ν_b + t ν̇_b` (exact to O(t³), enough for central differences).
fn at(s: &State, t: f64) -> (FloatingState<f64>, Vec<f64>, Vec<f64>) {
    let f = &s.floating;
    let vd = v3(&s.base_acc[..3]);
    let wd = v3(&s.base_acc[3..]);
    let acc = &f.omega_b.cross(&f.v_b) + &vd;
    let position = &(&f.position + &f.rotation.mul_vec(&f.v_b.scale(&t)))
        + &f.rotation.mul_vec(&acc.scale(&(0.5 * t * t)));
    let phi = &f.omega_b.scale(&t) + &wd.scale(&(0.5 * t * t));
    let angle = phi.dot(&phi).sqrt();
    let u = phi.scale(&(1.0 / angle));
    let state = FloatingState {
        position,
        rotation: f
            .rotation
            .mul_mat(&axis_rotation(&u, &angle.sin(), &angle.cos())),
        v_b: &f.v_b + &vd.scale(&t),
        omega_b: &f.omega_b + &wd.scale(&t),
    };
    let q = (0..s.q.len())
        .map(|i| s.q[i] + t * s.qd[i] + 0.5 * t * t * s.qdd[i])
        .collect();
    let qd = (0..s.q.len()).map(|i| s.qd[i] + t * s.qdd[i]).collect();
    (state, q, qd)
}

/// `ḣ = [Ṗ; L̇_O]` (inertial frame, about the inertial origin) of the base `base` and the tree, by
/// central differences along [`at`].
fn momentum_rate(p: &Params<f64>, base: &FloatingBase<f64>, s: &State) -> Vec<f64> {
    let h = 1e-4;
    let m = |t: f64| {
        let (st, q, qd) = at(s, t);
        let (l, a) = momentum::momentum(p, base, &st, &q, &qd);
        let mut v = l.0.to_vec();
        v.extend(a.0);
        v
    };
    sub(&m(h), &m(-h))
        .into_iter()
        .map(|x| x / (2.0 * h))
        .collect()
}

/// A wrench `[f; n]` (force, moment about the base origin, base coordinates) in the inertial
/// frame about the inertial origin.
fn to_inertial(s: &FloatingState<f64>, w: &[f64]) -> Vec<f64> {
    let f = s.rotation.mul_vec(&v3(&w[..3]));
    let n = &s.rotation.mul_vec(&v3(&w[3..6])) + &s.position.cross(&f);
    f.0.iter().chain(n.0.iter()).copied().collect()
}

/// The gravity and external wrenches of `loads` on the arm bodies (and on the base when
/// `base` is given), inertial frame, about the inertial origin.
fn applied(
    p: &Params<f64>,
    s: &State,
    loads: &Loads<f64>,
    base: Option<&FloatingBase<f64>>,
) -> Vec<f64> {
    let n = p.dof();
    let g = loads.gravity.clone().unwrap_or_else(Vec3::zero);
    let mut f = Vec3::zero();
    let mut m = Vec3::zero();
    let mut add = |force: Vec3<f64>, at: &Vec3<f64>, moment: Vec3<f64>| {
        m = &(&m + &at.cross(&force)) + &moment;
        f = &f + &force;
    };
    for b in 0..n {
        let (xc, _) =
            frames::floating_placement(p, &s.floating, &s.q, &com_frame(p, Some(b), &Vec3::zero()));
        add(g.scale(&p.joints[b].mass), &xc, Vec3::zero());
    }
    if let Some(base) = base {
        let (xc, _) =
            frames::floating_placement(p, &s.floating, &s.q, &com_frame(p, None, &base.com));
        add(g.scale(&base.mass), &xc, Vec3::zero());
    }
    for w in &loads.external {
        let body = (w.body != BASE_BODY).then_some(w.body);
        if body.is_none() && base.is_none() {
            continue;
        }
        let origin = FrameParams {
            parent: body,
            translation: Vec3::zero(),
            rotation: Mat3::identity(),
        };
        let (x, rot) = frames::floating_placement(p, &s.floating, &s.q, &origin);
        let (force, moment) = match w.frame {
            LoadFrame::Base => (w.force.clone(), w.moment.clone()),
            LoadFrame::Body => (rot.mul_vec(&w.force), rot.mul_vec(&w.moment)),
        };
        add(force, &x, moment);
    }
    f.0.iter().chain(m.0.iter()).copied().collect()
}

#[test]
fn base_wrench_and_reaction_are_momentum_rates() {
    let (mut worst_total, mut worst_arm, mut worst_newton) = (0.0_f64, 0.0_f64, 0.0_f64);
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let mut r = rng(800 + k as u64);
        let s = state(&mut r, n);
        let loads = floating_loads(&mut r, n);
        let id = rnea::floating_inverse_dynamics(
            &p,
            &s.base,
            &s.floating,
            &s.q,
            &s.qd,
            &s.base_acc,
            &s.qdd,
            &loads,
        );
        let reaction =
            rnea::base_reaction(&p, &s.floating, &s.q, &s.qd, &s.base_acc, &s.qdd, &loads);
        // The whole system: ḣ_O = w_b + applied loads (gravity on every body, all wrenches).
        let rate = momentum_rate(&p, &s.base, &s);
        let want = applied(&p, &s, &loads, Some(&s.base));
        let want: Vec<f64> = to_inertial(&s.floating, &id[..6])
            .iter()
            .zip(&want)
            .map(|(a, b)| a + b)
            .collect();
        let e_total = rel_err(&rate, &want);
        // The arm alone (a massless base carries no momentum): ḣ_arm = −reaction + loads on the
        // arm (the base pushes the arm with minus the arm's push on the base).
        let massless = FloatingBase::new(0.0, Vec3::zero(), Mat3::zero());
        let rate_arm = momentum_rate(&p, &massless, &s);
        let want_arm: Vec<f64> = to_inertial(&s.floating, &reaction)
            .iter()
            .zip(applied(&p, &s, &loads, None))
            .map(|(a, b)| b - a)
            .collect();
        let e_arm = rel_err(&rate_arm, &want_arm);
        // Newton–Euler of the base body alone, about its origin in base coordinates:
        // w_b + reaction + loads on the base = (m a_c, I_c ω̇ + ω × I_c ω + c × m a_c).
        let (c, ic, m) = (&s.base.com, &s.base.inertia_com, s.base.mass);
        let (v, w) = (&s.floating.v_b, &s.floating.omega_b);
        let (vd, wd) = (v3(&s.base_acc[..3]), v3(&s.base_acc[3..]));
        let a_c = &(&(&vd + &w.cross(v)) + &wd.cross(c)) + &w.cross(&w.cross(c));
        let f_need = a_c.scale(&m);
        let n_need = &(&ic.mul_vec(&wd) + &w.cross(&ic.mul_vec(w))) + &c.cross(&f_need);
        let r0t = s.floating.rotation.transpose();
        let g_b = r0t.mul_vec(loads.gravity.as_ref().unwrap());
        let mut f_loads = g_b.scale(&m);
        let mut n_loads = c.cross(&f_loads);
        for e in loads.external.iter().filter(|e| e.body == BASE_BODY) {
            assert_eq!(e.frame, LoadFrame::Base);
            f_loads = &f_loads + &r0t.mul_vec(&e.force);
            n_loads = &n_loads + &r0t.mul_vec(&e.moment);
        }
        let isolated: Vec<f64> = (&f_need - &f_loads)
            .0
            .iter()
            .chain((&n_need - &n_loads).0.iter())
            .copied()
            .collect();
        let newton: Vec<f64> = isolated.iter().zip(&reaction).map(|(a, b)| a - b).collect();
        let e_newton = rel_err(&id[..6], &newton);
        worst_total = worst_total.max(e_total);
        worst_arm = worst_arm.max(e_arm);
        worst_newton = worst_newton.max(e_newton);
        assert!(
            e_total < 1e-6,
            "{}: ḣ vs w_b + loads {e_total:e}",
            model.name()
        );
        assert!(
            e_arm < 1e-6,
            "{}: ḣ_arm vs −reaction + loads {e_arm:e}",
            model.name()
        );
        assert!(
            e_newton < 1e-12,
            "{}: w_b = isolated − reaction {e_newton:e}",
            model.name()
        );
    }
    println!(
        "ḣ vs w_b + loads {worst_total:.2e}; ḣ_arm vs −reaction + loads {worst_arm:.2e}; \
         w_b vs isolated − reaction {worst_newton:.2e}"
    );
}

#[test]
fn generalized_jacobian_is_the_frame_motion_at_zero_momentum() {
    let h = 1e-5;
    let mut worst = 0.0_f64;
    for (k, model) in trees().iter().enumerate() {
        let n = model.dof();
        let p = Params::<f64>::new(model);
        let mut r = rng(1000 + k as u64);
        let mut s = state(&mut r, n);
        // Zero momentum: ν_b = −A_bb⁻¹ A_bm q̇.
        let a = crba::floating_mass_matrix(&p, &s.base, &s.q);
        let a_bb: Vec<Vec<f64>> = a[..6].iter().map(|row| row[..6].to_vec()).collect();
        let rhs: Vec<f64> = (0..6)
            .map(|i| -(0..n).map(|j| a[i][6 + j] * s.qd[j]).sum::<f64>())
            .collect();
        let nub = solve(&ldlt(&a_bb), &rhs);
        s.floating.v_b = v3(&nub[..3]);
        s.floating.omega_b = v3(&nub[3..]);
        let (lin, ang) = momentum::momentum(&p, &s.base, &s.floating, &s.q, &s.qd);
        let scale = a[6..].iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(
            lin.dot(&lin).sqrt() + ang.dot(&ang).sqrt() < 1e-11 * scale * 10.0,
            "{}: momentum not zero",
            model.name()
        );
        for _ in 0..3 {
            let f = random_frame(&mut r, n);
            let js = frames::generalized_jacobian(&p, &s.base, &s.floating, &s.q, &f);
            assert_eq!((js.len(), js[0].len()), (6, n));
            let got = mat_vec(&js, &s.qd);
            let plus = frames::floating_placement(
                &p,
                &moved(&s.floating, h),
                &shifted(&s.q, &s.qd, h),
                &f,
            );
            let minus = frames::floating_placement(
                &p,
                &moved(&s.floating, -h),
                &shifted(&s.q, &s.qd, -h),
                &f,
            );
            let e = rel_err(&got, &twist_fd(&plus, &minus, h));
            worst = worst.max(e);
            assert!(e < 1e-8, "{}: {e:e}", model.name());
        }
    }
    println!("J* q̇ vs the frame's motion at zero momentum: {worst:.2e}");
}

// ---------------------------------------------------------------------------------------------
// 4. Chain-only methods say so; chains are unchanged.
// ---------------------------------------------------------------------------------------------

/// A branching tree (joint 2 hangs from body 0).
fn branching() -> (Model, Params<f64>) {
    let model = (0..50)
        .map(|s| tree(5, s))
        .find(|m| m.first_branch().is_some())
        .expect("a branching tree");
    let p = Params::new(&model);
    (model, p)
}

#[test]
fn check_names_the_method_and_the_first_branching_joint() {
    let (model, p) = branching();
    let j = p.first_branch().unwrap();
    assert_eq!(model.first_branch().unwrap().name, model.joints()[j].name);
    for m in Methods::ALL {
        let r = m.check(&p);
        assert_eq!(r.is_ok(), m == Methods::SPATIAL, "{m}");
        assert_eq!(m.supports_trees(), m == Methods::SPATIAL, "{m}");
        if let Err(e) = r {
            let text = e.to_string();
            assert!(
                text.contains(&format!("`{}`", m.mass_matrix.name())),
                "{text}"
            );
            assert!(text.contains(&format!("joint #{j}")), "{text}");
            assert!(text.contains("serial chains only"), "{text}");
        }
    }
    assert!(
        !NonlinearEffectsMethod::Recurrent.supports_trees()
            && NonlinearEffectsMethod::Rnea.supports_trees()
    );
    assert!(MassMatrixMethod::ALL
        .iter()
        .all(|m| m.supports_trees() == (*m == MassMatrixMethod::Crba)));
    let e = Methods {
        nonlinear_effects: NonlinearEffectsMethod::KaneDirect,
        ..Methods::SPATIAL
    }
    .check(&p)
    .unwrap_err();
    assert_eq!((e.method, e.joint), ("kane-direct", j));
    // Every method runs on a chain.
    let chain = Params::<f64>::new(&random_chain(&ChainSpec::default(), 1));
    assert!(Methods::ALL.iter().all(|m| m.check(&chain).is_ok()));
}

macro_rules! panics_on_a_tree {
    ($($name:ident, $expected:literal, |$p:ident, $q:ident| $call:expr;)*) => {$(
        #[test]
        #[should_panic(expected = $expected)]
        fn $name() {
            let (model, $p) = branching();
            let $q = vec![0.1; model.dof()];
            let _ = $call;
        }
    )*};
}

panics_on_a_tree! {
    recurrent_mass_matrix_panics_on_a_tree, "method `recurrent` handles serial chains only",
        |p, q| recurrent::mass_matrix(&p, &q, recurrent::Variant::R2);
    recurrent_r1_panics_on_a_tree, "method `recurrent-r1` handles serial chains only",
        |p, q| MassMatrixMethod::RecurrentR1.mass_matrix(&p, &q);
    recurrent_bias_panics_on_a_tree, "method `recurrent` handles serial chains only",
        |p, q| recurrent::tau_minus_c(&p, &q, &q, &Loads::default());
    kane_direct_panics_on_a_tree, "method `kane-direct` handles serial chains only",
        |p, q| kane_direct::tau_minus_c(&p, &q, &q, &Loads::default());
    crba_inertial_panics_on_a_tree, "method `crba-inertial` handles serial chains only",
        |p, q| crba_inertial::mass_matrix(&p, &q);
    inertial_frame_kinematics_panics_on_a_tree, "handles serial chains only",
        |p, q| kinematics::inertial_frame(&p, &q);
    floating_virtual_joints_panic_on_a_tree, "method `crba-inertial` handles serial chains only",
        |p, q| floating::mass_matrix(
            MassMatrixMethod::CrbaInertial,
            &p,
            &FloatingBase::from_inertial(&random_inertial(&mut rng(1), 10.0, 1.0)),
            &FloatingState::at_rest(),
            &q,
        );
    floating_bias_virtual_joints_panic_on_a_tree, "method `recurrent` handles serial chains only",
        |p, q| floating::tau_minus_c(
            NonlinearEffectsMethod::Recurrent,
            &p,
            &FloatingBase::from_inertial(&random_inertial(&mut rng(1), 10.0, 1.0)),
            &FloatingState::at_rest(),
            &q,
            &q,
            &Loads::default(),
        );
}

#[test]
fn random_trees_are_seeded_and_valid() {
    let spec = ChainSpec {
        n: 9,
        prismatic_fraction: 0.4,
        ..Default::default()
    };
    assert_eq!(random_tree(&spec, 5), random_tree(&spec, 5));
    assert_ne!(random_tree(&spec, 5), random_tree(&spec, 6));
    let m = random_tree(&spec, 5);
    assert!(m
        .joints()
        .iter()
        .enumerate()
        .all(|(j, jt)| jt.parent.is_none_or(|p| p < j)));
    let kinds: std::collections::HashSet<_> = (0..20)
        .flat_map(|s| random_tree(&spec, s).joints().to_vec())
        .map(|j| j.kind)
        .collect();
    assert_eq!(kinds.len(), 2, "revolute and prismatic joints");
    let roots = (0..20)
        .map(|s| {
            random_tree(&spec, s)
                .joints()
                .iter()
                .filter(|j| j.parent.is_none())
                .count()
        })
        .max()
        .unwrap();
    assert!(roots >= 2, "several subtrees on the base");
}
