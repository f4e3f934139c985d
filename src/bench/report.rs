//! Writing benchmark results: `irsig bench accuracy`'s CSV, JSON and SVG
//! plot (error against CPU time, one curve per knob).

use std::path::Path;

use anyhow::Context;
use plotters::prelude::*;

use crate::bench::accuracy::{AccuracyRow, KNOBS, to_csv};
use crate::output::write_text;

/// Writes `accuracy.csv`, `accuracy.json` and `accuracy.svg` into `dir`
/// (created if missing), each atomically.
pub fn write_accuracy(dir: &Path, rows: &[AccuracyRow]) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    write_text(&dir.join("accuracy.csv"), &to_csv(rows))?;
    write_text(
        &dir.join("accuracy.json"),
        &serde_json::to_string_pretty(rows)?,
    )?;
    plot(&dir.join("accuracy.svg"), rows)
}

/// Two panels, error against CPU time (s, all threads; wall time where
/// that is unknown), log-log, one curve per knob
/// and the default set as a separate point: left the apparent-temperature
/// RMS over all pixels, right the surface-temperature max over the
/// shadow-edge pixels (the spectral step, which does not change surface
/// temperature, lies on the floor there).
fn plot(path: &Path, rows: &[AccuracyRow]) -> anyhow::Result<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (1400, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        let (left, right) = root.split_horizontally(700);
        panel(
            &left,
            rows,
            "apparent-temperature RMS error vs CPU time",
            "apparent temperature RMS error vs reference, K",
            |r| r.apparent_temp_rms_k,
        )?;
        panel(
            &right,
            rows,
            "max error over shadow-edge pixels vs CPU time",
            "surface temperature max error (shadow-edge pixels), K",
            |r| r.edge_surface_temp_max_k,
        )?;
        root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    write_text(path, &svg)?;
    Ok(())
}

/// One panel of [`plot`]: `metric` (K; values below 1e-4 K and NaN drawn
/// at 1e-4) against CPU time.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    rows: &[AccuracyRow],
    caption: &str,
    y_desc: &str,
    metric: impl Fn(&AccuracyRow) -> f64,
) -> anyhow::Result<()> {
    let floor = 1e-4;
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            let m = metric(r);
            let t = if r.cpu_s > 0.0 { r.cpu_s } else { r.wall_s };
            (t, if m.is_nan() { floor } else { m.max(floor) })
        })
        .collect();
    let (xmin, xmax) = pts
        .iter()
        .fold((f64::MAX, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let ymax = pts.iter().fold(floor, |m, p| m.max(p.1));
    let mut chart = ChartBuilder::on(area)
        .caption(format!("irsig: {caption}"), ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            ((xmin * 0.8).max(1e-3)..xmax * 1.25).log_scale(),
            (floor..ymax * 2.0).log_scale(),
        )
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc("CPU time (all threads), s")
        .y_desc(y_desc)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let colours = [RED, BLUE, GREEN, MAGENTA, CYAN, BLACK];
    for (i, (knob, _, _)) in KNOBS.iter().enumerate() {
        let c = colours[i % colours.len()];
        let series: Vec<(f64, f64)> = rows
            .iter()
            .zip(&pts)
            .filter(|(r, _)| r.knob == *knob)
            .map(|(_, p)| *p)
            .collect();
        chart
            .draw_series(LineSeries::new(series.clone(), c.stroke_width(2)))
            .map_err(|e| anyhow::anyhow!("{e}"))?
            .label(knob.trim_start_matches("render."))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
        chart
            .draw_series(series.into_iter().map(|p| Circle::new(p, 4, c.filled())))
            .map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    let defaults: Vec<(f64, f64)> = rows
        .iter()
        .zip(&pts)
        .filter(|(r, _)| r.knob == "default")
        .map(|(_, p)| *p)
        .collect();
    chart
        .draw_series(
            defaults
                .into_iter()
                .map(|p| Cross::new(p, 8, BLACK.stroke_width(3))),
        )
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .label("irsig defaults")
        .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(())
}
