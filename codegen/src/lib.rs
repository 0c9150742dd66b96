//! # kanegen-codegen
//!
//! The emit stage of kanegen's pipeline: unrolled, allocation-free, `no_std` Rust for one fixed
//! model, from graphs traced by `kanegen-trace`.
//!
//! Generation is one [`Plan`], then emission: the plan ([`plan`]) decides the form (straight-line
//! or compact loops, [`compact`]) from traced prefixes of the model, and for every generated
//! function ([`api`]) of straight-line code traces the candidates with the model's numbers as
//! constants and keeps the cheapest in emitted `mul + add` ([`choose`]); its graph becomes
//! straight-line Rust ([`emit`]). A function in compact loops calls a kernel of
//! `kanegen_runtime::compact` over the model's tables ([`compact`]). The generated type
//! is a unit struct with associated constants and functions ([`generate_items`]);
//! [`generate_file`] wraps it into a formatted module file whose doc header ([`header`]) states
//! the model, the conventions and every traced candidate's counts. [`c::generate`] prints the
//! same plan's graphs, by the same walk ([`emit::emit_graph`] over an [`emit::Syntax`]), as a C99
//! header instead.
//!
//! # Op counts
//!
//! The generated type has `OP_COUNTS`, one entry per emitted function, and `CANDIDATES`, one per
//! traced candidate, both of a generated struct (`OpCount` in files from [`generate_file`],
//! `NameOpCount` from the `dynamics!` macro) with the fields `function`, `mass_matrix_method`,
//! `nonlinear_effects_method` (`None` when unused), `forward_method` (`ldlt` or `aba` for forward dynamics,
//! `None` otherwise; `aba` uses no mass-matrix or nonlinear-effects method), `mul`, `add`, `div`, `sqrt`,
//! `sincos` and `fma` (fused multiply-adds formed; only emitted code forms them, so
//! `CANDIDATES` lists 0). A function in compact loops has as `OP_COUNTS` entry its kernel traced
//! on the tracer `Sym` ([`compact::counts`]: every operation its loops execute), and
//! `CANDIDATES` has none of it.
//!
//! ```
//! use kanegen_codegen::{generate_file, Options};
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let model = random_chain(&ChainSpec { n: 2, ..Default::default() }, 1);
//! let src = generate_file(&model, &Options::new("Arm")).unwrap();
//! // Primitive types by their full paths: the including module may call something `f64`.
//! assert!(src.contains(
//!     "pub fn nonlinear_effects(
//!         q: &[::core::primitive::f64; 2],
//!         qd: &[::core::primitive::f64; 2],
//!     ) -> [::core::primitive::f64; 2] {"
//! ));
//! ```
#![warn(missing_docs)]

pub mod api;
pub mod c;
pub mod choose;
pub mod compact;
pub mod emit;
pub mod header;
mod options;
pub mod paths;
pub mod plan;
pub mod sincos;

pub use choose::Choice;
pub use emit::{Body, Emitter, Shape};
pub use options::{forced_algorithm, Error, Float, Form, Options, MAX_JOINTS, VERSION};
pub use plan::Plan;

use kanegen_model::Model;
use kanegen_trace::{Arg, Counts, Function};
use plan::{FunctionPlan, Kernel};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

/// Everything generated for one model.
pub struct Generated {
    /// The items: the unit struct, its `impl`, the op-count struct, and the payload struct when
    /// asked.
    pub items: TokenStream,
    /// The doc header lines (without comment markers).
    pub header: Vec<String>,
    /// One choice per generated function.
    pub choices: Vec<Choice>,
    /// Fused multiply-adds formed per generated function (all 0 without [`Options::fma`]).
    pub fmas: Vec<u64>,
}

impl Generated {
    /// Whether the derivative functions (`inverse_dynamics_derivatives`,
    /// `forward_dynamics_derivatives`, `mass_matrix_inverse`) were generated.
    #[must_use]
    pub fn has_derivatives(&self) -> bool {
        self.choices
            .iter()
            .any(|c| c.function == kanegen_trace::Function::ForwardDynamicsDerivatives)
    }
}

/// Generates the items for `model`.
///
/// # Errors
/// If an option is not a valid Rust identifier or path, or a function cannot be traced.
pub fn generate_items(model: &Model, opts: &Options) -> Result<Generated, Error> {
    generate_items_with(model, opts, true, None)
}

fn ident(what: &str, name: &str) -> Result<syn::Ident, Error> {
    syn::parse_str(name).map_err(|e| Error(format!("{what} `{name}`: {e}")))
}

/// [`generate_items`]; `header_on_struct`: document the struct with the full header (else one
/// line, for files whose module docs carry the header). With `bodies`, each function body is
/// formatted to text statement by statement as it is emitted ([`format_body`]) and pushed
/// there, and the items hold the placeholder `__kanegen_body_K()` instead ([`generate_file`]).
fn generate_items_with(
    model: &Model,
    opts: &Options,
    header_on_struct: bool,
    mut bodies: Option<&mut Vec<String>>,
) -> Result<Generated, Error> {
    check_generable(model)?;
    let names = Names::new(opts)?;
    let emitter = Emitter::new(opts)?;
    let (plan, graphs) = Plan::new(model, opts)?;
    let mut fns = Vec::new();
    let mut fmas = Vec::new();
    for (fp, graph) in plan.functions.iter().zip(graphs) {
        let body = function_body(&plan, fp, graph, opts, &emitter, bodies.as_deref_mut())?;
        fmas.push(body.fmas);
        fns.push(function_item(&plan, fp, body, opts, &names)?);
    }
    let header = header::lines(&plan, opts, &fmas);
    let items = type_items(&plan, opts, &names, &header, header_on_struct, &fns, &fmas)?;
    Ok(Generated {
        items,
        header,
        choices: plan.functions.into_iter().map(|fp| fp.choice).collect(),
        fmas,
    })
}

/// What the generated type cannot be made for: joints that move no mass (its forward dynamics
/// would divide by a singular `M`).
pub(crate) fn check_generable(model: &Model) -> Result<(), Error> {
    model
        .check_forward_dynamics()
        .map_err(|e| Error(e.to_string()))
}

/// The identifiers of the generated type, its payload struct and its op-count struct.
struct Names {
    ty: syn::Ident,
    payload: syn::Ident,
    op_count: syn::Ident,
}

impl Names {
    fn new(opts: &Options) -> Result<Self, Error> {
        let names = Names {
            ty: ident("type name", &opts.type_name)?,
            payload: ident("payload name", &opts.payload_name)?,
            op_count: ident("op-count name", &opts.op_count_name)?,
        };
        check_names(opts)?;
        Ok(names)
    }
}

/// Checks that the items the generated code declares in the including module, the type
/// ([`Options::type_name`]), its op-count struct ([`Options::op_count_name`]) and, with
/// [`Options::runtime_payload`], its payload struct ([`Options::payload_name`]), have names of
/// their own, and that none of them shadows a crate or module the emitted code calls into (the
/// first segment of the libm, runtime and fma paths): one clear error instead of the compiler's
/// cascade over the generated code.
///
/// # Errors
/// Naming the clash and what to rename.
pub fn check_names(opts: &Options) -> Result<(), Error> {
    let mut declared = vec![
        ("the generated type", &opts.type_name),
        ("its op-count struct", &opts.op_count_name),
    ];
    if opts.runtime_payload {
        declared.push(("its payload struct", &opts.payload_name));
    }
    if opts.runtime_payload && opts.payload_name == LANE_TYPE {
        return Err(Error(format!(
            "the payload struct is called `{LANE_TYPE}`, the lane type parameter of the \
             `_lanes` functions: rename it"
        )));
    }
    for (k, (what, name)) in declared.iter().enumerate() {
        if let Some((first, _)) = declared[..k].iter().find(|(_, n)| n == name) {
            return Err(Error(format!(
                "{first} and {what} are both called `{name}`: {}",
                rename(first)
            )));
        }
    }
    let mut called = vec![("libm", opts.libm()?), ("runtime", opts.runtime()?)];
    if let (true, Some(p)) = (opts.fma, &opts.fma_path) {
        let p: syn::Path = syn::parse_str(p).map_err(|e| Error(format!("fma path `{p}`: {e}")))?;
        called.push(("fma", quote!(#p)));
    }
    for (path_name, path) in &called {
        // A path from the crate root (`::libm`) or `$crate` cannot be shadowed.
        let Some(proc_macro2::TokenTree::Ident(head)) = path.clone().into_iter().next() else {
            continue;
        };
        if head == LANE_TYPE {
            return Err(Error(format!(
                "the {path_name} path `{}` starts with `{LANE_TYPE}`, the lane type parameter of \
                 the `_lanes` functions: give the path from the crate root (`::…`)",
                path.to_string().replace(' ', "")
            )));
        }
        if let Some((what, name)) = declared.iter().find(|(_, n)| head == n) {
            return Err(Error(format!(
                "{what} is called `{name}`, which would shadow the first segment of the {path_name} \
                 path `{}` the generated code calls: {}",
                path.to_string().replace(' ', ""),
                rename(what)
            )));
        }
    }
    Ok(())
}

/// The lane type parameter of the `_lanes` functions (`S: Lanes<F>`), which a payload struct or
/// a called path must not be named.
const LANE_TYPE: &str = "S";

/// What to rename in a name clash of [`check_names`] involving `what`.
fn rename(what: &str) -> &'static str {
    if what == "the generated type" {
        "give the type another name"
    } else {
        "rename one of them"
    }
}

/// The body of one function: the compact kernel's call, or the straight-line code of its graph.
/// With `texts`, the body is formatted to text there (streamed statement by statement for a
/// graph) and the returned tokens are its placeholder.
fn function_body(
    plan: &Plan,
    fp: &FunctionPlan,
    graph: Option<kanegen_trace::Traced>,
    opts: &Options,
    emitter: &Emitter,
    texts: Option<&mut Vec<String>>,
) -> Result<Body, Error> {
    let compact_tokens = match fp.kernel {
        Kernel::Compact(_) => compact::body(fp.function, opts, &plan.model, plan.floating())?,
        Kernel::Composed(_) => Some(composed_body(plan, fp, opts)?),
        Kernel::Unrolled => None,
    };
    let body = match (texts, compact_tokens, graph) {
        (None, Some(tokens), _) => Body { tokens, fmas: 0 },
        (Some(texts), Some(tokens), _) => {
            texts.push(format_body(&tokens)?);
            Body {
                tokens: placeholder(texts.len() - 1),
                fmas: 0,
            }
        }
        (None, None, Some(graph)) => emit::emit_body(&graph, emitter, fp.shape),
        (Some(texts), None, Some(graph)) => {
            let mut text = String::new();
            let mut failed = None;
            let mut b =
                emit::emit_body_streamed(
                    &graph,
                    emitter,
                    fp.shape,
                    &mut |s| match format_body(&s) {
                        Ok(t) => text.push_str(&t),
                        Err(e) => failed = Some(e),
                    },
                );
            drop(graph);
            if let Some(e) = failed {
                return Err(e);
            }
            text.push_str(&format_body(&b.tokens)?);
            b.tokens = placeholder(texts.len());
            texts.push(text);
            b
        }
        (_, None, None) => {
            return Err(Error(format!(
                "`{}` has neither a compact body nor a traced graph",
                fp.name
            )))
        }
    };
    Ok(body)
}

/// What a composed function calls: its parts `M⁻¹`, `c` and `∂τ` (the type's functions named
/// with `suffix`), its arguments `q`, `q̇`, `τ` and the payload argument.
struct Composed {
    parts: [syn::Ident; 3],
    args: [syn::Ident; 3],
    payload: Option<TokenStream>,
}

impl Composed {
    fn new(plan: &Plan, fp: &FunctionPlan, opts: &Options, suffix: &str) -> Result<Self, Error> {
        let part = |f: Function| -> Result<syn::Ident, Error> {
            let fp = (plan.functions.iter().find(|g| g.function == f))
                .ok_or_else(|| Error(format!("`{}` composes `{}`", fp.name, f.name())))?;
            Ok(format_ident!("{}{suffix}", fp.name))
        };
        Ok(Composed {
            parts: [
                part(Function::MassMatrixInverse)?,
                part(Function::NonlinearEffects)?,
                part(Function::InverseDynamicsDerivatives)?,
            ],
            args: [0, 1, 2].map(|k| format_ident!("{}", fp.args[k].0.name())),
            payload: opts.runtime_payload.then(|| quote!(, payload)),
        })
    }
}

/// The body of a composed function ([`Kernel::Composed`]): `M⁻¹` and `c` from the type's own
/// functions, `q̈ = M⁻¹ (τ − c)`, then `−M⁻¹ ∂τ/∂x` from its inverse-dynamics derivatives
/// (`kanegen_runtime::composed`).
fn composed_body(plan: &Plan, fp: &FunctionPlan, opts: &Options) -> Result<TokenStream, Error> {
    composed_parts(plan, fp, opts, "", &quote!())
}

/// The body of a composed `forward_dynamics_derivatives_lanes`: [`composed_body`] on lanes,
/// each part's own `_lanes` (a lane body, or its scalar function lane by lane) and the two loops
/// of `kanegen_runtime::composed` on the lane type itself (a `Ring`: `+ − ×` lane by lane), so
/// each lane is bit for bit the scalar function's result.
fn composed_lanes_body(
    plan: &Plan,
    fp: &FunctionPlan,
    opts: &Options,
) -> Result<Option<TokenStream>, Error> {
    composed_parts(plan, fp, opts, "_lanes", &quote!(::<S>)).map(Some)
}

/// [`composed_body`] calling the parts `NAME{suffix}{generics}`.
fn composed_parts(
    plan: &Plan,
    fp: &FunctionPlan,
    opts: &Options,
    suffix: &str,
    generics: &TokenStream,
) -> Result<TokenStream, Error> {
    let rt = opts.runtime()?;
    let Composed {
        parts: [minv, c, id],
        args: [q, qd, tau],
        payload: p,
    } = Composed::new(plan, fp, opts, suffix)?;
    let zero = quote!(#rt::Ring::zero());
    let nv = Literal::usize_unsuffixed(fp.speeds());
    Ok(quote! {
        let mut d = ([[#zero; #nv]; #nv], [[#zero; #nv]; #nv], Self::#minv #generics(#q #p));
        let qdd = #rt::composed::accelerations(&d.2, #tau, &Self::#c #generics(#q, #qd #p));
        #rt::composed::forward_dynamics_derivatives(&mut d, &Self::#id #generics(#q, #qd, &qdd #p));
        d
    })
}

/// A lane vector of `float` named in the generated docs.
fn vector_example(float: Float) -> &'static str {
    match float {
        Float::F64 => "f64x4",
        Float::F32 => "f32x8",
    }
}

/// The placeholder of the `k`-th formatted body ([`generate_file`]).
fn placeholder(k: usize) -> TokenStream {
    let name = format_ident!("__kanegen_body_{}", k);
    quote!(#name())
}

/// One generated function and its `_lanes` form: the documentation (what it computes, by which
/// methods, at what emitted cost), signatures and bodies.
///
/// Straight-line code is emitted once, as the body of `NAME_lanes<S: Lanes<F>>` (generic over
/// the lane type, [`emit`]), and `NAME` is its instantiation at `S = F`. A compact body is the
/// body of `NAME`, and `NAME_lanes` evaluates `NAME` lane by lane.
fn function_item(
    plan: &Plan,
    fp: &FunctionPlan,
    body: Body,
    opts: &Options,
    names: &Names,
) -> Result<TokenStream, Error> {
    let fl = opts.float.ty();
    let rt = opts.runtime()?;
    let s = quote!(S);
    let name = format_ident!("{}", fp.name);
    let lanes_name = format_ident!("{}_lanes", fp.name);
    let args = |ty: &TokenStream| -> Vec<TokenStream> {
        fp.args
            .iter()
            .map(|(a, len)| {
                let len = Literal::usize_unsuffixed(*len);
                let name = format_ident!("{}", a.name());
                if *a == Arg::FExt {
                    quote!(#name: &[[#ty; 6]; #len])
                } else {
                    quote!(#name: &[#ty; #len])
                }
            })
            .collect()
    };
    let arg_names: Vec<syn::Ident> = fp
        .args
        .iter()
        .map(|(a, _)| format_ident!("{}", a.name()))
        .collect();
    let (scalar_args, lane_args) = (args(&fl), args(&s));
    let payload_ty = &names.payload;
    let payload_arg = opts
        .runtime_payload
        .then(|| quote!(, payload: &#payload_ty));
    let payload_pass = opts.runtime_payload.then(|| quote!(, payload));
    let (ret, lanes_ret) = (return_type(fp.shape, &fl), return_type(fp.shape, &s));
    let (doc1, doc2) = function_docs(plan, fp, body.fmas, opts);
    let bound = quote!(S: #rt::lanes::Lanes<#fl>);
    let batch_name = format_ident!("{}_batch", fp.name);
    let batch_args: Vec<TokenStream> = fp
        .args
        .iter()
        .map(|(a, len)| {
            let len = Literal::usize_unsuffixed(*len);
            let name = format_ident!("{}", a.name());
            if *a == Arg::FExt {
                quote!(#name: &[[[#fl; 6]; #len]])
            } else {
                quote!(#name: &[[#fl; #len]])
            }
        })
        .collect();
    let payload_arg_batch = opts.runtime_payload.then(|| quote!(payload: &#payload_ty,));
    let unrolled = fp.kernel == Kernel::Unrolled;
    // A compact function whose kernel runs on lanes (the same kernel on `Lane<S>`), or a
    // composed one (its parts' lane forms).
    let kernel_lanes = match fp.kernel {
        Kernel::Compact(_) => compact::lanes_body(fp.function, opts, &plan.model, plan.floating())?,
        Kernel::Composed(_) => composed_lanes_body(plan, fp, opts)?,
        Kernel::Unrolled => None,
    };
    let lane_body = unrolled || kernel_lanes.is_some();
    let batch_doc = if lane_body {
        format!(
            " [`Self::{name}`] of every state of the slices, `S::LANES` states per call of \
             [`Self::{lanes_name}`]: `out[k]` is `{name}` of the `k`-th entries, for `k` below \
             the shortest slice's length (`out` included; entries of `out` past it are left as \
             they are); a last chunk of fewer states is padded with the last state, whose extra \
             results are discarded."
        )
    } else {
        format!(
            " [`Self::{name}`] of every state of the slices: `out[k]` is `{name}` of the `k`-th \
             entries, for `k` below the shortest slice's length (`out` included; entries of \
             `out` past it are left as they are). A function in loops or composed has no lane \
             body, so this calls `{name}` once per state whatever `S` is."
        )
    };
    let body = body.tokens;
    let (scalar_body, lanes_body, lanes_doc) = if let Some(kernel) = kernel_lanes {
        (
            body,
            kernel,
            format!(
                " [`Self::{name}`] of `S::LANES` states at once, one per lane of `S` (`{}` \
                 itself, or a SIMD vector of it such as `kanegen_runtime::lanes::{}`): {}, \
                 each lane's results bit for bit the scalar function's for that lane's state.",
                opts.float.name(),
                vector_example(opts.float),
                if matches!(fp.kernel, Kernel::Composed(_)) {
                    "composed from the lane forms of its parts, the two loops of \
                     `kanegen_runtime::composed` on `S` itself"
                } else {
                    "the same kernel on the tables' numbers as `kanegen_runtime::lanes::Lane`s \
                     of `S`"
                }
            ),
        )
    } else if !unrolled {
        let lane_of = arg_names
            .iter()
            .map(|a| quote!(&#rt::lanes::lane::<#fl, S, _>(#a, i)));
        (
            body,
            quote! {
                #rt::lanes::lanewise::<#fl, S, _>(|i| Self::#name(#(#lane_of),* #payload_pass))
            },
            format!(
                " [`Self::{name}`] of `S::LANES` states at once, one per lane of `S` (`{}` \
                 itself, or a SIMD vector of it such as `kanegen_runtime::lanes::{}`): a \
                 function in loops or composed evaluates the scalar function lane by lane.",
                opts.float.name(),
                vector_example(opts.float)
            ),
        )
    } else {
        (
            quote!(Self::#lanes_name::<#fl>(#(#arg_names),* #payload_pass)),
            body,
            format!(
                " [`Self::{name}`] of `S::LANES` states at once, one per lane of `S` (`{}` \
                 itself, or a SIMD vector of it such as `kanegen_runtime::lanes::{}`): the same \
                 straight-line code, each lane's results bit for bit the scalar function's for \
                 that lane's state.",
                opts.float.name(),
                vector_example(opts.float)
            ),
        )
    };
    let batch_body = if lane_body {
        quote! {
            #rt::lanes::batch::<#fl, S, _>(out, n, |start| {
                Self::#lanes_name::<S>(#(&#rt::lanes::gather::<#fl, S, _>(#arg_names, start, n)),* #payload_pass)
            });
        }
    } else {
        quote! {
            for (k, o) in out[..n].iter_mut().enumerate() {
                *o = Self::#name(#(&#arg_names[k]),* #payload_pass);
            }
        }
    };
    Ok(quote! {
        #[doc = #doc1]
        #[doc = ""]
        #[doc = #doc2]
        #[must_use]
        pub fn #name(#(#scalar_args),* #payload_arg) -> #ret {
            #scalar_body
        }

        #[doc = #lanes_doc]
        #[must_use]
        pub fn #lanes_name<#bound>(#(#lane_args),* #payload_arg) -> #lanes_ret {
            #lanes_body
        }

        #[doc = #batch_doc]
        pub fn #batch_name<#bound>(#(#batch_args,)* #payload_arg_batch out: &mut [#ret]) {
            let n = out.len() #(.min(#arg_names.len()))*;
            #batch_body
        }
    })
}

/// The Rust type of a function's results.
fn return_type(shape: Shape, fl: &TokenStream) -> TokenStream {
    let lit = Literal::usize_unsuffixed;
    match shape {
        Shape::Vector(k) => {
            let k = lit(k);
            quote!([#fl; #k])
        }
        Shape::SymMatrix(k) => {
            let k = lit(k);
            quote!([[#fl; #k]; #k])
        }
        Shape::SymMatrixAndVector(k) => {
            let k = lit(k);
            quote!(([[#fl; #k]; #k], [#fl; #k]))
        }
        Shape::Matrix(r, c) => {
            let (r, c) = (lit(r), lit(c));
            quote!([[#fl; #c]; #r])
        }
        Shape::Matrices(k, n) => {
            let n = lit(n);
            let mats = (0..k).map(|_| quote!([[#fl; #n]; #n]));
            quote!((#(#mats),*))
        }
        Shape::Placement => quote!(([#fl; 3], [[#fl; 3]; 3])),
    }
}

/// The two documentation lines of a function: what it computes ([`api::doc`]), then its methods
/// and counts (emitted; for a compact body, its loops' methods and its kernel's traced counts).
/// `k`: fused multiply-adds formed.
pub(crate) fn function_docs(
    plan: &Plan,
    fp: &FunctionPlan,
    k: u64,
    opts: &Options,
) -> (String, String) {
    let choice = &fp.choice;
    let compact = matches!(fp.kernel, Kernel::Compact(_));
    let mut doc1 = format!(
        " {}",
        api::doc(fp.function, plan.floating(), choice.chosen.forward)
    );
    if compact {
        for unrolled in [
            "by an unrolled branch-free LDLᵀ",
            "by an unrolled articulated-body algorithm",
        ] {
            doc1 = doc1.replace(
                unrolled,
                "by the articulated-body algorithm (RBDA Table 7.1) in loops",
            );
        }
    }
    let methods = [
        choice
            .mass_matrix_method(choice.chosen)
            .map(|m| format!("mass matrix `{m}`")),
        choice
            .nonlinear_effects_method(choice.chosen)
            .map(|m| format!("nonlinear effects `{m}`")),
        choice
            .forward_method(choice.chosen)
            .map(|m| format!("forward `{m}`")),
    ]
    .into_iter()
    .flatten()
    .collect::<Vec<_>>()
    .join(", ");
    if let Kernel::Composed(c) = fp.kernel {
        let doc2 = format!(
            " Composed (Carpentier & Mansard 2018, eq. (3); `kanegen_runtime::composed`): \
             `q̈ = M⁻¹ (τ − c)` from `mass_matrix_inverse` and `nonlinear_effects`, then \
             `∂q̈/∂x = −M⁻¹ ∂τ/∂x` from `inverse_dynamics_derivatives` at that `q̈`: {} mul, \
             {} add, {} div, {} sqrt, {} sincos (the three functions' and the two loops').",
            c.mul, c.add, c.div, c.sqrt, c.sincos
        );
        return (doc1, doc2);
    }
    if let Kernel::Compact(c) = fp.kernel {
        let doc2 = format!(
            " Compact form: loops over the model's constant tables (RBDA), {methods}, the \
             kernels of `kanegen_runtime::compact`: {} mul, {} add, {} div, {} sqrt, {} sincos \
             (traced: every operation the loops execute).",
            c.mul, c.add, c.div, c.sqrt, c.sincos
        );
        return (doc1, doc2);
    }
    let fused = if opts.fma {
        format!(", of which {k} fused multiply-adds")
    } else if opts.target_fma && k > 0 {
        format!(", of which {k} fused where the target has FMA")
    } else {
        String::new()
    };
    let c = choice.counts();
    let doc2 = format!(
        " {}{methods}: {} mul, {} add, {} div, {} sqrt, {} sincos (emitted){fused}.",
        if methods.is_empty() { "" } else { "Methods: " },
        c.mul,
        c.add,
        c.div,
        c.sqrt,
        c.sincos
    );
    (doc1, doc2)
}

/// The `OP_COUNTS` entries (one per emitted function, a compact one's its kernel's traced
/// counts) and
/// the `CANDIDATES` entries (one per traced candidate).
fn op_count_entries(
    plan: &Plan,
    fmas: &[u64],
    op_ty: &syn::Ident,
) -> (Vec<TokenStream>, Vec<TokenStream>) {
    let entry = |fp: &FunctionPlan, cand: &choose::Candidate, fma: u64| {
        let ch = &fp.choice;
        let (m, c, frames) = (cand.methods, cand.counts, cand.frames.name());
        let function = &fp.name;
        let (mm, bm, fm) = (
            paths::option(ch.mass_matrix_method(m)),
            paths::option(ch.nonlinear_effects_method(m)),
            paths::option(ch.forward_method(m)),
        );
        let (mul, add, div, sqrt, sincos) = (c.mul, c.add, c.div, c.sqrt, c.sincos);
        quote!(#op_ty {
            function: #function,
            mass_matrix_method: #mm,
            nonlinear_effects_method: #bm,
            forward_method: #fm,
            frames: #frames,
            mul: #mul,
            add: #add,
            div: #div,
            sqrt: #sqrt,
            sincos: #sincos,
            fma: #fma,
        })
    };
    let emitted = plan
        .functions
        .iter()
        .zip(fmas)
        .map(|(fp, k)| {
            let kernel = |counts| choose::Candidate {
                methods: fp.choice.chosen,
                frames: fp.choice.frames,
                counts,
            };
            match (fp.kernel, fp.choice.candidate()) {
                (Kernel::Compact(counts) | Kernel::Composed(counts), _) => {
                    entry(fp, &kernel(counts), 0)
                }
                (Kernel::Unrolled, Some(chosen)) => entry(fp, chosen, *k),
                (Kernel::Unrolled, None) => entry(fp, &kernel(Counts::default()), *k),
            }
        })
        .collect();
    let all = plan
        .functions
        .iter()
        .flat_map(|fp| fp.choice.candidates.iter().map(move |c| (fp, c)))
        .map(|(fp, c)| entry(fp, c, 0))
        .collect();
    (emitted, all)
}

/// The generated items around the functions `fns`: the documented unit struct, the payload
/// and op-count structs, and the `impl` with the constants, the functions and their helpers.
fn type_items(
    plan: &Plan,
    opts: &Options,
    names: &Names,
    header: &[String],
    header_on_struct: bool,
    fns: &[TokenStream],
    fmas: &[u64],
) -> Result<TokenStream, Error> {
    let model = &plan.model;
    let n = model.coordinate_count();
    let short = [format!(
        "Dynamics of `{}` (N = {n}); see the module documentation.",
        header::doc_safe(model.name())
    )];
    let struct_header: &[String] = if header_on_struct { header } else { &short };
    let struct_docs = struct_header.iter().map(|l| {
        let l = format!(" {l}");
        quote!(#[doc = #l])
    });
    let Names {
        ty,
        payload: payload_ty,
        op_count: op_ty,
    } = names;
    let payload_item = if opts.runtime_payload {
        payload_struct(model, opts, payload_ty)
    } else {
        quote!()
    };
    let op_doc = format!(
        " Emitted operation counts of one function of [`{}`] (`None`: the function uses no such \
         method; `fma`: fused multiply-adds formed, each also counted as one `mul` and one `add`).",
        opts.type_name
    );
    let consts = type_consts(plan, opts.float, fmas, op_ty);
    let helpers = helper_items(plan, opts)?;
    let (name, u64) = (paths::static_str(), paths::primitive("u64"));
    let method = paths::option_type(&name);
    Ok(quote! {
        #(#struct_docs)*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct #ty;

        #payload_item

        #[doc = #op_doc]
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub struct #op_ty {
            /// The generated function.
            pub function: #name,
            /// Its mass-matrix method.
            pub mass_matrix_method: #method,
            /// Its nonlinear-effects method.
            pub nonlinear_effects_method: #method,
            /// Its forward-dynamics method (`ldlt`: LDLᵀ on the mass matrix and `τ − c`; `aba`:
            /// the articulated-body algorithm, which uses neither), for forward dynamics.
            pub forward_method: #method,
            /// The body frames it is traced in: `model` (the model's own) or `canonical` (every
            /// joint axis z, modified-DH x; the same joint-space results).
            pub frames: #name,
            /// Multiplications.
            pub mul: #u64,
            /// Additions and subtractions.
            pub add: #u64,
            /// Divisions.
            pub div: #u64,
            /// Square roots.
            pub sqrt: #u64,
            /// Angles whose sine and cosine are taken.
            pub sincos: #u64,
            /// Fused multiply-adds (with `target_fma`, fused where the build targets FMA).
            pub fma: #u64,
        }

        #[allow(
            clippy::approx_constant,
            clippy::excessive_precision,
            clippy::unreadable_literal,
            clippy::neg_multiply,
            clippy::too_many_lines,
            clippy::many_single_char_names,
            clippy::similar_names,
            clippy::type_complexity,
            clippy::needless_range_loop,
            unused_parens
        )]
        impl #ty {
            #consts

            #(#fns)*

            #helpers
        }
    })
}

/// The type's constants: `N`, `JOINTS`, `FRAMES`, the joints' limits, a free-floating base's
/// `NQ` and `NV`, `OP_COUNTS` and `CANDIDATES`.
fn type_consts(plan: &Plan, float: Float, fmas: &[u64], op_ty: &syn::Ident) -> TokenStream {
    let model = &plan.model;
    let coordinates = model.coordinates();
    let n = coordinates.len();
    let nl = Literal::usize_unsuffixed(n);
    let joint_names = coordinates.iter().map(|&j| model.joints()[j].name.as_str());
    let frame_names = model.frames().iter().map(|f| f.name.as_str());
    let n_frames = Literal::usize_unsuffixed(model.frames().len());
    let (usize, name) = (paths::primitive("usize"), paths::static_str());
    let floating_consts = if plan.floating() {
        let (nq, nv) = (
            Literal::usize_unsuffixed(n + 7),
            Literal::usize_unsuffixed(n + 6),
        );
        quote! {
            /// Length of `q`: base position (3), quaternion `[x, y, z, w]` (4), joints.
            pub const NQ: #usize = #nq;
            /// Length of `v`: base linear and angular velocity (base frame), joint rates.
            pub const NV: #usize = #nv;
        }
    } else {
        quote!()
    };
    let limits: Vec<kanegen_model::Limits> =
        coordinates.iter().map(|&j| model.limits()[j]).collect();
    let limits = limit_consts(&limits, float);
    let n_fns = Literal::usize_unsuffixed(plan.functions.len());
    let (emitted, all) = op_count_entries(plan, fmas, op_ty);
    quote! {
        /// Degrees of freedom.
        pub const N: #usize = #nl;
        /// Joint names, in the order of the joint entries of `q` (a mimic joint follows its
        /// primary and has no entry).
        pub const JOINTS: [#name; #nl] = [#(#joint_names),*];
        /// Named frames, in the model's order (one `<frame>_…` function family each).
        pub const FRAMES: [#name; #n_frames] = [#(#frame_names),*];
        #limits
        #floating_consts
        /// Emitted operation counts of each generated function, in emission order.
        pub const OP_COUNTS: [#op_ty; #n_fns] = [#(#emitted),*];
        /// Emitted operation counts of every candidate traced (the cheapest is emitted).
        pub const CANDIDATES: &'static [#op_ty] = &[#(#all),*];
    }
}

/// The joints' limits as the model file gives them (a URDF's `<limit>`), in the order of
/// `JOINTS`, named as Pinocchio's `lowerPositionLimit`, `upperPositionLimit`, `velocityLimit`
/// and `effortLimit`; a limit the file does not give is `-∞` (lower) or `+∞`.
fn limit_consts(limits: &[kanegen_model::Limits], float: Float) -> TokenStream {
    let ty = float.ty();
    let n = Literal::usize_unsuffixed(limits.len());
    let column = |pick: fn(&kanegen_model::Limits) -> Option<f64>, absent: TokenStream| {
        let entries = limits.iter().map(|l| match pick(l) {
            Some(x) => {
                let x = float.suffixed(x);
                quote!(#x)
            }
            None => absent.clone(),
        });
        quote!([#(#entries),*])
    };
    let lower = column(|l| l.lower, quote!(#ty::NEG_INFINITY));
    let upper = column(|l| l.upper, quote!(#ty::INFINITY));
    let velocity = column(|l| l.velocity, quote!(#ty::INFINITY));
    let effort = column(|l| l.effort, quote!(#ty::INFINITY));
    quote! {
        /// Lowest joint positions (rad or m; `-∞` where the model gives none), in the order of `JOINTS`.
        pub const LOWER_POSITION_LIMIT: [#ty; #n] = #lower;
        /// Highest joint positions (rad or m; `+∞` where the model gives none).
        pub const UPPER_POSITION_LIMIT: [#ty; #n] = #upper;
        /// Largest joint speeds (rad/s or m/s; `+∞` where the model gives none).
        pub const VELOCITY_LIMIT: [#ty; #n] = #velocity;
        /// Largest drive torques or forces (N·m or N; `+∞` where the model gives none).
        pub const EFFORT_LIMIT: [#ty; #n] = #effort;
    }
}

/// The helpers after the functions: the type's own sine–cosine where a function takes one, and
/// the compact form's tables and loops.
fn helper_items(plan: &Plan, opts: &Options) -> Result<TokenStream, Error> {
    let compact = plan.has_loops();
    let compact_items = if compact {
        compact::items(&plan.model, opts)?
    } else {
        quote!()
    };
    // The type's own sine–cosine, where a function takes one (its products fused where the
    // functions' are).
    let sincos_item = opts.table_sincos() && (compact || choose::takes_trig(plan.choices()));
    let target_mul_add = !opts.fma && opts.target_fma;
    let sincos_item = if sincos_item {
        sincos::item(&opts.runtime()?, target_mul_add)
    } else {
        quote!()
    };
    Ok(quote! {
        #sincos_item

        #compact_items
    })
}

/// The payload struct (the last body's mass properties) and its nominal value.
fn payload_struct(model: &Model, opts: &Options, payload_ty: &syn::Ident) -> TokenStream {
    let fl = opts.float.ty();
    let last = model
        .joints()
        .last()
        .expect("a model has at least one joint");
    let doc = format!(
        " Mass properties of the payload, the last body (`{}`, moved by joint `{}`): mass (kg), \
         centre of mass in the body frame (m) and inertia about the centre of mass in body \
         axes (kg·m²; only the upper triangle is read).",
        header::doc_safe(&last.body),
        header::doc_safe(&last.name)
    );
    let lit = |x: f64| opts.float.suffixed(x);
    let m = lit(last.inertial.mass);
    let com = last.inertial.com.map(lit);
    let rows3 = last.inertial.inertia.iter().map(|r| {
        let r = r.map(lit);
        quote!([#(#r),*])
    });
    quote! {
        #[doc = #doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct #payload_ty {
            /// Mass, kg.
            pub mass: #fl,
            /// Centre of mass in the body frame, m.
            pub com: [#fl; 3],
            /// Inertia tensor about the centre of mass, body axes, kg·m².
            pub inertia: [[#fl; 3]; 3],
        }

        impl #payload_ty {
            /// The payload of the model file.
            pub const NOMINAL: #payload_ty = #payload_ty {
                mass: #m,
                com: [#(#com),*],
                inertia: [#(#rows3),*],
            };
        }
    }
}

/// A formatted module file for `model`: the doc header as inner doc comments, then the items.
///
/// # Errors
/// As [`generate_items`].
pub fn generate_file(model: &Model, opts: &Options) -> Result<String, Error> {
    let mut bodies = Vec::new();
    let g = generate_items_with(model, opts, false, Some(&mut bodies))?;
    let docs = g.header.iter().map(|l| {
        let l = if l.is_empty() {
            String::new()
        } else {
            format!(" {l}")
        };
        quote!(#![doc = #l])
    });
    let items = g.items;
    let file = quote! {
        #(#docs)*
        #items
    };
    let parsed: syn::File =
        syn::parse2(file).map_err(|e| Error(format!("generated code does not parse: {e}")))?;
    let skeleton = prettyplease::unparse(&parsed);
    drop(parsed);
    // Splice each body (formatted at the same indentation) in place of its placeholder line.
    let mut out =
        String::with_capacity(skeleton.len() + bodies.iter().map(String::len).sum::<usize>());
    let mut next = 0;
    for line in skeleton.split_inclusive('\n') {
        let placeholder = format!("        __kanegen_body_{next}()\n");
        if next < bodies.len() && line == placeholder {
            out.push_str(&bodies[next]);
            bodies[next] = String::new();
            next += 1;
        } else {
            out.push_str(line);
        }
    }
    if next != bodies.len() {
        return Err(Error(format!(
            "generated code: {} of {} function bodies placed",
            next,
            bodies.len()
        )));
    }
    Ok(out)
}

/// Statements (or a result expression) of a function body as prettyplease formats them inside a
/// method of an `impl` block (eight spaces of indentation): formatted alone, inside the same
/// nesting, they come out as they would in the whole file, without ever holding the whole
/// file's syntax tree (5 GB at N = 200).
fn format_body(tokens: &TokenStream) -> Result<String, Error> {
    let wrapped = quote!(impl W { fn f() { #tokens } });
    let parsed: syn::File =
        syn::parse2(wrapped).map_err(|e| Error(format!("generated code does not parse: {e}")))?;
    let text = prettyplease::unparse(&parsed);
    let mut lines = text.split_inclusive('\n');
    let (open, close) = (lines.next(), lines.next());
    debug_assert_eq!(open, Some("impl W {\n"));
    debug_assert_eq!(close, Some("    fn f() {\n"));
    let body: Vec<&str> = lines.collect();
    let end = body.len().saturating_sub(2);
    debug_assert_eq!(&body[end..], ["    }\n", "}\n"]);
    Ok(body[..end].concat())
}

/// The dynamics crate, re-exported for the proc-macro (`scene!`: wrench frames, the base body).
pub use kanegen_dynamics;
/// The model crate, re-exported for the proc-macro (readers, validation).
pub use kanegen_model;

#[cfg(test)]
mod tests {
    use super::*;
    use kanegen_model::random::{random_chain, ChainSpec};
    use std::collections::HashMap;
    use syn::visit::Visit;

    /// Binary `*`, `/`, `+`, `-` and libm calls in a function body.
    #[derive(Default)]
    struct OpCounter {
        mul: u64,
        add: u64,
        div: u64,
        sqrt: u64,
        sincos: u64,
        fma: u64,
    }

    impl<'a> Visit<'a> for OpCounter {
        fn visit_expr_binary(&mut self, e: &'a syn::ExprBinary) {
            match e.op {
                syn::BinOp::Mul(_) => self.mul += 1,
                syn::BinOp::Div(_) => self.div += 1,
                syn::BinOp::Add(_) | syn::BinOp::Sub(_) => self.add += 1,
                _ => {}
            }
            syn::visit::visit_expr_binary(self, e);
        }
        fn visit_expr_call(&mut self, e: &'a syn::ExprCall) {
            let name = match &*e.func {
                syn::Expr::Path(p) => p.path.segments.last().map(|s| s.ident.to_string()),
                _ => None,
            };
            match name.as_deref() {
                Some("sqrt" | "sqrtf") => self.sqrt += 1,
                Some("sincos" | "sincosf" | "sin" | "sinf" | "cos" | "cosf") => self.sincos += 1,
                // One angle per element of its array.
                Some("sincos_n" | "sincos_n_unfused") => {
                    if let Some(syn::Expr::Array(a)) = e.args.first() {
                        self.sincos += a.elems.len() as u64;
                    }
                }
                Some("fma" | "fmaf" | "mul_add" | "fma_with") => {
                    self.fma += 1;
                    self.mul += 1;
                    self.add += 1;
                }
                _ => {}
            }
            syn::visit::visit_expr_call(self, e);
        }
    }

    /// The operations of every generated function: `name → counts`.
    fn count_ops(items: TokenStream) -> HashMap<String, OpCounter> {
        let file: syn::File = syn::parse2(items).unwrap();
        let mut fns = HashMap::new();
        for item in &file.items {
            if let syn::Item::Impl(imp) = item {
                for it in &imp.items {
                    // `mul_add` is the private fused-multiply-add helper, not a dynamics function.
                    match it {
                        syn::ImplItem::Fn(f) if f.sig.ident != "mul_add" => {
                            let mut c = OpCounter::default();
                            c.visit_block(&f.block);
                            fns.insert(f.sig.ident.to_string(), c);
                        }
                        _ => {}
                    }
                }
            }
        }
        fns
    }

    /// How a variant fuses products: not at all, through libm's `fma`, or through the
    /// target-feature `S::mul_add`.
    #[derive(Clone, Copy, PartialEq, Eq)]
    enum Fuse {
        None,
        Libm,
        Target,
    }

    /// The emitted code performs exactly the trace's emitted operation counts, function by
    /// function, for random chains with prismatic joints, gravity and a runtime payload, in
    /// every precision (an fma counts as one mul and one add).
    #[test]
    fn emitted_code_has_the_traced_op_counts() {
        let variants = [
            (1, 3, false, Float::F64, Fuse::None),
            (2, 5, true, Float::F64, Fuse::None),
            (3, 7, false, Float::F64, Fuse::Target),
            (2, 5, true, Float::F32, Fuse::Target),
            (3, 7, false, Float::F64, Fuse::Libm),
            (2, 5, true, Float::F32, Fuse::Libm),
        ];
        for (seed, n, payload, float, fuse) in variants {
            let chain = random_chain(
                &ChainSpec {
                    n,
                    prismatic_fraction: 0.3,
                    ..Default::default()
                },
                seed,
            );
            let mut opts = Options::new("Arm");
            opts.gravity = Some([0.1, 0.2, -9.81]);
            opts.runtime_payload = payload;
            opts.float = float;
            opts.fma = fuse == Fuse::Libm;
            opts.target_fma = fuse == Fuse::Target;
            opts.form = Form::Unrolled;
            let g = generate_items(&chain, &opts).unwrap();
            let all = count_ops(g.items);
            // Each function is its `_lanes` body at `S = F`: a call, no operation of its own.
            let mut fns = HashMap::new();
            for (name, c) in all {
                if let Some(f) = name.strip_suffix("_lanes") {
                    fns.insert(f.to_string(), c);
                } else if !name.starts_with("sincos") {
                    // The helpers `Self::sincos` and `Self::sincos_n` are not generated
                    // functions.
                    assert_eq!(
                        (c.mul, c.add, c.div, c.sqrt, c.sincos, c.fma),
                        (0, 0, 0, 0, 0, 0),
                        "{name}"
                    );
                }
            }
            assert_eq!(
                fns.len(),
                10,
                "all functions, gravity and derivatives included"
            );
            if fuse != Fuse::None {
                assert!(fns.values().all(|c| c.fma > 0), "every function fuses");
            } else {
                assert!(fns.values().all(|c| c.fma == 0));
            }
            for ch in &g.choices {
                let want = ch.counts();
                let have = &fns[ch.function.name()];
                assert_eq!(
                    (have.mul, have.add, have.div, have.sqrt, have.sincos),
                    (want.mul, want.add, want.div, want.sqrt, want.sincos),
                    "{} (N = {n})",
                    ch.function.name()
                );
                let best = ch.candidates.iter().map(|c| c.counts.total()).min();
                assert_eq!(Some(want.total()), best);
            }
        }
    }

    #[test]
    fn bad_options_are_errors() {
        let chain = random_chain(&ChainSpec::default(), 1);
        assert!(generate_items(&chain, &Options::new("not an ident")).is_err());
        let mut o = Options::new("Arm");
        o.libm_path = "::".into();
        assert!(generate_items(&chain, &o).is_err());
        let mut o = Options::new("Arm");
        o.fma = true;
        o.fma_path = Some("f64::".into());
        assert!(generate_items(&chain, &o).is_err());
        // Not used without fma.
        o.fma = false;
        assert!(generate_items(&chain, &o).is_ok());
    }

    /// Two declared items of one name, or a declared name that would shadow a path the code
    /// calls, is one error naming the clash; the payload's name is free without a payload struct,
    /// and a path from the crate root cannot be shadowed.
    #[test]
    fn clashing_names_are_one_error() {
        let chain = random_chain(&ChainSpec::default(), 1);
        let err = |o: &Options| check_names(o).err().map(|e| e.0);
        let mut o = Options::new("OpCount");
        let clash = "the generated type and its op-count struct are both called `OpCount`: give \
                     the type another name";
        assert_eq!(err(&o).as_deref(), Some(clash));
        assert_eq!(
            generate_items(&chain, &o).err().map(|e| e.0).as_deref(),
            Some(clash)
        );
        o.type_name = "Payload".into();
        assert_eq!(err(&o), None);
        o.runtime_payload = true;
        assert_eq!(
            err(&o).as_deref(),
            Some(
                "the generated type and its payload struct are both called `Payload`: give the \
                 type another name"
            )
        );
        o.type_name = "Arm".into();
        o.op_count_name = "Payload".into();
        assert_eq!(
            err(&o).as_deref(),
            Some(
                "its op-count struct and its payload struct are both called `Payload`: rename \
                 one of them"
            )
        );
        let mut o = Options::new("libm");
        assert_eq!(
            err(&o).as_deref(),
            Some(
                "the generated type is called `libm`, which would shadow the first segment of \
                 the libm path `libm` the generated code calls: give the type another name"
            )
        );
        o.libm_path = "::libm".into();
        assert_eq!(err(&o), None);
        o.type_name = "kanegen_runtime".into();
        assert!(err(&o).is_some_and(|e| e.contains("the runtime path `kanegen_runtime`")));
        let mut o = Options::new("f64");
        o.fma_path = Some("f64::mul_add".into());
        assert_eq!(err(&o), None, "the fma path is not called without fma");
        o.fma = true;
        assert!(err(&o).is_some_and(|e| e.contains("the fma path `f64::mul_add`")));
    }

    /// The f32 code names no f64 anywhere; the fma code calls the fma path and says how many it
    /// formed; the defaults have neither the precision lines nor `FMA_COUNTS`.
    #[test]
    fn precision_variants_in_the_source() {
        let chain = random_chain(
            &ChainSpec {
                n: 4,
                prismatic_fraction: 0.3,
                ..Default::default()
            },
            7,
        );
        let mut o = Options::new("Arm");
        o.runtime_payload = true;
        o.gravity = Some([0.0, 0.0, -9.81]);
        let plain = generate_file(&chain, &o).unwrap();
        assert!(!plain.contains("f32") && !plain.contains("Precision") && !plain.contains("fma("));

        o.float = Float::F32;
        let f32_src = generate_file(&chain, &o).unwrap();
        assert!(!f32_src.contains("f64"), "{f32_src}");
        assert!(f32_src.contains("Precision: `f32`"));
        assert!(
            f32_src.contains("S::sincos(") && f32_src.contains("Lanes<::core::primitive::f32>")
        );
        assert!(f32_src.contains("Fused multiply-adds: none."));

        o.float = Float::F64;
        o.fma = true;
        o.fma_path = Some("f64::mul_add".into());
        let g = generate_items(&chain, &o).unwrap();
        let fma_src = generate_file(&chain, &o).unwrap();
        let calls = fma_src
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .map(|l| l.matches("f64::mul_add").count() as u64)
            .sum::<u64>();
        let total: u64 = count_ops(g.items.clone()).values().map(|c| c.fma).sum();
        assert!(calls > 0);
        assert_eq!(calls, total);
        assert!(fma_src.contains(&format!("Fused multiply-adds: {total} (")));
        // OP_COUNTS carries the same per-function fma counts.
        assert_eq!(g.fmas.iter().sum::<u64>(), total);
        for k in &g.fmas {
            assert!(fma_src.contains(&format!("fma: {k}u64")), "{k}");
        }
    }
}
