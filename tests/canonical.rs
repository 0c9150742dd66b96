//! `Model::canonical` turns body frames about their joint axes and snaps float noise; the robot
//! must not change. Oracle: the spatial algorithms (CRBA + RNEA, which take any axis) on the
//! original and on the canonical model agree on `M`, the bias with gravity, frame placements in
//! the base frame and frame Jacobians — fixed and free-floating base, random trees with prismatic
//! joints and the 15 Pinocchio robots of `tests/data/erd/`.

use kanegen::dynamics::algorithms::{crba, floating, frames, rnea};
use kanegen::dynamics::base::{FloatingBase, FloatingState};
use kanegen::dynamics::linalg::Vec3;
use kanegen::dynamics::metrics::{rel_err, rel_err_mat};
use kanegen::dynamics::{Loads, Methods, Params};
use kanegen::model::canonical::DEFAULT_SNAP;
use kanegen::model::io::load_model;
use kanegen::model::random::{random_tree, random_vec, rng, ChainSpec};
use kanegen::model::{BaseKind, Model};
use std::path::Path;

const TOL: f64 = 1e-12;

fn gravity() -> Loads<f64> {
    Loads {
        gravity: Some(Vec3::new(0.3, -1.1, -9.81)),
        ..Default::default()
    }
}

/// Largest relative difference between the two models' dynamics and frames at random states.
fn compare(a: &Model, b: &Model, seed: u64) -> f64 {
    let (pa, pb) = (Params::<f64>::new(a), Params::<f64>::new(b));
    let n = pa.dof();
    let mut r = rng(seed);
    let mut worst = 0.0_f64;
    for _ in 0..3 {
        let q = random_vec(&mut r, n, 2.0);
        let qd = random_vec(&mut r, n, 1.5);
        worst = worst.max(rel_err_mat(
            &crba::mass_matrix(&pa, &q),
            &crba::mass_matrix(&pb, &q),
        ));
        worst = worst.max(rel_err(
            &rnea::tau_minus_c(&pa, &q, &qd, &gravity()),
            &rnea::tau_minus_c(&pb, &q, &qd, &gravity()),
        ));
        for (fa, fb) in pa.frames.iter().zip(&pb.frames) {
            let (ta, ra) = frames::placement(&pa, &q, fa);
            let (tb, rb) = frames::placement(&pb, &q, fb);
            worst = worst.max(rel_err(&ta.0, &tb.0));
            let rows = |m: &kanegen::dynamics::linalg::Mat3<f64>| m.0.concat();
            worst = worst.max(rel_err(&rows(&ra), &rows(&rb)));
            worst = worst.max(rel_err_mat(
                &frames::jacobian(&pa, &q, fa),
                &frames::jacobian(&pb, &q, fb),
            ));
        }
        if let (Some(ia), Some(ib)) = (a.base_inertial(), b.base_inertial()) {
            let (ba, bb) = (
                FloatingBase::from_inertial(ia),
                FloatingBase::from_inertial(ib),
            );
            let mut s = FloatingState::at_rest();
            let w = random_vec(&mut r, 6, 0.7);
            s.v_b = Vec3::new(w[0], w[1], w[2]);
            s.omega_b = Vec3::new(w[3], w[4], w[5]);
            let m = Methods::SPATIAL;
            worst = worst.max(rel_err_mat(
                &floating::mass_matrix(m.mass_matrix, &pa, &ba, &s, &q),
                &floating::mass_matrix(m.mass_matrix, &pb, &bb, &s, &q),
            ));
            worst = worst.max(rel_err(
                &floating::tau_minus_c(m.nonlinear_effects, &pa, &ba, &s, &q, &qd, &gravity()),
                &floating::tau_minus_c(m.nonlinear_effects, &pb, &bb, &s, &q, &qd, &gravity()),
            ));
        }
    }
    worst
}

#[test]
fn random_trees_keep_their_dynamics() {
    let mut worst = 0.0_f64;
    for n in 1..=10 {
        let spec = ChainSpec {
            n,
            prismatic_fraction: 0.3,
            ..Default::default()
        };
        let m = random_tree(&spec, 70 + n as u64);
        let c = m.canonical().unwrap();
        assert!(c.model.joints().iter().all(|j| j.axis == [0.0, 0.0, 1.0]));
        assert_eq!(c.report.turned, n, "random axes: every body turns");
        worst = worst.max(compare(&m, &c.model, n as u64));
    }
    println!("random trees: worst relative difference {worst:.1e}");
    assert!(worst < TOL, "{worst:e}");
}

#[test]
fn pinocchio_robots_keep_their_dynamics_and_lose_their_noise() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/erd");
    let mut urdfs: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "urdf"))
        .collect();
    urdfs.sort();
    assert!(urdfs.len() >= 15, "{} URDFs", urdfs.len());
    let (mut worst, mut snapped, mut loose_snapped, mut snapped_alone) = (0.0_f64, 0, 0, 0);
    for (i, path) in urdfs.iter().enumerate() {
        let m = load_model(path).unwrap();
        // A loose tolerance also takes `rpy = 1.570796325`'s 4.9e-12 residues, and changes the
        // robot by about as much.
        let loose = m.canonical_with(1e-9).unwrap();
        assert!(loose.report.largest_snap <= 1e-9);
        let d = compare(&m, &loose.model, i as u64);
        assert!(
            d < 1e3 * loose.report.largest_snap.max(1e-15),
            "{}: {d:e} after snapping {:e}",
            path.display(),
            loose.report.largest_snap
        );
        loose_snapped += loose.report.snapped;
        let c = m.canonical().unwrap();
        assert!(c.report.largest_snap <= DEFAULT_SNAP);
        snapped += c.report.snapped;
        // Snapping alone (what the code generator applies): no frame turned, every joint's axis
        // and placement within the tolerance of the file's, the same dynamics.
        let s = m.snapped(DEFAULT_SNAP);
        assert_eq!(s.report.turned, 0);
        assert!(s.report.largest_snap <= DEFAULT_SNAP);
        snapped_alone += s.report.snapped;
        for (a, b) in m.joints().iter().zip(s.model.joints()) {
            let near =
                |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= DEFAULT_SNAP);
            assert!(near(&a.axis, &b.axis) && near(&a.origin.translation, &b.origin.translation));
            assert!(near(
                a.origin.rotation.as_flattened(),
                b.origin.rotation.as_flattened()
            ));
        }
        let d = compare(&m, &s.model, i as u64);
        assert!(d < TOL, "{} snapped: {d:e}", path.display());
        let d = compare(&m, &c.model, i as u64);
        worst = worst.max(d);
        assert!(d < TOL, "{}: {d:e}", path.display());
        if m.base_inertial().is_some() {
            let f = m.clone().with_base_kind(BaseKind::FreeFloating).unwrap();
            let cf = f.canonical().unwrap();
            assert_eq!(cf.model.base_kind(), BaseKind::FreeFloating);
            let d = compare(&f, &cf.model, 100 + i as u64);
            assert!(d < TOL, "{} free-floating: {d:e}", path.display());
        }
    }
    println!("15 robots: worst {worst:.1e}, {snapped} numbers snapped ({loose_snapped} at 1e-9)");
    // `rpy = 1.5707963267948966` leaves cos = 6.1e-17 (Panda), `1.570796325` 4.9e-12 (UR).
    assert!(snapped > 0, "the URDFs carry representation residues");
    assert!(snapped_alone > 0 && snapped_alone <= snapped);
    assert!(loose_snapped > snapped);
}

#[test]
fn coordinate_axes_turn_by_signed_permutations_exactly() {
    // An arm whose axes are ±x, ±y, z: every turned placement entry is a signed copy of an
    // original one (no rounding), so the canonical numbers are the originals rearranged.
    let m = random_tree(
        &ChainSpec {
            n: 6,
            ..Default::default()
        },
        5,
    );
    let axes = [
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let mut joints = m.joints().to_vec();
    for (j, a) in joints.iter_mut().zip(axes) {
        j.axis = a;
        j.origin.rotation = kanegen::model::placement::I3;
    }
    let m = Model::new(m.name(), m.base(), None, joints).unwrap();
    let c = m.canonical().unwrap();
    let originals: Vec<f64> = m
        .joints()
        .iter()
        .flat_map(|j| j.origin.translation.iter().map(|x| x.abs()))
        .collect();
    for j in c.model.joints() {
        for x in j.origin.translation {
            assert!(
                originals.contains(&x.abs()),
                "{x} is not a signed original translation"
            );
        }
        for x in j.origin.rotation.iter().flatten() {
            assert!([0.0, 1.0, -1.0].contains(x), "rotation entry {x}");
        }
    }
    assert_eq!(c.report.snapped, 0);
    assert!(compare(&m, &c.model, 9) < TOL);
}

/// A model at its validation bounds (inertia exactly 1e18 kg·m², found by `tests/fuzz.rs`):
/// turning its frames may round a number past the bound, so `canonical` says so instead of
/// panicking, and the generator keeps to the model's own frames.
#[test]
fn a_model_at_its_bounds_keeps_its_own_frames() {
    let text = r#"
name = "at_bounds"
[[joint]]
name = "j0"
type = "revolute"
xyz = [0.0, 0.0, 0.0]
rpy = [0.0, 0.0, 0.0]
axis = [0.0, 1.6692606987310081, -1.7946724189125696]
[joint.body]
mass = 0.26554066897078704
com = [0.0, 0.0, 0.0]
inertia = { ixx = 0.5, iyy = 0.6, izz = 0.7 }
[[joint]]
name = "j1"
type = "revolute"
xyz = [0.0, 0.0, 0.0]
rpy = [0.0, 0.0, 0.0]
axis = [0.6183691575941561, 0.0, 0.28166316518857754]
[joint.body]
mass = 1.2051721939607931
com = [0.0, 0.0, 0.0]
inertia = { ixx = 1e18, iyy = 1e18, izz = 1e18 }
"#;
    let m = kanegen::model::io::parse_toml(text).unwrap();
    let err = m.canonical().unwrap_err();
    assert!(err.to_string().contains("inertia"), "{err}");
    let g =
        kanegen::codegen::generate_items(&m, &kanegen::codegen::Options::new("AtBounds")).unwrap();
    assert!(g
        .choices
        .iter()
        .all(|ch| ch.candidates.iter().all(|c| c.frames.name() == "model")));
}
