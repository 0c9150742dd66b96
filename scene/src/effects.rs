//! A scene's effects as the plain data of the right-hand side both simulators run
//! ([`kanegen_runtime::scene`]): borrowed from the validated [`Scene`].

use crate::{Drives, Scene, SceneWrench, WrenchProfile};
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
            dof: self.model.dof(),
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
