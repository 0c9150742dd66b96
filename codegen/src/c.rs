//! C99 output: one header of `static inline` functions holding every function of the Rust output
//! (not the `_lanes` and `_batch` forms), printed from the same plan and the same traced graphs
//! by the same graph walk ([`crate::emit::emit_graph`]) in C syntax ([`CSyntax`]): the same
//! operations in the same order, the same names (`PREFIX_mass_matrix`, …), the same doc header.
//!
//! - Signatures are plain arrays, inputs `const`, outputs last as out-parameters, row-major (row
//!   `i` = output `i`): `void ur5_mass_matrix(const double q[6], double m[6][6]);`. A runtime
//!   payload is a `const PREFIX_payload *payload` argument after the inputs.
//! - `float` code for [`Float::F32`]: `float` arrays, `f`-suffixed constants, `sqrtf`, `fmaf`,
//!   `sinf`, `cosf`.
//! - Fused multiply-adds as in Rust: with [`Options::fma`], `fma(a, b, c)` of `<math.h>`
//!   always; with [`Options::target_fma`] (the default), `PREFIX_mul_add(a, b, c)`, which is
//!   `fma` where `<math.h>` defines `FP_FAST_FMA` (the target has the instruction) and `a * b +
//!   c` otherwise, like `S::mul_add`.
//! - The sine–cosine of `f64` code is the runtime's (`kanegen_runtime::sincos`) as a `static
//!   inline PREFIX_sincos_n`, its table and constants printed from the runtime's (bit for bit the
//!   same results on `|x| < 32768`; beyond, `sin` and `cos` of `<math.h>` where Rust calls
//!   `libm::sincos`).
//! - Nothing allocates; the only library is `<math.h>` (and the header `<stdint.h>` for the
//!   sine–cosine's table index).
//!
//! C has no loops of its own: the plan is made straight-line ([`Form::Unrolled`]), where the
//! Rust output of a large model takes the compact form (and emits derivatives in loops or
//! composed); past [`MAX_JOINTS`] joints only when asked for (`form = "unrolled"`). The derivative functions are generated up to
//! [`crate::plan::DERIVATIVES_MAX_NV`] speeds, as in Rust's `form = "unrolled"`. Asking for the
//! compact form, or for an `fma_path` (a Rust path), is an error.
//!
//! Results are bit-identical to the Rust functions of the same plan when both fuse the same
//! products (C compiled without contraction of `a * b + c`: GCC's default in ISO mode, `-std=c99`;
//! `-ffp-contract=off` otherwise).

use crate::emit::{emit_graph, BinOp, Emitter, Expr, Fuse, Shape, Syntax};
use crate::header;
use crate::options::{Error, Float, Form, Options};
use crate::plan::{FunctionPlan, Kernel, Plan};
use kanegen_model::Model;
use kanegen_trace::{Arg, Function, Input, PayloadField};
use std::fmt::Write;

/// C's reserved words and the `<math.h>` names a prefix or a frame's function must not take.
const RESERVED: &[&str] = &[
    "auto",
    "break",
    "case",
    "char",
    "const",
    "continue",
    "default",
    "do",
    "double",
    "else",
    "enum",
    "extern",
    "float",
    "for",
    "goto",
    "if",
    "inline",
    "int",
    "long",
    "register",
    "restrict",
    "return",
    "short",
    "signed",
    "sizeof",
    "static",
    "struct",
    "switch",
    "typedef",
    "union",
    "unsigned",
    "void",
    "volatile",
    "while",
    "_Bool",
    "_Complex",
    "_Imaginary",
];

/// The C prefix for a generated type name: `Ssrms` → `ssrms`, `SsrmsF32` → `ssrms_f32`.
#[must_use]
pub fn prefix(type_name: &str) -> String {
    let mut s = String::new();
    let mut prev_lower = false;
    for c in type_name.chars() {
        if c.is_ascii_uppercase() && prev_lower {
            s.push('_');
        }
        prev_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        s.push(c.to_ascii_lowercase());
    }
    s
}

/// Checks that `prefix` is a C identifier and not a reserved word.
fn check_prefix(prefix: &str) -> Result<(), Error> {
    let ok = prefix
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && prefix
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok || RESERVED.contains(&prefix) {
        return Err(Error(format!(
            "C prefix `{prefix}` is not a C identifier (letters, digits and `_`, not starting \
             with a digit, not a reserved word): give another name"
        )));
    }
    Ok(())
}

/// The C types and `<math.h>` names of one precision.
#[derive(Clone, Copy, Debug)]
struct CFloat(Float);

impl CFloat {
    fn ty(self) -> &'static str {
        match self.0 {
            Float::F64 => "double",
            Float::F32 => "float",
        }
    }
    /// `sqrt` or `sqrtf`.
    fn math(self, base: &str) -> String {
        match self.0 {
            Float::F64 => base.to_string(),
            Float::F32 => format!("{base}f"),
        }
    }
    /// `FP_FAST_FMA` or `FP_FAST_FMAF`.
    fn fast_fma(self) -> &'static str {
        match self.0 {
            Float::F64 => "FP_FAST_FMA",
            Float::F32 => "FP_FAST_FMAF",
        }
    }
    /// A constant: the shortest decimal that reads back as the value (`f`-suffixed in `float`
    /// code), `NAN`, `INFINITY`, `-INFINITY`.
    fn literal(self, x: f64) -> String {
        if x.is_nan() {
            return "NAN".into();
        }
        if x.is_infinite() {
            return if x > 0.0 { "INFINITY" } else { "-INFINITY" }.into();
        }
        match self.0 {
            Float::F64 => format!("{x:?}"),
            Float::F32 => {
                let v = x as f32;
                if v.is_infinite() {
                    return if v > 0.0 { "INFINITY" } else { "-INFINITY" }.into();
                }
                format!("{v:?}f")
            }
        }
    }
}

/// C99 text of one graph's statements and expressions ([`Syntax`]).
#[derive(Clone, Debug)]
pub struct CSyntax {
    float: CFloat,
    prefix: String,
}

/// The indentation of a function's statements.
const IND: &str = "    ";

impl Syntax for CSyntax {
    type Code = String;
    fn constant(&self, x: f64) -> String {
        self.float.literal(x)
    }
    fn input(&self, input: &Input) -> String {
        match input {
            Input::Joint(a, i) => format!("{}[{i}]", a.name()),
            Input::Row(a, r, c) => format!("{}[{r}][{c}]", a.name()),
            Input::Payload(PayloadField::Mass) => "payload->mass".into(),
            Input::Payload(PayloadField::Com(k)) => format!("payload->com[{k}]"),
            Input::Payload(PayloadField::Inertia(r, c)) => format!("payload->inertia[{r}][{c}]"),
            other => other.to_string().replace(['[', ']', '.'], "_"),
        }
    }
    fn name(&self, name: &str) -> String {
        name.to_string()
    }
    fn paren(&self, e: String) -> String {
        format!("({e})")
    }
    fn binary(&self, a: String, op: BinOp, b: String) -> String {
        let op = match op {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
        };
        format!("{a} {op} {b}")
    }
    fn neg(&self, e: &Expr<String>) -> String {
        if e.is_atom() && !e.tokens.starts_with('-') {
            format!("(-{})", e.tokens)
        } else {
            format!("(-({}))", e.tokens)
        }
    }
    fn sqrt(&self, e: String) -> String {
        format!("{}({e})", self.float.math("sqrt"))
    }
    fn fma(&self, fuse: &Fuse, a: String, b: String, c: String) -> String {
        match fuse {
            Fuse::Target => format!("{}_mul_add({a}, {b}, {c})", self.prefix),
            // A Rust path is refused before ([`check_options`]).
            Fuse::Libm | Fuse::Path(_) => format!("{}({a}, {b}, {c})", self.float.math("fma")),
        }
    }
    fn bind(&self, name: &str, e: String) -> String {
        format!("{IND}const {} {name} = {e};\n", self.float.ty())
    }
    fn sincos_table(
        &self,
        _fused: bool,
        names: &[(Option<String>, Option<String>)],
        angles: Vec<String>,
    ) -> String {
        let (ty, p) = (self.float.ty(), &self.prefix);
        let mut s = String::new();
        if let ([(sn, cn)], [a]) = (names, &angles[..]) {
            // One angle (not an input's): bound in a block of its own.
            let scratch = "sc_unused";
            let decl: Vec<&str> = [sn, cn].iter().filter_map(|n| n.as_deref()).collect();
            if decl.is_empty() {
                return s;
            }
            let _ = writeln!(s, "{IND}{ty} {};", decl.join(", "));
            let (ps, pc) = (
                sn.as_deref().unwrap_or(scratch),
                cn.as_deref().unwrap_or(scratch),
            );
            let unused = if sn.is_none() || cn.is_none() {
                format!(" {ty} {scratch};")
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "{IND}{{ const {ty} sc_a = {a};{unused} {p}_sincos_n(1, &sc_a, &{ps}, &{pc}); }}"
            );
            return s;
        }
        let k = angles.len();
        let _ = writeln!(s, "{IND}const {ty} sc_x[{k}] = {{{}}};", angles.join(", "));
        let _ = writeln!(s, "{IND}{ty} sc_s[{k}], sc_c[{k}];");
        let _ = writeln!(s, "{IND}{p}_sincos_n({k}, sc_x, sc_s, sc_c);");
        for (i, (sn, cn)) in names.iter().enumerate() {
            for (n, arr) in [(sn, "sc_s"), (cn, "sc_c")] {
                if let Some(n) = n {
                    let _ = writeln!(s, "{IND}const {ty} {n} = {arr}[{i}];");
                }
            }
        }
        s
    }
    fn sincos_libm(&self, sin: Option<&str>, cos: Option<&str>, angle: String) -> String {
        let ty = self.float.ty();
        let (fs, fc) = (self.float.math("sin"), self.float.math("cos"));
        match (sin, cos) {
            (Some(s), Some(c)) => format!(
                "{IND}{ty} {s}, {c};\n{IND}{{ const {ty} sc_a = {angle}; {s} = {fs}(sc_a); {c} = \
                 {fc}(sc_a); }}\n"
            ),
            (Some(s), None) => self.bind(s, format!("{fs}({angle})")),
            (None, Some(c)) => self.bind(c, format!("{fc}({angle})")),
            (None, None) => String::new(),
        }
    }
}

/// The names of a function's out-parameters, one per part of its [`Shape`].
fn output_names(f: Function, floating: bool) -> &'static [&'static str] {
    match f {
        Function::MassMatrix => &["m"],
        Function::MassMatrixInverse => &["minv"],
        Function::NonlinearEffects => &["c"],
        Function::Gravity => &["g"],
        Function::InverseDynamics => &["tau"],
        Function::ForwardDynamics | Function::ForwardDynamicsWithWrenches if floating => &["a"],
        Function::ForwardDynamics | Function::ForwardDynamicsWithWrenches => &["qdd"],
        Function::MassMatrixAndNonlinearEffects => &["m", "c"],
        Function::Momentum => &["h"],
        Function::BaseReaction => &["wrench"],
        Function::FramePlacement(_) => &["translation", "rotation"],
        Function::FrameJacobian(_) | Function::GeneralizedJacobian(_) => &["j"],
        Function::InverseDynamicsDerivatives => &["dtau_dq", "dtau_dv"],
        Function::ForwardDynamicsDerivatives => &["dqdd_dq", "dqdd_dv", "minv"],
        Function::GeneralizedForces => &["out"],
    }
}

/// The out-parameter declarations of `shape` named `names`, and the C lvalue of each output
/// of the trace in order (a symmetric matrix's upper-triangle entry: both of its places).
fn outputs(shape: Shape, names: &[&str], ty: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let sym = |m: &str, n: usize, at: &mut Vec<Vec<String>>| {
        for i in 0..n {
            for j in i..n {
                let mut places = vec![format!("{m}[{i}][{j}]")];
                if i != j {
                    places.push(format!("{m}[{j}][{i}]"));
                }
                at.push(places);
            }
        }
    };
    let dense = |m: &str, r: usize, c: usize, at: &mut Vec<Vec<String>>| {
        for i in 0..r {
            for j in 0..c {
                at.push(vec![format!("{m}[{i}][{j}]")]);
            }
        }
    };
    let vector = |m: &str, n: usize, at: &mut Vec<Vec<String>>| {
        at.extend((0..n).map(|i| vec![format!("{m}[{i}]")]));
    };
    let mut at = Vec::new();
    let decls = match shape {
        Shape::Vector(n) => {
            vector(names[0], n, &mut at);
            vec![format!("{ty} {}[{n}]", names[0])]
        }
        Shape::SymMatrix(n) => {
            sym(names[0], n, &mut at);
            vec![format!("{ty} {}[{n}][{n}]", names[0])]
        }
        Shape::SymMatrixAndVector(n) => {
            sym(names[0], n, &mut at);
            vector(names[1], n, &mut at);
            vec![
                format!("{ty} {}[{n}][{n}]", names[0]),
                format!("{ty} {}[{n}]", names[1]),
            ]
        }
        Shape::Matrix(r, c) => {
            dense(names[0], r, c, &mut at);
            vec![format!("{ty} {}[{r}][{c}]", names[0])]
        }
        Shape::Matrices(k, n) => (0..k)
            .map(|m| {
                dense(names[m], n, n, &mut at);
                format!("{ty} {}[{n}][{n}]", names[m])
            })
            .collect(),
        Shape::Placement => {
            vector(names[0], 3, &mut at);
            dense(names[1], 3, 3, &mut at);
            vec![
                format!("{ty} {}[3]", names[0]),
                format!("{ty} {}[3][3]", names[1]),
            ]
        }
    };
    (decls, at)
}

/// Most joints C output takes under [`Form::Auto`]: its code is straight-line at any size
/// (a random 64-joint chain: 5.8 MB of header in 3.3 s), where the Rust output of a large model
/// is the compact form. `form = "unrolled"` (`kanegen generate --lang c --allow-large`) prints a
/// larger model straight-line all the same.
pub const MAX_JOINTS: usize = 64;

/// Why `opts` cannot be printed in C, if so.
fn check_options(opts: &Options) -> Result<(), Error> {
    if opts.form == Form::Compact {
        return Err(Error(
            "C output does not support the compact form yet: C is straight-line only (use \
             form \"unrolled\" or \"auto\")"
                .into(),
        ));
    }
    if let (true, Some(p)) = (opts.fma, &opts.fma_path) {
        return Err(Error(format!(
            "C output calls `fma` of <math.h>: an fma path (`{p}`) is for Rust output only"
        )));
    }
    Ok(())
}

/// The C header for `model` under `opts`: its functions and types named `PREFIX_…`, an include
/// guard `KANEGEN_PREFIX_H` ([module docs](self)).
///
/// # Errors
/// A prefix that is not a C identifier, the compact form or an fma path asked for, a model the
/// functions cannot be generated for, or a function that cannot be traced.
pub fn generate(model: &Model, opts: &Options, prefix: &str) -> Result<String, Error> {
    check_prefix(prefix)?;
    check_options(opts)?;
    crate::check_generable(model)?;
    let n = model.coordinate_count();
    if opts.form == Form::Auto && n > MAX_JOINTS {
        return Err(Error(format!(
            "C output is straight-line only, and N = {n} is past the {MAX_JOINTS} joints it takes \
             by default (the Rust output of a model this size is the compact form, loops, which \
             C does not print yet): form \"unrolled\" (`--allow-large`) prints it straight-line \
             all the same"
        )));
    }
    let mut opts = opts.clone();
    opts.form = Form::Unrolled;
    let emitter = Emitter::new(&opts)?;
    let (mut plan, graphs) = Plan::new(model, &opts)?;
    plan.decision.line = plan
        .decision
        .line
        .replace("(asked for)", "(C output: straight-line for every model)");
    let syntax = CSyntax {
        float: CFloat(opts.float),
        prefix: prefix.to_string(),
    };
    let mut fns = String::new();
    let mut fmas = Vec::new();
    for (fp, graph) in plan.functions.iter().zip(graphs) {
        let graph = match (fp.kernel, graph) {
            (Kernel::Unrolled, Some(g)) => g,
            _ => {
                return Err(Error(format!(
                    "C output does not support the compact form yet (N = {}): `{}` has no \
                     straight-line body",
                    plan.model.coordinate_count(),
                    fp.name
                )))
            }
        };
        let (decls, places) = outputs(
            fp.shape,
            output_names(fp.function, plan.floating()),
            syntax.float.ty(),
        );
        let mut body = String::new();
        let (out, k) = emit_graph(&graph, &emitter, &syntax, &mut |s| body.push_str(&s));
        drop(graph);
        for (e, places) in out.iter().zip(&places) {
            for p in places {
                let _ = writeln!(body, "{IND}{p} = {e};");
            }
        }
        fmas.push(k);
        function_text(&mut fns, &plan, fp, &opts, &syntax, k, &decls, &body);
    }
    let header = header::c_lines(&plan, &opts, &fmas, prefix);
    Ok(file_text(&plan, &opts, &syntax, &header, &fns))
}

/// Appends one function: its doc comment, signature and body.
#[allow(clippy::too_many_arguments)]
fn function_text(
    out: &mut String,
    plan: &Plan,
    fp: &FunctionPlan,
    opts: &Options,
    syntax: &CSyntax,
    fmas: u64,
    out_decls: &[String],
    body: &str,
) {
    let (doc1, doc2) = crate::function_docs(plan, fp, fmas, opts);
    let ty = syntax.float.ty();
    let p = &syntax.prefix;
    let mut params: Vec<String> = fp
        .args
        .iter()
        .map(|(a, len)| match a {
            Arg::FExt => format!("const {ty} {}[{len}][6]", a.name()),
            _ => format!("const {ty} {}[{len}]", a.name()),
        })
        .collect();
    if opts.runtime_payload {
        params.push(format!("const {p}_payload *payload"));
    }
    params.extend(out_decls.iter().cloned());
    let _ = writeln!(out);
    comment(
        out,
        "",
        &[
            doc1.trim().to_string(),
            String::new(),
            doc2.trim().to_string(),
        ],
    );
    let _ = writeln!(
        out,
        "static inline void {p}_{}({}) {{",
        fp.name,
        params.join(", ")
    );
    for (a, _) in &fp.args {
        let _ = writeln!(out, "{IND}(void){};", a.name());
    }
    if opts.runtime_payload {
        let _ = writeln!(out, "{IND}(void)payload;");
    }
    out.push_str(body);
    out.push_str("}\n");
}

/// `lines` as `//` comments at `indent`, wrapped at 100 columns.
fn comment(out: &mut String, indent: &str, lines: &[String]) {
    for l in lines {
        if l.is_empty() {
            let _ = writeln!(out, "{indent}//");
            continue;
        }
        if l.starts_with('|') {
            // A table row stays one line.
            let _ = writeln!(out, "{indent}// {}", l.trim_end_matches('\\'));
            continue;
        }
        let mut line = String::new();
        for w in l.split(' ') {
            if !line.is_empty() && indent.len() + 3 + line.len() + 1 + w.len() > 100 {
                let _ = writeln!(out, "{indent}// {line}");
                line.clear();
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(w);
        }
        // A trailing backslash would continue the comment onto the next line.
        let line = line.trim_end_matches('\\');
        let _ = writeln!(out, "{indent}// {line}");
    }
}

/// The whole header around the functions `fns`.
fn file_text(
    plan: &Plan,
    opts: &Options,
    syntax: &CSyntax,
    header: &[String],
    fns: &str,
) -> String {
    let p = &syntax.prefix;
    let upper = p.to_ascii_uppercase();
    let model = &plan.model;
    let n = model.coordinate_count();
    let mut s = String::new();
    comment(&mut s, "", header);
    let _ = writeln!(
        s,
        "//\n// C99, header-only: every function `static inline`; no allocation; <math.h> only."
    );
    let _ = writeln!(s, "#ifndef KANEGEN_{upper}_H\n#define KANEGEN_{upper}_H\n");
    let _ = writeln!(s, "#include <math.h>");
    let trig = opts.table_sincos() && crate::choose::takes_trig(plan.choices());
    if trig {
        let _ = writeln!(s, "#include <stdint.h>");
    }
    let _ = writeln!(s, "\n/* Degrees of freedom. */\n#define {upper}_N {n}");
    if plan.floating() {
        let _ = writeln!(
            s,
            "/* Length of `q`: base position (3), quaternion x, y, z, w (4), joints. */\n\
             #define {upper}_NQ {}\n/* Length of `v`: base linear and angular velocity, joint \
             rates. */\n#define {upper}_NV {}",
            n + 7,
            n + 6
        );
    }
    let joints: Vec<String> = model
        .coordinates()
        .iter()
        .map(|&j| header::doc_safe(&model.joints()[j].name))
        .collect();
    comment(
        &mut s,
        "",
        &[format!(
            "Joints, in the order of `q`: {}.",
            joints.join(", ")
        )],
    );
    if opts.runtime_payload {
        s.push_str(&payload_text(model, syntax));
    }
    if !opts.fma && opts.target_fma {
        s.push_str(&mul_add_text(syntax));
    }
    if trig {
        s.push_str(&sincos_text(syntax, !opts.fma && opts.target_fma));
    }
    s.push_str(fns);
    let _ = writeln!(s, "\n#endif /* KANEGEN_{upper}_H */");
    s
}

/// The payload struct and its nominal value (a macro: an initializer).
fn payload_text(model: &Model, syntax: &CSyntax) -> String {
    let (p, ty, f) = (&syntax.prefix, syntax.float.ty(), syntax.float);
    let Some(last) = model.joints().last() else {
        return String::new();
    };
    let i = &last.inertial;
    let lit = |x: f64| f.literal(x);
    let com: Vec<String> = i.com.iter().map(|&x| lit(x)).collect();
    let rows: Vec<String> = i
        .inertia
        .iter()
        .map(|r| {
            let r: Vec<String> = r.iter().map(|&x| lit(x)).collect();
            format!("{{{}}}", r.join(", "))
        })
        .collect();
    format!(
        "\n/* Mass properties of the payload, the last body (`{}`, moved by joint `{}`): mass \
         (kg), centre of mass in the body frame (m), inertia about the centre of mass in body \
         axes (kg m^2; only the upper triangle is read). */\ntypedef struct {{\n{IND}{ty} mass;\n\
         {IND}{ty} com[3];\n{IND}{ty} inertia[3][3];\n}} {p}_payload;\n\n/* The payload of the \
         model file, as an initializer: `{p}_payload p = {}_PAYLOAD_NOMINAL;`. */\n#define \
         {}_PAYLOAD_NOMINAL {{{}, {{{}}}, {{{}}}}}\n",
        header::doc_safe(&last.body).replace("*/", "* /"),
        header::doc_safe(&last.name).replace("*/", "* /"),
        p.to_ascii_uppercase(),
        p.to_ascii_uppercase(),
        lit(i.mass),
        com.join(", "),
        rows.join(", ")
    )
}

/// `PREFIX_mul_add`: `fma` where the target has the instruction, `a * b + c` otherwise.
fn mul_add_text(syntax: &CSyntax) -> String {
    let (p, ty, f) = (&syntax.prefix, syntax.float.ty(), syntax.float);
    format!(
        "\n/* a * b + c: one fused instruction (`{fma}`) where <math.h> defines `{fast}`, two \
         roundings otherwise. */\nstatic inline {ty} {p}_mul_add({ty} a, {ty} b, {ty} c) {{\n\
         #ifdef {fast}\n{IND}return {fma}(a, b, c);\n#else\n{IND}return a * b + c;\n#endif\n}}\n",
        fma = f.math("fma"),
        fast = f.fast_fma(),
    )
}

/// `PREFIX_sincos_n`: the runtime's table sine–cosine (`kanegen_runtime::sincos`), its table
/// and constants printed from the runtime's; `fused`: its products by `PREFIX_mul_add`.
fn sincos_text(syntax: &CSyntax, fused: bool) -> String {
    use kanegen_runtime::sincos as rt;
    let p = &syntax.prefix;
    let lit = |x: f64| CFloat(Float::F64).literal(x);
    let table: Vec<String> = rt::SIN_TABLE.iter().map(|&x| lit(x)).collect();
    let table = table
        .chunks(4)
        .map(|c| format!("{IND}{},", c.join(", ")))
        .collect::<Vec<_>>()
        .join("\n");
    let ma = if fused {
        format!("{p}_mul_add(a, b, c)")
    } else {
        "a * b + c".to_string()
    };
    format!(
        r"
/* sin(k pi/128), k = 0, ..., 127, correctly rounded (kanegen_runtime::sincos::SIN_TABLE). */
static const double {p}_sin_table[128] = {{
{table}
}};

/* a * b + c as the sine-cosine takes it. */
static inline double {p}_sincos_ma(double a, double b, double c) {{
    return {ma};
}}

/* sin(k pi/128) for k mod 256 (bit 7: the half turn, a sign). */
static inline double {p}_sin_step(unsigned k) {{
    union {{ double d; uint64_t u; }} v;
    v.d = {p}_sin_table[k & 127u];
    v.u ^= (uint64_t)(k & 128u) << 56;
    return v.d;
}}

/* (sin x, cos x) of n angles (kanegen_runtime::sincos::sincos_n): x = k pi/128 + r, r by
   Cody and Waite's two-part pi/128, Taylor polynomials of sin r and cos r, the table for
   k pi/128, the angle sums; branch-free for |x| < {limit}, sin and cos of <math.h> for all n
   angles if one is beyond. */
static inline void {p}_sincos_n(int n, const double *x, double *s, double *c) {{
    int i, fast = 1;
    for (i = 0; i < n; i++) {{
        fast &= x[i] > -{limit} && x[i] < {limit};
    }}
    if (!fast) {{
        for (i = 0; i < n; i++) {{
            s[i] = sin(x[i]);
            c[i] = cos(x[i]);
        }}
        return;
    }}
    for (i = 0; i < n; i++) {{
        union {{ double d; uint64_t u; }} t;
        double k, r_hi, r, r2, r3, p_s, sin_r, p_c6, p_c, cos_r, sin_a, cos_a;
        unsigned j;
        t.d = {p}_sincos_ma(x[i], {steps}, {shift});
        k = t.d - {shift};
        r_hi = {p}_sincos_ma(-k, {hi}, x[i]);
        r = {p}_sincos_ma(-k, {lo}, r_hi);
        r2 = r * r;
        r3 = r * r2;
        p_s = {p}_sincos_ma(r2, {s5}, {s3});
        sin_r = {p}_sincos_ma(r3, p_s, r);
        p_c6 = {p}_sincos_ma(r2, {c6}, {c4});
        p_c = {p}_sincos_ma(r2, p_c6, {c2});
        cos_r = {p}_sincos_ma(r2, p_c, 1.0);
        j = (unsigned)(t.u & 255u);
        sin_a = {p}_sin_step(j);
        cos_a = {p}_sin_step(j + 64u);
        s[i] = {p}_sincos_ma(sin_a, cos_r, cos_a * sin_r);
        c[i] = {p}_sincos_ma(cos_a, cos_r, -(sin_a * sin_r));
    }}
}}
",
        limit = lit(rt::LIMIT),
        steps = lit(rt::STEPS_PER_RAD),
        shift = lit(rt::ROUND_SHIFT),
        hi = lit(rt::STEP_HI),
        lo = lit(rt::STEP_LO),
        s3 = lit(rt::S3),
        s5 = lit(rt::S5),
        c2 = lit(rt::C2),
        c4 = lit(rt::C4),
        c6 = lit(rt::C6),
    )
}
