//! Model readers: URDF ([`parse_urdf`]) and kanegen's TOML format ([`parse_toml`], documented in
//! `docs/models.md`), both producing a validated [`Model`].
//!
//! ```
//! let chain = kanegen_model::io::parse_toml(r#"
//!     name = "pendulum"
//!     [[joint]]
//!     name = "hinge"
//!     type = "revolute"
//!     axis = [0.0, 0.0, 1.0]
//!     [joint.body]
//!     mass = 1.0
//!     com = [0.5, 0.0, 0.0]
//!     inertia = { ixx = 0.01, iyy = 0.02, izz = 0.02 }
//! "#).unwrap();
//! assert_eq!(chain.dof(), 1);
//! assert_eq!(chain.joints()[0].body, "hinge_body");
//! ```

mod toml_model;
mod urdf;
mod write;

use crate::{Model, ModelError, Validation};
use std::path::Path;

pub use toml_model::{parse_toml, InertiaSpec};
pub use urdf::{parse_urdf, parse_urdf_with};
pub use write::to_toml;

/// Reads a model file, choosing the reader by extension: `.urdf` ([`parse_urdf`]) or `.toml`
/// ([`parse_toml`]). Parse errors are prefixed with the file name.
pub fn load_model(path: &Path) -> Result<Model, ModelError> {
    load_model_with(path, Validation::default())
}

/// [`load_model`] under the given [`Validation`].
pub fn load_model_with(path: &Path, validation: Validation) -> Result<Model, ModelError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let display = path.display().to_string();
    let read = || {
        std::fs::read_to_string(path).map_err(|e| ModelError::Io {
            path: display.clone(),
            reason: e.to_string(),
        })
    };
    match ext.as_deref() {
        Some("urdf") => {
            urdf::parse_urdf_with(&read()?, validation).map_err(|e| prefix(&display, e))
        }
        Some("toml") => toml_model::parse_toml_named(&read()?, Some(&display), validation),
        Some(other) => Err(ModelError::Parse(format!(
            "{display}: unsupported model file extension `.{other}` (expected `.urdf` or `.toml`)"
        ))),
        None => Err(ModelError::Parse(format!(
            "{display}: model file has no extension (expected `.urdf` or `.toml`)"
        ))),
    }
}

/// Prefixes parse errors with the file name.
fn prefix(file: &str, e: ModelError) -> ModelError {
    match e {
        ModelError::Parse(m) => ModelError::Parse(format!("{file}: {m}")),
        other => other,
    }
}
