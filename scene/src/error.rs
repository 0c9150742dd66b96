//! The error of reading a scene: what is wrong (naming the key, and the line where the table
//! starts), and which file it is in.

use std::fmt;
use std::path::PathBuf;

/// Why a scene was rejected.
///
/// `{}` prints the outermost message (`scene `scenes/arm.toml``), `{:#}` the whole chain
/// separated by `: ` (`scene `scenes/arm.toml`: simulation.step: must be > 0`), as
/// [`std::error::Error::source`] links it.
#[derive(Debug)]
pub enum SceneError {
    /// The scene file could not be read.
    Read {
        /// The scene file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A key is missing, unknown or out of range; the message names it
    /// (`drives.kp: required by this drive type`).
    Invalid(String),
    /// An error in the scene file at `path`.
    InFile {
        /// The scene file.
        path: PathBuf,
        /// What is wrong in it.
        source: Box<SceneError>,
    },
}

impl SceneError {
    /// The message naming the key.
    pub(crate) fn invalid(message: impl Into<String>) -> SceneError {
        SceneError::Invalid(message.into())
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::Read { path, source } => {
                write!(f, "cannot read scene `{}`", path.display())?;
                if f.alternate() {
                    write!(f, ": {source}")?;
                }
                Ok(())
            }
            SceneError::Invalid(message) => f.write_str(message),
            SceneError::InFile { path, source } => {
                write!(f, "scene `{}`", path.display())?;
                if f.alternate() {
                    write!(f, ": {source:#}")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SceneError::Read { source, .. } => Some(source),
            SceneError::Invalid(_) => None,
            SceneError::InFile { source, .. } => Some(source.as_ref()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SceneError;
    use std::error::Error;

    #[test]
    fn alternate_prints_the_chain() {
        let e = SceneError::InFile {
            path: "scenes/arm.toml".into(),
            source: Box::new(SceneError::invalid("simulation.step: must be > 0")),
        };
        assert_eq!(e.to_string(), "scene `scenes/arm.toml`");
        assert_eq!(
            format!("{e:#}"),
            "scene `scenes/arm.toml`: simulation.step: must be > 0"
        );
        assert_eq!(
            e.source().map(ToString::to_string).as_deref(),
            Some("simulation.step: must be > 0")
        );
        let read = SceneError::Read {
            path: "nowhere.toml".into(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "not found"),
        };
        assert_eq!(
            format!("{read:#}"),
            "cannot read scene `nowhere.toml`: not found"
        );
    }
}

/// The joint coordinates of a scene's model: what its per-joint lists (`initial.q`,
/// `drives.kp`, `effects.damping`, …) hold one value for. With mimic joints they are the
/// independent joints only (a mimic joint moves with the joint it follows and has no value of
/// its own).
#[derive(Clone, Copy)]
pub(crate) struct Coordinates<'a>(pub &'a kanegen_model::Model);

impl Coordinates<'_> {
    /// How many values a per-joint list holds.
    pub(crate) fn len(self) -> usize {
        self.0.coordinate_count()
    }

    /// The error of a per-joint list `key` of `got` values: the expected count and, with mimic
    /// joints, the coordinates by name and each mimic joint with the joint it follows.
    pub(crate) fn wrong_count(self, key: &str, got: usize) -> SceneError {
        let (model, n) = (self.0, self.len());
        if !model.has_mimics() {
            return SceneError::invalid(format!(
                "{key}: expected {n} values (the model's degrees of freedom), got {got}"
            ));
        }
        let joints = model.joints();
        let names: Vec<&str> = model
            .coordinates()
            .into_iter()
            .map(|j| joints[j].name.as_str())
            .collect();
        let mimics: Vec<String> = model
            .mimics()
            .iter()
            .enumerate()
            .filter_map(|(j, m)| {
                m.map(|m| {
                    format!(
                        "`{}` follows `{}` (q = {} · q_{} + {})",
                        joints[j].name,
                        joints[m.primary].name,
                        m.multiplier,
                        joints[m.primary].name,
                        m.offset
                    )
                })
            })
            .collect();
        SceneError::invalid(format!(
            "{key}: expected {n} values, one per coordinate of the model ({}), got {got}; a \
             mimic joint has no value of its own: {}",
            names.join(", "),
            mimics.join(", ")
        ))
    }
}
