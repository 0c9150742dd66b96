//! URDF reader: kinematic trees; fixed joints merged into their moving parent body, fixed links
//! kept as named frames.
//!
//! Read with `roxmltree`, which keeps every element's position: syntax errors and malformed
//! elements are reported with their line and element (`URDF line 12, <joint name="j1">: <origin
//! xyz="1 2">: expected 3 numbers`). Only the kinematic and inertial subset is read (robot name;
//! links' `<inertial>` origin, mass and inertia; joints' name, type, origin, parent, child and
//! axis); `<visual>`, `<collision>`, `<limit>`, `<dynamics>`, `<transmission>`, `<gazebo>` and
//! `<material>` are ignored. A link without `<inertial>` is massless, which is fine when it is
//! merged through a fixed joint into a body with mass; a moving body that ends up massless is
//! rejected by [`Model::new`] (mass must be > 0). Every link's own inertial is checked (bounds,
//! inertia positive semidefinite: points, rods and placeholder links are accepted, as Pinocchio
//! accepts them) before it is merged, naming the link; the merged body is then checked whole.

use crate::bounds::{INERTIA, LENGTH, MASS};
use crate::placement::{Placement, M3};
use crate::{Frame, Inertial, Joint, JointKind, Model, ModelError, Validation};
use std::collections::{HashMap, HashSet};

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

/// A joint as read.
struct UJoint {
    name: String,
    joint_type: JointType,
    xyz: [f64; 3],
    rpy: [f64; 3],
    parent: String,
    child: String,
    axis: [f64; 3],
    line: u32,
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

/// Reads the robot's name, links and joints.
fn read(text: &str) -> Result<(String, Vec<ULink>, Vec<UJoint>), ModelError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let p = e.pos();
        ModelError::Parse(format!("URDF line {}, column {}: {e}", p.row, p.col))
    })?;
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(at(&doc, robot, "the root element must be <robot>"));
    }
    let mut links = Vec::new();
    let mut joints = Vec::new();
    for node in robot.children().filter(roxmltree::Node::is_element) {
        match node.tag_name().name() {
            "link" => {
                let inertial = match child(node, "inertial") {
                    None => None,
                    Some(i) => {
                        let (xyz, rpy) = origin(&doc, i)?;
                        let m = child(i, "mass")
                            .ok_or_else(|| at(&doc, i, "missing <mass value=…>"))?;
                        let t = child(i, "inertia")
                            .ok_or_else(|| at(&doc, i, "missing <inertia ixx=… …>"))?;
                        let [ixx, ixy, ixz, iyy, iyz, izz] =
                            ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"].map(|k| number(&doc, t, k));
                        let (ixx, ixy, ixz, iyy, iyz, izz) = (ixx?, ixy?, ixz?, iyy?, iyz?, izz?);
                        Some(UInertial {
                            xyz,
                            rpy,
                            mass: number(&doc, m, "value")?,
                            inertia: [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]],
                        })
                    }
                };
                links.push(ULink {
                    name: attr(&doc, node, "name")?.to_string(),
                    inertial,
                    line: line_of(&doc, node),
                });
            }
            "joint" => {
                let ty = attr(&doc, node, "type")?;
                let joint_type = match ty {
                    "revolute" => JointType::Revolute,
                    "continuous" => JointType::Continuous,
                    "prismatic" => JointType::Prismatic,
                    "fixed" => JointType::Fixed,
                    "floating" => JointType::Floating,
                    "planar" => JointType::Planar,
                    "spherical" => JointType::Spherical,
                    other => return Err(at(&doc, node, format!("unknown joint type `{other}`"))),
                };
                let end = |tag: &str| -> Result<String, ModelError> {
                    let e = child(node, tag)
                        .ok_or_else(|| at(&doc, node, format!("missing <{tag} link=…>")))?;
                    Ok(attr(&doc, e, "link")?.to_string())
                };
                let (xyz, rpy) = origin(&doc, node)?;
                let axis = match child(node, "axis") {
                    None => [1.0, 0.0, 0.0],
                    Some(a) => vec3(&doc, a, "xyz", [1.0, 0.0, 0.0])?,
                };
                joints.push(UJoint {
                    name: attr(&doc, node, "name")?.to_string(),
                    joint_type,
                    xyz,
                    rpy,
                    parent: end("parent")?,
                    child: end("child")?,
                    axis,
                    line: line_of(&doc, node),
                });
            }
            _ => {}
        }
    }
    Ok((
        robot.attribute("name").unwrap_or_default().to_string(),
        links,
        joints,
    ))
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
    let (robot_name, robot_links, robot_joints) = read(text)?;
    let mut links = HashMap::new();
    for l in &robot_links {
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
    for j in &robot_joints {
        if !joint_names.insert(j.name.as_str()) {
            return Err(ModelError::Duplicate {
                name: j.name.clone(),
                what: "joint".into(),
            });
        }
        match j.joint_type {
            JointType::Revolute
            | JointType::Continuous
            | JointType::Prismatic
            | JointType::Fixed => {}
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
    let roots: Vec<&str> = robot_links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|n| !is_child.contains(n))
        .collect();
    let root = match roots.as_slice() {
        [r] => *r,
        [] => {
            return Err(ModelError::Parse(format!(
                "URDF `{}`: no root link (every link is some joint's child)",
                robot_name
            )))
        }
        many => {
            return Err(ModelError::Parse(format!(
                "URDF `{}`: several root links ({}); the model must be one connected chain",
                robot_name,
                many.join(", ")
            )))
        }
    };

    // Depth-first from the root. Each link belongs to a moving body (`None`: the base) and sits
    // at `offset` in that body's frame; `acc[body]` accumulates the body's parts.
    let mut acc: HashMap<Option<usize>, Option<Inertial>> = HashMap::new();
    let mut joints: Vec<Joint> = Vec::new();
    let mut frames: Vec<Frame> = Vec::new();
    add_link(
        acc.entry(None).or_default(),
        &Placement::identity(),
        links[root],
        root,
        validation,
    )?;
    // Joints to walk, each with the moving body its parent link belongs to and that link's
    // offset in the body frame; a link's child joints are pushed in reverse so that the first in
    // the file is walked first, and the whole subtree of a joint before its next sibling
    // (depth-first preorder: parents get smaller indices than their children).
    let kids = |link: &str| children.get(link).map(Vec::as_slice).unwrap_or(&[]);
    let mut stack: Vec<(&UJoint, Option<usize>, Placement)> = kids(root)
        .iter()
        .rev()
        .map(|j| (*j, None, Placement::identity()))
        .collect();
    let mut visited = 1usize;
    while let Some((j, owner, offset)) = stack.pop() {
        visited += 1;
        if visited > robot_links.len() {
            return Err(ModelError::Parse(format!(
                "URDF `{}`: the joint graph has a cycle",
                robot_name
            )));
        }
        let origin = offset.then(&Placement::from_xyz_rpy(j.xyz, j.rpy));
        let child = links[j.child.as_str()];
        let (child_owner, child_offset) = match j.joint_type {
            JointType::Fixed => {
                add_link(
                    acc.entry(owner).or_default(),
                    &origin,
                    child,
                    &j.name,
                    validation,
                )?;
                frames.push(Frame {
                    name: child.name.clone(),
                    parent: owner,
                    placement: origin,
                });
                (owner, origin)
            }
            t => {
                let k = joints.len();
                joints.push(Joint {
                    name: j.name.clone(),
                    kind: if t == JointType::Prismatic {
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
                let part = acc.entry(Some(k)).or_default();
                add_link(part, &Placement::identity(), child, &j.name, validation)?;
                (Some(k), Placement::identity())
            }
        };
        stack.extend(
            kids(&child.name)
                .iter()
                .rev()
                .map(|c| (*c, child_owner, child_offset)),
        );
    }
    for (k, j) in joints.iter_mut().enumerate() {
        j.inertial = inertial_of(acc.get(&Some(k)).unwrap_or(&None));
    }
    let base = inertial_of(acc.get(&None).unwrap_or(&None));
    let base_inertial = (base.mass != 0.0).then_some(base);
    if visited < robot_links.len() {
        return Err(ModelError::Parse(format!(
            "URDF `{}`: {} link(s) are not reachable from the root `{root}`",
            robot_name,
            robot_links.len() - visited
        )));
    }
    Model::new_with(robot_name.clone(), root, base_inertial, joints, validation)?
        .with_frames(frames)
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
    // negative moments. The body it is merged into is then checked whole (definite, triangle
    // inequality) by `Model::new`.
    if let Some(why) = (!validation.allow_nonphysical_inertia)
        .then(|| not_semidefinite(&inertia))
        .flatten()
    {
        return Err(ModelError::invalid(
            owner,
            &field("inertia"),
            format!("{why}: a link's inertia must be positive semidefinite"),
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

/// `Some(reason)` when the symmetric `i` has a negative principal minor beyond rounding
/// (relative 1e-12 of its largest entry, to the minor's degree).
fn not_semidefinite(i: &M3) -> Option<String> {
    let scale = i.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
    let tol = 1e-12 * scale;
    for (k, row) in i.iter().enumerate() {
        if row[k] < -tol {
            return Some(format!("diagonal entry {k} is {:e}", row[k]));
        }
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let minor = i[a][a] * i[b][b] - i[a][b] * i[b][a];
        if minor < -tol * scale {
            return Some(format!("the {a}{b} principal minor is {minor:e}"));
        }
    }
    let det = i[0][0] * (i[1][1] * i[2][2] - i[1][2] * i[2][1])
        - i[0][1] * (i[1][0] * i[2][2] - i[1][2] * i[2][0])
        + i[0][2] * (i[1][0] * i[2][1] - i[1][1] * i[2][0]);
    (det < -tol * scale * scale).then(|| format!("the determinant is {det:e}"))
}
