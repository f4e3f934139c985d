//! `irsig bench accuracy <scene>`: run time against error, knob by knob.
//! A converged reference is rendered (fine thermal step, 96 shadow samples
//! per 24 h, fine spectral step, tight thermal tolerance, 4x4 supersampling,
//! 72-h spin-up); then,
//! for each knob alone (the others at their reference values), a ladder of
//! cheaper settings, and irsig's default set (the code's defaults of
//! `[render]`, whatever the scene file says). Each row reports wall
//! time, rays, thermal solves and the error against the reference: RMS and
//! max of surface temperature (K), band radiance (%) and apparent
//! temperature (K). Writes CSV, JSON and an SVG plot (error vs time, one
//! curve per knob).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use plotters::prelude::*;
use serde::Serialize;

use crate::output::Planes;
use crate::render::{prepare_conditions, prepare_static, render};

#[derive(clap::Args, Debug)]
pub struct AccuracyArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Output image size (square), pixels.
    #[arg(long, default_value_t = 128)]
    pub size: u32,
    /// Folder for accuracy.csv, accuracy.json and accuracy.svg.
    #[arg(short, long, default_value = "out/bench-accuracy")]
    pub output: PathBuf,
    /// Override scene keys (as `irsig render --set`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<u32>,
    /// Run only these knobs' ladders (repeatable; e.g. `history_hours`);
    /// default: all of them.
    #[arg(long = "knob", value_name = "NAME")]
    pub knobs: Vec<String>,
    /// Keep the knobs not named by `--knob` at irsig's defaults in the
    /// reference and the ladders (a cheaper reference for one knob, e.g.
    /// supersampling at full image size).
    #[arg(long, requires = "knobs")]
    pub others_at_default: bool,
    /// Only the reference and the default set (checks a default set
    /// against the converged reference without the ladders).
    #[arg(long, conflicts_with_all = ["knobs", "others_at_default"])]
    pub no_ladders: bool,
    /// A candidate set: the defaults with these render keys changed (e.g.
    /// `render.shadow_interval_min=60`, repeatable); adds a `candidate` row.
    #[arg(long, value_name = "KEY=VALUE")]
    pub candidate: Vec<String>,
}

/// A knob, its reference value and its ladder of cheaper settings.
pub const KNOBS: &[(&str, f64, &[f64])] = &[
    ("render.thermal_step_min", 5.0, &[60.0, 30.0, 15.0, 10.0]),
    (
        "render.thermal_tol_k",
        0.0005,
        &[0.1, 0.05, 0.02, 0.005, 0.002],
    ),
    ("render.shadow_interval_min", 15.0, &[120.0, 60.0, 30.0]),
    ("render.spectral_step_cm1", 2.0, &[40.0, 20.0, 10.0, 5.0]),
    ("render.supersample", 4.0, &[1.0, 2.0, 3.0]),
    ("render.history_hours", 72.0, &[12.0, 24.0, 36.0, 48.0]),
];

/// Whether `name` (as given to `--knob`, with or without `render.`) names
/// knob `key`.
fn knob_named(key: &str, name: &str) -> bool {
    key == name || key.trim_start_matches("render.") == name
}

/// One row of the table.
#[derive(Debug, Serialize, Clone)]
pub struct AccuracyRow {
    /// The knob varied ("reference", "default", or a key).
    pub knob: String,
    pub value: f64,
    pub wall_s: f64,
    pub rays: u64,
    pub thermal_solves: u64,
    pub surface_temp_rms_k: f64,
    pub surface_temp_max_k: f64,
    pub radiance_rms_pct: f64,
    pub radiance_max_pct: f64,
    pub apparent_temp_rms_k: f64,
    pub apparent_temp_max_k: f64,
}

/// (RMS, max) of `f(a, b)` over the pixels where both are finite.
fn err(a: &[f32], b: &[f32], f: impl Fn(f64, f64) -> f64) -> (f64, f64) {
    let (mut s, mut m, mut n) = (0.0, 0.0f64, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        if x.is_finite() && y.is_finite() {
            let e = f(x as f64, y as f64);
            s += e * e;
            m = m.max(e.abs());
            n += 1;
        }
    }
    if n == 0 {
        (f64::NAN, f64::NAN)
    } else {
        ((s / n as f64).sqrt(), m)
    }
}

fn plane<'a>(p: &'a Planes, name: &str) -> &'a [f32] {
    &p.get(name).expect("render writes this plane").data
}

pub fn run(a: AccuracyArgs) -> anyhow::Result<i32> {
    let base = super::render::parse_overrides(&a.set)?;
    for n in &a.knobs {
        if !KNOBS.iter().any(|(k, _, _)| knob_named(k, n)) {
            anyhow::bail!(
                "--knob {n}: not a knob; expected one of {}",
                KNOBS
                    .iter()
                    .map(|(k, _, _)| k.trim_start_matches("render."))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    let pool = super::render::thread_pool(a.threads)?;
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("cannot create {}", a.output.display()))?;
    let size = a.size.to_string();
    let with = |extra: &[(String, String)]| -> Vec<(String, String)> {
        let mut v = base.clone();
        v.push(("sensor.width_px".into(), size.clone()));
        v.push(("sensor.height_px".into(), size.clone()));
        v.extend_from_slice(extra);
        v
    };
    let d = crate::scene::spec::RenderOptions::default();
    let defaults: Vec<(String, String)> = [
        ("render.thermal_step_min", d.thermal_step_min),
        ("render.thermal_tol_k", d.thermal_tol_k),
        ("render.shadow_interval_min", d.shadow_interval_min),
        ("render.spectral_step_cm1", d.spectral_step_cm1),
        ("render.supersample", d.supersample as f64),
        ("render.history_hours", d.history_hours),
    ]
    .iter()
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect();
    let selected = |k: &str| a.knobs.is_empty() || a.knobs.iter().any(|n| knob_named(k, n));
    // The reference: every knob at its converged value, or with
    // --others-at-default only the selected ones (the rest at the defaults).
    let reference: Vec<(String, String)> = KNOBS
        .iter()
        .map(|(k, r, _)| {
            if a.others_at_default && !selected(k) {
                defaults
                    .iter()
                    .find(|(dk, _)| dk == k)
                    .expect("every knob has a default")
                    .clone()
            } else {
                (k.to_string(), r.to_string())
            }
        })
        .collect();
    let run_one = |ov: Vec<(String, String)>| -> anyhow::Result<(Planes, f64, u64, u64)> {
        pool.install(|| {
            let t0 = Instant::now();
            let scene = crate::scene::load_with_overrides(&a.scene, &ov)?;
            let st = prepare_static(scene, None)?;
            let cond = prepare_conditions(&st, st.scene.scene.time.utc(&st.scene.scene.site))?;
            let f = render(&st, &cond)?;
            let s = &f.stats;
            Ok((
                f.planes,
                t0.elapsed().as_secs_f64(),
                s.primary_rays + s.specular_rays + s.solar_rays,
                s.thermal_solves,
            ))
        })
    };
    eprintln!("bench accuracy: reference");
    let (rp, rt, rr, rs) = run_one(with(&reference))?;
    let row = |knob: &str, value: f64, p: &Planes, wall: f64, rays: u64, solves: u64| {
        let (ts_rms, ts_max) = err(
            plane(p, "surface_temperature"),
            plane(&rp, "surface_temperature"),
            |x, y| x - y,
        );
        let (l_rms, l_max) = err(
            plane(p, "band_radiance"),
            plane(&rp, "band_radiance"),
            |x, y| 100.0 * (x - y) / y,
        );
        let (ta_rms, ta_max) = err(
            plane(p, "apparent_temperature"),
            plane(&rp, "apparent_temperature"),
            |x, y| x - y,
        );
        AccuracyRow {
            knob: knob.into(),
            value,
            wall_s: wall,
            rays,
            thermal_solves: solves,
            surface_temp_rms_k: ts_rms,
            surface_temp_max_k: ts_max,
            radiance_rms_pct: l_rms,
            radiance_max_pct: l_max,
            apparent_temp_rms_k: ta_rms,
            apparent_temp_max_k: ta_max,
        }
    };
    let mut rows = vec![row("reference", 0.0, &rp, rt, rr, rs)];
    for (knob, _, ladder) in KNOBS
        .iter()
        .filter(|(k, _, _)| !a.no_ladders && selected(k))
    {
        for &v in *ladder {
            eprintln!("bench accuracy: {knob} = {v}");
            let mut ov = reference.clone();
            ov.retain(|(k, _)| k != knob);
            ov.push((knob.to_string(), v.to_string()));
            let (p, t, r, s) = run_one(with(&ov))?;
            rows.push(row(knob, v, &p, t, r, s));
        }
    }
    eprintln!("bench accuracy: irsig defaults");
    let (p, t, r, s) = run_one(with(&defaults))?;
    rows.push(row("default", 0.0, &p, t, r, s));
    if !a.candidate.is_empty() {
        let mut cand = defaults.clone();
        cand.extend(super::render::parse_overrides(&a.candidate)?);
        eprintln!("bench accuracy: candidate set");
        let (p, t, r, s) = run_one(with(&cand))?;
        rows.push(row("candidate", 0.0, &p, t, r, s));
    }

    let mut csv = String::from(
        "knob,value,wall_s,rays,thermal_solves,surface_temp_rms_k,surface_temp_max_k,radiance_rms_pct,radiance_max_pct,apparent_temp_rms_k,apparent_temp_max_k\n",
    );
    for r in &rows {
        csv += &format!(
            "{},{},{:.3},{},{},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5}\n",
            r.knob,
            r.value,
            r.wall_s,
            r.rays,
            r.thermal_solves,
            r.surface_temp_rms_k,
            r.surface_temp_max_k,
            r.radiance_rms_pct,
            r.radiance_max_pct,
            r.apparent_temp_rms_k,
            r.apparent_temp_max_k
        );
    }
    let write = |name: &str, text: &str| {
        crate::output::write_atomic(&a.output.join(name), |w| {
            std::io::Write::write_all(w, text.as_bytes()).map_err(|e| e.to_string())
        })
    };
    write("accuracy.csv", &csv)?;
    write("accuracy.json", &serde_json::to_string_pretty(&rows)?)?;
    plot(&a.output.join("accuracy.svg"), &rows)?;
    print!("{csv}");
    Ok(0)
}

/// Error (apparent temperature RMS, K) against wall time (s), log-log, one
/// curve per knob; the default set as a separate point.
fn plot(path: &std::path::Path, rows: &[AccuracyRow]) -> anyhow::Result<()> {
    let floor = 1e-4;
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.wall_s, r.apparent_temp_rms_k.max(floor)))
        .collect();
    let (xmin, xmax) = pts
        .iter()
        .fold((f64::MAX, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let ymax = pts.iter().fold(floor, |m, p| m.max(p.1));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "irsig: apparent-temperature RMS error vs run time",
                ("sans-serif", 20),
            )
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
            .x_desc("wall time, s")
            .y_desc("apparent temperature RMS error vs reference, K")
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
        root.present().map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    crate::output::write_atomic(path, |w| {
        std::io::Write::write_all(w, svg.as_bytes()).map_err(|e| e.to_string())
    })?;
    Ok(())
}
