//! URDF reader: kinematic trees; fixed joints merged into their moving parent body, fixed links
//! kept as named frames.
//!
//! Parsed with `urdf-rs`, which fills a missing `<inertial>` with zeros: such a link is treated
//! as massless, which is fine when it is merged through a fixed joint into a body with mass; a
//! moving body that ends up massless is rejected by [`Model::new`] (mass must be > 0).

use crate::placement::{Placement, M3};
use crate::{Frame, Inertial, Joint, JointKind, Model, ModelError, Validation};
use std::collections::{HashMap, HashSet};
use urdf_rs::JointType;

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
    let robot =
        urdf_rs::read_from_string(text).map_err(|e| ModelError::Parse(format!("URDF: {e}")))?;

    let mut links = HashMap::new();
    for l in &robot.links {
        if links.insert(l.name.as_str(), l).is_some() {
            return Err(ModelError::Duplicate {
                name: l.name.clone(),
                what: "link".into(),
            });
        }
    }
    let mut joint_names = HashSet::new();
    let mut children: HashMap<&str, Vec<&urdf_rs::Joint>> = HashMap::new();
    let mut is_child = HashSet::new();
    for j in &robot.joints {
        if !joint_names.insert(j.name.as_str()) {
            return Err(ModelError::Duplicate {
                name: j.name.clone(),
                what: "joint".into(),
            });
        }
        match j.joint_type {
            JointType::Revolute | JointType::Continuous | JointType::Prismatic | JointType::Fixed => {}
            ref other => {
                return Err(ModelError::invalid(
                    &j.name,
                    "type",
                    format!(
                        "{other:?} joints are not supported (only revolute, continuous, prismatic and fixed)"
                    )
                    .to_lowercase(),
                ))
            }
        }
        for (end, link) in [("parent", &j.parent.link), ("child", &j.child.link)] {
            if !links.contains_key(link.as_str()) {
                return Err(ModelError::invalid(
                    &j.name,
                    end,
                    format!("unknown link `{link}`"),
                ));
            }
        }
        if !is_child.insert(j.child.link.as_str()) {
            return Err(ModelError::invalid(
                &j.name,
                "child",
                format!(
                    "link `{}` is the child of more than one joint",
                    j.child.link
                ),
            ));
        }
        children.entry(j.parent.link.as_str()).or_default().push(j);
    }
    let roots: Vec<&str> = robot
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
                robot.name
            )))
        }
        many => {
            return Err(ModelError::Parse(format!(
                "URDF `{}`: several root links ({}); the model must be one connected chain",
                robot.name,
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
    )?;
    // Joints to walk, each with the moving body its parent link belongs to and that link's
    // offset in the body frame; a link's child joints are pushed in reverse so that the first in
    // the file is walked first, and the whole subtree of a joint before its next sibling
    // (depth-first preorder: parents get smaller indices than their children).
    let kids = |link: &str| children.get(link).map(Vec::as_slice).unwrap_or(&[]);
    let mut stack: Vec<(&urdf_rs::Joint, Option<usize>, Placement)> = kids(root)
        .iter()
        .rev()
        .map(|j| (*j, None, Placement::identity()))
        .collect();
    let mut visited = 1usize;
    while let Some((j, owner, offset)) = stack.pop() {
        visited += 1;
        if visited > robot.links.len() {
            return Err(ModelError::Parse(format!(
                "URDF `{}`: the joint graph has a cycle",
                robot.name
            )));
        }
        let origin = offset.then(&Placement::from_xyz_rpy(*j.origin.xyz, *j.origin.rpy));
        let child = links[j.child.link.as_str()];
        let (child_owner, child_offset) = match j.joint_type {
            JointType::Fixed => {
                add_link(acc.entry(owner).or_default(), &origin, child, &j.name)?;
                frames.push(Frame {
                    name: child.name.clone(),
                    parent: owner,
                    placement: origin,
                });
                (owner, origin)
            }
            ref t => {
                let k = joints.len();
                joints.push(Joint {
                    name: j.name.clone(),
                    kind: if *t == JointType::Prismatic {
                        JointKind::Prismatic
                    } else {
                        JointKind::Revolute
                    },
                    parent: owner,
                    origin,
                    axis: *j.axis.xyz,
                    body: child.name.clone(),
                    inertial: inertial_of(&None),
                });
                let part = acc.entry(Some(k)).or_default();
                add_link(part, &Placement::identity(), child, &j.name)?;
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
    if visited < robot.links.len() {
        return Err(ModelError::Parse(format!(
            "URDF `{}`: {} link(s) are not reachable from the root `{root}`",
            robot.name,
            robot.links.len() - visited
        )));
    }
    Model::new_with(robot.name.clone(), root, base_inertial, joints, validation)?
        .with_frames(frames)
}

fn inertial_of(acc: &Option<Inertial>) -> Inertial {
    acc.clone().unwrap_or(Inertial {
        mass: 0.0,
        com: [0.0; 3],
        inertia: [[0.0; 3]; 3],
    })
}

/// Adds a link's `<inertial>` (placed at `offset` in the body frame) to the body.
/// Errors name `owner` (the joint whose child the link is, or the root link) and the link.
fn add_link(
    acc: &mut Option<Inertial>,
    offset: &Placement,
    link: &urdf_rs::Link,
    owner: &str,
) -> Result<(), ModelError> {
    let inl = &link.inertial;
    let m = inl.mass.value;
    if !m.is_finite() || m < 0.0 {
        return Err(ModelError::invalid(
            owner,
            &format!("inertial.mass (link `{}`)", link.name),
            format!("link mass must be finite and ≥ 0, got {m}"),
        ));
    }
    let i = &inl.inertia;
    let inertia: M3 = [
        [i.ixx, i.ixy, i.ixz],
        [i.ixy, i.iyy, i.iyz],
        [i.ixz, i.iyz, i.izz],
    ];
    if m == 0.0 {
        if inertia.iter().flatten().any(|x| *x != 0.0) {
            return Err(ModelError::invalid(
                owner,
                &format!("inertial.inertia (link `{}`)", link.name),
                "a massless link must have zero inertia",
            ));
        }
        return Ok(());
    }
    let frame = offset.then(&Placement::from_xyz_rpy(*inl.origin.xyz, *inl.origin.rpy));
    let part = Inertial {
        mass: m,
        com: [0.0; 3],
        inertia,
    }
    .moved(&frame);
    *acc = Inertial::merge_opt(acc.take(), Some(part));
    Ok(())
}
