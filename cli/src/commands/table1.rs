//! `kanegen table1`: the Markdown, JSON and Fig. 2 renderings of [`crate::table1`].

use anyhow::Result;
use kanegen_trace::poly::Poly;
use kanegen_trace::table1::{Table1, TableAlgorithm, N_MAX};
use plotters::prelude::*;

/// Renders the Markdown report through the tera template `templates/table1.md.tera`.
pub fn render_markdown(t: &Table1) -> Result<String> {
    let mut tera = tera::Tera::default();
    tera.add_raw_template("table1.md", include_str!("../../templates/table1.md.tera"))?;
    let mut ctx = tera::Context::from_serialize(t)?;
    ctx.insert("version", env!("CARGO_PKG_VERSION"));
    ctx.insert("n_max", &N_MAX);
    let printed: Vec<serde_json::Value> = t
        .printed_totals
        .iter()
        .map(|p| {
            let txt = |c: &[f64]| if c.is_empty() { "—".to_string() } else { Poly::from_f64(c).to_string() };
            serde_json::json!({"row": p.row, "name": p.name, "mul_text": txt(&p.mul), "add_text": txt(&p.add), "text": p.text})
        })
        .collect();
    ctx.insert("printed_totals", &printed);
    let mut ssrms_rows: Vec<(String, String, String, String, String)> = Vec::new();
    if let Some(p) = t.ssrms_n6["printed"].as_object() {
        for (name, v) in p {
            ssrms_rows.push((
                name.clone(),
                "printed".into(),
                v["mul"].to_string(),
                v["add"].to_string(),
                v["total"].to_string(),
            ));
        }
    }
    for v in t.ssrms_n6["traced"].as_array().into_iter().flatten() {
        ssrms_rows.push((
            v["algorithm"].as_str().unwrap_or("").into(),
            format!("traced, {}", v["convention"].as_str().unwrap_or("")),
            v["mul"].to_string(),
            v["add"].to_string(),
            v["total"].to_string(),
        ));
    }
    ctx.insert("ssrms_rows", &ssrms_rows);
    let cross: Vec<serde_json::Value> = t
        .crossovers
        .iter()
        .map(|c| serde_json::json!({"curve": c.curve, "text": Poly::from_f64(&c.total).to_string(), "at_n": if c.at_n.is_empty() { vec!["none in (1, 40)".to_string()] } else { c.at_n.iter().map(|x| format!("{x:.2}")).collect() }}))
        .collect();
    ctx.insert("crossovers", &cross);
    Ok(tera.render("table1.md", &ctx)?)
}

/// Renders Fig. 2 (operations against N) as SVG.
pub fn render_fig2(t: &Table1) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "Operations for A(q) against N (Fig. 2, printed and traced)",
                ("sans-serif", 20),
            )
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(1f64..N_MAX as f64, 0f64..17000f64)?;
        chart
            .configure_mesh()
            .x_desc("N (number of links)")
            .y_desc("multiplications + additions")
            .y_labels(18)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.0}"))
            .draw()?;
        let xs: Vec<f64> = (0..=((N_MAX - 1) * 10))
            .map(|k| 1.0 + k as f64 / 10.0)
            .collect();
        let printed = |row: &str| {
            Poly::from_f64(
                &t.printed_totals
                    .iter()
                    .find(|p| p.row == row)
                    .unwrap()
                    .total,
            )
        };
        let total_of = |alg: TableAlgorithm, conv: &str| {
            let r = t
                .totals
                .iter()
                .find(|x| x.algorithm == alg.name() && x.convention == conv)
                .unwrap();
            Poly::from_f64(&r.mul).add(&Poly::from_f64(&r.add))
        };
        let curves: Vec<(String, Poly, RGBColor, u8)> = vec![
            (
                "f: recurrent, printed 91.5N² − 136.5N + 39".into(),
                printed("14"),
                RED,
                1,
            ),
            ("g: «Kosynka», printed".into(), printed("15"), MAGENTA, 1),
            (
                "h: Stepanenko, printed 69N² + 69N".into(),
                printed("16"),
                BLUE,
                1,
            ),
            (
                "recurrent-r1, traced (paper conv.)".into(),
                total_of(TableAlgorithm::RecurrentR1, "paper"),
                RED,
                0,
            ),
            (
                "recurrent (R2), traced (paper conv.)".into(),
                total_of(TableAlgorithm::Recurrent, "paper"),
                RGBColor(200, 120, 0),
                0,
            ),
            (
                "crba-inertial, traced (paper conv.)".into(),
                total_of(TableAlgorithm::CrbaInertial, "paper"),
                BLUE,
                0,
            ),
            (
                "recurrent (R2), emitted".into(),
                total_of(TableAlgorithm::Recurrent, "emitted"),
                RGBColor(120, 60, 0),
                0,
            ),
            (
                "crba-inertial, emitted".into(),
                total_of(TableAlgorithm::CrbaInertial, "emitted"),
                RGBColor(0, 120, 160),
                0,
            ),
            (
                "Featherstone CRBA (RBDA Table 10.1)".into(),
                printed("—"),
                BLACK,
                2,
            ),
        ];
        for (label, p, color, style) in curves {
            let pts: Vec<(f64, f64)> = xs
                .iter()
                .map(|&x| (x, p.eval_f64(x)))
                .filter(|(_, y)| *y <= 17000.0)
                .collect();
            let s = ShapeStyle::from(&color).stroke_width(2);
            let series: Vec<(f64, f64)> = pts;
            match style {
                0 => chart.draw_series(LineSeries::new(series, s))?,
                1 => chart.draw_series(DashedLineSeries::new(series, 8, 5, s))?,
                _ => chart.draw_series(DashedLineSeries::new(series, 2, 4, s))?,
            }
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
    }
    Ok(svg)
}

/// The files `table1 --out DIR` writes.
pub const FILES: [&str; 3] = ["table1.md", "table1.json", "fig2.svg"];

/// Writes `table1.md`, `table1.json` and `fig2.svg` into `dir` (created if needed, files
/// replaced).
pub fn write_all(t: &Table1, dir: &std::path::Path) -> Result<()> {
    write_planned(t, &crate::output::OutputDir::plan(dir, &FILES, true, &[])?)
}

/// Writes the files into a planned output directory, atomically.
pub fn write_planned(t: &Table1, dir: &crate::output::OutputDir) -> Result<()> {
    let files = [
        (FILES[0], render_markdown(t)?.into_bytes()),
        (
            FILES[1],
            (serde_json::to_string_pretty(t)? + "\n").into_bytes(),
        ),
        (FILES[2], render_fig2(t)?.into_bytes()),
    ];
    dir.write_all(&files)
}
