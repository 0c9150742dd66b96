//! Real robots from example-robot-data (UR3/5/10, Panda, xArm7, Kinova, TALOS arm, Z1, and two
//! legged robots carrying an arm): serial arms with fixed side frames, and moving branches
//! (Panda's fingers, B1 + Z1, ANYmal + Kinova) as trees. `kanegen eval` on each URDF against
//! Pinocchio 4.1's values (`tests/data/erd/*.reference.json`, `tools/reference/`): fixed base
//! with gravity zero and (0, 0, −9.81), and free-floating with the root link as the base, to 1e-9
//! relative. Pinocchio orders sibling joints by name, kanegen by the file: `eval --json` lists
//! its joint order, and the reference is permuted by name.

use kanegen::dynamics::metrics::rel_err;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/erd")
}

fn nums(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(xs) => xs.iter().flat_map(nums).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        other => panic!("not a number: {other}"),
    }
}

fn models() -> Vec<String> {
    let index: Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("index.json")).unwrap()).unwrap();
    let v: Vec<String> = index["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap().to_string())
        .collect();
    assert!(v.len() >= 15, "{} models", v.len());
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

/// `perm[k]` = Pinocchio's index of kanegen's joint `k`.
fn permutation(r: &Value, ours: &[String]) -> Vec<usize> {
    let pin: Vec<&str> = r["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j["name"].as_str().unwrap())
        .collect();
    assert_eq!(pin.len(), ours.len(), "joint count");
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
                for (k, (g, s)) in got["results"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .zip(states)
                    .enumerate()
                {
                    let a = permute_matrix(&nums(&s["A"]), &perm, 0);
                    let b = permute_vector(&nums(&s[key]), &perm, 0);
                    let (ea, eb) = (rel_err(&nums(&g["A"]), &a), rel_err(&nums(&g["b"]), &b));
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
        for (k, (g, s)) in got["results"]
            .as_array()
            .unwrap()
            .iter()
            .zip(states)
            .enumerate()
        {
            let a = permute_matrix(&nums(&s["A"]), &perm, 6);
            let b = permute_vector(&nums(&s["b_gravity_zero"]), &perm, 6);
            let (ea, eb) = (rel_err(&nums(&g["A"]), &a), rel_err(&nums(&g["b"]), &b));
            worst = worst.max(ea).max(eb);
            assert!(
                ea < 1e-9 && eb < 1e-9,
                "{name} free-floating state {k}: A {ea:.2e}, b {eb:.2e}"
            );
        }
    }
    assert!(
        models_checked >= 4,
        "{models_checked} models without a stand-in base"
    );
    eprintln!("free-floating: {models_checked} models against Pinocchio, worst {worst:.2e}");
}
