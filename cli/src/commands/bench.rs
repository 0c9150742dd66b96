//! `kanegen bench`: nanoseconds per call of generated and interpreted dynamics for SSRMS, measured
//! side by side in one process run.
//!
//! These machines are shared and noisy, so absolute numbers mean little; the report is built for
//! ratios. Every candidate runs in each of many short rounds, in rotating order, and the median
//! round is reported: a burst of load on the machine hits every candidate of that round alike.

use crate::timing::{measure, BenchLine, Candidate};
use serde::Serialize;

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Model measured.
    pub model: String,
    /// Degrees of freedom.
    pub n: usize,
    /// Rounds per candidate.
    pub rounds: usize,
    /// Calls per round.
    pub calls_per_round: usize,
    /// Results.
    pub results: Vec<BenchLine>,
}

/// Human-readable table.
pub fn render_text(r: &BenchReport) -> String {
    use std::fmt::Write;
    let mut s = format!(
        "{} (N = {}), {} rounds × {} calls, median ns per call\n\n{:<20} {:<32} {:>12} {:>22} {:>10}\n",
        r.model, r.n, r.rounds, r.calls_per_round, "function", "candidate", "ns/call", "range", "× first"
    );
    for l in &r.results {
        let _ = writeln!(
            s,
            "{:<20} {:<32} {:>12.1} {:>10.1} – {:>9.1} {:>10.2}",
            l.function, l.name, l.ns, l.ns_range[0], l.ns_range[1], l.ratio_to_first
        );
    }
    s
}

/// The SSRMS model the generated code was emitted from (embedded, so the command runs anywhere).
pub const SSRMS_URDF: &str =
    include_str!("../../../tests/data/reference/ssrms_nguyen_hughes_1994.urdf");

/// Generated SSRMS code against the interpreted f64 algorithms, side by side: `M + c` (one
/// generated call against each preset's `A` and `b`), forward dynamics and inverse dynamics.
///
/// # Errors
/// If the embedded model does not parse.
pub fn bench_ssrms(rounds: usize, calls: usize) -> anyhow::Result<BenchReport> {
    use kanegen_dynamics::{Loads, Methods, Params};
    use kanegen_generated::ssrms::Ssrms;
    use kanegen_generated::ssrms_recurrent::SsrmsRecurrent;
    let model = kanegen_model::io::parse_urdf(SSRMS_URDF)?;
    let p = Params::<f64>::new(&model);
    let n = model.dof();
    let arr = |x: &[f64]| -> [f64; 7] { core::array::from_fn(|i| x[i]) };
    let zero = [0.0; 7];
    let mut c: Vec<Candidate<'_>> = Vec::new();
    c.push((
        "generated".into(),
        "M+c".into(),
        Box::new(move |q, qd| {
            let (m, nle) = Ssrms::mass_matrix_and_nonlinear_effects(&arr(q), &arr(qd));
            m[0][0] + m[6][6] + nle[0] + nle[6]
        }),
    ));
    c.push((
        "generated recurrent".into(),
        "M+c".into(),
        Box::new(move |q, qd| {
            let (m, nle) = SsrmsRecurrent::mass_matrix_and_nonlinear_effects(&arr(q), &arr(qd));
            m[0][0] + m[6][6] + nle[0] + nle[6]
        }),
    ));
    for (name, methods) in Methods::PRESETS {
        let p = &p;
        c.push((
            format!("interpreted {name}"),
            "M+c".into(),
            Box::new(move |q, qd| {
                let d = methods.dynamics(p, q, qd, &Loads::default());
                d.mass_matrix[0][0] + d.mass_matrix[6][6] + d.tau_minus_c[0] + d.tau_minus_c[6]
            }),
        ));
    }
    let fast = [
        ("recurrent", Methods::RECURRENT),
        ("crba-inertial", Methods::CRBA_INERTIAL),
        ("spatial", Methods::SPATIAL),
    ];
    c.push((
        "generated".into(),
        "forward_dynamics".into(),
        Box::new(move |q, qd| Ssrms::forward_dynamics(&arr(q), &arr(qd), &zero)[6]),
    ));
    c.push((
        "generated recurrent".into(),
        "forward_dynamics".into(),
        Box::new(move |q, qd| SsrmsRecurrent::forward_dynamics(&arr(q), &arr(qd), &zero)[6]),
    ));
    for (name, methods) in fast {
        let p = &p;
        c.push((
            format!("interpreted {name}"),
            "forward_dynamics".into(),
            Box::new(move |q, qd| methods.forward_dynamics(p, q, qd, &Loads::default())[6]),
        ));
    }
    // The run-time fast path of `kanegen simulate`: the articulated-body kernel on tables
    // built at run time, scratch allocated once.
    let tables = kanegen_dynamics::kernels::KernelTables::new(&p, None);
    let mut data = kanegen_dynamics::kernels::KernelData::new(n);
    let mut qdd = vec![0.0; n];
    c.push((
        "interpreted run-time kernel".into(),
        "forward_dynamics".into(),
        Box::new(move |q, qd| {
            let l = Loads::default();
            kanegen_dynamics::kernels::forward_dynamics(
                &tables, &mut data, None, q, qd, &l, None, &mut qdd,
            );
            qdd[6]
        }),
    ));
    c.push((
        "generated".into(),
        "inverse_dynamics".into(),
        Box::new(move |q, qd| Ssrms::inverse_dynamics(&arr(q), &arr(qd), &arr(qd))[6]),
    ));
    c.push((
        "generated recurrent".into(),
        "inverse_dynamics".into(),
        Box::new(move |q, qd| SsrmsRecurrent::inverse_dynamics(&arr(q), &arr(qd), &arr(qd))[6]),
    ));
    for (name, methods) in fast {
        let p = &p;
        c.push((
            format!("interpreted {name}"),
            "inverse_dynamics".into(),
            Box::new(move |q, qd| methods.inverse_dynamics(p, q, qd, qd, &Loads::default())[6]),
        ));
    }
    let mut results = measure(n, c, rounds, calls);
    results.extend(bench_free_floating(rounds, calls)?);
    Ok(BenchReport {
        model: model.name().into(),
        n,
        rounds,
        calls_per_round: calls,
        results,
    })
}

/// The bMSd 7-dof arm on its free-floating base: the generated forward dynamics
/// (`kanegen_generated::free_floating_7dof`) against the interpreted `spatial` and
/// `recurrent` free-floating forward dynamics, at base states with the arm's random `q`, `q̇`.
fn bench_free_floating(rounds: usize, calls: usize) -> anyhow::Result<Vec<BenchLine>> {
    use kanegen_dynamics::algorithms::floating;
    use kanegen_dynamics::base::{quat_to_matrix, FloatingBase, FloatingState};
    use kanegen_dynamics::linalg::Vec3;
    use kanegen_dynamics::{Loads, Methods, Params};
    use kanegen_generated::free_floating_7dof::FreeFloating7;
    let v = kanegen_model::Validation {
        allow_nonphysical_inertia: true,
    };
    let model = kanegen_model::io::parse_urdf_with(BMSD_URDF, v)?
        .with_base_kind(kanegen_model::BaseKind::FreeFloating)?;
    let p = Params::<f64>::new(&model);
    let base = FloatingBase::<f64>::from_inertial(model.base_inertial().expect("base inertial"));
    let n = model.dof();
    // A fixed, slightly turned and moving base; the arm's state varies.
    let quat = [0.1, -0.2, 0.3, 0.9273618495495703];
    let state = FloatingState {
        position: Vec3([0.5, -0.2, 1.0]),
        rotation: quat_to_matrix(&quat),
        v_b: Vec3([0.01, -0.02, 0.005]),
        omega_b: Vec3([0.002, 0.001, -0.003]),
    };
    let qv = |q: &[f64], qd: &[f64]| -> ([f64; 14], [f64; 13]) {
        let mut x = [0.0; 14];
        x[..3].copy_from_slice(&state.position.0);
        x[3..7].copy_from_slice(&quat);
        x[7..].copy_from_slice(q);
        let mut v = [0.0; 13];
        v[..3].copy_from_slice(&state.v_b.0);
        v[3..6].copy_from_slice(&state.omega_b.0);
        v[6..].copy_from_slice(qd);
        (x, v)
    };
    let tau = [0.0; 7];
    let mut c: Vec<Candidate<'_>> = vec![(
        "generated".into(),
        "free-floating forward_dynamics".into(),
        Box::new(move |q, qd| {
            let (x, v) = qv(q, qd);
            FreeFloating7::forward_dynamics(&x, &v, &tau)[6]
        }),
    )];
    for (name, methods) in [
        ("spatial", Methods::SPATIAL),
        ("recurrent", Methods::RECURRENT),
    ] {
        let (p, base, state) = (&p, &base, &state);
        c.push((
            format!("interpreted {name}"),
            "free-floating forward_dynamics".into(),
            Box::new(move |q, qd| {
                floating::forward_dynamics(methods, p, base, state, q, qd, &Loads::default())[6]
            }),
        ));
    }
    Ok(measure(n, c, rounds, calls))
}

/// The bMSd 7-dof free-floating model of `kanegen_generated::free_floating_7dof`.
const BMSD_URDF: &str = include_str!("../../../tests/data/reference/bmsd_7dof_free_floating.urdf");
