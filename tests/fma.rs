//! Generated code fuses its products where the build targets FMA (`Options::target_fma`): the
//! SSRMS `mass_matrix_and_nonlinear_effects` built with `-C target-feature=+fma`
//! (`tests/fma_crate`) agrees with the same code built without it (the checked-in
//! `kanegen-generated`, compiled for the baseline x86-64 of this test binary) to rounding, and
//! differs from it in the last bits — the products really are fused. Skipped, with a printed
//! reason, on a host that is not x86-64 or whose CPU has no FMA.

mod precondition;

use kanegen::dynamics::metrics::rel_err;
use kanegen::model::random::{random_vec, rng};
use kanegen_generated::ssrms::Ssrms;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

fn host_triple() -> String {
    let out = Command::new("rustc")
        .arg("-vV")
        .output()
        .expect("run rustc");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .expect("rustc -vV names the host")
        .to_string()
}

#[test]
fn fused_build_agrees_with_the_plain_build_and_differs_in_the_last_bits() {
    if !cfg!(target_arch = "x86_64") || !std::arch::is_x86_feature_detected!("fma") {
        precondition::absent(
            "fma",
            "this host has no x86-64 FMA to run the fused build on",
        );
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let triple = host_triple();
    // `--target` keeps RUSTFLAGS off the proc-macro, so the host artifacts are shared with the
    // no_std crate's build in the same target directory.
    let target_dir = root.join("target/no_std_crate");
    let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .current_dir(root.join("tests/fma_crate"))
        .env("CARGO_TARGET_DIR", &target_dir)
        .env("RUSTFLAGS", "-C target-feature=+fma")
        .args([
            "build",
            "--release",
            "--locked",
            "--offline",
            "--target",
            &triple,
        ])
        .output()
        .expect("run cargo build");
    assert!(
        out.status.success(),
        "the fused build fails:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let exe = target_dir
        .join(&triple)
        .join("release")
        .join("kanegen-fma-check");
    let mut r = rng(17);
    let states: Vec<(Vec<f64>, Vec<f64>)> = (0..50)
        .map(|_| (random_vec(&mut r, 7, 3.0), random_vec(&mut r, 7, 1.0)))
        .collect();
    let mut child = Command::new(&exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("run the fused build");
    {
        let mut stdin = child.stdin.take().expect("stdin");
        for (q, qd) in &states {
            let line: Vec<String> = q.iter().chain(qd).map(|x| format!("{x:e}")).collect();
            writeln!(stdin, "{}", line.join(" ")).unwrap();
        }
    }
    let out = child.wait_with_output().expect("fused build output");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let (mut worst, mut differ) = (0.0_f64, 0);
    for ((q, qd), line) in states.iter().zip(text.lines()) {
        let fused: Vec<f64> = line
            .split_whitespace()
            .map(|h| f64::from_bits(u64::from_str_radix(h, 16).unwrap()))
            .collect();
        let q: [f64; 7] = core::array::from_fn(|i| q[i]);
        let qd: [f64; 7] = core::array::from_fn(|i| qd[i]);
        let (m, c) = Ssrms::mass_matrix_and_nonlinear_effects(&q, &qd);
        let plain: Vec<f64> = (0..7)
            .flat_map(|i| (i..7).map(move |j| (i, j)))
            .map(|(i, j)| m[i][j])
            .chain(c)
            .collect();
        assert_eq!(fused.len(), plain.len());
        worst = worst.max(rel_err(&fused, &plain));
        differ += usize::from(fused != plain);
    }
    assert_eq!(text.lines().count(), states.len());
    println!("fused vs plain: worst {worst:.1e}, {differ} of 50 states differ in some bit");
    assert!(worst < 1e-13, "{worst:e}");
    assert!(
        differ > 25,
        "only {differ} of 50 states differ: are the products fused?"
    );
}
