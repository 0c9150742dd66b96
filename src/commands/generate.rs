//! `kanegen generate MODEL`: unrolled, allocation-free, `no_std` Rust for one model (see
//! [`kanegen_codegen`] and the README section "Code generation").

use kanegen_codegen::{generate_file, Options};

/// `CamelCase` type name from a model name or file stem: `ssrms_nguyen_hughes_1994` →
/// `SsrmsNguyenHughes1994`; a leading digit gets a `Model` prefix.
pub fn type_name(stem: &str) -> String {
    let mut s: String = stem
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut c = w.chars();
            c.next()
                .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                .unwrap_or_default()
        })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert_str(0, "Model");
    }
    s
}

/// The generated file for `chain` as written by `kanegen generate` (the `libm` crate by its plain
/// name: the including crate depends on `libm`).
///
/// # Errors
/// If the type name is not an identifier.
pub fn generate(
    chain: &kanegen_core::Chain,
    type_name: &str,
    gravity: Option<[f64; 3]>,
    runtime_payload: bool,
) -> Result<String, kanegen_codegen::Error> {
    let mut o = Options::new(type_name);
    o.gravity = gravity;
    o.runtime_payload = runtime_payload;
    generate_file(chain, &o)
}

/// One file of the `kanegen-generated` crate.
#[derive(Clone, Copy, Debug)]
pub struct GeneratedFile {
    /// Path of the file, relative to the repository root.
    pub file: &'static str,
    /// Model file, relative to the repository root.
    pub model: &'static str,
    /// Name of the generated struct.
    pub type_name: &'static str,
    /// Joint locked before generation: `(index, value)`.
    pub lock: Option<(usize, f64)>,
}

/// The files of `generated/src/`, each reproducible with
/// `kanegen generate MODEL --name TYPE [--lock INDEX=VALUE] -o FILE`.
pub const GENERATED: [GeneratedFile; 3] = [
    GeneratedFile {
        file: "generated/src/ssrms.rs",
        model: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        type_name: "Ssrms",
        lock: None,
    },
    GeneratedFile {
        file: "generated/src/ssrms6.rs",
        model: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        type_name: "Ssrms6",
        lock: Some((0, 0.0)),
    },
    GeneratedFile {
        file: "generated/src/srms.rs",
        model: "tests/data/reference/srms_nguyen_hughes_1994.urdf",
        type_name: "Srms",
        lock: None,
    },
];

impl GeneratedFile {
    /// The chain, locked when asked; `root` is the repository root.
    ///
    /// # Errors
    /// If the model cannot be read or locked.
    pub fn chain(
        &self,
        root: &std::path::Path,
    ) -> Result<kanegen_core::Chain, kanegen_core::ModelError> {
        let chain = kanegen_core::io::load_model(&root.join(self.model))?;
        match self.lock {
            Some((i, v)) => chain.lock_joint(i, v),
            None => Ok(chain),
        }
    }

    /// The file's expected contents.
    ///
    /// # Errors
    /// If the model cannot be read or locked.
    pub fn render(&self, root: &std::path::Path) -> Result<String, String> {
        let chain = self.chain(root).map_err(|e| e.to_string())?;
        generate(&chain, self.type_name, None, false).map_err(|e| e.to_string())
    }
}
