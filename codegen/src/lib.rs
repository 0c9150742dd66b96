//! # kanegen-codegen
//!
//! Unrolled, allocation-free Rust emitted from simplified [`Sym`] graphs, for one fixed chain.
//!
//! For every generated function ([`FUNCTIONS`]), every algorithm of [`Algorithm::ALL`] is traced
//! on [`Sym`] with the model's numbers as constants; the trace with the fewest emitted
//! operations (`mul + add`, [`Convention::Emitted`]) wins and is emitted:
//!
//! * one `let` per shared subexpression (a node used more than once), per expensive node
//!   (division, square root, sine/cosine) and per output; single-use nodes are inlined into their
//!   user's expression with the parentheses that keep the graph's evaluation order, so the
//!   emitted code performs exactly the emitted operation count of the trace;
//! * sine and cosine of one argument come from one `libm::sincos` call (the path of the `libm`
//!   crate is an [`Options::libm_path`]), square roots from `libm::sqrt`: the code is `no_std`;
//! * inputs are fixed-size arrays `&[f64; N]` (`q`, `qd`, `tau`, `qdd`) indexed by constants, and
//!   with [`Options::runtime_payload`] a `payload: &Payload` (last argument);
//! * outputs are `[[f64; N]; N]` (the symmetric `A`: upper triangle computed, both written) or
//!   `[f64; N]`;
//! * with [`Options::float`] = [`Float::F32`] every type is `f32` instead, the constants are the
//!   model's numbers rounded to `f32` and the libm calls are the `f32` ones (`sincosf`, `sqrtf`);
//! * with [`Options::fma`] an addition or subtraction of a single-use product becomes one fused
//!   multiply-add `fma(a, b, c)` = `a·b + c` ([`Options::fma_path`]), which still counts as one
//!   multiplication and one addition.
//!
//! The output is a unit struct with associated constants and functions ([`generate_items`]);
//! [`generate_file`] wraps it into a formatted module file with a doc header (model, N, joints,
//! chosen algorithm per function, the op counts of every candidate, generator version).
#![warn(missing_docs)]

use kanegen_core::linalg::{Mat3, Vec3};
use kanegen_core::sym::{Convention, Counts, Node, Sym, Trace, Tracer};
use kanegen_core::{Algorithm, Chain, JointKind, Loads, Scalar};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::collections::{HashMap, HashSet};

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
    /// Make the last body's (the payload's) mass, centre of mass and inertia runtime inputs: every
    /// function then takes a last argument `payload: &Payload`.
    pub runtime_payload: bool,
    /// Path of the `libm` crate in the generated code: `libm` for a crate depending on `libm`,
    /// `::kanegen::__private::libm` for the output of the `dynamics!` macro.
    pub libm_path: String,
    /// Name of the generated payload struct (used with [`Options::runtime_payload`]).
    pub payload_name: String,
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

    fn ty(self) -> TokenStream {
        let t = format_ident!("{}", self.name());
        quote!(#t)
    }

    /// The libm function `base` for this type: `sin` or `sinf`.
    fn libm_fn(self, base: &str) -> proc_macro2::Ident {
        match self {
            Float::F64 => format_ident!("{}", base),
            Float::F32 => format_ident!("{}f", base),
        }
    }

    /// A literal of this type with the value `x` (rounded for `f32`), suffixed like `quote!`
    /// suffixes an `f64`.
    fn suffixed(self, x: f64) -> Literal {
        match self {
            Float::F64 => Literal::f64_suffixed(x),
            Float::F32 => Literal::f32_suffixed(x as f32),
        }
    }
}

impl Options {
    /// Defaults: space (no gravity), constant payload, `libm` path `libm`, payload struct
    /// `Payload`, `f64`, no fused multiply-adds.
    pub fn new(type_name: impl Into<String>) -> Self {
        Options {
            type_name: type_name.into(),
            gravity: None,
            runtime_payload: false,
            libm_path: "libm".into(),
            payload_name: "Payload".into(),
            float: Float::F64,
            fma: false,
            fma_path: None,
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

/// An argument of a generated function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arg {
    /// Joint positions `q` (rad or m).
    Q,
    /// Joint velocities `q̇`.
    Qd,
    /// Joint drives `τ` (N·m or N).
    Tau,
    /// Joint accelerations `q̈`.
    Qdd,
}

impl Arg {
    /// The argument's name in generated code.
    pub fn name(self) -> &'static str {
        match self {
            Arg::Q => "q",
            Arg::Qd => "qd",
            Arg::Tau => "tau",
            Arg::Qdd => "qdd",
        }
    }
}

/// A generated function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Function {
    /// Its name.
    pub name: &'static str,
    /// Its arguments, in order (then `payload` with [`Options::runtime_payload`]).
    pub args: &'static [Arg],
    /// Whether it returns the symmetric `N×N` matrix (else an `N`-vector).
    pub matrix: bool,
    /// Only generated when the model has gravity.
    pub needs_gravity: bool,
    /// Its documentation (first line).
    pub doc: &'static str,
}

/// The generated functions, in emission order.
pub const FUNCTIONS: [Function; 6] = [
    Function {
        name: "mass_matrix",
        args: &[Arg::Q],
        matrix: true,
        needs_gravity: false,
        doc: "The generalized inertia matrix `A(q)` (symmetric, both triangles written).",
    },
    Function {
        name: "bias",
        args: &[Arg::Q, Arg::Qd, Arg::Tau],
        matrix: false,
        needs_gravity: false,
        doc:
            "The generalized forces `b = Q − h` of `A q̈ = b`: joint drives `tau` (and gravity when \
              the model has it) minus the velocity-product terms.",
    },
    Function {
        name: "bias_velocity",
        args: &[Arg::Q, Arg::Qd],
        matrix: false,
        needs_gravity: false,
        doc: "The velocity part of `b` only: `−h(q, q̇)` (no drives, no gravity).",
    },
    Function {
        name: "gravity",
        args: &[Arg::Q],
        matrix: false,
        needs_gravity: true,
        doc: "The generalized gravity force only (the gravity part of `Q`).",
    },
    Function {
        name: "inverse_dynamics",
        args: &[Arg::Q, Arg::Qd, Arg::Qdd],
        matrix: false,
        needs_gravity: false,
        doc: "Inverse dynamics: the drives `τ = A q̈ − b(q, q̇, τ = 0)`.",
    },
    Function {
        name: "forward_dynamics",
        args: &[Arg::Q, Arg::Qd, Arg::Tau],
        matrix: false,
        needs_gravity: false,
        doc: "Forward dynamics `q̈ = A⁻¹ b(q, q̇, τ)`, by an unrolled branch-free LDLᵀ.",
    },
];

/// The functions generated for the given options.
pub fn functions(opts: &Options) -> impl Iterator<Item = &'static Function> + '_ {
    FUNCTIONS
        .iter()
        .filter(move |f| !f.needs_gravity || opts.gravity.is_some())
}

/// A traced function: the trace and, per trace input, the Rust expression that reads it.
pub struct Traced {
    /// The frozen graph; outputs are the upper triangle (row-major) for matrices.
    pub trace: Trace,
    /// `inputs[i]` reads input `i` (e.g. `q[3]`, `payload.com[0]`).
    pub inputs: Vec<TokenStream>,
}

/// Traces `f` of `alg` for `chain` under `opts`.
#[allow(clippy::needless_range_loop)] // the symmetric fill reads best with indices
pub fn trace_function(chain: &Chain, f: &Function, alg: Algorithm, opts: &Options) -> Traced {
    let n = chain.dof();
    let t = Tracer::new();
    let mut inputs: Vec<TokenStream> = Vec::new();
    let mut input = |tokens: TokenStream| {
        let name = tokens.to_string().replace(' ', "");
        inputs.push(tokens);
        t.input(name)
    };
    let mut p = chain.params::<Sym>();
    if opts.runtime_payload {
        let last = p.joints.last_mut().expect("a chain has at least one joint");
        last.mass = input(quote!(payload.mass));
        let com: [Sym; 3] = core::array::from_fn(|k| {
            let k = Literal::usize_unsuffixed(k);
            input(quote!(payload.com[#k]))
        });
        last.com = Vec3(com);
        // Upper triangle read, mirrored: the tensor is symmetric.
        let mut i = [[Sym::zero(); 3]; 3];
        for r in 0..3 {
            for c in r..3 {
                let (lr, lc) = (Literal::usize_unsuffixed(r), Literal::usize_unsuffixed(c));
                let s = input(quote!(payload.inertia[#lr][#lc]));
                i[r][c] = s;
                i[c][r] = s;
            }
        }
        last.inertia_com = Mat3(i);
    }
    let mut vecs: HashMap<&str, Vec<Sym>> = HashMap::new();
    for a in f.args {
        let name = format_ident!("{}", a.name());
        let v: Vec<Sym> = (0..n)
            .map(|i| {
                let i = Literal::usize_unsuffixed(i);
                input(quote!(#name[#i]))
            })
            .collect();
        vecs.insert(a.name(), v);
    }
    let gravity = opts.gravity.map(Vec3::from_f64);
    let q = &vecs["q"];
    let out: Vec<Sym> = match f.name {
        "mass_matrix" => {
            let a = alg.mass_matrix(&p, q);
            a.iter()
                .enumerate()
                .flat_map(|(i, r)| r[i..].to_vec())
                .collect()
        }
        "bias" => {
            let loads = Loads {
                tau: Some(vecs["tau"].clone()),
                gravity,
                external: Vec::new(),
            };
            alg.bias(&p, q, &vecs["qd"], &loads)
        }
        "bias_velocity" => alg.bias(&p, q, &vecs["qd"], &Loads::default()),
        "gravity" => {
            let zeros = vec![Sym::zero(); n];
            let loads = Loads {
                tau: None,
                gravity,
                external: Vec::new(),
            };
            alg.bias(&p, q, &zeros, &loads)
        }
        "inverse_dynamics" => {
            let loads = Loads {
                tau: None,
                gravity,
                external: Vec::new(),
            };
            alg.inverse_dynamics(&p, q, &vecs["qd"], &vecs["qdd"], &loads)
        }
        "forward_dynamics" => {
            let loads = Loads {
                tau: Some(vecs["tau"].clone()),
                gravity,
                external: Vec::new(),
            };
            alg.forward_dynamics(&p, q, &vecs["qd"], &loads)
        }
        other => unreachable!("unknown generated function {other}"),
    };
    let trace = t.finish(&out);
    Traced { trace, inputs }
}

/// The emitted counts of every candidate algorithm for one function, and the winner.
#[derive(Clone, Debug)]
pub struct Choice {
    /// The function.
    pub function: &'static Function,
    /// `(algorithm, emitted counts)` for every algorithm of [`Algorithm::ALL`].
    pub candidates: Vec<(Algorithm, Counts)>,
    /// The algorithm with the fewest emitted `mul + add` (the first in [`Algorithm::ALL`] order
    /// on ties).
    pub chosen: Algorithm,
}

impl Choice {
    /// Emitted counts of the chosen algorithm.
    pub fn counts(&self) -> Counts {
        self.candidates
            .iter()
            .find(|(a, _)| *a == self.chosen)
            .map(|(_, c)| *c)
            .unwrap_or_default()
    }
}

/// Traces every algorithm for `f` and keeps the cheapest.
pub fn choose(chain: &Chain, f: &'static Function, opts: &Options) -> (Choice, Traced) {
    let mut best: Option<(u64, Algorithm, Traced)> = None;
    let mut candidates = Vec::new();
    for alg in Algorithm::ALL {
        let t = trace_function(chain, f, alg, opts);
        let c = t.trace.counts(Convention::Emitted);
        candidates.push((alg, c));
        let better = match &best {
            None => true,
            Some((b, _, _)) => c.total() < *b,
        };
        if better {
            best = Some((c.total(), alg, t));
        }
    }
    let (_, chosen, traced) = best.expect("Algorithm::ALL is not empty");
    (
        Choice {
            function: f,
            candidates,
            chosen,
        },
        traced,
    )
}

// ---------------------------------------------------------------------------------------------
// Emission of one graph.

/// Operator precedence of an emitted expression (higher binds tighter).
const P_ADD: u8 = 1;
const P_MUL: u8 = 2;
const P_NEG: u8 = 3;
const P_ATOM: u8 = 4;

#[derive(Clone)]
struct Expr {
    tokens: TokenStream,
    prec: u8,
}

impl Expr {
    fn atom(tokens: TokenStream) -> Self {
        Expr {
            tokens,
            prec: P_ATOM,
        }
    }
    /// The expression, parenthesized unless it binds at least as tightly as `min`.
    fn at(&self, min: u8) -> TokenStream {
        let t = &self.tokens;
        if self.prec >= min {
            t.clone()
        } else {
            quote!((#t))
        }
    }
}

/// A constant of type `float`: the f64 value, rounded for `f32`.
fn constant(x: f64, float: Float) -> Expr {
    let ty = float.ty();
    let x = match float {
        Float::F64 => x,
        Float::F32 => f64::from(x as f32),
    };
    if x.is_nan() {
        return Expr::atom(quote!(#ty::NAN));
    }
    if x.is_infinite() {
        return if x > 0.0 {
            Expr::atom(quote!(#ty::INFINITY))
        } else {
            Expr::atom(quote!(#ty::NEG_INFINITY))
        };
    }
    let lit = match float {
        Float::F64 => Literal::f64_unsuffixed(x.abs()),
        Float::F32 => Literal::f32_unsuffixed((x as f32).abs()),
    };
    if x.is_sign_negative() && x != 0.0 {
        Expr {
            tokens: quote!(-#lit),
            prec: P_NEG,
        }
    } else {
        Expr::atom(quote!(#lit))
    }
}

/// How one graph is emitted: the libm path, the floating-point type and the fused multiply-add
/// function (none: no fusion). Built from [`Options`] by [`Emitter::new`].
#[derive(Clone, Debug)]
pub struct Emitter {
    libm: TokenStream,
    float: Float,
    fma: Option<TokenStream>,
}

impl Emitter {
    /// The emitter of `opts`.
    ///
    /// # Errors
    /// If [`Options::libm_path`] or [`Options::fma_path`] is not a Rust path.
    pub fn new(opts: &Options) -> Result<Self, Error> {
        let libm: syn::Path = syn::parse_str(&opts.libm_path)
            .map_err(|e| Error(format!("libm path `{}`: {e}", opts.libm_path)))?;
        let libm = quote!(#libm);
        let fma = if opts.fma {
            Some(match &opts.fma_path {
                Some(p) => {
                    let path: syn::Path =
                        syn::parse_str(p).map_err(|e| Error(format!("fma path `{p}`: {e}")))?;
                    quote!(#path)
                }
                None => {
                    let f = opts.float.libm_fn("fma");
                    quote!(#libm::#f)
                }
            })
        } else {
            None
        };
        Ok(Emitter {
            libm,
            float: opts.float,
            fma,
        })
    }
}

/// The emitted body of one function.
pub struct Body {
    /// The statements and the result expression.
    pub tokens: TokenStream,
    /// Fused multiply-adds formed (0 without [`Options::fma`]).
    pub fmas: u64,
}

/// The statements and result expression of one traced function. `matrix`: the outputs are the
/// upper triangle of a symmetric `n×n` matrix.
pub fn emit_body(t: &Traced, emitter: &Emitter, matrix: bool, n: usize) -> Body {
    let Emitter { libm, float, fma } = emitter;
    let float = *float;
    let trace = &t.trace;
    let sched = trace.schedule();
    let outputs: HashSet<u32> = trace.outputs().iter().map(|s| s.id()).collect();
    let nodes: HashMap<u32, Node> = sched.iter().copied().collect();
    let mut uses: HashMap<u32, usize> = HashMap::new();
    // Sine and cosine nodes per argument.
    let mut trig: HashMap<u32, (Option<u32>, Option<u32>)> = HashMap::new();
    for (id, node) in &sched {
        match *node {
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => {
                *uses.entry(a.id()).or_default() += 1;
                *uses.entry(b.id()).or_default() += 1;
            }
            Node::Neg(a) | Node::Sqrt(a) => *uses.entry(a.id()).or_default() += 1,
            Node::Sin(a) => {
                *uses.entry(a.id()).or_default() += 1;
                trig.entry(a.id()).or_default().0 = Some(*id);
            }
            Node::Cos(a) => {
                *uses.entry(a.id()).or_default() += 1;
                trig.entry(a.id()).or_default().1 = Some(*id);
            }
            Node::Const(_) | Node::Input(_) => {}
        }
    }
    // Inlined (single-use, not an output): its expression appears once, in its user's.
    let inlined = |s: Sym| !outputs.contains(&s.id()) && uses.get(&s.id()).copied() == Some(1);
    // The factors of a product that fuses into its user: an inlined multiplication.
    let product = |s: Sym| match nodes.get(&s.id()) {
        Some(Node::Mul(a, b)) if fma.is_some() && inlined(s) => Some((*a, *b)),
        _ => None,
    };
    let is_const = |s: Sym| matches!(nodes.get(&s.id()), Some(Node::Const(_)));
    let mut exprs: HashMap<u32, Expr> = HashMap::new();
    let mut stmts: Vec<TokenStream> = Vec::new();
    let mut counter = 0usize;
    let mut fmas = 0u64;
    // A readable name for the sine/cosine of an argument: `s_q0` for `q[0]`.
    let trig_base = |arg: u32, counter: usize| -> String {
        match nodes[&arg] {
            Node::Input(i) => t.inputs[i as usize]
                .to_string()
                .chars()
                .filter(char::is_ascii_alphanumeric)
                .collect(),
            _ => format!("{counter}"),
        }
    };
    for (id, node) in &sched {
        let id = *id;
        let get = |s: Sym| exprs[&s.id()].clone();
        // `−s` as a call argument: constants negated, an inlined negation unwrapped.
        let neg = |s: Sym| -> TokenStream {
            match nodes.get(&s.id()) {
                Some(Node::Const(x)) => constant(-x, float).tokens,
                Some(Node::Neg(z)) if inlined(s) => get(*z).tokens,
                _ => {
                    let e = get(s).at(P_NEG);
                    quote!(-#e)
                }
            }
        };
        let call = |a: TokenStream, b: TokenStream, c: TokenStream| {
            let f = fma
                .as_ref()
                .expect("products fuse only with an fma function");
            Expr::atom(quote!(#f(#a, #b, #c)))
        };
        let expr = match node {
            Node::Const(x) => {
                exprs.insert(id, constant(*x, float));
                continue;
            }
            Node::Input(i) => {
                exprs.insert(id, Expr::atom(t.inputs[*i as usize].clone()));
                continue;
            }
            Node::Sin(a) | Node::Cos(a) => {
                if exprs.contains_key(&id) {
                    continue; // bound together with its partner by one sincos
                }
                let arg = get(*a).tokens;
                let base = trig_base(a.id(), counter);
                counter += 1;
                match trig[&a.id()] {
                    (Some(s), Some(c)) => {
                        let (sn, cn) = (format_ident!("s_{}", base), format_ident!("c_{}", base));
                        let f = float.libm_fn("sincos");
                        stmts.push(quote!(let (#sn, #cn) = #libm::#f(#arg);));
                        exprs.insert(s, Expr::atom(quote!(#sn)));
                        exprs.insert(c, Expr::atom(quote!(#cn)));
                    }
                    (Some(s), None) => {
                        let sn = format_ident!("s_{}", base);
                        let f = float.libm_fn("sin");
                        stmts.push(quote!(let #sn = #libm::#f(#arg);));
                        exprs.insert(s, Expr::atom(quote!(#sn)));
                    }
                    (None, Some(c)) => {
                        let cn = format_ident!("c_{}", base);
                        let f = float.libm_fn("cos");
                        stmts.push(quote!(let #cn = #libm::#f(#arg);));
                        exprs.insert(c, Expr::atom(quote!(#cn)));
                    }
                    (None, None) => unreachable!("trig node without entry"),
                }
                continue;
            }
            // x + a·b, a·b + x: fma(a, b, x) (the right product first: sums accumulate
            // from the left, so the left operand is the running sum).
            Node::Add(x, y) if product(*y).is_some() || product(*x).is_some() => {
                fmas += 1;
                let (m, c) = if product(*y).is_some() {
                    (*y, *x)
                } else {
                    (*x, *y)
                };
                let (a, b) = product(m).expect("checked");
                call(get(a).tokens, get(b).tokens, get(c).tokens)
            }
            // x − a·b: fma(−a, b, x) (the constant factor negated when there is one).
            Node::Sub(x, y) if product(*y).is_some() => {
                fmas += 1;
                let (a, b) = product(*y).expect("checked");
                if is_const(b) && !is_const(a) {
                    call(get(a).tokens, neg(b), get(*x).tokens)
                } else {
                    call(neg(a), get(b).tokens, get(*x).tokens)
                }
            }
            // a·b − y: fma(a, b, −y).
            Node::Sub(x, y) if product(*x).is_some() => {
                fmas += 1;
                let (a, b) = product(*x).expect("checked");
                call(get(a).tokens, get(b).tokens, neg(*y))
            }
            Node::Add(a, b) => {
                let (a, b) = (get(*a).at(P_ADD), get(*b).at(P_MUL));
                Expr {
                    tokens: quote!(#a + #b),
                    prec: P_ADD,
                }
            }
            Node::Sub(a, b) => {
                let (a, b) = (get(*a).at(P_ADD), get(*b).at(P_MUL));
                Expr {
                    tokens: quote!(#a - #b),
                    prec: P_ADD,
                }
            }
            Node::Mul(a, b) => {
                let (a, b) = (get(*a).at(P_MUL), get(*b).at(P_NEG));
                Expr {
                    tokens: quote!(#a * #b),
                    prec: P_MUL,
                }
            }
            Node::Div(a, b) => {
                let (a, b) = (get(*a).at(P_MUL), get(*b).at(P_NEG));
                Expr {
                    tokens: quote!(#a / #b),
                    prec: P_MUL,
                }
            }
            Node::Neg(a) => {
                let a = get(*a).at(P_NEG);
                Expr {
                    tokens: quote!(-#a),
                    prec: P_NEG,
                }
            }
            Node::Sqrt(a) => {
                let a = get(*a).tokens;
                let f = float.libm_fn("sqrt");
                Expr::atom(quote!(#libm::#f(#a)))
            }
        };
        let bind = outputs.contains(&id)
            || uses.get(&id).copied().unwrap_or(0) > 1
            || matches!(node, Node::Div(..) | Node::Sqrt(..));
        if bind {
            let name = format_ident!("x{}", counter);
            counter += 1;
            let e = expr.tokens;
            stmts.push(quote!(let #name = #e;));
            exprs.insert(id, Expr::atom(quote!(#name)));
        } else {
            exprs.insert(id, expr);
        }
    }
    let out: Vec<TokenStream> = trace
        .outputs()
        .iter()
        .map(|s| exprs[&s.id()].at(P_NEG))
        .collect();
    let result = if matrix {
        // Upper triangle, row-major: index of (i, j), i ≤ j.
        let idx = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
        let rows = (0..n).map(|i| {
            let row = (0..n).map(|j| &out[idx(i.min(j), i.max(j))]);
            quote!([#(#row),*])
        });
        quote!([#(#rows),*])
    } else {
        quote!([#(#out),*])
    };
    Body {
        tokens: quote!(#(#stmts)* #result),
        fmas,
    }
}

// ---------------------------------------------------------------------------------------------
// Whole model.

/// Everything generated for one model.
pub struct Generated {
    /// The items: the unit struct, its `impl`, and the payload struct when asked.
    pub items: TokenStream,
    /// The doc header lines (without comment markers).
    pub header: Vec<String>,
    /// One choice per generated function.
    pub choices: Vec<Choice>,
}

fn joint_list(chain: &Chain) -> String {
    chain
        .joints()
        .iter()
        .map(|j| {
            let k = match j.kind {
                JointKind::Revolute => "revolute",
                JointKind::Prismatic => "prismatic",
            };
            format!("`{}` ({k})", j.name)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Generates the items for `chain`.
///
/// # Errors
/// If an option is not a valid Rust identifier or path.
pub fn generate_items(chain: &Chain, opts: &Options) -> Result<Generated, Error> {
    generate_items_with(chain, opts, true)
}

/// [`generate_items`]; `header_on_struct`: document the struct with the full header (else one
/// line, for files whose module docs carry the header).
fn generate_items_with(
    chain: &Chain,
    opts: &Options,
    header_on_struct: bool,
) -> Result<Generated, Error> {
    let n = chain.dof();
    let nl = Literal::usize_unsuffixed(n);
    let ty: syn::Ident = syn::parse_str(&opts.type_name)
        .map_err(|e| Error(format!("type name `{}`: {e}", opts.type_name)))?;
    let payload_ty: syn::Ident = syn::parse_str(&opts.payload_name)
        .map_err(|e| Error(format!("payload name `{}`: {e}", opts.payload_name)))?;
    let emitter = Emitter::new(opts)?;
    let fl = opts.float.ty();

    let mut fns = Vec::new();
    let mut choices = Vec::new();
    let mut fmas = Vec::new();
    for f in functions(opts) {
        let (choice, traced) = choose(chain, f, opts);
        let Body {
            tokens: body,
            fmas: k,
        } = emit_body(&traced, &emitter, f.matrix, n);
        let name = format_ident!("{}", f.name);
        let args = f.args.iter().map(|a| {
            let a = format_ident!("{}", a.name());
            quote!(#a: &[#fl; #nl])
        });
        let payload_arg = opts
            .runtime_payload
            .then(|| quote!(, payload: &#payload_ty));
        let ret = if f.matrix {
            quote!([[#fl; #nl]; #nl])
        } else {
            quote!([#fl; #nl])
        };
        let c = choice.counts();
        let doc1 = format!(" {}", f.doc);
        let fused = if opts.fma {
            format!(", of which {k} fused multiply-adds")
        } else {
            String::new()
        };
        let doc2 = format!(
            " Algorithm `{}`: {} mul, {} add, {} div, {} sqrt, {} sincos (emitted){fused}.",
            choice.chosen, c.mul, c.add, c.div, c.sqrt, c.sincos
        );
        fmas.push((f.name, k));
        fns.push(quote! {
            #[doc = #doc1]
            #[doc = ""]
            #[doc = #doc2]
            #[must_use]
            pub fn #name(#(#args),* #payload_arg) -> #ret {
                #body
            }
        });
        choices.push(choice);
    }

    let mut rows = Vec::new();
    let mut chosen_rows = Vec::new();
    for ch in &choices {
        let fname = ch.function.name;
        let alg = ch.chosen.name();
        chosen_rows.push(quote!((#fname, #alg)));
        for (a, c) in &ch.candidates {
            let (aname, m, ad) = (a.name(), c.mul, c.add);
            rows.push(quote!((#fname, #aname, #m, #ad)));
        }
    }

    let header = header_lines(chain, opts, &choices, &fmas);
    let short = [format!(
        "Dynamics of `{}` (N = {n}); see the module documentation.",
        chain.name()
    )];
    let struct_header: &[String] = if header_on_struct { &header } else { &short };
    let struct_docs = struct_header.iter().map(|l| {
        let l = format!(" {l}");
        quote!(#[doc = #l])
    });
    let joint_names = chain.joints().iter().map(|j| j.name.as_str());

    let payload_item = if opts.runtime_payload {
        let last = &chain.joints()[n - 1];
        let m = last.inertial.mass;
        let com = last.inertial.com;
        let i = last.inertial.inertia;
        let doc = format!(
            " Mass properties of the payload, the last body (`{}`, moved by joint `{}`): mass (kg), \
             centre of mass in the body frame (m) and inertia about the centre of mass in body \
             axes (kg·m²; only the upper triangle is read).",
            last.body, last.name
        );
        let lit = |x: f64| opts.float.suffixed(x);
        let m = lit(m);
        let com = com.map(lit);
        let rows3 = i.iter().map(|r| {
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
    } else {
        quote!()
    };

    let fma_const = if opts.fma {
        let rows = fmas.iter().map(|(f, k)| quote!((#f, #k)));
        quote! {
            /// Fused multiply-adds in each function: `(function, count)` (each also counts as one
            /// mul and one add in [`Self::OP_COUNTS`]).
            pub const FMA_COUNTS: &'static [(&'static str, u64)] = &[#(#rows),*];
        }
    } else {
        quote!()
    };

    let items = quote! {
        #(#struct_docs)*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        pub struct #ty;

        #payload_item

        #[allow(
            clippy::approx_constant,
            clippy::excessive_precision,
            clippy::unreadable_literal,
            clippy::neg_multiply,
            clippy::too_many_lines,
            clippy::many_single_char_names,
            clippy::similar_names,
            unused_parens
        )]
        impl #ty {
            /// Degrees of freedom.
            pub const N: usize = #nl;
            /// Joint names, from the base.
            pub const JOINTS: [&'static str; #nl] = [#(#joint_names),*];
            /// Emitted operation counts of every candidate algorithm:
            /// `(function, algorithm, mul, add)`.
            pub const OP_COUNTS: &'static [(&'static str, &'static str, u64, u64)] = &[#(#rows),*];
            /// The algorithm emitted for each function: `(function, algorithm)`.
            pub const ALGORITHMS: &'static [(&'static str, &'static str)] = &[#(#chosen_rows),*];
            #fma_const

            #(#fns)*
        }
    };
    Ok(Generated {
        items,
        header,
        choices,
    })
}

fn header_lines(
    chain: &Chain,
    opts: &Options,
    choices: &[Choice],
    fmas: &[(&str, u64)],
) -> Vec<String> {
    let mut h = vec![
        format!(
            "Dynamics of `{}` (N = {}), generated by kanegen-codegen {VERSION}. Do not edit.",
            chain.name(),
            chain.dof()
        ),
        String::new(),
        format!("Joints: {}.", joint_list(chain)),
        String::new(),
        match opts.gravity {
            Some(g) => format!(
                "Gravity: [{}, {}, {}] m/s² in the base frame.",
                g[0], g[1], g[2]
            ),
            None => "Gravity: none (space).".into(),
        },
        if opts.runtime_payload {
            format!(
                "Runtime payload: the last body's mass properties are the argument `payload: &{}`.",
                opts.payload_name
            )
        } else {
            "Runtime payload: no (every model number is a constant).".into()
        },
    ];
    // Precision lines only for a non-default precision: the default f64 header is unchanged.
    if opts.float != Float::F64 || opts.fma {
        h.push(match opts.float {
            Float::F64 => "Precision: `f64`.".into(),
            Float::F32 => "Precision: `f32`: inputs, outputs and every intermediate; the model's \
                           numbers rounded to `f32` constants; libm's `sincosf`, `sinf`, `cosf`, \
                           `sqrtf`."
                .into(),
        });
        h.push(if opts.fma {
            let total: u64 = fmas.iter().map(|(_, k)| k).sum();
            let per = fmas
                .iter()
                .map(|(f, k)| format!("`{f}` {k}"))
                .collect::<Vec<_>>()
                .join(", ");
            let path = opts
                .fma_path
                .clone()
                .unwrap_or_else(|| format!("{}::{}", opts.libm_path, opts.float.libm_fn("fma")));
            format!(
                "Fused multiply-adds: {total} ({per}), each `{path}(a, b, c)` = a·b + c rounded \
                 once; the counts below count each as 1 mul + 1 add."
            )
        } else {
            "Fused multiply-adds: none.".into()
        });
    }
    h.extend([
        String::new(),
        "Emitted operation counts per candidate algorithm (the cheapest in mul + add is emitted, *):"
            .into(),
        String::new(),
        "| function | algorithm | mul | add | div | sqrt | sincos | mul + add |".into(),
        "|---|---|---:|---:|---:|---:|---:|---:|".into(),
    ]);
    for ch in choices {
        for (a, c) in &ch.candidates {
            let star = if *a == ch.chosen { " *" } else { "" };
            h.push(format!(
                "| `{}` | `{}`{star} | {} | {} | {} | {} | {} | {} |",
                ch.function.name,
                a.name(),
                c.mul,
                c.add,
                c.div,
                c.sqrt,
                c.sincos,
                c.total()
            ));
        }
    }
    h
}

/// A formatted module file for `chain`: the doc header as inner doc comments, then the items.
///
/// # Errors
/// As [`generate_items`].
pub fn generate_file(chain: &Chain, opts: &Options) -> Result<String, Error> {
    let g = generate_items_with(chain, opts, false)?;
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
    Ok(prettyplease::unparse(&parsed))
}

/// The core crate, re-exported for the proc-macro (models, readers, validation).
pub use kanegen_core;

#[cfg(test)]
mod tests {
    use super::*;
    use kanegen_core::random::{random_chain, ChainSpec};
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
                Some("fma" | "fmaf" | "mul_add") => {
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
                    if let syn::ImplItem::Fn(f) = it {
                        let mut c = OpCounter::default();
                        c.visit_block(&f.block);
                        fns.insert(f.sig.ident.to_string(), c);
                    }
                }
            }
        }
        fns
    }

    /// The emitted code performs exactly the trace's emitted operation counts, function by
    /// function, for random chains with prismatic joints, gravity and a runtime payload, in
    /// every precision (an fma counts as one mul and one add).
    #[test]
    fn emitted_code_has_the_traced_op_counts() {
        let variants = [
            (1, 3, false, Float::F64, false),
            (2, 5, true, Float::F64, false),
            (3, 7, false, Float::F64, false),
            (2, 5, true, Float::F32, false),
            (3, 7, false, Float::F64, true),
            (2, 5, true, Float::F32, true),
        ];
        for (seed, n, payload, float, fma) in variants {
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
            opts.fma = fma;
            let g = generate_items(&chain, &opts).unwrap();
            let fns = count_ops(g.items);
            assert_eq!(fns.len(), 6, "all functions, gravity included");
            if fma {
                assert!(fns.values().all(|c| c.fma > 0), "every function fuses");
            } else {
                assert!(fns.values().all(|c| c.fma == 0));
            }
            for ch in &g.choices {
                let want = ch.counts();
                let have = &fns[ch.function.name];
                assert_eq!(
                    (have.mul, have.add, have.div, have.sqrt, have.sincos),
                    (want.mul, want.add, want.div, want.sqrt, want.sincos),
                    "{} (N = {n})",
                    ch.function.name
                );
                let best = ch.candidates.iter().map(|(_, c)| c.total()).min();
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
        assert!(!plain.contains("f32") && !plain.contains("Precision") && !plain.contains("fma"));

        o.float = Float::F32;
        let f32_src = generate_file(&chain, &o).unwrap();
        assert!(!f32_src.contains("f64"), "{f32_src}");
        assert!(f32_src.contains("Precision: `f32`"));
        assert!(f32_src.contains("libm::sincosf("));
        assert!(f32_src.contains("Fused multiply-adds: none."));

        o.float = Float::F64;
        o.fma = true;
        o.fma_path = Some("f64::mul_add".into());
        let g = generate_items(&chain, &o).unwrap();
        let fma_src = generate_file(&chain, &o).unwrap();
        let calls = fma_src
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .map(|l| l.matches("f64::mul_add(").count() as u64)
            .sum::<u64>();
        let total: u64 = count_ops(g.items).values().map(|c| c.fma).sum();
        assert!(calls > 0);
        assert_eq!(calls, total);
        assert!(fma_src.contains(&format!("Fused multiply-adds: {total} (")));
        assert!(fma_src.contains("FMA_COUNTS"));
    }
}
