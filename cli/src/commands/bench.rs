//! `kanegen bench`: nanoseconds per call of generated and interpreted dynamics for SSRMS, measured
//! side by side in one process run, and states per second of the generated functions over a
//! batch: one state per call, lanes (`f64x2`, `f64x4`) and all cores.
//!
//! These machines are shared and noisy, so absolute numbers mean little; the report is built for
//! ratios. Every candidate runs in each of many short rounds, in rotating order, and the median
//! round is reported: a burst of load on the machine hits every candidate of that round alike.

use crate::timing::{measure, rounds_side_by_side, BenchLine, Candidate};
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
    /// States per second of the generated functions over a batch: one state per call, lanes,
    /// all cores.
    pub throughput: Throughput,
}

/// States per second of generated SSRMS functions over one batch of random states, one state
/// per call, `L` states per call (`NAME_batch::<f64x2>`, `::<f64x4>`) and the lanes on all cores
/// (`kanegen_runtime::par::batch` over the same batch functions), side by side in one run.
#[derive(Clone, Debug, Serialize)]
pub struct Throughput {
    /// States per batch.
    pub batch: usize,
    /// Threads of the parallel batches (`rayon`'s pool: the machine's CPUs).
    pub threads: usize,
    /// Rounds per candidate (each a whole batch; the median is reported).
    pub rounds: usize,
    /// One line per function.
    pub lines: Vec<ThroughputLine>,
}

/// One function's states per second (the median round) in each way.
#[derive(Clone, Debug, Serialize)]
pub struct ThroughputLine {
    /// The generated function.
    pub function: String,
    /// One state per call (`NAME` in a loop).
    pub one_state: f64,
    /// `NAME_batch::<f64x2>`.
    pub f64x2: f64,
    /// `NAME_batch::<f64x4>`.
    pub f64x4: f64,
    /// `NAME_batch::<f64x2>` on all cores.
    pub cores_f64x2: f64,
    /// `NAME_batch::<f64x4>` on all cores.
    pub cores_f64x4: f64,
    /// The better lanes width over one state per call.
    pub lanes_ratio: f64,
    /// The better all-cores figure over the better lanes width (one core).
    pub cores_ratio: f64,
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
    let t = &r.throughput;
    let _ = write!(
        s,
        "\nThroughput, {} states per batch, {} threads, {} rounds, median states per second \
         (lanes ×: the better width over one state; cores ×: the better all-cores over the \
         better width)\n\n{:<36} {:>10} {:>10} {:>10} {:>12} {:>12} {:>8} {:>8}\n",
        t.batch,
        t.threads,
        t.rounds,
        "function",
        "1 state",
        "f64x2",
        "f64x4",
        "cores f64x2",
        "cores f64x4",
        "lanes ×",
        "cores ×"
    );
    let m = |x: f64| format!("{:.2}M", x / 1e6);
    for l in &t.lines {
        let _ = writeln!(
            s,
            "{:<36} {:>10} {:>10} {:>10} {:>12} {:>12} {:>8.2} {:>8.2}",
            l.function,
            m(l.one_state),
            m(l.f64x2),
            m(l.f64x4),
            m(l.cores_f64x2),
            m(l.cores_f64x4),
            l.lanes_ratio,
            l.cores_ratio
        );
    }
    s
}

/// One way of evaluating a batch: runs it once over the whole batch.
type Way<'a> = Box<dyn FnMut() + Send + 'a>;

/// The five ways of [`ThroughputLine`] for generated function `$f` of `$t` (batch form
/// `$batch`) over the batch's argument slices, each with its own results, `$zero` to start.
macro_rules! ways {
    ($t:ty, $f:ident / $batch:ident ($($arg:ident),*), $zero:expr) => {{
        use kanegen_runtime::lanes::{f64x2, f64x4};
        use kanegen_runtime::par;
        use std::hint::black_box;
        let b = [$($arg.len()),*][0];
        let ways: Vec<Way<'_>> = vec![
            Box::new({
                let mut o = vec![$zero; b];
                move || {
                    for (k, o) in o.iter_mut().enumerate() {
                        *o = <$t>::$f($(&$arg[k]),*);
                    }
                    black_box(&o);
                }
            }),
            Box::new({
                let mut o = vec![$zero; b];
                move || {
                    <$t>::$batch::<f64x2>($($arg,)* &mut o);
                    black_box(&o);
                }
            }),
            Box::new({
                let mut o = vec![$zero; b];
                move || {
                    <$t>::$batch::<f64x4>($($arg,)* &mut o);
                    black_box(&o);
                }
            }),
            Box::new({
                let mut o = vec![$zero; b];
                move || {
                    par::batch(&mut o, |r, o| <$t>::$batch::<f64x2>($(&$arg[r.clone()],)* o));
                    black_box(&o);
                }
            }),
            Box::new({
                let mut o = vec![$zero; b];
                move || {
                    par::batch(&mut o, |r, o| <$t>::$batch::<f64x4>($(&$arg[r.clone()],)* o));
                    black_box(&o);
                }
            }),
        ];
        (stringify!($f), ways)
    }};
}

/// The time over which [`bench_throughput`] calls one way back to back for one sample (s).
const SAMPLE: f64 = 200e-6;

/// States per second of the generated SSRMS functions `M`, `c`, `(M, c)`, inverse and forward
/// dynamics and the forward-dynamics derivatives over `batch` random states (at least one), each
/// way of [`ThroughputLine`] timed over the whole batch, called back to back for about
/// [`SAMPLE`] seconds, in each of `rounds` rounds, side by side
/// (every way of every function in each round, in rotating order), the median round reported.
#[must_use]
pub fn bench_throughput(rounds: usize, batch: usize) -> Throughput {
    use kanegen_generated::ssrms::Ssrms;
    use kanegen_model::random::{random_vec, rng};
    let batch = batch.max(1);
    let mut r = rng(2027);
    let mut states = |scale: f64| -> Vec<[f64; 7]> {
        (0..batch)
            .map(|_| {
                let v = random_vec(&mut r, 7, scale);
                core::array::from_fn(|i| v[i])
            })
            .collect()
    };
    let (q, qd, tau) = (states(3.0), states(0.1), states(0.1));
    let (q, qd, tau) = (&q[..], &qd[..], &tau[..]);
    let (z, m) = ([0.0; 7], [[0.0; 7]; 7]);
    let mut groups = [
        ways!(Ssrms, mass_matrix / mass_matrix_batch(q), m),
        ways!(Ssrms, nonlinear_effects / nonlinear_effects_batch(q, qd), z),
        ways!(
            Ssrms,
            mass_matrix_and_nonlinear_effects / mass_matrix_and_nonlinear_effects_batch(q, qd),
            (m, z)
        ),
        ways!(
            Ssrms,
            inverse_dynamics / inverse_dynamics_batch(q, qd, tau),
            z
        ),
        ways!(
            Ssrms,
            forward_dynamics / forward_dynamics_batch(q, qd, tau),
            z
        ),
        ways!(
            Ssrms,
            forward_dynamics_derivatives / forward_dynamics_derivatives_batch(q, qd, tau),
            (m, m, m)
        ),
    ];
    let mut all: Vec<&mut Way<'_>> = groups.iter_mut().flat_map(|g| g.1.iter_mut()).collect();
    // On a thread of the pool, as a sampler's loop runs (`par::install`): between batches the
    // pool's threads stay awake, and the caller waits for them without sleeping.
    let samples = kanegen_runtime::par::install(|| {
        // Warm-up, and each way's calls per sample: back to back for about `SAMPLE` seconds, as
        // a sampler or a horizon calls batch after batch.
        let calls: Vec<u32> = all
            .iter_mut()
            .map(|w| {
                w();
                let t0 = std::time::Instant::now();
                w();
                (SAMPLE / t0.elapsed().as_secs_f64().max(1e-9))
                    .ceil()
                    .clamp(1.0, 1e6) as u32
            })
            .collect();
        rounds_side_by_side(all.len(), rounds, |i| {
            // One call untimed: the pool's threads, asleep while other ways ran, are awake when
            // the sample starts, as they are in a loop of batches.
            (all[i])();
            let t0 = std::time::Instant::now();
            for _ in 0..calls[i] {
                (all[i])();
            }
            f64::from(calls[i]) * batch as f64 / t0.elapsed().as_secs_f64()
        })
    });
    let median = |mut s: Vec<f64>| {
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    };
    let rates: Vec<f64> = samples.into_iter().map(median).collect();
    let lines = groups
        .iter()
        .zip(rates.chunks(5))
        .map(|(g, r)| {
            let lanes = r[1].max(r[2]);
            ThroughputLine {
                function: g.0.into(),
                one_state: r[0],
                f64x2: r[1],
                f64x4: r[2],
                cores_f64x2: r[3],
                cores_f64x4: r[4],
                lanes_ratio: lanes / r[0],
                cores_ratio: r[3].max(r[4]) / lanes,
            }
        })
        .collect();
    Throughput {
        batch,
        threads: kanegen_runtime::par::threads(),
        rounds,
        lines,
    }
}

/// The SSRMS model the generated code was emitted from (embedded, so the command runs anywhere).
pub const SSRMS_URDF: &str =
    include_str!("../../../tests/data/reference/ssrms_nguyen_hughes_1994.urdf");

/// Generated SSRMS code against the interpreted f64 algorithms, side by side: `M + c` (one
/// generated call against each preset's `A` and `b`), forward dynamics and inverse dynamics;
/// then the generated functions' throughput over `batch` states ([`bench_throughput`]).
///
/// # Errors
/// If the embedded model does not parse.
pub fn bench_ssrms(rounds: usize, calls: usize, batch: usize) -> anyhow::Result<BenchReport> {
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
        throughput: bench_throughput(rounds, batch),
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
