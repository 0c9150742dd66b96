//! SVG plots of a simulation run against time: joint angles, energy/momentum drift, the
//! end-effector position and (free-floating) the base attitude.

use anyhow::Result;
use kanegen_dynamics::algorithms::frames;
use kanegen_dynamics::base::quat_to_matrix;
use kanegen_dynamics::linalg::{Mat3, Vec3};
use kanegen_dynamics::{FrameParams, Params};
use kanegen_sim::scene::Scene;
use kanegen_sim::simulate::Run;
use plotters::prelude::*;

/// A named polyline.
pub type Series = (String, Vec<(f64, f64)>);

/// Renders `series` as an SVG line chart.
pub fn line_chart(title: &str, y_desc: &str, series: &[Series]) -> Result<String> {
    let pts = series.iter().flat_map(|(_, p)| p.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let pad = ((y1 - y0) * 0.05).max(1e-300);
    let (y0, y1) = if y1 > y0 {
        (y0 - pad, y1 + pad)
    } else {
        (y0 - 1.0, y1 + 1.0)
    };
    let x1 = if x1 > x0 { x1 } else { x0 + 1.0 };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 500)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .y_desc(y_desc)
            .y_label_formatter(&|y| format!("{y:.3e}"))
            .draw()?;
        for (k, (name, p)) in series.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
    }
    Ok(svg)
}

/// The inertial-frame position of the end effector at every sample (`x`, `y`, `z` series): the
/// model's first named frame, or the origin of the last body when it names none.
#[must_use]
pub fn end_effector_series(scene: &Scene, run: &Run) -> Vec<Series> {
    let n = scene.dof();
    let params = Params::<f64>::new(&scene.model);
    // The joints' positions from the coordinates (mimic joints follow theirs).
    let coupling = kanegen_dynamics::mimic::Coupling::new(scene.model.mimics());
    let target = params.frames.first().cloned().unwrap_or(FrameParams {
        parent: Some(scene.model.dof() - 1),
        translation: Vec3::zero(),
        rotation: Mat3::identity(),
    });
    let mut out: Vec<Series> = ["x", "y", "z"]
        .iter()
        .map(|c| ((*c).to_string(), Vec::with_capacity(run.samples.len())))
        .collect();
    for s in &run.samples {
        let x = &s.x;
        let q = if scene.is_floating() {
            &x[7..7 + n]
        } else {
            &x[..n]
        };
        let (o, _) = frames::placement(&params, &coupling.full_positions(q), &target);
        let p = if scene.is_floating() {
            let quat: [f64; 4] = x[3..7].try_into().expect("4 entries");
            &quat_to_matrix(&quat).mul_vec(&o) + &Vec3::new(x[0], x[1], x[2])
        } else {
            o
        };
        for (i, series) in out.iter_mut().enumerate() {
            series.1.push((s.t, p.0[i]));
        }
    }
    out
}

/// Roll, pitch, yaw (Z–Y–X Euler angles, rad) of the base quaternion `[x, y, z, w]` at every
/// sample of a free-floating run, unwrapped (multiples of 2π added) to stay continuous.
#[must_use]
pub fn base_attitude_series(run: &Run) -> Vec<Series> {
    let mut out: Vec<Series> = ["roll", "pitch", "yaw"]
        .iter()
        .map(|c| ((*c).to_string(), Vec::with_capacity(run.samples.len())))
        .collect();
    for s in &run.samples {
        let [x, y, z, w] = [s.x[3], s.x[4], s.x[5], s.x[6]];
        let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
        let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
        let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
        for (series, v) in out.iter_mut().zip([roll, pitch, yaw]) {
            // Unwrap the ±π jumps of roll and yaw so the curves stay continuous.
            let v = match series.1.last() {
                Some(&(_, prev)) => {
                    v + (std::f64::consts::TAU * ((prev - v) / std::f64::consts::TAU).round())
                }
                None => v,
            };
            series.1.push((s.t, v));
        }
    }
    out
}

/// Renders `joints.svg` (joint positions), `end_effector.svg` (inertial position of the last
/// body's origin), for a free-floating base `base_attitude.svg` (roll/pitch/yaw) and, when the
/// scene monitors any conserved quantity, `drift.svg` (relative energy and momentum drift):
/// `(file name, SVG)`.
pub fn render_plots(scene: &Scene, run: &Run) -> Result<Vec<(&'static str, String)>> {
    let off = if scene.is_floating() { 7 } else { 0 };
    let joints: Vec<Series> = scene
        .coordinate_names()
        .into_iter()
        .enumerate()
        .map(|(i, j)| {
            (
                j.to_string(),
                run.samples.iter().map(|s| (s.t, s.x[off + i])).collect(),
            )
        })
        .collect();
    let mut files: Vec<(&'static str, String)> = Vec::new();
    let mut write = |name: &'static str, svg: String| -> Result<()> {
        files.push((name, svg));
        Ok(())
    };
    write(
        "joints.svg",
        line_chart("Joint positions", "q (rad or m)", &joints)?,
    )?;
    write(
        "end_effector.svg",
        line_chart(
            "End-effector (last body origin), inertial frame",
            "position (m)",
            &end_effector_series(scene, run),
        )?,
    )?;
    if scene.is_floating() {
        write(
            "base_attitude.svg",
            line_chart(
                "Base attitude (Z-Y-X Euler angles)",
                "angle (rad)",
                &base_attitude_series(run),
            )?,
        )?;
    }
    let mut drift: Vec<Series> = Vec::new();
    let pick =
        |f: &dyn Fn(&kanegen_sim::simulate::Sample) -> Option<f64>| -> Option<Vec<(f64, f64)>> {
            run.samples.iter().map(|s| f(s).map(|v| (s.t, v))).collect()
        };
    if let Some(p) = pick(&|s| s.energy_drift) {
        drift.push(("energy".into(), p));
    }
    if let Some(p) = pick(&|s| s.momentum_drift.map(|m| m.0)) {
        drift.push(("linear momentum".into(), p));
    }
    if let Some(p) = pick(&|s| s.momentum_drift.map(|m| m.1)) {
        drift.push(("angular momentum".into(), p));
    }
    if !drift.is_empty() {
        write(
            "drift.svg",
            line_chart(
                "Relative drift of conserved quantities",
                "relative drift",
                &drift,
            )?,
        )?;
    }
    Ok(files)
}
