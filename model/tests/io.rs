//! Model readers: URDF and TOML (with DH) against each other and against hand computations.

use kanegen_model::io::{load_model, parse_toml, parse_urdf};
use kanegen_model::{JointKind, Model, ModelError};
use std::f64::consts::FRAC_PI_2;
use std::path::{Path, PathBuf};

type M3 = [[f64; 3]; 3];
type V3 = [f64; 3];

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn mm(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}
fn mv(a: &M3, v: &V3) -> V3 {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}
fn tr(a: &M3) -> M3 {
    [0, 1, 2].map(|i| [0, 1, 2].map(|j| a[j][i]))
}
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// Rodrigues rotation about unit axis `u` by `q`.
fn axis_rot(u: &V3, q: f64) -> M3 {
    let (s, c) = q.sin_cos();
    let k: M3 = [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]];
    let k2 = mm(&k, &k);
    [0, 1, 2].map(|i| {
        [0, 1, 2].map(|j| if i == j { 1.0 } else { 0.0 } + s * k[i][j] + (1.0 - c) * k2[i][j])
    })
}
fn rpy(r: V3) -> M3 {
    kanegen_model::placement::rpy_to_matrix(r)
}

/// World (base-frame) CoM position and world-axes inertia about the CoM of every body at `q`.
fn fk(chain: &Model, q: &[f64]) -> Vec<(V3, M3)> {
    let (mut r, mut p): (M3, V3) = (
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [0.0; 3],
    );
    let mut out = Vec::new();
    for (j, qj) in chain.joints().iter().zip(q) {
        p = add(p, mv(&r, &j.origin.translation));
        r = mm(&r, &j.origin.rotation);
        match j.kind {
            JointKind::Revolute => r = mm(&r, &axis_rot(&j.axis, *qj)),
            JointKind::Prismatic => p = add(p, mv(&r, &j.axis.map(|a| a * qj))),
        }
        let com = add(p, mv(&r, &j.inertial.com));
        let i = mm(&mm(&r, &j.inertial.inertia), &tr(&r));
        out.push((com, i));
    }
    out
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}
fn assert_v(a: &V3, b: &V3, tol: f64, what: &str) {
    for k in 0..3 {
        assert!(close(a[k], b[k], tol), "{what}: {a:?} vs {b:?}");
    }
}
/// Matrices compared entry-wise relative to the larger matrix's largest entry.
fn assert_m(a: &M3, b: &M3, tol: f64, what: &str) {
    let scale = a
        .iter()
        .chain(b)
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    for k in 0..3 {
        for l in 0..3 {
            assert!(
                (a[k][l] - b[k][l]).abs() <= tol * (1.0 + scale),
                "{what}: {a:?} vs {b:?}"
            );
        }
    }
}

/// Same kinematics and mass distribution: compares world CoMs and inertias at several states.
fn assert_same_dynamics(a: &Model, b: &Model, tol: f64) {
    assert_eq!(a.dof(), b.dof());
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 6.0 - 3.0
    };
    for _ in 0..10 {
        let q: Vec<f64> = (0..a.dof()).map(|_| rnd()).collect();
        let (fa, fb) = (fk(a, &q), fk(b, &q));
        for (k, ((ca, ia), (cb, ib))) in fa.iter().zip(&fb).enumerate() {
            let (ma, mb) = (a.joints()[k].inertial.mass, b.joints()[k].inertial.mass);
            assert!(close(ma, mb, tol), "body {k} mass {ma} vs {mb}");
            assert_v(ca, cb, tol, &format!("body {k} world CoM at q = {q:?}"));
            assert_m(ia, ib, tol, &format!("body {k} world inertia at q = {q:?}"));
        }
    }
}

/// Field-by-field numeric equality of two chains (names, kinds, origins, axes, inertials).
fn assert_chains_equal(a: &Model, b: &Model, tol: f64) {
    assert_eq!(a.name(), b.name());
    assert_eq!(a.base(), b.base());
    assert_eq!(a.dof(), b.dof());
    match (a.base_inertial(), b.base_inertial()) {
        (Some(x), Some(y)) => {
            assert!(close(x.mass, y.mass, tol));
            assert_v(&x.com, &y.com, tol, "base com");
            assert_m(&x.inertia, &y.inertia, tol, "base inertia");
        }
        (None, None) => {}
        (x, y) => panic!("base inertial {x:?} vs {y:?}"),
    }
    for (x, y) in a.joints().iter().zip(b.joints()) {
        assert_eq!(x.name, y.name);
        assert_eq!(x.body, y.body);
        assert_eq!(x.kind, y.kind);
        assert_v(&x.origin.translation, &y.origin.translation, tol, &x.name);
        assert_m(&x.origin.rotation, &y.origin.rotation, tol, &x.name);
        assert_v(&x.axis, &y.axis, tol, &x.name);
        assert!(close(x.inertial.mass, y.inertial.mass, tol), "{}", x.name);
        assert_v(&x.inertial.com, &y.inertial.com, tol, &x.name);
        assert_m(&x.inertial.inertia, &y.inertial.inertia, tol, &x.name);
    }
}

// ---------------------------------------------------------------------------------------------
// URDF

/// Every reference URDF parses; those whose links `models/space_arms.json` flags as violating
/// the triangle inequality (documented data defects) are rejected by `Model::new`, naming the
/// joint of the first such link; all others load with the indexed dof.
#[test]
fn every_reference_urdf_loads_with_the_indexed_dof() {
    let dir = repo().join("tests/data/reference");
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("index.json")).unwrap()).unwrap();
    let arms: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo().join("models/space_arms.json")).unwrap(),
    )
    .unwrap();
    let models = index["models"].as_array().unwrap();
    assert!(models.len() >= 11);
    let mut loaded = 0;
    for m in models {
        let id = m["id"].as_str().unwrap();
        let arm = arms["models"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["id"] == id)
            .unwrap();
        let bad_link = arm["physical_checks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["triangle_margin"].as_f64().unwrap() < 0.0)
            .map(|c| c["link"].as_str().unwrap().to_string());
        let text = std::fs::read_to_string(dir.join(format!("{id}.urdf"))).unwrap();
        match (load_model(&dir.join(format!("{id}.urdf"))), bad_link) {
            (Ok(chain), None) => {
                assert_eq!(chain.dof() as u64, m["dof"].as_u64().unwrap(), "{id}");
                assert_eq!(chain.name(), id);
                loaded += 1;
            }
            (Err(e), Some(link)) => {
                let e = e.to_string();
                // The joint whose child is the flagged link.
                let pos = text.find(&format!("<child link=\"{link}\"/>")).unwrap();
                let jpos = text[..pos].rfind("<joint name=\"").unwrap() + 13;
                let joint = &text[jpos..jpos + text[jpos..].find('"').unwrap()];
                assert!(
                    e.contains(&format!("`{joint}`")) && e.contains("triangle inequality"),
                    "{id}: {e}"
                );
            }
            (r, bad) => panic!("{id}: {r:?}, flagged link {bad:?}"),
        }
    }
    assert!(loaded >= 8);
}

#[test]
fn ssrms_toml_equals_ssrms_urdf() {
    let urdf =
        load_model(&repo().join("tests/data/reference/ssrms_nguyen_hughes_1994.urdf")).unwrap();
    let toml = load_model(&repo().join("models/ssrms.toml")).unwrap();
    assert_eq!(urdf.base(), "root");
    assert_eq!(urdf.base_inertial().unwrap().mass, 243.66);
    assert_chains_equal(&urdf, &toml, 1e-12);
    // Spot values straight from the URDF text.
    let j = &urdf.joints()[2];
    assert_eq!(j.name, "shoulder_pitch");
    assert_eq!(j.body, "B4");
    assert_eq!(j.origin.translation, [0.0, -0.5692, 0.0]);
    assert_eq!(j.axis, [0.0, 1.0, 0.0]);
    assert_eq!(j.inertial.inertia[0][1], 49.52);
    assert_eq!(j.inertial.inertia[2][2], 2103.19);
}

#[test]
fn two_link_model_loads() {
    let c = load_model(&repo().join("models/two_link.toml")).unwrap();
    assert_eq!((c.name(), c.base(), c.dof()), ("two_link", "base", 2));
    assert_eq!(c.joints()[1].origin.translation, [1.0, 0.0, 0.0]);
    assert!(c.base_inertial().is_none());
}

const MERGE_URDF: &str = r#"<?xml version="1.0"?>
<robot name="merge">
  <link name="world"/>
  <joint name="mount" type="fixed">
    <parent link="world"/><child link="base_link"/>
    <origin xyz="0 0 1" rpy="0 0 0"/>
  </joint>
  <link name="base_link">
    <inertial><origin xyz="0 0 0.5"/><mass value="5"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="package://nowhere/missing.stl"/></geometry></visual>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base_link"/><child link="link1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <link name="link1">
    <inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  </link>
  <joint name="bracket" type="fixed">
    <parent link="link1"/><child link="link1b"/>
    <origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/>
  </joint>
  <link name="link1b">
    <inertial><origin xyz="0.5 0 0"/><mass value="2"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/></inertial>
    <collision><geometry><box size="1 1 1"/></geometry></collision>
  </link>
  <joint name="j2" type="continuous">
    <parent link="link1b"/><child link="link2"/>
    <origin xyz="2 0 0"/><axis xyz="0 0 1"/>
  </joint>
  <link name="link2">
    <inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <joint name="tool_mount" type="fixed">
    <parent link="link2"/><child link="tool"/>
    <origin xyz="0 0 3"/>
  </joint>
  <link name="tool"/>
</robot>"#;

#[test]
fn fixed_joints_merge_into_the_parent_body() {
    let c = parse_urdf(MERGE_URDF).unwrap();
    assert_eq!((c.name(), c.base(), c.dof()), ("merge", "world", 2));
    // Base: base_link merged into the massless world at z = 1.
    let b = c.base_inertial().unwrap();
    assert_eq!(b.mass, 5.0);
    assert_v(&b.com, &[0.0, 0.0, 1.5], 1e-14, "base com");
    // j1 origin: mount ∘ j1.
    assert_v(
        &c.joints()[0].origin.translation,
        &[0.0, 0.0, 1.1],
        1e-14,
        "j1 origin",
    );
    // Body 1 = link1 (2 kg at 0, I = 1) + link1b (2 kg at (1, 0.5, 0), I = diag(0.2, 0.1, 0.3)
    // after the 90° yaw): hand-merged.
    let j1 = &c.joints()[0].inertial;
    assert_eq!(j1.mass, 4.0);
    assert_v(&j1.com, &[0.5, 0.25, 0.0], 1e-14, "merged com");
    let expected = [[1.45, -0.5, 0.0], [-0.5, 2.1, 0.0], [0.0, 0.0, 2.55]];
    assert_m(&j1.inertia, &expected, 1e-12, "merged inertia");
    // j2 origin: bracket ∘ j2 = (1,0,0) + Rz(90°)(2,0,0) = (1, 2, 0), rotation Rz(90°).
    let o = &c.joints()[1].origin;
    assert_v(&o.translation, &[1.0, 2.0, 0.0], 1e-12, "j2 origin");
    assert_m(
        &o.rotation,
        &rpy([0.0, 0.0, FRAC_PI_2]),
        1e-12,
        "j2 rotation",
    );
    assert_eq!(c.joints()[1].kind, JointKind::Revolute);
    // The massless trailing tool link changes nothing.
    assert_eq!(c.joints()[1].inertial.mass, 1.0);
    assert_v(&c.joints()[1].inertial.com, &[0.0; 3], 0.0, "tool");
}

#[test]
fn trailing_fixed_link_with_mass_merges_into_the_last_body() {
    let text = MERGE_URDF.replace(
        r#"<link name="tool"/>"#,
        r#"<link name="tool"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>"#,
    );
    let c = parse_urdf(&text).unwrap();
    let b = &c.joints()[1].inertial;
    assert_eq!(b.mass, 2.0);
    assert_v(&b.com, &[0.0, 0.0, 1.5], 1e-14, "com");
    // 0.1 + 0.1 + 2·(1 kg · 1.5²) about x and y.
    assert_m(
        &b.inertia,
        &[[4.7, 0.0, 0.0], [0.0, 4.7, 0.0], [0.0, 0.0, 0.2]],
        1e-12,
        "inertia",
    );
}

#[test]
fn inertial_origin_rpy_is_honoured() {
    let r0 = [0.3, -0.2, 0.5];
    let text = format!(
        r#"<robot name="r"><link name="a"/><link name="b">
        <inertial><origin xyz="0.1 0.2 0.3" rpy="{} {} {}"/><mass value="3"/>
        <inertia ixx="1" ixy="0.1" ixz="0" iyy="2" iyz="0" izz="2.5"/></inertial></link>
        <joint name="j" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="0 2 0"/>
        <limit lower="0" upper="1" effort="1" velocity="1"/></joint></robot>"#,
        r0[0], r0[1], r0[2]
    );
    let c = parse_urdf(&text).unwrap();
    let j = &c.joints()[0];
    assert_eq!(j.kind, JointKind::Prismatic);
    assert_eq!(j.axis, [0.0, 1.0, 0.0]);
    assert!(c.base_inertial().is_none());
    assert_v(&j.inertial.com, &[0.1, 0.2, 0.3], 1e-15, "com");
    let r = rpy(r0);
    let i_urdf = [[1.0, 0.1, 0.0], [0.1, 2.0, 0.0], [0.0, 0.0, 2.5]];
    let expected = mm(&mm(&r, &i_urdf), &tr(&r));
    assert_m(&j.inertial.inertia, &expected, 1e-12, "R I Rᵀ");
    assert!(
        (j.inertial.inertia[0][0] - 1.0).abs() > 1e-3,
        "rotation must change the tensor"
    );
}

#[test]
fn urdf_joint_origin_rpy_and_default_axis() {
    let text = r#"<robot name="r"><link name="a"/><link name="b">
        <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
        <joint name="j" type="continuous"><parent link="a"/><child link="b"/>
        <origin xyz="1 2 3" rpy="0.1 0.2 0.3"/></joint></robot>"#;
    let c = parse_urdf(text).unwrap();
    let j = &c.joints()[0];
    assert_eq!(j.axis, [1.0, 0.0, 0.0]);
    assert_eq!(j.origin.translation, [1.0, 2.0, 3.0]);
    assert_m(&j.origin.rotation, &rpy([0.1, 0.2, 0.3]), 1e-15, "origin");
}

const BOX: &str = r#"<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>"#;

/// A trunk with two moving arms and fixed side frames: depth-first order (an arm's whole subtree
/// before the next arm), parents, fixed links merged and kept as frames.
#[test]
fn branching_urdf_loads_as_a_tree_depth_first() {
    let text = format!(
        r#"<robot name="tree"><link name="trunk">{BOX}</link>
      <link name="l1">{BOX}</link><link name="l2">{BOX}</link>
      <link name="r1">{BOX}</link><link name="tool"/><link name="cam">{BOX}</link>
      <joint name="jl1" type="revolute"><parent link="trunk"/><child link="l1"/><origin xyz="0 1 0"/><axis xyz="0 0 1"/></joint>
      <joint name="jr1" type="prismatic"><parent link="trunk"/><child link="r1"/><origin xyz="0 -1 0"/><axis xyz="1 0 0"/></joint>
      <joint name="jl2" type="continuous"><parent link="l1"/><child link="l2"/><origin xyz="1 0 0"/></joint>
      <joint name="flange" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0.5 0 0" rpy="0 0 1.5707963267948966"/></joint>
      <joint name="camera" type="fixed"><parent link="trunk"/><child link="cam"/><origin xyz="0 0 2"/></joint></robot>"#
    );
    let m = parse_urdf(&text).unwrap();
    let names: Vec<&str> = m.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(
        names,
        ["jl1", "jl2", "jr1"],
        "depth first, file order among siblings"
    );
    let parents: Vec<Option<usize>> = m.joints().iter().map(|j| j.parent).collect();
    assert_eq!(parents, [None, Some(0), None]);
    assert!(!m.is_chain());
    assert_eq!(m.first_branch().map(|j| j.name.as_str()), Some("jr1"));
    // The camera (1 kg, fixed to the trunk 2 m up) is merged into the base; the massless tool
    // is only a frame of body `jl2`.
    let base = m.base_inertial().unwrap();
    assert_eq!(base.mass, 2.0);
    assert_v(&base.com, &[0.0, 0.0, 1.0], 1e-15, "base com");
    assert_eq!(m.joints()[1].inertial.mass, 1.0);
    let frames: Vec<(&str, Option<usize>)> = m
        .frames()
        .iter()
        .map(|f| (f.name.as_str(), f.parent))
        .collect();
    assert_eq!(frames, [("tool", Some(1)), ("cam", None)]);
    assert_v(
        &m.frames()[0].placement.translation,
        &[0.5, 0.0, 0.0],
        1e-15,
        "tool",
    );
    // A joint in the TOML writer's round trip keeps its parent and the frames.
    let back = kanegen_model::io::parse_toml(&kanegen_model::io::to_toml(&m)).unwrap();
    assert_eq!(back, m);
}

/// Locking the trunk joint of an arm re-hangs its children and frames on the base.
#[test]
fn locking_a_tree_joint_rehangs_its_children_and_frames() {
    let text = format!(
        r#"<robot name="tree"><link name="trunk">{BOX}</link>
      <link name="l1">{BOX}</link><link name="l2">{BOX}</link><link name="r1">{BOX}</link><link name="tip"/>
      <joint name="jl1" type="revolute"><parent link="trunk"/><child link="l1"/><origin xyz="0 1 0"/><axis xyz="0 0 1"/></joint>
      <joint name="jl2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
      <joint name="tip" type="fixed"><parent link="l1"/><child link="tip"/><origin xyz="2 0 0"/></joint>
      <joint name="jr1" type="revolute"><parent link="trunk"/><child link="r1"/><origin xyz="0 -1 0"/><axis xyz="0 0 1"/></joint></robot>"#
    );
    let m = parse_urdf(&text).unwrap();
    let l = m.lock_joint(0, std::f64::consts::FRAC_PI_2).unwrap();
    let names: Vec<&str> = l.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["jl2", "jr1"]);
    assert_eq!(l.joints()[0].parent, None);
    assert_eq!(l.joints()[1].parent, None);
    // jl2 sat 1 m along l1's x; l1 is turned a quarter about z at (0, 1, 0): now at (0, 2, 0).
    assert_v(
        &l.joints()[0].origin.translation,
        &[0.0, 2.0, 0.0],
        1e-15,
        "jl2",
    );
    assert_eq!(l.frames()[0].parent, None);
    assert_v(
        &l.frames()[0].placement.translation,
        &[0.0, 3.0, 0.0],
        1e-15,
        "tip",
    );
    assert_eq!(l.base_inertial().unwrap().mass, 2.0);
}

/// TOML trees: `parent` names the base, an earlier joint or its body; `[[frame]]`; a
/// free-floating `[base]`.
#[test]
fn toml_tree_with_frames_and_free_floating_base() {
    let text = r#"
name = "two_arms"
[base]
name = "bus"
type = "free-floating"
mass = 100.0
inertia = { ixx = 10.0, iyy = 10.0, izz = 10.0 }
[[joint]]
name = "a1"
type = "revolute"
axis = [0.0, 0.0, 1.0]
[joint.body]
name = "arm_a"
mass = 1.0
inertia = { ixx = 0.1, iyy = 0.1, izz = 0.1 }
[[joint]]
name = "b1"
type = "revolute"
parent = "bus"
axis = [0.0, 0.0, 1.0]
[joint.body]
mass = 1.0
inertia = { ixx = 0.1, iyy = 0.1, izz = 0.1 }
[[joint]]
name = "a2"
type = "revolute"
parent = "arm_a"
xyz = [1.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
[joint.body]
mass = 1.0
inertia = { ixx = 0.1, iyy = 0.1, izz = 0.1 }
[[frame]]
name = "gripper"
parent = "a2"
xyz = [0.5, 0.0, 0.0]
"#;
    let m = parse_toml(text).unwrap();
    let parents: Vec<Option<usize>> = m.joints().iter().map(|j| j.parent).collect();
    assert_eq!(parents, [None, None, Some(0)]);
    assert_eq!(m.base_kind(), kanegen_model::BaseKind::FreeFloating);
    assert_eq!(m.frames()[0].parent, Some(2));
    assert_eq!(
        parse_toml(&kanegen_model::io::to_toml(&m)).unwrap(),
        m,
        "round trip"
    );
    // A parent that comes later, or does not exist, is an error naming the joint and field.
    let bad = text.replace("parent = \"arm_a\"", "parent = \"nowhere\"");
    let e = parse_toml(&bad).unwrap_err().to_string();
    assert!(
        e.contains("a2") && e.contains("parent") && e.contains("nowhere"),
        "{e}"
    );
    // A free-floating base needs its mass properties.
    let e = parse_toml("name = \"x\"\n[base]\ntype = \"free-floating\"\n[[joint]]\ntype = \"revolute\"\naxis = [0.0, 0.0, 1.0]\n[joint.body]\nmass = 1.0\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("base.mass"), "{e}");
}

#[test]
fn floating_and_planar_joints_are_rejected_naming_the_joint() {
    for ty in ["floating", "planar"] {
        let text = format!(
            r#"<robot name="f"><link name="w"/><link name="b">
            <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
            <joint name="free_flyer" type="{ty}"><parent link="w"/><child link="b"/></joint></robot>"#
        );
        let e = parse_urdf(&text).unwrap_err().to_string();
        assert!(
            e.contains("free_flyer") && e.contains(ty) && e.contains("type"),
            "{e}"
        );
    }
}

#[test]
fn urdf_moving_body_without_mass_is_a_massless_body() {
    let text = r#"<robot name="r"><link name="a"/><link name="b"/>
        <joint name="hinge" type="continuous"><parent link="a"/><child link="b"/></joint></robot>"#;
    let m = parse_urdf(text).unwrap();
    assert_eq!(m.massless_joints(), ["hinge"]);
    let e = m.check_forward_dynamics().unwrap_err().to_string();
    assert!(e.contains("joint `hinge`") && e.contains("singular"), "{e}");
    let text = r#"<robot name="r"><link name="a"/></robot>"#;
    assert!(matches!(parse_urdf(text), Err(ModelError::Empty(_))));
}

#[test]
fn urdf_negative_mass_names_the_joint_and_link() {
    let text = MERGE_URDF.replace(r#"<mass value="2"/>"#, r#"<mass value="-2"/>"#);
    let e = parse_urdf(&text).unwrap_err().to_string();
    assert!(
        e.contains("`j1`") && e.contains("inertial.mass") && e.contains("link1"),
        "{e}"
    );
}

#[test]
fn urdf_syntax_errors_are_parse_errors() {
    assert!(matches!(
        parse_urdf("<robot name="),
        Err(ModelError::Parse(_))
    ));
}

// ---------------------------------------------------------------------------------------------
// load_model

#[test]
fn load_model_dispatches_on_extension_and_names_the_file() {
    let e = load_model(Path::new("model.sdf")).unwrap_err().to_string();
    assert!(e.contains(".sdf"), "{e}");
    let e = load_model(Path::new("/nonexistent/model.toml")).unwrap_err();
    assert!(matches!(e, ModelError::Io { .. }), "{e}");
    let dir = std::env::temp_dir().join(format!("kanegen-io-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bad.toml");
    std::fs::write(&f, "name = \"x\"\ncolour = 3\n").unwrap();
    let e = load_model(&f).unwrap_err().to_string();
    assert!(e.contains("bad.toml") && e.contains("colour"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

// ---------------------------------------------------------------------------------------------
// TOML validation: each error names the joint and the field.

fn toml_joint(name: &str, body: &str, extra: &str) -> String {
    format!(
        "[[joint]]\n{name}type = \"revolute\"\naxis = [0.0, 0.0, 1.0]\n{extra}\n[joint.body]\n{body}\n"
    )
}
const GOOD_BODY: &str =
    "mass = 1.0\ncom = [0.1, 0.0, 0.0]\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }";

fn two_joint_model(second_body: &str, second_extra: &str) -> String {
    format!(
        "name = \"m\"\n{}{}",
        toml_joint("name = \"shoulder\"\n", GOOD_BODY, ""),
        toml_joint("name = \"elbow\"\n", second_body, second_extra)
    )
}

fn err_of(text: &str) -> String {
    match parse_toml(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn toml_good_model_parses() {
    let c = parse_toml(&two_joint_model(GOOD_BODY, "xyz = [1.0, 0.0, 0.0]")).unwrap();
    assert_eq!(c.dof(), 2);
    assert_eq!(c.joints()[1].body, "elbow_body");
    assert_eq!(c.base(), "base");
}

#[test]
fn toml_negative_mass() {
    let e = err_of(&two_joint_model(
        "mass = -3.0\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }",
        "",
    ));
    assert!(
        e.contains("`elbow`") && e.contains("`body.mass`") && e.contains("-3"),
        "{e}"
    );
}

#[test]
fn toml_non_spd_inertia() {
    let e = err_of(&two_joint_model(
        "mass = 1.0\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0, ixy = 2.0 }",
        "",
    ));
    assert!(
        e.contains("`elbow`")
            && e.contains("`body.inertia`")
            && e.contains("positive semidefinite")
            && e.contains("--allow-nonphysical")
            && e.contains("allow_nonphysical = true"),
        "{e}"
    );
}

#[test]
fn toml_triangle_inequality() {
    let e = err_of(&two_joint_model(
        "mass = 1.0\ninertia = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]]",
        "",
    ));
    assert!(
        e.contains("`elbow`") && e.contains("`body.inertia`") && e.contains("triangle"),
        "{e}"
    );
}

#[test]
fn toml_zero_axis() {
    let text = two_joint_model(GOOD_BODY, "").replace(
        "name = \"elbow\"\ntype = \"revolute\"\naxis = [0.0, 0.0, 1.0]",
        "name = \"elbow\"\ntype = \"revolute\"\naxis = [0.0, 0.0, 0.0]",
    );
    let e = err_of(&text);
    assert!(
        e.contains("`elbow`") && e.contains("`axis`") && e.contains("zero"),
        "{e}"
    );
}

#[test]
fn toml_non_orthonormal_rotation() {
    let e = err_of(&two_joint_model(
        GOOD_BODY,
        "rotation = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]]",
    ));
    assert!(
        e.contains("`elbow`") && e.contains("`rotation`") && e.contains("not a rotation"),
        "{e}"
    );
    let e = err_of(&two_joint_model(
        GOOD_BODY,
        "rotation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\nrpy = [0.0, 0.0, 0.0]",
    ));
    assert!(e.contains("`elbow`") && e.contains("not both"), "{e}");
}

#[test]
fn toml_unknown_key() {
    let e = err_of(&two_joint_model(GOOD_BODY, "stiffness = 3.0"));
    assert!(e.contains("stiffness"), "{e}");
    let e = err_of(&two_joint_model(&format!("{GOOD_BODY}\ncolour = 1"), ""));
    assert!(e.contains("colour"), "{e}");
    let e = err_of(&two_joint_model(
        "mass = 1.0\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0, iyx = 0.0 }",
        "",
    ));
    assert!(e.contains("iyx"), "{e}");
    let e = err_of("name = \"m\"\n[dh]\nconvention = \"modified\"\nshift = 1\n");
    assert!(e.contains("shift"), "{e}");
}

#[test]
fn toml_duplicate_names() {
    let text = two_joint_model(GOOD_BODY, "").replace("\"elbow\"", "\"shoulder\"");
    let e = parse_toml(&text).unwrap_err();
    assert!(
        matches!(&e, ModelError::Duplicate { name, .. } if name == "shoulder"),
        "{e}"
    );
    assert!(e.to_string().contains("`shoulder`") && e.to_string().contains("joint"));
    let text = two_joint_model(&format!("name = \"shoulder_body\"\n{GOOD_BODY}"), "");
    let e = parse_toml(&text).unwrap_err().to_string();
    assert!(e.contains("`shoulder_body`") && e.contains("link"), "{e}");
}

#[test]
fn toml_empty_chain() {
    let e = parse_toml("name = \"nothing\"\n").unwrap_err();
    assert!(matches!(&e, ModelError::Empty(n) if n == "nothing"), "{e}");
}

#[test]
fn toml_nan_and_unnamed_joint() {
    let text = format!(
        "name = \"m\"\n{}{}",
        toml_joint("name = \"shoulder\"\n", GOOD_BODY, ""),
        toml_joint("", GOOD_BODY, "xyz = [0.0, nan, 0.0]")
    );
    let e = err_of(&text);
    assert!(
        e.contains("`joint #2`") && e.contains("`xyz`") && e.contains("NaN"),
        "{e}"
    );
    let e = err_of(&two_joint_model(
        "mass = nan\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }",
        "",
    ));
    assert!(
        e.contains("`elbow`") && e.contains("`body.mass`") && e.contains("NaN"),
        "{e}"
    );
    let e = err_of(&two_joint_model(
        "mass = 1.0\ncom = [inf, 0.0, 0.0]\ninertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }",
        "",
    ));
    assert!(e.contains("`elbow`") && e.contains("`body.com`"), "{e}");
}

#[test]
fn toml_geometry_mode_conflicts() {
    let e = err_of(&two_joint_model(GOOD_BODY, "alpha = 1.0"));
    assert!(
        e.contains("`elbow`") && e.contains("`alpha`") && e.contains("[dh]"),
        "{e}"
    );
    let e = err_of(&two_joint_model(GOOD_BODY, "").replacen(
        "[[joint]]",
        "[dh]\nconvention = \"standard\"\n[[joint]]",
        1,
    ));
    assert!(e.contains("`shoulder`") && e.contains("`axis`"), "{e}");
    let e = err_of(&two_joint_model(GOOD_BODY, "").replace("axis = [0.0, 0.0, 1.0]\n", ""));
    assert!(
        e.contains("`shoulder`") && e.contains("`axis`") && e.contains("missing"),
        "{e}"
    );
}

#[test]
fn toml_base_inertial() {
    let text = format!(
        "name = \"m\"\n[base]\nname = \"bus\"\nmass = 100.0\ncom = [0.0, 0.0, 0.5]\ninertia = {{ ixx = 10.0, iyy = 10.0, izz = 10.0 }}\n{}",
        toml_joint("name = \"j\"\n", GOOD_BODY, "")
    );
    let c = parse_toml(&text).unwrap();
    assert_eq!(c.base(), "bus");
    assert_eq!(c.base_inertial().unwrap().com, [0.0, 0.0, 0.5]);
    let e = err_of(&text.replace("mass = 100.0", "mass = -100.0"));
    assert!(e.contains("`bus`") && e.contains("`base.mass`"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// DH

#[test]
fn ssrms_xyz_modified_dh_and_standard_dh_agree() {
    let xyz = load_model(&repo().join("models/ssrms.toml")).unwrap();
    let urdf =
        load_model(&repo().join("tests/data/reference/ssrms_nguyen_hughes_1994.urdf")).unwrap();
    let modified = load_model(&repo().join("models/ssrms_dh.toml")).unwrap();
    let standard = load_model(&repo().join("models/ssrms_dh_standard.toml")).unwrap();
    // The DH tables' angles carry 10 significant digits.
    assert_same_dynamics(&urdf, &xyz, 1e-12);
    assert_same_dynamics(&xyz, &modified, 1e-8);
    assert_same_dynamics(&xyz, &standard, 1e-8);
    // The body frames differ (so the test can see a wrong mapping).
    assert!(modified.joints()[3].inertial.com != xyz.joints()[3].inertial.com);
}

/// Writes one arm in standard DH, in modified DH and in xyz/rotation form; all must agree.
#[test]
fn random_dh_arms_agree_across_conventions() {
    let mut seed = 99u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let fmt_v = |v: &V3| format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2]);
    let fmt_m = |m: &M3| format!("[{}, {}, {}]", fmt_v(&m[0]), fmt_v(&m[1]), fmt_v(&m[2]));
    let rot_x = |a: f64| -> M3 {
        let (s, c) = a.sin_cos();
        [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
    };
    let rot_z = |a: f64| -> M3 {
        let (s, c) = a.sin_cos();
        [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    };
    for trial in 0..5 {
        let n = 4;
        let kinds: Vec<&str> = (0..n)
            .map(|k| {
                if (k + trial) % 3 == 1 {
                    "prismatic"
                } else {
                    "revolute"
                }
            })
            .collect();
        // Standard rows (θ, d, a, α) and inertials in DH frame i.
        let rows: Vec<[f64; 4]> = (0..n)
            .map(|_| [3.0 * rnd(), rnd(), rnd(), 3.0 * rnd()])
            .collect();
        let bodies: Vec<(f64, V3, M3)> = (0..n)
            .map(|_| {
                let m = 1.0 + rnd().abs();
                let com = [rnd(), rnd(), rnd()];
                let r = rpy([3.0 * rnd(), 3.0 * rnd(), 3.0 * rnd()]);
                let d = [
                    [1.0 + 0.2 * rnd(), 0.0, 0.0],
                    [0.0, 1.0 + 0.2 * rnd(), 0.0],
                    [0.0, 0.0, 1.3 + 0.2 * rnd()],
                ];
                (m, com, mm(&mm(&r, &d), &tr(&r)))
            })
            .collect();
        let body_toml = |m: f64, c: &V3, i: &M3| {
            format!(
                "[joint.body]\nmass = {m:?}\ncom = {}\ninertia = {}\n",
                fmt_v(c),
                fmt_m(i)
            )
        };
        let head = "name = \"arm\"\n[dh]\nbase_xyz = [0.1, 0.2, 0.3]\nbase_rpy = [0.4, 0.5, 0.6]\n";
        // Standard DH.
        let mut std_t = format!("{head}convention = \"standard\"\n");
        for k in 0..n {
            let [th, d, a, al] = rows[k];
            std_t += &format!("[[joint]]\nname = \"j{k}\"\ntype = \"{}\"\ntheta = {th:?}\nd = {d:?}\na = {a:?}\nalpha = {al:?}\n", kinds[k]);
            std_t += &body_toml(bodies[k].0, &bodies[k].1, &bodies[k].2);
        }
        // Modified DH: row k takes a, α of standard row k−1; frame i = std frame i ∘ (TransX(a) RotX(α))⁻¹.
        let mut mod_t = format!("{head}convention = \"modified\"\n");
        for k in 0..n {
            let [th, d, _, _] = rows[k];
            let (ap, alp) = if k == 0 {
                (0.0, 0.0)
            } else {
                (rows[k - 1][2], rows[k - 1][3])
            };
            let (a, al) = (rows[k][2], rows[k][3]);
            let r = rot_x(al);
            let com = add(mv(&r, &bodies[k].1), [a, 0.0, 0.0]);
            let i = mm(&mm(&r, &bodies[k].2), &tr(&r));
            mod_t += &format!("[[joint]]\nname = \"j{k}\"\ntype = \"{}\"\ntheta = {th:?}\nd = {d:?}\na = {ap:?}\nalpha = {alp:?}\n", kinds[k]);
            mod_t += &body_toml(bodies[k].0, &com, &i);
        }
        // xyz/rotation form, body frame = modified DH frame i.
        let mut xyz_t = "name = \"arm\"\n".to_string();
        for k in 0..n {
            let [th, d, _, _] = rows[k];
            let (ap, alp) = if k == 0 {
                (0.0, 0.0)
            } else {
                (rows[k - 1][2], rows[k - 1][3])
            };
            // origin = RotX(α) TransX(a) RotZ(θ) TransZ(d)
            let mut r = mm(&rot_x(alp), &rot_z(th));
            let mut p = add(mv(&rot_x(alp), &[ap, 0.0, 0.0]), mv(&r, &[0.0, 0.0, d]));
            if k == 0 {
                let rb = rpy([0.4, 0.5, 0.6]);
                p = add(mv(&rb, &p), [0.1, 0.2, 0.3]);
                r = mm(&rb, &r);
            }
            let (a, al) = (rows[k][2], rows[k][3]);
            let rx = rot_x(al);
            let com = add(mv(&rx, &bodies[k].1), [a, 0.0, 0.0]);
            let i = mm(&mm(&rx, &bodies[k].2), &tr(&rx));
            xyz_t += &format!(
                "[[joint]]\nname = \"j{k}\"\ntype = \"{}\"\nxyz = {}\nrotation = {}\naxis = [0.0, 0.0, 1.0]\n",
                kinds[k], fmt_v(&p), fmt_m(&r)
            );
            xyz_t += &body_toml(bodies[k].0, &com, &i);
        }
        let s = parse_toml(&std_t).unwrap_or_else(|e| panic!("{e}\n{std_t}"));
        let m = parse_toml(&mod_t).unwrap_or_else(|e| panic!("{e}\n{mod_t}"));
        let x = parse_toml(&xyz_t).unwrap_or_else(|e| panic!("{e}\n{xyz_t}"));
        assert_same_dynamics(&x, &m, 1e-12);
        assert_same_dynamics(&x, &s, 1e-12);
    }
}

#[test]
fn to_toml_round_trips_random_chains_exactly() {
    use kanegen_model::random::{random_chain, ChainSpec};
    for seed in 0..20 {
        let spec = ChainSpec {
            n: 1 + seed as usize % 9,
            prismatic_fraction: 0.3,
            ..Default::default()
        };
        let chain = random_chain(&spec, seed);
        let text = kanegen_model::io::to_toml(&chain);
        let back = kanegen_model::io::parse_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(back, chain, "seed {seed}");
    }
    let ssrms = kanegen_model::io::load_model(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../models/ssrms.toml"
    )))
    .unwrap();
    assert_eq!(
        kanegen_model::io::parse_toml(&kanegen_model::io::to_toml(&ssrms)).unwrap(),
        ssrms
    );
}

#[test]
fn to_toml_round_trips_random_trees_exactly() {
    use kanegen_model::random::{random_tree, ChainSpec};
    for seed in 0..20 {
        let spec = ChainSpec {
            n: 1 + seed as usize % 9,
            prismatic_fraction: 0.3,
            ..Default::default()
        };
        let tree = random_tree(&spec, seed);
        let text = kanegen_model::io::to_toml(&tree);
        let back = kanegen_model::io::parse_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(back, tree, "seed {seed}");
    }
}

#[test]
fn with_base_inertial_sets_validated_base_mass_properties() {
    use kanegen_model::random::{random_chain, ChainSpec};
    use kanegen_model::{BaseKind, Inertial};
    let chain = random_chain(&ChainSpec::default(), 3);
    assert!(chain.base_inertial().is_none());
    assert!(chain
        .clone()
        .with_base_kind(BaseKind::FreeFloating)
        .is_err());
    let bus = Inertial {
        mass: 10.0,
        com: [0.0; 3],
        inertia: [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
    };
    let m = chain
        .clone()
        .with_base_inertial(bus.clone())
        .and_then(|m| m.with_base_kind(BaseKind::FreeFloating))
        .unwrap();
    assert_eq!(m.base_inertial(), Some(&bus));
    let bad = Inertial { mass: -1.0, ..bus };
    let e = chain.with_base_inertial(bad).unwrap_err().to_string();
    assert!(e.contains("base.inertial") && e.contains("mass"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Reliability: URDF positions, per-link inertials, magnitude bounds

/// URDF syntax errors carry the line and column; malformed elements their line and element.
#[test]
fn urdf_errors_name_the_line_and_element() {
    let e = parse_urdf("<robot name=\"r\">\n  <link name=\"a\">\n</robot>")
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 3"), "{e}");
    let text = MERGE_URDF.replace(r#"<origin xyz="2 0 0"/>"#, r#"<origin xyz="2 0"/>"#);
    let e = parse_urdf(&text).unwrap_err().to_string();
    let line = MERGE_URDF
        .lines()
        .position(|l| l.contains(r#"<origin xyz="2 0 0"/>"#))
        .unwrap()
        + 1;
    assert!(
        e.contains(&format!("line {line}")) && e.contains("<origin") && e.contains("xyz"),
        "{e}"
    );
    let text = MERGE_URDF.replace(
        r#"ixx="0.1" ixy="0" ixz="0" iyy="0.2""#,
        r#"ixx="x" ixy="0" ixz="0" iyy="0.2""#,
    );
    let e = parse_urdf(&text).unwrap_err().to_string();
    assert!(
        e.contains("<inertia") && e.contains("ixx") && e.contains("line"),
        "{e}"
    );
}

/// A fixed link's own inertia is checked before it is merged (the merged one may be fine),
/// naming the joint and the link; a rank-one placeholder inertia (B1's dummy `base` link: 1e-6
/// kg, every entry 1e-6) is semidefinite and accepted, as Pinocchio accepts it.
#[test]
fn urdf_fixed_link_with_a_non_positive_definite_inertia_is_rejected() {
    let dummy = MERGE_URDF.replace(
        r#"<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/>"#,
        r#"<inertia ixx="1e-6" ixy="1e-6" ixz="1e-6" iyy="1e-6" iyz="1e-6" izz="1e-6"/>"#,
    );
    assert_ne!(dummy, MERGE_URDF);
    parse_urdf(&dummy).unwrap();
    let text = MERGE_URDF.replace(
        r#"<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/>"#,
        r#"<inertia ixx="0.1" ixy="0" ixz="0" iyy="-0.05" iyz="0" izz="0.3"/>"#,
    );
    let e = parse_urdf(&text).unwrap_err().to_string();
    assert!(
        e.contains("`bracket`") && e.contains("link1b") && e.contains("positive semidefinite"),
        "{e}"
    );
}

/// Magnitudes whose squares or products overflow are errors naming the field and the bound; an
/// axis of 1e200 is normalized without overflow.
#[test]
fn magnitude_bounds_name_the_field_and_the_bound() {
    let base = r#"name = "b"
[[joint]]
name = "j"
type = "revolute"
xyz = XYZ
axis = AXIS
[joint.body]
mass = MASS
com = COM
inertia = { ixx = 1.0, iyy = 1.0, izz = 1.0 }
"#;
    let model = |xyz: &str, axis: &str, mass: &str, com: &str| {
        parse_toml(
            &base
                .replace("XYZ", xyz)
                .replace("AXIS", axis)
                .replace("MASS", mass)
                .replace("COM", com),
        )
    };
    let ok = model(
        "[0.0, 0.0, 1.0]",
        "[1e200, 0.0, 0.0]",
        "1.0",
        "[0.0, 0.0, 0.0]",
    )
    .unwrap();
    assert_eq!(ok.joints()[0].axis, [1.0, 0.0, 0.0]);
    // Shorter than 1e-9: a zero axis (its square would underflow to 0 as well).
    let e = model(
        "[0.0, 0.0, 1.0]",
        "[1e-200, 1e-200, 0.0]",
        "1.0",
        "[0.0, 0.0, 0.0]",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("zero axis"), "{e}");
    for (xyz, mass, com, field, bound) in [
        (
            "[0.0, 0.0, 1e308]",
            "1.0",
            "[0.0, 0.0, 0.0]",
            "xyz",
            "1e6 m",
        ),
        (
            "[0.0, 0.0, 1.0]",
            "1e13",
            "[0.0, 0.0, 0.0]",
            "body.mass",
            "1e12 kg",
        ),
        (
            "[0.0, 0.0, 1.0]",
            "1.0",
            "[1e200, 0.0, 0.0]",
            "body.com",
            "1e6 m",
        ),
    ] {
        let e = model(xyz, "[0.0, 0.0, 1.0]", mass, com)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("`{field}`")) && e.contains(bound) && e.contains("exceeds"),
            "{e}"
        );
    }
    let e = ok.lock_joint(0, f64::NAN).unwrap_err().to_string();
    assert!(e.contains("lock value") && e.contains("not finite"), "{e}");
}
