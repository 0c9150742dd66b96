//! The applied loads of one evaluation: joint drives, gravity and external wrenches, each present
//! only when given, so a traced scene without gravity or loads has no term for them.

use crate::linalg::Vec3;

/// Which frame an external wrench is expressed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadFrame {
    /// The frame of the body it acts on.
    Body,
    /// The base frame (fixed base) or the inertial frame (free-floating base).
    Base,
}

/// An external wrench on one body: a force applied at the body frame origin `O_j` and a moment,
/// both expressed in `frame` (paper eq. (7): `f^E_j`, `m^E_j`).
#[derive(Clone, Debug)]
pub struct ExternalWrench<S> {
    /// Index of the body (0-based; body `j` is moved by joint `j`; [`crate::base::BASE_BODY`]
    /// for the base of a free-floating chain).
    pub body: usize,
    /// The frame of `force` and `moment`.
    pub frame: LoadFrame,
    /// Force at `O_j`.
    pub force: Vec3<S>,
    /// Moment (about `O_j`).
    pub moment: Vec3<S>,
}

/// The applied loads of a call.
#[derive(Clone, Debug)]
pub struct Loads<S> {
    /// Joint drive torques (revolute) or forces (prismatic), `m^J`, `f^J` of eq. (10).
    pub tau: Option<Vec<S>>,
    /// Uniform gravitational acceleration in the base frame (fixed base) or the inertial frame
    /// (free-floating base).
    pub gravity: Option<Vec3<S>>,
    /// External wrenches on bodies.
    pub external: Vec<ExternalWrench<S>>,
}

impl<S> Default for Loads<S> {
    fn default() -> Self {
        Loads {
            tau: None,
            gravity: None,
            external: Vec::new(),
        }
    }
}

impl<S: Clone> Loads<S> {
    /// The same loads without the joint drives.
    #[must_use]
    pub fn passive(&self) -> Self {
        Loads {
            tau: None,
            ..self.clone()
        }
    }
}
