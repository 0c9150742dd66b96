//! Writes a [`Model`] in kanegen's TOML model format (the inverse of [`super::parse_toml`]).

use crate::{BaseKind, Inertial, JointKind, Model};
use std::fmt::Write;

fn v3(x: &[f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", x[0], x[1], x[2])
}

fn m3(m: &[[f64; 3]; 3]) -> String {
    format!("[{}, {}, {}]", v3(&m[0]), v3(&m[1]), v3(&m[2]))
}

fn inertial(s: &mut String, table: &str, b: &Inertial) {
    let _ = writeln!(s, "mass = {:?}", b.mass);
    let _ = writeln!(s, "com = {}", v3(&b.com));
    let _ = writeln!(s, "inertia = {}", m3(&b.inertia));
    let _ = table;
}

/// The model as a kanegen TOML model: every joint with `xyz`, a `rotation` matrix, `axis`, its
/// `parent` where it is not the previous joint, and its body's inertial; the base's inertial and
/// type when the model has them; the named frames. Numbers are written with full precision
/// (`{:?}`), so reading the text back gives the same model exactly.
pub fn to_toml(model: &Model) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "name = {:?}", model.name());
    match model.base_inertial() {
        Some(b) => {
            let _ = writeln!(s, "\n[base]\nname = {:?}", model.base());
            if model.base_kind() == BaseKind::FreeFloating {
                let _ = writeln!(s, "type = \"free-floating\"");
            }
            inertial(&mut s, "base", b);
        }
        None => {
            let _ = writeln!(s, "base = {:?}", model.base());
        }
    }
    let parent_name = |p: Option<usize>| match p {
        Some(p) => model.joints()[p].name.clone(),
        None => model.base().to_string(),
    };
    for (k, j) in model.joints().iter().enumerate() {
        let kind = match j.kind {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        };
        let _ = writeln!(s, "\n[[joint]]\nname = {:?}\ntype = {kind:?}", j.name);
        let _ = writeln!(s, "xyz = {}", v3(&j.origin.translation));
        let _ = writeln!(s, "rotation = {}", m3(&j.origin.rotation));
        let _ = writeln!(s, "axis = {}", v3(&j.axis));
        if j.parent != k.checked_sub(1) {
            let _ = writeln!(s, "parent = {:?}", parent_name(j.parent));
        }
        let _ = writeln!(s, "[joint.body]\nname = {:?}", j.body);
        inertial(&mut s, "joint.body", &j.inertial);
    }
    for f in model.frames() {
        let _ = writeln!(s, "\n[[frame]]\nname = {:?}", f.name);
        let _ = writeln!(s, "parent = {:?}", parent_name(f.parent));
        let _ = writeln!(s, "xyz = {}", v3(&f.placement.translation));
        let _ = writeln!(s, "rotation = {}", m3(&f.placement.rotation));
    }
    s
}
