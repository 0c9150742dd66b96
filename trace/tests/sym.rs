//! Tests of the counting symbolic scalar `Sym`: folding, hash-consing, sign normalisation,
//! the three counting conventions on the primitives of `docs/paper.md` ("Operation counts"), sections,
//! evaluation and misuse panics.

use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::scalar::Scalar;
use kanegen_trace::sym::{record as trace, Convention, Counts, Node, Sym, Tracer};

fn c(x: f64) -> Sym {
    Sym::constant(x)
}

fn vec_in(t: &Tracer, name: &str) -> Vec3<Sym> {
    Vec3(core::array::from_fn(|i| t.input(format!("{name}{i}"))))
}

fn mat_in(t: &Tracer, name: &str) -> Mat3<Sym> {
    Mat3(core::array::from_fn(|r| {
        core::array::from_fn(|k| t.input(format!("{name}{r}{k}")))
    }))
}

fn mat_out(m: Mat3<Sym>) -> Vec<Sym> {
    m.into_array().into_iter().flatten().collect()
}

/// (mul, add) under each convention: [paper, folded, emitted].
fn ma(t: &kanegen_trace::sym::Trace) -> [(u64, u64); 3] {
    Convention::ALL.map(|cv| {
        let k = t.counts(cv);
        (k.mul, k.add)
    })
}

// ------------------------------------------------------------------------------------------
// Folding identities.

#[test]
fn folding_identities() {
    let t = Tracer::new();
    let x = t.input("x");
    let y = t.input("y");
    // Constants fold.
    assert_eq!((c(2.0) * c(3.0)).const_value(), Some(6.0));
    assert_eq!((c(2.0) + c(3.0)).const_value(), Some(5.0));
    assert_eq!((c(2.0) - c(3.0)).const_value(), Some(-1.0));
    assert_eq!((c(3.0) / c(2.0)).const_value(), Some(1.5));
    assert_eq!(c(4.0).sqrt().const_value(), Some(2.0));
    assert_eq!(c(0.0).sin().const_value(), Some(0.0));
    assert_eq!(c(0.0).cos().const_value(), Some(1.0));
    // Zeros and ones.
    assert_eq!((x * c(0.0)).const_value(), Some(0.0));
    assert_eq!((c(0.0) * x).const_value(), Some(0.0));
    assert_eq!((x * c(1.0)).id(), (x).id());
    assert_eq!((c(1.0) * x).id(), (x).id());
    assert_eq!((x * c(-1.0)).id(), (-x).id());
    assert_eq!((c(-1.0) * x).id(), (-x).id());
    assert_eq!((x + c(0.0)).id(), (x).id());
    assert_eq!((c(0.0) + x).id(), (x).id());
    assert_eq!((x - c(0.0)).id(), (x).id());
    assert_eq!((c(0.0) - x).id(), (-x).id());
    assert_eq!((x - x).const_value(), Some(0.0));
    assert_eq!((x / c(1.0)).id(), (x).id());
    assert_eq!((c(0.0) / x).const_value(), Some(0.0));
    assert_eq!((-(-x)).id(), (x).id());
    assert_eq!((-c(2.0)).const_value(), Some(-2.0));
    // -0.0 and 0.0 are the same constant.
    assert_eq!((c(-0.0)).id(), (c(0.0)).id());
    // Non-foldable things stay.
    assert_eq!((x + y).const_value(), None);
    assert_ne!((x + x).id(), (x).id());
    let tr = t.finish(&[]);
    // Only the user's negations and x + y, x + x survived folding (-x made once per call).
    let f = tr.counts(Convention::Folded);
    assert_eq!(
        (f.mul, f.add, f.div, f.sqrt, f.sin, f.cos),
        (0, 2, 0, 0, 0, 0)
    );
    // Every call counts in the paper convention.
    let p = tr.counts(Convention::Paper);
    assert_eq!(
        (p.mul, p.add, p.div, p.sqrt, p.sin, p.cos),
        (7, 9, 3, 1, 1, 1)
    );
    // Nothing is reachable.
    assert_eq!(tr.counts(Convention::Emitted), Counts::default());
}

#[test]
fn folded_count_excludes_folded_calls_but_includes_cse_hits() {
    let tr = trace(|t| {
        let x = t.input("x");
        let y = t.input("y");
        let a = x * y;
        let b = y * x; // hash-cons hit: still one folded operation
        let _ = x * c(0.0) + c(0.0); // fully folded
        vec![a, b]
    });
    assert_eq!(ma(&tr), [(3, 1), (2, 0), (1, 0)]);
}

// ------------------------------------------------------------------------------------------
// Hash-consing and sign normalisation.

#[test]
fn hash_consing() {
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        assert_eq!((a * b).id(), (b * a).id());
        assert_eq!((a + b).id(), (b + a).id());
        assert_ne!((a - b).id(), (b - a).id());
        assert_eq!((a / b).id(), (a / b).id());
        assert_ne!((a / b).id(), (b / a).id());
        assert_eq!((a.sin()).id(), (a.sin()).id());
        assert_eq!((c(1.5)).id(), (c(1.5)).id());
        // Inputs are distinct per call, even with the same name.
        let a2 = t.input("a");
        assert_ne!((a).id(), (a2).id());
        assert_ne!((a * b).id(), (a2 * b).id());
        vec![a * b]
    });
    assert_eq!(tr.input_names(), ["a", "b", "a"]);
}

#[test]
fn sign_normalisation() {
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        assert_eq!(((-a) * b).id(), (-(a * b)).id());
        assert_eq!((a * (-b)).id(), (-(a * b)).id());
        assert_eq!(((-a) * (-b)).id(), (a * b).id());
        assert_eq!((a + (-b)).id(), (a - b).id());
        assert_eq!(((-a) + b).id(), (b - a).id());
        assert_eq!(((-a) + (-b)).id(), (-(a + b)).id());
        assert_eq!((a - (-b)).id(), (a + b).id());
        assert_eq!(((-a) - b).id(), (-(a + b)).id());
        assert_eq!(((-a) - (-b)).id(), (b - a).id());
        assert_eq!(((-a) / b).id(), (-(a / b)).id());
        assert_eq!((a / (-b)).id(), (-(a / b)).id());
        assert_eq!(((-a) + a).id(), (c(0.0)).id());
        assert_eq!((a + (-a)).id(), (c(0.0)).id());
        vec![]
    });
    // Negations never nest and never wrap another negation.
    for (_, n) in tr.schedule() {
        if let Node::Neg(inner) = n {
            assert!(!matches!(tr.node(inner), Node::Neg(_)));
        }
    }
    // (-a)*(-b): one multiplication after folding, no negation left.
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        vec![(-a) * (-b)]
    });
    let f = tr.counts(Convention::Folded);
    assert_eq!(f.mul, 1);
    assert_eq!(tr.counts(Convention::Emitted).neg, 0);
    assert_eq!(tr.counts(Convention::Paper).neg, 2);
    assert!(matches!(tr.node(tr.outputs()[0]), Node::Mul(..)));
}

// ------------------------------------------------------------------------------------------
// The primitives of the paper's counting convention (docs/paper.md, "Operation counts").

#[test]
fn skew_skew_product() {
    let tr = trace(|t| {
        let x = vec_in(t, "x");
        let y = vec_in(t, "y");
        mat_out(Mat3::skew(&x).mul_mat(&Mat3::skew(&y).transpose()))
    });
    assert_eq!(ma(&tr), [(27, 27), (12, 3), (9, 3)]);
}

#[test]
fn scaled_skew_skew_product() {
    let tr = trace(|t| {
        let m = t.input("m");
        let x = vec_in(t, "x");
        let y = vec_in(t, "y");
        mat_out(
            Mat3::skew(&x)
                .mul_mat(&Mat3::skew(&y).transpose())
                .scale(&m),
        )
    });
    assert_eq!(ma(&tr), [(36, 27), (21, 3), (18, 3)]);
}

#[test]
fn bilinear_form() {
    let tr = trace(|t| {
        let a = vec_in(t, "a");
        let m = mat_in(t, "M");
        let b = vec_in(t, "b");
        vec![a.dot(&m.mul_vec(&b))]
    });
    assert_eq!(ma(&tr), [(12, 12), (12, 8), (12, 8)]);
}

#[test]
fn cross_product() {
    let tr = trace(|t| {
        let x = vec_in(t, "x");
        let f = vec_in(t, "f");
        Mat3::skew(&x).mul_vec(&f).into_array().to_vec()
    });
    assert_eq!(ma(&tr), [(9, 9), (6, 3), (6, 3)]);
}

// ------------------------------------------------------------------------------------------
// Evaluation.

/// A generic function exercising every operation, folding and sign normalisation.
fn mixed<S: Scalar>(v: &[S]) -> Vec<S> {
    let x = Vec3::new(v[0].clone(), v[1].clone(), v[2].clone());
    let y = Vec3::new(v[3].clone(), v[4].clone(), v[5].clone());
    let (s, co) = v[6].clone().sin_cos();
    let u = Vec3::new(S::constant(0.6), S::zero(), S::constant(0.8));
    let r = kanegen_dynamics::linalg::axis_rotation(&u, &s, &co);
    let p = Mat3::skew(&x).mul_mat(&Mat3::skew(&y).transpose());
    let q = r.mul_mat(&p).mul_mat(&r.transpose());
    let n = x.dot(&x).sqrt();
    let w = (-x.cross(&y)).scale(&(S::one() / n.clone()));
    let z = (-(v[0].clone()) - v[1].clone()) / (-(v[2].clone()) + S::constant(3.5))
        + v[6].clone().sin() * v[5].clone().cos()
        - (S::zero() - v[3].clone()) * S::constant(-1.0);
    let mut out: Vec<S> = q.into_array().into_iter().flatten().collect();
    out.extend(w.into_array());
    out.push(z);
    out.push(n);
    out
}

#[test]
fn eval_matches_f64() {
    let inputs = [0.3, -1.2, 2.5, 1.1, 0.7, -0.4, 0.9];
    let tr = trace(|t| {
        let v: Vec<Sym> = (0..inputs.len())
            .map(|i| t.input(format!("v{i}")))
            .collect();
        mixed(&v)
    });
    let want = mixed(&inputs);
    let got = tr.eval(&inputs);
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).abs() <= 1e-14 * w.abs().max(1.0), "{g} vs {w}");
    }
    // A second point, to make sure nothing is baked in.
    let inputs2 = [-0.7, 0.2, 1.9, -2.1, 0.4, 1.3, -2.2];
    let want2 = mixed(&inputs2);
    for (g, w) in tr.eval(&inputs2).iter().zip(&want2) {
        assert!((g - w).abs() <= 1e-14 * w.abs().max(1.0), "{g} vs {w}");
    }
}

#[test]
#[should_panic(expected = "expected 2 input values")]
fn eval_with_missing_inputs_panics() {
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        vec![a + b]
    });
    let _ = tr.eval(&[1.0]);
}

#[test]
fn schedule_is_topological_and_minimal() {
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        let _dead = a / b + c(3.0);
        let s = (a * b).sin();
        vec![s + a, s]
    });
    let sched = tr.schedule();
    let ids: Vec<u32> = sched.iter().map(|(i, _)| *i).collect();
    // a, b, a*b, sin, s + a — the division and the constant 3 are dead.
    assert_eq!(sched.len(), 5);
    assert!(ids.windows(2).all(|w| w[0] < w[1]));
    for (id, n) in &sched {
        let deps: Vec<Sym> = match *n {
            Node::Add(x, y) | Node::Sub(x, y) | Node::Mul(x, y) | Node::Div(x, y) => vec![x, y],
            Node::Neg(x) | Node::Sin(x) | Node::Cos(x) | Node::Sqrt(x) => vec![x],
            Node::Const(_) | Node::Input(_) => vec![],
        };
        for d in deps {
            assert!(ids.contains(&d.id()), "operand {} not scheduled", d.id());
            assert!(d.id() < *id, "operand {} after its user {id}", d.id());
        }
    }
    let kinds: Vec<&str> = sched
        .iter()
        .map(|(_, n)| match n {
            Node::Input(_) => "in",
            Node::Mul(..) => "mul",
            Node::Sin(_) => "sin",
            Node::Add(..) => "add",
            _ => "other",
        })
        .collect();
    assert_eq!(kinds, ["in", "in", "mul", "sin", "add"]);
    match tr.node(tr.outputs()[1]) {
        Node::Sin(arg) => assert_eq!(arg.id(), sched[2].0),
        n => panic!("expected a sine, got {n:?}"),
    }
}

// ------------------------------------------------------------------------------------------
// Dead code, trig counting, sections.

#[test]
fn dead_code_not_emitted() {
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        let _unused = a * b + b / a;
        let used = a - b;
        vec![used, -used]
    });
    let p = tr.counts(Convention::Paper);
    let e = tr.counts(Convention::Emitted);
    assert_eq!((p.mul, p.add, p.div, p.neg), (1, 2, 1, 1));
    assert_eq!((e.mul, e.add, e.div, e.neg), (0, 1, 0, 1));
}

#[test]
fn trig_counts() {
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        let (sa, ca) = a.sin_cos();
        let sb = b.sin();
        let cb = b.cos();
        let _dead = (a + b).cos();
        let _folded = c(1.0).sin_cos();
        vec![sa, ca, sb, cb]
    });
    let k = |cv| {
        let k: Counts = tr.counts(cv);
        (k.sin, k.cos, k.sincos)
    };
    assert_eq!(k(Convention::Paper), (3, 4, 5));
    assert_eq!(k(Convention::Folded), (2, 3, 4));
    assert_eq!(k(Convention::Emitted), (2, 2, 2));
}

#[test]
fn sections_attribute_counts() {
    let tr = trace(|t| {
        let a = t.input("a");
        let b = t.input("b");
        let pre = a + b; // unlabelled
        <Sym as Scalar>::section("A");
        let _p = a * b; // emitted here, in A
        let _dead = a * c(0.0);
        <Sym as Scalar>::section("B");
        let q = b * a; // CSE hit: emitted in A
        let r = q - pre;
        <Sym as Scalar>::section("A");
        let s = r / a;
        vec![s]
    });
    let by = |cv| tr.counts_by_section(cv);
    let names: Vec<String> = by(Convention::Paper).into_iter().map(|(n, _)| n).collect();
    assert_eq!(names, ["", "A", "B"]);
    let get = |cv, i: usize| {
        let k = by(cv)[i].1;
        (k.mul, k.add, k.div)
    };
    assert_eq!(get(Convention::Paper, 0), (0, 1, 0));
    assert_eq!(get(Convention::Paper, 1), (2, 0, 1));
    assert_eq!(get(Convention::Paper, 2), (1, 1, 0));
    assert_eq!(get(Convention::Folded, 1), (1, 0, 1));
    assert_eq!(get(Convention::Folded, 2), (1, 1, 0));
    assert_eq!(get(Convention::Emitted, 0), (0, 1, 0));
    assert_eq!(get(Convention::Emitted, 1), (1, 0, 1));
    assert_eq!(get(Convention::Emitted, 2), (0, 1, 0));
    for cv in Convention::ALL {
        let sum = by(cv)
            .into_iter()
            .fold(Counts::default(), |acc, (_, k)| acc + k);
        assert_eq!(sum, tr.counts(cv));
    }
}

#[test]
fn unlabelled_section_listed_only_when_used() {
    let tr = trace(|t| {
        let a = t.input("a");
        <Sym as Scalar>::section("only");
        vec![a * a]
    });
    let by = tr.counts_by_section(Convention::Emitted);
    assert_eq!(by.len(), 1);
    assert_eq!(by[0].0, "only");
    assert_eq!(by[0].1.mul, 1);
}

#[test]
fn counts_arithmetic_and_names() {
    let a = Counts {
        mul: 2,
        add: 3,
        neg: 7,
        ..Counts::default()
    };
    let mut b = Counts {
        mul: 1,
        div: 4,
        ..Counts::default()
    };
    b += a;
    assert_eq!(
        b,
        Counts {
            mul: 3,
            add: 3,
            div: 4,
            neg: 7,
            ..Counts::default()
        }
    );
    assert_eq!((a + a).total(), 10);
    let names: Vec<_> = Convention::ALL.iter().map(|c| c.name()).collect();
    assert_eq!(names, ["paper", "folded", "emitted"]);
}

// ------------------------------------------------------------------------------------------
// Misuse.

#[test]
#[should_panic(expected = "no active Tracer on this thread")]
fn no_tracer_panics() {
    let _ = Sym::constant(1.0);
}

#[test]
#[should_panic(expected = "no active Tracer on this thread")]
fn sym_after_drop_panics() {
    let x = {
        let t = Tracer::new();
        t.input("x")
    };
    let _ = x + x;
}

#[test]
#[should_panic(expected = "no active Tracer on this thread")]
fn sym_from_dropped_tracer_under_new_tracer_panics() {
    let x = {
        let t = Tracer::new();
        t.input("x")
    };
    let t = Tracer::new();
    let y = t.input("y");
    let _ = x + y;
}

#[test]
#[should_panic(expected = "already active")]
fn two_tracers_panic() {
    let _a = Tracer::new();
    let _b = Tracer::new();
}

#[test]
fn tracer_is_reusable_after_finish_and_drop() {
    let t1 = trace(|t| vec![t.input("a") * c(2.0)]);
    {
        let t = Tracer::new();
        let _ = t.input("z") + c(1.0);
    }
    let t2 = trace(|t| vec![t.input("b") + c(2.0)]);
    assert_eq!(t1.eval(&[3.0]), [6.0]);
    assert_eq!(t2.eval(&[3.0]), [5.0]);
    assert_eq!(t2.counts(Convention::Paper).mul, 0);
}

#[test]
fn large_trace_evaluates() {
    // A long recurrence with many shared subexpressions: x_{k+1} = x_k·c_k + s_k, where the
    // c_k, s_k are sin/cos of inputs; checks eval and the counting scale linearly.
    let n = 20_000;
    let vals: Vec<f64> = (0..n).map(|i| 0.001 * i as f64).collect();
    let tr = trace(|t| {
        let qs: Vec<Sym> = (0..n).map(|i| t.input(format!("q{i}"))).collect();
        let mut x = Sym::one();
        for q in &qs {
            let (s, co) = q.sin_cos();
            x = x * co + s * c(0.5) - Sym::zero();
        }
        vec![x]
    });
    let mut want = 1.0f64;
    for q in &vals {
        let (s, c) = q.sin_cos();
        want = want * c + s * 0.5 - 0.0;
    }
    let got = tr.eval(&vals)[0];
    assert!(
        (got - want).abs() <= 1e-12 * want.abs().max(1.0),
        "{got} vs {want}"
    );
    let e = tr.counts(Convention::Emitted);
    let n = n as u64;
    // The first step folds 1·c; every later step costs 2 m + 1 a.
    assert_eq!((e.mul, e.add, e.sincos), (2 * n - 1, n, n));
    assert_eq!(tr.counts(Convention::Paper).add, 2 * n);
}

/// One step of a random straight-line program over registers (operands index earlier registers).
#[derive(Clone, Debug)]
enum Step {
    Const(f64),
    Bin(u8, usize, usize),
    Un(u8, usize),
}

fn run<S: Scalar>(inputs: &[S], prog: &[Step]) -> Vec<S> {
    let mut r: Vec<S> = inputs.to_vec();
    for st in prog {
        let n = r.len();
        let v = match *st {
            Step::Const(x) => S::constant(x),
            Step::Bin(op, i, j) => {
                let (a, b) = (r[i % n].clone(), r[j % n].clone());
                match op % 4 {
                    0 => a + b,
                    1 => a - b,
                    2 => a * b,
                    _ => a / b,
                }
            }
            Step::Un(op, i) => {
                let a = r[i % n].clone();
                match op % 5 {
                    0 => -a,
                    1 => a.sin(),
                    2 => a.cos(),
                    3 => a.sqrt(),
                    _ => a.sin_cos().1,
                }
            }
        };
        r.push(v);
    }
    r
}

mod random_programs {
    use super::*;
    use proptest::prelude::*;

    fn step() -> impl Strategy<Value = Step> {
        prop_oneof![
            prop::sample::select(vec![0.0, 1.0, -1.0, 2.5, -0.0]).prop_map(Step::Const),
            (0u8..4, 0usize..64, 0usize..64).prop_map(|(o, i, j)| Step::Bin(o, i, j)),
            (0u8..5, 0usize..64).prop_map(|(o, i)| Step::Un(o, i)),
        ]
    }

    proptest! {
        /// Folding and sign normalisation are exact in IEEE arithmetic, so every finite value of a
        /// random program is reproduced bit for bit (up to the sign of zero) by the trace.
        #[test]
        fn eval_equals_f64(
            xs in prop::collection::vec(-3.0f64..3.0, 1..4),
            prog in prop::collection::vec(step(), 1..40),
        ) {
            let want = run(&xs, &prog);
            let tr = trace(|t| {
                let ins: Vec<Sym> = (0..xs.len()).map(|i| t.input(format!("x{i}"))).collect();
                run(&ins, &prog)
            });
            let got = tr.eval(&xs);
            for (g, w) in got.iter().zip(&want) {
                if w.is_finite() {
                    prop_assert!(g == w, "{} vs {}", g, w);
                }
            }
            // Folding never increases a count; CSE and DCE never increase it further.
            let [p, f, e] = Convention::ALL.map(|c| tr.counts(c));
            for (a, b) in [(p, f), (f, e)] {
                prop_assert!(a.mul >= b.mul && a.add >= b.add && a.div >= b.div);
                prop_assert!(a.sin >= b.sin && a.cos >= b.cos && a.sqrt >= b.sqrt);
                prop_assert!(a.sincos >= b.sincos);
            }
        }
    }
}
