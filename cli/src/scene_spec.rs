//! A scene's effects as a trace [`Spec`]: what `kanegen count SCENE` and the accuracy report
//! trace. A constant wrench is folded into the graph; a tabulated one becomes six runtime inputs.

use kanegen_sim::scene::{BaseSpec, Scene};
use kanegen_trace::{Base, Spec, Wrench, WrenchValue};

/// The spec of `scene`: its base, gravity, wrenches and damping.
#[must_use]
pub fn spec(scene: &Scene) -> Spec {
    Spec {
        base: match &scene.base {
            BaseSpec::Fixed => Base::Fixed,
            BaseSpec::FreeFloating { inertial, .. } => Base::FreeFloating(inertial.clone()),
        },
        gravity: scene.gravity,
        wrenches: scene
            .wrenches
            .iter()
            .map(|w| Wrench {
                body: w.body,
                frame: w.frame,
                value: if w.is_tabulated() {
                    WrenchValue::Runtime
                } else {
                    let (force, moment) = w.value_at(0.0);
                    WrenchValue::Constant { force, moment }
                },
            })
            .collect(),
        damping: scene.damping.clone(),
        ..Spec::default()
    }
}
