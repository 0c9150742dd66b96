//! The operation cost of a scene's payload events (`[[events]]`) for `kanegen count SCENE`,
//! counted from the formulas of `kanegen_sim::events` (one-time costs per event, not per step).
//!
//! A capture evaluates `A` twice (`H` before, `H'` after: the table's `mass_matrix` line of the
//! method, taken from it) and then does the impulse algebra on `n_v = 6 + N` speeds:
//! `H ν⁻` (`n_v²` mul, `n_v (n_v − 1)` add), `h_p = [m v; R (I (Rᵀ ω))]` (30 mul, 18 add),
//! `J_pᵀ h_p` added to it (`6 n_v` mul and add), the armature on both matrices (`2 N` add with
//! `[effects] rotor`), and the LDLᵀ factorization and solve of `H'` (`kanegen_dynamics::ldlt`):
//! factor `Σ_i i (i + 1) / 2` mul and add and `n_v (n_v − 1) / 2` div, solve `n_v (n_v − 1)` mul
//! and add and `n_v` div. The payload frame's Jacobian and placement (one kinematic pass) are not
//! counted. A release switches the model and keeps `ν`: no operations.

use kanegen_dynamics::MassMatrixMethod;
use kanegen_sim::scene::{EventKind, Scene};
use kanegen_trace::count::{CountLine, EffectLine};

/// `(mul, add, div)` of the impulse algebra of one capture with `n` joints (the module doc).
#[must_use]
pub fn impulse_ops(n: usize, rotor: bool) -> (i64, i64, i64) {
    let nv = (6 + n) as i64;
    let factor: i64 = (0..nv).map(|i| i * (i + 1) / 2).sum();
    let mul = nv * nv + 30 + 6 * nv + factor + nv * (nv - 1);
    let add =
        nv * (nv - 1) + 18 + 6 * nv + factor + nv * (nv - 1) + if rotor { 2 * n as i64 } else { 0 };
    let div = nv * (nv - 1) / 2 + nv;
    (mul, add, div)
}

/// One line per event kind the scene has (`capture`, `release`), mass-matrix method and
/// convention (`emitted`, `paper`): the operations of one event. Empty without events.
#[must_use]
pub fn event_effect_lines(
    scene: &Scene,
    mass: &[MassMatrixMethod],
    counts: &[CountLine],
) -> Vec<EffectLine> {
    let has = |capture: bool| {
        scene
            .events
            .iter()
            .any(|e| matches!(e.kind, EventKind::Capture { .. }) == capture)
    };
    let (mul, add, div) = impulse_ops(scene.model.dof(), scene.rotor.is_some());
    let mut lines = Vec::new();
    for m in mass {
        for conv in ["emitted", "paper"] {
            let a = counts.iter().find(|c| {
                c.function == "mass_matrix" && c.method == m.name() && c.convention == conv
            });
            let (am, aa, ad) = a.map_or((0, 0, 0), |c| (c.mul as i64, c.add as i64, c.div as i64));
            if has(true) {
                lines.push(EffectLine {
                    effect: "capture".into(),
                    method: m.name().into(),
                    convention: conv.into(),
                    mul: 2 * am + mul,
                    add: 2 * aa + add,
                    div: 2 * ad + div,
                });
            }
            if has(false) {
                lines.push(EffectLine {
                    effect: "release".into(),
                    method: m.name().into(),
                    convention: conv.into(),
                    mul: 0,
                    add: 0,
                    div: 0,
                });
            }
        }
    }
    lines
}
