//! Drive effects: reflected rotor inertia `I_m n²` on the diagonal of `M` and drive
//! friction (viscous = `damping`, regularized Coulomb `τ_c tanh(q̇ / v_s)`), in the interpreted
//! simulator and `kanegen count SCENE`:
//!
//! - with rotor inertia alone (fixed-base SSRMS, no gravity, no drives) the energy
//!   `½ q̇ᵀ (M + diag(I_m n²)) q̇` is conserved to RK4's accuracy, and the energy without the rotor
//!   term is not (the rotor inertia acts in the solve, not beside it);
//! - with viscous + Coulomb friction and no drives that energy falls at every sample;
//! - scenes without the effects run and count exactly as on `main` before them (golden files
//!   `tests/data/golden/`, written by main's `kanegen` at 6f58384);
//! - `count SCENE` lists `coulomb` and `rotor` with nonzero costs;
//! - bad values name the key (and its line).
//!
//! Run with `--nocapture` to see the measured numbers.

use kanegen::sim::scene::Scene;
use kanegen::sim::simulate::{simulate, SceneSystem};
use std::path::Path;

mod common;
use common::{kanegen, root, scene, scene_err};

/// The fixed-base SSRMS, no gravity, moving, no drives, with `effects`.
fn ssrms(effects: &str) -> String {
    format!(
        r#"
model = "tests/data/reference/ssrms_nguyen_hughes_1994.urdf"
[effects]
{effects}
[initial]
q = [0.0, 0.2, -0.8, 0.5, 0.0, 0.3, 0.0]
qd = [0.05, -0.04, 0.06, 0.03, -0.08, 0.05, 0.07]
[simulation]
duration = 5.0
step = 0.005
output_every = 10
"#
    )
}

const ROTOR: &str = "rotor = { inertia = [1e-3, 1e-3, 1e-3, 1e-3, 5e-4, 5e-4, 5e-4], \
                     gear_ratio = [1000.0, 1000.0, 1000.0, 1000.0, 500.0, 500.0, 500.0] }";

/// Energy of every sample of a run of `s` (`SceneSystem::energy`, with the rotor term).
fn energies(s: &Scene) -> Vec<f64> {
    let run = simulate(s, None).unwrap();
    assert!(run.summary.complete);
    let sys = SceneSystem::new(s);
    run.samples
        .iter()
        .map(|x| sys.energy(&x.x).unwrap())
        .collect()
}

#[test]
fn rotor_inertia_conserves_the_energy_with_the_rotor_term() {
    let s = scene(&ssrms(ROTOR));
    let e = energies(&s);
    let drift = e
        .iter()
        .map(|x| ((x - e[0]) / e[0]).abs())
        .fold(0.0, f64::max);
    // The same states with the arm's energy only (no rotor term): not conserved.
    let plain = {
        let mut p = s.clone();
        p.rotor = None;
        let sys = SceneSystem::new(&p);
        let run = simulate(&s, None).unwrap();
        let e: Vec<f64> = run
            .samples
            .iter()
            .map(|x| sys.energy(&x.x).unwrap())
            .collect();
        e.iter()
            .map(|x| ((x - e[0]) / e[0]).abs())
            .fold(0.0, f64::max)
    };
    eprintln!(
        "rotor: energy drift {drift:.2e} relative over {} samples; without the rotor term {plain:.2e}",
        e.len()
    );
    assert!(drift < 1e-9, "drift {drift:e}");
    assert!(plain > 1e-3, "the rotor term should matter: {plain:e}");
    // The rotor inertia changes the motion (it is in the solve).
    let without = simulate(&scene(&ssrms("")), None).unwrap();
    let with = simulate(&s, None).unwrap();
    let (a, b) = (
        &without.samples.last().unwrap().x,
        &with.samples.last().unwrap().x,
    );
    let d = common::max_abs_diff(a, b);
    eprintln!("rotor: final state moved by {d:.2e}");
    assert!(d > 1e-2);
}

#[test]
fn friction_dissipates_at_every_sample() {
    let fr = "friction = { viscous = [50.0, 50.0, 50.0, 50.0, 10.0, 10.0, 10.0], \
              coulomb = [200.0, 200.0, 200.0, 200.0, 50.0, 50.0, 50.0], v_s = 1e-3 }";
    for effects in [format!("{ROTOR}\n{fr}"), fr.to_string()] {
        let s = scene(&ssrms(&effects));
        let e = energies(&s);
        let worst_rise = e.windows(2).map(|w| w[1] - w[0]).fold(f64::MIN, f64::max);
        eprintln!(
            "friction: energy {:.4e} -> {:.4e} J, largest sample-to-sample change {worst_rise:.2e} J",
            e[0],
            e.last().unwrap()
        );
        assert!(worst_rise <= 1e-12 * e[0], "energy rose by {worst_rise:e}");
        assert!(*e.last().unwrap() < 0.9 * e[0]);
    }
    // Coulomb alone dissipates too (the sign opposes the motion).
    let s = scene(&ssrms(
        "friction = { coulomb = [200.0, 200.0, 200.0, 200.0, 50.0, 50.0, 50.0] }",
    ));
    let e = energies(&s);
    assert!(e.windows(2).all(|w| w[1] <= w[0] + 1e-12 * e[0]));
    assert!(*e.last().unwrap() < 0.9 * e[0]);
}

/// The numbers of a trajectory CSV (header skipped).
fn csv_numbers(bytes: &[u8]) -> Vec<f64> {
    String::from_utf8_lossy(bytes)
        .lines()
        .skip(1)
        .flat_map(|l| {
            l.split(',')
                .map(|x| x.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Trajectories (two scenes) and counts (every example scene without the new effects) are
/// byte-identical to main's before the drive effects: the trajectories on the LDLᵀ path with
/// the `recurrent` algorithm those runs used (the scene with `algorithm = "recurrent"` named);
/// on the run-time fast path (the workspace ABA, the default since) they agree to rounding
/// (measured 2.2e-17 on `ssrms_effects`, 9.4e-14 on `free_floating_7dof`, of the largest value;
/// bound 1e-10).
#[test]
fn scenes_without_the_effects_are_unchanged() {
    let golden = root().join("tests/data/golden");
    let dir = std::env::temp_dir().join(format!("kanegen-drive-effects-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["ssrms_effects", "free_floating_7dof"] {
        let want = std::fs::read(golden.join(format!("{name}.csv"))).unwrap();
        // The scene as it is, and with the algorithm named (its model path made absolute).
        let text = std::fs::read_to_string(root().join(format!("scenes/{name}.toml"))).unwrap();
        let named = text
            .replace("model = \"../", &format!("model = \"{}/", root().display()))
            .replace(
                "[simulation]\n",
                "[simulation]\nalgorithm = \"recurrent\"\n",
            );
        let named_path = dir.join(format!("{name}.toml"));
        std::fs::write(&named_path, named).unwrap();
        for (label, scene) in [
            ("ldlt", named_path.to_str().unwrap().to_string()),
            ("fast", format!("scenes/{name}.toml")),
        ] {
            let out = dir.join(format!("{name}-{label}"));
            kanegen(&[
                "simulate",
                &scene,
                "--out",
                out.to_str().unwrap(),
                "--force",
                "--json",
            ]);
            let got = std::fs::read(out.join("trajectory.csv")).unwrap();
            if label == "ldlt" {
                assert!(got == want, "{name}: trajectory differs from main's");
            } else {
                let (a, b) = (csv_numbers(&got), csv_numbers(&want));
                assert_eq!(a.len(), b.len());
                let e = kanegen::dynamics::metrics::rel_err(&a, &b);
                assert!(e < 1e-10, "{name}: fast path vs main's {e:e}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    for name in [
        "ssrms_effects",
        "ssrms_payload_fixed",
        "srms",
        "free_floating_7dof",
        "dextre_free_floating",
    ] {
        let scene = format!("scenes/{name}.toml");
        let got = kanegen(&["count", &scene, "--json"]).stdout;
        let want = std::fs::read(golden.join(format!("{name}.count.json"))).unwrap();
        assert!(got == want, "{name}: count differs from main's");
    }
}

#[test]
fn count_lists_the_drive_effects() {
    let out = kanegen(&["count", "scenes/ssrms_drives.toml", "--json"]).stdout;
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let effects = v["effects"].as_array().unwrap();
    for name in ["coulomb", "rotor", "damping"] {
        let lines: Vec<_> = effects.iter().filter(|e| e["effect"] == name).collect();
        assert_eq!(lines.len(), 3 * 2, "{name}: 3 bias methods × 2 conventions");
        for l in lines {
            let total = l["mul"].as_i64().unwrap() + l["add"].as_i64().unwrap();
            assert!(total > 0, "{name}: {l}");
            eprintln!(
                "{name} {} {}: mul {} add {}",
                l["method"], l["convention"], l["mul"], l["add"]
            );
        }
    }
    // 7 joints: Coulomb 2 mul + 1 add each, rotor 1 add each.
    let c = effects.iter().find(|e| e["effect"] == "coulomb").unwrap();
    assert_eq!((c["mul"].as_i64(), c["add"].as_i64()), (Some(14), Some(7)));
    let r = effects.iter().find(|e| e["effect"] == "rotor").unwrap();
    assert_eq!((r["mul"].as_i64(), r["add"].as_i64()), (Some(0), Some(7)));
}

#[test]
fn bad_drive_effects_name_the_key() {
    let cases = [
        (
            "rotor = { inertia = [-1e-3, 1e-3, 1e-3, 1e-3, 5e-4, 5e-4, 5e-4], gear_ratio = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0] }",
            "effects.rotor.inertia (line 4): must be >= 0",
        ),
        (
            "rotor = { inertia = [1e-3, 1e-3], gear_ratio = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0] }",
            "effects.rotor.inertia (line 4): expected 7 values",
        ),
        (
            "rotor = { inertia = [1e-3, 1e-3, 1e-3, 1e-3, 5e-4, 5e-4, 5e-4], gear_ratio = [1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0] }",
            "effects.rotor.gear_ratio (line 4): must be non-zero",
        ),
        (
            "friction = { coulomb = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], v_s = 0.0 }",
            "effects.friction.v_s (line 4): must be > 0",
        ),
        (
            "friction = { coulomb = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], v_s = -1e-3 }",
            "effects.friction.v_s (line 4): must be > 0",
        ),
        (
            "friction = { coulomb = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0] }",
            "effects.friction.coulomb (line 4): expected 7 values",
        ),
        (
            "friction = { coulomb = [1.0, 1.0, 1.0, -1.0, 1.0, 1.0, 1.0] }",
            "effects.friction.coulomb (line 4): friction torques must be >= 0",
        ),
        (
            "friction = { viscous = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, -1.0] }",
            "effects.friction.viscous (line 4): coefficients must be >= 0",
        ),
        (
            "damping = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]\nfriction = { viscous = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0] }",
            "effects.friction.viscous (line 5): viscous friction is `effects.damping`",
        ),
        ("friction = { v_s = 1e-3 }", "effects.friction (line 4)"),
        (
            "friction = { coulomb = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], stiction = 2.0 }",
            "unknown field `stiction`",
        ),
        ("backlash = 1.0", "unknown field `backlash`"),
    ];
    for (effects, want) in cases {
        let e = scene_err(&ssrms(effects));
        assert!(e.contains(want), "{effects}\n  got: {e}\n  want: {want}");
    }
    // The TOML errors carry the line too; the file is named when loading one.
    let e = scene_err(&ssrms("backlash = 1.0"));
    assert!(e.contains("line 4"), "{e}");
    let dir = std::env::temp_dir().join(format!("kanegen-drive-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bad_friction.toml");
    let text = ssrms("friction = { coulomb = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], v_s = 0.0 }")
        .replace(
            "tests/data/reference",
            root().join("tests/data/reference").to_str().unwrap(),
        );
    std::fs::write(&file, text).unwrap();
    let e = format!("{:#}", Scene::load(&file).unwrap_err());
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        e.contains("bad_friction.toml") && e.contains("effects.friction.v_s (line 4)"),
        "{e}"
    );
    // Rotor inertia on a free-floating base is the armature model (tests/capture.rs).
    let floating = format!(
        r#"
model = "tests/data/reference/bmsd_7dof_free_floating.urdf"
allow_nonphysical = true
[base]
type = "free-floating"
[effects]
{ROTOR}
[simulation]
duration = 1.0
"#
    );
    assert!(scene(&floating).rotor.is_some());
}

/// The example scene parses with both effects and its regularization speed.
#[test]
fn example_scene_has_both_effects() {
    let s = Scene::load(Path::new(&root().join("scenes/ssrms_drives.toml"))).unwrap();
    let r = s.rotor.as_ref().unwrap();
    assert_eq!(r.reflected[0], 1e-3 * 1000.0 * 1000.0);
    assert_eq!(s.coulomb.as_ref().unwrap().v_s, 1e-3);
    assert!(s.damping.is_some());
}
