//! The model-effects part of `kanegen accuracy`: for each effect a scene enables, the operations
//! it adds to the emitted `b` and how far the trajectory moves without it — what leaving an
//! effect out would save, and what it would cost in accuracy.

use super::integration::state_error;
use crate::scene_spec;
use anyhow::Result;
use kanegen_sim::scene::Scene;
use kanegen_sim::simulate::simulate;
use kanegen_trace::count::effect_lines;
use kanegen_trace::Effect;
use serde::{Deserialize, Serialize};

/// One effect of a scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct EffectRow {
    /// `gravity`, `wrench[i]` or `damping`.
    pub effect: String,
    /// Multiplications plus additions the effect adds to the emitted `b` (the scene's nonlinear-effects method).
    pub ops: i64,
    /// `max |x(T) − x_without(T)| / max |x(T)|`: the final state with the effect against the one
    /// without it, same integrator settings.
    pub trajectory_change: f64,
}

/// The scene without `effect`.
#[must_use]
pub fn without(scene: &Scene, effect: Effect) -> Scene {
    let mut s = scene.clone();
    match effect {
        Effect::Gravity => s.gravity = None,
        Effect::Damping => s.damping = None,
        Effect::Wrench(i) => {
            s.wrenches.remove(i);
        }
    }
    s
}

fn final_state(scene: &Scene) -> Result<Vec<f64>> {
    let run = simulate(scene, None)?;
    Ok(run.samples.last().map(|s| s.x.clone()).unwrap_or_default())
}

/// Cost and trajectory change of every effect `scene` names.
pub fn effects_report(scene: &Scene) -> Result<Vec<EffectRow>> {
    let spec = scene_spec::spec(scene);
    let lines = effect_lines(
        &scene.model,
        &[scene.simulation.algorithm.nonlinear_effects],
        &spec,
    )?;
    let x = final_state(scene)?;
    let mut rows = Vec::new();
    for e in spec.effects() {
        let ops = lines
            .iter()
            .filter(|l| l.effect == e.name() && l.convention == "emitted")
            .map(|l| l.mul + l.add)
            .sum();
        let x_without = final_state(&without(scene, e))?;
        rows.push(EffectRow {
            effect: e.name(),
            ops,
            trajectory_change: state_error(&x_without, &x),
        });
    }
    Ok(rows)
}
