//! Table 1 of the paper reproduced by tracing (`kanegen table1`).
//!
//! Each algorithm's mass-matrix part is traced on [`Sym`] for `N = 1..=12` over chains with general
//! geometry and inertia: the base-frame inputs `r_{j−1,j}`, `a_j`, `m_j`, `c_j`, `I_j` (the paper's
//! Table 1 starts from them, `docs/paper.md`, "Operation counts") are all independent symbolic inputs, so no
//! count depends on a particular model's zeros. The `spatial` algorithm works in local frames and
//! is traced from `q` with every model parameter symbolic, so its count includes the kinematics.
//!
//! The operations are attributed to Table 1 rows by the equation sections the algorithm files mark
//! (`S::section("(14b)")`), exact polynomials in `N` are fitted to every row and total, and each fit
//! is checked at values of `N` not used for it.

use crate::entry::trace;
use crate::function::Function;
use crate::poly::{fit_exact, Fit, Poly};
use crate::spec::{Spec, Subject};
use crate::sym::{Convention, Counts, Trace};
use kanegen_dynamics::{MassMatrixMethod, Methods};
use serde::Serialize;
use std::collections::BTreeMap;

/// Largest `N` traced.
pub const N_MAX: usize = 12;

/// An algorithm of the table: a mass-matrix method, or the paper's own bookkeeping of (14b).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub enum TableAlgorithm {
    /// `recurrent-r1`: the paper's structure ((14a), (14b) as printed) plus the exact R1 correction.
    RecurrentR1,
    /// `recurrent`: (14b) in the exact form R2.
    Recurrent,
    /// The paper's structure alone ((14b) as printed, inexact for N ≥ 3): what Table 1 counts.
    RecurrentP,
    /// `kane-direct`: the direct sums (9).
    KaneDirect,
    /// `crba-base`: composite rigid bodies in base-frame notation.
    CrbaBase,
    /// `spatial`: Featherstone's CRBA in local frames, from `q` (includes kinematics).
    Spatial,
}

impl TableAlgorithm {
    /// All traced algorithms in report order.
    pub const ALL: [TableAlgorithm; 6] = [
        TableAlgorithm::RecurrentR1,
        TableAlgorithm::Recurrent,
        TableAlgorithm::RecurrentP,
        TableAlgorithm::KaneDirect,
        TableAlgorithm::CrbaBase,
        TableAlgorithm::Spatial,
    ];
    /// Name used in reports (the CLI's algorithm names, plus `recurrent-p`).
    pub fn name(self) -> &'static str {
        match self {
            TableAlgorithm::RecurrentR1 => "recurrent-r1",
            TableAlgorithm::Recurrent => "recurrent",
            TableAlgorithm::RecurrentP => "recurrent-p",
            TableAlgorithm::KaneDirect => "kane-direct",
            TableAlgorithm::CrbaBase => "crba-base",
            TableAlgorithm::Spatial => "spatial",
        }
    }

    /// The mass-matrix method traced, and whether (14b) is taken as printed.
    fn method(self) -> (MassMatrixMethod, bool) {
        match self {
            TableAlgorithm::RecurrentR1 => (MassMatrixMethod::RecurrentR1, false),
            TableAlgorithm::Recurrent => (MassMatrixMethod::Recurrent, false),
            TableAlgorithm::RecurrentP => (MassMatrixMethod::RecurrentR1, true),
            TableAlgorithm::KaneDirect => (MassMatrixMethod::KaneDirect, false),
            TableAlgorithm::CrbaBase => (MassMatrixMethod::CrbaBase, false),
            TableAlgorithm::Spatial => (MassMatrixMethod::Crba, false),
        }
    }
}

/// Traces the mass-matrix computation of `alg` for `n` bodies with general geometry and inertia;
/// the outputs are the `N(N+1)/2` non-overlapping elements `A_ij`, `i ≤ j`. The base-frame
/// algorithms start from the base-frame inputs of eq. (1), (2), (6) ([`Subject::BaseFrame`]),
/// `spatial` from `q` with every model parameter symbolic ([`Subject::Generic`]).
pub fn trace_mass_matrix(alg: TableAlgorithm, n: usize) -> Trace {
    let (mass_matrix, paper_14b) = alg.method();
    let subject = match alg {
        TableAlgorithm::Spatial => Subject::Generic { n },
        _ => Subject::BaseFrame { n },
    };
    let methods = Methods {
        mass_matrix,
        ..Methods::SPATIAL
    };
    let spec = Spec {
        paper_14b,
        ..Spec::default()
    };
    trace(subject, Function::MassMatrix, methods, &spec)
        .expect("Table 1's traces are valid requests")
        .trace
}

/// Counts of one trace: totals and per section, for each convention.
#[derive(Clone, Debug)]
pub struct TraceCounts {
    /// Total per convention.
    pub total: BTreeMap<&'static str, Counts>,
    /// Per convention, per section label.
    pub sections: BTreeMap<&'static str, BTreeMap<String, Counts>>,
}

fn counts_of(trace: &Trace) -> TraceCounts {
    let mut total = BTreeMap::new();
    let mut sections = BTreeMap::new();
    for c in Convention::ALL {
        total.insert(c.name(), trace.counts(c));
        sections.insert(c.name(), trace.counts_by_section(c).into_iter().collect());
    }
    TraceCounts { total, sections }
}

/// A Table 1 row: which sections of which algorithm it sums, and what the paper printed.
struct RowSpec {
    row: &'static str,
    quantity: &'static str,
    /// Sections summed; `mul_only`/`add_only` split one section across rows 3 and 4 as printed.
    sections: &'static [&'static str],
    part: Part,
    paper_mul: &'static [f64],
    paper_add: &'static [f64],
    explain: &'static str,
}

#[derive(Clone, Copy, PartialEq)]
enum Part {
    Both,
    MulOnly,
    AddOnly,
}

const ROWS: &[RowSpec] = &[
    RowSpec { row: "1", quantity: "m^Σ_j", sections: &["(12a)"], part: Part::Both, paper_mul: &[0.0], paper_add: &[0.0, 1.0], explain: "" },
    RowSpec { row: "2", quantity: "r_ij", sections: &["(12)"], part: Part::Both, paper_mul: &[0.0], paper_add: &[3.0, -4.5, 1.5], explain: "" },
    RowSpec { row: "3", quantity: "C_ij", sections: &["(12b)"], part: Part::MulOnly, paper_mul: &[0.0, -1.5, 1.5], paper_add: &[0.0], explain: "" },
    RowSpec { row: "4", quantity: "(label illegible; the additions of (12b))", sections: &["(12b)"], part: Part::AddOnly, paper_mul: &[0.0], paper_add: &[0.0, -1.5, 1.5], explain: "" },
    RowSpec { row: "6", quantity: "M^rr,1", sections: &["(13)"], part: Part::Both, paper_mul: &[0.0], paper_add: &[-9.0, 9.0], explain: "" },
    RowSpec { row: "7", quantity: "M^rr,2", sections: &["(14a)", "(14b)"], part: Part::Both, paper_mul: &[-18.0, 0.0, 18.0], paper_add: &[9.0, -27.0, 18.0],
        explain: "I1: the text's own sub-counts, (14a) 36N − 36 m and (14b) 18N² − 54N + 36 m, sum to 18N² − 18N; the text's total line and the table print 18N² − 18." },
    RowSpec { row: "8", quantity: "M^rr,3", sections: &["(15a)", "(15b)"], part: Part::Both, paper_mul: &[27.0, -40.5, 13.5], paper_add: &[36.0, -54.0, 18.0],
        explain: "I2: the row prints (15b) alone and omits (15a), 27(N − 1) m + 27(N − 1) a, that the text itself counts." },
    RowSpec { row: "9", quantity: "M^Σ,rr", sections: &["(16)"], part: Part::Both, paper_mul: &[0.0], paper_add: &[-9.0, -4.5, 13.5], explain: "" },
    RowSpec { row: "10", quantity: "A^rr", sections: &["(20)"], part: Part::Both, paper_mul: &[0.0, 3.0, 3.0], paper_add: &[0.0, 3.0, 3.0],
        explain: "I3: the text charges (3m + 3a)·2 per element; a_iᵀ M^Σ_ij a_j with a full 3×3 matrix takes 9 + 3 = 12 m and 12 a (accumulated from zero), so the row is twice the printed one." },
];

/// Sections of the R1 correction (not in the paper).
const R1_CORRECTION: &[&str] = &["R1-corr"];

/// One row of the reproduced table (the JSON contract).
#[derive(Clone, Debug, Serialize)]
pub struct RowReport {
    /// Table 1 row number as printed ("1", "2", …, "R1" for the correction).
    pub row: String,
    /// The quantity.
    pub quantity: String,
    /// The equations whose operations the row sums.
    pub equations: Vec<String>,
    /// Printed polynomials (`null` for rows the paper does not have).
    pub paper: Option<MulAdd>,
    /// Traced polynomials, paper convention.
    pub traced: MulAdd,
    /// Traced after folding.
    pub folded: MulAdd,
    /// Traced as emitted (fold + CSE + DCE).
    pub emitted: MulAdd,
    /// Whether printed and traced (paper convention) agree exactly.
    pub agree: Option<bool>,
    /// For disagreements: the arithmetic that explains them.
    pub note: String,
}

/// A pair of polynomials (coefficient lists, lowest degree first) with their validity.
#[derive(Clone, Debug, Serialize)]
pub struct MulAdd {
    /// Multiplications.
    pub mul: Vec<f64>,
    /// Additions and subtractions.
    pub add: Vec<f64>,
    /// The fit matches every traced N ≥ this (absent for printed formulas).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub valid_from: Option<i64>,
    /// Human-readable forms.
    pub text: [String; 2],
}

impl MulAdd {
    fn printed(mul: &Poly, add: &Poly) -> Self {
        MulAdd {
            mul: mul.coeffs_f64(),
            add: add.coeffs_f64(),
            valid_from: None,
            text: [mul.to_string(), add.to_string()],
        }
    }
    fn fitted(mul: &Fit, add: &Fit) -> Self {
        MulAdd {
            mul: mul.poly.coeffs_f64(),
            add: add.poly.coeffs_f64(),
            valid_from: Some(mul.valid_from.max(add.valid_from)),
            text: [mul.poly.to_string(), add.poly.to_string()],
        }
    }
}

/// A fitted total of one algorithm under one convention.
#[derive(Clone, Debug, Serialize)]
pub struct TotalReport {
    /// Algorithm name.
    pub algorithm: String,
    /// `paper`, `folded` or `emitted`.
    pub convention: String,
    /// Multiplications polynomial.
    pub mul: Vec<f64>,
    /// Additions polynomial.
    pub add: Vec<f64>,
    /// Fit valid from this N.
    pub valid_from: i64,
    /// Human-readable.
    pub text: [String; 2],
    /// Traced (mul, add) for N = 1..=N_MAX.
    pub values: Vec<[u64; 2]>,
    /// N values the fit was checked at without being fitted to them.
    pub checked_at: Vec<i64>,
}

/// The whole reproduction.
#[derive(Clone, Debug, Serialize)]
pub struct Table1 {
    /// Rows 1–10 and the R1 correction.
    pub rows: Vec<RowReport>,
    /// Row 11 printed and the traced totals of every algorithm and convention.
    pub totals: Vec<TotalReport>,
    /// The text's per-step derivations against the trace.
    pub derivations: Vec<RowReport>,
    /// Rows 12–16 as printed, with the traced counterparts.
    pub printed_totals: Vec<PrintedTotal>,
    /// The SSRMS line (N = 6).
    pub ssrms_n6: serde_json::Value,
    /// Crossovers with Stepanenko's printed curve.
    pub crossovers: Vec<Crossover>,
}

/// A printed total (rows 11–16).
#[derive(Clone, Debug, Serialize)]
pub struct PrintedTotal {
    /// Row number.
    pub row: String,
    /// What it is.
    pub name: String,
    /// Printed multiplications, additions (rows 11–13) or total (14–16).
    pub mul: Vec<f64>,
    /// Printed additions (empty for total-only rows).
    pub add: Vec<f64>,
    /// Printed total polynomial.
    pub total: Vec<f64>,
    /// Human-readable total.
    pub text: String,
}

/// Where a curve crosses Stepanenko's printed curve `69N² + 69N`.
#[derive(Clone, Debug, Serialize)]
pub struct Crossover {
    /// The curve.
    pub curve: String,
    /// Its total polynomial (mult + add).
    pub total: Vec<f64>,
    /// Real crossing points with N in (1, 40).
    pub at_n: Vec<f64>,
}

/// Per-N counts of every traced algorithm, N = 1..=N_MAX.
pub fn trace_all() -> BTreeMap<TableAlgorithm, Vec<TraceCounts>> {
    TableAlgorithm::ALL
        .iter()
        .map(|&alg| {
            (
                alg,
                (1..=N_MAX)
                    .map(|n| counts_of(&trace_mass_matrix(alg, n)))
                    .collect(),
            )
        })
        .collect()
}

fn section_sum(tc: &TraceCounts, conv: &str, sections: &[&str]) -> Counts {
    let mut c = Counts::default();
    for s in sections {
        if let Some(x) = tc.sections[conv].get(*s) {
            c += *x;
        }
    }
    c
}

fn fit_series(values: &[(i64, i64)]) -> Fit {
    fit_exact(values, 3)
        .unwrap_or_else(|| panic!("traced counts are not a polynomial of degree ≤ 3: {values:?}"))
}

fn fit_mul_add(per_n: &[Counts], part: Part) -> (Fit, Fit) {
    let pts = |f: &dyn Fn(&Counts) -> u64| -> Vec<(i64, i64)> {
        per_n
            .iter()
            .enumerate()
            .map(|(k, c)| (k as i64 + 1, f(c) as i64))
            .collect()
    };
    let mul = pts(&|c| if part == Part::AddOnly { 0 } else { c.mul });
    let add = pts(&|c| if part == Part::MulOnly { 0 } else { c.add });
    (fit_series(&mul), fit_series(&add))
}

fn diff_note(row: &str, printed: &Poly, traced: &Poly, what: &str) -> Option<String> {
    let d = traced.sub(printed);
    d.degree()?;
    Some(format!(
        "row {row} {what}: traced − printed = {d} ({} at N = 6)",
        fmt_num(d.eval_f64(6.0))
    ))
}

fn fmt_num(x: f64) -> String {
    let s = if x.fract() == 0.0 {
        format!("{x:+}")
    } else {
        format!("{x:+.1}")
    };
    s.replace('-', "−")
}

/// Builds the reproduction from traces.
pub fn build(traces: &BTreeMap<TableAlgorithm, Vec<TraceCounts>>) -> Table1 {
    let r1 = &traces[&TableAlgorithm::RecurrentR1];
    let mut rows = Vec::new();
    let per_section = |secs: &[&str], conv: &str| -> Vec<Counts> {
        r1.iter().map(|tc| section_sum(tc, conv, secs)).collect()
    };
    let mut sum_printed = (Poly::zero(), Poly::zero());
    let mut sum_traced = (Poly::zero(), Poly::zero());
    for spec in ROWS {
        let [t, f, e] = ["paper", "folded", "emitted"]
            .map(|c| fit_mul_add(&per_section(spec.sections, c), spec.part));
        let pm = Poly::from_f64(spec.paper_mul);
        let pa = Poly::from_f64(spec.paper_add);
        sum_printed = (sum_printed.0.add(&pm), sum_printed.1.add(&pa));
        sum_traced = (sum_traced.0.add(&t.0.poly), sum_traced.1.add(&t.1.poly));
        let agree = pm == t.0.poly && pa == t.1.poly;
        let mut notes: Vec<String> = [
            diff_note(spec.row, &pm, &t.0.poly, "mult"),
            diff_note(spec.row, &pa, &t.1.poly, "add"),
        ]
        .into_iter()
        .flatten()
        .collect();
        if !agree && !spec.explain.is_empty() {
            notes.push(spec.explain.to_string());
        }
        rows.push(RowReport {
            row: spec.row.into(),
            quantity: spec.quantity.into(),
            equations: spec.sections.iter().map(|s| s.to_string()).collect(),
            paper: Some(MulAdd::printed(&pm, &pa)),
            traced: MulAdd::fitted(&t.0, &t.1),
            folded: MulAdd::fitted(&f.0, &f.1),
            emitted: MulAdd::fitted(&e.0, &e.1),
            agree: Some(agree),
            note: notes.join("; "),
        });
    }
    // The R1 correction row (exactness costs this much on top of the paper's structure).
    {
        let [t, f, e] = ["paper", "folded", "emitted"]
            .map(|c| fit_mul_add(&per_section(R1_CORRECTION, c), Part::Both));
        rows.push(RowReport {
            row: "R1".into(),
            quantity: "correction Q_j of (14b) folded into M^rr,1 (not in the paper)".into(),
            equations: R1_CORRECTION.iter().map(|s| s.to_string()).collect(),
            paper: None,
            traced: MulAdd::fitted(&t.0, &t.1),
            folded: MulAdd::fitted(&f.0, &f.1),
            emitted: MulAdd::fitted(&e.0, &e.1),
            agree: None,
            note: "the printed scalar form of (14b) is not an identity for N ≥ 3 (docs/paper.md, R6); this O(N) term makes it exact".into(),
        });
    }

    // Totals of every algorithm and convention.
    let mut totals = Vec::new();
    for (&alg, per_n) in traces {
        for conv in Convention::ALL {
            let c: Vec<Counts> = per_n.iter().map(|tc| tc.total[conv.name()]).collect();
            let (m, a) = fit_mul_add(&c, Part::Both);
            totals.push(TotalReport {
                algorithm: alg.name().into(),
                convention: conv.name().into(),
                mul: m.poly.coeffs_f64(),
                add: a.poly.coeffs_f64(),
                valid_from: m.valid_from.max(a.valid_from),
                text: [m.poly.to_string(), a.poly.to_string()],
                values: c.iter().map(|x| [x.mul, x.add]).collect(),
                checked_at: m.check_points.clone(),
            });
        }
    }

    // Row 11 printed, and what rows 1–10 of the paper actually add up to.
    let row11 = (
        Poly::from_f64(&[9.0, -39.0, 36.0]),
        Poly::from_f64(&[30.0, -97.5, 55.5]),
    );
    let mut derivations = derivation_rows(r1);
    derivations.push(RowReport {
        row: "11".into(),
        quantity: "rows 1–10 summed (printed) vs printed row 11".into(),
        equations: vec![],
        paper: Some(MulAdd::printed(&row11.0, &row11.1)),
        traced: MulAdd { valid_from: None, ..MulAdd::printed(&sum_printed.0, &sum_printed.1) },
        folded: MulAdd::printed(&sum_traced.0, &sum_traced.1),
        emitted: MulAdd::printed(&sum_traced.0, &sum_traced.1),
        agree: Some(sum_printed.0 == row11.0 && sum_printed.1 == row11.1),
        note: format!(
            "I4: the printed rows 1–10 sum to {} m and {} a; row 11 prints {} a, {} at N = 6. The traced rows sum to {} m and {} a.",
            sum_printed.0,
            sum_printed.1,
            row11.1,
            fmt_num(row11.1.sub(&sum_printed.1).eval_f64(6.0)),
            sum_traced.0,
            sum_traced.1
        ),
    });

    let printed_totals = printed_totals();
    let ssrms_n6 = ssrms(&totals, &printed_totals);
    let crossovers = crossovers(&totals, &printed_totals);
    Table1 {
        rows,
        totals,
        derivations,
        printed_totals,
        ssrms_n6,
        crossovers,
    }
}

/// The text's per-step derivations (printed next to each formula) against the trace.
fn derivation_rows(r1: &[TraceCounts]) -> Vec<RowReport> {
    // (label, sections, printed mult, printed add, the text's derivation)
    type Step = (
        &'static str,
        &'static [&'static str],
        &'static [f64],
        &'static [f64],
        &'static str,
    );
    let steps: &[Step] = &[
        ("(13)", &["(13)"], &[0.0], &[-9.0, 9.0], "9(N − 1) a"),
        (
            "(14a)",
            &["(14a)"],
            &[-36.0, 36.0],
            &[-27.0, 27.0],
            "N − 1 matrices × (36 m + 27 a)",
        ),
        (
            "(14b)",
            &["(14b)"],
            &[36.0, -54.0, 18.0],
            &[36.0, -54.0, 18.0],
            "(N² − 3N + 2)/2 matrices × (36 m + 36 a)",
        ),
        (
            "(14) total",
            &["(14a)", "(14b)"],
            &[-18.0, 0.0, 18.0],
            &[9.0, -27.0, 18.0],
            "the text's \"in total for M^rr,2\" line",
        ),
        (
            "(15a)",
            &["(15a)"],
            &[-27.0, 27.0],
            &[-27.0, 27.0],
            "N − 1 matrices × (27 m + 27 a)",
        ),
        (
            "(15b)",
            &["(15b)"],
            &[27.0, -40.5, 13.5],
            &[36.0, -54.0, 18.0],
            "(N² − 3N + 2)/2 matrices × (27 m + 36 a)",
        ),
        (
            "(16)",
            &["(16)"],
            &[0.0],
            &[-9.0, -4.5, 13.5],
            "(27N − 27) + (9N − 9) + (13.5N² − 40.5N + 27) a",
        ),
        (
            "(20)",
            &["(20)"],
            &[0.0, 3.0, 3.0],
            &[0.0, 3.0, 3.0],
            "(N² + N)/2 elements × (3 m + 3 a)·2",
        ),
    ];
    steps
        .iter()
        .map(|(label, secs, pm, pa, text)| {
            let per: [Vec<Counts>; 3] = ["paper", "folded", "emitted"]
                .map(|c| r1.iter().map(|tc| section_sum(tc, c, secs)).collect());
            let [t, f, e] = per.map(|p| fit_mul_add(&p, Part::Both));
            let (pm, pa) = (Poly::from_f64(pm), Poly::from_f64(pa));
            let agree = pm == t.0.poly && pa == t.1.poly;
            let note = [
                diff_note(label, &pm, &t.0.poly, "mult"),
                diff_note(label, &pa, &t.1.poly, "add"),
            ]
            .into_iter()
            .flatten()
            .collect::<Vec<_>>()
            .join("; ");
            RowReport {
                row: label.to_string(),
                quantity: text.to_string(),
                equations: secs.iter().map(|s| s.to_string()).collect(),
                paper: Some(MulAdd::printed(&pm, &pa)),
                traced: MulAdd::fitted(&t.0, &t.1),
                folded: MulAdd::fitted(&f.0, &f.1),
                emitted: MulAdd::fitted(&e.0, &e.1),
                agree: Some(agree),
                note,
            }
        })
        .collect()
}

fn printed_totals() -> Vec<PrintedTotal> {
    let both = |row: &str, name: &str, m: &[f64], a: &[f64]| {
        let (pm, pa) = (Poly::from_f64(m), Poly::from_f64(a));
        let t = pm.add(&pa);
        PrintedTotal {
            row: row.into(),
            name: name.into(),
            mul: pm.coeffs_f64(),
            add: pa.coeffs_f64(),
            total: t.coeffs_f64(),
            text: t.to_string(),
        }
    };
    let total = |row: &str, name: &str, t: &[f64]| {
        let t = Poly::from_f64(t);
        PrintedTotal {
            row: row.into(),
            name: name.into(),
            mul: vec![],
            add: vec![],
            total: t.coeffs_f64(),
            text: t.to_string(),
        }
    };
    vec![
        both(
            "11",
            "Recurrent algorithm",
            &[9.0, -39.0, 36.0],
            &[30.0, -97.5, 55.5],
        ),
        both(
            "12",
            "«Kosynka» algorithm",
            &[0.0, -9.0, 24.0, 3.0],
            &[0.0, -50.0, 105.0, 11.0],
        ),
        both(
            "13",
            "Stepanenko's algorithm",
            &[0.0, 38.0, 38.0],
            &[0.0, 31.0, 31.0],
        ),
        total(
            "14",
            "Recurrent algorithm, total operations",
            &[39.0, -136.5, 91.5],
        ),
        total(
            "15",
            "«Kosynka» algorithm, total",
            &[0.0, -59.0, 129.0, 14.0],
        ),
        total(
            "16",
            "Stepanenko's algorithm, total operations",
            &[0.0, 69.0, 69.0],
        ),
        both(
            "—",
            "Featherstone CRBA (RBDA 2008, Table 10.1), incl. frame transforms",
            &[-32.0, 22.0, 10.0],
            &[-43.0, 37.0, 6.0],
        ),
    ]
}

fn poly_of(c: &[f64]) -> Poly {
    Poly::from_f64(c)
}

fn ssrms(totals: &[TotalReport], printed: &[PrintedTotal]) -> serde_json::Value {
    let at6 = |c: &[f64]| poly_of(c).eval_f64(6.0);
    let mut printed_map = serde_json::Map::new();
    for p in printed
        .iter()
        .filter(|p| ["11", "12", "13"].contains(&p.row.as_str()))
    {
        printed_map.insert(
            p.name.clone(),
            serde_json::json!({"mul": at6(&p.mul) as i64, "add": at6(&p.add) as i64, "total": at6(&p.total) as i64}),
        );
    }
    let traced: Vec<serde_json::Value> = totals
        .iter()
        .map(|t| {
            let v = t.values[5];
            serde_json::json!({"algorithm": t.algorithm, "convention": t.convention, "mul": v[0], "add": v[1], "total": v[0] + v[1]})
        })
        .collect();
    serde_json::json!({"n": 6, "printed": printed_map, "traced": traced})
}

fn crossovers(totals: &[TotalReport], printed: &[PrintedTotal]) -> Vec<Crossover> {
    let step = poly_of(&printed.iter().find(|p| p.row == "16").unwrap().total);
    let mut curves: Vec<(String, Poly)> = vec![
        (
            "printed recurrent (row 14)".into(),
            poly_of(&printed.iter().find(|p| p.row == "14").unwrap().total),
        ),
        (
            "printed «Kosynka» (row 15)".into(),
            poly_of(&printed.iter().find(|p| p.row == "15").unwrap().total),
        ),
    ];
    for t in totals.iter().filter(|t| t.convention == "paper") {
        curves.push((
            format!("traced {} (paper convention)", t.algorithm),
            poly_of(&t.mul).add(&poly_of(&t.add)),
        ));
    }
    curves
        .into_iter()
        .map(|(curve, p)| Crossover {
            at_n: p
                .sub(&step)
                .real_roots(1.0, 40.0)
                .into_iter()
                .map(|x| (x * 100.0).round() / 100.0)
                .collect(),
            total: p.coeffs_f64(),
            curve,
        })
        .collect()
}
