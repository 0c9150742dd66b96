//! What published robot files need of the URDF reader: inertia checks with a tolerance relative
//! to the body's own magnitude (float noise passes, real violations do not, point masses pass),
//! massless bodies, `<limit>`, `<mimic>` (chains resolved, cycles and missing primaries refused)
//! and the notes of what was ignored and merged.

use kanegen_model::inertial::{nonphysical, PHYSICAL_TOLERANCE};
use kanegen_model::io::{parse_urdf, parse_urdf_noted, parse_urdf_with};
use kanegen_model::{Inertial, Validation};

/// A two-link robot: `base` fixed, `arm` on revolute `j1`, with `arm`'s `<inertial>` given.
fn one_joint(inertial: &str) -> String {
    format!(
        r#"<robot name="r"><link name="base"/>
        <link name="arm"><inertial><origin xyz="0.008 0 0.0553"/>{inertial}</inertial></link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="2" velocity="3" effort="40"/></joint>
        </robot>"#
    )
}

fn inertia(m: f64, [ixx, ixy, ixz, iyy, iyz, izz]: [f64; 6]) -> String {
    format!(
        r#"<mass value="{m}"/><inertia ixx="{ixx}" ixy="{ixy}" ixz="{ixz}" iyy="{iyy}" iyz="{iyz}" izz="{izz}"/>"#
    )
}

#[test]
fn float_noise_on_a_point_mass_passes_and_a_real_violation_does_not() {
    // iCub's l_ankle_2: a point mass of 0.2675 kg whose only inertia is ixz = 1.35e-20.
    let noisy = one_joint(&inertia(0.2675, [0.0, 0.0, 1.35525e-20, 0.0, 0.0, 0.0]));
    let m = parse_urdf(&noisy).unwrap();
    assert_eq!(m.joints()[0].inertial.mass, 0.2675);
    // The exact point mass, too.
    parse_urdf(&one_joint(&inertia(0.2675, [0.0; 6]))).unwrap();
    // The same off-diagonal entry at a physical size is a negative principal moment.
    let bad = one_joint(&inertia(0.2675, [0.0, 0.0, 1e-4, 0.0, 0.0, 0.0]));
    let e = parse_urdf(&bad).unwrap_err().to_string();
    for part in [
        "`j1`",
        "link `arm`",
        "URDF line 2",
        "positive semidefinite",
        "--allow-nonphysical",
        "allow_nonphysical = true",
    ] {
        assert!(e.contains(part), "{part}: {e}");
    }
    let allow = Validation {
        allow_nonphysical_inertia: true,
    };
    parse_urdf_with(&bad, allow).unwrap();
}

#[test]
fn the_tolerance_is_relative_to_the_bodys_magnitude() {
    let body = |i: [[f64; 3]; 3], com: [f64; 3]| Inertial {
        mass: 2.0,
        com,
        inertia: i,
    };
    let d = |a: f64, b: f64, c: f64| [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]];
    // Triangle inequality: 1 + 1 = 2 holds exactly (a thin disc); beyond it by a relative
    // 1e-12 passes, by 1e-6 does not, at any overall scale.
    for scale in [1e-9, 1.0, 1e6] {
        let s = |x: f64| x * scale;
        assert_eq!(
            nonphysical(&body(d(s(1.0), s(1.0), s(2.0)), [0.0; 3]), true),
            None
        );
        let noise = d(s(1.0), s(1.0), s(2.0 + 1e-12));
        assert_eq!(nonphysical(&body(noise, [0.0; 3]), true), None);
        let real = d(s(1.0), s(1.0), s(2.0 + 1e-6));
        let why = nonphysical(&body(real, [0.0; 3]), true).unwrap();
        assert!(why.contains("triangle"), "{why}");
        // Without the triangle check (a link on its own) it is a valid rod-like placeholder.
        assert_eq!(nonphysical(&body(real, [0.0; 3]), false), None);
        let neg = d(s(1.0), s(1.0), -s(1e-6));
        assert!(nonphysical(&body(neg, [0.0; 3]), false).is_some());
    }
    // Noise beyond the inertia's own magnitude, but far below the point mass's m|c|².
    let noise = 1e3 * PHYSICAL_TOLERANCE * 1e-20;
    let mut i = d(0.0, 0.0, 0.0);
    i[0][2] = noise;
    i[2][0] = noise;
    assert_eq!(nonphysical(&body(i, [0.1, 0.0, 0.0]), true), None);
    assert!(nonphysical(&body(i, [0.0; 3]), true).is_some());
}

#[test]
fn massless_bodies_load_and_forward_dynamics_names_them() {
    // romeo's fingers: mass 0 and inertia 0 on moving joints, behind a massive arm.
    let text = r#"<robot name="hand"><link name="base"/>
        <link name="palm"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
        <link name="finger"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
        <link name="tip"/>
        <joint name="wrist" type="revolute"><parent link="base"/><child link="palm"/></joint>
        <joint name="finger_joint" type="revolute"><parent link="palm"/><child link="finger"/></joint>
        <joint name="tip_joint" type="prismatic"><parent link="finger"/><child link="tip"/></joint>
        </robot>"#;
    let m = parse_urdf(text).unwrap();
    assert_eq!(m.massless_joints(), ["finger_joint", "tip_joint"]);
    let e = m.check_forward_dynamics().unwrap_err().to_string();
    assert!(
        e.contains("move no mass (no body with mass beyond them): joint `finger_joint`, joint `tip_joint`;") && !e.contains("wrist"),
        "{e}"
    );
    // Rotational inertia without mass is not physical.
    let spinning = text.replace(r#"<inertia ixx="0" ixy="0""#, r#"<inertia ixx="1" ixy="0""#);
    let e = parse_urdf(&spinning).unwrap_err().to_string();
    assert!(e.contains("mass 0 with rotational inertia"), "{e}");
}

#[test]
fn limits_are_read() {
    let m = parse_urdf(&one_joint(&inertia(1.0, [1.0, 0.0, 0.0, 1.0, 0.0, 1.0]))).unwrap();
    let l = m.limits()[0];
    assert_eq!(
        (l.lower, l.upper, l.velocity, l.effort),
        (Some(-1.0), Some(2.0), Some(3.0), Some(40.0))
    );
    let swapped = one_joint(&inertia(1.0, [1.0, 0.0, 0.0, 1.0, 0.0, 1.0]))
        .replace(r#"lower="-1" upper="2""#, r#"lower="2" upper="-1""#);
    let e = parse_urdf(&swapped).unwrap_err().to_string();
    assert!(e.contains("j1") && e.contains("lower 2 > upper -1"), "{e}");
    // Limits survive the canonical frames (same joints).
    assert_eq!(m.canonical_with(0.0).unwrap().model.limits(), m.limits());
}

const BOX: &str = r#"<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>"#;

/// Chain `a` → `b` → `c` → `d` of revolute joints; `mimics[k]` is the `<mimic>` of joint `k`.
fn chain(mimics: [&str; 4]) -> String {
    let mut s = r#"<robot name="m"><link name="l0"/><gazebo/><transmission name="t"/>"#.to_string();
    for (k, (name, mimic)) in ["a", "b", "c", "d"].iter().zip(mimics).enumerate() {
        s += &format!(
            r#"<link name="l{}">{BOX}<visual/></link>
            <joint name="{name}" type="revolute"><parent link="l{k}"/><child link="l{}"/>{mimic}</joint>"#,
            k + 1,
            k + 1
        );
    }
    s + r#"<link name="tool"/><joint name="flange" type="fixed"><parent link="l4"/><child link="tool"/><mimic joint="a"/></joint></robot>"#
}

#[test]
fn mimic_chains_resolve_to_the_primary() {
    let text = chain([
        "",
        r#"<mimic joint="a" multiplier="2" offset="0.5"/>"#,
        r#"<mimic joint="b" multiplier="-3" offset="0.25"/>"#,
        "",
    ]);
    let (m, notes) = parse_urdf_noted(&text, Validation::default()).unwrap();
    assert_eq!(m.coordinates(), [0, 3]);
    let b = m.mimics()[1].unwrap();
    assert_eq!((b.primary, b.multiplier, b.offset), (0, 2.0, 0.5));
    // q_c = −3 (2 q_a + 0.5) + 0.25 = −6 q_a − 1.25.
    let c = m.mimics()[2].unwrap();
    assert_eq!((c.primary, c.multiplier, c.offset), (0, -6.0, -1.25));
    assert!(m.mimics()[0].is_none() && m.mimics()[3].is_none());
    let e = m.lock_joint(3, 0.0).unwrap_err().to_string();
    assert!(e.contains("`b`") && e.contains("mimic joints"), "{e}");
    let free = m.clone().without_mimics();
    assert_eq!(free.coordinates(), [0, 1, 2, 3]);
    assert_eq!(free.lock_joint(1, 0.2).unwrap().dof(), 3);
    assert_eq!(notes.merged, ["tool"]);
    let ignored: Vec<(&str, usize)> = notes
        .ignored
        .iter()
        .map(|(k, v)| (k.as_str(), *v))
        .collect();
    assert_eq!(
        ignored,
        [
            ("gazebo", 1),
            ("mimic (on a fixed joint)", 1),
            ("transmission", 1),
            ("visual", 4)
        ]
    );
}

#[test]
fn mimic_cycles_and_missing_primaries_are_errors() {
    let cycle = chain([r#"<mimic joint="c"/>"#, "", r#"<mimic joint="a"/>"#, ""]);
    let e = parse_urdf(&cycle).unwrap_err().to_string();
    assert!(
        e.contains("`a`") && e.contains("a → c → a") && e.contains("cycle"),
        "{e}"
    );
    let missing = chain(["", r#"<mimic joint="nope"/>"#, "", ""]);
    let e = parse_urdf(&missing).unwrap_err().to_string();
    assert!(e.contains("`b`") && e.contains("no joint `nope`"), "{e}");
    let fixed = chain(["", r#"<mimic joint="flange"/>"#, "", ""]);
    let e = parse_urdf(&fixed).unwrap_err().to_string();
    assert!(e.contains("`flange`") && e.contains("is fixed"), "{e}");
}
