//! Emission of one traced graph as straight-line Rust: one `let` per shared or expensive
//! subexpression and per output, single-use nodes inlined with the parentheses that keep the
//! graph's evaluation order (so the code performs exactly the emitted operation count), one
//! `sincos` per angle, optional fused multiply-adds.

use crate::options::{Error, Float, Options};
use kanegen_trace::{Input, Node, PayloadField, Sym, Traced};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::cell::RefCell;
use std::collections::{HashMap, HashSet};

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
    /// Sines and cosines by the type's `Self::sincos` ([`Options::table_sincos`]), not libm.
    table_sincos: bool,
}

impl Emitter {
    /// The emitter of `opts`.
    ///
    /// # Errors
    /// If [`Options::libm_path`] or [`Options::fma_path`] is not a Rust path.
    pub fn new(opts: &Options) -> Result<Self, Error> {
        let libm = opts.libm()?;
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
        } else if opts.target_fma {
            Some(quote!(Self::mul_add))
        } else {
            None
        };
        Ok(Emitter {
            libm,
            float: opts.float,
            fma,
            table_sincos: opts.table_sincos(),
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

/// How the outputs of a traced function are returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// `[f; n]`.
    Vector(usize),
    /// The upper triangle (row-major) of a symmetric `n×n` matrix, returned whole
    /// (`[[f; n]; n]`, both triangles written).
    SymMatrix(usize),
    /// A symmetric matrix's upper triangle then an `n`-vector, returned as a tuple.
    SymMatrixAndVector(usize),
    /// A `rows × cols` matrix, row-major (`[[f; cols]; rows]`).
    Matrix(usize, usize),
    /// A placement: origin (3) then rotation matrix (9, row-major), returned as
    /// `([f; 3], [[f; 3]; 3])`.
    Placement,
}

/// The Rust expression that reads a trace input.
#[must_use]
pub fn input_tokens(input: &Input) -> TokenStream {
    let lit = Literal::usize_unsuffixed;
    match input {
        Input::Joint(a, i) => {
            let a = format_ident!("{}", a.name());
            let i = lit(*i);
            quote!(#a[#i])
        }
        Input::Row(a, r, c) => {
            let a = format_ident!("{}", a.name());
            let (r, c) = (lit(*r), lit(*c));
            quote!(#a[#r][#c])
        }
        Input::Payload(PayloadField::Mass) => quote!(payload.mass),
        Input::Payload(PayloadField::Com(k)) => {
            let k = lit(*k);
            quote!(payload.com[#k])
        }
        Input::Payload(PayloadField::Inertia(r, c)) => {
            let (r, c) = (lit(*r), lit(*c));
            quote!(payload.inertia[#r][#c])
        }
        other => {
            let name = format_ident!("{}", other.to_string().replace(['[', ']', '.'], "_"));
            quote!(#name)
        }
    }
}

/// The statements and result expression of one traced function, returned as `shape`.
pub fn emit_body(t: &Traced, emitter: &Emitter, shape: Shape) -> Body {
    let mut stmts: Vec<TokenStream> = Vec::new();
    let Body {
        tokens: result,
        fmas,
    } = emit_body_streamed(t, emitter, shape, &mut |s| stmts.push(s));
    Body {
        tokens: quote!(#(#stmts)* #result),
        fmas,
    }
}

/// Fused calls an inlined expression may nest before it is bound to a name.
const MAX_CALL_NESTING: u32 = 2;

/// [`emit_body`], handing each `let` statement to `stmt` as soon as it is emitted instead of
/// keeping it: the returned body holds the result expression only. A caller that turns each
/// statement into text at once keeps the memory of one statement, not of the whole body (33 MB
/// of text for `forward_dynamics` at N = 200).
pub fn emit_body_streamed(
    t: &Traced,
    emitter: &Emitter,
    shape: Shape,
    stmt: &mut dyn FnMut(TokenStream),
) -> Body {
    let inputs: Vec<TokenStream> = t.inputs.iter().map(input_tokens).collect();
    let Emitter {
        libm,
        float,
        fma,
        table_sincos,
    } = emitter;
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
    let inlined_id = |id: u32| !outputs.contains(&id) && uses.get(&id).copied() == Some(1);
    let inlined = |s: Sym| inlined_id(s.id());
    // The factors of a product that fuses into its user: an inlined multiplication.
    let product = |s: Sym| match nodes.get(&s.id()) {
        Some(Node::Mul(a, b)) if fma.is_some() && inlined(s) => Some((*a, *b)),
        _ => None,
    };
    let is_const = |s: Sym| matches!(nodes.get(&s.id()), Some(Node::Const(_)));
    // An inlined node's expression is taken out when its one user reads it: memory stays linear
    // in the emitted code, and a long single-use chain is moved into its user, not copied. A
    // node its user may look through (a product that fuses, an inlined negation that a fused
    // call unwraps) builds its own expression from copies, so the user can still take the
    // operands.
    let exprs: RefCell<HashMap<u32, Expr>> = RefCell::new(HashMap::new());
    // Fused calls nested in an inlined expression: past `MAX_CALL_NESTING` the expression is
    // bound to a name, so a long fused sum reads as a few short lines instead of a staircase
    // (formatted, each level indents every line below it: N = 100 code grew 10× before).
    let mut nesting: HashMap<u32, u32> = HashMap::new();
    let mut counter = 0usize;
    let mut fmas = 0u64;
    // A readable name for the sine/cosine of an argument: `s_q0` for `q[0]`.
    let trig_base = |arg: u32, counter: usize| -> String {
        match nodes[&arg] {
            Node::Input(i) => inputs[i as usize]
                .to_string()
                .chars()
                .filter(char::is_ascii_alphanumeric)
                .collect(),
            _ => format!("{counter}"),
        }
    };
    // With the type's own `sincos`: the sines and cosines of the inputs (joint angles), or of an
    // input plus a constant (a joint's angle offset, `JointParams::angle_offset`) used by them
    // alone, in one `Self::sincos_n` at the top, so their polynomials run side by side in vector
    // registers. The sums are written into the call and not bound apart (`hoisted`).
    let mut hoisted: HashSet<u32> = HashSet::new();
    if *table_sincos {
        // The input of a hoistable argument, and the constant added to it.
        let input_plus = |a: u32| -> Option<(u32, Option<f64>)> {
            let input = |s: Sym| matches!(nodes[&s.id()], Node::Input(_)).then_some(s.id());
            let konst = |s: Sym| match nodes[&s.id()] {
                Node::Const(c) => Some(c),
                _ => None,
            };
            match nodes[&a] {
                Node::Input(_) => Some((a, None)),
                Node::Add(x, y) => {
                    let (s, c) = trig[&a];
                    let trig_uses = usize::from(s.is_some()) + usize::from(c.is_some());
                    if uses.get(&a).copied() != Some(trig_uses) {
                        return None;
                    }
                    match (input(x), konst(y), konst(x), input(y)) {
                        (Some(i), Some(c), ..) | (.., Some(c), Some(i)) => Some((i, Some(c))),
                        _ => None,
                    }
                }
                _ => None,
            }
        };
        let mut args: Vec<(u32, u32, Option<f64>)> = trig
            .keys()
            .filter_map(|&a| input_plus(a).map(|(i, c)| (a, i, c)))
            .collect();
        // By input, as the joints are numbered.
        args.sort_unstable_by_key(|&(a, i, _)| (i, a));
        if args.len() > 1 {
            let mut pats = Vec::new();
            let mut xs = Vec::new();
            let mut bases = HashSet::new();
            for (a, i, offset) in args {
                let mut base = trig_base(i, counter);
                counter += 1;
                if !bases.insert(base.clone()) {
                    base = format!("{base}_{counter}");
                }
                let (sn, cn) = (format_ident!("s_{}", base), format_ident!("c_{}", base));
                let (s, c) = trig[&a];
                let bind = |node: Option<u32>, name: &proc_macro2::Ident| match node {
                    Some(n) => {
                        exprs.borrow_mut().insert(n, Expr::atom(quote!(#name)));
                        quote!(#name)
                    }
                    None => quote!(_),
                };
                let (ps, pc) = (bind(s, &sn), bind(c, &cn));
                pats.push(quote!((#ps, #pc)));
                let x = &inputs[match nodes[&i] {
                    Node::Input(k) => k as usize,
                    _ => unreachable!("filtered to inputs"),
                }];
                xs.push(match offset {
                    None => x.clone(),
                    Some(c) => {
                        hoisted.insert(a);
                        let lit = constant(c.abs(), float).tokens;
                        if c.is_sign_negative() {
                            quote!(#x - #lit)
                        } else {
                            quote!(#x + #lit)
                        }
                    }
                });
            }
            stmt(quote!(let [#(#pats),*] = Self::sincos_n([#(#xs),*]);));
        }
    }
    for (id, node) in &sched {
        let id = *id;
        if hoisted.contains(&id) {
            continue; // written into the `sincos_n` call
        }
        let see_through = match node {
            Node::Mul(..) => fma.is_some() && inlined_id(id),
            Node::Neg(..) => fma.is_some(),
            _ => false,
        };
        let get = |s: Sym| {
            if !see_through && inlined(s) {
                exprs
                    .borrow_mut()
                    .remove(&s.id())
                    .expect("an operand is emitted before its user")
            } else {
                exprs.borrow()[&s.id()].clone()
            }
        };
        // `−s` as a call argument: constants negated, an inlined negation unwrapped.
        let neg = |s: Sym| -> TokenStream {
            match nodes.get(&s.id()) {
                Some(Node::Const(x)) => constant(-x, float).tokens,
                Some(Node::Neg(z)) if inlined(s) => {
                    exprs.borrow_mut().remove(&s.id()); // looked through
                    get(*z).tokens
                }
                _ => {
                    let e = get(s).at(P_NEG);
                    quote!(-#e)
                }
            }
        };
        // The factors of the fusing product `m`, its own expression dropped (looked through).
        let factors = |m: Sym| {
            exprs.borrow_mut().remove(&m.id());
            product(m).expect("checked")
        };
        let call = |a: TokenStream, b: TokenStream, c: TokenStream| {
            let f = fma
                .as_ref()
                .expect("products fuse only with an fma function");
            Expr::atom(quote!(#f(#a, #b, #c)))
        };
        let operands: &[Sym] = match node {
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => &[*a, *b],
            Node::Neg(a) | Node::Sqrt(a) => core::slice::from_ref(a),
            _ => &[],
        };
        // Nesting of this node's expression: its deepest operand's (a looked-through product
        // counts as its factors), one more when it becomes a fused call.
        let deepest = operands
            .iter()
            .flat_map(|o| match product(*o) {
                Some((a, b)) => [a, b],
                None => [*o, *o],
            })
            .map(|o| nesting.get(&o.id()).copied().unwrap_or(0))
            .max()
            .unwrap_or(0);
        let fmas_before = fmas;
        let expr = match node {
            Node::Const(x) => {
                exprs.borrow_mut().insert(id, constant(*x, float));
                continue;
            }
            Node::Input(i) => {
                exprs
                    .borrow_mut()
                    .insert(id, Expr::atom(inputs[*i as usize].clone()));
                continue;
            }
            Node::Sin(a) | Node::Cos(a) => {
                if exprs.borrow().contains_key(&id) {
                    continue; // bound together with its partner by one sincos
                }
                let arg = get(*a).tokens;
                let base = trig_base(a.id(), counter);
                counter += 1;
                // The type's own `sincos` (a table and short polynomials) takes both at the
                // price of one; libm has `sin` and `cos` apart.
                let (sin_call, cos_call, sincos_call) = if *table_sincos {
                    (
                        quote!(Self::sincos(#arg).0),
                        quote!(Self::sincos(#arg).1),
                        quote!(Self::sincos(#arg)),
                    )
                } else {
                    let (s, c, sc) = (
                        float.libm_fn("sin"),
                        float.libm_fn("cos"),
                        float.libm_fn("sincos"),
                    );
                    (
                        quote!(#libm::#s(#arg)),
                        quote!(#libm::#c(#arg)),
                        quote!(#libm::#sc(#arg)),
                    )
                };
                match trig[&a.id()] {
                    (Some(s), Some(c)) => {
                        let (sn, cn) = (format_ident!("s_{}", base), format_ident!("c_{}", base));
                        stmt(quote!(let (#sn, #cn) = #sincos_call;));
                        exprs.borrow_mut().insert(s, Expr::atom(quote!(#sn)));
                        exprs.borrow_mut().insert(c, Expr::atom(quote!(#cn)));
                    }
                    (Some(s), None) => {
                        let sn = format_ident!("s_{}", base);
                        stmt(quote!(let #sn = #sin_call;));
                        exprs.borrow_mut().insert(s, Expr::atom(quote!(#sn)));
                    }
                    (None, Some(c)) => {
                        let cn = format_ident!("c_{}", base);
                        stmt(quote!(let #cn = #cos_call;));
                        exprs.borrow_mut().insert(c, Expr::atom(quote!(#cn)));
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
                let (a, b) = factors(m);
                call(get(a).tokens, get(b).tokens, get(c).tokens)
            }
            // x − a·b: fma(−a, b, x) (the constant factor negated when there is one).
            Node::Sub(x, y) if product(*y).is_some() => {
                fmas += 1;
                let (a, b) = factors(*y);
                if is_const(b) && !is_const(a) {
                    call(get(a).tokens, neg(b), get(*x).tokens)
                } else {
                    call(neg(a), get(b).tokens, get(*x).tokens)
                }
            }
            // a·b − y: fma(a, b, −y).
            Node::Sub(x, y) if product(*x).is_some() => {
                fmas += 1;
                let (a, b) = factors(*x);
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
        let depth = deepest + u32::from(fmas > fmas_before);
        let bind = outputs.contains(&id)
            || uses.get(&id).copied().unwrap_or(0) > 1
            || matches!(node, Node::Div(..) | Node::Sqrt(..))
            || depth > MAX_CALL_NESTING;
        if bind {
            let name = format_ident!("x{}", counter);
            counter += 1;
            let e = expr.tokens;
            stmt(quote!(let #name = #e;));
            exprs.borrow_mut().insert(id, Expr::atom(quote!(#name)));
        } else {
            nesting.insert(id, depth);
            exprs.borrow_mut().insert(id, expr);
        }
    }
    let out: Vec<TokenStream> = trace
        .outputs()
        .iter()
        .map(|s| exprs.borrow()[&s.id()].at(P_NEG))
        .collect();
    // Upper triangle, row-major: index of (i, j), i ≤ j.
    let sym_matrix = |out: &[TokenStream], n: usize| {
        let idx = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
        let rows = (0..n).map(|i| {
            let row = (0..n).map(|j| &out[idx(i.min(j), i.max(j))]);
            quote!([#(#row),*])
        });
        quote!([#(#rows),*])
    };
    let result = match shape {
        Shape::Vector(_) => quote!([#(#out),*]),
        Shape::SymMatrix(n) => sym_matrix(&out, n),
        Shape::SymMatrixAndVector(n) => {
            let k = n * (n + 1) / 2;
            let m = sym_matrix(&out[..k], n);
            let v = &out[k..];
            quote!((#m, [#(#v),*]))
        }
        Shape::Matrix(_, cols) => {
            let rows = out.chunks(cols).map(|r| quote!([#(#r),*]));
            quote!([#(#rows),*])
        }
        Shape::Placement => {
            let p = &out[..3];
            let rows = out[3..].chunks(3).map(|r| quote!([#(#r),*]));
            quote!(([#(#p),*], [#(#rows),*]))
        }
    };
    Body {
        tokens: result,
        fmas,
    }
}
