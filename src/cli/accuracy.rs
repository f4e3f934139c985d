//! `irsig bench accuracy <scene>`: run time against error, knob by knob.
//! A converged reference is rendered (fine thermal step, 10-min shadow
//! samples, fine spectral step, tight thermal tolerance, 4x4 supersampling,
//! 72-h spin-up); then,
//! for each knob alone (the others at their reference values), a ladder of
//! cheaper settings, and irsig's default set (the code's defaults of
//! `[render]`, whatever the scene file says). Each row reports wall and
//! CPU time, rays, thermal solves and the error against the reference: RMS,
//! 99th percentile and max of |error| in surface temperature (K), band
//! radiance (%) and apparent temperature (K) over all pixels, and the same
//! for surface and apparent temperature over the reference's shadow-edge
//! pixels ([`shadow_edge_pixels`]), where shadow sampling errors
//! concentrate. Writes CSV, JSON and an SVG plot (error vs CPU time, one
//! curve per knob: RMS over all pixels, and max over shadow-edge pixels).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use plotters::prelude::*;
use serde::Serialize;

use crate::output::Planes;
use crate::render::prepare::SunSample;
use crate::render::{Frame, prepare_conditions, prepare_static, render};

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
    /// Replace the ladder of the one knob named by `--knob` with these
    /// values (e.g. `--ladder 60,30,20` for a cheaper run at full size).
    #[arg(long, value_delimiter = ',', value_name = "VALUES")]
    pub ladder: Vec<f64>,
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
    (
        "render.shadow_interval_min",
        10.0,
        &[120.0, 60.0, 30.0, 20.0, 15.0],
    ),
    ("render.spectral_step_cm1", 2.0, &[40.0, 20.0, 10.0, 5.0]),
    ("render.supersample", 4.0, &[1.0, 2.0, 3.0]),
    ("render.history_hours", 72.0, &[12.0, 24.0, 36.0, 48.0]),
];

/// Whether `name` (as given to `--knob`, with or without `render.`) names
/// knob `key`.
fn knob_named(key: &str, name: &str) -> bool {
    key == name || key.trim_start_matches("render.") == name
}

/// One row of the table. Errors are of |test − reference| per output
/// pixel; `_p99_` is the 99th percentile by the nearest-rank rule
/// ([`percentile`]); `edge_` columns are over the reference's shadow-edge
/// pixels only ([`shadow_edge_pixels`]; NaN when there are none).
#[derive(Debug, Serialize, Clone)]
pub struct AccuracyRow {
    /// The knob varied ("reference", "default", or a key).
    pub knob: String,
    pub value: f64,
    pub wall_s: f64,
    /// CPU time of the process (all threads) during the render, s: the
    /// cost measure that a shared machine disturbs least.
    pub cpu_s: f64,
    pub rays: u64,
    pub thermal_solves: u64,
    pub surface_temp_rms_k: f64,
    pub surface_temp_p99_k: f64,
    pub surface_temp_max_k: f64,
    pub radiance_rms_pct: f64,
    pub radiance_p99_pct: f64,
    pub radiance_max_pct: f64,
    pub apparent_temp_rms_k: f64,
    pub apparent_temp_p99_k: f64,
    pub apparent_temp_max_k: f64,
    /// Number of shadow-edge pixels (of the reference).
    pub edge_pixels: usize,
    pub edge_surface_temp_rms_k: f64,
    pub edge_surface_temp_p99_k: f64,
    pub edge_surface_temp_max_k: f64,
    pub edge_apparent_temp_rms_k: f64,
    pub edge_apparent_temp_p99_k: f64,
    pub edge_apparent_temp_max_k: f64,
}

/// CPU time (user + system, all threads) this process has used so far, s,
/// from /proc/self/stat (clock ticks of USER_HZ = 100); NaN where unknown.
pub fn process_cpu_s() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the command name's closing parenthesis start at field 3
    // (state); utime and stime are fields 14 and 15.
    let after = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = after.split_whitespace().collect();
    match (
        f.get(11).and_then(|v| v.parse::<f64>().ok()),
        f.get(12).and_then(|v| v.parse::<f64>().ok()),
    ) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}

/// One render of [`run`]: planes, (wall, CPU) s, rays, thermal solves,
/// shadow-edge pixels.
type Run = (Planes, (f64, f64), u64, u64, Vec<bool>);

/// The `p`-th percentile (0 < p ≤ 100) of `v` by the nearest-rank rule:
/// the smallest value of the list with at least `p` % of the values at or
/// below it (element ⌈p·n/100⌉ of the sorted list, 1-based). NaN for an
/// empty list. Sorts `v` (NaNs last).
pub fn percentile(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let rank = (p / 100.0 * v.len() as f64).ceil() as usize;
    v[rank.clamp(1, v.len()) - 1]
}

/// RMS, 99th percentile and max of |error|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrStats {
    pub rms: f64,
    pub p99: f64,
    pub max: f64,
}

/// [`ErrStats`] of `f(a, b)` over the pixels where both are finite (and,
/// with a mask, the mask is set); NaN when there are none.
fn err(a: &[f32], b: &[f32], mask: Option<&[bool]>, f: impl Fn(f64, f64) -> f64) -> ErrStats {
    let mut e: Vec<f64> = a
        .iter()
        .zip(b)
        .enumerate()
        .filter(|(i, (x, y))| x.is_finite() && y.is_finite() && mask.is_none_or(|m| m[*i]))
        .map(|(_, (&x, &y))| f(x as f64, y as f64).abs())
        .collect();
    if e.is_empty() {
        return ErrStats {
            rms: f64::NAN,
            p99: f64::NAN,
            max: f64::NAN,
        };
    }
    let rms = (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt();
    let p99 = percentile(&mut e, 99.0);
    ErrStats {
        rms,
        p99,
        max: *e.last().expect("not empty"),
    }
}

/// The least cos(incidence) of the sun's beam on a facet at which a change
/// of its sunlit flag counts as a shadow edge crossing it
/// ([`shadow_edge_pixels`]).
pub const EDGE_MIN_COS: f32 = 0.2;

/// The shadow-edge pixels of a frame (row-major, `planes.width` ×
/// `planes.height`): a pixel is one when the primary surface of any of its
/// samples has, anywhere in its sun history, two consecutive samples at
/// which the sun's beam strikes the facet at cos(incidence) ≥
/// [`EDGE_MIN_COS`] (on level ground: the sun ≥ 11.5° high) but the sunlit
/// flag differs, i.e. the edge of a cast shadow crossed it while the sun
/// carried real energy. Sunrise, sunset, the sun passing the facet's plane
/// and the long shadows of a sun near the horizon do not count, so open
/// ground and roofs are not edge pixels; the ground swept by a building's
/// shadow by day and the facets it shades are. These are the pixels whose
/// temperature depends on when, between history samples, the shadow
/// arrived or left.
pub fn shadow_edge_pixels(frame: &Frame, suns: &[SunSample]) -> Vec<bool> {
    let (w, h) = (frame.planes.width as usize, frame.planes.height as usize);
    let sw = frame.sample_width as usize;
    let n = (sw / w.max(1)).max(1);
    let mut edge = vec![false; w * h];
    for (i, s) in frame.samples.iter().enumerate() {
        let Some(surf) = &s.surface else { continue };
        let (px, py) = ((i % sw) / n, (i / sw) / n);
        if px >= w || py >= h || edge[py * w + px] {
            continue;
        }
        let facing = |k: usize| suns[k].up && surf.normal.dot(suns[k].dir) >= EDGE_MIN_COS;
        let crossed = surf
            .history
            .windows(2)
            .enumerate()
            .any(|(k, f)| f[0] != f[1] && k + 1 < suns.len() && facing(k) && facing(k + 1));
        edge[py * w + px] = crossed;
    }
    edge
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
    if !a.ladder.is_empty() && a.knobs.len() != 1 {
        anyhow::bail!("--ladder needs exactly one --knob");
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
    // One render: its planes, (wall, CPU) time, rays, thermal solves and
    // (for the reference) its shadow-edge pixels, found after the clock
    // stops.
    let run_one = |ov: Vec<(String, String)>| -> anyhow::Result<Run> {
        pool.install(|| {
            let (t0, c0) = (Instant::now(), process_cpu_s());
            let scene = crate::scene::load_with_overrides(&a.scene, &ov)?;
            let st = prepare_static(scene, None)?;
            let cond = prepare_conditions(&st, st.scene.scene.time.utc(&st.scene.scene.site))?;
            let f = render(&st, &cond)?;
            let wall = (t0.elapsed().as_secs_f64(), process_cpu_s() - c0);
            let s = &f.stats;
            let (rays, solves) = (
                s.primary_rays + s.specular_rays + s.solar_rays,
                s.thermal_solves,
            );
            let edge = shadow_edge_pixels(&f, &cond.suns);
            Ok((f.planes, wall, rays, solves, edge))
        })
    };
    eprintln!("bench accuracy: reference");
    let (rp, rt, rr, rs, edge) = run_one(with(&reference))?;
    let row = |knob: &str, value: f64, p: &Planes, wall: (f64, f64), rays: u64, solves: u64| {
        let ts = |m| {
            err(
                plane(p, "surface_temperature"),
                plane(&rp, "surface_temperature"),
                m,
                |x, y| x - y,
            )
        };
        let ta = |m| {
            err(
                plane(p, "apparent_temperature"),
                plane(&rp, "apparent_temperature"),
                m,
                |x, y| x - y,
            )
        };
        let l = err(
            plane(p, "band_radiance"),
            plane(&rp, "band_radiance"),
            None,
            |x, y| 100.0 * (x - y) / y,
        );
        let (ts_all, ta_all) = (ts(None), ta(None));
        let (ts_edge, ta_edge) = (ts(Some(&edge)), ta(Some(&edge)));
        AccuracyRow {
            knob: knob.into(),
            value,
            wall_s: wall.0,
            cpu_s: wall.1,
            rays,
            thermal_solves: solves,
            surface_temp_rms_k: ts_all.rms,
            surface_temp_p99_k: ts_all.p99,
            surface_temp_max_k: ts_all.max,
            radiance_rms_pct: l.rms,
            radiance_p99_pct: l.p99,
            radiance_max_pct: l.max,
            apparent_temp_rms_k: ta_all.rms,
            apparent_temp_p99_k: ta_all.p99,
            apparent_temp_max_k: ta_all.max,
            edge_pixels: edge.iter().filter(|e| **e).count(),
            edge_surface_temp_rms_k: ts_edge.rms,
            edge_surface_temp_p99_k: ts_edge.p99,
            edge_surface_temp_max_k: ts_edge.max,
            edge_apparent_temp_rms_k: ta_edge.rms,
            edge_apparent_temp_p99_k: ta_edge.p99,
            edge_apparent_temp_max_k: ta_edge.max,
        }
    };
    let mut rows = vec![row("reference", 0.0, &rp, rt, rr, rs)];
    for (knob, _, ladder) in KNOBS
        .iter()
        .filter(|(k, _, _)| !a.no_ladders && selected(k))
    {
        let ladder: &[f64] = if a.ladder.is_empty() {
            ladder
        } else {
            &a.ladder
        };
        for &v in ladder {
            eprintln!("bench accuracy: {knob} = {v}");
            let mut ov = reference.clone();
            ov.retain(|(k, _)| k != knob);
            ov.push((knob.to_string(), v.to_string()));
            let (p, t, r, s, _) = run_one(with(&ov))?;
            rows.push(row(knob, v, &p, t, r, s));
        }
    }
    eprintln!("bench accuracy: irsig defaults");
    let (p, t, r, s, _) = run_one(with(&defaults))?;
    rows.push(row("default", 0.0, &p, t, r, s));
    if !a.candidate.is_empty() {
        let mut cand = defaults.clone();
        cand.extend(super::render::parse_overrides(&a.candidate)?);
        eprintln!("bench accuracy: candidate set");
        let (p, t, r, s, _) = run_one(with(&cand))?;
        rows.push(row("candidate", 0.0, &p, t, r, s));
    }

    let mut csv = String::from(
        "knob,value,wall_s,cpu_s,rays,thermal_solves,\
         surface_temp_rms_k,surface_temp_p99_k,surface_temp_max_k,\
         radiance_rms_pct,radiance_p99_pct,radiance_max_pct,\
         apparent_temp_rms_k,apparent_temp_p99_k,apparent_temp_max_k,edge_pixels,\
         edge_surface_temp_rms_k,edge_surface_temp_p99_k,edge_surface_temp_max_k,\
         edge_apparent_temp_rms_k,edge_apparent_temp_p99_k,edge_apparent_temp_max_k\n",
    );
    for r in &rows {
        csv += &format!(
            "{},{},{:.3},{:.2},{},{}",
            r.knob, r.value, r.wall_s, r.cpu_s, r.rays, r.thermal_solves
        );
        for v in [
            r.surface_temp_rms_k,
            r.surface_temp_p99_k,
            r.surface_temp_max_k,
            r.radiance_rms_pct,
            r.radiance_p99_pct,
            r.radiance_max_pct,
            r.apparent_temp_rms_k,
            r.apparent_temp_p99_k,
            r.apparent_temp_max_k,
        ] {
            csv += &format!(",{v:.5}");
        }
        csv += &format!(",{}", r.edge_pixels);
        for v in [
            r.edge_surface_temp_rms_k,
            r.edge_surface_temp_p99_k,
            r.edge_surface_temp_max_k,
            r.edge_apparent_temp_rms_k,
            r.edge_apparent_temp_p99_k,
            r.edge_apparent_temp_max_k,
        ] {
            csv += &format!(",{v:.5}");
        }
        csv += "\n";
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

/// Two panels, error against CPU time (s, all threads; wall time where
/// that is unknown), log-log, one curve per knob
/// and the default set as a separate point: left the apparent-temperature
/// RMS over all pixels, right the surface-temperature max over the
/// shadow-edge pixels (the spectral step, which does not change surface
/// temperature, lies on the floor there).
fn plot(path: &std::path::Path, rows: &[AccuracyRow]) -> anyhow::Result<()> {
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
    crate::output::write_atomic(path, |w| {
        std::io::Write::write_all(w, svg.as_bytes()).map_err(|e| e.to_string())
    })?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_is_the_nearest_rank() {
        // 1..=100 shuffled: the p-th percentile is p itself.
        let mut v: Vec<f64> = (0..100).map(|i| ((i * 37) % 100 + 1) as f64).collect();
        assert_eq!(percentile(&mut v, 99.0), 99.0);
        assert_eq!(percentile(&mut v, 50.0), 50.0);
        assert_eq!(percentile(&mut v, 100.0), 100.0);
        assert_eq!(percentile(&mut v, 0.5), 1.0);
        // Five values: rank ⌈0.99·5⌉ = 5 (the max), ⌈0.4·5⌉ = 2.
        let mut w = [3.0, 1.0, 5.0, 2.0, 4.0];
        assert_eq!(percentile(&mut w, 99.0), 5.0);
        assert_eq!(percentile(&mut w, 40.0), 2.0);
        assert!(percentile(&mut [], 99.0).is_nan());
    }

    #[test]
    fn process_cpu_time_grows() {
        let c0 = process_cpu_s();
        let mut x = 0u64;
        let t = Instant::now();
        while t.elapsed().as_secs_f64() < 0.05 {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
        let c1 = process_cpu_s();
        assert!(c0.is_finite() && c1 >= c0, "{c0} {c1}");
    }

    #[test]
    fn errors_over_all_and_masked_pixels() {
        let r = [10.0f32, 10.0, 10.0, 10.0, f32::NAN];
        let t = [10.0f32, 11.0, 7.0, 10.0, 12.0];
        let all = err(&t, &r, None, |x, y| x - y);
        assert_eq!(all.max, 3.0);
        assert_eq!(all.p99, 3.0);
        assert!((all.rms - (10.0f64 / 4.0).sqrt()).abs() < 1e-12);
        let m = [false, true, false, true, true];
        let edge = err(&t, &r, Some(&m), |x, y| x - y);
        assert_eq!((edge.max, edge.p99), (1.0, 1.0));
        assert!((edge.rms - 0.5f64.sqrt()).abs() < 1e-12);
        assert!(err(&t, &r, Some(&[false; 5]), |x, y| x - y).rms.is_nan());
    }
}
