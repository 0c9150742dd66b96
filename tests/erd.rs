//! Real robots from example-robot-data (UR3/5/10, Panda, xArm7, Kinova, TALOS arm, Z1, and two
//! legged robots carrying an arm): serial arms with fixed side frames, and moving branches
//! (Panda's fingers, B1 + Z1, ANYmal + Kinova) as trees. `kanegen eval` on each URDF against
//! Pinocchio 4.1's values (`tests/data/erd/*.reference.json`, `tools/reference/`): fixed base
//! with gravity zero and (0, 0, −9.81), and free-floating with the root link as the base, to 1e-9
//! relative. Pinocchio orders sibling joints by name, kanegen by the file: `eval --json` lists
//! its joint order, and the reference is permuted by name. Panda's finger mimic is left to the
//! whole-set test (these references read the URDFs with Pinocchio's `mimic=False`).
//!
//! The whole example-robot-data 6.0 set (`tests/data/erd_all/`, `tools/reference/erd_all.py`):
//! every other URDF whose joints are revolute, continuous, prismatic, fixed or mimic, against
//! Pinocchio with `mimic=True` (or `Gᵀ A G` of `mimic=False` where Pinocchio's mimic reader
//! refuses the file), fixed base with gravity and free-floating, to 1e-9 relative; the files
//! not copied are listed with the reason.

mod common;

use common::nums;
use kanegen::dynamics::metrics::rel_err;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/erd")
}

fn models() -> Vec<String> {
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("index.json")).unwrap()).unwrap();
    let v: Vec<String> = index["models"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["mimic_joints"].as_array().unwrap().is_empty())
        .map(|m| m["name"].as_str().unwrap().to_string())
        .collect();
    assert!(v.len() >= 14, "{} models", v.len());
    v
}

fn eval(urdf: &Path, states: &Value, args: &[&str]) -> Value {
    let tmp = std::env::temp_dir().join(format!(
        "kanegen-erd-{}-{}.json",
        std::process::id(),
        urdf.file_stem().unwrap().to_string_lossy()
    ));
    std::fs::write(&tmp, states.to_string()).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .arg("eval")
        .arg(urdf)
        .arg("--states")
        .arg(&tmp)
        .arg("--json")
        .args(args)
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&tmp);
    assert!(
        out.status.success(),
        "{}: {}",
        urdf.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `perm[k]` = Pinocchio's index of kanegen's joint `k`; the reference lists its joints as
/// objects with a `name` or as names.
fn permutation(r: &Value, ours: &[String]) -> Vec<usize> {
    let pin: Vec<&str> = r["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().or_else(|| j["name"].as_str()).unwrap())
        .collect();
    assert_eq!(pin.len(), ours.len(), "joint count: {pin:?} vs {ours:?}");
    ours.iter()
        .map(|n| pin.iter().position(|p| p == n).expect("joint in both"))
        .collect()
}

/// Reference matrix `a` (n × n, Pinocchio order) in kanegen's order; `offset` leading speeds
/// (the free-floating base's six) keep their place.
fn permute_matrix(a: &[f64], perm: &[usize], offset: usize) -> Vec<f64> {
    let idx: Vec<usize> = (0..offset).chain(perm.iter().map(|p| p + offset)).collect();
    let n = idx.len();
    (0..n)
        .flat_map(|i| idx.iter().map(move |&j| (i, j)))
        .map(|(i, j)| a[idx[i] * n + j])
        .collect()
}

fn permute_vector(b: &[f64], perm: &[usize], offset: usize) -> Vec<f64> {
    (0..offset)
        .chain(perm.iter().map(|p| p + offset))
        .map(|i| b[i])
        .collect()
}

/// Relative errors of `A` and `b` of each result of `got` against the reference states (key
/// `key` for `b`; `offset` leading base speeds), with the state's index.
fn state_errors(
    got: &Value,
    states: &[Value],
    perm: &[usize],
    offset: usize,
    key: &str,
) -> Vec<(usize, f64, f64)> {
    let results = got["results"].as_array().unwrap();
    assert_eq!(results.len(), states.len(), "one result per state");
    results
        .iter()
        .zip(states)
        .enumerate()
        .map(|(k, (g, s))| {
            let a = permute_matrix(&nums(&s["A"]), perm, offset);
            let b = permute_vector(&nums(&s[key]), perm, offset);
            (k, rel_err(&nums(&g["A"]), &a), rel_err(&nums(&g["b"]), &b))
        })
        .collect()
}

#[test]
fn fixed_base_eval_matches_pinocchio_on_real_urdfs() {
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for name in models() {
        let r: Value = serde_json::from_str(
            &std::fs::read_to_string(dir().join(format!("{name}.reference.json"))).unwrap(),
        )
        .unwrap();
        let urdf = dir().join(format!("{name}.urdf"));
        let states = r["fixed"]["states"].as_array().unwrap();
        let probe = eval(&urdf, &json!({ "states": [] }), &[]);
        let ours: Vec<String> = probe["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap().to_string())
            .collect();
        assert_eq!(probe["base"], "fixed");
        let perm = permutation(&r, &ours);
        let to_ours = |v: &Value| -> Vec<f64> {
            let x = nums(v);
            perm.iter().map(|&i| x[i]).collect()
        };
        let input = json!({ "states": states.iter().map(|s| json!({
            "q": to_ours(&s["q"]), "qd": to_ours(&s["qd"]) })).collect::<Vec<_>>() });
        // Trees take the local-frame algorithms; chains every algorithm.
        let joints = r["joints"].as_array().unwrap();
        let chain = joints.iter().enumerate().all(|(k, j)| match k {
            0 => j["parent"].is_null(),
            _ => j["parent"] == joints[k - 1]["name"],
        });
        let algorithms: &[&str] = if chain {
            &[
                "recurrent",
                "recurrent-r1",
                "kane-direct",
                "crba-inertial",
                "spatial",
            ]
        } else {
            &["spatial"]
        };
        for alg in algorithms {
            for (key, gravity) in [("b_gravity_zero", None), ("b_gravity", Some("0,0,-9.81"))] {
                let mut args = vec!["--algorithm", alg];
                if let Some(g) = gravity {
                    args.extend(["--gravity", g]);
                }
                let got = eval(&urdf, &input, &args);
                for (k, ea, eb) in state_errors(&got, states, &perm, 0, key) {
                    worst = worst.max(ea).max(eb);
                    assert!(
                        ea < 1e-9 && eb < 1e-9,
                        "{name} {alg} {key} state {k}: A {ea:.2e}, b {eb:.2e}"
                    );
                    checked += 2;
                }
            }
        }
    }
    eprintln!("fixed base: {checked} matrices and vectors against Pinocchio, worst {worst:.2e}");
}

#[test]
fn free_floating_eval_matches_pinocchio_free_flyer() {
    let mut worst: f64 = 0.0;
    let mut models_checked = 0;
    for name in models() {
        let r: Value = serde_json::from_str(
            &std::fs::read_to_string(dir().join(format!("{name}.reference.json"))).unwrap(),
        )
        .unwrap();
        // The base inertial is the URDF root link's with the links fixed to it; models whose
        // root is massless got a stand-in in the reference, which a URDF cannot say.
        if r["free_flyer"]["stand_in_added"].as_bool().unwrap() {
            continue;
        }
        models_checked += 1;
        let urdf = dir().join(format!("{name}.urdf"));
        let states = r["free_flyer"]["states"].as_array().unwrap();
        let probe = eval(
            &urdf,
            &json!({ "states": [] }),
            &["--base", "free-floating", "--algorithm", "spatial"],
        );
        assert_eq!(probe["base"], "free-floating");
        let ours: Vec<String> = probe["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j.as_str().unwrap().to_string())
            .collect();
        let perm = permutation(&r, &ours);
        let to_ours = |v: &Value| -> Vec<f64> {
            let x = nums(v);
            perm.iter().map(|&i| x[i]).collect()
        };
        let input = json!({ "states": states.iter().map(|s| json!({
            "q": to_ours(&s["q"]), "qd": to_ours(&s["qd"]), "base": s["base"].clone() }))
            .collect::<Vec<_>>() });
        let got = eval(
            &urdf,
            &input,
            &["--base", "free-floating", "--algorithm", "spatial"],
        );
        for (k, ea, eb) in state_errors(&got, states, &perm, 6, "b_gravity_zero") {
            worst = worst.max(ea).max(eb);
            assert!(
                ea < 1e-9 && eb < 1e-9,
                "{name} free-floating state {k}: A {ea:.2e}, b {eb:.2e}"
            );
        }
    }
    assert!(
        models_checked >= 3,
        "{models_checked} models without a stand-in base"
    );
    eprintln!("free-floating: {models_checked} models against Pinocchio, worst {worst:.2e}");
}

fn dir_all() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/erd_all")
}

/// The files of the package that are not physically realisable (a negative principal moment,
/// the triangle inequality violated, or rotational inertia without mass): kanegen refuses them
/// unless `--allow-nonphysical`, as docs/models.md says.
const NONPHYSICAL: [&str; 6] = [
    "bolt",
    "romeo_laas_small",
    "romeo_small",
    "tiago",
    "tiago_dual",
    "tiago_no_hand",
];

/// `kanegen eval --json` of no state, with `--allow-nonphysical` when the plain load refuses the
/// file for that reason (then the message must name the override in both spellings); the
/// coordinate names and whether the override was needed.
fn probe(urdf: &Path, base: &[&str]) -> (Vec<String>, bool) {
    let empty = std::env::temp_dir().join(format!("kanegen-erd-probe-{}.json", std::process::id()));
    std::fs::write(&empty, r#"{"states": []}"#).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .args(["eval", "--json", "--states"])
        .arg(&empty)
        .arg(urdf)
        .args(base)
        .output()
        .unwrap();
    let nonphysical = !out.status.success();
    let v = if nonphysical {
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(
            e.contains("--allow-nonphysical") && e.contains("allow_nonphysical = true"),
            "{}: {e}",
            urdf.display()
        );
        let mut args = base.to_vec();
        args.push("--allow-nonphysical");
        eval(urdf, &json!({ "states": [] }), &args)
    } else {
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let joints = v["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap().to_string())
        .collect();
    (joints, nonphysical)
}

/// Compares `kanegen eval` with the reference states of one base (`offset` leading base
/// speeds); the worst relative error.
fn compare_all(
    name: &str,
    urdf: &Path,
    r: &Value,
    states: &[Value],
    args: &[&str],
    offset: usize,
) -> f64 {
    let (ours, nonphysical) = probe(urdf, &args[..args.len().min(2)]);
    let perm = permutation(r, &ours);
    let to_ours = |v: &Value| -> Vec<f64> {
        let x = nums(v);
        perm.iter().map(|&i| x[i]).collect()
    };
    let input = json!({ "states": states.iter().map(|s| {
        let mut st = json!({ "q": to_ours(&s["q"]), "qd": to_ours(&s["qd"]) });
        if offset > 0 {
            st["base"] = s["base"].clone();
        }
        st
    }).collect::<Vec<_>>() });
    let mut args = args.to_vec();
    if nonphysical {
        args.push("--allow-nonphysical");
    }
    let got = eval(urdf, &input, &args);
    let mut worst: f64 = 0.0;
    for (k, ea, eb) in state_errors(&got, states, &perm, offset, "b") {
        worst = worst.max(ea).max(eb);
        assert!(
            ea < 1e-9 && eb < 1e-9,
            "{name} {args:?} state {k}: A {ea:.2e}, b {eb:.2e}"
        );
    }
    worst
}

#[test]
fn the_whole_example_robot_data_set_matches_pinocchio() {
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(dir_all().join("index.json")).unwrap())
            .unwrap();
    for s in index["not_copied"].as_array().unwrap() {
        eprintln!(
            "not checked: {}: {}",
            s["source"].as_str().unwrap(),
            s["reason"].as_str().unwrap()
        );
    }
    let models = index["models"].as_array().unwrap();
    assert!(models.len() >= 45, "{} models", models.len());
    let (mut worst, mut nonphysical, mut mimic) = (0.0_f64, Vec::new(), 0);
    for m in models {
        let name = m["name"].as_str().unwrap();
        let r: Value = serde_json::from_str(
            &std::fs::read_to_string(dir_all().join(format!("{name}.json"))).unwrap(),
        )
        .unwrap();
        let urdf = dir_all().join(format!("{name}.urdf"));
        if probe(&urdf, &[]).1 {
            nonphysical.push(name.to_string());
        }
        mimic += usize::from(r["mimic"].as_bool().unwrap());
        let fixed = r["fixed"]["states"].as_array().unwrap();
        let gravity = ["--gravity", "0,0,-9.81", "--algorithm", "spatial"];
        worst = worst.max(compare_all(name, &urdf, &r, fixed, &gravity, 0));
        if let Some(free) = r["free_flyer"]["states"].as_array() {
            let args = ["--base", "free-floating", "--algorithm", "spatial"];
            worst = worst.max(compare_all(name, &urdf, &r, free, &args, 6));
        }
    }
    assert_eq!(
        nonphysical, NONPHYSICAL,
        "files that need --allow-nonphysical"
    );
    assert!(mimic >= 5, "{mimic} files with mimic joints");
    eprintln!(
        "whole set: {} models ({mimic} with mimic joints, {} non-physical) against Pinocchio, \
         worst {worst:.2e}",
        models.len(),
        nonphysical.len()
    );
}
