//! Writes a [`Model`] in kanegen's TOML model format (the inverse of [`super::parse_toml`]).

use crate::{Inertial, JointKind, Model};
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

/// The chain as a kanegen TOML model: every joint with `xyz`, a `rotation` matrix, `axis` and its
/// body's inertial; the base's inertial when the chain has one. Numbers are written with full
/// precision (`{:?}`), so reading the text back gives the same chain exactly.
pub fn to_toml(chain: &Model) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "name = {:?}", chain.name());
    match chain.base_inertial() {
        Some(b) => {
            let _ = writeln!(s, "\n[base]\nname = {:?}", chain.base());
            inertial(&mut s, "base", b);
        }
        None => {
            let _ = writeln!(s, "base = {:?}", chain.base());
        }
    }
    for j in chain.joints() {
        let kind = match j.kind {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        };
        let _ = writeln!(s, "\n[[joint]]\nname = {:?}\ntype = {kind:?}", j.name);
        let _ = writeln!(s, "xyz = {}", v3(&j.origin.translation));
        let _ = writeln!(s, "rotation = {}", m3(&j.origin.rotation));
        let _ = writeln!(s, "axis = {}", v3(&j.axis));
        let _ = writeln!(s, "[joint.body]\nname = {:?}", j.body);
        inertial(&mut s, "joint.body", &j.inertial);
    }
    s
}
