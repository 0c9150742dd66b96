//! Log–log work–precision charts (SVG through plotters).

use anyhow::Result;
use plotters::prelude::*;

/// A named set of `(cost, error)` points, drawn as a line with markers.
pub type Curve = (String, Vec<(f64, f64)>);

/// Renders `curves` on log–log axes: cost (x) against relative error (y). Non-positive or
/// non-finite points are left out (an error of exactly zero cannot be drawn on a log axis).
pub fn work_precision_chart(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    curves: &[Curve],
) -> Result<String> {
    let ok = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0;
    let curves: Vec<(String, Vec<(f64, f64)>)> = curves
        .iter()
        .map(|(n, p)| (n.clone(), p.iter().copied().filter(ok).collect()))
        .collect();
    let pts = || curves.iter().flat_map(|(_, p)| p.iter().copied());
    let lo_hi = |f: fn((f64, f64)) -> f64| {
        pts()
            .map(f)
            .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)))
    };
    let (mut x0, mut x1) = lo_hi(|p| p.0);
    let (mut y0, mut y1) = lo_hi(|p| p.1);
    if x0 > x1 {
        (x0, x1, y0, y1) = (1.0, 10.0, 1e-16, 1.0);
    }
    // A decade-aligned frame with some room around the points.
    let (x0, x1) = (x0 / 2.0, x1 * 2.0);
    let (y0, y1) = (y0 / 10.0, y1 * 10.0);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .x_label_formatter(&|x| format!("{x:.0e}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()?;
        for (k, (name, p)) in curves.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
            chart.draw_series(
                p.iter()
                    .map(|&(x, y)| Circle::new((x, y), 4, color.filled())),
            )?;
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
