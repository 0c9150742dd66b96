//! `kanegen generate MODEL`: unrolled, allocation-free, `no_std` Rust for one model (see
//! [`kanegen_codegen`] and `docs/codegen.md`).

use kanegen_codegen::{generate_file, Float, Options};
use kanegen_model::{BaseKind, Model, ModelError};

/// Most joints `kanegen generate` accepts without `--allow-large`
/// ([`kanegen_codegen::MAX_JOINTS`], the bound `dynamics!` applies too; random chain N = 1000:
/// 0.55–3.4 s, 59 MB, 1.6 MB of code).
pub const MAX_N: usize = kanegen_codegen::MAX_JOINTS;

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

/// The generated file for `model` as written by `kanegen generate` (the `libm` crate by its plain
/// name: the including crate depends on `libm`).
///
/// # Errors
/// If the type name is not an identifier, or a function cannot be traced.
pub fn generate(model: &Model, opts: &Options) -> Result<String, kanegen_codegen::Error> {
    generate_file(model, opts)
}

/// [`generate`], refusing code that holds a non-finite constant (`f64::NAN`, `f64::INFINITY`):
/// a model quantity folded into the code overflowed. The joint-limit tables are exempt: an
/// absent limit is `±∞` by design.
///
/// # Errors
/// As [`generate`], or a non-finite constant.
pub fn generate_checked(model: &Model, opts: &Options) -> anyhow::Result<String> {
    let code = generate(model, opts)?;
    if let Some((line, token)) = non_finite_constant(&code) {
        anyhow::bail!(
            "the generated code holds the non-finite constant `{token}` (line {}): a model \
             quantity folded into the code overflowed",
            line + 1
        );
    }
    Ok(code)
}

/// The language `kanegen generate` writes (`--lang`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Lang {
    /// A Rust module file ([`generate`]).
    #[default]
    Rust,
    /// A C99 header ([`generate_c`]).
    C,
}

impl Lang {
    /// `rust` or `c`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "rust" => Some(Lang::Rust),
            "c" => Some(Lang::C),
            _ => None,
        }
    }
}

/// The C header for `model` (`kanegen generate --lang c`, [`kanegen_codegen::c`]): its
/// functions named `PREFIX_…`, the prefix [`Options::type_name`] in `snake_case`.
///
/// # Errors
/// As [`kanegen_codegen::c::generate`].
pub fn generate_c(model: &Model, opts: &Options) -> Result<String, kanegen_codegen::Error> {
    kanegen_codegen::c::generate(model, opts, &kanegen_codegen::c::prefix(&opts.type_name))
}

/// [`generate_c`], refusing code that holds a non-finite constant (`NAN`, `INFINITY`): a model
/// quantity folded into the code overflowed.
///
/// # Errors
/// As [`generate_c`], or a non-finite constant.
pub fn generate_c_checked(model: &Model, opts: &Options) -> anyhow::Result<String> {
    let code = generate_c(model, opts)?;
    let found = code.lines().enumerate().find_map(|(i, l)| {
        let l = l.trim_start();
        if l.starts_with("//") || l.starts_with("/*") {
            return None;
        }
        l.split(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_'))
            .find(|w| *w == "NAN" || *w == "INFINITY")
            .map(|w| (i, w.to_string()))
    });
    if let Some((line, token)) = found {
        anyhow::bail!(
            "the generated code holds the non-finite constant `{token}` (line {}): a model \
             quantity folded into the code overflowed",
            line + 1
        );
    }
    Ok(code)
}

/// The first non-finite constant of `code` outside comments and the joint-limit tables: its
/// line (0-based) and its name (`f64::INFINITY`; the code names it by its full path,
/// `::core::primitive::f64::INFINITY`).
fn non_finite_constant(code: &str) -> Option<(usize, String)> {
    let checked = checked_lines(code);
    for ty in ["f64", "f32"] {
        for c in ["NAN", "INFINITY", "NEG_INFINITY"] {
            let token = format!("{ty}::{c}");
            let path = format!("::{token}");
            if let Some(&(line, _)) = checked.iter().find(|(_, l)| {
                !l.trim_start().starts_with("//")
                    && l.split(|ch: char| !(ch.is_alphanumeric() || ch == '_' || ch == ':'))
                        .any(|w| w == token || w.ends_with(&path))
            }) {
                return Some((line, token));
            }
        }
    }
    None
}

/// The lines of `code` (0-based number, text) outside the joint-limit tables
/// (`pub const …_LIMIT: [..] = [..];`, where `±∞` marks an absent limit).
fn checked_lines(code: &str) -> Vec<(usize, &str)> {
    let mut in_table = false;
    let mut lines = Vec::new();
    for (i, l) in code.lines().enumerate() {
        if !in_table && l.trim_start().starts_with("pub const ") && l.contains("_LIMIT: [") {
            in_table = true;
        }
        if in_table {
            in_table = !l.trim_end().ends_with(';');
        } else {
            lines.push((i, l));
        }
    }
    lines
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
    /// Precision (`--scalar`).
    pub float: Float,
    /// Fused multiply-adds (`--fma`).
    pub fma: bool,
    /// The base (`--base`; `None`: the model's).
    pub base: Option<BaseKind>,
    /// Accept published inertias that violate the triangle inequality (`--allow-nonphysical`).
    pub allow_nonphysical: bool,
    /// The forced algorithm (`--algorithm`; `None`: the cheapest per function).
    pub algorithm: Option<&'static str>,
    /// The derivative functions (off: `--no-derivatives`). Only one file carries them: they
    /// are several times the size of the rest, and the crate is also built with `+fma`.
    pub derivatives: bool,
}

/// The files of `generated/src/`, each reproducible with
/// `kanegen generate MODEL --name TYPE [--lock INDEX=VALUE] [--scalar f32] [--fma]
/// [--base free-floating] [--allow-nonphysical] [--algorithm NAME] [--no-derivatives] -o FILE`.
pub const GENERATED: [GeneratedFile; 7] = [
    GeneratedFile {
        file: "generated/src/ssrms.rs",
        model: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        type_name: "Ssrms",
        lock: None,
        float: Float::F64,
        fma: false,
        base: None,
        allow_nonphysical: false,
        algorithm: None,
        derivatives: true,
    },
    GeneratedFile {
        file: "generated/src/ssrms6.rs",
        model: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        type_name: "Ssrms6",
        lock: Some((0, 0.0)),
        float: Float::F64,
        fma: false,
        base: None,
        allow_nonphysical: false,
        algorithm: None,
        derivatives: false,
    },
    GeneratedFile {
        file: "generated/src/srms.rs",
        model: "tests/data/reference/srms_nguyen_hughes_1994.urdf",
        type_name: "Srms",
        lock: None,
        float: Float::F64,
        fma: false,
        base: None,
        allow_nonphysical: false,
        algorithm: None,
        derivatives: false,
    },
    GeneratedFile {
        file: "generated/src/ssrms_f32.rs",
        model: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        type_name: "SsrmsF32",
        lock: None,
        float: Float::F32,
        fma: false,
        base: None,
        allow_nonphysical: false,
        algorithm: None,
        derivatives: true,
    },
    GeneratedFile {
        file: "generated/src/ssrms_fma.rs",
        model: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        type_name: "SsrmsFma",
        lock: None,
        float: Float::F64,
        fma: true,
        base: None,
        allow_nonphysical: false,
        algorithm: None,
        derivatives: true,
    },
    GeneratedFile {
        file: "generated/src/free_floating_7dof.rs",
        model: "tests/data/reference/bmsd_7dof_free_floating.urdf",
        type_name: "FreeFloating7",
        lock: None,
        float: Float::F64,
        fma: false,
        base: Some(BaseKind::FreeFloating),
        allow_nonphysical: true,
        algorithm: None,
        derivatives: false,
    },
    GeneratedFile {
        file: "generated/src/ssrms_recurrent.rs",
        model: "tests/data/reference/ssrms_nguyen_hughes_1994.urdf",
        type_name: "SsrmsRecurrent",
        lock: None,
        float: Float::F64,
        fma: false,
        base: None,
        allow_nonphysical: false,
        algorithm: Some("recurrent"),
        derivatives: false,
    },
];

impl GeneratedFile {
    /// The model, locked when asked; `root` is the repository root.
    ///
    /// # Errors
    /// If the model cannot be read or locked.
    pub fn model(&self, root: &std::path::Path) -> Result<Model, ModelError> {
        let v = kanegen_model::Validation {
            allow_nonphysical_inertia: self.allow_nonphysical,
        };
        let model = kanegen_model::io::load_model_with(&root.join(self.model), v)?;
        match self.lock {
            Some((i, v)) => model.lock_joint(i, v),
            None => Ok(model),
        }
    }

    /// The `kanegen generate` command that writes this file.
    #[must_use]
    pub fn command(&self) -> String {
        let mut c = format!("kanegen generate {} --name {}", self.model, self.type_name);
        if let Some((i, v)) = self.lock {
            c += &format!(" --lock {i}={v}");
        }
        if self.float == Float::F32 {
            c += " --scalar f32";
        }
        if self.fma {
            c += " --fma";
        }
        if let Some(b) = self.base {
            c += &format!(" --base {}", b.name());
        }
        if self.allow_nonphysical {
            c += " --allow-nonphysical";
        }
        if let Some(a) = self.algorithm {
            c += &format!(" --algorithm {a}");
        }
        if !self.derivatives {
            c += " --no-derivatives";
        }
        c + &format!(" -o {}", self.file)
    }

    /// The generator options of this file.
    #[must_use]
    pub fn options(&self) -> Options {
        let mut o = Options::new(self.type_name);
        o.float = self.float;
        o.fma = self.fma;
        o.base = self.base;
        o.algorithm = self
            .algorithm
            .map(|a| kanegen_codegen::forced_algorithm(a).expect("a known algorithm"));
        o.derivatives = self.derivatives;
        o
    }

    /// The file's expected contents.
    ///
    /// # Errors
    /// If the model cannot be read or locked.
    pub fn render(&self, root: &std::path::Path) -> Result<String, String> {
        let model = self.model(root).map_err(|e| e.to_string())?;
        generate(&model, &self.options()).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::non_finite_constant;

    /// A non-finite constant is found by its full path or its short one, outside comments and
    /// the joint-limit tables (where `±∞` marks an absent limit).
    #[test]
    fn non_finite_constants_are_found_outside_the_limit_tables() {
        let limits = "    pub const EFFORT_LIMIT: [::core::primitive::f64; 2] = [\n        \
                      ::core::primitive::f64::INFINITY,\n        1f64,\n    ];\n";
        let comment = "    // f64::NAN\n";
        assert_eq!(non_finite_constant(&format!("{limits}{comment}")), None);
        for (code, token) in [
            (
                "let x = ::core::primitive::f64::NEG_INFINITY;",
                "f64::NEG_INFINITY",
            ),
            ("let x = f32::NAN * q[0];", "f32::NAN"),
        ] {
            let text = format!("{limits}{comment}{code}\n");
            assert_eq!(
                non_finite_constant(&text),
                Some((5, token.to_string())),
                "{code}"
            );
        }
    }
}
