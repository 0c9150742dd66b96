//! Random valid chains, trees and states, for tests, benchmarks and op-count traces with general
//! geometry. Deterministic for a given seed (ChaCha8).
//!
//! ```
//! use kanegen_model::random::{random_chain, ChainSpec};
//! let chain = random_chain(&ChainSpec { n: 5, prismatic_fraction: 0.3, ..Default::default() }, 7);
//! assert_eq!(chain.dof(), 5);
//! let tree = kanegen_model::random::random_tree(&ChainSpec { n: 6, ..Default::default() }, 3);
//! assert!(tree.joints().iter().enumerate().all(|(j, jt)| jt.parent.map_or(true, |p| p < j)));
//! ```

use crate::placement::{axis_rotation, mat_mul, transpose};
use crate::{Inertial, Joint, JointKind, Model, Placement};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// What kind of random chain to make.
#[derive(Clone, Debug)]
pub struct ChainSpec {
    /// Number of joints.
    pub n: usize,
    /// Probability that a joint is prismatic.
    pub prismatic_fraction: f64,
    /// Typical link length, m.
    pub length: f64,
    /// Typical link mass, kg.
    pub mass: f64,
}

impl Default for ChainSpec {
    fn default() -> Self {
        ChainSpec {
            n: 6,
            prismatic_fraction: 0.0,
            length: 1.0,
            mass: 10.0,
        }
    }
}

/// A seeded random number generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

fn unit(rng: &mut ChaCha8Rng) -> [f64; 3] {
    loop {
        let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if n > 0.2 && n <= 1.0 {
            return v.map(|x| x / n);
        }
    }
}

/// A random rotation matrix.
pub fn random_rotation(rng: &mut ChaCha8Rng) -> [[f64; 3]; 3] {
    let u = unit(rng);
    let ang: f64 = rng.random_range(-3.0..3.0);
    axis_rotation(&u, ang.sin(), ang.cos())
}

/// A random physically valid inertial (SPD, triangle inequality) of mass about `mass`.
pub fn random_inertial(rng: &mut ChaCha8Rng, mass: f64, length: f64) -> Inertial {
    let m = mass * rng.random_range(0.2..2.0);
    // Principal moments of a random box: a, b, c in (0.1, 1)·length.
    let d: [f64; 3] = std::array::from_fn(|_| length * rng.random_range(0.1..1.0));
    let p = [
        m * (d[1] * d[1] + d[2] * d[2]) / 12.0,
        m * (d[0] * d[0] + d[2] * d[2]) / 12.0,
        m * (d[0] * d[0] + d[1] * d[1]) / 12.0,
    ];
    let r = random_rotation(rng);
    let diag = [[p[0], 0.0, 0.0], [0.0, p[1], 0.0], [0.0, 0.0, p[2]]];
    let mut i = mat_mul(&mat_mul(&r, &diag), &transpose(&r));
    // Exact symmetry.
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        let s = 0.5 * (i[a][b] + i[b][a]);
        i[a][b] = s;
        i[b][a] = s;
    }
    Inertial {
        mass: m,
        com: std::array::from_fn(|_| length * rng.random_range(-0.6..0.6)),
        inertia: i,
    }
}

/// One random joint `j` with the given parent: kind, placement, axis and inertial.
fn random_joint(rng: &mut ChaCha8Rng, spec: &ChainSpec, j: usize, parent: Option<usize>) -> Joint {
    let kind = if rng.random_bool(spec.prismatic_fraction.clamp(0.0, 1.0)) {
        JointKind::Prismatic
    } else {
        JointKind::Revolute
    };
    Joint {
        name: format!("j{}", j + 1),
        kind,
        parent,
        origin: Placement {
            translation: std::array::from_fn(|_| spec.length * rng.random_range(-1.0..1.0)),
            rotation: random_rotation(rng),
        },
        axis: unit(rng),
        body: format!("b{}", j + 1),
        inertial: random_inertial(rng, spec.mass, spec.length),
    }
}

/// A random valid serial chain with general geometry: random joint placements and rotations,
/// random axes, random inertials.
pub fn random_chain(spec: &ChainSpec, seed: u64) -> Model {
    let mut rng = rng(seed);
    let joints = (0..spec.n)
        .map(|j| random_joint(&mut rng, spec, j, j.checked_sub(1)))
        .collect();
    Model::new(format!("random_n{}_s{seed}", spec.n), "base", None, joints)
        .expect("random chains are valid by construction")
}

/// A random valid kinematic tree with the geometry of [`random_chain`]: joint `j > 0` hangs
/// from a parent drawn uniformly from the base and bodies `0..j` (so `λ(j) < j`), joint 0 from
/// the base; revolute or prismatic by `spec.prismatic_fraction`. With `n ≥ 3` most seeds branch
/// ([`Model::first_branch`]); a seed may still give a chain.
pub fn random_tree(spec: &ChainSpec, seed: u64) -> Model {
    let mut rng = rng(seed);
    let joints = (0..spec.n)
        .map(|j| {
            // j + 1 choices: the base (drawn as j) or one of the bodies 0..j.
            let pick = rng.random_range(0..=j);
            let parent = (pick < j).then_some(pick);
            random_joint(&mut rng, spec, j, parent)
        })
        .collect();
    Model::new(
        format!("random_tree_n{}_s{seed}", spec.n),
        "base",
        None,
        joints,
    )
    .expect("random trees are valid by construction")
}

/// A random vector of length `n` with entries in `(-scale, scale)`.
pub fn random_vec(rng: &mut ChaCha8Rng, n: usize, scale: f64) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-scale..scale)).collect()
}
