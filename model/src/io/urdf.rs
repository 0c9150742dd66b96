//! URDF reader: kinematic trees; fixed joints merged into their moving parent body, fixed links
//! kept as named frames.
//!
//! Read with `roxmltree`, which keeps every element's position: syntax errors and malformed
//! elements are reported with their line and element (`URDF line 12, <joint name="j1">: <origin
//! xyz="1 2">: expected 3 numbers`). Only the kinematic and inertial subset is read (robot name;
//! links' `<inertial>` origin, mass and inertia; joints' name, type, origin, parent, child,
//! axis, `<limit>` and `<mimic>`); every other element (`<visual>`, `<collision>`,
//! `<dynamics>`, `<transmission>`, `<gazebo>`, `<material>`, …) is ignored and counted in the
//! [`ReadNotes`]. A link without `<inertial>` is massless; a moving body that ends up massless
//! is a massless body ([`Model::massless_joints`]). Every link's own inertial is checked (bounds,
//! inertia positive semidefinite to [`crate::inertial::PHYSICAL_TOLERANCE`]: points, rods and
//! placeholder links are accepted, as Pinocchio accepts them) before it is merged, naming the
//! link and its line; the merged body is then checked whole (also the triangle inequality).

use crate::bounds::{INERTIA, LENGTH, MASS};
use crate::inertial::{nonphysical, validate_inertial_with, NONPHYSICAL_OVERRIDE};
use crate::placement::{Placement, M3};
use crate::{Frame, Inertial, Joint, JointKind, Limits, Mimic, Model, ModelError, Validation};
use serde::Serialize;
use std::collections::{BTreeMap, HashMap, HashSet};

/// A link as read: its name, its `<inertial>` (absent: massless) and its line.
struct ULink {
    name: String,
    inertial: Option<UInertial>,
    line: u32,
}

/// A link's `<inertial>`: origin (`xyz`, `rpy`), mass, inertia tensor (URDF attributes).
struct UInertial {
    xyz: [f64; 3],
    rpy: [f64; 3],
    mass: f64,
    inertia: M3,
}

/// The joint types of URDF.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum JointType {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
    Floating,
    Planar,
    Spherical,
}

/// A `<mimic joint multiplier offset>` as read.
struct UMimic {
    joint: String,
    multiplier: f64,
    offset: f64,
}

/// A joint as read.
struct UJoint {
    name: String,
    joint_type: JointType,
    xyz: [f64; 3],
    rpy: [f64; 3],
    parent: String,
    child: String,
    axis: [f64; 3],
    limits: Limits,
    mimic: Option<UMimic>,
    line: u32,
}

/// A URDF document as read.
struct Urdf {
    name: String,
    links: Vec<ULink>,
    joints: Vec<UJoint>,
    ignored: BTreeMap<String, usize>,
}

/// What the URDF reader left out or merged (reported by `kanegen info`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ReadNotes {
    /// Elements not read, by tag (`gazebo`, `transmission`, `visual`, …), with their count;
    /// `mimic (on a fixed joint)` counts mimic tags where there is nothing to couple.
    pub ignored: BTreeMap<String, usize>,
    /// Links attached by fixed joints, merged into the body (or base) they hang from and kept
    /// as named frames.
    pub merged: Vec<String>,
}

/// `URDF line L, <elem name="…">: message`.
fn at(doc: &roxmltree::Document, node: roxmltree::Node, msg: impl std::fmt::Display) -> ModelError {
    let line = doc.text_pos_at(node.range().start).row;
    let name = node
        .attribute("name")
        .map(|n| format!(" name=\"{n}\""))
        .unwrap_or_default();
    ModelError::Parse(format!(
        "URDF line {line}, <{}{name}>: {msg}",
        node.tag_name().name()
    ))
}

fn line_of(doc: &roxmltree::Document, node: roxmltree::Node) -> u32 {
    doc.text_pos_at(node.range().start).row
}

/// A required attribute.
fn attr<'a>(
    doc: &roxmltree::Document,
    node: roxmltree::Node<'a, 'a>,
    key: &str,
) -> Result<&'a str, ModelError> {
    node.attribute(key)
        .ok_or_else(|| at(doc, node, format!("missing attribute `{key}`")))
}

/// A number attribute.
fn number(doc: &roxmltree::Document, node: roxmltree::Node, key: &str) -> Result<f64, ModelError> {
    let v = attr(doc, node, key)?;
    v.trim().parse::<f64>().map_err(|_| {
        at(
            doc,
            node,
            format!("attribute `{key}`: `{v}` is not a number"),
        )
    })
}

/// An optional 3-vector attribute (`"x y z"`).
fn vec3(
    doc: &roxmltree::Document,
    node: roxmltree::Node,
    key: &str,
    default: [f64; 3],
) -> Result<[f64; 3], ModelError> {
    let Some(v) = node.attribute(key) else {
        return Ok(default);
    };
    let parts: Vec<&str> = v.split_whitespace().collect();
    let nums: Vec<f64> = parts.iter().filter_map(|p| p.parse().ok()).collect();
    if parts.len() != 3 || nums.len() != 3 {
        return Err(at(
            doc,
            node,
            format!("attribute `{key}`: expected 3 numbers, got `{v}`"),
        ));
    }
    Ok([nums[0], nums[1], nums[2]])
}

fn child<'a>(node: roxmltree::Node<'a, 'a>, tag: &str) -> Option<roxmltree::Node<'a, 'a>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == tag)
}

/// `<origin xyz rpy>` of `node` (identity when absent).
fn origin(
    doc: &roxmltree::Document,
    node: roxmltree::Node,
) -> Result<([f64; 3], [f64; 3]), ModelError> {
    match child(node, "origin") {
        None => Ok(([0.0; 3], [0.0; 3])),
        Some(o) => Ok((
            vec3(doc, o, "xyz", [0.0; 3])?,
            vec3(doc, o, "rpy", [0.0; 3])?,
        )),
    }
}

/// An optional number attribute.
fn opt_number(
    doc: &roxmltree::Document,
    node: roxmltree::Node,
    key: &str,
) -> Result<Option<f64>, ModelError> {
    node.attribute(key)
        .map(|_| number(doc, node, key))
        .transpose()
}

/// A link's `<inertial>`, when it has one.
fn read_inertial(
    doc: &roxmltree::Document,
    node: roxmltree::Node,
) -> Result<Option<UInertial>, ModelError> {
    let Some(i) = child(node, "inertial") else {
        return Ok(None);
    };
    let (xyz, rpy) = origin(doc, i)?;
    let m = child(i, "mass").ok_or_else(|| at(doc, i, "missing <mass value=…>"))?;
    let t = child(i, "inertia").ok_or_else(|| at(doc, i, "missing <inertia ixx=… …>"))?;
    let [ixx, ixy, ixz, iyy, iyz, izz] =
        ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"].map(|k| number(doc, t, k));
    let (ixx, ixy, ixz, iyy, iyz, izz) = (ixx?, ixy?, ixz?, iyy?, iyz?, izz?);
    Ok(Some(UInertial {
        xyz,
        rpy,
        mass: number(doc, m, "value")?,
        inertia: [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]],
    }))
}

/// A `<joint>` element.
fn read_joint(doc: &roxmltree::Document, node: roxmltree::Node) -> Result<UJoint, ModelError> {
    let ty = attr(doc, node, "type")?;
    let joint_type = match ty {
        "revolute" => JointType::Revolute,
        "continuous" => JointType::Continuous,
        "prismatic" => JointType::Prismatic,
        "fixed" => JointType::Fixed,
        "floating" => JointType::Floating,
        "planar" => JointType::Planar,
        "spherical" => JointType::Spherical,
        other => return Err(at(doc, node, format!("unknown joint type `{other}`"))),
    };
    let end = |tag: &str| -> Result<String, ModelError> {
        let e = child(node, tag).ok_or_else(|| at(doc, node, format!("missing <{tag} link=…>")))?;
        Ok(attr(doc, e, "link")?.to_string())
    };
    let (xyz, rpy) = origin(doc, node)?;
    let axis = match child(node, "axis") {
        None => [1.0, 0.0, 0.0],
        Some(a) => vec3(doc, a, "xyz", [1.0, 0.0, 0.0])?,
    };
    let limits = match child(node, "limit") {
        None => Limits::default(),
        Some(l) => Limits {
            lower: opt_number(doc, l, "lower")?,
            upper: opt_number(doc, l, "upper")?,
            velocity: opt_number(doc, l, "velocity")?,
            effort: opt_number(doc, l, "effort")?,
        },
    };
    let mimic = child(node, "mimic")
        .map(|m| -> Result<UMimic, ModelError> {
            Ok(UMimic {
                joint: attr(doc, m, "joint")?.to_string(),
                multiplier: opt_number(doc, m, "multiplier")?.unwrap_or(1.0),
                offset: opt_number(doc, m, "offset")?.unwrap_or(0.0),
            })
        })
        .transpose()?;
    Ok(UJoint {
        name: attr(doc, node, "name")?.to_string(),
        joint_type,
        xyz,
        rpy,
        parent: end("parent")?,
        child: end("child")?,
        axis,
        limits,
        mimic,
        line: line_of(doc, node),
    })
}

/// The child elements of `node` the reader does not read, counted by tag into `ignored`.
fn count_ignored(node: roxmltree::Node, read: &[&str], ignored: &mut BTreeMap<String, usize>) {
    for c in node.children().filter(roxmltree::Node::is_element) {
        let tag = c.tag_name().name();
        if !read.contains(&tag) {
            *ignored.entry(tag.to_string()).or_default() += 1;
        }
    }
}

/// Reads the robot's name, links and joints, counting what it ignores.
fn read(text: &str) -> Result<Urdf, ModelError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let p = e.pos();
        ModelError::Parse(format!("URDF line {}, column {}: {e}", p.row, p.col))
    })?;
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(at(&doc, robot, "the root element must be <robot>"));
    }
    let mut urdf = Urdf {
        name: robot.attribute("name").unwrap_or_default().to_string(),
        links: Vec::new(),
        joints: Vec::new(),
        ignored: BTreeMap::new(),
    };
    count_ignored(robot, &["link", "joint"], &mut urdf.ignored);
    for node in robot.children().filter(roxmltree::Node::is_element) {
        match node.tag_name().name() {
            "link" => {
                count_ignored(node, &["inertial"], &mut urdf.ignored);
                urdf.links.push(ULink {
                    name: attr(&doc, node, "name")?.to_string(),
                    inertial: read_inertial(&doc, node)?,
                    line: line_of(&doc, node),
                });
            }
            "joint" => {
                let read = ["origin", "parent", "child", "axis", "limit", "mimic"];
                count_ignored(node, &read, &mut urdf.ignored);
                urdf.joints.push(read_joint(&doc, node)?);
            }
            _ => {}
        }
    }
    Ok(urdf)
}

/// Parses a URDF document into a [`Model`].
///
/// * Revolute, continuous (treated as revolute), prismatic and fixed joints are accepted;
///   floating, planar and spherical joints are rejected naming the joint.
/// * The root is the link that is no joint's child; the tree is walked from it depth first,
///   the child joints of a link in the order of the file. Each moving joint becomes a joint of
///   the model in that order (so parents come first); its parent is the moving body the joint's
///   parent link belongs to, or the base.
/// * Fixed joints are merged: the child link's inertial is added to the moving body (or the base)
///   its parent link belongs to (combined mass, CoM, and inertia about the combined CoM by the
///   parallel-axis theorem, in that body's frame), and the fixed joint's origin is composed into
///   the origins of the moving joints below it. Every link attached by fixed joints is kept as a
///   named [`Frame`] (tool flanges, sensors), with its placement in that body's frame.
/// * The inertial `<origin>` is honoured: `com = xyz`, `I_body = R(rpy) I_urdf Rᵀ`.
/// * Visual and collision elements are ignored (meshes are never opened).
///
/// The model is named after the robot; the base after the root link, whose (merged) inertial
/// becomes the base inertial when its mass is non-zero. The base is fixed
/// ([`Model::with_base_kind`] makes it free-floating).
pub fn parse_urdf(text: &str) -> Result<Model, ModelError> {
    parse_urdf_with(text, Validation::default())
}

/// [`parse_urdf`] under the given [`Validation`].
pub fn parse_urdf_with(text: &str, validation: Validation) -> Result<Model, ModelError> {
    parse_urdf_noted(text, validation).map(|(model, _)| model)
}

/// [`parse_urdf_with`], with what the reader ignored and merged.
pub fn parse_urdf_noted(
    text: &str,
    validation: Validation,
) -> Result<(Model, ReadNotes), ModelError> {
    let urdf = read(text)?;
    let tree = Tree::new(&urdf)?;
    let walk = walk(&urdf, &tree, validation)?;
    let mimics = resolve_mimics(&urdf, &walk)?;
    let limits = walk
        .sources
        .iter()
        .map(|j| match j.joint_type {
            // A continuous joint has no position limits (Pinocchio ignores them).
            JointType::Continuous => Limits {
                lower: None,
                upper: None,
                ..j.limits
            },
            _ => j.limits,
        })
        .collect();
    let mut ignored = urdf.ignored.clone();
    let fixed_mimics = urdf
        .joints
        .iter()
        .filter(|j| j.joint_type == JointType::Fixed && j.mimic.is_some())
        .count();
    if fixed_mimics > 0 {
        ignored.insert("mimic (on a fixed joint)".into(), fixed_mimics);
    }
    let notes = ReadNotes {
        ignored,
        merged: walk.frames.iter().map(|f| f.name.clone()).collect(),
    };
    let model = Model::new_with(
        urdf.name.clone(),
        tree.root,
        walk.base_inertial,
        walk.joints,
        validation,
    )?
    .with_frames(walk.frames)?
    .with_limits(limits)?
    .with_mimics(mimics)?;
    Ok((model, notes))
}

/// The links by name, the child joints of each link (in file order) and the root link.
struct Tree<'a> {
    links: HashMap<&'a str, &'a ULink>,
    children: HashMap<&'a str, Vec<&'a UJoint>>,
    root: &'a str,
}

impl<'a> Tree<'a> {
    /// Checks names, joint types and link references, and finds the one root.
    fn new(urdf: &'a Urdf) -> Result<Self, ModelError> {
        let mut links = HashMap::new();
        for l in &urdf.links {
            if links.insert(l.name.as_str(), l).is_some() {
                return Err(ModelError::Duplicate {
                    name: l.name.clone(),
                    what: "link".into(),
                });
            }
        }
        let mut joint_names = HashSet::new();
        let mut children: HashMap<&str, Vec<&UJoint>> = HashMap::new();
        let mut is_child = HashSet::new();
        for j in &urdf.joints {
            if !joint_names.insert(j.name.as_str()) {
                return Err(ModelError::Duplicate {
                    name: j.name.clone(),
                    what: "joint".into(),
                });
            }
            check_joint(j, &links)?;
            if !is_child.insert(j.child.as_str()) {
                return Err(ModelError::invalid(
                    &j.name,
                    "child",
                    format!(
                        "link `{}` is the child of more than one joint (URDF line {})",
                        j.child, j.line
                    ),
                ));
            }
            children.entry(j.parent.as_str()).or_default().push(j);
        }
        let roots: Vec<&str> = urdf
            .links
            .iter()
            .map(|l| l.name.as_str())
            .filter(|n| !is_child.contains(n))
            .collect();
        let root = match roots.as_slice() {
            [r] => *r,
            [] => {
                return Err(ModelError::Parse(format!(
                    "URDF `{}`: no root link (every link is some joint's child)",
                    urdf.name
                )))
            }
            many => {
                return Err(ModelError::Parse(format!(
                    "URDF `{}`: several root links ({}); the model must be one connected chain",
                    urdf.name,
                    many.join(", ")
                )))
            }
        };
        Ok(Tree {
            links,
            children,
            root,
        })
    }

    fn kids(&self, link: &str) -> &[&'a UJoint] {
        self.children.get(link).map(Vec::as_slice).unwrap_or(&[])
    }
}

/// A supported joint type, and links that exist.
fn check_joint(j: &UJoint, links: &HashMap<&str, &ULink>) -> Result<(), ModelError> {
    match j.joint_type {
        JointType::Revolute | JointType::Continuous | JointType::Prismatic | JointType::Fixed => {}
        other => {
            return Err(ModelError::invalid(
                &j.name,
                "type",
                format!(
                    "{} joints are not supported (only revolute, continuous, prismatic and \
                     fixed; URDF line {})",
                    format!("{other:?}").to_lowercase(),
                    j.line
                ),
            ))
        }
    }
    for (end, link) in [("parent", &j.parent), ("child", &j.child)] {
        if !links.contains_key(link.as_str()) {
            return Err(ModelError::invalid(
                &j.name,
                end,
                format!("unknown link `{link}` (URDF line {})", j.line),
            ));
        }
    }
    Ok(())
}

/// The tree walked: the model's joints (each with its merged body), the URDF joint each came
/// from, the frames of the fixed links, and the base's merged inertial (`None`: massless).
struct Walk<'a> {
    joints: Vec<Joint>,
    sources: Vec<&'a UJoint>,
    frames: Vec<Frame>,
    base_inertial: Option<Inertial>,
}

/// Walks the tree depth first from the root, merging fixed links into the moving body (or the
/// base) they hang from, then checks each merged body whole, naming its link and line.
fn walk<'a>(urdf: &Urdf, tree: &Tree<'a>, validation: Validation) -> Result<Walk<'a>, ModelError> {
    // Each link belongs to a moving body (`None`: the base) and sits at `offset` in that body's
    // frame; `acc[body]` accumulates the body's parts.
    let mut acc: HashMap<Option<usize>, Option<Inertial>> = HashMap::new();
    let mut out = Walk {
        joints: Vec::new(),
        sources: Vec::new(),
        frames: Vec::new(),
        base_inertial: None,
    };
    let root = tree.links[tree.root];
    add_link(
        acc.entry(None).or_default(),
        &Placement::identity(),
        root,
        tree.root,
        validation,
    )?;
    // Joints to walk, each with the moving body its parent link belongs to and that link's
    // offset in the body frame; a link's child joints are pushed in reverse so that the first in
    // the file is walked first, and the whole subtree of a joint before its next sibling
    // (depth-first preorder: parents get smaller indices than their children).
    let mut stack: Vec<(&UJoint, Option<usize>, Placement)> = tree
        .kids(tree.root)
        .iter()
        .rev()
        .map(|j| (*j, None, Placement::identity()))
        .collect();
    let mut visited = 1usize;
    while let Some((j, owner, offset)) = stack.pop() {
        visited += 1;
        if visited > urdf.links.len() {
            return Err(ModelError::Parse(format!(
                "URDF `{}`: the joint graph has a cycle",
                urdf.name
            )));
        }
        let origin = offset.then(&Placement::from_xyz_rpy(j.xyz, j.rpy));
        let child = tree.links[j.child.as_str()];
        let (child_owner, child_offset) = if j.joint_type == JointType::Fixed {
            add_link(
                acc.entry(owner).or_default(),
                &origin,
                child,
                &j.name,
                validation,
            )?;
            out.frames.push(Frame {
                name: child.name.clone(),
                parent: owner,
                placement: origin,
            });
            (owner, origin)
        } else {
            let k = out.joints.len();
            out.joints.push(Joint {
                name: j.name.clone(),
                kind: if j.joint_type == JointType::Prismatic {
                    JointKind::Prismatic
                } else {
                    JointKind::Revolute
                },
                parent: owner,
                origin,
                axis: j.axis,
                body: child.name.clone(),
                inertial: inertial_of(&None),
            });
            out.sources.push(j);
            let part = acc.entry(Some(k)).or_default();
            add_link(part, &Placement::identity(), child, &j.name, validation)?;
            (Some(k), Placement::identity())
        };
        stack.extend(
            tree.kids(&child.name)
                .iter()
                .rev()
                .map(|c| (*c, child_owner, child_offset)),
        );
    }
    if visited < urdf.links.len() {
        return Err(ModelError::Parse(format!(
            "URDF `{}`: {} link(s) are not reachable from the root `{}`",
            urdf.name,
            urdf.links.len() - visited,
            tree.root
        )));
    }
    for (k, j) in out.joints.iter_mut().enumerate() {
        j.inertial = inertial_of(acc.get(&Some(k)).unwrap_or(&None));
        let line = tree.links[j.body.as_str()].line;
        validate_inertial_with(&j.name, "inertial", &j.inertial, validation).map_err(
            |e| match e {
                ModelError::Invalid {
                    joint,
                    field,
                    reason,
                } => ModelError::Invalid {
                    joint,
                    field: format!(
                        "{field} (link `{}` with the links fixed to it, URDF line {line})",
                        j.body
                    ),
                    reason,
                },
                other => other,
            },
        )?;
    }
    let base = inertial_of(acc.get(&None).unwrap_or(&None));
    out.base_inertial = (base.mass != 0.0).then_some(base);
    Ok(out)
}

/// Each moving joint's mimic coupling, resolved through chains of mimics to an independent
/// joint: `q = m₁ (m₂ q_p + o₂) + o₁ = m₁m₂ q_p + (m₁o₂ + o₁)`.
fn resolve_mimics(urdf: &Urdf, walk: &Walk) -> Result<Vec<Option<Mimic>>, ModelError> {
    let index: HashMap<&str, usize> = walk
        .sources
        .iter()
        .enumerate()
        .map(|(k, j)| (j.name.as_str(), k))
        .collect();
    let line_of = |name: &str| urdf.joints.iter().find(|j| j.name == name).map(|j| j.line);
    let mut out = Vec::with_capacity(walk.sources.len());
    for j in &walk.sources {
        let Some(first) = &j.mimic else {
            out.push(None);
            continue;
        };
        let (mut multiplier, mut offset) = (first.multiplier, first.offset);
        let mut target = first.joint.as_str();
        let mut path = vec![j.name.as_str()];
        loop {
            let field = "mimic.joint";
            let Some(&k) = index.get(target) else {
                let why = match line_of(target) {
                    Some(l) => {
                        format!("joint `{target}` (URDF line {l}) is fixed: nothing to follow")
                    }
                    None => format!("no joint `{target}` in the file"),
                };
                return Err(ModelError::invalid(
                    &j.name,
                    field,
                    format!("{why} (URDF line {})", j.line),
                ));
            };
            path.push(target);
            if path[..path.len() - 1].contains(&target) {
                return Err(ModelError::invalid(
                    &j.name,
                    field,
                    format!(
                        "the mimic chain {} is a cycle (URDF line {})",
                        path.join(" → "),
                        j.line
                    ),
                ));
            }
            match &walk.sources[k].mimic {
                None => {
                    out.push(Some(Mimic {
                        primary: k,
                        multiplier,
                        offset,
                    }));
                    break;
                }
                Some(next) => {
                    offset += multiplier * next.offset;
                    multiplier *= next.multiplier;
                    target = next.joint.as_str();
                }
            }
        }
    }
    Ok(out)
}

fn inertial_of(acc: &Option<Inertial>) -> Inertial {
    acc.clone().unwrap_or(Inertial {
        mass: 0.0,
        com: [0.0; 3],
        inertia: [[0.0; 3]; 3],
    })
}

/// Adds a link's `<inertial>` (placed at `offset` in the body frame) to the body, after checking
/// the link's own mass properties (bounds; with mass, a valid inertia about its centre of mass).
/// Errors name `owner` (the joint whose child the link is, or the root link) and the link.
fn add_link(
    acc: &mut Option<Inertial>,
    offset: &Placement,
    link: &ULink,
    owner: &str,
    validation: Validation,
) -> Result<(), ModelError> {
    let Some(inl) = &link.inertial else {
        return Ok(());
    };
    let field = |f: &str| {
        format!(
            "inertial.{f} (link `{}`, URDF line {})",
            link.name, link.line
        )
    };
    let m = inl.mass;
    if !m.is_finite() || m < 0.0 {
        return Err(ModelError::invalid(
            owner,
            &field("mass"),
            format!("link mass must be finite and ≥ 0, got {m}"),
        ));
    }
    let inertia = inl.inertia;
    if m != 0.0 {
        MASS.check(&[m])
            .map_err(|r| ModelError::invalid(owner, &field("mass"), r))?;
    }
    LENGTH
        .check(&inl.xyz)
        .map_err(|r| ModelError::invalid(owner, &field("origin.xyz"), r))?;
    INERTIA
        .check(inertia.as_flattened())
        .map_err(|r| ModelError::invalid(owner, &field("inertia"), r))?;
    // A link on its own may be a point, a rod or a placeholder (Pinocchio takes them all: a
    // dummy `base` link of 1e-6 kg with every inertia entry 1e-6 is rank one); it must not have
    // negative moments. The body it is merged into is then checked whole (triangle inequality).
    let own = Inertial {
        mass: m,
        com: inl.xyz,
        inertia,
    };
    if let Some(why) = (!validation.allow_nonphysical_inertia)
        .then(|| nonphysical(&own, false))
        .flatten()
    {
        return Err(ModelError::invalid(
            owner,
            &field("inertia"),
            format!("{why}: not physically realisable; {NONPHYSICAL_OVERRIDE}"),
        ));
    }
    let part = Inertial {
        mass: m,
        com: [0.0; 3],
        inertia,
    };
    let frame = offset.then(&Placement::from_xyz_rpy(inl.xyz, inl.rpy));
    *acc = Inertial::merge_opt(acc.take(), Some(part.moved(&frame)));
    Ok(())
}
