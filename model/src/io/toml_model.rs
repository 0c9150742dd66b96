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
    let base_inertial = match (base.mass, &base.inertia) {
        (None, None) if base.com.is_none() => None,
        (Some(m), Some(i)) => Some(inertial_of(&base_name, "base", m, base.com, i, validation)?),
        (None, _) => {
            return Err(ModelError::invalid(
                &base_name,
                "base.mass",
                "missing (the base inertial needs mass and inertia)",
            ))
        }
        (Some(_), None) => {
            return Err(ModelError::invalid(
                &base_name,
                "base.inertia",
                "missing (the base inertial needs mass and inertia)",
            ))
        }
    };

    let dh_base = match &spec.dh {
        Some(dh) => {
            let xyz = dh.base_xyz.unwrap_or([0.0; 3]);
            bounded("dh", "dh.base_xyz", &xyz, LENGTH)?;
            Some(Placement {
                rotation: rotation_of("dh", "dh.base_", dh.base_rpy, dh.base_rotation)?,
                translation: xyz,
            })
        }
        None => None,
    };

    let base_kind = match base.kind.as_deref() {
        None => BaseKind::Fixed,
        Some(k) => BaseKind::from_name(k).ok_or_else(|| {
            ModelError::invalid(
                &base_name,
                "base.type",
                format!("unknown base type `{k}` (expected \"fixed\" or \"free-floating\")"),
            )
        })?,
    };
    // A parent named in the file: the base, an earlier joint, or an earlier joint's body.
    let parent_of = |label: &str, field: &str, name: &str, joints: &[Joint]| {
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
    };
    let mut labels = Vec::new();
    let mut joints: Vec<Joint> = Vec::new();
    // Standard DH: the constant distal part of the previous joint, to go into the next origin.
    let mut carry = dh_base.unwrap_or_else(Placement::identity);
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
        let kind = match js.kind {
            KindSpec::Revolute => JointKind::Revolute,
            KindSpec::Prismatic => JointKind::Prismatic,
        };
        let mut inertial = inertial_of(
            &label,
            "body",
            js.body.mass,
            js.body.com,
            &js.body.inertia,
            validation,
        )?;
        let parent = match (&js.parent, &spec.dh) {
            (None, _) => k.checked_sub(1),
            (Some(_), Some(_)) => {
                return Err(ModelError::invalid(
                    &label,
                    "parent",
                    "a DH model ([dh]) is a serial chain: `parent` is not allowed",
                ))
            }
            (Some(p), None) => parent_of(&label, "parent", p, &joints)?,
        };
        let (origin, axis) = match &spec.dh {
            None => {
                for (field, present) in [
                    ("a", js.a.is_some()),
                    ("alpha", js.alpha.is_some()),
                    ("d", js.d.is_some()),
                    ("theta", js.theta.is_some()),
                ] {
                    if present {
                        return Err(ModelError::invalid(
                            &label,
                            field,
                            "DH parameters need a top-level [dh] table (convention = \"standard\" or \"modified\")",
                        ));
                    }
                }
                let xyz = js.xyz.unwrap_or([0.0; 3]);
                bounded(&label, "xyz", &xyz, LENGTH)?;
                let r = rotation_of(&label, "", js.rpy, js.rotation)?;
                let axis = js.axis.ok_or_else(|| {
                    ModelError::invalid(&label, "axis", "missing (required unless [dh] is given)")
                })?;
                finite(&label, "axis", &axis)?;
                (
                    Placement {
                        rotation: r,
                        translation: xyz,
                    },
                    axis,
                )
            }
            Some(dh) => {
                for (field, present) in [
                    ("xyz", js.xyz.is_some()),
                    ("rpy", js.rpy.is_some()),
                    ("rotation", js.rotation.is_some()),
                    ("axis", js.axis.is_some()),
                ] {
                    if present {
                        return Err(ModelError::invalid(
                            &label,
                            field,
                            "not allowed in a DH model ([dh] is given): use a, alpha, d, theta",
                        ));
                    }
                }
                let [a, alpha, d, theta] =
                    [js.a, js.alpha, js.d, js.theta].map(|x| x.unwrap_or(0.0));
                for (field, x, b) in [
                    ("a", a, LENGTH),
                    ("alpha", alpha, POSITION),
                    ("d", d, LENGTH),
                    ("theta", theta, POSITION),
                ] {
                    bounded(&label, field, &[x], b)?;
                }
                let origin = match dh.convention {
                    DhConvention::Modified => {
                        let o = Placement::rot_x(alpha)
                            .then(&Placement::trans([a, 0.0, 0.0]))
                            .then(&Placement::rot_z(theta))
                            .then(&Placement::trans([0.0, 0.0, d]));
                        let o = if k == 0 { carry.then(&o) } else { o };
                        carry = Placement::identity();
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
                        carry = c;
                        o
                    }
                };
                (origin, [0.0, 0.0, 1.0])
            }
        };
        joints.push(Joint {
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
        });
    }
    let mut frames = Vec::new();
    for f in &spec.frames {
        let xyz = f.xyz.unwrap_or([0.0; 3]);
        bounded(&f.name, "frame.xyz", &xyz, LENGTH)?;
        frames.push(Frame {
            name: f.name.clone(),
            parent: parent_of(&f.name, "frame.parent", &f.parent, &joints)?,
            placement: Placement {
                translation: xyz,
                rotation: rotation_of(&f.name, "frame.", f.rpy, f.rotation)?,
            },
        });
    }
    let is_dh = spec.dh.is_some();
    let model =
        Model::new_with(spec.name, base_name, base_inertial, joints, validation).map_err(|e| {
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
        })?;
    model.with_frames(frames)?.with_base_kind(base_kind)
}
