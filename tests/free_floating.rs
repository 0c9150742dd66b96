//! Generated free-floating dynamics against Pinocchio's free-flyer model (`JointModelFreeFlyer`
//! root) on real URDFs of example-robot-data (`tests/data/erd/*.reference.json`, made by
//! `tools/reference/pinocchio_reference.py`): the `(6+N)×(6+N)` mass matrix, the nonlinear
//! effects and the total momentum, at ten random base states and joint states each, to 1e-9
//! relative — on the TALOS arm (a chain), Panda (a tree: two finger joints on the hand) and
//! B1 + Z1 (a quadruped carrying an arm: a 19-joint tree). The base is the URDF's root link with every link fixed to it (these models need no
//! stand-in base inertial). Joint order: Pinocchio's (`"joints"`), permuted by name to the
//! order of `JOINTS`.

mod common;

use common::nums;
use kanegen::dynamics::metrics::rel_err;
use serde_json::Value;
use std::path::Path;

kanegen::dynamics!(
    TalosArm,
    "tests/data/erd/talos_left_arm.urdf",
    base = "free-floating"
);
kanegen::dynamics!(
    Panda,
    "tests/data/erd/panda.urdf",
    base = "free-floating",
    ignore_mimic = true
);
kanegen::dynamics!(B1Z1, "tests/data/erd/b1-z1.urdf", base = "free-floating");

fn reference(name: &str) -> Value {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/erd/{name}.reference.json"));
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// `perm[k]`: the index in Pinocchio's order of our joint `k`.
fn permutation(r: &Value, ours: &[&str]) -> Vec<usize> {
    let pin: Vec<&str> = r["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j["name"].as_str().unwrap())
        .collect();
    ours.iter()
        .map(|n| {
            pin.iter()
                .position(|p| p == n)
                .unwrap_or_else(|| panic!("joint {n}"))
        })
        .collect()
}

/// `(q [7 + N], v [6 + N])` of a reference state in our joint order.
fn state(s: &Value, perm: &[usize]) -> (Vec<f64>, Vec<f64>) {
    let b = &s["base"];
    let (qj, qdj) = (nums(&s["q"]), nums(&s["qd"]));
    let mut q = nums(&b["position"]);
    q.extend(nums(&b["quaternion"]));
    q.extend(perm.iter().map(|&i| qj[i]));
    let mut v = nums(&b["v"]);
    v.extend(nums(&b["omega"]));
    v.extend(perm.iter().map(|&i| qdj[i]));
    (q, v)
}

/// A reference matrix or vector over the speeds `[base (6), joints (Pinocchio order)]` in our
/// order.
fn speeds_perm(perm: &[usize]) -> Vec<usize> {
    (0..6).chain(perm.iter().map(|i| i + 6)).collect()
}

macro_rules! check_model {
    ($t:ident, $name:literal) => {{
        let r = reference($name);
        let perm = permutation(&r, &$t::JOINTS);
        let sp = speeds_perm(&perm);
        let mut worst: f64 = 0.0;
        let states = r["free_flyer"]["states"].as_array().unwrap();
        assert!(states.len() >= 10);
        for (k, s) in states.iter().enumerate() {
            let (q, v) = state(s, &perm);
            let q: [f64; $t::NQ] = q.try_into().unwrap();
            let v: [f64; $t::NV] = v.try_into().unwrap();
            let a_ref = nums(&s["A"]);
            let nv = $t::NV;
            let a_want: Vec<f64> = (0..nv)
                .flat_map(|i| sp.iter().map(move |&j| (i, j)))
                .map(|(i, j)| a_ref[sp[i] * nv + j])
                .collect();
            let m = $t::mass_matrix(&q);
            let e = rel_err(&m.concat(), &a_want);
            worst = worst.max(e);
            assert!(e < 1e-9, "{} state {k}: M {e:.2e}", $name);
            let c_ref = nums(&s["nle_gravity_zero"]);
            let c_want: Vec<f64> = sp.iter().map(|&i| c_ref[i]).collect();
            let e = rel_err(&$t::nonlinear_effects(&q, &v), &c_want);
            worst = worst.max(e);
            assert!(e < 1e-9, "{} state {k}: c {e:.2e}", $name);
            let (m2, c2) = $t::mass_matrix_and_nonlinear_effects(&q, &v);
            assert!(rel_err(&m2.concat(), &a_want) < 1e-9 && rel_err(&c2, &c_want) < 1e-9);
            let e = rel_err(&$t::momentum(&q, &v), &nums(&s["momentum"]));
            worst = worst.max(e);
            assert!(e < 1e-9, "{} state {k}: momentum {e:.2e}", $name);
            // ½ vᵀ M v is Pinocchio's kinetic energy.
            let ke: f64 = 0.5
                * (0..nv)
                    .map(|i| (0..nv).map(|j| v[i] * m[i][j] * v[j]).sum::<f64>())
                    .sum::<f64>();
            let e = (ke - s["kinetic_energy"].as_f64().unwrap()).abs() / ke.abs();
            assert!(e < 1e-9, "{} state {k}: kinetic energy {e:.2e}", $name);
        }
        eprintln!(
            "{}: generated free-floating code vs Pinocchio, worst {worst:.2e}",
            $name
        );
    }};
}

#[test]
fn generated_free_floating_dynamics_equal_pinocchio_free_flyer() {
    check_model!(TalosArm, "talos_left_arm");
    check_model!(Panda, "panda");
    check_model!(B1Z1, "b1-z1");
}
