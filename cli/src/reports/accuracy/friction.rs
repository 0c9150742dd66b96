//! The friction part of `kanegen accuracy`: what the regularization of Coulomb drive friction
//! costs in accuracy and in time.
//!
//! A scene's Coulomb friction is `τ_c tanh(q̇ / v_s)` ([`kanegen_sim::scene::Coulomb`]): the
//! discontinuous law `τ_c sign(q̇)` smoothed over joint rates of about `v_s`. A smaller `v_s` is
//! closer to the discontinuous law (a joint held by less than `τ_c` creeps at about
//! `v_s atanh(τ / τ_c)` instead of sticking), but the slope `τ_c / v_s` of the right-hand side at
//! `q̇ = 0` grows with it, the equations get stiff, and an explicit adaptive integrator takes
//! more steps. For each `v_s` of [`V_S_LADDER`] (and the scene's own) the scene runs with dopri5
//! at tolerance [`TOLERANCE`], which keeps the integration error below the differences the
//! table shows; the error of each final state is measured against the finest `v_s` of the
//! ladder: an estimate of the regularization error as `v_s → 0` (the limit is the Filippov
//! solution of the discontinuous law; no event-driven stick–slip simulator is used).

use super::integration::{run_scene, state_error, with_setting, IntegrationRow};
use anyhow::Result;
use kanegen_sim::scene::{Integrator, Scene};
use serde::{Deserialize, Serialize};

/// Regularization speeds `v_s` of the ladder, coarse to fine (rad/s, or m/s for a prismatic
/// joint); the last is the reference.
pub const V_S_LADDER: [f64; 5] = [1e-1, 1e-2, 1e-3, 1e-4, 1e-5];

/// dopri5 tolerance of every run of the ladder.
pub const TOLERANCE: f64 = 1e-10;

/// One regularization speed: the dopri5 run of the scene with it (`integrator` `dopri5`,
/// `setting` `v_s = …`; `final_error` against the finest `v_s` of the ladder, `0` for the finest
/// itself).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FrictionRow {
    /// The regularization speed `v_s`.
    pub v_s: f64,
    /// Whether this is the scene's own `v_s`.
    pub scene: bool,
    /// The run.
    #[serde(flatten)]
    pub run: IntegrationRow,
}

/// The ladder of a scene with Coulomb friction, coarse to fine; empty for a scene without.
/// Each setting runs `repeats` times (at least once) and reports the median wall time.
pub fn friction_report(scene: &Scene, repeats: usize) -> Result<Vec<FrictionRow>> {
    let Some(coulomb) = &scene.coulomb else {
        return Ok(Vec::new());
    };
    let mut ladder = V_S_LADDER.to_vec();
    if !ladder.contains(&coulomb.v_s) {
        ladder.push(coulomb.v_s);
        ladder.sort_by(|a, b| b.total_cmp(a));
    }
    let at = |v_s: f64| {
        let mut s = with_setting(scene, Integrator::Dopri5, 0.0, TOLERANCE);
        if let Some(c) = &mut s.coulomb {
            c.v_s = v_s;
        }
        s
    };
    let finest = ladder[ladder.len() - 1];
    let xref = run_scene(&at(finest), 1).x.map_err(|e| {
        anyhow::anyhow!(
            "the friction reference (v_s = {finest:e}, dopri5 tol {TOLERANCE:e}) failed: {e}"
        )
    })?;
    Ok(ladder
        .iter()
        .map(|&v_s| {
            let o = run_scene(&at(v_s), repeats);
            FrictionRow {
                v_s,
                scene: v_s == coulomb.v_s,
                run: IntegrationRow {
                    integrator: "dopri5".into(),
                    setting: format!("v_s = {v_s:e}"),
                    final_error: o.x.as_ref().ok().map(|x| state_error(x, &xref)),
                    wall_s: o.wall_s,
                    steps: o.steps,
                    evals: o.evals,
                    failure: o.x.err(),
                },
            }
        })
        .collect())
}

/// One sentence per row: the digits the regularization leaves and what a finer `v_s` costs.
#[must_use]
pub fn friction_sentences(rows: &[FrictionRow]) -> Vec<String> {
    rows.iter()
        .enumerate()
        .map(|(k, r)| {
            let own = if r.scene { " (the scene's)" } else { "" };
            match (r.run.final_error, k.checked_sub(1).map(|p| &rows[p])) {
                (None, _) => format!(
                    "v_s = {:e}{own}: failed ({})",
                    r.v_s,
                    r.run.failure.as_deref().unwrap_or("no final state")
                ),
                (Some(_), _) if k + 1 == rows.len() => format!(
                    "v_s = {:e}{own}: the reference, {} steps ({:.1}× those of v_s = {:e}).",
                    r.v_s,
                    r.run.steps,
                    r.run.steps as f64 / rows[0].run.steps.max(1) as f64,
                    rows[0].v_s
                ),
                (Some(e), prev) => {
                    let cost = prev.map_or(String::new(), |p| {
                        format!(
                            "; {:.2}× the steps of v_s = {:e}",
                            r.run.steps as f64 / p.run.steps.max(1) as f64,
                            p.v_s
                        )
                    });
                    format!(
                        "v_s = {:e}{own}: {:.1} digits of the v_s → 0 limit{cost}.",
                        r.v_s,
                        super::digits(e)
                    )
                }
            }
        })
        .collect()
}
