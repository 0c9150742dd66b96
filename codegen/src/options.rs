//! Generator options: the generated type's name, gravity, a runtime payload, the precision, and
//! the paths the emitted code calls.

use kanegen_dynamics::{ForwardMethod, Methods};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

/// Most joints a model may have for generation without an explicit override (`--allow-large`
/// of `kanegen generate`, `allow_large = true` of `dynamics!`). Large models take the compact
/// form, decided from a traced prefix ([`crate::plan`]), so generating is quick at that size;
/// beyond it the generated code is what grows: its functions keep O(N) arrays on the caller's
/// stack (a frame Jacobian returns 6·N entries).
pub const MAX_JOINTS: usize = 1000;

/// Version of the generator, written into every generated header.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Generator options.
#[derive(Clone, Debug)]
pub struct Options {
    /// Name of the generated unit struct (a Rust identifier, e.g. `Ssrms`).
    pub type_name: String,
    /// Uniform gravity in the base frame, m/s². `None` (default): space, no gravity code at all
    /// and no `gravity` function.
    pub gravity: Option<[f64; 3]>,
    /// The base: `None` (default) the model's own ([`kanegen_model::Model::base_kind`]), or
    /// fixed or free-floating (which needs the model's base inertial).
    pub base: Option<kanegen_model::BaseKind>,
    /// Make the last body's (the payload's) mass, centre of mass and inertia runtime inputs: every
    /// function then takes a last argument `payload: &Payload`.
    pub runtime_payload: bool,
    /// Path of the `libm` crate in the generated code: `libm` for a crate depending on `libm`,
    /// `$crate::__private::libm` (the facade's) for the output of the `dynamics!` macro.
    pub libm_path: String,
    /// The `libm` path as tokens, overriding [`Options::libm_path`] in the code (not in the
    /// header): the `dynamics!` macro passes `$crate::__private::libm`, which no string spells.
    pub libm_tokens: Option<TokenStream>,
    /// Path of the `kanegen-runtime` crate in the generated code: `kanegen_runtime` for a crate
    /// depending on it, `kanegen::__private::runtime` (the facade's) for the output of the
    /// `dynamics!` macro.
    pub runtime_path: String,
    /// The runtime path as tokens, overriding [`Options::runtime_path`] in the code (not in the
    /// header): the `dynamics!` macro passes `$crate::__private::runtime`.
    pub runtime_tokens: Option<TokenStream>,
    /// Name of the generated payload struct (used with [`Options::runtime_payload`]).
    pub payload_name: String,
    /// Name of the generated struct of [`OP_COUNTS`](crate#op-counts) entries.
    pub op_count_name: String,
    /// Floating-point type of the emitted code (default [`Float::F64`]).
    pub float: Float,
    /// Fuse single-use products into their sum or difference: `c + a·b`, `a·b + c` become
    /// `fma(a, b, c)`, `c − a·b` becomes `fma(−a, b, c)` and `a·b − c` becomes `fma(a, b, −c)`
    /// (one rounding instead of two). Default `false`.
    pub fma: bool,
    /// The function called for a fused multiply-add, as `path(a, b, c)` = `a·b + c`. `None`
    /// (default): `fma` (f64) or `fmaf` (f32) of [`Options::libm_path`]. `f64::mul_add` /
    /// `f32::mul_add` (UFCS of the std method; not `no_std`) work as well.
    pub fma_path: Option<String>,
    /// Without [`Options::fma`]: fuse the same products through `S::mul_add(a, b, c)` of the
    /// lane type (`kanegen_runtime::lanes::Lanes`), one fused instruction where the build targets it (`x86_64` with
    /// `target_feature = "fma"`, e.g. `-C target-cpu=native`; AArch64) and `a·b + c` otherwise,
    /// where the code is then bit-identical to unfused code. Default `true`.
    pub target_fma: bool,
    /// Let the local-frame algorithms read regrouped inertial parameters
    /// (`kanegen_dynamics::regroup`: each revolute body's axis mass carried by its parent): the
    /// same joint-space results in fewer operations. Default `true`; the base reaction always
    /// reads the model's own numbers.
    pub regroup: bool,
    /// Snap float noise in the model before tracing ([`kanegen_model::Model::snapped`]):
    /// rotations within `snap` of a signed permutation become it exactly, and translations,
    /// axis components, centres of mass and relative inertia entries below `snap` become 0, so
    /// `rpy = 1.5707963267948966`'s `cos = 6.1e-17` costs no multiplication. Default
    /// [`kanegen_model::canonical::DEFAULT_SNAP`] (1e-15: representation residues only, the
    /// dynamics stay within 1e-15 of the file's); `0.0` snaps nothing; `1e-9` also catches
    /// `rpy = 1.570796325` (4.9e-12) and changes the robot by that much. The header says what
    /// was snapped.
    pub snap: f64,
    /// Trace the joint-space functions in the model's canonical frames too
    /// ([`crate::choose::BodyFrames`]) and emit whichever is cheaper. Default `true`.
    pub canonical: bool,
    /// Take sines and cosines from libm (`sincos`, `sin`, `cos`) instead of the emitted
    /// `Self::sincos` ([`crate::sincos`]: a table and short polynomials, branch-free, within
    /// 1 ulp of 1 of libm's). Default `false`; `f32` code always uses libm's `sincosf`.
    pub libm_trig: bool,
    /// Force one algorithm for every function that has a mass-matrix, nonlinear-effects or forward method
    /// instead of the cheapest candidate: a preset of [`Methods::PRESETS`] (`recurrent`, the
    /// paper's; `recurrent-r1`, `kane-direct`, `crba-inertial`, `spatial`) or [`Methods::ABA`]
    /// (`aba`), by [`forced_algorithm`]. Default `None`: the cheapest. The header says which.
    pub algorithm: Option<Methods>,
    /// Straight-line or compact code ([`Form`], default [`Form::Auto`]: chosen by size, see
    /// [`crate::compact`]).
    pub form: Form,
    /// Generate the derivative functions (`inverse_dynamics_derivatives`,
    /// `forward_dynamics_derivatives`, `mass_matrix_inverse`) where the form allows them
    /// ([`crate::plan::derivatives_generated`]). Default `true`; `false` leaves them out to
    /// save compile time (they are several times the size of the other functions).
    pub derivatives: bool,
}

/// The methods `algorithm = NAME` forces ([`Options::algorithm`]).
///
/// # Errors
/// For a name that is neither a preset nor `aba`, listing the names.
pub fn forced_algorithm(name: &str) -> Result<Methods, Error> {
    if name == ForwardMethod::Aba.name() {
        return Ok(Methods::ABA);
    }
    Methods::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = Methods::PRESETS.iter().map(|(n, _)| *n).collect();
        Error(format!(
            "unknown algorithm `{name}` (expected {}, or aba)",
            names.join(", ")
        ))
    })
}

/// Which form of the generated functions to emit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Form {
    /// Compact code when the unrolled code would exceed `compact::AUTO_LIMIT` emitted operations and the
    /// model is supported (`compact::unsupported`), straight-line code otherwise (default). In
    /// compact code, the O(N) Newton–Euler functions stay straight-line within
    /// `compact::LINEAR_AUTO_LIMIT` operations of their own (`compact::keeps_unrolled`).
    #[default]
    Auto,
    /// Straight-line code from traced graphs (`emit`).
    Unrolled,
    /// Loops over constant tables (`compact`).
    Compact,
}

impl Form {
    /// `auto`, `unrolled` or `compact`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Form::Auto => "auto",
            Form::Unrolled => "unrolled",
            Form::Compact => "compact",
        }
    }

    /// The form of a name ([`Form::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(Form::Auto),
            "unrolled" => Some(Form::Unrolled),
            "compact" => Some(Form::Compact),
            _ => None,
        }
    }
}

/// Floating-point type of the emitted code.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Float {
    /// `f64` (default).
    #[default]
    F64,
    /// `f32`: inputs, outputs, constants and libm calls.
    F32,
}

impl Float {
    /// The Rust type name, `f64` or `f32`.
    pub fn name(self) -> &'static str {
        match self {
            Float::F64 => "f64",
            Float::F32 => "f32",
        }
    }

    /// `f64` or `f32` from its name.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "f64" => Some(Float::F64),
            "f32" => Some(Float::F32),
            _ => None,
        }
    }

    /// The type in emitted code, by its full path ([`crate::paths::primitive`]).
    pub(crate) fn ty(self) -> TokenStream {
        crate::paths::primitive(self.name())
    }

    /// The libm function `base` for this type: `sin` or `sinf`.
    pub(crate) fn libm_fn(self, base: &str) -> proc_macro2::Ident {
        match self {
            Float::F64 => format_ident!("{}", base),
            Float::F32 => format_ident!("{}f", base),
        }
    }

    /// A literal of this type with the value `x` (rounded for `f32`), suffixed like `quote!`
    /// suffixes an `f64`.
    pub(crate) fn suffixed(self, x: f64) -> Literal {
        match self {
            Float::F64 => Literal::f64_suffixed(x),
            Float::F32 => Literal::f32_suffixed(x as f32),
        }
    }
}

impl Options {
    /// The path of libm in the emitted code: [`Options::libm_tokens`], else
    /// [`Options::libm_path`] parsed.
    ///
    /// # Errors
    /// If [`Options::libm_path`] is not a Rust path.
    pub(crate) fn libm(&self) -> Result<TokenStream, Error> {
        Ok(match &self.libm_tokens {
            Some(t) => t.clone(),
            None => {
                let p: syn::Path = syn::parse_str(&self.libm_path)
                    .map_err(|e| Error(format!("libm path `{}`: {e}", self.libm_path)))?;
                quote!(#p)
            }
        })
    }

    /// The path of `kanegen-runtime` in the emitted code: [`Options::runtime_tokens`], else
    /// [`Options::runtime_path`] parsed.
    ///
    /// # Errors
    /// If [`Options::runtime_path`] is not a Rust path.
    pub(crate) fn runtime(&self) -> Result<TokenStream, Error> {
        Ok(match &self.runtime_tokens {
            Some(t) => t.clone(),
            None => {
                let p: syn::Path = syn::parse_str(&self.runtime_path)
                    .map_err(|e| Error(format!("runtime path `{}`: {e}", self.runtime_path)))?;
                quote!(#p)
            }
        })
    }

    /// Whether the emitted code takes sines and cosines from its own `Self::sincos`
    /// ([`crate::sincos`]): `f64` code without [`Options::libm_trig`].
    #[must_use]
    pub fn table_sincos(&self) -> bool {
        self.float == Float::F64 && !self.libm_trig
    }

    /// Defaults: space (no gravity), constant payload, `libm` path `libm`, structs `Payload` and
    /// `OpCount`, `f64`, products fused where the target has FMA ([`Options::target_fma`]), regrouped
    /// inertial parameters.
    pub fn new(type_name: impl Into<String>) -> Self {
        Options {
            type_name: type_name.into(),
            gravity: None,
            base: None,
            runtime_payload: false,
            libm_path: "libm".into(),
            libm_tokens: None,
            runtime_path: "kanegen_runtime".into(),
            runtime_tokens: None,
            payload_name: "Payload".into(),
            op_count_name: "OpCount".into(),
            float: Float::F64,
            fma: false,
            fma_path: None,
            target_fma: true,
            regroup: true,
            snap: kanegen_model::canonical::DEFAULT_SNAP,
            canonical: true,
            libm_trig: false,
            algorithm: None,
            form: Form::Auto,
            derivatives: true,
        }
    }
}

/// An error of the generator.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error(pub String);

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Error {}
