//! `kanegen count MODEL`: operation counts of A and b for one model, per algorithm and convention.

use kanegen_core::linalg::Vec3;
use kanegen_core::sym::{Convention, Counts, Sym, Trace, Tracer};
use kanegen_core::{Algorithm, Chain, Loads};
use serde::Serialize;

/// One line of the report (the JSON contract).
#[derive(Clone, Debug, Serialize)]
pub struct CountLine {
    /// Algorithm name.
    pub algorithm: String,
    /// `mass_matrix` or `bias`.
    pub function: String,
    /// `paper`, `folded` or `emitted`.
    pub convention: String,
    /// Multiplications.
    pub mul: u64,
    /// Additions and subtractions.
    pub add: u64,
    /// Divisions.
    pub div: u64,
    /// Square roots.
    pub sqrt: u64,
    /// Angles whose sine and/or cosine is taken.
    pub sincos: u64,
}

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct CountReport {
    /// Model name.
    pub model: String,
    /// Degrees of freedom.
    pub n: usize,
    /// Whether gravity was included in `bias`.
    pub gravity: bool,
    /// One line per algorithm, function and convention.
    pub counts: Vec<CountLine>,
}

/// Traces `A(q)` of `alg` for `chain` (model numbers as constants, `q` as inputs); outputs are the
/// upper triangle.
pub fn trace_mass_matrix(chain: &Chain, alg: Algorithm) -> Trace {
    let t = Tracer::new();
    let p = chain.params::<Sym>();
    let q: Vec<Sym> = chain
        .joints()
        .iter()
        .map(|j| t.input(format!("q_{}", j.name)))
        .collect();
    let a = alg.mass_matrix(&p, &q);
    let out: Vec<Sym> = a
        .iter()
        .enumerate()
        .flat_map(|(i, r)| r[i..].to_vec())
        .collect();
    t.finish(&out)
}

/// Traces `b(q, q̇, τ)` of `alg` (gravity when given).
pub fn trace_bias(chain: &Chain, alg: Algorithm, gravity: Option<[f64; 3]>) -> Trace {
    let t = Tracer::new();
    let p = chain.params::<Sym>();
    let names: Vec<&str> = chain.joints().iter().map(|j| j.name.as_str()).collect();
    let q: Vec<Sym> = names.iter().map(|n| t.input(format!("q_{n}"))).collect();
    let qd: Vec<Sym> = names.iter().map(|n| t.input(format!("qd_{n}"))).collect();
    let tau: Vec<Sym> = names.iter().map(|n| t.input(format!("tau_{n}"))).collect();
    let loads = Loads {
        tau: Some(tau),
        gravity: gravity.map(Vec3::from_f64),
        external: Vec::new(),
    };
    let b = alg.bias(&p, &q, &qd, &loads);
    t.finish(&b)
}

fn line(alg: Algorithm, function: &str, conv: Convention, c: Counts) -> CountLine {
    CountLine {
        algorithm: alg.name().into(),
        function: function.into(),
        convention: conv.name().into(),
        mul: c.mul,
        add: c.add,
        div: c.div,
        sqrt: c.sqrt,
        sincos: c.sincos,
    }
}

/// Counts for every requested algorithm.
pub fn count(chain: &Chain, algorithms: &[Algorithm], gravity: Option<[f64; 3]>) -> CountReport {
    let mut counts = Vec::new();
    for &alg in algorithms {
        for (function, trace) in [
            ("mass_matrix", trace_mass_matrix(chain, alg)),
            ("bias", trace_bias(chain, alg, gravity)),
        ] {
            for conv in Convention::ALL {
                counts.push(line(alg, function, conv, trace.counts(conv)));
            }
        }
    }
    CountReport {
        model: chain.name().into(),
        n: chain.dof(),
        gravity: gravity.is_some(),
        counts,
    }
}

/// Human-readable table.
pub fn render_text(r: &CountReport) -> String {
    use std::fmt::Write;
    let mut s = format!(
        "model {} (N = {}), gravity {}\n\n{:<14} {:<12} {:<9} {:>8} {:>8} {:>8} {:>5} {:>5} {:>7}\n",
        r.model,
        r.n,
        if r.gravity { "on" } else { "off" },
        "algorithm",
        "function",
        "conv.",
        "mul",
        "add",
        "m+a",
        "div",
        "sqrt",
        "sincos"
    );
    for c in &r.counts {
        let _ = writeln!(
            s,
            "{:<14} {:<12} {:<9} {:>8} {:>8} {:>8} {:>5} {:>5} {:>7}",
            c.algorithm,
            c.function,
            c.convention,
            c.mul,
            c.add,
            c.mul + c.add,
            c.div,
            c.sqrt,
            c.sincos
        );
    }
    s
}
