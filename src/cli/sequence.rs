//! `irsig sequence` (one frame per local clock time, the paper's Fig. 12)
//! and `irsig sweep` (one frame per value of a scene key, Figs. 13 and 14).
//!
//! Both write, into an output folder, each frame as `irsig render` does
//! (EXR + PNG quicklook + JSON summary, via [`write_frame`]), a contact
//! sheet PNG of every frame's `sensor_radiance` under one common stretch,
//! and `index.json` listing the frames with their value and statistics
//! (mean, min, max and standard deviation of band radiance and apparent
//! temperature), so that the phenomena can be read from numbers.
//!
//! The work shared between frames is done once: a sequence prepares the
//! static part (geometry, BVH, materials, band, atmosphere) once and only
//! the conditions (weather forcing, sun samples, thermal cache) per frame;
//! a sweep re-derives the static part per value with
//! [`derive_static`], which shares the geometry, tracer and atmosphere
//! table whenever the value leaves them unchanged.

use std::path::PathBuf;

use anyhow::{Context, bail};
use chrono::{NaiveDate, NaiveDateTime, NaiveTime};
use serde::Serialize;

use super::render::{Summary, parse_overrides, thread_pool, write_frame};
use crate::output::quicklook::{Stretch, percentile_stretch, to_grey, write_grey_png};
use crate::output::write_atomic;
use crate::render::{Reused, Static, derive_static, prepare_conditions, render};
use crate::scene::LoadedScene;
use crate::scene::spec::TimeSpec;
use crate::trace::Backend;

/// Options shared by `sequence` and `sweep`.
#[derive(clap::Args, Debug)]
pub struct Common {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// Output folder (created if needed): one EXR + PNG + JSON per frame,
    /// `contact_sheet.png` and `index.json`.
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Override a scene key before loading, e.g. `--set sensor.width_px=128`
    /// or a whole table: `--set 'sensor.pose={slant_range={slant_range_m=10000,
    /// view_zenith_deg=0,azimuth_deg=180}}'` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Remove a key or a whole table from the scene before the overrides,
    /// e.g. `--unset sensor.pose.altitude` (repeatable).
    #[arg(long = "unset", value_name = "KEY")]
    pub unset: Vec<String>,
    /// Also write an ENVI BSQ float32 cube of every plane per frame.
    #[arg(long)]
    pub envi: bool,
    /// Ray-tracing backend (default: the scene's `render.tracer`).
    #[arg(long, value_enum)]
    pub tracer: Option<Backend>,
    /// Worker threads per frame (default: all cores). Results do not
    /// depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

#[derive(clap::Args, Debug)]
pub struct SequenceArgs {
    #[command(flatten)]
    pub common: Common,
    /// First local clock time: `HH:MM[:SS]` on the scene's image date, or a
    /// local date-time `YYYY-MM-DDTHH:MM[:SS]` (the site's `utc_offset_h`
    /// applies).
    #[arg(long)]
    pub from: String,
    /// Last local clock time (included when a step lands on it); same forms.
    #[arg(long)]
    pub to: String,
    /// Time step, e.g. `1h`, `30min`, `1h30m`, `90s`.
    #[arg(long)]
    pub step: String,
}

#[derive(clap::Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    pub common: Common,
    /// The dotted scene key to sweep, e.g. `weather.constant.wind_m_s` or
    /// `sensor.pose.slant_range.view_zenith_deg`.
    #[arg(long)]
    pub key: String,
    /// Comma-separated TOML values, one frame each, e.g. `0,4.47,8.94,13.41`.
    #[arg(long, value_name = "V1,V2,...")]
    pub values: String,
}

/// Most frames one command may render.
pub const MAX_FRAMES: usize = 1000;

/// Parses a duration such as `1h`, `30min`, `1h30m`, `90s`, `0.5h` into
/// whole seconds (> 0).
pub fn parse_step_s(s: &str) -> anyhow::Result<i64> {
    let err = || {
        anyhow::anyhow!(
            "--step {s:?}: expected a positive duration such as 1h, 30min, 1h30m or 90s"
        )
    };
    let t = s.trim();
    let mut total = 0.0;
    let mut rest = t;
    if rest.is_empty() {
        return Err(err());
    }
    while !rest.is_empty() {
        let num_end = rest
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .ok_or_else(err)?;
        let value: f64 = rest[..num_end].parse().map_err(|_| err())?;
        rest = &rest[num_end..];
        let unit_end = rest
            .find(|c: char| c.is_ascii_digit() || c == '.')
            .unwrap_or(rest.len());
        let scale = match rest[..unit_end].trim() {
            "h" | "hr" | "hrs" | "hour" | "hours" => 3600.0,
            "m" | "min" | "mins" | "minute" | "minutes" => 60.0,
            "s" | "sec" | "secs" | "second" | "seconds" => 1.0,
            _ => return Err(err()),
        };
        total += value * scale;
        rest = &rest[unit_end..];
    }
    let secs = total.round();
    if !(secs >= 1.0 && secs.is_finite()) {
        return Err(err());
    }
    Ok(secs as i64)
}

/// Parses a local time: `HH:MM[:SS]` on `date`, or a full local date-time
/// (`YYYY-MM-DDTHH:MM[:SS]`, a space instead of `T` accepted).
pub fn parse_local_time(flag: &str, s: &str, date: NaiveDate) -> anyhow::Result<NaiveDateTime> {
    let t = s.trim();
    for f in ["%H:%M", "%H:%M:%S"] {
        if let Ok(tm) = NaiveTime::parse_from_str(t, f) {
            return Ok(date.and_time(tm));
        }
    }
    for f in [
        "%Y-%m-%dT%H:%M",
        "%Y-%m-%dT%H:%M:%S",
        "%Y-%m-%d %H:%M",
        "%Y-%m-%d %H:%M:%S",
    ] {
        if let Ok(dt) = NaiveDateTime::parse_from_str(t, f) {
            return Ok(dt);
        }
    }
    bail!(
        "{flag} {s:?}: expected a local clock time HH:MM[:SS] (on the scene's image date {date}) \
         or a local date-time YYYY-MM-DDTHH:MM[:SS]"
    )
}

/// The local times from `from` to `to` (inclusive when a step lands on it).
pub fn time_steps(
    from: NaiveDateTime,
    to: NaiveDateTime,
    step_s: i64,
) -> anyhow::Result<Vec<NaiveDateTime>> {
    if to < from {
        bail!("--to {to} is before --from {from}");
    }
    let span = (to - from).num_seconds();
    let n = span / step_s + 1;
    if n as usize > MAX_FRAMES {
        bail!(
            "--from {from} --to {to} --step {step_s} s would give {n} frames; at most {MAX_FRAMES}"
        );
    }
    Ok((0..n)
        .map(|k| from + chrono::Duration::seconds(k * step_s))
        .collect())
}

/// Summary statistics of the finite values of a plane.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct PlaneStats {
    pub mean: f64,
    pub min: f64,
    pub max: f64,
    /// Population standard deviation.
    pub std: f64,
    /// Number of finite values.
    pub count: usize,
}

/// Statistics of the finite values of `data` (NaN fields when none).
pub fn plane_stats(data: &[f32]) -> PlaneStats {
    let v: Vec<f64> = data
        .iter()
        .filter(|x| x.is_finite())
        .map(|&x| x as f64)
        .collect();
    if v.is_empty() {
        return PlaneStats {
            mean: f64::NAN,
            min: f64::NAN,
            max: f64::NAN,
            std: f64::NAN,
            count: 0,
        };
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    PlaneStats {
        mean,
        min: v.iter().copied().fold(f64::INFINITY, f64::min),
        max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        std: var.sqrt(),
        count: v.len(),
    }
}

/// One frame of the index.
#[derive(Serialize)]
pub struct FrameEntry {
    pub index: usize,
    /// The swept value as given (sweep) or the local time (sequence).
    pub value: String,
    /// The value as a number when it is one.
    pub value_number: Option<f64>,
    pub local_time: String,
    pub image_time_utc: String,
    pub exr: String,
    pub png: String,
    pub json: String,
    pub sun_zenith_deg: f64,
    pub sun_azimuth_deg: f64,
    pub band_radiance_w_m2_sr_um: PlaneStats,
    pub apparent_temperature_k: PlaneStats,
    /// What this frame shared with the frame before.
    pub reused: Reused,
    /// Render time (trace + thermal + radiometry + sensor), s.
    pub seconds: f64,
}

/// The contact sheet's layout and stretch.
#[derive(Serialize)]
pub struct SheetInfo {
    pub file: String,
    pub plane: String,
    pub unit: String,
    pub stretch: String,
    pub stretch_lo: f32,
    pub stretch_hi: f32,
    pub columns: u32,
    pub rows: u32,
    pub cell_width_px: u32,
    pub cell_height_px: u32,
    pub gap_px: u32,
    pub order: String,
}

/// `index.json`.
#[derive(Serialize)]
pub struct Index {
    pub command: String,
    pub scene: String,
    /// The swept key (sweep only).
    pub key: Option<String>,
    pub band: String,
    pub contact_sheet: SheetInfo,
    pub frames: Vec<FrameEntry>,
}

/// One planned frame.
struct Plan {
    /// The value label (sweep value or local time).
    value: String,
    /// File stem of the frame's outputs inside the output folder.
    stem: String,
    /// The frame's scene; `None`: the previous frame's static part as is.
    scene: Option<LoadedScene>,
    /// Local image time; `None`: the scene's `[time]`.
    local: Option<NaiveDateTime>,
}

/// Pixels between contact-sheet cells.
const GAP_PX: u32 = 4;

/// Tiles equally sized or smaller frames (`(width, height, data)`) into a
/// grid of ⌈√n⌉ columns under one stretch; returns (width, height, grey,
/// columns, rows, cell width, cell height). Gaps and unused cell area are 0.
#[allow(clippy::type_complexity)]
pub fn tile_sheet(
    frames: &[(u32, u32, &[f32])],
    s: Stretch,
    gap: u32,
) -> (u32, u32, Vec<u8>, u32, u32, u32, u32) {
    let n = frames.len().max(1) as u32;
    let cols = (n as f64).sqrt().ceil() as u32;
    let rows = n.div_ceil(cols);
    let cw = frames.iter().map(|f| f.0).max().unwrap_or(1);
    let ch = frames.iter().map(|f| f.1).max().unwrap_or(1);
    let (w, h) = (cols * cw + (cols - 1) * gap, rows * ch + (rows - 1) * gap);
    let mut grey = vec![0u8; (w * h) as usize];
    for (k, (fw, fh, data)) in frames.iter().enumerate() {
        let (c, r) = (k as u32 % cols, k as u32 / cols);
        let (x0, y0) = (c * (cw + gap), r * (ch + gap));
        let g = to_grey(data, s);
        for y in 0..*fh {
            let dst = ((y0 + y) * w + x0) as usize;
            let src = (y * fw) as usize;
            grey[dst..dst + *fw as usize].copy_from_slice(&g[src..src + *fw as usize]);
        }
    }
    (w, h, grey, cols, rows, cw, ch)
}

/// Reads the scene text with `--unset` and `--set` applied.
fn scene_text(c: &Common) -> anyhow::Result<String> {
    let text = std::fs::read_to_string(&c.scene)
        .with_context(|| format!("cannot read {}", c.scene.display()))?;
    let text = if c.unset.is_empty() {
        text
    } else {
        crate::scene::remove_keys(&c.scene, &text, &c.unset)?
    };
    let overrides = parse_overrides(&c.set)?;
    Ok(crate::scene::apply_overrides(&c.scene, &text, &overrides)?)
}

/// A swept key inside one pose table (`sensor.pose.<kind>.…`) while the
/// scene has another pose table is an error that says how to switch.
fn check_pose_key(text: &str, key: &str) -> anyhow::Result<()> {
    let parts: Vec<&str> = key.split('.').map(str::trim).collect();
    let ["sensor", "pose", kind, _, ..] = parts.as_slice() else {
        return Ok(());
    };
    let Ok(doc) = text.parse::<toml_edit::DocumentMut>() else {
        return Ok(()); // the loader reports bad TOML
    };
    let others: Vec<String> = doc
        .get("sensor")
        .and_then(|s| s.as_table_like())
        .and_then(|s| s.get("pose"))
        .and_then(|p| p.as_table_like())
        .map(|p| {
            p.iter()
                .map(|(k, _)| k.to_string())
                .filter(|k| k != kind)
                .collect()
        })
        .unwrap_or_default();
    if let Some(o) = others.first() {
        bail!(
            "--key {key}: the scene's pose is [sensor.pose.{o}], and a pose has exactly one table; \
             switch with --unset sensor.pose.{o} and --set sensor.pose.{kind}.<key>=<value> for its \
             other keys, or give the whole pose: --set 'sensor.pose={{{kind}={{...}}}}'"
        );
    }
    Ok(())
}

/// Keeps letters, digits, `.`, `+`, `-`; anything else becomes `_`.
fn sanitise(s: &str) -> String {
    let t: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-') {
                c
            } else {
                '_'
            }
        })
        .take(40)
        .collect();
    if t.is_empty() { "_".into() } else { t }
}

pub fn run_sequence(a: SequenceArgs) -> anyhow::Result<i32> {
    let c = &a.common;
    let step_s = parse_step_s(&a.step)?;
    let scene = crate::scene::load_text(&c.scene, scene_text(c)?)?;
    let date = scene.scene.time.local.date();
    let from = parse_local_time("--from", &a.from, date)?;
    let to = parse_local_time("--to", &a.to, date)?;
    let times = time_steps(from, to, step_s)?;
    let one_day = times.iter().all(|t| t.date() == times[0].date());
    let whole_minutes = times.iter().all(|t| chrono::Timelike::second(t) == 0);
    let mut scene = Some(scene);
    let plans = times
        .iter()
        .map(|t| Plan {
            value: t.format("%Y-%m-%dT%H:%M:%S").to_string(),
            stem: if one_day && whole_minutes {
                t.format("frame_%H%M").to_string()
            } else {
                t.format("frame_%Y%m%dT%H%M%S").to_string()
            },
            scene: scene.take(),
            local: Some(*t),
        })
        .collect();
    run_frames(c, "sequence", None, plans)
}

pub fn run_sweep(a: SweepArgs) -> anyhow::Result<i32> {
    let c = &a.common;
    let key = a.key.trim();
    if key.is_empty() || key.split('.').any(|p| p.trim().is_empty()) {
        bail!(
            "--key {:?}: expected a dotted scene key such as weather.constant.wind_m_s",
            a.key
        );
    }
    let values: Vec<&str> = a.values.split(',').map(str::trim).collect();
    if values.iter().all(|v| v.is_empty()) {
        bail!("--values is empty: expected comma-separated values, e.g. --values 0,4.47,8.94");
    }
    if let Some(i) = values.iter().position(|v| v.is_empty()) {
        bail!(
            "--values {:?}: value {} is empty: expected comma-separated values, e.g. 0,4.47,8.94",
            a.values,
            i + 1
        );
    }
    if values.len() > MAX_FRAMES {
        bail!(
            "--values gives {} frames; at most {MAX_FRAMES}",
            values.len()
        );
    }
    let text = scene_text(c)?;
    check_pose_key(&text, key)?;
    let last = key.rsplit('.').next().unwrap_or(key);
    // Load (and so validate) every value's scene before rendering any.
    let plans = values
        .iter()
        .enumerate()
        .map(|(i, v)| -> anyhow::Result<Plan> {
            let t = crate::scene::apply_overrides(
                &c.scene,
                &text,
                &[(key.to_string(), v.to_string())],
            )?;
            let scene = crate::scene::load_text(&c.scene, t)
                .with_context(|| format!("sweep --key {key} = {v}"))?;
            Ok(Plan {
                value: v.to_string(),
                stem: format!("{i:02}_{}_{}", sanitise(last), sanitise(v)),
                scene: Some(scene),
                local: None,
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    run_frames(c, "sweep", Some(key), plans)
}

/// Renders the planned frames one after another (each parallel inside),
/// writes them, the contact sheet and the index.
fn run_frames(
    c: &Common,
    command: &str,
    key: Option<&str>,
    plans: Vec<Plan>,
) -> anyhow::Result<i32> {
    let dir = &c.output;
    if dir.extension().is_some_and(|e| e == "exr" || e == "png") {
        bail!(
            "-o {}: expected an output folder, not a file",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let pool = thread_pool(c.threads)?;
    let n = plans.len();
    let mut st: Option<Static> = None;
    let mut entries = Vec::with_capacity(n);
    let mut quicklooks: Vec<(u32, u32, Vec<f32>)> = Vec::with_capacity(n);
    let mut band = String::new();
    for (i, plan) in plans.into_iter().enumerate() {
        let value = plan.value;
        let (frame, entry_base) = pool.install(|| -> anyhow::Result<_> {
            let reused = match plan.scene {
                Some(scene) => {
                    let (s, r) = derive_static(st.as_ref(), scene, c.tracer)?;
                    st = Some(s);
                    r
                }
                None => Reused {
                    geometry: true,
                    atmosphere: true,
                },
            };
            let st = st.as_ref().expect("the first plan has a scene");
            let sc = &st.scene.scene;
            let local = plan.local.unwrap_or(sc.time.local);
            let utc = TimeSpec { local }.utc(&sc.site);
            let cond = prepare_conditions(st, utc)
                .with_context(|| format!("frame {} ({value})", i + 1))?;
            let frame = render(st, &cond).with_context(|| format!("frame {} ({value})", i + 1))?;
            Ok((
                frame,
                (
                    reused,
                    local,
                    utc,
                    cond.sun_now.zenith_deg,
                    cond.sun_now.azimuth_deg,
                    st.band.label.clone(),
                    cond.estimators.to_string(),
                    st.scene.path.display().to_string(),
                ),
            ))
        })?;
        let (reused, local, utc, sun_z, sun_az, band_label, estimators, scene_path) = entry_base;
        band = band_label.clone();
        let exr = dir.join(format!("{}.exr", plan.stem));
        let planes: Vec<(String, String)> = frame
            .planes
            .planes
            .iter()
            .map(|p| (p.name.clone(), p.unit.clone()))
            .collect();
        let frame_info = serde_json::json!({
            "command": command,
            "index": i,
            "key": key,
            "value": value,
            "local_time": local.format("%Y-%m-%dT%H:%M:%S").to_string(),
        });
        write_frame(
            &exr,
            &frame,
            |quicklook| {
                let mut v = serde_json::to_value(Summary {
                    scene: scene_path,
                    image_time_utc: utc.to_rfc3339(),
                    sun_zenith_deg: sun_z,
                    sun_azimuth_deg: sun_az,
                    band: band_label,
                    estimators,
                    quicklook,
                    planes,
                    stats: &frame.stats,
                })?;
                v["frame"] = frame_info;
                Ok(serde_json::to_string_pretty(&v)?)
            },
            c.envi,
        )?;
        let p = &frame.planes;
        let get = |name: &str| {
            p.get(name)
                .map(|pl| pl.data.as_slice())
                .ok_or_else(|| anyhow::anyhow!("render gave no {name} plane"))
        };
        let s = &frame.stats.seconds;
        let seconds = s.trace + s.thermal + s.radiometry + s.sensor;
        let entry = FrameEntry {
            index: i,
            value_number: value.parse().ok(),
            value,
            local_time: local.format("%Y-%m-%dT%H:%M:%S").to_string(),
            image_time_utc: utc.to_rfc3339(),
            exr: format!("{}.exr", plan.stem),
            png: format!("{}.png", plan.stem),
            json: format!("{}.json", plan.stem),
            sun_zenith_deg: sun_z,
            sun_azimuth_deg: sun_az,
            band_radiance_w_m2_sr_um: plane_stats(get("band_radiance")?),
            apparent_temperature_k: plane_stats(get("apparent_temperature")?),
            reused,
            seconds,
        };
        println!(
            "frame {}/{n} {}: wrote {} ({}x{}), {seconds:.2} s; apparent temperature std {:.3} K",
            i + 1,
            entry.value,
            exr.display(),
            p.width,
            p.height,
            entry.apparent_temperature_k.std,
        );
        quicklooks.push((p.width, p.height, get("sensor_radiance")?.to_vec()));
        entries.push(entry);
    }

    // Contact sheet under one stretch over all frames.
    let all: Vec<f32> = quicklooks
        .iter()
        .flat_map(|q| q.2.iter().copied())
        .collect();
    let stretch = percentile_stretch(&all);
    drop(all);
    let views: Vec<(u32, u32, &[f32])> = quicklooks
        .iter()
        .map(|(w, h, d)| (*w, *h, d.as_slice()))
        .collect();
    let (w, h, grey, cols, rows, cw, ch) = tile_sheet(&views, stretch, GAP_PX);
    let stretch_text = format!(
        "linear, 2-98 percentile of all frames together: {} .. {} W m-2 sr-1 um-1 -> 0 .. 255",
        stretch.lo, stretch.hi
    );
    let labels: Vec<String> = entries.iter().map(|e| e.value.clone()).collect::<Vec<_>>();
    let what = match key {
        Some(k) => format!("sweep of {k} over {}", labels.join(", ")),
        None => format!("sequence at local times {}", labels.join(", ")),
    };
    let sheet = dir.join("contact_sheet.png");
    write_grey_png(
        &sheet,
        w,
        h,
        &grey,
        &format!(
            "irsig {what}; plane sensor_radiance; {n} frames row-major in {cols} columns x {rows} rows \
             of {cw}x{ch} px with {GAP_PX} px gaps; common stretch for all frames: {stretch_text}"
        ),
    )?;
    let index = Index {
        command: command.into(),
        scene: c.scene.display().to_string(),
        key: key.map(str::to_string),
        band,
        contact_sheet: SheetInfo {
            file: "contact_sheet.png".into(),
            plane: "sensor_radiance".into(),
            unit: "W m-2 sr-1 um-1".into(),
            stretch: stretch_text,
            stretch_lo: stretch.lo,
            stretch_hi: stretch.hi,
            columns: cols,
            rows,
            cell_width_px: cw,
            cell_height_px: ch,
            gap_px: GAP_PX,
            order: "row-major, frames in index order".into(),
        },
        frames: entries,
    };
    let json = serde_json::to_string_pretty(&index)?;
    write_atomic(&dir.join("index.json"), |w| {
        std::io::Write::write_all(w, json.as_bytes()).map_err(|e| e.to_string())
    })?;
    println!(
        "wrote {} frames, {} and {}",
        n,
        sheet.display(),
        dir.join("index.json").display()
    );
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_parse() {
        assert_eq!(parse_step_s("1h").unwrap(), 3600);
        assert_eq!(parse_step_s("30min").unwrap(), 1800);
        assert_eq!(parse_step_s("1h30m").unwrap(), 5400);
        assert_eq!(parse_step_s("90s").unwrap(), 90);
        assert_eq!(parse_step_s("0.5h").unwrap(), 1800);
        for bad in ["", "0h", "h", "1", "1x", "-1h", "1h-"] {
            assert!(parse_step_s(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn times_parse_and_step() {
        let d = NaiveDate::from_ymd_opt(2001, 8, 8).unwrap();
        let a = parse_local_time("--from", "08:00", d).unwrap();
        let b = parse_local_time("--to", "2001-08-08T15:00", d).unwrap();
        assert_eq!(a.to_string(), "2001-08-08 08:00:00");
        let t = time_steps(a, b, 3600).unwrap();
        assert_eq!(t.len(), 8);
        assert_eq!(t[7], b);
        // a step that does not land on --to stops before it
        assert_eq!(time_steps(a, b, 7200).unwrap().len(), 4);
        assert!(parse_local_time("--from", "25:00", d).is_err());
        assert!(time_steps(b, a, 3600).is_err());
        assert!(time_steps(a, b, 1).is_err()); // too many frames
    }

    #[test]
    fn stats_of_known_values() {
        let s = plane_stats(&[1.0, 2.0, 3.0, 4.0, f32::NAN]);
        assert_eq!(s.count, 4);
        assert!((s.mean - 2.5).abs() < 1e-12);
        assert!((s.std - 1.25f64.sqrt()).abs() < 1e-12);
        assert_eq!((s.min, s.max), (1.0, 4.0));
    }

    #[test]
    fn sheet_tiles_frames_under_one_stretch() {
        let a = [0.0f32; 4];
        let b = [10.0f32; 4];
        let c = [5.0f32; 4];
        let s = Stretch { lo: 0.0, hi: 10.0 };
        let (w, h, g, cols, rows, _, _) =
            tile_sheet(&[(2, 2, &a[..]), (2, 2, &b[..]), (2, 2, &c[..])], s, 1);
        assert_eq!((cols, rows, w, h), (2, 2, 5, 5));
        assert_eq!(g[0], 0); // frame a
        assert_eq!(g[3], 255); // frame b, right of the 1-px gap
        assert_eq!(g[3 * 5], 128); // frame c, below
    }
}
