//! The paper's printed (14b) — what Table 1 counts — evaluated through the tracer, the only way
//! to evaluate it: it is exact for N ≤ 2 and wrong for N ≥ 3.

use kanegen_dynamics::algorithms::kinematics::inertial_frame;
use kanegen_dynamics::algorithms::recurrent::{self, Variant};
use kanegen_dynamics::metrics::rel_err_mat as rel_err;
use kanegen_dynamics::{Params, Scalar};
use kanegen_model::random::{random_chain, random_vec, rng, ChainSpec};
use kanegen_trace::sym::{record, Sym};

const SEEDS: std::ops::Range<u64> = 0..6;

/// `A` by the printed (14b), evaluated numerically from its trace (every input a constant).
fn paper_a(model: &kanegen_model::Model, q: &[f64]) -> Vec<Vec<f64>> {
    let n = q.len();
    let t = record(|_| {
        let qs: Vec<Sym> = q.iter().map(|&x| Sym::constant(x)).collect();
        let kin = inertial_frame(&Params::<Sym>::new(model), &qs);
        recurrent::mass_matrix_paper_bookkeeping(&kin)
            .into_iter()
            .flatten()
            .collect()
    });
    let v = t.eval(&[]);
    v.chunks(n).map(<[f64]>::to_vec).collect()
}

#[test]
fn variant_p_is_exact_only_up_to_two_bodies() {
    let mut smallest_wrong = f64::INFINITY;
    for n in 1..=10 {
        for seed in SEEDS.clone() {
            let model = random_chain(
                &ChainSpec {
                    n,
                    ..Default::default()
                },
                seed,
            );
            let q = random_vec(&mut rng(seed ^ 0x5eed), n, 2.0);
            let p = Params::<f64>::new(&model);
            let e = rel_err(
                &paper_a(&model, &q),
                &recurrent::mass_matrix(&p, &q, Variant::R2),
            );
            if n <= 2 {
                assert!(e < 1e-14, "P should be exact for N = {n}: {e:e}");
            } else {
                smallest_wrong = smallest_wrong.min(e);
                assert!(
                    e > 1e-3,
                    "P unexpectedly close for N = {n}, seed {seed}: {e:e}"
                );
            }
        }
    }
    println!("variant P, N >= 3: smallest rel err {smallest_wrong:.2e}");
}
