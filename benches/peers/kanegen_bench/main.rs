//! Times kanegen's generated code (`kanegen::dynamics!`) the way src/driver.c times the
//! CasADi-generated C and src/pin_numeric.cpp numeric Pinocchio: same states, same protocol
//! (src/timing.h: warm-up of ROUND_US, calls per round clamped to [10, CALLS], median of ROUNDS
//! rounds in thread CPU time, wall median too), same output format. Adapted from the shared harness (peers/casadi/src/kanegen_bench).
//!
//! usage: kanegen_bench LABEL time ROUNDS CALLS ROUND_US
//!            -> "kanegen,LABEL,MODEL,FUNC,median_ns,min_ns,calls,checksum,wall_median_ns"
//!        kanegen_bench LABEL dump   -> JSON with every output at every state + OP_COUNTS
//!
//! `src/kanegen_models.rs` is one of tools/prepare.py's `NAME.kg_*.rs`: one model per build (one
//! `dynamics!`; the native build adds the `fma = true` variant), its states in Pinocchio's joint
//! order, and `for_each_model!`. The states are put into kanegen's joint order (`Name::JOINTS`,
//! matched by name) once, before timing; dumps are put back into Pinocchio's order.
//!
//! Functions, under the names the other sides use:
//!   M      mass_matrix(q)
//!   nle    nonlinear_effects(q, qd)                     (Pinocchio's nonLinearEffects, same sign)
//!   M_nle  mass_matrix_and_nonlinear_effects(q, qd)     (one call; CasADi's M_nle)
//!   rnea   inverse_dynamics(q, qd, qdd = a)
//!   aba    forward_dynamics(q, qd, tau)
//!   rnea_derivs  inverse_dynamics_derivatives(q, qd, qdd = a) -> (dtau_dq, dtau_dv)
//!   aba_derivs   forward_dynamics_derivatives(q, qd, tau) -> (ddq_dq, ddq_dv, minv)
//!   minv         mass_matrix_inverse(q)
//!          (the three derivative rows with the crate feature `derivs`, which run.sh turns on
//!          with DERIVS=1; row i = output i, column j = input j, as Pinocchio)
//!   sincos_n  N x libm::sincos (what the generated code calls), for scale
//!   aba_runtime  forward dynamics on the run-time path, no compilation: the model read from
//!          its URDF when the program starts, `kernels::forward_dynamics` (the compact
//!          form's articulated-body kernel on tables built then, scratch allocated once: what
//!          `kanegen simulate` evaluates per right-hand side); checked
//!          against the generated forward_dynamics at every state first (default and native
//!          builds)
use kanegen_dynamics::kernels::{self, KernelData, KernelTables};
use kanegen_dynamics::{Loads, Params};
use std::hint::black_box;
use std::time::Instant;

include!("kanegen_models.rs");

struct Ctx {
    label: String,
    rounds: usize,
    calls: usize,
    round_us: f64,
}

impl Ctx {
    /// `f(k, e)` evaluates one function at state `k` and returns element `e` of its result
    /// (the caller passes the whole result through `black_box`, so nothing is skipped).
    fn time<F: FnMut(usize, usize) -> f64>(
        &self,
        model: &str,
        suffix: &str,
        func: &str,
        n_states: usize,
        nn: usize,
        mut f: F,
    ) {
        let mut chk = 0.0f64;
        let (mut k, mut e) = (0usize, 0usize);
        let mut one = |chk: &mut f64| {
            *chk += f(k, e);
            k += 1;
            if k == n_states {
                k = 0;
            }
            e += 1;
            if e == nn {
                e = 0;
            }
        };
        let t_w = Instant::now();
        let mut wc = 0usize;
        let mut el;
        loop {
            one(&mut chk);
            wc += 1;
            el = t_w.elapsed().as_nanos() as f64;
            if wc >= 2 && el >= self.round_us * 1000.0 {
                break;
            }
        }
        let est = (el / wc as f64).max(1e-3);
        let calls = (self.round_us * 1000.0 / est).clamp(10.0, self.calls as f64) as usize;
        let mut ns = Vec::with_capacity(self.rounds);
        let mut wall = Vec::with_capacity(self.rounds);
        for _ in 0..self.rounds {
            let t = Instant::now();
            let c0 = cpu_ns();
            for _ in 0..calls {
                one(&mut chk);
            }
            ns.push((cpu_ns() - c0) / calls as f64);
            wall.push(t.elapsed().as_nanos() as f64 / calls as f64);
        }
        ns.sort_by(|a, b| a.partial_cmp(b).unwrap());
        wall.sort_by(|a, b| a.partial_cmp(b).unwrap());
        println!(
            "kanegen,{}{},{},{},{:.2},{:.2},{},{:.6e},{:.2}",
            self.label,
            suffix,
            model,
            func,
            ns[self.rounds / 2],
            ns[0],
            self.rounds * calls,
            chk,
            wall[self.rounds / 2]
        );
    }
}

/// `struct timespec` on 64-bit Linux.
#[repr(C)]
struct Timespec {
    tv_sec: i64,
    tv_nsec: i64,
}

extern "C" {
    fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
}

/// This thread's CPU time in ns (`CLOCK_THREAD_CPUTIME_ID`, 3 on Linux), as `peers_cpu_ns` in
/// src/timing.h: the time slices lost to other processes do not count.
fn cpu_ns() -> f64 {
    let mut t = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid, writable `struct timespec`; clock 3 exists on Linux.
    let rc = unsafe { clock_gettime(3, &mut t) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID)");
    t.tv_sec as f64 * 1e9 + t.tv_nsec as f64
}

fn vec_json(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter()
            .map(|x| format!("{x:e}"))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// `p[i]`: the Pinocchio index of kanegen joint `i` (matched by name).
fn permutation(kanegen: &[&str], pinocchio: &[&str]) -> Vec<usize> {
    kanegen
        .iter()
        .map(|j| {
            pinocchio.iter().position(|p| p == j).unwrap_or_else(|| {
                panic!("kanegen joint `{j}` not among Pinocchio's joints {pinocchio:?}")
            })
        })
        .collect()
}

/// The states of one model in kanegen's joint order.
struct States<const N: usize> {
    q: Vec<[f64; N]>,
    v: Vec<[f64; N]>,
    tau: Vec<[f64; N]>,
    a: Vec<[f64; N]>,
    p: Vec<usize>,
}

impl<const N: usize> States<N> {
    fn new(
        joints: &[&str],
        names: &[&str],
        q: &[[f64; N]],
        v: &[[f64; N]],
        tau: &[[f64; N]],
        a: &[[f64; N]],
    ) -> Self {
        let p = permutation(joints, names);
        let perm = |x: &[[f64; N]]| -> Vec<[f64; N]> {
            x.iter()
                .map(|s| core::array::from_fn(|i| s[p[i]]))
                .collect()
        };
        States {
            q: perm(q),
            v: perm(v),
            tau: perm(tau),
            a: perm(a),
            p: p.clone(),
        }
    }
    /// A kanegen-order vector in Pinocchio's order.
    fn back(&self, x: &[f64; N]) -> [f64; N] {
        let mut o = [0.0; N];
        for i in 0..N {
            o[self.p[i]] = x[i];
        }
        o
    }
    fn back_m(&self, m: &[[f64; N]; N]) -> Vec<String> {
        let mut o = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..N {
                o[self.p[i]][self.p[j]] = m[i][j];
            }
        }
        o.iter().map(|r| vec_json(r)).collect()
    }
}

macro_rules! states_of {
    ($ty:ident, $st:ident) => {
        States::<{ $ty::N }>::new(
            &$ty::JOINTS,
            &$st::NAMES,
            &$st::Q,
            &$st::V,
            &$st::TAU,
            &$st::A,
        )
    };
}

/// The derivative rows (crate feature `derivs`): each call's whole result goes through
/// `black_box`; the checksum adds one entry of each returned matrix.
#[cfg(feature = "derivs")]
macro_rules! bench_derivatives {
    ($ty:ident, $name:expr, $s:ident, $sfx:ident, $ctx:ident) => {{
        const N: usize = $ty::N;
        let k_n = $s.q.len();
        $ctx.time($name, $sfx, "rnea_derivs", k_n, N * N, |k, e| {
            let (dq, dv) = black_box($ty::inverse_dynamics_derivatives(
                black_box(&$s.q[k]),
                black_box(&$s.v[k]),
                black_box(&$s.a[k]),
            ));
            dq[e / N][e % N] + dv[e / N][e % N]
        });
        $ctx.time($name, $sfx, "aba_derivs", k_n, N * N, |k, e| {
            let (dq, dv, minv) = black_box($ty::forward_dynamics_derivatives(
                black_box(&$s.q[k]),
                black_box(&$s.v[k]),
                black_box(&$s.tau[k]),
            ));
            dq[e / N][e % N] + dv[e / N][e % N] + minv[e / N][e % N]
        });
        $ctx.time($name, $sfx, "minv", k_n, N * N, |k, e| {
            let m = black_box($ty::mass_matrix_inverse(black_box(&$s.q[k])));
            m[e / N][e % N]
        });
    }};
}

macro_rules! bench_model {
    ($ty:ident, $name:expr, $st:ident, $suffix:expr, $ctx:expr) => {{
        let ctx: &Ctx = $ctx;
        let sfx: &str = $suffix;
        const N: usize = $ty::N;
        let s = states_of!($ty, $st);
        let k_n = s.q.len();
        let nn = N * N;
        ctx.time($name, sfx, "M", k_n, nn, |k, e| {
            let m = black_box($ty::mass_matrix(black_box(&s.q[k])));
            m[e / N][e % N]
        });
        ctx.time($name, sfx, "nle", k_n, N, |k, e| {
            let c = black_box($ty::nonlinear_effects(
                black_box(&s.q[k]),
                black_box(&s.v[k]),
            ));
            c[e]
        });
        ctx.time($name, sfx, "M_nle", k_n, nn, |k, e| {
            let (m, c) = black_box($ty::mass_matrix_and_nonlinear_effects(
                black_box(&s.q[k]),
                black_box(&s.v[k]),
            ));
            m[e / N][e % N] + c[e % N]
        });
        ctx.time($name, sfx, "rnea", k_n, N, |k, e| {
            let t = black_box($ty::inverse_dynamics(
                black_box(&s.q[k]),
                black_box(&s.v[k]),
                black_box(&s.a[k]),
            ));
            t[e]
        });
        ctx.time($name, sfx, "aba", k_n, N, |k, e| {
            let d = black_box($ty::forward_dynamics(
                black_box(&s.q[k]),
                black_box(&s.v[k]),
                black_box(&s.tau[k]),
            ));
            d[e]
        });
        #[cfg(feature = "derivs")]
        bench_derivatives!($ty, $name, s, sfx, ctx);
        // the run-time path: the URDF read now, the kernel ABA (default and native builds)
        if sfx.is_empty() && (ctx.label == "default" || ctx.label == "native") {
            let path = format!("{}/models/{}.urdf", env!("CARGO_MANIFEST_DIR"), $name);
            let model = kanegen_model::io::load_model(std::path::Path::new(&path))
                .unwrap_or_else(|e| panic!("{path}: {e}"));
            let names: Vec<&str> = model.joints().iter().map(|j| j.name.as_str()).collect();
            assert_eq!(names, $ty::JOINTS, "{path}: joint order");
            let t = KernelTables::new(&Params::<f64>::new(&model), None);
            let mut data = KernelData::new(t.dof());
            let mut loads: Vec<Loads<f64>> = s
                .tau
                .iter()
                .map(|t| Loads {
                    tau: Some(t.to_vec()),
                    ..Loads::default()
                })
                .collect();
            let mut qdd = [0.0f64; N];
            for k in 0..k_n {
                kernels::forward_dynamics(
                    &t, &mut data, None, &s.q[k], &s.v[k], &loads[k], None, &mut qdd,
                );
                let want = $ty::forward_dynamics(&s.q[k], &s.v[k], &s.tau[k]);
                let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                for i in 0..N {
                    assert!(
                        (qdd[i] - want[i]).abs() <= 1e-9 * scale,
                        "{path}: state {k}, q̈[{i}] = {} at run time, {} generated",
                        qdd[i],
                        want[i]
                    );
                }
            }
            let loads = &mut loads;
            ctx.time($name, sfx, "aba_runtime", k_n, N, |k, e| {
                kernels::forward_dynamics(
                    &t,
                    &mut data,
                    None,
                    black_box(&s.q[k]),
                    black_box(&s.v[k]),
                    black_box(&loads[k]),
                    None,
                    &mut qdd,
                );
                black_box(&qdd)[e]
            });
        }
        // trigonometry floor: N x libm::sincos (what kanegen's code calls), stored like an output
        if sfx.is_empty() {
            ctx.time($name, sfx, "sincos_n", k_n, 2 * N, |k, e| {
                let q = black_box(&s.q[k]);
                let mut o = [0.0f64; 2 * N];
                for j in 0..N {
                    let (sn, cs) = kanegen::__private::libm::sincos(q[j]);
                    o[2 * j] = sn;
                    o[2 * j + 1] = cs;
                }
                black_box(o)[e]
            });
        }
    }};
}

/// The derivative entries of one state's dump (crate feature `derivs`), each key led by ", ".
#[cfg(feature = "derivs")]
macro_rules! dump_derivatives {
    ($ty:ident, $s:ident, $q:ident, $v:ident, $tau:ident, $a:ident) => {{
        let (tq, tv) = $ty::inverse_dynamics_derivatives($q, $v, $a);
        let (dq, dv, mi) = $ty::forward_dynamics_derivatives($q, $v, $tau);
        format!(
            ", \"rnea_derivs\": [{}], \"rnea_derivs.dtau_dv\": [{}], \"aba_derivs\": [{}], \"aba_derivs.ddq_dv\": [{}], \"aba_derivs.Minv\": [{}], \"minv\": [{}]",
            $s.back_m(&tq).join(", "),
            $s.back_m(&tv).join(", "),
            $s.back_m(&dq).join(", "),
            $s.back_m(&dv).join(", "),
            $s.back_m(&mi).join(", "),
            $s.back_m(&$ty::mass_matrix_inverse($q)).join(", "),
        )
    }};
}

macro_rules! dump_model {
    ($ty:ident, $name:expr, $st:ident, $suffix:expr, $out:expr) => {{
        let out: &mut Vec<String> = $out;
        let sfx: &str = $suffix;
        let s = states_of!($ty, $st);
        let mut samples = Vec::new();
        for k in 0..s.q.len() {
            let (q, v, tau, a) = (&s.q[k], &s.v[k], &s.tau[k], &s.a[k]);
            let (m2, c2) = $ty::mass_matrix_and_nonlinear_effects(q, v);
            #[cfg(feature = "derivs")]
            let derivs = dump_derivatives!($ty, s, q, v, tau, a);
            #[cfg(not(feature = "derivs"))]
            let derivs = String::new();
            samples.push(format!(
                "{{\"M\": [{}], \"nle\": {}, \"M_nle\": [{}], \"M_nle.nle\": {}, \"rnea\": {}, \"aba\": {}{}}}",
                s.back_m(&$ty::mass_matrix(q)).join(", "),
                vec_json(&s.back(&$ty::nonlinear_effects(q, v))),
                s.back_m(&m2).join(", "),
                vec_json(&s.back(&c2)),
                vec_json(&s.back(&$ty::inverse_dynamics(q, v, a))),
                vec_json(&s.back(&$ty::forward_dynamics(q, v, tau))),
                derivs,
            ));
        }
        let opt = |x: Option<&str>| x.map_or("null".to_string(), |m| format!("\"{m}\""));
        let ops: Vec<String> = $ty::OP_COUNTS
            .iter()
            .map(|o| {
                format!(
                    "{{\"function\": \"{}\", \"mass_matrix_method\": {}, \"nonlinear_effects_method\": {}, \"mul\": {}, \"add\": {}, \"div\": {}, \"sqrt\": {}, \"sincos\": {}, \"fma\": {}}}",
                    o.function,
                    opt(o.mass_matrix_method),
                    opt(o.nonlinear_effects_method),
                    o.mul,
                    o.add,
                    o.div,
                    o.sqrt,
                    o.sincos,
                    o.fma
                )
            })
            .collect();
        let joints: Vec<String> = $ty::JOINTS.iter().map(|j| format!("\"{j}\"")).collect();
        out.push(format!(
            "\"{}{}\": {{\"n\": {}, \"joints\": [{}], \"op_counts\": [{}], \"samples\": [{}]}}",
            $name,
            sfx,
            $ty::N,
            joints.join(", "),
            ops.join(", "),
            samples.join(",\n")
        ));
    }};
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: {} LABEL time ROUNDS CALLS ROUND_US | dump", args[0]);
        std::process::exit(2);
    }
    let arg = |i: usize, d: &str| args.get(i).map_or(d.to_string(), |s| s.clone());
    let ctx = Ctx {
        label: args[1].clone(),
        rounds: arg(3, "15").parse().unwrap(),
        calls: arg(4, "20000").parse().unwrap(),
        round_us: arg(5, "4000").parse().unwrap(),
    };
    match args[2].as_str() {
        "time" => {
            for_each_model!(bench_model, &ctx);
        }
        "dump" => {
            let mut out = Vec::new();
            for_each_model!(dump_model, &mut out);
            println!(
                "{{\"side\": \"kanegen\", \"label\": \"{}\", \"models\": {{{}}}}}",
                ctx.label,
                out.join(",\n")
            );
        }
        m => {
            eprintln!("unknown mode {m}");
            std::process::exit(2);
        }
    }
}
