//! The random models, loads and base states that the articulated-body tests share
//! (`aba.rs`, `kernels.rs`).

#![allow(dead_code)]

use kanegen_dynamics::base::{FloatingState, BASE_BODY};
use kanegen_dynamics::linalg::{axis_rotation, Vec3};
use kanegen_dynamics::{ExternalWrench, LoadFrame, Loads};
use kanegen_model::random::{
    random_chain, random_inertial, random_tree, random_vec, rng, ChainSpec,
};
use kanegen_model::{Inertial, Model};

/// Random trees N = 1…10 and chains N = 2…12, a third of the joints prismatic.
pub fn models() -> Vec<Model> {
    let spec = |n| ChainSpec {
        n,
        prismatic_fraction: 0.35,
        ..Default::default()
    };
    (1..=10)
        .map(|n| random_tree(&spec(n), 40 + n as u64))
        .chain((2..=12).map(|n| random_chain(&spec(n), 80 + n as u64)))
        .collect()
}

/// A wrench from six random numbers.
pub fn wrench(body: usize, frame: LoadFrame, w: &[f64]) -> ExternalWrench<f64> {
    ExternalWrench {
        body,
        frame,
        force: Vec3::new(w[0], w[1], w[2]),
        moment: Vec3::new(w[3], w[4], w[5]),
    }
}

/// Drives, gravity and wrenches: on the last body in its frame, on the first in the base frame,
/// two on a middle body (one per frame), and on a floating base in both frames. `variant`
/// leaves some out, so the branches without them run too.
pub fn loads(n: usize, seed: u64, floating: bool, variant: usize) -> Loads<f64> {
    let mut r = rng(seed);
    let w = random_vec(&mut r, 42, 5.0);
    let mut external = vec![
        wrench(n - 1, LoadFrame::Body, &w[0..6]),
        wrench(0, LoadFrame::Base, &w[6..12]),
        wrench(n / 2, LoadFrame::Body, &w[12..18]),
        wrench(n / 2, LoadFrame::Base, &w[18..24]),
    ];
    if floating {
        external.push(wrench(BASE_BODY, LoadFrame::Body, &w[24..30]));
        external.push(wrench(BASE_BODY, LoadFrame::Base, &w[30..36]));
    }
    match variant {
        0 => Loads {
            tau: Some(random_vec(&mut r, n, 20.0)),
            gravity: Some(Vec3::new(0.7, -1.3, -9.81)),
            external,
        },
        1 => Loads {
            tau: Some(random_vec(&mut r, n, 20.0)),
            ..Loads::default()
        },
        _ => Loads {
            tau: None,
            gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
            external: external.split_off(2),
        },
    }
}

/// A free-floating base state: turned, moving.
pub fn base_state(seed: u64) -> FloatingState<f64> {
    let mut r = rng(seed);
    let w = random_vec(&mut r, 10, 1.0);
    let n = (w[6] * w[6] + w[7] * w[7] + w[8] * w[8]).sqrt();
    FloatingState {
        position: Vec3::new(w[0], w[1], w[2]),
        rotation: axis_rotation(
            &Vec3::new(w[6] / n, w[7] / n, w[8] / n),
            &(2.0 * w[9]).sin(),
            &(2.0 * w[9]).cos(),
        ),
        v_b: Vec3::new(w[3], w[4], w[5]),
        omega_b: Vec3::new(w[5], -w[3], w[4]),
    }
}

pub fn base_inertial(seed: u64) -> Inertial {
    random_inertial(&mut rng(seed), 80.0, 1.2)
}
