//! The counting symbolic scalar [`Sym`] and its tracer.
//!
//! A [`Sym`] is a small `Copy` handle into an expression graph owned by the active [`Tracer`] of
//! the current thread (the only global state of the crate). Running an algorithm that is generic
//! over [`Scalar`] on `Sym` records every operation it performs; [`Tracer::finish`] freezes the
//! graph into a [`Trace`], which counts operations under three [`Convention`]s, evaluates the graph
//! numerically ([`Trace::eval`]) and hands a code emitter the reachable nodes in dependency order
//! ([`Trace::schedule`]).
//!
//! # Conventions
//!
//! * [`Convention::Paper`] — every call of `+ − × ÷ sqrt sin cos` is counted *before* any
//!   simplification, even `0·x` or `const + const`. This is the bookkeeping of the paper (each
//!   element of a 3×3 product is `3 m + 3 a`, skew zeros are multiplied). Negation is free and is
//!   reported in [`Counts::neg`] only.
//! * [`Convention::Folded`] — the operations left after folding at construction: constants fold,
//!   `0·x`, `1·x`, `−1·x`, `x ± 0`, `0 − x`, `x − x`, `x/1`, `0/x`, `−(−x)` vanish, and signs are
//!   normalised (`(−a)·b → −(a·b)`, `a·(−k) → −(a·k)` for a constant `k`, `a + (−b) → a − b`,
//!   `(−a) − b → −(a + b)`, `b − a → −(a − b)` for the older `a`, …) so that negations
//!   float to the top where they are free. Operations that then hit the hash-cons table are still
//!   counted (no CSE yet).
//! * [`Convention::Emitted`] — the unique non-leaf nodes reachable from the outputs: folding plus
//!   common-subexpression elimination (hash-consing with sorted operands of `+` and `×`) plus
//!   dead-code elimination. This is what a straightforward code generator emits.
//!
//! `sincos` counts trigonometric evaluations of one argument: under `Paper` and `Folded`, each
//! [`Scalar::sin_cos`] call and each lone `sin` / `cos` call counts one; under `Emitted` it is the
//! number of distinct argument nodes whose sine and/or cosine is reachable.
//!
//! Operations are attributed to the section set by [`Scalar::section`]: raw and folded counts to
//! the section current when the operation ran; emitted counts to the section current when the node
//! was first created.
//!
//! # Example
//!
//! ```
//! use kanegen_dynamics::linalg::{Mat3, Vec3};
//! use kanegen_dynamics::Scalar;
//! use kanegen_trace::sym::{record, Convention, Counts, Sym};
//!
//! let t = record(|tr| {
//!     let x = Vec3::new(tr.input("x0"), tr.input("x1"), tr.input("x2"));
//!     let y = Vec3::new(tr.input("y0"), tr.input("y1"), tr.input("y2"));
//!     <Sym as Scalar>::section("cross");
//!     x.cross(&y).into_array().to_vec()
//! });
//! let c = t.counts(Convention::Paper);
//! assert_eq!((c.mul, c.add), (9, 9)); // the paper's (3m+3a)·3
//! let c = t.counts(Convention::Folded);
//! assert_eq!((c.mul, c.add), (6, 3)); // skew zeros folded away
//! assert_eq!(t.counts_by_section(Convention::Emitted)[0].0, "cross");
//! // The trace evaluates to the f64 result of the same expression.
//! let v = t.eval(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
//! assert_eq!(v, vec![2.0 * 6.0 - 3.0 * 5.0, 3.0 * 4.0 - 1.0 * 6.0, 1.0 * 5.0 - 2.0 * 4.0]);
//! ```

use core::cell::RefCell;
use core::hash::{BuildHasherDefault, Hash, Hasher};
use core::marker::PhantomData;
use core::ops::{Add, AddAssign, Div, Mul, Neg, Sub};
use kanegen_dynamics::scalar::{Scalar, Symbolic};
use std::collections::{HashMap, HashSet};
use std::sync::atomic::{AtomicU32, Ordering};

/// A symbolic scalar: a handle to a node of the active [`Tracer`]'s expression graph.
///
/// All arithmetic on `Sym` is recorded (and counted) in the thread's graph. Using a `Sym` after its
/// tracer was dropped or finished, or with no tracer active, panics. There is deliberately no
/// comparison at all (no `PartialEq`, no ordering), so a traced computation cannot branch on its
/// values; tools that need node identity (after folding and hash-consing `a * b` and `b * a` are
/// the same node) compare [`Sym::id`].
#[derive(Clone, Copy, Debug)]
pub struct Sym {
    id: u32,
    gen: u32,
}

impl Sym {
    /// The node id (index in creation order; operands always have smaller ids).
    pub fn id(self) -> u32 {
        self.id
    }

    /// `Some(value)` if the node is a constant. Structural: it inspects the graph node, it does not
    /// compare data. Needs the active tracer that created `self`.
    pub fn const_value(self) -> Option<f64> {
        with_graph(|g| {
            g.check(self);
            match g.ops[self.id as usize] {
                Op::Const(bits) => Some(f64::from_bits(bits)),
                _ => None,
            }
        })
    }
}

/// One node of a frozen graph, as seen by a code emitter.
#[derive(Clone, Copy, Debug)]
pub enum Node {
    /// A constant.
    Const(f64),
    /// The runtime input with this index (creation order of [`Tracer::input`]).
    Input(u32),
    /// Sum.
    Add(Sym, Sym),
    /// Difference.
    Sub(Sym, Sym),
    /// Product.
    Mul(Sym, Sym),
    /// Quotient.
    Div(Sym, Sym),
    /// Sign change.
    Neg(Sym),
    /// Sine.
    Sin(Sym),
    /// Cosine.
    Cos(Sym),
    /// Square root.
    Sqrt(Sym),
}

/// Operation counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counts {
    /// Multiplications.
    pub mul: u64,
    /// Additions and subtractions.
    pub add: u64,
    /// Divisions.
    pub div: u64,
    /// Square roots.
    pub sqrt: u64,
    /// Sines.
    pub sin: u64,
    /// Cosines.
    pub cos: u64,
    /// Trigonometric evaluations of one argument (see the module docs).
    pub sincos: u64,
    /// Sign changes (free; not part of [`Counts::total`]).
    pub neg: u64,
}

impl Counts {
    /// `mul + add`, the paper's total.
    pub fn total(&self) -> u64 {
        self.mul + self.add
    }

    fn is_zero(&self) -> bool {
        *self == Counts::default()
    }

    fn bump(&mut self, op: &Op) {
        match op {
            Op::Const(_) | Op::Input(_) => {}
            Op::Add(..) | Op::Sub(..) => self.add += 1,
            Op::Mul(..) => self.mul += 1,
            Op::Div(..) => self.div += 1,
            Op::Neg(_) => self.neg += 1,
            Op::Sin(_) => self.sin += 1,
            Op::Cos(_) => self.cos += 1,
            Op::Sqrt(_) => self.sqrt += 1,
        }
    }
}

impl Add for Counts {
    type Output = Counts;
    fn add(mut self, o: Counts) -> Counts {
        self += o;
        self
    }
}

impl AddAssign for Counts {
    fn add_assign(&mut self, o: Counts) {
        self.mul += o.mul;
        self.add += o.add;
        self.div += o.div;
        self.sqrt += o.sqrt;
        self.sin += o.sin;
        self.cos += o.cos;
        self.sincos += o.sincos;
        self.neg += o.neg;
    }
}

/// How operations are counted (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Convention {
    /// Every operation call, before any simplification (the paper's bookkeeping).
    Paper,
    /// Operations left after folding constants, zeros, ones and signs at construction.
    Folded,
    /// Unique operations reachable from the outputs (fold + CSE + dead-code elimination).
    Emitted,
}

impl Convention {
    /// All conventions, in the order `Paper`, `Folded`, `Emitted`.
    pub const ALL: [Convention; 3] = [Convention::Paper, Convention::Folded, Convention::Emitted];

    /// `"paper"`, `"folded"` or `"emitted"`.
    pub fn name(self) -> &'static str {
        match self {
            Convention::Paper => "paper",
            Convention::Folded => "folded",
            Convention::Emitted => "emitted",
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The graph.

/// Internal node: operands are node ids. `Const` holds the bits of the value (−0.0 normalised).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Op {
    Const(u64),
    Input(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Neg(u32),
    Sin(u32),
    Cos(u32),
    Sqrt(u32),
}

/// A small multiplicative hasher (FxHash-like); the keys are a few machine words.
#[derive(Default)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u8(&mut self, i: u8) {
        self.write_u64(u64::from(i));
    }
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    fn write_isize(&mut self, i: isize) {
        self.write_u64(i as u64);
    }
}

type FxMap<K, V> = HashMap<K, V, BuildHasherDefault<FxHasher>>;

/// The mutable graph of an active tracer; frozen into a [`Trace`].
#[derive(Debug)]
struct Graph {
    gen: u32,
    ops: Vec<Op>,
    /// Section index current when each node was created.
    node_section: Vec<u32>,
    table: FxMap<Op, u32>,
    input_names: Vec<String>,
    section_names: Vec<String>,
    section_index: HashMap<&'static str, u32>,
    current: u32,
    raw: Vec<Counts>,
    folded: Vec<Counts>,
}

const NO_TRACER: &str = "no active Tracer on this thread (a Sym was used outside Tracer::new() .. \
                         finish/drop, or after its Tracer was dropped)";

thread_local! {
    static GRAPH: RefCell<Option<Graph>> = const { RefCell::new(None) };
}

static GENERATION: AtomicU32 = AtomicU32::new(1);

fn with_graph<R>(f: impl FnOnce(&mut Graph) -> R) -> R {
    GRAPH.with(|cell| {
        let mut b = cell.borrow_mut();
        let g = b.as_mut().expect(NO_TRACER);
        f(g)
    })
}

fn norm_bits(x: f64) -> u64 {
    if x == 0.0 {
        0.0f64.to_bits()
    } else {
        x.to_bits()
    }
}

impl Graph {
    fn new() -> Graph {
        Graph {
            gen: GENERATION.fetch_add(1, Ordering::Relaxed),
            ops: Vec::new(),
            node_section: Vec::new(),
            table: FxMap::default(),
            input_names: Vec::new(),
            section_names: vec![String::new()],
            section_index: HashMap::new(),
            current: 0,
            raw: vec![Counts::default()],
            folded: vec![Counts::default()],
        }
    }

    fn check(&self, s: Sym) {
        assert!(
            s.gen == self.gen,
            "Sym #{} belongs to a different Tracer than the one active on this thread ({NO_TRACER})",
            s.id
        );
    }

    fn sym(&self, id: u32) -> Sym {
        Sym { id, gen: self.gen }
    }

    fn set_section(&mut self, label: &'static str) {
        let n = self.section_names.len() as u32;
        let idx = *self.section_index.entry(label).or_insert(n);
        if idx == n {
            self.section_names.push(label.to_string());
            self.raw.push(Counts::default());
            self.folded.push(Counts::default());
        }
        self.current = idx;
    }

    fn raw(&mut self) -> &mut Counts {
        &mut self.raw[self.current as usize]
    }

    /// Interns a node (hash-consing); non-leaf nodes count as one folded operation.
    fn mk(&mut self, op: Op) -> u32 {
        self.folded[self.current as usize].bump(&op);
        self.intern(op)
    }

    fn intern(&mut self, op: Op) -> u32 {
        if let Some(&id) = self.table.get(&op) {
            return id;
        }
        let id = u32::try_from(self.ops.len()).expect("Sym graph exceeds u32::MAX nodes");
        self.ops.push(op);
        self.node_section.push(self.current);
        self.table.insert(op, id);
        id
    }

    fn constant(&mut self, x: f64) -> u32 {
        self.intern(Op::Const(norm_bits(x)))
    }

    fn input(&mut self, name: String) -> u32 {
        let idx = self.input_names.len() as u32;
        self.input_names.push(name);
        self.intern(Op::Input(idx))
    }

    fn cval(&self, id: u32) -> Option<f64> {
        match self.ops[id as usize] {
            Op::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    /// Whether node `id` is the constant `v`.
    fn is(&self, id: u32, v: f64) -> bool {
        self.cval(id) == Some(v)
    }

    /// `(negated, inner)`: strips one sign change (there is never more than one).
    fn strip(&self, id: u32) -> (bool, u32) {
        match self.ops[id as usize] {
            Op::Neg(x) => (true, x),
            _ => (false, id),
        }
    }

    fn neg(&mut self, a: u32) -> u32 {
        match self.ops[a as usize] {
            Op::Neg(x) => x,
            Op::Const(bits) => self.constant(-f64::from_bits(bits)),
            _ => self.mk(Op::Neg(a)),
        }
    }

    fn sign(&mut self, negate: bool, x: u32) -> u32 {
        if negate {
            self.neg(x)
        } else {
            x
        }
    }

    fn add_core(&mut self, a: u32, b: u32) -> u32 {
        self.mk(Op::Add(a.min(b), a.max(b)))
    }

    fn sub_core(&mut self, a: u32, b: u32) -> u32 {
        if a == b {
            self.constant(0.0)
        } else if a > b {
            // `a − b = −(b − a)` exactly: one node for both orders.
            let d = self.mk(Op::Sub(b, a));
            self.neg(d)
        } else {
            self.mk(Op::Sub(a, b))
        }
    }

    fn add(&mut self, a: u32, b: u32) -> u32 {
        if let (Some(x), Some(y)) = (self.cval(a), self.cval(b)) {
            return self.constant(x + y);
        }
        if self.is(a, 0.0) {
            return b;
        }
        if self.is(b, 0.0) {
            return a;
        }
        match (self.strip(a), self.strip(b)) {
            ((false, a), (false, b)) => self.add_core(a, b),
            ((false, a), (true, b)) => self.sub_core(a, b),
            ((true, a), (false, b)) => self.sub_core(b, a),
            ((true, a), (true, b)) => {
                let s = self.add_core(a, b);
                self.neg(s)
            }
        }
    }

    fn sub(&mut self, a: u32, b: u32) -> u32 {
        if let (Some(x), Some(y)) = (self.cval(a), self.cval(b)) {
            return self.constant(x - y);
        }
        if self.is(b, 0.0) {
            return a;
        }
        if self.is(a, 0.0) {
            return self.neg(b);
        }
        match (self.strip(a), self.strip(b)) {
            ((false, a), (false, b)) => self.sub_core(a, b),
            ((false, a), (true, b)) => self.add_core(a, b),
            ((true, a), (false, b)) => {
                let s = self.add_core(a, b);
                self.neg(s)
            }
            ((true, a), (true, b)) => self.sub_core(b, a),
        }
    }

    /// `(negated, id)` with a negative constant turned positive: `a·(−k)` and `a·k` are one
    /// product and a sign change (which the sums around it absorb), not two products.
    fn strip_sign(&mut self, id: u32) -> (bool, u32) {
        match self.cval(id) {
            Some(x) if x < 0.0 => (true, self.constant(-x)),
            _ => self.strip(id),
        }
    }

    fn mul(&mut self, a: u32, b: u32) -> u32 {
        if let (Some(x), Some(y)) = (self.cval(a), self.cval(b)) {
            return self.constant(x * y);
        }
        if self.is(a, 0.0) || self.is(b, 0.0) {
            return self.constant(0.0);
        }
        for (k, x) in [(a, b), (b, a)] {
            if self.is(k, 1.0) {
                return x;
            }
            if self.is(k, -1.0) {
                return self.neg(x);
            }
        }
        let (na, a) = self.strip_sign(a);
        let (nb, b) = self.strip_sign(b);
        let p = self.mk(Op::Mul(a.min(b), a.max(b)));
        self.sign(na != nb, p)
    }

    fn div(&mut self, a: u32, b: u32) -> u32 {
        if let (Some(x), Some(y)) = (self.cval(a), self.cval(b)) {
            return self.constant(x / y);
        }
        if self.is(b, 1.0) {
            return a;
        }
        if self.is(b, -1.0) {
            return self.neg(a);
        }
        if self.is(a, 0.0) {
            return self.constant(0.0);
        }
        let (na, a) = self.strip(a);
        let (nb, b) = self.strip(b);
        let q = self.mk(Op::Div(a, b));
        self.sign(na != nb, q)
    }

    fn unary(&mut self, a: u32, op: fn(u32) -> Op, f: fn(f64) -> f64) -> u32 {
        match self.cval(a) {
            Some(x) => self.constant(f(x)),
            None => self.mk(op(a)),
        }
    }

    /// Sine and/or cosine of `a`, counted as one trigonometric evaluation.
    fn trig(&mut self, a: u32, sin: bool, cos: bool) -> (u32, u32) {
        let raw = self.raw();
        raw.sin += u64::from(sin);
        raw.cos += u64::from(cos);
        raw.sincos += 1;
        if self.cval(a).is_none() {
            self.folded[self.current as usize].sincos += 1;
        }
        let s = if sin {
            self.unary(a, Op::Sin, f64::sin)
        } else {
            a
        };
        let c = if cos {
            self.unary(a, Op::Cos, f64::cos)
        } else {
            a
        };
        (s, c)
    }

    fn node(&self, id: u32) -> Node {
        let s = |i| self.sym(i);
        match self.ops[id as usize] {
            Op::Const(bits) => Node::Const(f64::from_bits(bits)),
            Op::Input(i) => Node::Input(i),
            Op::Add(a, b) => Node::Add(s(a), s(b)),
            Op::Sub(a, b) => Node::Sub(s(a), s(b)),
            Op::Mul(a, b) => Node::Mul(s(a), s(b)),
            Op::Div(a, b) => Node::Div(s(a), s(b)),
            Op::Neg(a) => Node::Neg(s(a)),
            Op::Sin(a) => Node::Sin(s(a)),
            Op::Cos(a) => Node::Cos(s(a)),
            Op::Sqrt(a) => Node::Sqrt(s(a)),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Tracer and Trace.

/// RAII guard of the thread's expression graph.
///
/// [`Tracer::new`] starts a fresh graph on this thread; [`Tracer::finish`] freezes it into a
/// [`Trace`]; dropping an unfinished tracer discards it. Only one tracer can be active per thread.
#[derive(Debug)]
pub struct Tracer {
    gen: u32,
    /// The graph lives in a thread-local: the tracer must stay on its thread.
    _not_send: PhantomData<*const ()>,
}

impl Tracer {
    /// Starts a fresh graph on this thread.
    ///
    /// # Panics
    /// If a tracer is already active on this thread.
    #[allow(clippy::new_without_default)]
    pub fn new() -> Tracer {
        GRAPH.with(|cell| {
            let mut b = cell.borrow_mut();
            assert!(b.is_none(), "a Tracer is already active on this thread");
            let g = Graph::new();
            let gen = g.gen;
            *b = Some(g);
            Tracer {
                gen,
                _not_send: PhantomData,
            }
        })
    }

    /// A named runtime input (a leaf). Each call makes a distinct input; [`Trace::eval`] takes the
    /// inputs' values in the order of these calls.
    pub fn input(&self, name: impl Into<String>) -> Sym {
        let name = name.into();
        with_graph(|g| {
            assert_eq!(g.gen, self.gen, "{NO_TRACER}");
            let id = g.input(name);
            g.sym(id)
        })
    }

    /// Freezes the graph with the given outputs.
    pub fn finish(self, outputs: &[Sym]) -> Trace {
        let g = GRAPH
            .with(|cell| cell.borrow_mut().take())
            .expect(NO_TRACER);
        assert_eq!(g.gen, self.gen, "{NO_TRACER}");
        for &o in outputs {
            g.check(o);
        }
        Trace {
            g,
            outputs: outputs.to_vec(),
        }
    }
}

impl Drop for Tracer {
    fn drop(&mut self) {
        // `try_with`: the thread-local may already be gone during thread teardown.
        let _ = GRAPH.try_with(|cell| {
            if let Ok(mut b) = cell.try_borrow_mut() {
                if b.as_ref().is_some_and(|g| g.gen == self.gen) {
                    *b = None;
                }
            }
        });
    }
}

/// Records `f` under a fresh [`Tracer`] and freezes the graph with the outputs it returns (the
/// low-level form of [`crate::trace`]).
pub fn record<F: FnOnce(&Tracer) -> Vec<Sym>>(f: F) -> Trace {
    let t = Tracer::new();
    let out = f(&t);
    t.finish(&out)
}

/// A frozen expression graph with its outputs and operation counts.
#[derive(Debug)]
pub struct Trace {
    g: Graph,
    outputs: Vec<Sym>,
}

impl Trace {
    /// Total counts under a convention.
    pub fn counts(&self, c: Convention) -> Counts {
        self.counts_by_section(c)
            .into_iter()
            .fold(Counts::default(), |acc, (_, x)| acc + x)
    }

    /// Counts per section, in order of first appearance of the section label. Operations before
    /// the first [`Scalar::section`] call go to the label `""`, which is listed only if any
    /// operation was recorded there.
    pub fn counts_by_section(&self, c: Convention) -> Vec<(String, Counts)> {
        let per = match c {
            Convention::Paper => self.g.raw.clone(),
            Convention::Folded => self.g.folded.clone(),
            Convention::Emitted => self.emitted(),
        };
        self.g
            .section_names
            .iter()
            .cloned()
            .zip(per)
            .enumerate()
            .filter(|(i, _)| *i != 0 || !self.g.raw[0].is_zero())
            .map(|(_, x)| x)
            .collect()
    }

    fn emitted(&self) -> Vec<Counts> {
        let mut per = vec![Counts::default(); self.g.section_names.len()];
        let mut trig_args = HashSet::new();
        let live = self.reachable();
        for (id, op) in self.g.ops.iter().enumerate() {
            if !live[id] {
                continue;
            }
            let sec = &mut per[self.g.node_section[id] as usize];
            sec.bump(op);
            if let Op::Sin(a) | Op::Cos(a) = op {
                if trig_args.insert(*a) {
                    sec.sincos += 1;
                }
            }
        }
        per
    }

    /// Marks the nodes reachable from the outputs (operands have smaller ids than their users, so
    /// one backward sweep suffices).
    fn reachable(&self) -> Vec<bool> {
        let mut live = vec![false; self.g.ops.len()];
        for o in &self.outputs {
            live[o.id as usize] = true;
        }
        for id in (0..self.g.ops.len()).rev() {
            if !live[id] {
                continue;
            }
            match self.g.ops[id] {
                Op::Const(_) | Op::Input(_) => {}
                Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) => {
                    live[a as usize] = true;
                    live[b as usize] = true;
                }
                Op::Neg(a) | Op::Sin(a) | Op::Cos(a) | Op::Sqrt(a) => live[a as usize] = true,
            }
        }
        live
    }

    /// The value of each output for the given input values (in creation order of
    /// [`Tracer::input`]). Each reachable node is evaluated once.
    ///
    /// # Panics
    /// If `inputs.len()` differs from the number of inputs of the trace.
    pub fn eval(&self, inputs: &[f64]) -> Vec<f64> {
        self.eval_with(inputs, f64::sin, f64::cos)
    }

    /// [`Trace::eval`] with sines and cosines by `sin` and `cos` (e.g. the generated code's
    /// table sine–cosine, to reproduce its results bit for bit).
    ///
    /// # Panics
    /// If `inputs.len()` differs from the number of inputs of the trace.
    pub fn eval_with(
        &self,
        inputs: &[f64],
        sin: impl Fn(f64) -> f64,
        cos: impl Fn(f64) -> f64,
    ) -> Vec<f64> {
        assert_eq!(
            inputs.len(),
            self.g.input_names.len(),
            "Trace::eval: expected {} input values ({:?}), got {}",
            self.g.input_names.len(),
            self.g.input_names,
            inputs.len()
        );
        let live = self.reachable();
        let mut v = vec![0.0f64; self.g.ops.len()];
        for (id, op) in self.g.ops.iter().enumerate() {
            if !live[id] {
                continue;
            }
            let x = |i: u32| v[i as usize];
            v[id] = match *op {
                Op::Const(bits) => f64::from_bits(bits),
                Op::Input(i) => inputs[i as usize],
                Op::Add(a, b) => x(a) + x(b),
                Op::Sub(a, b) => x(a) - x(b),
                Op::Mul(a, b) => x(a) * x(b),
                Op::Div(a, b) => x(a) / x(b),
                Op::Neg(a) => -x(a),
                Op::Sin(a) => sin(x(a)),
                Op::Cos(a) => cos(x(a)),
                Op::Sqrt(a) => x(a).sqrt(),
            };
        }
        self.outputs.iter().map(|o| v[o.id as usize]).collect()
    }

    /// Names of the inputs, in creation order.
    pub fn input_names(&self) -> &[String] {
        &self.g.input_names
    }

    /// The outputs given to [`Tracer::finish`].
    pub fn outputs(&self) -> &[Sym] {
        &self.outputs
    }

    /// The nodes reachable from the outputs (leaves included), in dependency order: every
    /// operand precedes its users.
    pub fn schedule(&self) -> Vec<(u32, Node)> {
        let live = self.reachable();
        (0..self.g.ops.len() as u32)
            .filter(|&id| live[id as usize])
            .map(|id| (id, self.g.node(id)))
            .collect()
    }

    /// The node behind `s`.
    ///
    /// # Panics
    /// If `s` does not belong to this trace.
    pub fn node(&self, s: Sym) -> Node {
        self.g.check(s);
        self.g.node(s.id)
    }

    /// Number of nodes in the graph (reachable or not, leaves included).
    pub fn num_nodes(&self) -> usize {
        self.g.ops.len()
    }

    /// The section labels, in order of first appearance (index 0 is the unlabelled `""`).
    pub fn section_names(&self) -> &[String] {
        &self.g.section_names
    }
}

// ---------------------------------------------------------------------------------------------
// Arithmetic.

macro_rules! binop {
    ($trait:ident, $method:ident, $field:ident) => {
        impl $trait for Sym {
            type Output = Sym;
            fn $method(self, o: Sym) -> Sym {
                with_graph(|g| {
                    g.check(self);
                    g.check(o);
                    g.raw().$field += 1;
                    let id = g.$method(self.id, o.id);
                    g.sym(id)
                })
            }
        }
    };
}
binop!(Add, add, add);
binop!(Sub, sub, add);
binop!(Mul, mul, mul);
binop!(Div, div, div);

impl Neg for Sym {
    type Output = Sym;
    fn neg(self) -> Sym {
        with_graph(|g| {
            g.check(self);
            g.raw().neg += 1;
            let id = g.neg(self.id);
            g.sym(id)
        })
    }
}

impl Symbolic for Sym {}

impl Scalar for Sym {
    fn constant(x: f64) -> Self {
        with_graph(|g| {
            let id = g.constant(x);
            g.sym(id)
        })
    }

    fn sin(self) -> Self {
        with_graph(|g| {
            g.check(self);
            let (s, _) = g.trig(self.id, true, false);
            g.sym(s)
        })
    }

    fn cos(self) -> Self {
        with_graph(|g| {
            g.check(self);
            let (_, c) = g.trig(self.id, false, true);
            g.sym(c)
        })
    }

    fn sqrt(self) -> Self {
        with_graph(|g| {
            g.check(self);
            g.raw().sqrt += 1;
            let id = g.unary(self.id, Op::Sqrt, f64::sqrt);
            g.sym(id)
        })
    }

    fn sin_cos(self) -> (Self, Self) {
        with_graph(|g| {
            g.check(self);
            let (s, c) = g.trig(self.id, true, true);
            (g.sym(s), g.sym(c))
        })
    }

    fn section(label: &'static str) {
        with_graph(|g| g.set_section(label));
    }
}
