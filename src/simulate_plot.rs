//! SVG plots of a simulation run: joint angles, and energy/momentum drift, against time.

use crate::scene::Scene;
use crate::simulate::Run;
use anyhow::{Context, Result};
use plotters::prelude::*;
use std::path::Path;

/// A named polyline.
type Series = (String, Vec<(f64, f64)>);

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

/// Writes `joints.svg` (joint positions) and, when the scene monitors any conserved quantity,
/// `drift.svg` (relative energy and momentum drift) into `dir`.
pub fn write_plots(scene: &Scene, run: &Run, dir: &Path) -> Result<()> {
    let n = scene.chain.dof();
    let off = if scene.is_floating() { 7 } else { 0 };
    let joints: Vec<Series> = scene
        .chain
        .joints()
        .iter()
        .enumerate()
        .take(n)
        .map(|(i, j)| {
            (
                j.name.clone(),
                run.samples.iter().map(|s| (s.t, s.x[off + i])).collect(),
            )
        })
        .collect();
    let write = |name: &str, svg: String| -> Result<()> {
        let p = dir.join(name);
        std::fs::write(&p, svg).with_context(|| format!("cannot write `{}`", p.display()))
    };
    write(
        "joints.svg",
        line_chart("Joint positions", "q (rad or m)", &joints)?,
    )?;
    let mut drift: Vec<Series> = Vec::new();
    let pick = |f: &dyn Fn(&crate::simulate::Sample) -> Option<f64>| -> Option<Vec<(f64, f64)>> {
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
    Ok(())
}
