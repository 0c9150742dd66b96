//! Forward dynamics at run time, no compilation: the model read from its file, then either the
//! local-frame articulated-body algorithm of `kanegen-dynamics` in a preallocated workspace
//! ([`aba::forward_dynamics_in`]), the allocating [`aba::forward_dynamics`], the model's own
//! trace of the articulated-body algorithm (regrouped parameters, constants folded, common
//! subexpressions shared: the graph the code generator emits) evaluated as a flat tape of `f64`
//! registers, or the run-time path: the compact form's articulated-body kernel
//! (`kanegen_runtime::compact::aba`) on tables built at run time
//! (`kanegen_dynamics::kernels`). ns per call (best of 7 rounds of 20000 calls), on SSRMS and
//! the random chains of `benches/data`. Run: `cargo run --release --example runtime_fd`; the
//! measured table is in `docs/performance.md` ("The run-time path").

use kanegen::dynamics::algorithms::aba;
use kanegen::dynamics::kernels::{KernelData, KernelTables};
use kanegen::dynamics::{Loads, Params};
use kanegen::runtime::compact::{self as kernels, Rates};
use kanegen::trace::{trace, Function, Node, Spec, Subject};
use std::hint::black_box;
use std::time::Instant;

fn time(mut f: impl FnMut(usize) -> f64) -> f64 {
    let mut best = f64::INFINITY;
    let calls = 20_000;
    for _ in 0..7 {
        let t = Instant::now();
        let mut s = 0.0;
        for k in 0..calls {
            s += f(k);
        }
        black_box(s);
        best = best.min(t.elapsed().as_nanos() as f64 / calls as f64);
    }
    best
}

/// One tape instruction: `r[dst] = op(r[a], r[b])`, `dst` the instruction's index plus the
/// number of leaves (constants and inputs come first).
#[derive(Clone, Copy)]
struct Instr {
    op: u8,
    a: u32,
    b: u32,
}

/// A trace as a flat tape: registers `[constants…, inputs…, one per instruction]`.
struct Tape {
    regs: Vec<f64>,
    /// Register of input `i`.
    input_reg: Vec<u32>,
    /// The first instruction's register.
    first: usize,
    code: Vec<Instr>,
    outputs: Vec<u32>,
}

impl Tape {
    fn new(t: &kanegen::trace::Trace) -> Tape {
        let sched = t.schedule();
        let mut reg = std::collections::HashMap::new();
        let mut regs = Vec::new();
        // Unread inputs (a leaf's q̇, say) have no register.
        let mut input_reg = vec![u32::MAX; t.input_names().len()];
        for (id, node) in &sched {
            match node {
                Node::Const(c) => {
                    reg.insert(*id, regs.len() as u32);
                    regs.push(*c);
                }
                Node::Input(i) => {
                    reg.insert(*id, regs.len() as u32);
                    input_reg[*i as usize] = regs.len() as u32;
                    regs.push(0.0);
                }
                _ => {}
            }
        }
        let first = regs.len();
        let mut code = Vec::new();
        for (id, node) in &sched {
            let r = |s: kanegen::trace::Sym| reg[&s.id()];
            let (op, a, b) = match *node {
                Node::Const(_) | Node::Input(_) => continue,
                Node::Add(a, b) => (0, r(a), r(b)),
                Node::Sub(a, b) => (1, r(a), r(b)),
                Node::Mul(a, b) => (2, r(a), r(b)),
                Node::Div(a, b) => (3, r(a), r(b)),
                Node::Neg(a) => (4, r(a), 0),
                Node::Sin(a) => (5, r(a), 0),
                Node::Cos(a) => (6, r(a), 0),
                Node::Sqrt(a) => (7, r(a), 0),
            };
            reg.insert(*id, (first + code.len()) as u32);
            code.push(Instr { op, a, b });
        }
        regs.resize(first + code.len(), 0.0);
        let outputs = t.outputs().iter().map(|s| reg[&s.id()]).collect();
        Tape {
            regs,
            input_reg,
            first,
            code,
            outputs,
        }
    }

    fn eval(&mut self, inputs: &[&[f64]], out: &mut [f64]) {
        for (x, &r) in inputs.iter().flat_map(|x| x.iter()).zip(&self.input_reg) {
            if r != u32::MAX {
                self.regs[r as usize] = *x;
            }
        }
        for (i, ins) in self.code.iter().enumerate() {
            let regs = &mut self.regs;
            // Operands precede their users, so both registers hold their values.
            let (a, b) = (regs[ins.a as usize], regs[ins.b as usize]);
            regs[self.first + i] = match ins.op {
                0 => a + b,
                1 => a - b,
                2 => a * b,
                3 => a / b,
                4 => -a,
                5 => a.sin(),
                6 => a.cos(),
                _ => a.sqrt(),
            };
        }
        for (o, r) in out.iter_mut().zip(&self.outputs) {
            *o = self.regs[*r as usize];
        }
    }
}

/// The compact form's articulated-body kernel (`kanegen_runtime::compact::aba`) on slices, as
/// the run-time path calls it: the model's tables built at run time
/// ([`KernelTables`], unregrouped, no gravity), its scratch ([`KernelData`]) allocated once.
struct Kernel {
    t: KernelTables,
    data: KernelData,
}

impl Kernel {
    fn new(model: &kanegen::model::Model) -> Self {
        let t = KernelTables::new(&Params::<f64>::new(model), None);
        Kernel {
            data: KernelData::new(t.dof()),
            t,
        }
    }

    /// `q̈` into `qdd`: the joint transforms, then the articulated-body algorithm.
    fn forward_dynamics(&mut self, q: &[f64], qd: &[f64], tau: &[f64], qdd: &mut [f64]) {
        let tables = self.t.tables();
        let (mut b, mut ab, _) = self.data.split();
        kernels::spatial::transforms(&tables, q, f64::sin_cos, b.x);
        let rates = Rates {
            qd,
            tau,
            f_ext: None,
            armature: None,
        };
        kernels::aba::aba(&tables, tables.inertia, rates, &mut b, &mut ab, qdd);
    }
}

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = vec![root.join("tests/data/reference/ssrms_nguyen_hughes_1994.urdf")];
    for n in [8, 16, 32, 64] {
        files.push(root.join(format!("benches/data/random_n{n}.toml")));
    }
    println!(
        "| model | N | workspace ns | allocating ns | tape ns | tape instructions | compact kernel ns |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for f in files {
        let model = kanegen::model::io::load_model(&f).unwrap();
        let p = Params::<f64>::new(&model);
        let n = p.dof();
        let states: Vec<(Vec<f64>, Vec<f64>)> = (0..16)
            .map(|k| {
                let q = (0..n)
                    .map(|i| ((k * 7 + i * 3) as f64 * 0.37).sin())
                    .collect();
                let qd = (0..n)
                    .map(|i| ((k * 5 + i * 11) as f64 * 0.29).cos())
                    .collect();
                (q, qd)
            })
            .collect();
        let loads = Loads {
            tau: Some((0..n).map(|i| (i as f64 * 0.3).sin()).collect()),
            ..Loads::default()
        };
        let mut ws = aba::Workspace::new(&p);
        let mut qdd = vec![0.0; n];
        let t_ws = time(|k| {
            let (q, qd) = &states[k % 16];
            aba::forward_dynamics_in(
                &p,
                &mut ws,
                black_box(q),
                black_box(qd),
                &loads,
                None,
                &mut qdd,
            );
            qdd[k % n]
        });
        let t_alloc = time(|k| {
            let (q, qd) = &states[k % 16];
            aba::forward_dynamics(&p, black_box(q), black_box(qd), &loads)[k % n]
        });
        let spec = Spec {
            regroup: true,
            ..Spec::default()
        };
        let traced = trace(
            Subject::Model(&model),
            Function::ForwardDynamics,
            kanegen::dynamics::Methods::ABA,
            &spec,
        )
        .unwrap();
        let mut tape = Tape::new(&traced.trace);
        let tau = loads.tau.clone().unwrap();
        // The tape computes the same q̈.
        let (q, qd) = &states[3];
        let mut out = vec![0.0; n];
        tape.eval(&[q, qd, &tau], &mut out);
        let want = aba::forward_dynamics(&p, q, qd, &loads);
        let err = kanegen::dynamics::metrics::rel_err(&out, &want);
        assert!(err < 1e-10, "tape vs ABA {err:e}");
        let t_tape = time(|k| {
            let (q, qd) = &states[k % 16];
            tape.eval(&[black_box(q), black_box(qd), &tau], &mut out);
            out[k % n]
        });
        // The compact kernel computes the same q̈.
        let mut kernel = Kernel::new(&model);
        kernel.forward_dynamics(q, qd, &tau, &mut out);
        let err = kanegen::dynamics::metrics::rel_err(&out, &want);
        assert!(err < 1e-10, "compact kernel vs ABA {err:e}");
        let t_kernel = time(|k| {
            let (q, qd) = &states[k % 16];
            kernel.forward_dynamics(black_box(q), black_box(qd), &tau, &mut out);
            out[k % n]
        });
        println!(
            "| {} | {n} | {t_ws:.0} | {t_alloc:.0} | {t_tape:.0} | {} | {t_kernel:.0} |",
            model.name(),
            tape.code.len()
        );
    }
}
