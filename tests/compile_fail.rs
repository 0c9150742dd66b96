//! `dynamics!` rejects bad models at compile time with the reader's message at the path literal
//! (also a model with joints that move no mass, naming the joints),
//! and bad options (`scalar = f16`, `fma_path` without `fma = true`, `snap = 0.5`,
//! `algorithm = "fastest"`, `form = "rolled"`, gravity beyond its bound, an unknown key, a
//! key given twice) at the option, and a type name that would shadow a path the generated code
//! calls (`f64` with `fma_path = f64::mul_add`) at the name; `scene!` rejects a
//! bad scene key (the scene reader's message), a value for a mimic joint (naming the joint it
//! follows) and a feature it does not generate (a tabulated
//! wrench with a computed-torque drive), naming the key and the scene file, at the path literal.
//!
//! trybuild compiles each case in its own project, `<target>/tests/trybuild/kanegen`, whose
//! `CARGO_MANIFEST_DIR` is that directory: the bad models of `tests/data/codegen/bad/` are copied
//! there first, and the cases name them relative to it (`bad/…`); the scenes there name
//! `models/two_link.toml`, copied next to `bad/`.

use std::path::Path;

#[test]
fn dynamics_macro_errors() {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("the target tmp dir has a parent");
    let project = target.join("tests/trybuild/kanegen/bad");
    std::fs::create_dir_all(&project).unwrap();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/codegen/bad");
    for e in std::fs::read_dir(&src).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), project.join(e.file_name())).unwrap();
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(
        root.join("models/two_link.toml"),
        project.parent().unwrap().join("two_link.toml"),
    )
    .unwrap();
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
