//! Generated forward dynamics by the articulated-body algorithm, where it is the cheaper: a
//! random chain of 32 joints with gravity (`benches/data/random_n32.toml`: general geometry,
//! ABA 25462 operations against 37129 for the cheapest LDLᵀ) through `kanegen::dynamics!`, and
//! the free-floating 7-dof arm of `kanegen-generated` with ABA forced (its checked-in file takes
//! LDLᵀ, 2735 operations against ABA's 2869): the emitted code says so in `OP_COUNTS`, and
//! equals the interpreted ABA to 1e-12 (8e-14 measured), and LDLᵀ to 1e-12 on the free-flyer,
//! to 1e-10 on the 32-joint chain (cond(M) up to 1e5 there; 8e-13 measured).
//! SSRMS (coordinate axes) keeps LDLᵀ, the cheaper there, and equals both to 1e-12.

use kanegen::dynamics::algorithms::{aba, floating};
use kanegen::dynamics::base::{quat_to_matrix, FloatingBase, FloatingState, BASE_BODY};
use kanegen::dynamics::linalg::Vec3;
use kanegen::dynamics::metrics::rel_err;
use kanegen::dynamics::regroup::regrouped;
use kanegen::dynamics::{ExternalWrench, LoadFrame, Loads, Methods, Params};
use kanegen::model::random::{random_vec, rng};
use kanegen::model::Model;
use kanegen_generated::free_floating_7dof::FreeFloating7;
use kanegen_generated::ssrms::Ssrms;
use std::path::Path;

// The free-floating arm of `kanegen-generated` with ABA forced: its checked-in file takes LDLᵀ,
// the cheaper since the two-step inertia carry through near-permutation placements.
kanegen::dynamics!(
    FreeFloating7Aba,
    "tests/data/reference/bmsd_7dof_free_floating.urdf",
    base = "free-floating",
    allow_nonphysical = true,
    algorithm = "aba",
);

// Straight-line code, whose candidates are traced (a compact type's functions in loops are not).
kanegen::dynamics!(
    RandomN32,
    "benches/data/random_n32.toml",
    gravity = [0.3, -1.2, -9.81],
    form = "unrolled",
);

const TOL: f64 = 1e-12;

fn load(rel: &str) -> Model {
    kanegen::model::io::load_model(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

/// The `OP_COUNTS` entries of the functions `fs` say `aba` and no other method.
macro_rules! assert_aba_chosen {
    ($t:ident, $fs:expr) => {
        for f in $fs {
            let c = $t::OP_COUNTS.iter().find(|c| c.function == f).unwrap();
            assert_eq!(c.forward_method, Some("aba"), "{f}");
            assert_eq!((c.mass_matrix_method, c.bias_method), (None, None), "{f}");
            // The cheapest of its candidates, which include LDLᵀ.
            let cands: Vec<_> = $t::CANDIDATES.iter().filter(|x| x.function == f).collect();
            assert!(cands.iter().any(|x| x.forward_method == Some("ldlt")));
            let best = cands.iter().map(|x| x.mul + x.add).min().unwrap();
            assert_eq!(c.mul + c.add, best, "{f}");
        }
        let m = $t::OP_COUNTS
            .iter()
            .find(|c| c.function == "mass_matrix")
            .unwrap();
        assert_eq!(m.forward_method, None);
    };
}

#[test]
fn generated_aba_equals_interpreted_forward_dynamics() {
    const BOTH: [&str; 2] = ["forward_dynamics", "forward_dynamics_with_wrenches"];
    assert_aba_chosen!(RandomN32, BOTH);
    // SSRMS: LDLᵀ with the classical Newton–Euler bias (862 operations) beats ABA (944); its
    // generated forward dynamics is set beside both interpreted algorithms below.
    let fd = Ssrms::OP_COUNTS
        .iter()
        .find(|c| c.function == "forward_dynamics")
        .unwrap();
    let aba_candidate = Ssrms::CANDIDATES
        .iter()
        .find(|c| c.function == "forward_dynamics" && c.forward_method == Some("aba"))
        .unwrap();
    assert_eq!(fd.forward_method, Some("ldlt"));
    assert!(fd.mul + fd.add < aba_candidate.mul + aba_candidate.add);
    let ssrms = kanegen::cli::commands::generate::GENERATED[0]
        .model(Path::new(env!("CARGO_MANIFEST_DIR")))
        .unwrap();
    let ps = Params::<f64>::new(&ssrms);
    let chain = load("benches/data/random_n32.toml");
    let p = Params::<f64>::new(&chain);
    let gravity = Some(Vec3::new(0.3, -1.2, -9.81));
    let (mut worst, mut worst_ldlt) = (0.0_f64, 0.0_f64);
    for seed in 0..20 {
        let mut r = rng(seed);
        let mut v = |s| -> [f64; 32] { random_vec(&mut r, 32, s).try_into().unwrap() };
        let (q, qd, tau) = (v(2.5), v(1.0), v(20.0));
        let f_ext: [[f64; 6]; 32] =
            core::array::from_fn(|_| random_vec(&mut r, 6, 5.0).try_into().unwrap());
        // SSRMS, no gravity (space).
        let (q7, qd7, tau7): ([f64; 7], [f64; 7], [f64; 7]) = (
            q[..7].try_into().unwrap(),
            qd[..7].try_into().unwrap(),
            tau[..7].try_into().unwrap(),
        );
        let l7 = Loads {
            tau: Some(tau7.to_vec()),
            ..Loads::default()
        };
        let have = Ssrms::forward_dynamics(&q7, &qd7, &tau7);
        for want in [
            aba::forward_dynamics(&ps, &q7, &qd7, &l7),
            Methods::SPATIAL.forward_dynamics(&ps, &q7, &qd7, &l7),
        ] {
            let e = rel_err(&have, &want);
            assert!(e < TOL, "SSRMS seed {seed}: {e:e}");
            worst = worst.max(e);
        }
        // The random chain with gravity, without and with a wrench on every body.
        let mut loads = Loads {
            tau: Some(tau.to_vec()),
            gravity: gravity.clone(),
            external: Vec::new(),
        };
        let pairs = [
            (RandomN32::forward_dynamics(&q, &qd, &tau), false),
            (
                RandomN32::forward_dynamics_with_wrenches(&q, &qd, &tau, &f_ext),
                true,
            ),
        ];
        for (have, with) in pairs {
            if with {
                loads.external = f_ext
                    .iter()
                    .enumerate()
                    .map(|(body, w)| ExternalWrench {
                        body,
                        frame: LoadFrame::Body,
                        force: Vec3::new(w[0], w[1], w[2]),
                        moment: Vec3::new(w[3], w[4], w[5]),
                    })
                    .collect();
            }
            // The same algorithm interpreted: to 1e-12.
            let e = rel_err(&have, &aba::forward_dynamics(&p, &q, &qd, &loads));
            assert!(e < TOL, "random N = 32 seed {seed} wrenches {with}: {e:e}");
            worst = worst.max(e);
            // LDLᵀ: another algorithm, whose rounding grows with cond(M) (up to 1e5 on these
            // 32-joint chains; docs/numerics.md, hard cases): to 1e-10.
            let ldlt = Methods::SPATIAL.forward_dynamics(&p, &q, &qd, &loads);
            let e = rel_err(&have, &ldlt);
            assert!(
                e < 1e-10,
                "random N = 32 seed {seed} wrenches {with}: vs LDLᵀ {e:e}"
            );
            worst_ldlt = worst_ldlt.max(e);
        }
    }
    println!(
        "generated ABA (SSRMS, random N = 32) vs interpreted ABA: worst {worst:.1e}; random \
         N = 32 vs LDLᵀ {worst_ldlt:.1e}"
    );
}

/// The free-floating 7-dof arm, generated with ABA forced and checked in with the cheapest
/// method (LDLᵀ): both `forward_dynamics` equal the interpreted floating ABA and LDLᵀ, the
/// model's own and regrouped parameters alike.
#[test]
fn generated_floating_fd_equals_interpreted() {
    for f in ["forward_dynamics", "forward_dynamics_with_wrenches"] {
        let forced = FreeFloating7Aba::OP_COUNTS.iter().find(|c| c.function == f);
        assert_eq!(forced.unwrap().forward_method, Some("aba"), "{f}");
        let chosen = FreeFloating7::OP_COUNTS.iter().find(|c| c.function == f);
        assert_eq!(chosen.unwrap().forward_method, Some("ldlt"), "{f}");
    }
    let g = kanegen::cli::commands::generate::GENERATED
        .iter()
        .find(|g| g.type_name == "FreeFloating7")
        .unwrap();
    let model = g.model(Path::new(env!("CARGO_MANIFEST_DIR"))).unwrap();
    let model = model
        .with_base_kind(kanegen::model::BaseKind::FreeFloating)
        .unwrap();
    let inertial = model.base_inertial().unwrap().clone();
    let p = Params::<f64>::new(&model);
    let base = FloatingBase::<f64>::from_inertial(&inertial);
    let rg = regrouped::<f64>(&model, Some(&inertial), &[]);
    let mut worst = 0.0_f64;
    for seed in 0..20 {
        let mut r = rng(300 + seed);
        let mut q: [f64; 14] = random_vec(&mut r, 14, 1.5).try_into().unwrap();
        let n = q[3..7].iter().map(|x| x * x).sum::<f64>().sqrt();
        for x in &mut q[3..7] {
            *x /= n;
        }
        let v: [f64; 13] = random_vec(&mut r, 13, 1.0).try_into().unwrap();
        let tau: [f64; 7] = random_vec(&mut r, 7, 20.0).try_into().unwrap();
        let f_ext: [[f64; 6]; 8] =
            core::array::from_fn(|_| random_vec(&mut r, 6, 5.0).try_into().unwrap());
        let state = FloatingState {
            position: Vec3::new(q[0], q[1], q[2]),
            rotation: quat_to_matrix(&[q[3], q[4], q[5], q[6]]),
            v_b: Vec3::new(v[0], v[1], v[2]),
            omega_b: Vec3::new(v[3], v[4], v[5]),
        };
        let mut loads = Loads {
            tau: Some(tau.to_vec()),
            ..Loads::default()
        };
        let pairs = [
            (
                FreeFloating7::forward_dynamics(&q, &v, &tau).to_vec(),
                false,
            ),
            (
                FreeFloating7Aba::forward_dynamics(&q, &v, &tau).to_vec(),
                false,
            ),
            (
                FreeFloating7::forward_dynamics_with_wrenches(&q, &v, &tau, &f_ext).to_vec(),
                true,
            ),
            (
                FreeFloating7Aba::forward_dynamics_with_wrenches(&q, &v, &tau, &f_ext).to_vec(),
                true,
            ),
        ];
        for (have, with) in pairs {
            if with {
                loads.external = f_ext
                    .iter()
                    .enumerate()
                    .map(|(r, w)| ExternalWrench {
                        body: if r == 0 { BASE_BODY } else { r - 1 },
                        frame: LoadFrame::Body,
                        force: Vec3::new(w[0], w[1], w[2]),
                        moment: Vec3::new(w[3], w[4], w[5]),
                    })
                    .collect();
            }
            let (qj, vj) = (&q[7..], &v[6..]);
            let rb = rg.base.as_ref().unwrap();
            for want in [
                aba::floating(&p, &base, &state, qj, vj, &loads),
                aba::floating(&rg.params, rb, &state, qj, vj, &loads),
                floating::forward_dynamics(Methods::SPATIAL, &p, &base, &state, qj, vj, &loads),
            ] {
                let e = rel_err(&have, &want);
                assert!(e < TOL, "seed {seed} wrenches {with}: {e:e}");
                worst = worst.max(e);
            }
        }
    }
    println!("generated floating ABA vs interpreted: worst {worst:.1e}");
}
