//! Emission of one traced graph as straight-line Rust: one `let` per shared or expensive
//! subexpression and per output, single-use nodes inlined with the parentheses that keep the
//! graph's evaluation order (so the code performs exactly the emitted operation count), one
//! `sincos` per angle, optional fused multiply-adds.
//!
//! The code is generic over the lane type `S: kanegen_runtime::lanes::Lanes<F>` (`F` the
//! emitted float type): constants are `S::splat(…)`, negation `S::neg`, and every call (fused
//! multiply-add, square root, sine and cosine) a method of `S`, so one body serves the scalar
//! function (`S = F`) and its `_lanes` form on SIMD vectors.

use crate::options::{Error, Float, Options};
use kanegen_trace::{Input, Node, PayloadField, Sym, Traced};
use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};
use std::collections::{HashMap, HashSet};

/// Operator precedence of an emitted expression (higher binds tighter).
const P_ADD: u8 = 1;
const P_MUL: u8 = 2;
const P_NEG: u8 = 3;
const P_ATOM: u8 = 4;

/// An emitted expression in the code of a [`Syntax`] and how tightly it binds.
#[derive(Clone)]
pub struct Expr<C> {
    /// The code.
    pub tokens: C,
    /// Its precedence (higher binds tighter): a sum 1, a product 2, a negation 3, an atom
    /// (name, literal, call, parenthesized) 4.
    pub prec: u8,
}

impl<C: Clone> Expr<C> {
    fn atom(tokens: C) -> Self {
        Expr {
            tokens,
            prec: P_ATOM,
        }
    }
    /// Whether it is an atom (a name, a literal, a call, or parenthesized).
    #[must_use]
    pub fn is_atom(&self) -> bool {
        self.prec >= P_ATOM
    }
    /// The expression, parenthesized by `syntax` unless it binds at least as tightly as `min`.
    fn at<L: Syntax<Code = C>>(&self, syntax: &L, min: u8) -> C {
        if self.prec >= min {
            self.tokens.clone()
        } else {
            syntax.paren(self.tokens.clone())
        }
    }
}

/// A binary operator of the graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`.
    Add,
    /// `-`.
    Sub,
    /// `*`.
    Mul,
    /// `/`.
    Div,
}

/// The printer of one graph's code: what [`emit_graph`] writes for each construct, Rust tokens
/// ([`RustSyntax`]) or another language's text (`crate::c`). The graph walk — the order, the
/// inlining, the parentheses, the fused multiply-adds, the hoisted sine–cosine — is the same for
/// every syntax, so every language performs the same operations in the same order.
pub trait Syntax {
    /// A piece of code: an expression or a statement.
    type Code: Clone + core::fmt::Display;
    /// A constant (an atom).
    fn constant(&self, x: f64) -> Self::Code;
    /// The code that reads a trace input (an atom).
    fn input(&self, input: &Input) -> Self::Code;
    /// A bound name (an atom).
    fn name(&self, name: &str) -> Self::Code;
    /// `(e)`.
    fn paren(&self, e: Self::Code) -> Self::Code;
    /// `a op b`, the operands already parenthesized as needed.
    fn binary(&self, a: Self::Code, op: BinOp, b: Self::Code) -> Self::Code;
    /// `−e` as an atom.
    fn neg(&self, e: &Expr<Self::Code>) -> Self::Code;
    /// `√e` as an atom (`e` is a call argument).
    fn sqrt(&self, e: Self::Code) -> Self::Code;
    /// The fused multiply-add `a·b + c` by `fuse`, as an atom.
    fn fma(&self, fuse: &Fuse, a: Self::Code, b: Self::Code, c: Self::Code) -> Self::Code;
    /// The statement binding `e` to a new `name`.
    fn bind(&self, name: &str, e: Self::Code) -> Self::Code;
    /// The statement binding the sines and cosines of `angles` by the table sine–cosine
    /// (`fused`: its products fused where the target has FMA): `names[k]` holds the names of
    /// angle `k`'s sine and cosine, `None` for one that is not used.
    fn sincos_table(
        &self,
        fused: bool,
        names: &[(Option<String>, Option<String>)],
        angles: Vec<Self::Code>,
    ) -> Self::Code;
    /// The statement binding the sine and/or cosine of `angle` by libm (`sin`, `cos`, or both).
    fn sincos_libm(&self, sin: Option<&str>, cos: Option<&str>, angle: Self::Code) -> Self::Code;
}

/// Rust tokens generic over the lane type `S: Lanes<F>` ([module docs](self)).
#[derive(Clone, Copy, Debug)]
pub struct RustSyntax {
    float: Float,
}

impl Syntax for RustSyntax {
    type Code = TokenStream;
    fn constant(&self, x: f64) -> TokenStream {
        constant(x, self.float).tokens
    }
    fn input(&self, input: &Input) -> TokenStream {
        input_tokens(input)
    }
    fn name(&self, name: &str) -> TokenStream {
        let name = format_ident!("{}", name);
        quote!(#name)
    }
    fn paren(&self, e: TokenStream) -> TokenStream {
        quote!((#e))
    }
    fn binary(&self, a: TokenStream, op: BinOp, b: TokenStream) -> TokenStream {
        match op {
            BinOp::Add => quote!(#a + #b),
            BinOp::Sub => quote!(#a - #b),
            BinOp::Mul => quote!(#a * #b),
            BinOp::Div => quote!(#a / #b),
        }
    }
    fn neg(&self, e: &Expr<TokenStream>) -> TokenStream {
        let e = &e.tokens;
        quote!(S::neg(#e))
    }
    fn sqrt(&self, e: TokenStream) -> TokenStream {
        quote!(S::sqrt(#e))
    }
    fn fma(&self, fuse: &Fuse, a: TokenStream, b: TokenStream, c: TokenStream) -> TokenStream {
        match fuse {
            Fuse::Target => quote!(S::mul_add(#a, #b, #c)),
            Fuse::Libm => quote!(S::fma(#a, #b, #c)),
            Fuse::Path(path) => quote!(S::fma_with(#a, #b, #c, #path)),
        }
    }
    fn bind(&self, name: &str, e: TokenStream) -> TokenStream {
        let name = format_ident!("{}", name);
        quote!(let #name = #e;)
    }
    fn sincos_table(
        &self,
        fused: bool,
        names: &[(Option<String>, Option<String>)],
        angles: Vec<TokenStream>,
    ) -> TokenStream {
        let f = if fused {
            quote!(S::sincos_n)
        } else {
            quote!(S::sincos_n_unfused)
        };
        let pat = |n: &Option<String>| match n {
            Some(n) => self.name(n),
            None => quote!(_),
        };
        if let ([(s, c)], [a]) = (names, &angles[..]) {
            let call = quote!(#f([#a])[0]);
            return match (s, c) {
                (Some(_), Some(_)) => {
                    let (s, c) = (pat(s), pat(c));
                    quote!(let (#s, #c) = #call;)
                }
                (Some(s), None) => self.bind(s, quote!(#call.0)),
                (None, Some(c)) => self.bind(c, quote!(#call.1)),
                (None, None) => quote!(),
            };
        }
        let pats = names.iter().map(|(s, c)| {
            let (s, c) = (pat(s), pat(c));
            quote!((#s, #c))
        });
        quote!(let [#(#pats),*] = #f([#(#angles),*]);)
    }
    fn sincos_libm(&self, sin: Option<&str>, cos: Option<&str>, angle: TokenStream) -> TokenStream {
        match (sin, cos) {
            (Some(s), Some(c)) => {
                let (s, c) = (format_ident!("{}", s), format_ident!("{}", c));
                quote!(let (#s, #c) = S::sincos(#angle);)
            }
            (Some(s), None) => self.bind(s, quote!(S::sin(#angle))),
            (None, Some(c)) => self.bind(c, quote!(S::cos(#angle))),
            (None, None) => quote!(),
        }
    }
}

/// The literal of a constant of type `float`: the f64 value, rounded for `f32`.
fn literal(x: f64, float: Float) -> TokenStream {
    let ty = float.ty();
    let x = match float {
        Float::F64 => x,
        Float::F32 => f64::from(x as f32),
    };
    if x.is_nan() {
        return quote!(#ty::NAN);
    }
    if x.is_infinite() {
        return if x > 0.0 {
            quote!(#ty::INFINITY)
        } else {
            quote!(#ty::NEG_INFINITY)
        };
    }
    let lit = match float {
        Float::F64 => Literal::f64_unsuffixed(x.abs()),
        Float::F32 => Literal::f32_unsuffixed((x as f32).abs()),
    };
    if x.is_sign_negative() && x != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// A constant of type `float` in every lane: `S::splat(literal)`.
fn constant(x: f64, float: Float) -> Expr<TokenStream> {
    let lit = literal(x, float);
    Expr::atom(quote!(S::splat(#lit)))
}

/// How products are fused.
#[derive(Clone, Debug)]
pub enum Fuse {
    /// `S::mul_add`: fused where the build targets FMA ([`Options::target_fma`]).
    Target,
    /// `S::fma`: libm's `fma`, always fused ([`Options::fma`]).
    Libm,
    /// `S::fma_with(a, b, c, path)`: [`Options::fma_path`] on each lane.
    Path(TokenStream),
}

/// How one graph is emitted: the floating-point type, the fused multiply-add (none: no fusion)
/// and the sine–cosine. Built from [`Options`] by [`Emitter::new`].
#[derive(Clone, Debug)]
pub struct Emitter {
    float: Float,
    fma: Option<Fuse>,
    /// Sines and cosines by the table sine–cosine `S::sincos_n` ([`Options::table_sincos`]),
    /// not libm.
    table_sincos: bool,
    /// The table sine–cosine's products fused where the build targets FMA (with
    /// [`Options::target_fma`] and without [`Options::fma`]): `S::sincos_n`, else
    /// `S::sincos_n_unfused`.
    sincos_fused: bool,
}

impl Emitter {
    /// The emitter of `opts`.
    ///
    /// # Errors
    /// If [`Options::libm_path`] or [`Options::fma_path`] is not a Rust path.
    pub fn new(opts: &Options) -> Result<Self, Error> {
        opts.libm()?;
        let fma = if opts.fma {
            Some(match &opts.fma_path {
                Some(p) => {
                    let path: syn::Path =
                        syn::parse_str(p).map_err(|e| Error(format!("fma path `{p}`: {e}")))?;
                    Fuse::Path(quote!(#path))
                }
                None => Fuse::Libm,
            })
        } else if opts.target_fma {
            Some(Fuse::Target)
        } else {
            None
        };
        Ok(Emitter {
            float: opts.float,
            fma,
            table_sincos: opts.table_sincos(),
            sincos_fused: !opts.fma && opts.target_fma,
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
    /// `k` square `n × n` matrices one after the other, each row-major, returned as a tuple of
    /// `k` `[[f; n]; n]` (the derivatives).
    Matrices(usize, usize),
    /// A placement: origin (3) then rotation matrix (9, row-major), returned as
    /// `([f; 3], [[f; 3]; 3])`.
    Placement,
}

/// The Rust expression that reads a trace input: an argument's entry (of type `S`), or a
/// payload field (of type `F`, the same for every lane) splat over the lanes.
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
        Input::Payload(PayloadField::Mass) => quote!(S::splat(payload.mass)),
        Input::Payload(PayloadField::Com(k)) => {
            let k = lit(*k);
            quote!(S::splat(payload.com[#k]))
        }
        Input::Payload(PayloadField::Inertia(r, c)) => {
            let (r, c) = (lit(*r), lit(*c));
            quote!(S::splat(payload.inertia[#r][#c]))
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
    let syntax = RustSyntax {
        float: emitter.float,
    };
    let (out, fmas) = emit_graph(t, emitter, &syntax, stmt);
    Body {
        tokens: result_tokens(&out, shape),
        fmas,
    }
}

/// The walk of one traced graph in `syntax`: each statement handed to `stmt` as it is emitted,
/// then the outputs' expressions (in the trace's order, parenthesized to bind at least as a
/// negation) and the fused multiply-adds formed. Every syntax gets the same statements in the
/// same order.
pub fn emit_graph<L: Syntax>(
    t: &Traced,
    emitter: &Emitter,
    syntax: &L,
    stmt: &mut dyn FnMut(L::Code),
) -> (Vec<L::Code>, u64) {
    let sched = t.trace.schedule();
    let mut g = GraphEmitter::new(t, emitter, syntax, &sched);
    if emitter.table_sincos {
        g.hoist_sincos(stmt);
    }
    for (id, node) in &sched {
        g.emit_node(*id, node, stmt);
    }
    let out = t
        .trace
        .outputs()
        .iter()
        .map(|s| g.exprs[&s.id()].at(syntax, P_NEG))
        .collect();
    (out, g.fmas)
}

/// The state of emitting one graph in schedule order.
struct GraphEmitter<'a, L: Syntax> {
    emitter: &'a Emitter,
    syntax: &'a L,
    /// The code of each input.
    inputs: Vec<L::Code>,
    outputs: HashSet<u32>,
    nodes: HashMap<u32, Node>,
    /// How many nodes read each node.
    uses: HashMap<u32, usize>,
    /// Sine and cosine nodes per argument.
    trig: HashMap<u32, (Option<u32>, Option<u32>)>,
    /// The expression of each emitted node not yet read by its one user (inlined) or bound to
    /// a name. An inlined node's expression is taken out when its one user reads it: memory
    /// stays linear in the emitted code, and a long single-use chain is moved into its user,
    /// not copied. A node its user may look through (a product that fuses, an inlined negation
    /// that a fused call unwraps) builds its own expression from copies, so the user can still
    /// take the operands.
    exprs: HashMap<u32, Expr<L::Code>>,
    /// Fused calls nested in an inlined expression: past `MAX_CALL_NESTING` the expression is
    /// bound to a name, so a long fused sum reads as a few short lines instead of a staircase
    /// (formatted, each level indents every line below it: N = 100 code grew 10× before).
    nesting: HashMap<u32, u32>,
    /// Sine–cosine arguments written into the `sincos_n` call, not bound apart.
    hoisted: HashSet<u32>,
    /// Names given so far (the `x…` and sine–cosine suffixes).
    counter: usize,
    /// Fused multiply-adds formed.
    fmas: u64,
}

impl<'a, L: Syntax> GraphEmitter<'a, L> {
    /// The uses and the sine–cosine pairs of the scheduled graph.
    fn new(t: &Traced, emitter: &'a Emitter, syntax: &'a L, sched: &[(u32, Node)]) -> Self {
        let mut uses: HashMap<u32, usize> = HashMap::new();
        let mut trig: HashMap<u32, (Option<u32>, Option<u32>)> = HashMap::new();
        for (id, node) in sched {
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
        GraphEmitter {
            emitter,
            syntax,
            inputs: t.inputs.iter().map(|i| syntax.input(i)).collect(),
            outputs: t.trace.outputs().iter().map(|s| s.id()).collect(),
            nodes: sched.iter().copied().collect(),
            uses,
            trig,
            exprs: HashMap::new(),
            nesting: HashMap::new(),
            hoisted: HashSet::new(),
            counter: 0,
            fmas: 0,
        }
    }

    /// Inlined (single-use, not an output): its expression appears once, in its user's.
    fn inlined_id(&self, id: u32) -> bool {
        !self.outputs.contains(&id) && self.uses.get(&id).copied() == Some(1)
    }

    fn inlined(&self, s: Sym) -> bool {
        self.inlined_id(s.id())
    }

    /// The factors of a product that fuses into its user: an inlined multiplication.
    fn product(&self, s: Sym) -> Option<(Sym, Sym)> {
        match self.nodes.get(&s.id()) {
            Some(Node::Mul(a, b)) if self.emitter.fma.is_some() && self.inlined(s) => {
                Some((*a, *b))
            }
            _ => None,
        }
    }

    fn is_const(&self, s: Sym) -> bool {
        matches!(self.nodes.get(&s.id()), Some(Node::Const(_)))
    }

    /// A constant in the syntax.
    fn constant(&self, x: f64) -> L::Code {
        self.syntax.constant(x)
    }

    /// A readable name for the sine/cosine of an argument: `s_q0` for `q[0]`.
    fn trig_base(&self, arg: u32) -> String {
        match self.nodes[&arg] {
            Node::Input(i) => self.inputs[i as usize]
                .to_string()
                .chars()
                .filter(char::is_ascii_alphanumeric)
                .collect(),
            _ => format!("{}", self.counter),
        }
    }

    /// The input of a hoistable sine–cosine argument `a`, and the constant added to it.
    fn input_plus(&self, a: u32) -> Option<(u32, Option<f64>)> {
        let nodes = &self.nodes;
        let input = |s: Sym| matches!(nodes[&s.id()], Node::Input(_)).then_some(s.id());
        let konst = |s: Sym| match nodes[&s.id()] {
            Node::Const(c) => Some(c),
            _ => None,
        };
        match nodes[&a] {
            Node::Input(_) => Some((a, None)),
            Node::Add(x, y) => {
                let (s, c) = self.trig[&a];
                let trig_uses = usize::from(s.is_some()) + usize::from(c.is_some());
                if self.uses.get(&a).copied() != Some(trig_uses) {
                    return None;
                }
                match (input(x), konst(y), konst(x), input(y)) {
                    (Some(i), Some(c), ..) | (.., Some(c), Some(i)) => Some((i, Some(c))),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// With the table sine–cosine: the sines and cosines of the inputs (joint angles), or of
    /// an input plus a constant (a joint's angle offset, `JointParams::angle_offset`) used by
    /// them alone, in one `S::sincos_n` at the top, so their polynomials run side by side in
    /// vector registers. The sums are written into the call and not bound apart (`hoisted`).
    fn hoist_sincos(&mut self, stmt: &mut dyn FnMut(L::Code)) {
        let mut args: Vec<(u32, u32, Option<f64>)> = self
            .trig
            .keys()
            .filter_map(|&a| self.input_plus(a).map(|(i, c)| (a, i, c)))
            .collect();
        // By input, as the joints are numbered.
        args.sort_unstable_by_key(|&(a, i, _)| (i, a));
        if args.len() <= 1 {
            return;
        }
        let mut names = Vec::new();
        let mut xs = Vec::new();
        let mut bases = HashSet::new();
        for (a, i, offset) in args {
            let mut base = self.trig_base(i);
            self.counter += 1;
            if !bases.insert(base.clone()) {
                base = format!("{base}_{}", self.counter);
            }
            let (s, c) = self.trig[&a];
            let (sn, cn) = (format!("s_{base}"), format!("c_{base}"));
            let mut bind = |node: Option<u32>, name: String| {
                node.map(|n| {
                    self.exprs.insert(n, Expr::atom(self.syntax.name(&name)));
                    name
                })
            };
            names.push((bind(s, sn), bind(c, cn)));
            let x = self.inputs[match self.nodes[&i] {
                Node::Input(k) => k as usize,
                _ => unreachable!("filtered to inputs"),
            }]
            .clone();
            xs.push(match offset {
                None => x,
                Some(c) => {
                    self.hoisted.insert(a);
                    let lit = self.constant(c.abs());
                    let op = if c.is_sign_negative() {
                        BinOp::Sub
                    } else {
                        BinOp::Add
                    };
                    self.syntax.binary(x, op, lit)
                }
            });
        }
        stmt(
            self.syntax
                .sincos_table(self.emitter.sincos_fused, &names, xs),
        );
    }

    /// Emits node `id`: records its expression, or binds it to a name.
    fn emit_node(&mut self, id: u32, node: &Node, stmt: &mut dyn FnMut(L::Code)) {
        if self.hoisted.contains(&id) {
            return; // written into the `sincos_n` call
        }
        match node {
            Node::Const(x) => {
                self.exprs.insert(id, Expr::atom(self.constant(*x)));
                return;
            }
            Node::Input(i) => {
                let e = Expr::atom(self.inputs[*i as usize].clone());
                self.exprs.insert(id, e);
                return;
            }
            Node::Sin(a) | Node::Cos(a) => {
                self.emit_trig(id, *a, stmt);
                return;
            }
            _ => {}
        }
        let deepest = self.deepest_operand(node);
        let fmas_before = self.fmas;
        let expr = self.arithmetic(id, node);
        let depth = deepest + u32::from(self.fmas > fmas_before);
        let bind = self.outputs.contains(&id)
            || self.uses.get(&id).copied().unwrap_or(0) > 1
            || matches!(node, Node::Div(..) | Node::Sqrt(..))
            || depth > MAX_CALL_NESTING;
        if bind {
            let name = format!("x{}", self.counter);
            self.counter += 1;
            stmt(self.syntax.bind(&name, expr.tokens));
            self.exprs.insert(id, Expr::atom(self.syntax.name(&name)));
        } else {
            self.nesting.insert(id, depth);
            self.exprs.insert(id, expr);
        }
    }

    /// Nesting of a node's expression before fusion: its deepest operand's (a looked-through
    /// product counts as its factors).
    fn deepest_operand(&self, node: &Node) -> u32 {
        let operands: &[Sym] = match node {
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => &[*a, *b],
            Node::Neg(a) | Node::Sqrt(a) => core::slice::from_ref(a),
            _ => &[],
        };
        operands
            .iter()
            .flat_map(|o| match self.product(*o) {
                Some((a, b)) => [a, b],
                None => [*o, *o],
            })
            .map(|o| self.nesting.get(&o.id()).copied().unwrap_or(0))
            .max()
            .unwrap_or(0)
    }

    /// The sine and/or cosine of `a`, bound by one call when both are used: the table
    /// sine–cosine (a table and short polynomials) takes both at the price of one; libm has `sin`
    /// and `cos` apart.
    fn emit_trig(&mut self, id: u32, a: Sym, stmt: &mut dyn FnMut(L::Code)) {
        if self.exprs.contains_key(&id) {
            return; // bound together with its partner by one sincos
        }
        let arg = self.take(a, false).tokens;
        let base = self.trig_base(a.id());
        self.counter += 1;
        let (s, c) = self.trig[&a.id()];
        let (sn, cn) = (
            s.map(|_| format!("s_{base}")),
            c.map(|_| format!("c_{base}")),
        );
        for (node, name) in [(s, &sn), (c, &cn)] {
            if let (Some(node), Some(name)) = (node, name) {
                self.exprs.insert(node, Expr::atom(self.syntax.name(name)));
            }
        }
        stmt(if self.emitter.table_sincos {
            self.syntax
                .sincos_table(self.emitter.sincos_fused, &[(sn, cn)], vec![arg])
        } else {
            self.syntax.sincos_libm(sn.as_deref(), cn.as_deref(), arg)
        });
    }

    /// The expression of operand `s`: taken out when it is inlined (unless its user looks
    /// through it, `see_through`), copied otherwise.
    fn take(&mut self, s: Sym, see_through: bool) -> Expr<L::Code> {
        if !see_through && self.inlined(s) {
            self.exprs
                .remove(&s.id())
                .expect("an operand is emitted before its user")
        } else {
            self.exprs[&s.id()].clone()
        }
    }

    /// `−s` as a call argument: constants negated, an inlined negation unwrapped.
    fn neg(&mut self, s: Sym, see_through: bool) -> L::Code {
        match self.nodes.get(&s.id()).copied() {
            Some(Node::Const(x)) => self.constant(-x),
            Some(Node::Neg(z)) if self.inlined(s) => {
                self.exprs.remove(&s.id()); // looked through
                self.take(z, see_through).tokens
            }
            _ => {
                let e = self.take(s, see_through);
                self.syntax.neg(&e)
            }
        }
    }

    /// The factors of the fusing product `m`, its own expression dropped (looked through).
    fn factors(&mut self, m: Sym) -> (Sym, Sym) {
        self.exprs.remove(&m.id());
        self.product(m).expect("checked")
    }

    /// `fma(a, b, c)`, one more fused multiply-add.
    fn call(&mut self, a: L::Code, b: L::Code, c: L::Code) -> Expr<L::Code> {
        self.fmas += 1;
        let fuse = (self.emitter.fma.as_ref()).expect("products fuse only with an fma function");
        Expr::atom(self.syntax.fma(fuse, a, b, c))
    }

    /// The expression of an arithmetic node, with products fused into their users.
    fn arithmetic(&mut self, id: u32, node: &Node) -> Expr<L::Code> {
        let st = match node {
            Node::Mul(..) => self.emitter.fma.is_some() && self.inlined_id(id),
            Node::Neg(..) => self.emitter.fma.is_some(),
            _ => false,
        };
        match *node {
            // x + a·b, a·b + x: fma(a, b, x) (the right product first: sums accumulate
            // from the left, so the left operand is the running sum).
            Node::Add(x, y) if self.product(y).is_some() || self.product(x).is_some() => {
                let (m, c) = if self.product(y).is_some() {
                    (y, x)
                } else {
                    (x, y)
                };
                let (a, b) = self.factors(m);
                let (a, b, c) = (
                    self.take(a, st).tokens,
                    self.take(b, st).tokens,
                    self.take(c, st).tokens,
                );
                self.call(a, b, c)
            }
            // x − a·b: fma(−a, b, x) (the constant factor negated when there is one).
            Node::Sub(x, y) if self.product(y).is_some() => {
                let (a, b) = self.factors(y);
                let (a, b, c) = if self.is_const(b) && !self.is_const(a) {
                    (
                        self.take(a, st).tokens,
                        self.neg(b, st),
                        self.take(x, st).tokens,
                    )
                } else {
                    (
                        self.neg(a, st),
                        self.take(b, st).tokens,
                        self.take(x, st).tokens,
                    )
                };
                self.call(a, b, c)
            }
            // a·b − y: fma(a, b, −y).
            Node::Sub(x, y) if self.product(x).is_some() => {
                let (a, b) = self.factors(x);
                let (a, b, c) = (
                    self.take(a, st).tokens,
                    self.take(b, st).tokens,
                    self.neg(y, st),
                );
                self.call(a, b, c)
            }
            Node::Add(a, b) => self.binary(a, b, st, BinOp::Add),
            Node::Sub(a, b) => self.binary(a, b, st, BinOp::Sub),
            Node::Mul(a, b) => self.binary(a, b, st, BinOp::Mul),
            Node::Div(a, b) => self.binary(a, b, st, BinOp::Div),
            Node::Neg(a) => {
                let a = self.take(a, st);
                Expr::atom(self.syntax.neg(&a))
            }
            Node::Sqrt(a) => {
                let a = self.take(a, st).tokens;
                Expr::atom(self.syntax.sqrt(a))
            }
            Node::Const(_) | Node::Input(_) | Node::Sin(_) | Node::Cos(_) => {
                unreachable!("emitted by emit_node")
            }
        }
    }

    /// `a op b` with the parentheses that keep the graph's evaluation order: sums and
    /// differences bind the left operand at `+` and the right at `*`; products and quotients
    /// the left at `*` and the right at unary minus.
    fn binary(&mut self, a: Sym, b: Sym, st: bool, op: BinOp) -> Expr<L::Code> {
        let (left, right, prec) = match op {
            BinOp::Add | BinOp::Sub => (P_ADD, P_MUL, P_ADD),
            BinOp::Mul | BinOp::Div => (P_MUL, P_NEG, P_MUL),
        };
        let syntax = self.syntax;
        let (a, b) = (
            self.take(a, st).at(syntax, left),
            self.take(b, st).at(syntax, right),
        );
        Expr {
            tokens: syntax.binary(a, op, b),
            prec,
        }
    }
}

/// The function's result expression: the outputs `out` returned as `shape`.
fn result_tokens(out: &[TokenStream], shape: Shape) -> TokenStream {
    // Upper triangle, row-major: index of (i, j), i ≤ j.
    let sym_matrix = |out: &[TokenStream], n: usize| {
        let idx = |i: usize, j: usize| i * n - i * (i + 1) / 2 + j;
        let rows = (0..n).map(|i| {
            let row = (0..n).map(|j| &out[idx(i.min(j), i.max(j))]);
            quote!([#(#row),*])
        });
        quote!([#(#rows),*])
    };
    match shape {
        Shape::Vector(_) => quote!([#(#out),*]),
        Shape::SymMatrix(n) => sym_matrix(out, n),
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
        Shape::Matrices(_, n) => {
            let mats = out.chunks(n * n).map(|m| {
                let rows = m.chunks(n).map(|r| quote!([#(#r),*]));
                quote!([#(#rows),*])
            });
            quote!((#(#mats),*))
        }
        Shape::Placement => {
            let p = &out[..3];
            let rows = out[3..].chunks(3).map(|r| quote!([#(#r),*]));
            quote!(([#(#p),*], [#(#rows),*]))
        }
    }
}
