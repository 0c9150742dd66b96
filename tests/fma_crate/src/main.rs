//! Prints `M(q)` (upper triangle) and `c(q, q̇)` of the SSRMS at the states on stdin, one line of
//! `f64` bit patterns (hex) per state: `q` and `q̇` come as 14 numbers per line. It also checks that
//! the checked-in `kanegen-generated` SSRMS (the same code, in a crate that denies unsafe code)
//! builds with FMA and gives the same bits.

use std::io::BufRead;

kanegen::dynamics!(Ssrms, "../data/reference/ssrms_nguyen_hughes_1994.urdf");

fn main() {
    for line in std::io::stdin().lock().lines() {
        let line = line.expect("stdin");
        let x: Vec<f64> = line
            .split_whitespace()
            .map(|t| t.parse().expect("a number"))
            .collect();
        let q: [f64; 7] = core::array::from_fn(|i| x[i]);
        let qd: [f64; 7] = core::array::from_fn(|i| x[7 + i]);
        let (m, c) = Ssrms::mass_matrix_and_nonlinear_effects(&q, &qd);
        // The checked-in file is the same code: the same bits.
        assert_eq!(
            kanegen_generated::ssrms::Ssrms::mass_matrix_and_nonlinear_effects(&q, &qd),
            (m, c)
        );
        let out: Vec<String> = (0..7)
            .flat_map(|i| (i..7).map(move |j| (i, j)))
            .map(|(i, j)| m[i][j])
            .chain(c)
            .map(|v| format!("{:016x}", v.to_bits()))
            .collect();
        println!("{}", out.join(" "));
    }
}
