//! Prints `M(q)` (upper triangle) and `c(q, q̇)` of the SSRMS at the states on stdin, one line of
//! `f64` bit patterns (hex) per state: `q` and `q̇` come as 14 numbers per line. It also checks that
//! the checked-in `kanegen-generated` SSRMS (the same code, in a crate that denies unsafe code)
//! builds with FMA and gives the same bits, and that the `f64x4` batches give them too.

use std::io::BufRead;

kanegen::dynamics!(Ssrms, "../data/reference/ssrms_nguyen_hughes_1994.urdf");

fn main() {
    let mut states: Vec<([f64; 7], [f64; 7])> = Vec::new();
    for line in std::io::stdin().lock().lines() {
        let line = line.expect("stdin");
        let x: Vec<f64> = line
            .split_whitespace()
            .map(|t| t.parse().expect("a number"))
            .collect();
        states.push((
            core::array::from_fn(|i| x[i]),
            core::array::from_fn(|i| x[7 + i]),
        ));
    }
    let results: Vec<_> = states
        .iter()
        .map(|(q, qd)| Ssrms::mass_matrix_and_nonlinear_effects(q, qd))
        .collect();
    lanes_are_the_one_state_results(&states, &results);
    for ((q, qd), (m, c)) in states.iter().zip(&results) {
        // The checked-in file is the same code: the same bits.
        assert_eq!(
            kanegen_generated::ssrms::Ssrms::mass_matrix_and_nonlinear_effects(q, qd),
            (*m, *c)
        );
        let out: Vec<String> = (0..7)
            .flat_map(|i| (i..7).map(move |j| (i, j)))
            .map(|(i, j)| m[i][j])
            .chain(*c)
            .map(|v| format!("{:016x}", v.to_bits()))
            .collect();
        println!("{}", out.join(" "));
    }
}

/// The batches on four lanes give every state's one-state results bit for bit: in this build
/// (AVX, from `+fma`) a whole chunk's rows are written by AVX's transposes
/// (`kanegen::runtime::lanes`), a partial last chunk number by number.
fn lanes_are_the_one_state_results(
    states: &[([f64; 7], [f64; 7])],
    results: &[([[f64; 7]; 7], [f64; 7])],
) {
    use kanegen::runtime::lanes::f64x4;
    let (q, qd): (Vec<[f64; 7]>, Vec<[f64; 7]>) = states.iter().copied().unzip();
    let bits = |m: &[[f64; 7]; 7], c: &[f64; 7]| -> Vec<u64> {
        m.iter().flatten().chain(c).map(|v| v.to_bits()).collect()
    };
    let mut both = vec![([[0.0; 7]; 7], [0.0; 7]); states.len()];
    Ssrms::mass_matrix_and_nonlinear_effects_batch::<f64x4>(&q, &qd, &mut both);
    let mut m = vec![[[0.0; 7]; 7]; states.len()];
    Ssrms::mass_matrix_batch::<f64x4>(&q, &mut m);
    for (k, (r, (b, mk))) in results.iter().zip(both.iter().zip(&m)).enumerate() {
        assert_eq!(
            bits(&b.0, &b.1),
            bits(&r.0, &r.1),
            "state {k}: (M, c) on f64x4"
        );
        assert_eq!(
            bits(mk, &[0.0; 7]),
            bits(&r.0, &[0.0; 7]),
            "state {k}: M on f64x4"
        );
    }
}
