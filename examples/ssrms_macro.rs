//! One `kanegen::dynamics!` expansion for SSRMS, used to measure what a macro expansion costs at
//! compile time (`docs/codegen.md`). Prints `A(q)` at `q = 0`.
//!
//! Run: `cargo run --release --example ssrms_macro`

kanegen::dynamics!(
    SsrmsMacro,
    "tests/data/reference/ssrms_nguyen_hughes_1994.urdf"
);

fn main() {
    let a = SsrmsMacro::mass_matrix(&[0.0; SsrmsMacro::N]);
    for row in a {
        println!("{}", row.map(|x| format!("{x:>12.3}")).join(" "));
    }
}
