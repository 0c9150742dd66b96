//! The text of `kanegen simulate`: the human-readable summary of a run and its trajectory as
//! CSV (one column per state component, named by joint).

use kanegen_sim::scene::Scene;
use kanegen_sim::simulate::{Run, Sample, Summary};

/// A human-readable summary.
#[must_use]
pub fn render_text(s: &Summary) -> String {
    let f = |x: Option<f64>| x.map_or("not conserved".to_string(), |v| format!("{v:.3e}"));
    let status = if s.complete {
        String::new()
    } else {
        format!(
            "INCOMPLETE: stopped at t = {} ({})\n",
            s.t_end,
            s.stopped.as_deref().unwrap_or("")
        )
    };
    format!(
        "{status}base: {}\nsteps: {} accepted, {} rejected, {} evaluations, {:.3} s\n\
         energy drift (rel): {}\nlinear momentum drift (rel): {}\n\
         angular momentum drift (rel): {}\nfinal q: {:?}\nfinal qd: {:?}",
        s.base,
        s.steps,
        s.rejected_steps,
        s.evals,
        s.wall_s,
        f(s.max_energy_drift_rel),
        f(s.max_linear_momentum_drift_rel),
        f(s.max_angular_momentum_drift_rel),
        s.final_state.q,
        s.final_state.qd,
    ) + &events_text(s)
        + &s.singularity.as_ref().map_or(String::new(), |m| {
            format!(
                "\nsmallest σ_min of J* ({}): {:.3e} at t = {} s",
                m.body, m.sigma_min, m.t
            )
        })
}

/// One line per payload event of a summary (empty without events).
pub fn events_text(s: &Summary) -> String {
    s.events
        .iter()
        .map(|e| {
            format!(
                "\nevent at t = {}: {} by {}, momentum error through it (rel) {:.3e} linear, \
                 {:.3e} angular, kinetic energy change {:.6e} J",
                e.t,
                e.kind,
                e.body,
                e.linear_momentum_error_rel,
                e.angular_momentum_error_rel,
                e.energy_change
            )
        })
        .collect()
}

/// The CSV header of a scene's trajectory: `t`, `q_<joint>`…, `qd_<joint>`… (the model's
/// coordinates: mimic joints have no column), and for a
/// free-floating base `p0_x…`, `quat_x, quat_y, quat_z, quat_w`, `v_b_x…`, `omega_b_x…`.
#[must_use]
pub fn csv_header(scene: &Scene) -> Vec<String> {
    let names = scene.coordinate_names();
    let mut h = vec!["t".to_string()];
    h.extend(names.iter().map(|n| format!("q_{n}")));
    h.extend(names.iter().map(|n| format!("qd_{n}")));
    if scene.flexible.is_some() {
        h.extend(names.iter().map(|n| format!("theta_{n}")));
        h.extend(names.iter().map(|n| format!("thetad_{n}")));
    }
    if scene.is_floating() {
        for (p, comps) in [
            ("p0", &["x", "y", "z"][..]),
            ("quat", &["x", "y", "z", "w"][..]),
            ("v_b", &["x", "y", "z"][..]),
            ("omega_b", &["x", "y", "z"][..]),
        ] {
            h.extend(comps.iter().map(|c| format!("{p}_{c}")));
        }
    }
    h
}

/// One CSV row of a sample (see [`csv_header`]), with its newline. Numbers in Rust's shortest
/// round-trip `{:e}` form.
#[must_use]
pub fn csv_row(scene: &Scene, s: &Sample) -> String {
    let cells: Vec<String> = csv_values(scene, s)
        .iter()
        .map(|v| format!("{v:e}"))
        .collect();
    let mut out = cells.join(",");
    out.push('\n');
    out
}

/// The numbers of one CSV row of a sample, in the order of [`csv_header`].
#[must_use]
pub fn csv_values(scene: &Scene, s: &Sample) -> Vec<f64> {
    let n = scene.dof();
    let x = &s.x;
    let mut row: Vec<f64> = vec![s.t];
    if scene.is_floating() {
        row.extend(&x[7..7 + n]);
        row.extend(&x[13 + n..13 + 2 * n]);
        row.extend(&x[..7]);
        row.extend(&x[7 + n..13 + n]);
    } else {
        row.extend(x);
    }
    row
}

/// The trajectory as CSV text (see [`csv_header`]).
#[must_use]
pub fn trajectory_csv(scene: &Scene, run: &Run) -> String {
    let mut out = csv_header(scene).join(",");
    out.push('\n');
    for s in &run.samples {
        out.push_str(&csv_row(scene, s));
    }
    out
}
