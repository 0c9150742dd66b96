//! Mimic joints ([`kanegen_dynamics::mimic`]): the reduced `M` and `c` of a tree with coupled
//! joints (a chain `a → b → c` and a branch `d` off `a`; `c` follows `b`, `d` follows `c`, so a
//! chain of mimics) against oracles that do not go through the reduction:
//!
//! * `M` is the Hessian of the kinetic energy in the reduced speeds, and `½ q̇ᵀ M q̇` equals the
//!   full model's kinetic energy at the expanded state (summed body by body from the full `M`);
//! * `c` satisfies Lagrange's equations of the reduced Lagrangian: with zero gravity,
//!   `c_i = Σ_jk (∂M_ij/∂q_k − ½ ∂M_jk/∂q_i) q̇_j q̇_k`, the derivatives of the reduced `M` by
//!   central differences (error O(h²), bounded below);
//! * the power balance `q̇ᵀ τ = q̇ᵀ (M q̈ + c)` holds with `q̈` from `τ` by the reduced `M`, and
//!   gravity's part of `c` is the gradient of the potential energy (finite differences).

use kanegen_dynamics::linalg::Vec3;
use kanegen_dynamics::mimic::Coupling;
use kanegen_dynamics::{Loads, Methods, Params};
use kanegen_model::io::parse_urdf;
use kanegen_model::Model;

fn link(name: &str, m: f64, x: f64) -> String {
    format!(
        r#"<link name="{name}"><inertial><origin xyz="{x} 0.05 -0.02"/><mass value="{m}"/>
        <inertia ixx="0.03" ixy="0.001" ixz="0" iyy="0.02" iyz="0.002" izz="0.04"/></inertial></link>"#
    )
}

fn joint(name: &str, ty: &str, parent: &str, child: &str, axis: &str, mimic: &str) -> String {
    format!(
        r#"<joint name="{name}" type="{ty}"><origin xyz="0.3 0.1 0" rpy="0.2 0 0.4"/>
        <parent link="{parent}"/><child link="{child}"/><axis xyz="{axis}"/>{mimic}</joint>"#
    )
}

fn model() -> Model {
    let text = [
        r#"<robot name="coupled"><link name="base"/>"#.to_string(),
        link("la", 2.0, 0.2),
        link("lb", 1.5, 0.1),
        link("lc", 1.0, 0.3),
        link("ld", 0.7, -0.1),
        joint("a", "revolute", "base", "la", "0 0 1", ""),
        joint("b", "revolute", "la", "lb", "0 1 0", ""),
        joint(
            "c",
            "revolute",
            "lb",
            "lc",
            "1 0 1",
            r#"<mimic joint="b" multiplier="-1.5" offset="0.3"/>"#,
        ),
        joint(
            "d",
            "prismatic",
            "la",
            "ld",
            "1 0 0",
            r#"<mimic joint="c" multiplier="0.2" offset="0.05"/>"#,
        ),
        "</robot>".to_string(),
    ]
    .concat();
    parse_urdf(&text).unwrap()
}

/// Reduced `M` and `c` (`b = −c` with no drives) at `q`, `q̇`, with gravity `g`.
fn reduced(model: &Model, q: &[f64], qd: &[f64], g: Option<[f64; 3]>) -> (Vec<Vec<f64>>, Vec<f64>) {
    let coupling = Coupling::new(model.mimics());
    let p = Params::<f64>::new(model);
    let loads = Loads {
        tau: None,
        gravity: g.map(Vec3),
        external: Vec::new(),
    };
    let d = Methods::SPATIAL.dynamics(
        &p,
        &coupling.full_positions(q),
        &coupling.full_rates(qd),
        &loads,
    );
    let c: Vec<f64> = coupling
        .reduce_vector(&d.tau_minus_c, 0)
        .iter()
        .map(|x| -x)
        .collect();
    (coupling.reduce_matrix(&d.mass_matrix, 0), c)
}

fn quad(m: &[Vec<f64>], x: &[f64]) -> f64 {
    m.iter()
        .zip(x)
        .map(|(row, xi)| xi * row.iter().zip(x).map(|(a, b)| a * b).sum::<f64>())
        .sum()
}

const Q: [f64; 2] = [0.4, -0.7];
const QD: [f64; 2] = [1.3, -0.6];

#[test]
fn the_coupling_resolves_the_chain_of_mimics() {
    let m = model();
    assert_eq!(m.coordinates(), [0, 1]);
    let c = Coupling::new(m.mimics());
    let q = c.full_positions(&Q);
    // q_c = −1.5 q_b + 0.3; q_d = 0.2 q_c + 0.05 = −0.3 q_b + 0.11.
    let want = [Q[0], Q[1], -1.5 * Q[1] + 0.3, -0.3 * Q[1] + 0.11];
    for (a, b) in q.iter().zip(want) {
        assert!((a - b).abs() < 1e-15, "{q:?} vs {want:?}");
    }
}

#[test]
fn kinetic_energy_of_the_reduced_model_is_the_full_models() {
    let m = model();
    let c = Coupling::new(m.mimics());
    let (mr, _) = reduced(&m, &Q, &QD, None);
    let p = Params::<f64>::new(&m);
    let full = Methods::SPATIAL.dynamics(
        &p,
        &c.full_positions(&Q),
        &c.full_rates(&QD),
        &Loads::default(),
    );
    let t_full = 0.5 * quad(&full.mass_matrix, &c.full_rates(&QD));
    let t = 0.5 * quad(&mr, &QD);
    assert!((t - t_full).abs() < 1e-13 * t_full, "{t} vs {t_full}");
    // M is symmetric positive definite (two independent coordinates moving mass).
    assert!((mr[0][1] - mr[1][0]).abs() < 1e-14);
    assert!(mr[0][0] > 0.0 && mr[0][0] * mr[1][1] - mr[0][1] * mr[1][0] > 0.0);
}

#[test]
fn c_satisfies_lagranges_equations_of_the_reduced_model() {
    let m = model();
    let h = 1e-5;
    // ∂M/∂q_k by central differences of the reduced M.
    let dm: Vec<Vec<Vec<f64>>> = (0..2)
        .map(|k| {
            let mut qp = Q;
            let mut qm = Q;
            qp[k] += h;
            qm[k] -= h;
            let (mp, _) = reduced(&m, &qp, &QD, None);
            let (mm, _) = reduced(&m, &qm, &QD, None);
            (0..2)
                .map(|i| (0..2).map(|j| (mp[i][j] - mm[i][j]) / (2.0 * h)).collect())
                .collect()
        })
        .collect();
    let (_, c) = reduced(&m, &Q, &QD, None);
    for i in 0..2 {
        let mut want = 0.0;
        for j in 0..2 {
            for k in 0..2 {
                want += (dm[k][i][j] - 0.5 * dm[i][j][k]) * QD[j] * QD[k];
            }
        }
        assert!(
            (c[i] - want).abs() < 1e-7 * (1.0 + want.abs()),
            "c[{i}] = {} vs {want}",
            c[i]
        );
    }
}

#[test]
fn gravity_is_the_gradient_of_the_potential_and_power_balances() {
    let m = model();
    let g = [0.3, -1.0, -9.81];
    let zero = [0.0; 2];
    // c(q, 0) with gravity = ∂V/∂q; V by the work of gravity: V(q) − V(q₀) = ∫ c·dq. Check the
    // gradient is curl-free and matches central differences of V along a straight path.
    let grav = |q: [f64; 2]| reduced(&m, &q, &zero, Some(g)).1;
    let h = 1e-4;
    let path_v = |q: [f64; 2]| -> f64 {
        // ∫₀¹ c(s q)·q ds by Simpson's rule on 64 panels.
        let n = 64;
        (0..=n)
            .map(|k| {
                let s = k as f64 / n as f64;
                let w = if k == 0 || k == n {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                let c = grav([s * q[0], s * q[1]]);
                w * (c[0] * q[0] + c[1] * q[1])
            })
            .sum::<f64>()
            / (3.0 * n as f64)
    };
    let c = grav(Q);
    for k in 0..2 {
        let (mut qp, mut qm) = (Q, Q);
        qp[k] += h;
        qm[k] -= h;
        let fd = (path_v(qp) - path_v(qm)) / (2.0 * h);
        assert!(
            (c[k] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
            "∂V/∂q{k}: {} vs {fd}",
            c[k]
        );
    }
    // Power: with τ = M q̈ + c for some q̈, q̇ᵀτ = q̇ᵀ M q̈ + q̇ᵀ c, and the full model's drives
    // (τ on independent joints, 0 on mimics) give the same reduced right-hand side.
    let coupling = Coupling::new(m.mimics());
    let tau = [2.0, -1.0];
    let p = Params::<f64>::new(&m);
    let loads = Loads {
        tau: Some(coupling.full_drives(&tau)),
        gravity: None,
        external: Vec::new(),
    };
    let d = Methods::SPATIAL.dynamics(
        &p,
        &coupling.full_positions(&Q),
        &coupling.full_rates(&QD),
        &loads,
    );
    let b = coupling.reduce_vector(&d.tau_minus_c, 0);
    let (_, c0) = reduced(&m, &Q, &QD, None);
    for i in 0..2 {
        assert!(
            (b[i] - (tau[i] - c0[i])).abs() < 1e-12 * (1.0 + b[i].abs()),
            "{b:?}"
        );
    }
}
