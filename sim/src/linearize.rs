//! The Jacobians `(A, B)` of one step of a scene's integrator, `x⁺ = Φ(t, x, u)` with `u` the
//! joint torques added to the scene's drive, over the run-time dynamics and their derivatives
//! ([`kanegen_runtime::scene::linearize`], [`kanegen_runtime::ode::linearize`]): exact for the
//! scheme, what `kanegen simulate --linearize` prints. A `scene!` type computes the same from
//! its generated derivatives (`Name::step_jacobians`).

use crate::scene::Integrator;
use crate::system::SceneSystem;
use anyhow::{bail, Result};
use kanegen_runtime::ode::{
    floating_midpoint_step_jacobians, floating_rk4_step_jacobians, midpoint_step_jacobians,
    rk4_step_jacobians, VecScratch,
};
use kanegen_runtime::scene::linearize::jacobian_work_len;
use kanegen_runtime::scene::SceneControl;

/// One step with its Jacobians.
#[derive(Clone, Debug, PartialEq)]
pub struct StepJacobians {
    /// The state after the step.
    pub state: Vec<f64>,
    /// `A = ∂x⁺/∂x`, `d × d` (row `i` = `x⁺_i`); on a free-floating base `(d − 1) × (d − 1)`
    /// in the tangent space ([`kanegen_runtime::ode::floating_rk4_step_jacobians`]).
    pub a: Vec<Vec<f64>>,
    /// `B = ∂x⁺/∂u`, `d × N` (`(d − 1) × N` on a free-floating base).
    pub b: Vec<Vec<f64>>,
    /// The names of `A`'s rows and columns (and `B`'s rows): the state's components
    /// ([`SceneSystem::component_name`]), on a free-floating base with the pose's tangent
    /// directions `dp0_x`, `dp0_y`, `dp0_z`, `dtheta_x`, `dtheta_y`, `dtheta_z` (base
    /// coordinates) for `p0_*` and `quat_*`.
    pub names: Vec<String>,
    /// The scheme stepped: `"rk4"` or `"midpoint"`.
    pub scheme: &'static str,
}

/// The scheme whose step a scene's `step` takes and whose Jacobians are exact: RK4 for RK4 and
/// dopri5 scenes, the implicit midpoint rule for midpoint scenes.
///
/// # Errors
/// Rodas4 (rosenbrock) scenes, and mimic joints on a free-floating base or with external
/// wrenches, named.
pub fn scheme(sys: &SceneSystem<'_>) -> Result<&'static str> {
    let scene = sys.scene();
    let profiles = scene.wrench_profiles();
    let effects = scene.effects(&profiles);
    if effects.floating && scene.model.has_mimics() {
        bail!("step Jacobians on a free-floating base cover models without mimic joints; this model has mimic joints");
    }
    if !effects.wrenches.is_empty() && scene.model.has_mimics() {
        bail!("step Jacobians with external wrenches cover models without mimic joints; this model has mimic joints");
    }
    match scene.simulation.integrator {
        Integrator::Rk4 | Integrator::Dopri5 => Ok("rk4"),
        Integrator::Midpoint => Ok("midpoint"),
        Integrator::Rosenbrock => bail!(
            "step Jacobians are those of an RK4 step (rk4 and dopri5 scenes) or of an implicit \
             midpoint step; this scene integrates with rosenbrock (Rodas4)"
        ),
    }
}

/// One step of size `h` from `(t, x)` under the torques `u` (`N`) with its Jacobians.
///
/// # Errors
/// What [`scheme`] refuses; a state or input of the wrong length; a step that fails (its
/// [`kanegen_runtime::ode::Stop`] in words).
pub fn step_jacobians(
    sys: &mut SceneSystem<'_>,
    t: f64,
    x: &[f64],
    u: &[f64],
    h: f64,
) -> Result<StepJacobians> {
    let scheme = scheme(sys)?;
    let scene = sys.scene();
    let profiles = scene.wrench_profiles();
    let effects = scene.effects(&profiles);
    let (d, n) = (effects.dim(), sys.n());
    if x.len() != d || u.len() != n {
        bail!(
            "a state of {} and an input of {} numbers, for {d} and {n}",
            x.len(),
            u.len()
        );
    }
    // The Jacobians' rows and columns: the tangent space's on a free-floating base.
    let td = if effects.floating { d - 1 } else { d };
    let mut work = vec![0.0; jacobian_work_len(&effects)];
    let mut control = SceneControl {
        dynamics: &mut sys.dynamics,
        effects: &effects,
        work: &mut work,
    };
    let (mut state, mut a, mut b) = (x.to_vec(), vec![0.0; td * td], vec![0.0; td * n]);
    let mut scratch = VecScratch::default();
    let stepped = if effects.floating && scheme == "midpoint" {
        floating_midpoint_step_jacobians(
            &mut control,
            t,
            h,
            &mut state,
            u,
            &mut a,
            &mut b,
            &mut scratch,
        )
    } else if effects.floating {
        floating_rk4_step_jacobians(
            &mut control,
            t,
            h,
            &mut state,
            u,
            &mut a,
            &mut b,
            &mut scratch,
        )
    } else if scheme == "rk4" {
        rk4_step_jacobians(
            &mut control,
            t,
            h,
            &mut state,
            u,
            &mut a,
            &mut b,
            &mut scratch,
        )
    } else {
        midpoint_step_jacobians(
            &mut control,
            t,
            h,
            &mut state,
            u,
            &mut a,
            &mut b,
            &mut scratch,
        )
    };
    if let Err(stop) = stepped {
        bail!("{stop}");
    }
    let rows = |m: &[f64], cols: usize| m.chunks_exact(cols).map(<[f64]>::to_vec).collect();
    let names = if effects.floating {
        let pose = [
            "dp0_x", "dp0_y", "dp0_z", "dtheta_x", "dtheta_y", "dtheta_z",
        ];
        let rest = (7..d).map(|i| sys.component_name(i));
        pose.iter().map(|s| (*s).to_string()).chain(rest).collect()
    } else {
        (0..d).map(|i| sys.component_name(i)).collect()
    };
    Ok(StepJacobians {
        state,
        a: rows(&a, td),
        b: rows(&b, n),
        names,
        scheme,
    })
}
