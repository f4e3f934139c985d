//! Run time against error, knob by knob (`irsig bench accuracy`).
//! A converged reference is rendered (fine thermal step, 10-min shadow
//! samples with transitions bisected to 1 min, fine spectral step, tight thermal tolerance, 4x4 supersampling,
//! 72-h spin-up); then,
//! for each knob alone (the others at their reference values), a ladder of
//! cheaper settings, and irsig's default set (the code's defaults of
//! `[render]`, whatever the scene file says). Each row reports wall and
//! CPU time, rays, thermal solves and the error against the reference: RMS,
//! 99th percentile and max of |error| in surface temperature (K), band
//! radiance (%) and apparent temperature (K) over all pixels, and the same
//! for surface and apparent temperature over the reference's shadow-edge
//! pixels ([`shadow_edge_pixels`]), where shadow sampling errors
//! concentrate, and over its object-edge pixels ([`object_edge_pixels`]),
//! where the sub-pixel coverage of supersampling matters. Writes CSV, JSON and an SVG plot (error vs CPU time, one
//! curve per knob: RMS over all pixels, and max over shadow-edge pixels).

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use super::process_cpu_s;
use crate::render::adaptive::same_plane;
use crate::render::planes::Planes;
use crate::render::prepare::SunSample;
use crate::render::{Frame, prepare_conditions, prepare_static, render, thread_pool};

/// What [`accuracy`] runs: plain data, as the CLI's flags give it.
#[derive(Debug, Clone)]
pub struct AccuracyOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// Output image size (square), pixels.
    pub size: u32,
    /// Scene-key overrides applied to every render (as `render --set`).
    pub overrides: Vec<(String, String)>,
    /// Worker threads (None: all cores).
    pub threads: Option<u32>,
    /// Run only these knobs' ladders (with or without `render.`); empty:
    /// all of them.
    pub knobs: Vec<String>,
    /// Keep the knobs not named in `knobs` at irsig's defaults in the
    /// reference and the ladders.
    pub others_at_default: bool,
    /// Only the reference and the default set.
    pub no_ladders: bool,
    /// Replaces the ladder of the one knob in `knobs`.
    pub ladder: Vec<f64>,
    /// A candidate set: the defaults with these render keys changed; adds
    /// a `candidate` row when not empty.
    pub candidate: Vec<(String, String)>,
    /// Further candidate sets (the defaults with these keys changed), one
    /// row each (`also1`, `also2`, …).
    pub also: Vec<Vec<(String, String)>>,
    /// Changes to the converged reference (e.g. 16×16 supersampling).
    pub reference: Vec<(String, String)>,
}

impl AccuracyOptions {
    /// The defaults of `irsig bench accuracy SCENE`: 128², every knob.
    pub fn new(scene: impl Into<PathBuf>) -> AccuracyOptions {
        AccuracyOptions {
            scene: scene.into(),
            size: 128,
            overrides: Vec::new(),
            threads: None,
            knobs: Vec::new(),
            others_at_default: false,
            no_ladders: false,
            ladder: Vec::new(),
            candidate: Vec::new(),
            also: Vec::new(),
            reference: Vec::new(),
        }
    }
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
    ("render.shadow_resolution_min", 1.0, &[20.0, 10.0, 5.0, 2.0]),
    ("render.shadow_key_recent_h", 240.0, &[1.0, 2.0, 4.0, 8.0]),
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
/// pixels only ([`shadow_edge_pixels`]; NaN when there are none),
/// `object_edge_` columns over its object-edge pixels
/// ([`object_edge_pixels`]).
#[derive(Debug, Serialize, Clone)]
pub struct AccuracyRow {
    /// The knob varied ("reference", "default", or a key).
    pub knob: String,
    /// The knob's value.
    pub value: f64,
    /// Wall time of the render, s.
    pub wall_s: f64,
    /// CPU time of the process (all threads) during the render, s: the
    /// cost measure that a shared machine disturbs least.
    pub cpu_s: f64,
    /// Rays traced.
    pub rays: u64,
    /// Thermal solves (cache misses).
    pub thermal_solves: u64,
    /// Surface temperature error, RMS, K.
    pub surface_temp_rms_k: f64,
    /// Surface temperature error, 99th percentile, K.
    pub surface_temp_p99_k: f64,
    /// Surface temperature error, largest, K.
    pub surface_temp_max_k: f64,
    /// Band radiance error, RMS, % of the reference.
    pub radiance_rms_pct: f64,
    /// Band radiance error, 99th percentile, %.
    pub radiance_p99_pct: f64,
    /// Band radiance error, largest, %.
    pub radiance_max_pct: f64,
    /// Apparent temperature error, RMS, K.
    pub apparent_temp_rms_k: f64,
    /// Apparent temperature error, 99th percentile, K.
    pub apparent_temp_p99_k: f64,
    /// Apparent temperature error, largest, K.
    pub apparent_temp_max_k: f64,
    /// Number of shadow-edge pixels (of the reference).
    pub edge_pixels: usize,
    /// As `surface_temp_rms_k`, over the shadow-edge pixels.
    pub edge_surface_temp_rms_k: f64,
    /// As `surface_temp_p99_k`, over the shadow-edge pixels.
    pub edge_surface_temp_p99_k: f64,
    /// As `surface_temp_max_k`, over the shadow-edge pixels.
    pub edge_surface_temp_max_k: f64,
    /// As `apparent_temp_rms_k`, over the shadow-edge pixels.
    pub edge_apparent_temp_rms_k: f64,
    /// As `apparent_temp_p99_k`, over the shadow-edge pixels.
    pub edge_apparent_temp_p99_k: f64,
    /// As `apparent_temp_max_k`, over the shadow-edge pixels.
    pub edge_apparent_temp_max_k: f64,
    /// Number of object-edge pixels (of the reference,
    /// [`object_edge_pixels`]).
    pub object_edge_pixels: usize,
    /// As `surface_temp_rms_k`, over the object-edge pixels.
    pub object_edge_surface_temp_rms_k: f64,
    /// As `surface_temp_p99_k`, over the object-edge pixels.
    pub object_edge_surface_temp_p99_k: f64,
    /// As `surface_temp_max_k`, over the object-edge pixels.
    pub object_edge_surface_temp_max_k: f64,
    /// As `apparent_temp_rms_k`, over the object-edge pixels.
    pub object_edge_apparent_temp_rms_k: f64,
    /// As `apparent_temp_p99_k`, over the object-edge pixels.
    pub object_edge_apparent_temp_p99_k: f64,
    /// As `apparent_temp_max_k`, over the object-edge pixels.
    pub object_edge_apparent_temp_max_k: f64,
}

/// One render of [`accuracy`]: planes, (wall, CPU) s, rays, thermal solves,
/// shadow-edge pixels, object-edge pixels.
type Run = (Planes, (f64, f64), u64, u64, Vec<bool>, Vec<bool>);

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
    /// Root mean square.
    pub rms: f64,
    /// 99th percentile (nearest rank).
    pub p99: f64,
    /// Largest.
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
        // The flag differs between samples k − 1 and k exactly at the
        // history's transitions k.
        let crossed = (surf.history.switches().iter())
            .map(|&k| k as usize)
            .any(|k| k < suns.len() && facing(k - 1) && facing(k));
        edge[py * w + px] = crossed;
    }
    edge
}

/// The object-edge pixels of a frame (row-major, as
/// [`shadow_edge_pixels`]): a pixel is one when its samples do not all see
/// one plane of one material ([`same_plane`]: the same material, normals
/// within 1°, points within 5 cm + 10⁻⁴ of the range of one plane) or do
/// not all see a surface: silhouettes against the sky or a background,
/// steps, creases and material boundaries, where sub-pixel coverage is
/// what the supersampling buys. Each sample is compared with the pixel's
/// first.
pub fn object_edge_pixels(frame: &Frame) -> Vec<bool> {
    let (w, h) = (frame.planes.width as usize, frame.planes.height as usize);
    let sw = frame.sample_width as usize;
    let n = (sw / w.max(1)).max(1);
    let mut edge = vec![false; w * h];
    for (i, s) in frame.samples.iter().enumerate() {
        let (px, py) = ((i % sw) / n, (i / sw) / n);
        if px >= w || py >= h || edge[py * w + px] {
            continue;
        }
        let first = &frame.samples[(py * n) * sw + px * n];
        edge[py * w + px] = match (&first.surface, &s.surface) {
            (None, None) => false,
            (Some(a), Some(b)) => !same_plane(a, b),
            _ => true,
        };
    }
    edge
}

fn plane<'a>(p: &'a Planes, name: &str) -> &'a [f32] {
    &p.get(name).expect("render writes this plane").data
}

/// Renders the converged reference, each selected knob's ladder (the other
/// knobs at their reference values), irsig's default set and the optional
/// candidate set, and returns one row per render with its cost and its
/// errors against the reference. `progress` hears the name of each render
/// before it starts.
pub fn accuracy(
    a: &AccuracyOptions,
    progress: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<AccuracyRow>> {
    let base = a.overrides.clone();
    for n in &a.knobs {
        if !KNOBS.iter().any(|(k, _, _)| knob_named(k, n)) {
            anyhow::bail!(
                "knob {n}: not a knob; expected one of {}",
                KNOBS
                    .iter()
                    .map(|(k, _, _)| k.trim_start_matches("render."))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    if !a.ladder.is_empty() && a.knobs.len() != 1 {
        anyhow::bail!("a ladder needs exactly one knob (got {})", a.knobs.len());
    }
    let pool = thread_pool(a.threads)?;
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
        (
            "render.shadow_resolution_min",
            d.shadow_resolution_min.unwrap_or(d.shadow_interval_min),
        ),
        (
            "render.shadow_key_recent_h",
            d.shadow_key_recent_h.unwrap_or(240.0),
        ),
        ("render.spectral_step_cm1", d.spectral_step_cm1),
        ("render.supersample", d.supersample() as f64),
        ("render.history_hours", d.history_hours),
    ]
    .iter()
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect();
    let mut defaults = defaults;
    let sampling = match d.sampling {
        crate::scene::spec::Sampling::Adaptive => "\"adaptive\"",
        crate::scene::spec::Sampling::Uniform => "\"uniform\"",
    };
    defaults.push(("render.sampling".into(), sampling.into()));
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
            let mut st = prepare_static(scene, None)?;
            st.keep_samples = true; // shadow_edge_pixels reads the histories
            let cond = prepare_conditions(&st, st.scene.scene.time.utc(&st.scene.scene.site))?;
            let f = render(&st, &cond)?;
            let wall = (t0.elapsed().as_secs_f64(), process_cpu_s() - c0);
            let s = &f.stats;
            let (rays, solves) = (
                s.primary_rays + s.specular_rays + s.solar_rays,
                s.thermal_solves,
            );
            let edge = shadow_edge_pixels(&f, &cond.suns);
            let objects = object_edge_pixels(&f);
            Ok((f.planes, wall, rays, solves, edge, objects))
        })
    };
    // (the reference and the ladders sample uniformly: every pixel at the
    // reference's density; the defaults row samples as irsig does)
    let mut reference = reference;
    reference.insert(0, ("render.sampling".into(), "\"uniform\"".into()));
    reference.extend(a.reference.iter().cloned());
    progress("reference");
    let (rp, rt, rr, rs, edge, objects) = run_one(with(&reference))?;
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
        let (ts_obj, ta_obj) = (ts(Some(&objects)), ta(Some(&objects)));
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
            object_edge_pixels: objects.iter().filter(|e| **e).count(),
            object_edge_surface_temp_rms_k: ts_obj.rms,
            object_edge_surface_temp_p99_k: ts_obj.p99,
            object_edge_surface_temp_max_k: ts_obj.max,
            object_edge_apparent_temp_rms_k: ta_obj.rms,
            object_edge_apparent_temp_p99_k: ta_obj.p99,
            object_edge_apparent_temp_max_k: ta_obj.max,
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
            progress(&format!("{knob} = {v}"));
            let mut ov = reference.clone();
            ov.retain(|(k, _)| k != knob);
            ov.push((knob.to_string(), v.to_string()));
            let (p, t, r, s, ..) = run_one(with(&ov))?;
            rows.push(row(knob, v, &p, t, r, s));
        }
    }
    progress("irsig defaults");
    let (p, t, r, s, ..) = run_one(with(&defaults))?;
    rows.push(row("default", 0.0, &p, t, r, s));
    if !a.candidate.is_empty() {
        let mut cand = defaults.clone();
        cand.extend(a.candidate.iter().cloned());
        progress("candidate set");
        let (p, t, r, s, ..) = run_one(with(&cand))?;
        rows.push(row("candidate", 0.0, &p, t, r, s));
    }
    for (k, set) in a.also.iter().enumerate() {
        let mut cand = defaults.clone();
        cand.extend(set.iter().cloned());
        let name = format!("also{}", k + 1);
        progress(&name);
        let (p, t, r, s, ..) = run_one(with(&cand))?;
        rows.push(row(&name, 0.0, &p, t, r, s));
    }

    Ok(rows)
}

/// The rows as CSV (header line, then one line per row; times to 1 ms /
/// 10 ms, errors to 1e-5).
pub fn to_csv(rows: &[AccuracyRow]) -> String {
    let mut csv = String::from(
        "knob,value,wall_s,cpu_s,rays,thermal_solves,\
         surface_temp_rms_k,surface_temp_p99_k,surface_temp_max_k,\
         radiance_rms_pct,radiance_p99_pct,radiance_max_pct,\
         apparent_temp_rms_k,apparent_temp_p99_k,apparent_temp_max_k,edge_pixels,\
         edge_surface_temp_rms_k,edge_surface_temp_p99_k,edge_surface_temp_max_k,\
         edge_apparent_temp_rms_k,edge_apparent_temp_p99_k,edge_apparent_temp_max_k,\
         object_edge_pixels,object_edge_surface_temp_rms_k,object_edge_surface_temp_p99_k,\
         object_edge_surface_temp_max_k,object_edge_apparent_temp_rms_k,\
         object_edge_apparent_temp_p99_k,object_edge_apparent_temp_max_k\n",
    );
    // The error columns, to 1e-5.
    let errors = |csv: &mut String, vs: &[f64]| {
        for v in vs {
            *csv += &format!(",{v:.5}");
        }
    };
    for r in rows {
        csv += &format!(
            "{},{},{:.3},{:.2},{},{}",
            r.knob, r.value, r.wall_s, r.cpu_s, r.rays, r.thermal_solves
        );
        errors(
            &mut csv,
            &[
                r.surface_temp_rms_k,
                r.surface_temp_p99_k,
                r.surface_temp_max_k,
                r.radiance_rms_pct,
                r.radiance_p99_pct,
                r.radiance_max_pct,
                r.apparent_temp_rms_k,
                r.apparent_temp_p99_k,
                r.apparent_temp_max_k,
            ],
        );
        csv += &format!(",{}", r.edge_pixels);
        errors(
            &mut csv,
            &[
                r.edge_surface_temp_rms_k,
                r.edge_surface_temp_p99_k,
                r.edge_surface_temp_max_k,
                r.edge_apparent_temp_rms_k,
                r.edge_apparent_temp_p99_k,
                r.edge_apparent_temp_max_k,
            ],
        );
        csv += &format!(",{}", r.object_edge_pixels);
        errors(
            &mut csv,
            &[
                r.object_edge_surface_temp_rms_k,
                r.object_edge_surface_temp_p99_k,
                r.object_edge_surface_temp_max_k,
                r.object_edge_apparent_temp_rms_k,
                r.object_edge_apparent_temp_p99_k,
                r.object_edge_apparent_temp_max_k,
            ],
        );
        csv += "\n";
    }
    csv
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
    fn object_edges_are_pixels_whose_samples_leave_one_plane() {
        use crate::render::sample::{Sample, Surface};
        use glam::Vec3;
        // Three pixels of 2×2 samples (a 6×2 sample grid): the first sees
        // one plane throughout (its points 1 m apart on it), the second
        // a step of 10 cm in one sample, the third the sky in one sample.
        let on = |x: f32, z: f32| Sample {
            surface: Some(Surface {
                point: Vec3::new(x, 0.0, z),
                normal: Vec3::Z,
                range_m: 10.0,
                ..Default::default()
            }),
            ..Default::default()
        };
        let mut samples: Vec<Sample> = (0..12).map(|i| on((i % 6) as f32, 0.0)).collect();
        samples[9] = on(3.0, 0.1); // pixel 1, lower right
        samples[4].surface = None; // pixel 2, upper left
        let frame = Frame {
            planes: Planes::new(3, 1),
            stats: Default::default(),
            samples,
            sample_width: 6,
        };
        assert_eq!(object_edge_pixels(&frame), vec![false, true, true]);
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
