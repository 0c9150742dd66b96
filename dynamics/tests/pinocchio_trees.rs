//! Fifteen real robots (example-robot-data URDFs in `tests/data/erd/`, serial arms and the trees
//! Panda, B1+Z1 and ANYmal+Kinova) against Pinocchio 4.1 (`<name>.reference.json`, conventions in
//! its "conventions" text):
//!
//! - fixed base, 10 states each: `A` and `b` without and with gravity `(0, 0, −9.81)` by the
//!   local-frame methods (CRBA + RNEA) on every model, and by every inertial-frame method on the
//!   serial chains; the world placement of every fixed link frame;
//! - free-flyer, 10 states each: `A`, `b` (gravity zero), the total momentum (inertial frame,
//!   about the origin, and about the base origin in base coordinates), the kinetic energy, and
//!   the floating inverse dynamics at `ν̇ = 0` (`= −b`).
//!
//! Pinocchio lists the joints depth first with the children of a link sorted by joint name;
//! kanegen keeps the URDF's file order, so every vector and matrix is permuted by joint name.
//! Errors are relative, `max|x − y| / max|y|`, per model over its states; run with
//! `--nocapture` for the table.

// Matrix identities read best with explicit indices.
#![allow(clippy::needless_range_loop)]

use kanegen_dynamics::algorithms::{floating, frames, momentum, rnea};
use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::metrics::{rel_err, rel_err_mat};
use kanegen_dynamics::{Loads, MassMatrixMethod, Methods, NonlinearEffectsMethod, Params};
use kanegen_model::io::load_model;
use kanegen_model::{BaseKind, Inertial, Model};
use serde_json::Value;
use std::path::PathBuf;

const TOL: f64 = 1e-9;

fn data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/data/erd")
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

fn mat(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().expect("rows").iter().map(f64s).collect()
}

fn arr3(v: &Value) -> [f64; 3] {
    f64s(v).try_into().expect("3 numbers")
}

fn inertial(v: &Value) -> Inertial {
    let m = mat(&v["inertia"]);
    Inertial {
        mass: v["mass"].as_f64().unwrap(),
        com: arr3(&v["com"]),
        inertia: core::array::from_fn(|i| core::array::from_fn(|j| m[i][j])),
    }
}

/// One reference file with its model: `perm[k]` is kanegen's index of Pinocchio's joint `k`.
struct Robot {
    name: String,
    json: Value,
    model: Model,
    perm: Vec<usize>,
}

impl Robot {
    /// Pinocchio-ordered vector → kanegen order.
    fn to_ours(&self, x: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; x.len()];
        for (k, &i) in self.perm.iter().enumerate() {
            out[i] = x[k];
        }
        out
    }
    /// kanegen-ordered vector → Pinocchio order (`off` leading entries kept in place).
    fn to_pin(&self, x: &[f64], off: usize) -> Vec<f64> {
        let mut out = x[..off].to_vec();
        out.extend(self.perm.iter().map(|&i| x[off + i]));
        out
    }
    /// kanegen-ordered matrix → Pinocchio order (`off` leading rows and columns kept in place).
    fn mat_to_pin(&self, a: &[Vec<f64>], off: usize) -> Vec<Vec<f64>> {
        let idx: Vec<usize> = (0..off).chain(self.perm.iter().map(|&i| off + i)).collect();
        idx.iter()
            .map(|&r| idx.iter().map(|&c| a[r][c]).collect())
            .collect()
    }
}

fn robots() -> Vec<Robot> {
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(data().join("index.json")).unwrap()).unwrap();
    let models = index["models"].as_array().unwrap();
    assert_eq!(models.len(), 15, "fifteen reference robots");
    models
        .iter()
        .map(|m| {
            let name = m["name"].as_str().unwrap().to_string();
            let model = load_model(&data().join(m["urdf"].as_str().unwrap()))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let json: Value = serde_json::from_str(
                &std::fs::read_to_string(data().join(m["reference"].as_str().unwrap())).unwrap(),
            )
            .unwrap();
            let joints = json["joints"].as_array().unwrap();
            assert_eq!(joints.len(), model.dof(), "{name}: dof");
            let perm: Vec<usize> = joints
                .iter()
                .map(|j| {
                    let jn = j["name"].as_str().unwrap();
                    model
                        .joints()
                        .iter()
                        .position(|ours| ours.name == jn)
                        .unwrap_or_else(|| panic!("{name}: no joint `{jn}`"))
                })
                .collect();
            // The same tree: Pinocchio's parent joint is kanegen's parent body.
            for (k, j) in joints.iter().enumerate() {
                let want = j["parent"]
                    .as_str()
                    .map(|pj| model.joints().iter().position(|o| o.name == pj).unwrap());
                assert_eq!(
                    model.joints()[perm[k]].parent,
                    want,
                    "{name}: parent of {k}"
                );
            }
            Robot {
                name,
                json,
                model,
                perm,
            }
        })
        .collect()
}

/// The worst relative errors of one model, for the table.
#[derive(Default)]
struct Worst {
    a: f64,
    b0: f64,
    bg: f64,
    frames: f64,
    inertial_frame_methods: f64,
}

#[test]
fn fixed_base_matches_pinocchio() {
    let gravity = Loads {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        ..Loads::default()
    };
    let mut trees = 0;
    for r in robots() {
        let p = Params::<f64>::new(&r.model);
        let fixed = &r.json["fixed"];
        assert_eq!(f64s(&fixed["gravity"]), [0.0, 0.0, -9.81]);
        let chain = r.model.is_chain();
        trees += usize::from(!chain);
        // Every "body" frame is one of ours, on the same body.
        let ref_frames = r.json["frames"].as_array().unwrap();
        let body_frames: Vec<(usize, usize)> = ref_frames
            .iter()
            .enumerate()
            .filter(|(_, f)| f["kind"] == "body")
            .map(|(k, f)| {
                let fname = f["name"].as_str().unwrap();
                let ours = r
                    .model
                    .frames()
                    .iter()
                    .position(|o| o.name == fname)
                    .unwrap_or_else(|| panic!("{}: no frame `{fname}`", r.name));
                let want = f["parent_joint"]
                    .as_str()
                    .map(|pj| r.model.joints().iter().position(|o| o.name == pj).unwrap());
                assert_eq!(r.model.frames()[ours].parent, want, "{}: {fname}", r.name);
                (k, ours)
            })
            .collect();
        assert!(!body_frames.is_empty(), "{}: no body frames", r.name);
        let mut w = Worst::default();
        let states = fixed["states"].as_array().unwrap();
        assert_eq!(states.len(), 10);
        for s in states {
            let q = r.to_ours(&f64s(&s["q"]));
            let qd = r.to_ours(&f64s(&s["qd"]));
            let a_ref = mat(&s["A"]);
            let b0_ref = f64s(&s["b_gravity_zero"]);
            let bg_ref = f64s(&s["b_gravity"]);
            let d0 = Methods::SPATIAL.dynamics(&p, &q, &qd, &Loads::default());
            let bg = Methods::SPATIAL
                .nonlinear_effects
                .tau_minus_c(&p, &q, &qd, &gravity);
            w.a =
                w.a.max(rel_err_mat(&r.mat_to_pin(&d0.mass_matrix, 0), &a_ref));
            w.b0 = w.b0.max(rel_err(&r.to_pin(&d0.tau_minus_c, 0), &b0_ref));
            w.bg = w.bg.max(rel_err(&r.to_pin(&bg, 0), &bg_ref));
            if chain {
                for m in MassMatrixMethod::ALL {
                    let a = m.mass_matrix(&p, &q);
                    let e = rel_err_mat(&r.mat_to_pin(&a, 0), &a_ref);
                    assert!(e < TOL, "{} {}: A {e:e}", r.name, m.name());
                    w.inertial_frame_methods = w.inertial_frame_methods.max(e);
                }
                for m in NonlinearEffectsMethod::ALL {
                    for (loads, want) in [(&Loads::default(), &b0_ref), (&gravity, &bg_ref)] {
                        let b = m.tau_minus_c(&p, &q, &qd, loads);
                        let e = rel_err(&r.to_pin(&b, 0), want);
                        assert!(e < TOL, "{} {}: b {e:e}", r.name, m.name());
                        w.inertial_frame_methods = w.inertial_frame_methods.max(e);
                    }
                }
            } else {
                assert!(Methods::RECURRENT.check(&p).is_err(), "{}: a tree", r.name);
            }
            // World placements of the fixed link frames.
            let placements = s["frames"].as_array().unwrap();
            assert_eq!(placements.len(), ref_frames.len());
            for &(k, ours) in &body_frames {
                let f = &p.frames[ours];
                let (x, rot) = frames::placement(&p, &q, f);
                let mut got: Vec<f64> = x.0.to_vec();
                got.extend(rot.0.iter().flatten());
                let mut want = f64s(&placements[k]["translation"]);
                want.extend(mat(&placements[k]["rotation"]).into_iter().flatten());
                // Positions in m and rotation entries share one scale (both O(1)).
                let e = rel_err(&got, &want);
                w.frames = w.frames.max(e);
            }
        }
        println!(
            "{:26} {:5} N={:2}  A {:.1e}  b(g=0) {:.1e}  b(g) {:.1e}  frames {:.1e}  inertial-frame methods {}",
            r.name,
            if chain { "chain" } else { "tree" },
            r.model.dof(),
            w.a,
            w.b0,
            w.bg,
            w.frames,
            if chain {
                format!("{:.1e}", w.inertial_frame_methods)
            } else {
                "-".into()
            }
        );
        for (what, e) in [
            ("A", w.a),
            ("b(g=0)", w.b0),
            ("b(g)", w.bg),
            ("frames", w.frames),
        ] {
            assert!(e < TOL, "{}: {what} {e:e}", r.name);
        }
    }
    assert_eq!(trees, 3, "panda, b1-z1 and anymal-kinova are trees");
}

#[test]
fn free_flyer_matches_pinocchio() {
    for r in robots() {
        let p = Params::<f64>::new(&r.model);
        let ff = &r.json["free_flyer"];
        assert_eq!(f64s(&ff["gravity"]), [0.0, 0.0, 0.0]);
        // The URDF reader's base (root link and the links fixed to it) is Pinocchio's.
        let ours = r.model.base_inertial().expect("a base inertial");
        let theirs = inertial(&ff["urdf_base_inertial"]);
        let flat = |i: &Inertial| {
            let mut v = vec![i.mass];
            v.extend(i.com);
            v.extend(i.inertia.iter().flatten());
            v
        };
        assert!(
            rel_err(&flat(ours), &flat(&theirs)) < TOL,
            "{}: base inertial",
            r.name
        );
        // The base actually used (a stand-in added to a massless root link), through the model.
        let model = r
            .model
            .clone()
            .with_base_inertial(inertial(&ff["base_inertial"]))
            .and_then(|m| m.with_base_kind(BaseKind::FreeFloating))
            .unwrap_or_else(|e| panic!("{}: {e}", r.name));
        assert_eq!(model.base_kind(), BaseKind::FreeFloating);
        let base = FloatingBase::<f64>::from_inertial(model.base_inertial().unwrap());
        let (mut ea, mut eb, mut ep, mut epb, mut et, mut eid, mut eother) = (
            0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64,
        );
        for s in ff["states"].as_array().unwrap() {
            let b = &s["base"];
            let quat: [f64; 4] = f64s(&b["quaternion"]).try_into().unwrap();
            let state = FloatingState {
                position: Vec3::from_f64(arr3(&b["position"])),
                rotation: quat_to_matrix(&quat),
                v_b: Vec3::from_f64(arr3(&b["v"])),
                omega_b: Vec3::from_f64(arr3(&b["omega"])),
            };
            let q = r.to_ours(&f64s(&s["q"]));
            let qd = r.to_ours(&f64s(&s["qd"]));
            let d = floating::dynamics(
                Methods::SPATIAL,
                &p,
                &base,
                &state,
                &q,
                &qd,
                &Loads::default(),
            );
            let a_ref = mat(&s["A"]);
            let b_ref = f64s(&s["b_gravity_zero"]);
            ea = ea.max(rel_err_mat(&r.mat_to_pin(&d.mass_matrix, 6), &a_ref));
            eb = eb.max(rel_err(&r.to_pin(&d.tau_minus_c, 6), &b_ref));
            if r.model.is_chain() {
                for m in Methods::ALL {
                    let d = floating::dynamics(m, &p, &base, &state, &q, &qd, &Loads::default());
                    let e = rel_err_mat(&r.mat_to_pin(&d.mass_matrix, 6), &a_ref)
                        .max(rel_err(&r.to_pin(&d.tau_minus_c, 6), &b_ref));
                    assert!(e < TOL, "{} {m}: {e:e}", r.name);
                    eother = eother.max(e);
                }
            }
            // Momentum, kinetic energy.
            let (lin, ang) = momentum::momentum(&p, &base, &state, &q, &qd);
            let mut h: Vec<f64> = lin.0.to_vec();
            h.extend(ang.0);
            ep = ep.max(rel_err(&h, &f64s(&s["momentum"])));
            let hb = momentum::momentum_base(&p, &base, &state, &q, &qd);
            epb = epb.max(rel_err(&hb, &f64s(&s["momentum_base"])));
            let t = momentum::kinetic_energy(&p, &base, &state, &q, &qd);
            et = et.max(rel_err(&[t], &[s["kinetic_energy"].as_f64().unwrap()]));
            // Inverse dynamics at ν̇ = 0 is the nonlinear effects, −b.
            let n = r.model.dof();
            let id = rnea::floating_inverse_dynamics(
                &p,
                &base,
                &state,
                &q,
                &qd,
                &[0.0; 6],
                &vec![0.0; n],
                &Loads::default(),
            );
            eid = eid.max(rel_err(&r.to_pin(&id, 6), &f64s(&s["nle_gravity_zero"])));
        }
        println!(
            "{:26} free-flyer  A {ea:.1e}  b {eb:.1e}  momentum {ep:.1e} (base {epb:.1e})  T {et:.1e}  ID(ν̇=0) {eid:.1e}{}",
            r.name,
            if r.model.is_chain() {
                format!("  inertial-frame methods {eother:.1e}")
            } else {
                String::new()
            }
        );
        for (what, e) in [
            ("A", ea),
            ("b", eb),
            ("momentum", ep),
            ("momentum_base", epb),
            ("T", et),
            ("ID", eid),
        ] {
            assert!(e < TOL, "{}: {what} {e:e}", r.name);
        }
    }
}
