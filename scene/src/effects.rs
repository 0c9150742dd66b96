//! A scene's effects as the plain data of the right-hand side both simulators run
//! ([`kanegen_runtime::scene`]): borrowed from the validated [`Scene`].

use crate::{BaseSpec, Drives, Scene, SceneWrench, WrenchProfile};
use kanegen_runtime::scene::{Coulomb, Drive, Flexible, Profile, SceneEffects};

impl SceneWrench {
    /// The wrench's time profile as right-hand-side data.
    #[must_use]
    pub fn profile_data(&self) -> Profile<'_> {
        match &self.profile {
            WrenchProfile::Constant { force, moment } => Profile::Constant {
                force: *force,
                moment: *moment,
            },
            WrenchProfile::Table {
                time,
                force,
                moment,
            } => Profile::Table {
                time,
                force,
                moment,
            },
        }
    }
}

impl Scene {
    /// The initial state vector in the layout of [`kanegen_runtime::scene`] (fixed base
    /// `[q, q̇]`, with flexible joints `[q, q̇, θ, θ̇]` the motors starting at the links;
    /// free-floating `[p₀, quat, q, v_b, ω_b, q̇]`).
    #[must_use]
    pub fn initial_state(&self) -> Vec<f64> {
        match &self.base {
            BaseSpec::Fixed if self.flexible.is_some() => {
                [self.q0.as_slice(), &self.qd0, &self.q0, &self.qd0].concat()
            }
            BaseSpec::Fixed => [self.q0.as_slice(), &self.qd0].concat(),
            BaseSpec::FreeFloating {
                position,
                quaternion,
                v,
                omega,
                ..
            } => [
                position.as_slice(),
                quaternion,
                &self.q0,
                v,
                omega,
                &self.qd0,
            ]
            .concat(),
        }
    }

    /// The profiles of the scene's wrenches, in order (what [`Scene::effects`] borrows).
    #[must_use]
    pub fn wrench_profiles(&self) -> Vec<Profile<'_>> {
        self.wrenches
            .iter()
            .map(SceneWrench::profile_data)
            .collect()
    }

    /// The effects of the scene with the wrench profiles `wrenches` (of
    /// [`Scene::wrench_profiles`]): only those the scene names.
    #[must_use]
    pub fn effects<'a>(&'a self, wrenches: &'a [Profile<'a>]) -> SceneEffects<'a> {
        SceneEffects {
            dof: self.dof(),
            floating: self.is_floating(),
            drive: self.drive(),
            damping: self.damping.as_deref(),
            coulomb: self.coulomb.as_ref().map(|c| Coulomb {
                tau_c: &c.tau_c,
                v_s: c.v_s,
            }),
            wrenches,
            armature: self.rotor.as_ref().map(|r| r.reflected.as_slice()),
            flexible: self.flexible.as_ref().map(|f| Flexible {
                stiffness: &f.stiffness,
                damping: &f.damping,
                reflected: &f.reflected,
            }),
        }
    }

    /// The scene's drives as right-hand-side data.
    fn drive(&self) -> Drive<'_> {
        match &self.drives {
            Drives::None => Drive::None,
            Drives::Constant { tau } => Drive::Constant(tau),
            Drives::Pd { kp, kd, target } => Drive::Pd { kp, kd, target },
            Drives::ComputedTorque {
                kp,
                kd,
                target,
                duration,
            } => Drive::ComputedTorque {
                kp,
                kd,
                q0: &self.q0,
                target,
                duration: *duration,
            },
        }
    }
}
