//! # kanegen-macros
//!
//! The `dynamics!` proc-macro: unrolled, allocation-free dynamics code for a fixed model, emitted
//! at compile time by [`kanegen_codegen`]; and `scene!`, a simulator specialized for one scene
//! file (`scene`). Use them through the `kanegen` facade (`kanegen::dynamics!`,
//! `kanegen::scene!`), `macro_rules!` wrappers that pass the facade's path (`$crate`) first, so
//! the generated code calls the facade's `libm` and integrators however the user names the
//! dependency.
#![warn(missing_docs)]

mod scene;
mod scene_events;
mod scene_linearize;
mod scene_provider;

use proc_macro::TokenStream;
use proc_macro2::Span;
use quote::quote;
use syn::parse::{Parse, ParseStream};
use syn::{Expr, ExprArray, ExprLit, ExprUnary, Ident, Lit, LitBool, LitStr, Token, UnOp};

struct Input {
    /// The facade's path (`$crate` of `kanegen::dynamics!`), before a `;`.
    runtime: syn::Path,
    name: Ident,
    path: LitStr,
    gravity: Option<[f64; 3]>,
    base: Option<kanegen_codegen::kanegen_model::BaseKind>,
    allow_nonphysical: bool,
    allow_large: bool,
    ignore_mimic: bool,
    runtime_payload: bool,
    float: kanegen_codegen::Float,
    fma: bool,
    fma_path: Option<syn::Path>,
    target_fma: bool,
    regroup: bool,
    canonical: bool,
    libm_trig: bool,
    snap: Option<f64>,
    algorithm: Option<kanegen_codegen::kanegen_dynamics::Methods>,
    form: kanegen_codegen::Form,
    derivatives: bool,
}

fn float(e: &Expr) -> syn::Result<f64> {
    match e {
        Expr::Lit(ExprLit {
            lit: Lit::Float(f), ..
        }) => f.base10_parse(),
        Expr::Lit(ExprLit {
            lit: Lit::Int(i), ..
        }) => i.base10_parse::<i64>().map(|x| x as f64),
        Expr::Unary(ExprUnary {
            op: UnOp::Neg(_),
            expr,
            ..
        }) => float(expr).map(|x| -x),
        other => Err(syn::Error::new_spanned(other, "expected a number literal")),
    }
}

/// The options `dynamics!` takes after the model's path, in the order its messages list them.
const OPTIONS: &[&str] = &[
    "gravity",
    "base",
    "allow_nonphysical",
    "allow_large",
    "ignore_mimic",
    "runtime_payload",
    "scalar",
    "fma",
    "fma_path",
    "target_fma",
    "regroup",
    "canonical",
    "libm_trig",
    "snap",
    "algorithm",
    "form",
    "derivatives",
];

impl Input {
    /// The defaults of every option.
    fn new(runtime: syn::Path, name: Ident, path: LitStr) -> Self {
        Input {
            runtime,
            name,
            path,
            gravity: None,
            base: None,
            allow_nonphysical: false,
            allow_large: false,
            ignore_mimic: false,
            runtime_payload: false,
            float: kanegen_codegen::Float::F64,
            fma: false,
            fma_path: None,
            target_fma: true,
            regroup: true,
            canonical: true,
            derivatives: true,
            libm_trig: false,
            snap: None,
            algorithm: None,
            form: kanegen_codegen::Form::Auto,
        }
    }

    /// Parses the value of option `key` (its `=` already read) into `self`.
    fn option(&mut self, key: &Ident, input: ParseStream) -> syn::Result<()> {
        match key.to_string().as_str() {
            "gravity" => self.gravity = Some(gravity(input)?),
            "base" => self.base = Some(base(input)?),
            "allow_nonphysical" => self.allow_nonphysical = input.parse::<LitBool>()?.value,
            "allow_large" => self.allow_large = input.parse::<LitBool>()?.value,
            "ignore_mimic" => self.ignore_mimic = input.parse::<LitBool>()?.value,
            "runtime_payload" => self.runtime_payload = input.parse::<LitBool>()?.value,
            "scalar" => self.float = scalar(input)?,
            "fma" => self.fma = input.parse::<LitBool>()?.value,
            "regroup" => self.regroup = input.parse::<LitBool>()?.value,
            "canonical" => self.canonical = input.parse::<LitBool>()?.value,
            "derivatives" => self.derivatives = input.parse::<LitBool>()?.value,
            "libm_trig" => self.libm_trig = input.parse::<LitBool>()?.value,
            "target_fma" => self.target_fma = input.parse::<LitBool>()?.value,
            "algorithm" => {
                let name: LitStr = input.parse()?;
                self.algorithm = Some(
                    kanegen_codegen::forced_algorithm(&name.value())
                        .map_err(|e| syn::Error::new(name.span(), e.0))?,
                );
            }
            "snap" => self.snap = Some(snap(input)?),
            "form" => self.form = form(input)?,
            "fma_path" => self.fma_path = Some(input.parse::<syn::Path>()?),
            other => {
                return Err(syn::Error::new(
                    key.span(),
                    format!("unknown option `{other}` (expected {})", OPTIONS.join(", ")),
                ))
            }
        }
        Ok(())
    }
}

/// `gravity = [x, y, z]`: three finite components within the bound the CLI applies
/// ([`kanegen_codegen::kanegen_model::bounds::GRAVITY`]).
fn gravity(input: ParseStream) -> syn::Result<[f64; 3]> {
    let arr: ExprArray = input.parse()?;
    let v: Vec<f64> = arr.elems.iter().map(float).collect::<syn::Result<_>>()?;
    let g: [f64; 3] = v
        .try_into()
        .map_err(|_| syn::Error::new_spanned(&arr, "gravity must have three components"))?;
    kanegen_codegen::kanegen_model::bounds::GRAVITY
        .check(&g)
        .map_err(|e| syn::Error::new_spanned(&arr, format!("gravity: {e}")))?;
    Ok(g)
}

/// `base = "fixed" | "free-floating"`.
fn base(input: ParseStream) -> syn::Result<kanegen_codegen::kanegen_model::BaseKind> {
    let lit: LitStr = input.parse()?;
    kanegen_codegen::kanegen_model::BaseKind::from_name(&lit.value()).ok_or_else(|| {
        syn::Error::new(
            lit.span(),
            format!(
                "unknown base `{}`: expected \"fixed\" or \"free-floating\"",
                lit.value()
            ),
        )
    })
}

/// `scalar = f32 | f64`.
fn scalar(input: ParseStream) -> syn::Result<kanegen_codegen::Float> {
    let ty: Ident = input
        .parse()
        .map_err(|e| syn::Error::new(e.span(), "expected `f32` or `f64` (scalar = f32)"))?;
    kanegen_codegen::Float::from_name(&ty.to_string()).ok_or_else(|| {
        syn::Error::new(
            ty.span(),
            format!("unsupported scalar `{ty}`: expected `f32` or `f64`"),
        )
    })
}

/// `snap = x` with `x` in [0, 0.1).
fn snap(input: ParseStream) -> syn::Result<f64> {
    let e: Expr = input.parse()?;
    let x = float(&e)?;
    if !(0.0..0.1).contains(&x) {
        return Err(syn::Error::new_spanned(
            e,
            format!("snap tolerance {x} is not in [0, 0.1)"),
        ));
    }
    Ok(x)
}

/// `form = "auto" | "unrolled" | "compact"`.
fn form(input: ParseStream) -> syn::Result<kanegen_codegen::Form> {
    let lit: LitStr = input.parse()?;
    kanegen_codegen::Form::from_name(&lit.value()).ok_or_else(|| {
        syn::Error::new(
            lit.span(),
            format!(
                "unknown form `{}`: expected \"auto\", \"unrolled\" or \"compact\"",
                lit.value()
            ),
        )
    })
}

/// The head every macro input starts with: `RUNTIME; Name, "path"`.
fn head(input: ParseStream) -> syn::Result<(syn::Path, Ident, LitStr)> {
    let runtime: syn::Path = input.parse()?;
    input.parse::<Token![;]>()?;
    let name: Ident = input.parse()?;
    input.parse::<Token![,]>()?;
    Ok((runtime, name, input.parse()?))
}

impl Parse for Input {
    /// `RUNTIME; Name, "path" [, key = value]*`: each option at most once.
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let (runtime, name, path) = head(input)?;
        let mut out = Input::new(runtime, name, path);
        let mut seen: Vec<Ident> = Vec::new();
        while input.parse::<Option<Token![,]>>()?.is_some() {
            if input.is_empty() {
                break;
            }
            let key: Ident = input.parse()?;
            if let Some(first) = seen.iter().find(|k| **k == key) {
                let mut e = syn::Error::new(
                    key.span(),
                    format!("option `{key}` is given twice: give each option once"),
                );
                e.combine(syn::Error::new(first.span(), "first given here"));
                return Err(e);
            }
            input.parse::<Token![=]>()?;
            out.option(&key, input)?;
            seen.push(key);
        }
        if let (Some(key), false) = (seen.iter().find(|k| *k == "fma_path"), out.fma) {
            return Err(syn::Error::new(key.span(), "`fma_path` needs `fma = true`"));
        }
        Ok(out)
    }
}

/// The implementation of `kanegen::dynamics!` (documented there): `dynamics!(RUNTIME; Name,
/// "path" [, options])`, where `RUNTIME` is the path of the `kanegen` facade.
#[proc_macro]
pub fn dynamics(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as Input);
    match expand(&input) {
        Ok(ts) => ts.into(),
        Err(e) => e.to_compile_error().into(),
    }
}

/// The expansion; an error at the type name for a name clash ([`kanegen_codegen::check_names`]),
/// else at the model's path.
fn expand(input: &Input) -> syn::Result<proc_macro2::TokenStream> {
    let opts = options(input);
    kanegen_codegen::check_names(&opts).map_err(|e| syn::Error::new(input.name.span(), e.0))?;
    generate(input, &opts).map_err(|msg| syn::Error::new(input.path.span(), msg))
}

/// The generator options of `input`.
fn options(input: &Input) -> kanegen_codegen::Options {
    let name = input.name.to_string();
    let mut opts = kanegen_codegen::Options::new(name.clone());
    opts.gravity = input.gravity;
    opts.base = input.base;
    opts.runtime_payload = input.runtime_payload;
    let runtime = &input.runtime;
    opts.libm_path = "kanegen::__private::libm".into();
    opts.libm_tokens = Some(quote!(#runtime::__private::libm));
    opts.runtime_path = "kanegen::__private::runtime".into();
    opts.runtime_tokens = Some(quote!(#runtime::__private::runtime));
    opts.payload_name = format!("{name}Payload");
    opts.op_count_name = format!("{name}OpCount");
    opts.float = input.float;
    opts.fma = input.fma;
    opts.regroup = input.regroup;
    opts.canonical = input.canonical;
    opts.derivatives = input.derivatives;
    opts.libm_trig = input.libm_trig;
    opts.target_fma = input.target_fma;
    opts.algorithm = input.algorithm;
    if let Some(snap) = input.snap {
        opts.snap = snap;
    }
    opts.form = input.form;
    opts.fma_path = input
        .fma_path
        .as_ref()
        .map(|p| quote!(#p).to_string().replace(' ', ""));
    opts
}

/// The items for `input`'s model under `opts` (the model read, checked for size, then
/// generated), after a constant that includes the model file so that a change to it rebuilds.
fn generate(
    input: &Input,
    opts: &kanegen_codegen::Options,
) -> Result<proc_macro2::TokenStream, String> {
    let rel = input.path.value();
    let dir = std::env::var("CARGO_MANIFEST_DIR").unwrap_or_else(|_| ".".into());
    let path = std::path::Path::new(&dir).join(&rel);
    let abs = path.display().to_string();
    let v = kanegen_codegen::kanegen_model::Validation {
        allow_nonphysical_inertia: input.allow_nonphysical,
    };
    // Messages name the path as written, not the machine's absolute path.
    let mut model = kanegen_codegen::kanegen_model::io::load_model_with(&path, v)
        .map_err(|e| e.to_string().replace(&abs, &rel))?;
    if input.ignore_mimic {
        model = model.without_mimics();
    }
    let n = model.dof();
    if n > kanegen_codegen::MAX_JOINTS && !input.allow_large {
        return Err(format!(
            "`{rel}` has {n} joints, more than {}: the generated functions would keep O(N) arrays \
             on the caller's stack and straight-line frame functions of 6·N Jacobian entries; \
             `allow_large = true` generates it anyway",
            kanegen_codegen::MAX_JOINTS
        ));
    }
    let g = kanegen_codegen::generate_items(&model, opts).map_err(|e| e.to_string())?;
    let (include, items) = (include_file(&abs), g.items);
    Ok(quote! {
        #include
        #items
    })
}

/// `const _: &[u8] = include_bytes!("abs");`, by full paths: the file at `abs` becomes an input
/// of the build, so that a change to it expands the macro again.
fn include_file(abs: &str) -> proc_macro2::TokenStream {
    let abs = LitStr::new(abs, Span::call_site());
    let u8 = kanegen_codegen::paths::primitive("u8");
    quote!(const _: &[#u8] = ::core::include_bytes!(#abs);)
}

struct SceneInput {
    runtime: syn::Path,
    name: Ident,
    path: LitStr,
}

impl Parse for SceneInput {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let (runtime, name, path) = head(input)?;
        input.parse::<Option<Token![,]>>()?;
        if !input.is_empty() {
            return Err(input.error(
                "scene! takes a type name and a scene path only (the scene file holds the options)",
            ));
        }
        Ok(SceneInput {
            runtime,
            name,
            path,
        })
    }
}

/// The implementation of `kanegen::scene!` (documented there): `scene!(RUNTIME; Name,
/// "path")`, where `RUNTIME` is the path of the `kanegen` facade.
#[proc_macro]
pub fn scene(input: TokenStream) -> TokenStream {
    let input = syn::parse_macro_input!(input as SceneInput);
    match scene::expand(&input.runtime, &input.name, &input.path.value()) {
        Ok(ts) => ts.into(),
        Err(msg) => syn::Error::new(input.path.span(), msg)
            .to_compile_error()
            .into(),
    }
}
