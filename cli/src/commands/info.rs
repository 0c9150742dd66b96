//! `kanegen info MODEL [--base fixed|free-floating] [--json]`: what a model file became — the
//! joints in the order of `q` (name, type, parent, axis, limits, mimic relation), the frames,
//! the number of coordinates, the base, the total mass, and what the URDF reader ignored and
//! merged.

use anyhow::{Context, Result};
use kanegen_model::io::ReadNotes;
use kanegen_model::{BaseKind, Limits, Model, Validation};
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

/// Loads `path`, on the given base, and prints its report (text or JSON) to `out`.
///
/// # Errors
/// The model does not load, or the base needs mass properties the model lacks.
pub fn run(
    path: &Path,
    base: Option<BaseKind>,
    allow_nonphysical: bool,
    as_json: bool,
    out: &mut dyn Write,
) -> Result<()> {
    let validation = Validation {
        allow_nonphysical_inertia: allow_nonphysical,
    };
    let (mut model, notes) = kanegen_model::io::load_model_noted(path, validation)
        .with_context(|| format!("model `{}`", path.display()))?;
    if let Some(kind) = base {
        model = model
            .with_base_kind(kind)
            .with_context(|| format!("model `{}`: --base", path.display()))?;
    }
    let report = info(&model, notes.as_ref());
    let text = if as_json {
        serde_json::to_string_pretty(&report)? + "\n"
    } else {
        render_text(&report)
    };
    crate::output::print(out, &text)
}

/// A joint as `info` reports it.
#[derive(Clone, Debug, Serialize)]
pub struct JointInfo {
    /// Joint name.
    pub name: String,
    /// `revolute` or `prismatic` (a URDF `continuous` joint is revolute without position limits).
    #[serde(rename = "type")]
    pub kind: &'static str,
    /// The joint whose body it hangs from, or `None` for the base.
    pub parent: Option<String>,
    /// Unit axis in the joint frame.
    pub axis: [f64; 3],
    /// The body it moves.
    pub body: String,
    /// Mass of that body (with the links fixed to it), kg.
    pub mass: f64,
    /// Its index in `q`, or `None` for a mimic joint (no coordinate of its own).
    pub coordinate: Option<usize>,
    /// Position, velocity and effort limits (absent: not given).
    pub limits: Limits,
    /// `q = multiplier · q[joint] + offset` for a mimic joint.
    pub mimic: Option<MimicInfo>,
}

/// A mimic relation, by name.
#[derive(Clone, Debug, Serialize)]
pub struct MimicInfo {
    /// The independent joint it follows.
    pub joint: String,
    /// Factor on that joint's position.
    pub multiplier: f64,
    /// Added to the position.
    pub offset: f64,
}

/// A named frame and the body it is fixed to.
#[derive(Clone, Debug, Serialize)]
pub struct FrameInfo {
    /// Frame name.
    pub name: String,
    /// The joint whose body holds it, or `None` for the base.
    pub parent: Option<String>,
}

/// What `info` prints.
#[derive(Clone, Debug, Serialize)]
pub struct Info {
    /// Model name.
    pub model: String,
    /// `fixed` or `free-floating`.
    pub base: &'static str,
    /// The base body's name.
    pub base_body: String,
    /// Number of entries of `q` (independent joints; the base's six speeds not counted).
    pub coordinates: usize,
    /// Number of joints (bodies), mimic joints included.
    pub joints_total: usize,
    /// Mass of every body and of the base, kg.
    pub total_mass: f64,
    /// The joints, in the order of the model (the coordinates in the order of `q`).
    pub joints: Vec<JointInfo>,
    /// The named frames.
    pub frames: Vec<FrameInfo>,
    /// Joints that move no mass (forward dynamics is undefined with them).
    pub massless_joints: Vec<String>,
    /// Elements the reader ignored, by tag, counted (URDF only).
    pub ignored: BTreeMap<String, usize>,
    /// Links merged into bodies through fixed joints (URDF only).
    pub merged: Vec<String>,
}

/// The report of `model`, with the reader's notes when it came from a URDF.
#[must_use]
pub fn info(model: &Model, notes: Option<&ReadNotes>) -> Info {
    let joints = model.joints();
    let name_of = |p: Option<usize>| p.map(|p| joints[p].name.clone());
    let mut next = 0;
    let joint_infos = joints
        .iter()
        .enumerate()
        .map(|(k, j)| {
            let mimic = model.mimics()[k].map(|m| MimicInfo {
                joint: joints[m.primary].name.clone(),
                multiplier: m.multiplier,
                offset: m.offset,
            });
            let coordinate = mimic.is_none().then(|| {
                next += 1;
                next - 1
            });
            JointInfo {
                name: j.name.clone(),
                kind: match j.kind {
                    kanegen_model::JointKind::Revolute => "revolute",
                    kanegen_model::JointKind::Prismatic => "prismatic",
                },
                parent: name_of(j.parent),
                axis: j.axis,
                body: j.body.clone(),
                mass: j.inertial.mass,
                coordinate,
                limits: model.limits()[k],
                mimic,
            }
        })
        .collect();
    Info {
        model: model.name().to_string(),
        base: model.base_kind().name(),
        base_body: model.base().to_string(),
        coordinates: model.coordinates().len(),
        joints_total: joints.len(),
        total_mass: model.base_inertial().map_or(0.0, |b| b.mass)
            + joints.iter().map(|j| j.inertial.mass).sum::<f64>(),
        joints: joint_infos,
        frames: model
            .frames()
            .iter()
            .map(|f| FrameInfo {
                name: f.name.clone(),
                parent: name_of(f.parent),
            })
            .collect(),
        massless_joints: model
            .massless_joints()
            .into_iter()
            .map(str::to_string)
            .collect(),
        ignored: notes.map(|n| n.ignored.clone()).unwrap_or_default(),
        merged: notes.map(|n| n.merged.clone()).unwrap_or_default(),
    }
}

/// `lo..hi` of a limit pair, `-` for absent values.
fn range(lo: Option<f64>, hi: Option<f64>) -> String {
    let f = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x}"));
    format!("[{}, {}]", f(lo), f(hi))
}

/// The text rendering: a header, one line per joint, then frames and notes.
#[must_use]
pub fn render_text(i: &Info) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "model {}: {} coordinates ({} joints), {} base `{}`, total mass {} kg",
        i.model, i.coordinates, i.joints_total, i.base, i.base_body, i.total_mass
    );
    let _ = writeln!(s, "\njoints (q order):");
    for j in &i.joints {
        let index = j
            .coordinate
            .map_or("  -".to_string(), |c| format!("{c:>3}"));
        let limits = &j.limits;
        let _ = write!(
            s,
            "{index} {} ({}, parent {}, axis [{}, {}, {}], position {}, velocity {}, effort {})",
            j.name,
            j.kind,
            j.parent.as_deref().unwrap_or("base"),
            j.axis[0],
            j.axis[1],
            j.axis[2],
            range(limits.lower, limits.upper),
            limits.velocity.map_or("-".into(), |v| v.to_string()),
            limits.effort.map_or("-".into(), |v| v.to_string()),
        );
        if let Some(m) = &j.mimic {
            let _ = write!(s, " = {} · {} + {}", m.multiplier, m.joint, m.offset);
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "\nframes:");
    for f in &i.frames {
        let _ = writeln!(
            s,
            "  {} (on {})",
            f.name,
            f.parent.as_deref().unwrap_or("base")
        );
    }
    if !i.massless_joints.is_empty() {
        let _ = writeln!(
            s,
            "\nmove no mass (forward dynamics undefined): {}",
            i.massless_joints.join(", ")
        );
    }
    if !i.merged.is_empty() {
        let _ = writeln!(s, "\nmerged fixed links: {}", i.merged.join(", "));
    }
    if !i.ignored.is_empty() {
        let items: Vec<String> = i
            .ignored
            .iter()
            .map(|(k, n)| format!("<{k}> × {n}"))
            .collect();
        let _ = writeln!(s, "ignored: {}", items.join(", "));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    const URDF: &str = r#"<robot name="gripper"><link name="base"/><gazebo/>
        <link name="palm"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial><visual/></link>
        <link name="left"><inertial><mass value="0.1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
        <link name="right"><inertial><mass value="0.1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
        <link name="tcp"/>
        <joint name="wrist" type="continuous"><parent link="base"/><child link="palm"/><axis xyz="0 0 1"/>
          <limit lower="-1" upper="1" velocity="2" effort="30"/></joint>
        <joint name="left_finger" type="prismatic"><parent link="palm"/><child link="left"/><axis xyz="0 1 0"/>
          <limit lower="0" upper="0.04" velocity="0.2" effort="100"/></joint>
        <joint name="right_finger" type="prismatic"><parent link="palm"/><child link="right"/><axis xyz="0 -1 0"/>
          <mimic joint="left_finger" multiplier="1" offset="0.001"/></joint>
        <joint name="tool" type="fixed"><parent link="palm"/><child link="tcp"/></joint>
        </robot>"#;

    #[test]
    fn lists_coordinates_limits_mimics_and_what_the_reader_left_out() {
        let dir = std::env::temp_dir().join(format!("kanegen-info-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("gripper.urdf");
        std::fs::write(&path, URDF).unwrap();
        let mut out = Vec::new();
        run(&path, None, false, true, &mut out).unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
        assert_eq!(v["coordinates"], 2);
        assert_eq!(v["joints_total"], 3);
        let names: Vec<&str> = v["joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| j["name"].as_str().unwrap())
            .collect();
        assert_eq!(names, ["wrist", "left_finger", "right_finger"]);
        let j = &v["joints"];
        // A continuous joint keeps velocity and effort limits, not position ones.
        assert_eq!(j[0]["limits"]["lower"], serde_json::Value::Null);
        assert_eq!(j[0]["limits"]["effort"], 30.0);
        assert_eq!(j[1]["limits"]["upper"], 0.04);
        assert_eq!(j[1]["coordinate"], 1);
        assert_eq!(j[2]["coordinate"], serde_json::Value::Null);
        assert_eq!(j[2]["mimic"]["joint"], "left_finger");
        assert_eq!(j[2]["mimic"]["offset"], 0.001);
        assert_eq!(j[2]["parent"], "wrist");
        assert_eq!(v["merged"], serde_json::json!(["tcp"]));
        assert_eq!(v["ignored"], serde_json::json!({"gazebo": 1, "visual": 1}));
        assert!((v["total_mass"].as_f64().unwrap() - 1.2).abs() < 1e-15);
        let mut text = Vec::new();
        run(&path, None, false, false, &mut text).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert!(
            text.contains("right_finger") && text.contains("= 1 · left_finger + 0.001"),
            "{text}"
        );
        let e = run(
            &path,
            Some(BaseKind::FreeFloating),
            false,
            true,
            &mut Vec::new(),
        );
        assert!(format!("{:#}", e.unwrap_err()).contains("--base"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
