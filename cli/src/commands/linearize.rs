//! `kanegen simulate SCENE --linearize`: the Jacobians `(A, B)` of one step of the scene's
//! integrator at its initial state ([`kanegen_sim::linearize`]), as text or JSON.

use anyhow::Result;
use kanegen_sim::linearize::{step_jacobians, StepJacobians};
use kanegen_sim::scene::Scene;
use kanegen_sim::system::SceneSystem;

/// The Jacobians of the scene's step from its initial state at `t = 0` with no added torque
/// (`u = 0`), of the scene's step size, with the state's component names.
///
/// # Errors
/// What [`kanegen_sim::linearize::scheme`] refuses, or a failed step.
pub fn at_initial_state(scene: &Scene) -> Result<(StepJacobians, Vec<String>, Vec<f64>)> {
    let mut sys = SceneSystem::new(scene);
    let x = sys.initial_state();
    let names = (0..x.len()).map(|i| sys.component_name(i)).collect();
    let u = vec![0.0; sys.n()];
    let j = step_jacobians(&mut sys, 0.0, &x, &u, scene.simulation.step)?;
    Ok((j, names, x))
}

/// The JSON report: scene, scheme, step, state names, `x`, `x⁺`, `A`, `B` (row-major rows).
#[must_use]
pub fn to_json(
    scene: &Scene,
    (j, names, x): &(StepJacobians, Vec<String>, Vec<f64>),
) -> serde_json::Value {
    serde_json::json!({
        "scheme": j.scheme,
        "t": 0.0,
        "h": scene.simulation.step,
        "state": names,
        "tangent": j.names,
        "inputs": scene.coordinate_names(),
        "x": x,
        "x_next": j.state,
        "A": j.a,
        "B": j.b,
    })
}

/// The text report: a line on what was linearized, then `A` and `B`, a row a state component.
#[must_use]
pub fn render_text(scene: &Scene, (j, _, _): &(StepJacobians, Vec<String>, Vec<f64>)) -> String {
    let names = &j.names;
    let width = names.iter().map(String::len).max().unwrap_or(0);
    let matrix = |m: &[Vec<f64>]| -> String {
        m.iter()
            .zip(names)
            .map(|(row, name)| {
                let cells: Vec<String> = row.iter().map(|v| format!("{v:>13.6e}")).collect();
                format!("{name:<width$} {}\n", cells.join(" "))
            })
            .collect()
    };
    let inputs = scene.coordinate_names();
    format!(
        "x⁺ = Φ(x, u): one {} step of {} s from the initial state at t = 0, u = 0 (u: joint \
         torques added to the drive: {}); exact for the scheme\nA = ∂x⁺/∂x ({d} × {d}; columns in \
         the order of the rows{})\n{}B = ∂x⁺/∂u ({d} × {})\n{}",
        if j.scheme == "rk4" {
            "RK4"
        } else {
            "implicit midpoint"
        },
        scene.simulation.step,
        inputs.join(", "),
        if names.len() + 1 == j.state.len() {
            "; the free-floating base's pose in the tangent space of Pinocchio's integrate, \
             base coordinates"
        } else {
            ""
        },
        matrix(&j.a),
        inputs.len(),
        matrix(&j.b),
        d = names.len(),
    )
}
