//! kanegen's TOML model format (see `docs/models.md`), with optional DH geometry.

use crate::bounds::{LENGTH, POSITION};
use crate::inertial::{bounded, finite, rotate_inertia, validate_inertial_with};
use crate::placement::{rpy_to_matrix, Placement, I3, M3, V3};
use crate::{BaseKind, Frame, Inertial, Joint, JointKind, Model, ModelError, Validation};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelSpec {
    name: String,
    #[serde(default)]
    base: Option<BaseSpec>,
    #[serde(default)]
    dh: Option<DhSpec>,
    #[serde(default, rename = "joint")]
    joints: Vec<JointSpec>,
    #[serde(default, rename = "frame")]
    frames: Vec<FrameSpec>,
}

/// `[[frame]]`: a named frame fixed to a body.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameSpec {
    name: String,
    parent: String,
    xyz: Option<V3>,
    rpy: Option<V3>,
    rotation: Option<M3>,
}

/// `base = "name"` or a `[base]` table with the base's name and mass properties.
struct BaseSpec(BaseTable);

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct BaseTable {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: Option<String>,
    mass: Option<f64>,
    com: Option<V3>,
    inertia: Option<InertiaSpec>,
}

impl<'de> Deserialize<'de> for BaseSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = BaseSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a base name or a [base] table (name, mass, com, inertia)")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<BaseSpec, E> {
                Ok(BaseSpec(BaseTable {
                    name: Some(s.to_string()),
                    ..Default::default()
                }))
            }
            fn visit_map<A: MapAccess<'de>>(self, m: A) -> Result<BaseSpec, A::Error> {
                BaseTable::deserialize(de::value::MapAccessDeserializer::new(m)).map(BaseSpec)
            }
        }
        d.deserialize_any(V)
    }
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
enum DhConvention {
    Standard,
    Modified,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DhSpec {
    convention: DhConvention,
    base_xyz: Option<V3>,
    base_rpy: Option<V3>,
    base_rotation: Option<M3>,
}

#[derive(Deserialize, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum KindSpec {
    #[serde(alias = "continuous")]
    Revolute,
    Prismatic,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointSpec {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: KindSpec,
    xyz: Option<V3>,
    rpy: Option<V3>,
    rotation: Option<M3>,
    axis: Option<V3>,
    a: Option<f64>,
    alpha: Option<f64>,
    d: Option<f64>,
    theta: Option<f64>,
    parent: Option<String>,
    body: BodySpec,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BodySpec {
    name: Option<String>,
    mass: f64,
    com: Option<V3>,
    inertia: InertiaSpec,
}

/// An inertia tensor as written in kanegen's TOML files (models and scenes):
/// `{ ixx, iyy, izz, ixy, ixz, iyz }` (off-diagonals default 0, URDF sign convention) or a
/// row-major 3×3 matrix. Deserializes with serde; `.0` is the matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InertiaSpec(pub M3);

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InertiaComponents {
    ixx: f64,
    iyy: f64,
    izz: f64,
    #[serde(default)]
    ixy: f64,
    #[serde(default)]
    ixz: f64,
    #[serde(default)]
    iyz: f64,
}

impl<'de> Deserialize<'de> for InertiaSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = InertiaSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an inertia table { ixx, iyy, izz, ixy, ixz, iyz } or a 3x3 matrix")
            }
            fn visit_map<A: MapAccess<'de>>(self, m: A) -> Result<InertiaSpec, A::Error> {
                let c = InertiaComponents::deserialize(de::value::MapAccessDeserializer::new(m))?;
                Ok(InertiaSpec([
                    [c.ixx, c.ixy, c.ixz],
                    [c.ixy, c.iyy, c.iyz],
                    [c.ixz, c.iyz, c.izz],
                ]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, s: A) -> Result<InertiaSpec, A::Error> {
                M3::deserialize(de::value::SeqAccessDeserializer::new(s)).map(InertiaSpec)
            }
        }
        d.deserialize_any(V)
    }
}

/// Parses kanegen's TOML model format (documented in `docs/models.md`) into a [`Model`].
///
/// Unknown keys and syntax errors are reported by the `toml` crate (naming the key and line) as
/// [`ModelError::Parse`]; every value error names the joint (by name, or `joint #k`, 1-based,
/// when unnamed) and the TOML field, e.g. ``joint `elbow`: field `body.mass`: mass must be > 0``.
///
/// With a `[dh]` table each joint gives `a`, `alpha`, `d`, `theta` instead of
/// `xyz`/`rpy`/`rotation`/`axis`:
/// * `convention = "modified"` (Craig): `T_i = RotX(α_{i−1}) TransX(a_{i−1}) RotZ(θ_i + q_i)
///   TransZ(d_i)` (prismatic: `TransZ(d_i + q_i)`); joint `i`'s row holds `a_{i−1}`, `α_{i−1}`,
///   `d_i`, `θ_i`; the body frame is DH frame `i`.
/// * `convention = "standard"`: `T_i = RotZ(θ_i + q_i) TransZ(d_i) TransX(a_i) RotX(α_i)`; the
///   body inertials are given in DH frame `i` (the distal frame) and are re-expressed here in the
///   joint frame `F_{i−1} RotZ(θ_i + q_i)` (prismatic: `F_{i−1} RotZ(θ_i) TransZ(q_i)`); the
///   constant `TransZ(d_i) TransX(a_i) RotX(α_i)` goes into the next joint's origin.
///
/// `base_xyz` and `base_rpy`/`base_rotation` in `[dh]` place DH frame 0 in the base body frame.
pub fn parse_toml(text: &str) -> Result<Model, ModelError> {
    parse_toml_named(text, None, Validation::default())
}

pub(crate) fn parse_toml_named(
    text: &str,
    file: Option<&str>,
    validation: Validation,
) -> Result<Model, ModelError> {
    let spec: ModelSpec = toml::from_str(text).map_err(|e| {
        ModelError::Parse(match file {
            Some(f) => format!("{f}: {e}"),
            None => e.to_string(),
        })
    })?;
    build(spec, validation)
}

fn rotation_of(
    label: &str,
    prefix: &str,
    rpy: Option<V3>,
    rotation: Option<M3>,
) -> Result<M3, ModelError> {
    match (rpy, rotation) {
        (Some(_), Some(_)) => Err(ModelError::invalid(
            label,
            &format!("{prefix}rotation"),
            format!("give either `{prefix}rpy` or `{prefix}rotation`, not both"),
        )),
        (Some(rpy), None) => {
            finite(label, &format!("{prefix}rpy"), &rpy)?;
            Ok(rpy_to_matrix(rpy))
        }
        (None, Some(r)) => {
            finite(label, &format!("{prefix}rotation"), r.as_flattened())?;
            Ok(r)
        }
        (None, None) => Ok(I3),
    }
}

fn inertial_of(
    label: &str,
    field: &str,
    mass: f64,
    com: Option<V3>,
    inertia: &InertiaSpec,
    validation: Validation,
) -> Result<Inertial, ModelError> {
    let b = Inertial {
        mass,
        com: com.unwrap_or([0.0; 3]),
        inertia: inertia.0,
    };
    validate_inertial_with(label, field, &b, validation)?;
    Ok(b)
}

fn build(spec: ModelSpec, validation: Validation) -> Result<Model, ModelError> {
    let base = spec.base.map(|b| b.0).unwrap_or_default();
    let base_name = base.name.clone().unwrap_or_else(|| "base".to_string());
    let base_inertial = base_inertial_of(&base, &base_name, validation)?;
    let dh_frame0 = spec.dh.as_ref().map(dh_frame0_of).transpose()?;
    let base_kind = base_kind_of(&base, &base_name)?;
    let mut labels = Vec::new();
    let mut joints: Vec<Joint> = Vec::new();
    // Standard DH: the constant distal part of the previous joint, to go into the next origin.
    let mut carry = dh_frame0.unwrap_or_else(Placement::identity);
    for (k, js) in spec.joints.iter().enumerate() {
        let label = js
            .name
            .clone()
            .unwrap_or_else(|| format!("joint #{}", k + 1));
        let name = js
            .name
            .clone()
            .unwrap_or_else(|| format!("joint_{}", k + 1));
        labels.push((name.clone(), label.clone()));
        let context = JointContext {
            k,
            label: &label,
            base_name: &base_name,
            dh: spec.dh.as_ref(),
            validation,
        };
        let joint = joint_of(&context, name, js, &joints, &mut carry)?;
        joints.push(joint);
    }
    let frames = frames_of(&spec.frames, &base_name, &joints)?;
    let is_dh = spec.dh.is_some();
    let model = Model::new_with(spec.name, base_name, base_inertial, joints, validation)
        .map_err(|e| in_file_terms(e, &labels, is_dh))?;
    model.with_frames(frames)?.with_base_kind(base_kind)
}

/// The base's mass properties: all of `mass`, `inertia` (and optionally `com`), or none.
fn base_inertial_of(
    base: &BaseTable,
    base_name: &str,
    validation: Validation,
) -> Result<Option<Inertial>, ModelError> {
    match (base.mass, &base.inertia) {
        (None, None) if base.com.is_none() => Ok(None),
        (Some(m), Some(i)) => inertial_of(base_name, "base", m, base.com, i, validation).map(Some),
        (None, _) => Err(ModelError::invalid(
            base_name,
            "base.mass",
            "missing (the base inertial needs mass and inertia)",
        )),
        (Some(_), None) => Err(ModelError::invalid(
            base_name,
            "base.inertia",
            "missing (the base inertial needs mass and inertia)",
        )),
    }
}

/// `[dh]`'s placement of DH frame 0 in the base body frame.
fn dh_frame0_of(dh: &DhSpec) -> Result<Placement, ModelError> {
    let xyz = dh.base_xyz.unwrap_or([0.0; 3]);
    bounded("dh", "dh.base_xyz", &xyz, LENGTH)?;
    Ok(Placement {
        rotation: rotation_of("dh", "dh.base_", dh.base_rpy, dh.base_rotation)?,
        translation: xyz,
    })
}

/// `base.type`: fixed (the default) or free-floating.
fn base_kind_of(base: &BaseTable, base_name: &str) -> Result<BaseKind, ModelError> {
    match base.kind.as_deref() {
        None => Ok(BaseKind::Fixed),
        Some(k) => BaseKind::from_name(k).ok_or_else(|| {
            ModelError::invalid(
                base_name,
                "base.type",
                format!("unknown base type `{k}` (expected \"fixed\" or \"free-floating\")"),
            )
        }),
    }
}

/// A parent named in the file: the base (`None`), an earlier joint, or an earlier joint's body.
fn parent_of(
    base_name: &str,
    label: &str,
    field: &str,
    name: &str,
    joints: &[Joint],
) -> Result<Option<usize>, ModelError> {
    if name == base_name || name == "base" {
        return Ok(None);
    }
    joints
        .iter()
        .position(|j| j.name == name || j.body == name)
        .map(Some)
        .ok_or_else(|| {
            ModelError::invalid(
                label,
                field,
                format!(
                    "no joint or body `{name}` before it (a parent must be the base, `{base_name}`, or an earlier joint or its body)"
                ),
            )
        })
}

/// What reading joint `k` needs besides its table.
struct JointContext<'a> {
    /// Its index in the file.
    k: usize,
    /// Its name in error messages (`joint #k` when unnamed).
    label: &'a str,
    base_name: &'a str,
    dh: Option<&'a DhSpec>,
    validation: Validation,
}

/// Joint `js` (called `name`) and its body; `joints` are the ones before it, `carry` the
/// standard-DH placement handed from the previous joint to this one's origin.
fn joint_of(
    cx: &JointContext,
    name: String,
    js: &JointSpec,
    joints: &[Joint],
    carry: &mut Placement,
) -> Result<Joint, ModelError> {
    let label = cx.label;
    let kind = match js.kind {
        KindSpec::Revolute => JointKind::Revolute,
        KindSpec::Prismatic => JointKind::Prismatic,
    };
    let mut inertial = inertial_of(
        label,
        "body",
        js.body.mass,
        js.body.com,
        &js.body.inertia,
        cx.validation,
    )?;
    let parent = match (&js.parent, cx.dh) {
        (None, _) => cx.k.checked_sub(1),
        (Some(_), Some(_)) => {
            return Err(ModelError::invalid(
                label,
                "parent",
                "a DH model ([dh]) is a serial chain: `parent` is not allowed",
            ))
        }
        (Some(p), None) => parent_of(cx.base_name, label, "parent", p, joints)?,
    };
    let (origin, axis) = match cx.dh {
        None => explicit_placement(label, js)?,
        Some(dh) => (
            dh_placement(cx, js, dh, carry, &mut inertial)?,
            [0.0, 0.0, 1.0],
        ),
    };
    Ok(Joint {
        body: js
            .body
            .name
            .clone()
            .unwrap_or_else(|| format!("{name}_body")),
        name,
        kind,
        parent,
        origin,
        axis,
        inertial,
    })
}

/// The origin (`xyz`, `rpy` or `rotation`) and the axis of a joint of a model without `[dh]`.
fn explicit_placement(label: &str, js: &JointSpec) -> Result<(Placement, V3), ModelError> {
    for (field, present) in [
        ("a", js.a.is_some()),
        ("alpha", js.alpha.is_some()),
        ("d", js.d.is_some()),
        ("theta", js.theta.is_some()),
    ] {
        if present {
            return Err(ModelError::invalid(
                label,
                field,
                "DH parameters need a top-level [dh] table (convention = \"standard\" or \"modified\")",
            ));
        }
    }
    let xyz = js.xyz.unwrap_or([0.0; 3]);
    bounded(label, "xyz", &xyz, LENGTH)?;
    let r = rotation_of(label, "", js.rpy, js.rotation)?;
    let axis = js.axis.ok_or_else(|| {
        ModelError::invalid(label, "axis", "missing (required unless [dh] is given)")
    })?;
    finite(label, "axis", &axis)?;
    Ok((
        Placement {
            rotation: r,
            translation: xyz,
        },
        axis,
    ))
}

/// The origin of a DH joint (its axis is z) from `a`, `alpha`, `d`, `theta`. Modified DH: the
/// whole `RotX(α) TransX(a) RotZ(θ) TransZ(d)` (after DH frame 0 for the first joint). Standard
/// DH: `carry RotZ(θ)`, and the constant `TransZ(d) TransX(a) RotX(α)` becomes the next `carry`,
/// the body's mass properties moved into the joint frame.
fn dh_placement(
    cx: &JointContext,
    js: &JointSpec,
    dh: &DhSpec,
    carry: &mut Placement,
    inertial: &mut Inertial,
) -> Result<Placement, ModelError> {
    let label = cx.label;
    for (field, present) in [
        ("xyz", js.xyz.is_some()),
        ("rpy", js.rpy.is_some()),
        ("rotation", js.rotation.is_some()),
        ("axis", js.axis.is_some()),
    ] {
        if present {
            return Err(ModelError::invalid(
                label,
                field,
                "not allowed in a DH model ([dh] is given): use a, alpha, d, theta",
            ));
        }
    }
    let [a, alpha, d, theta] = [js.a, js.alpha, js.d, js.theta].map(|x| x.unwrap_or(0.0));
    for (field, x, b) in [
        ("a", a, LENGTH),
        ("alpha", alpha, POSITION),
        ("d", d, LENGTH),
        ("theta", theta, POSITION),
    ] {
        bounded(label, field, &[x], b)?;
    }
    Ok(match dh.convention {
        DhConvention::Modified => {
            let o = Placement::rot_x(alpha)
                .then(&Placement::trans([a, 0.0, 0.0]))
                .then(&Placement::rot_z(theta))
                .then(&Placement::trans([0.0, 0.0, d]));
            let o = if cx.k == 0 { carry.then(&o) } else { o };
            *carry = Placement::identity();
            o
        }
        DhConvention::Standard => {
            let o = carry.then(&Placement::rot_z(theta));
            // Frame i in the body (joint) frame: TransZ(d) TransX(a) RotX(α).
            let c = Placement::trans([0.0, 0.0, d])
                .then(&Placement::trans([a, 0.0, 0.0]))
                .then(&Placement::rot_x(alpha));
            inertial.com = c.point(&inertial.com);
            inertial.inertia = rotate_inertia(&c.rotation, &inertial.inertia);
            *carry = c;
            o
        }
    })
}

/// The `[[frame]]` tables, each on the base or an earlier joint's body.
fn frames_of(
    specs: &[FrameSpec],
    base_name: &str,
    joints: &[Joint],
) -> Result<Vec<Frame>, ModelError> {
    specs
        .iter()
        .map(|f| {
            let xyz = f.xyz.unwrap_or([0.0; 3]);
            bounded(&f.name, "frame.xyz", &xyz, LENGTH)?;
            Ok(Frame {
                name: f.name.clone(),
                parent: parent_of(base_name, &f.name, "frame.parent", &f.parent, joints)?,
                placement: Placement {
                    translation: xyz,
                    rotation: rotation_of(&f.name, "frame.", f.rpy, f.rotation)?,
                },
            })
        })
        .collect()
}

/// A model error in the file's terms: the joint by its label (`joint #k` when unnamed) and the
/// field by the key the file spells (`xyz`, `rotation`, `body.mass`, `base.mass`…).
fn in_file_terms(e: ModelError, labels: &[(String, String)], is_dh: bool) -> ModelError {
    match e {
        ModelError::Invalid {
            joint,
            field,
            reason,
        } => {
            let joint = labels
                .iter()
                .find(|(n, _)| *n == joint)
                .map_or(joint, |(_, l)| l.clone());
            let field = match field.as_str() {
                "origin.rotation" if is_dh => "dh.base_rotation".to_string(),
                "origin.rotation" => "rotation".to_string(),
                "origin.translation" => "xyz".to_string(),
                f => f
                    .strip_prefix("inertial.")
                    .map(|r| format!("body.{r}"))
                    .or_else(|| {
                        f.strip_prefix("base.inertial.")
                            .map(|r| format!("base.{r}"))
                    })
                    .unwrap_or_else(|| f.to_string()),
            };
            ModelError::Invalid {
                joint,
                field,
                reason,
            }
        }
        other => other,
    }
}
