//! `kanegen count` on URDF and TOML models: the JSON contract, the same counts for the same arm
//! in both formats, and the ordering paper ≥ folded ≥ emitted.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn count_json(model: &Path) -> Value {
    let out = Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .arg("count")
        .arg(model)
        .arg("--json")
        .output()
        .expect("run kanegen");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn count_reports_every_method_function_and_convention() {
    let urdf = count_json(&root().join("tests/data/reference/ssrms_nguyen_hughes_1994.urdf"));
    let toml = count_json(&root().join("models/ssrms.toml"));
    assert_eq!(urdf["n"], 7);
    let lines = urdf["counts"].as_array().unwrap();
    assert_eq!(
        lines.len(),
        (5 + 4) * 3,
        "(5 mass-matrix methods + 4 bias methods) × 3 conventions"
    );
    for key in [
        "method",
        "function",
        "convention",
        "mul",
        "add",
        "div",
        "sqrt",
        "sincos",
    ] {
        assert!(lines.iter().all(|l| l.get(key).is_some()), "missing {key}");
    }
    // The same arm in two formats costs the same.
    assert_eq!(urdf["counts"], toml["counts"]);
    // Folding and CSE never add operations; sin/cos once per joint in emitted code.
    let methods = [
        ("mass_matrix", "recurrent"),
        ("mass_matrix", "recurrent-r1"),
        ("mass_matrix", "kane-direct"),
        ("mass_matrix", "crba-base"),
        ("mass_matrix", "crba"),
        ("bias", "recurrent"),
        ("bias", "kane-direct"),
        ("bias", "rnea"),
        ("bias", "newton-euler"),
    ];
    for (f, alg) in methods {
        {
            let get = |conv: &str| {
                lines
                    .iter()
                    .find(|l| l["method"] == alg && l["function"] == f && l["convention"] == conv)
                    .unwrap()
            };
            let tot = |l: &Value| l["mul"].as_u64().unwrap() + l["add"].as_u64().unwrap();
            let (p, fo, e) = (get("paper"), get("folded"), get("emitted"));
            assert!(
                tot(p) >= tot(fo) && tot(fo) >= tot(e),
                "{alg} {f}: {} {} {}",
                tot(p),
                tot(fo),
                tot(e)
            );
            assert!(tot(e) > 0);
            // At most one sin/cos pair per joint. The local-frame algorithms need none for joint 1
            // without gravity (A and h are invariant to rotating the whole arm about the fixed
            // first axis), so their emitted code drops it; the base-frame ones keep all 7. The
            // CRBA's M needs none for the last joint either: SSRMS's last body is isotropic about
            // its axis (iyy = izz = 44.41 about x), and the double-angle turn of its inertia
            // (`RbInertia::turned_about_axis`) has no terms in the angle, where the congruence
            // computed 44.41 c² + 44.41 s².
            let sc = e["sincos"].as_u64().unwrap();
            let want = match alg {
                "crba" => 5,
                "rnea" | "newton-euler" => 6,
                _ => 7,
            };
            assert_eq!(sc, want, "{alg} {f}: sin/cos pairs");
        }
    }
}

/// `count` lists every method the generator may emit: on a chain each mass-matrix and bias
/// method (`newton-euler` included), on a tree the local-frame ones (`crba`; `rnea`,
/// `newton-euler`), each in three conventions.
#[test]
fn count_lists_every_method_the_generator_may_emit() {
    let methods = |model: &str| {
        let report = count_json(&root().join(model));
        let mut m: Vec<(String, String)> = report["counts"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|l| l["convention"] == "emitted")
            .map(|l| {
                let s = |k: &str| l[k].as_str().unwrap().to_string();
                (s("function"), s("method"))
            })
            .collect();
        m.sort();
        m
    };
    let pairs = |v: &[(&str, &str)]| {
        let mut v: Vec<(String, String)> = v
            .iter()
            .map(|(f, m)| ((*f).to_string(), (*m).to_string()))
            .collect();
        v.sort();
        v
    };
    assert_eq!(
        methods("tests/data/compact/tree7.toml"),
        pairs(&[
            ("mass_matrix", "crba"),
            ("bias", "rnea"),
            ("bias", "newton-euler")
        ])
    );
    let chain = methods("tests/data/compact/chain3.toml");
    for bias in ["recurrent", "kane-direct", "rnea", "newton-euler"] {
        assert!(chain.contains(&("bias".into(), bias.into())), "{bias}");
    }
    for mass in [
        "recurrent",
        "recurrent-r1",
        "kane-direct",
        "crba-base",
        "crba",
    ] {
        assert!(
            chain.contains(&("mass_matrix".into(), mass.into())),
            "{mass}"
        );
    }
}

#[test]
fn count_rejects_a_bad_model_naming_the_field() {
    let dir = std::env::temp_dir().join(format!("kanegen-count-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        r#"name = "bad"
[[joint]]
name = "elbow"
type = "revolute"
axis = [0.0, 0.0, 0.0]
[joint.body]
mass = 1.0
com = [0.0, 0.0, 0.0]
inertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }
"#,
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_kanegen"))
        .arg("count")
        .arg(&bad)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("elbow") && err.contains("axis"),
        "stderr: {err}"
    );
}
