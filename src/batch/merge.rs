//! Merging a finished batch (`irsig batch merge`) into one result set in
//! `merged/`:
//! - `stack.nc`: a NetCDF-4 file (CF-1.8 conventions) with dimensions
//!   `frame`, `y`, `x`; every plane a float32 variable (frame, y, x) with
//!   `units` and `long_name`; coordinates along `frame`: `id`, `time` (UTC,
//!   seconds since 1970-01-01), `local_time`, the sun's zenith and azimuth,
//!   `scene` and one per varied dimension (numbers as float64, otherwise
//!   text); `y`/`x` are pixel rows and columns (row 0 at the top);
//! - `index.json`: per frame its labels, times, sun and the statistics of
//!   band radiance and apparent temperature;
//! - `contact_sheet.png`: `sensor_radiance` of up to [`SHEET_MAX`] frames
//!   (evenly spaced through the manifest) under one common stretch.
//!
//! Each file is written under a temporary name and renamed, so a killed
//! merge leaves the previous result set or none.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Serialize;

use super::{Batch, FrameJob};
use crate::output::quicklook::write_grey_png;
use crate::output::sequence::{GAP_PX, contact_sheet};
use crate::output::set::OutputSet;
use crate::output::{PlaneStats, plane_stats};

/// Most frames on the contact sheet.
pub const SHEET_MAX: usize = 100;

/// What [`merge`] wrote.
#[derive(Debug, Clone, Serialize)]
pub struct MergeReport {
    pub frames: usize,
    pub width: u32,
    pub height: u32,
    pub planes: Vec<String>,
    pub stack: PathBuf,
    pub index: PathBuf,
    pub contact_sheet: PathBuf,
}

/// One frame of the merged `index.json`.
#[derive(Debug, Clone, Serialize)]
pub struct MergedFrame {
    pub id: String,
    pub index: usize,
    pub labels: std::collections::BTreeMap<String, String>,
    pub local_time: String,
    pub image_time_utc: String,
    pub sun_zenith_deg: f64,
    pub sun_azimuth_deg: f64,
    pub exr: PathBuf,
    pub band_radiance_w_m2_sr_um: PlaneStats,
    pub apparent_temperature_k: PlaneStats,
}

/// The merged `index.json`.
#[derive(Debug, Clone, Serialize)]
pub struct MergedIndex {
    pub name: String,
    pub spec: PathBuf,
    pub dimensions: Vec<String>,
    pub band: String,
    pub stack: String,
    pub contact_sheet: String,
    pub contact_sheet_frames: Vec<String>,
    pub contact_sheet_stretch: String,
    pub frames: Vec<MergedFrame>,
}

/// What a frame's JSON summary tells the merge.
struct FrameMeta {
    image_time_utc: chrono::DateTime<chrono::Utc>,
    local_time: String,
    sun_zenith_deg: f64,
    sun_azimuth_deg: f64,
    band: String,
    planes: Vec<(String, String)>,
}

fn read_meta(dir: &Path, f: &FrameJob) -> anyhow::Result<FrameMeta> {
    let p = dir.join(&f.outputs.json);
    let text =
        std::fs::read_to_string(&p).with_context(|| format!("cannot read {}", p.display()))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", p.display()))?;
    let bad = |what: &str| anyhow::anyhow!("{}: no {what} in the frame summary", p.display());
    let t = v["image_time_utc"]
        .as_str()
        .ok_or_else(|| bad("image_time_utc"))?;
    let image_time_utc = chrono::DateTime::parse_from_rfc3339(t)
        .with_context(|| format!("{}: image_time_utc {t:?}", p.display()))?
        .with_timezone(&chrono::Utc);
    let planes = v["planes"]
        .as_array()
        .ok_or_else(|| bad("planes"))?
        .iter()
        .map(|e| {
            Some((
                e.get(0)?.as_str()?.to_string(),
                e.get(1)?.as_str()?.to_string(),
            ))
        })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| bad("planes list of [name, unit]"))?;
    Ok(FrameMeta {
        image_time_utc,
        local_time: v["frame"]["local_time"].as_str().unwrap_or("").to_string(),
        sun_zenith_deg: v["sun_zenith_deg"]
            .as_f64()
            .ok_or_else(|| bad("sun_zenith_deg"))?,
        sun_azimuth_deg: v["sun_azimuth_deg"]
            .as_f64()
            .ok_or_else(|| bad("sun_azimuth_deg"))?,
        band: v["band"].as_str().unwrap_or("").to_string(),
        planes,
    })
}

/// Long names of the planes (CF `long_name`).
fn long_name(plane: &str) -> String {
    plane.replace('_', " ")
}

fn nc<T>(r: Result<T, netcdf::Error>, what: &str, path: &Path) -> anyhow::Result<T> {
    r.map_err(|e| anyhow::anyhow!("cannot write {}: {what}: {e}", path.display()))
}

/// Merges the batch in `dir` (every frame must be done) into `dir/merged/`;
/// `planes`: only these planes go into the stack (None: every plane).
pub fn merge(dir: &Path, planes: Option<&[String]>) -> anyhow::Result<MergeReport> {
    let batch = Batch::open(dir)?;
    let st = batch.status();
    if st.done != st.total {
        let first = st
            .failed
            .first()
            .map(|(id, e)| format!("; first failure: {id}: {e}"))
            .unwrap_or_default();
        bail!(
            "{}: {} of {} frames are done ({} failed, {} missing): run `irsig batch run` \
             (or see `irsig batch status`) before merging{first}",
            dir.display(),
            st.done,
            st.total,
            st.failed.len(),
            st.missing.len()
        );
    }
    if batch.frames.is_empty() {
        bail!("{}: the batch has no frames", dir.display());
    }
    let out = dir.join("merged");
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let metas: Vec<FrameMeta> = batch
        .frames
        .iter()
        .map(|f| read_meta(dir, f))
        .collect::<anyhow::Result<_>>()?;
    let first = &metas[0];
    for (f, m) in batch.frames.iter().zip(&metas) {
        if m.planes != first.planes {
            bail!(
                "frame {} has other planes than frame {} ({:?} vs {:?}): a stack needs one plane set",
                f.id,
                batch.frames[0].id,
                m.planes.iter().map(|p| &p.0).collect::<Vec<_>>(),
                first.planes.iter().map(|p| &p.0).collect::<Vec<_>>()
            );
        }
    }

    let stack_planes: Vec<(String, String)> = match planes {
        None => first.planes.clone(),
        Some(want) => want
            .iter()
            .map(|w| {
                first
                    .planes
                    .iter()
                    .find(|(n, _)| n == w)
                    .cloned()
                    .ok_or_else(|| {
                        anyhow::anyhow!(
                            "plane {w:?}: the frames have no such plane; they have {}",
                            first
                                .planes
                                .iter()
                                .map(|p| p.0.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    })
            })
            .collect::<anyhow::Result<_>>()?,
    };
    // The result set (index.json last: its marker); then the stack,
    // written by libnetcdf into a scratch file under a temporary name.
    let index_path = out.join("index.json");
    let mut set = OutputSet::new(&index_path)?;
    let tmp = tempfile::Builder::new()
        .prefix(".irsig-partial-")
        .suffix(".nc")
        .tempfile_in(&out)
        .with_context(|| format!("cannot write in {}", out.display()))?;
    let stack_path = out.join("stack.nc");
    let n = batch.frames.len();
    let mut entries = Vec::with_capacity(n);
    let sheet_pick: Vec<usize> = if n <= SHEET_MAX {
        (0..n).collect()
    } else {
        (0..SHEET_MAX)
            .map(|k| k * (n - 1) / (SHEET_MAX - 1))
            .collect()
    };
    let mut sheet_data: Vec<(u32, u32, Vec<f32>)> = Vec::new();
    let (width, height) = {
        let tp = tmp.path();
        let mut file = nc(netcdf::create(tp), "create", tp)?;
        // The first frame is read once: its size shapes the stack, and the
        // loop below takes its planes.
        let (w0, h0, chans0) =
            crate::output::exr::read_exr(&dir.join(&batch.frames[0].outputs.exr))
                .map_err(anyhow::Error::msg)?;
        let mut first_chans = Some(chans0);
        nc(file.add_dimension("frame", n), "frame", tp)?;
        nc(file.add_dimension("y", h0 as usize), "y", tp)?;
        nc(file.add_dimension("x", w0 as usize), "x", tp)?;
        for (k, v) in [
            ("Conventions", "CF-1.8"),
            ("title", &format!("irsig batch {}", batch.info.name)),
            ("source", &format!("irsig {}", env!("CARGO_PKG_VERSION"))),
            ("irsig_spec", &batch.info.spec.display().to_string()),
            ("band", &first.band),
        ] {
            nc(file.add_attribute(k, v), k, tp)?;
        }
        {
            let mut v = nc(file.add_variable::<i32>("frame", &["frame"]), "frame", tp)?;
            nc(
                v.put_attribute("long_name", "frame index in the manifest"),
                "frame",
                tp,
            )?;
            let idx: Vec<i32> = (0..n as i32).collect();
            nc(v.put_values(&idx, ..), "frame", tp)?;
        }
        for (name, len, what) in [
            ("y", h0, "pixel row (0 at the top)"),
            ("x", w0, "pixel column (0 at the left)"),
        ] {
            let mut v = nc(file.add_variable::<i32>(name, &[name]), name, tp)?;
            nc(v.put_attribute("long_name", what), name, tp)?;
            nc(v.put_attribute("units", "1"), name, tp)?;
            let idx: Vec<i32> = (0..len as i32).collect();
            nc(v.put_values(&idx, ..), name, tp)?;
        }
        {
            let mut v = nc(file.add_variable::<f64>("time", &["frame"]), "time", tp)?;
            nc(v.put_attribute("standard_name", "time"), "time", tp)?;
            nc(v.put_attribute("long_name", "image time (UTC)"), "time", tp)?;
            nc(
                v.put_attribute("units", "seconds since 1970-01-01 00:00:00"),
                "time",
                tp,
            )?;
            nc(v.put_attribute("calendar", "standard"), "time", tp)?;
            let t: Vec<f64> = metas
                .iter()
                .map(|m| {
                    m.image_time_utc.timestamp() as f64
                        + m.image_time_utc.timestamp_subsec_nanos() as f64 * 1e-9
                })
                .collect();
            nc(v.put_values(&t, ..), "time", tp)?;
        }
        for (name, unit, vals) in [
            (
                "sun_zenith",
                "degree",
                metas.iter().map(|m| m.sun_zenith_deg).collect::<Vec<_>>(),
            ),
            (
                "sun_azimuth",
                "degree",
                metas.iter().map(|m| m.sun_azimuth_deg).collect(),
            ),
        ] {
            let mut v = nc(file.add_variable::<f64>(name, &["frame"]), name, tp)?;
            nc(v.put_attribute("units", unit), name, tp)?;
            nc(v.put_attribute("long_name", long_name(name)), name, tp)?;
            nc(v.put_values(&vals, ..), name, tp)?;
        }
        // Text coordinates along `frame`: id, local time, and each
        // dimension (numbers as float64 when every value is one).
        let mut text_coords: Vec<(String, Vec<String>)> = vec![
            (
                "id".into(),
                batch.frames.iter().map(|f| f.id.clone()).collect(),
            ),
            (
                "local_time".into(),
                metas.iter().map(|m| m.local_time.clone()).collect(),
            ),
        ];
        for d in &batch.info.dimensions {
            if d == "time" {
                continue;
            }
            let vals: Vec<String> = batch
                .frames
                .iter()
                .map(|f| f.labels.get(d).cloned().unwrap_or_default())
                .collect();
            let nums: Option<Vec<f64>> = vals.iter().map(|s| s.parse::<f64>().ok()).collect();
            match nums {
                Some(nums) if d != "scene" => {
                    let mut v = nc(file.add_variable::<f64>(d, &["frame"]), d, tp)?;
                    nc(
                        v.put_attribute("long_name", format!("scene key {d}")),
                        d,
                        tp,
                    )?;
                    nc(v.put_values(&nums, ..), d, tp)?;
                }
                _ => text_coords.push((d.clone(), vals)),
            }
        }
        for (name, vals) in &text_coords {
            let mut v = nc(file.add_string_variable(name, &["frame"]), name, tp)?;
            for (k, s) in vals.iter().enumerate() {
                nc(v.put_string(s, [k]), name, tp)?;
            }
        }
        // CF: the per-frame variables are coordinates of every plane.
        let mut coord_names = vec![
            "time".to_string(),
            "sun_zenith".into(),
            "sun_azimuth".into(),
        ];
        coord_names.extend(
            batch
                .info
                .dimensions
                .iter()
                .filter(|d| *d != "time" && *d != "scene")
                .cloned(),
        );
        coord_names.extend(text_coords.iter().map(|(n, _)| n.clone()));
        let coordinates = coord_names.join(" ");
        for (name, unit) in &stack_planes {
            let mut v = nc(
                file.add_variable::<f32>(name, &["frame", "y", "x"]),
                name,
                tp,
            )?;
            // One chunk per frame, deflated (level 1 with byte shuffle:
            // lossless, deterministic).
            nc(v.set_chunking(&[1, h0 as usize, w0 as usize]), name, tp)?;
            nc(v.set_compression(1, true), name, tp)?;
            nc(
                v.put_attribute("coordinates", coordinates.as_str()),
                name,
                tp,
            )?;
            nc(v.put_attribute("units", unit.as_str()), name, tp)?;
            nc(v.put_attribute("long_name", long_name(name)), name, tp)?;
        }
        // The planes, frame by frame (one frame in memory at a time).
        for (k, (f, m)) in batch.frames.iter().zip(&metas).enumerate() {
            let exr = dir.join(&f.outputs.exr);
            let (w, h, chans) = match first_chans.take() {
                Some(c) => (w0, h0, c),
                None => crate::output::exr::read_exr(&exr).map_err(anyhow::Error::msg)?,
            };
            if (w, h) != (w0, h0) {
                bail!(
                    "{}: {w}x{h} px, but the batch's first frame is {w0}x{h0}: a stack needs one image size",
                    exr.display()
                );
            }
            let get = |name: &str| -> anyhow::Result<&Vec<f32>> {
                chans
                    .iter()
                    .find(|(c, _)| c == name)
                    .map(|c| &c.1)
                    .ok_or_else(|| anyhow::anyhow!("{}: no channel {name}", exr.display()))
            };
            for (name, _) in &stack_planes {
                let data = get(name)?;
                let mut v = file
                    .variable_mut(name)
                    .ok_or_else(|| anyhow::anyhow!("stack variable {name} vanished"))?;
                nc(
                    v.put_values(data, [k..k + 1, 0..h as usize, 0..w as usize]),
                    name,
                    tp,
                )?;
            }
            let sr = get("sensor_radiance")?;
            if sheet_pick.binary_search(&k).is_ok() {
                sheet_data.push((w, h, sr.clone()));
            }
            entries.push(MergedFrame {
                id: f.id.clone(),
                index: f.index,
                labels: f.labels.clone(),
                local_time: m.local_time.clone(),
                image_time_utc: m.image_time_utc.format("%Y-%m-%dT%H:%M:%SZ").to_string(),
                sun_zenith_deg: m.sun_zenith_deg,
                sun_azimuth_deg: m.sun_azimuth_deg,
                exr: f.outputs.exr.clone(),
                band_radiance_w_m2_sr_um: plane_stats(get("band_radiance")?),
                apparent_temperature_k: plane_stats(get("apparent_temperature")?),
            });
        }
        nc(file.close(), "close", tp)?;
        (w0, h0)
    };
    // The set: stack, contact sheet, then index.json as the marker.
    set.stage(&stack_path, |w| {
        let mut f = std::fs::File::open(tmp.path()).map_err(|e| e.to_string())?;
        std::io::copy(&mut f, w)
            .map(|_| ())
            .map_err(|e| e.to_string())
    })?;
    drop(tmp);

    let views: Vec<(u32, u32, &[f32])> = sheet_data
        .iter()
        .map(|(w, h, d)| (*w, *h, d.as_slice()))
        .collect();
    let sheet = contact_sheet(&views);
    let stretch = format!(
        "linear, 2-98 percentile of the sheet's frames together: {} .. {} W m-2 sr-1 um-1 -> 0 .. 255",
        sheet.stretch.lo, sheet.stretch.hi
    );
    let sheet_path = out.join("contact_sheet.png");
    write_grey_png(
        &mut set,
        &sheet_path,
        sheet.width,
        sheet.height,
        &sheet.grey,
        &format!(
            "irsig batch {}; plane sensor_radiance; {} frames row-major in {} columns x {} rows with {GAP_PX} px gaps; {stretch}",
            batch.info.name,
            views.len(),
            sheet.columns,
            sheet.rows
        ),
    )?;
    let index = MergedIndex {
        name: batch.info.name.clone(),
        spec: batch.info.spec.clone(),
        dimensions: batch.info.dimensions.clone(),
        band: first.band.clone(),
        stack: "stack.nc".into(),
        contact_sheet: "contact_sheet.png".into(),
        contact_sheet_frames: sheet_pick
            .iter()
            .map(|&k| batch.frames[k].id.clone())
            .collect(),
        contact_sheet_stretch: stretch,
        frames: entries,
    };
    let json = serde_json::to_string_pretty(&index)? + "\n";
    set.stage(&index_path, |w| {
        std::io::Write::write_all(w, json.as_bytes()).map_err(|e| e.to_string())
    })?;
    set.commit()?;
    Ok(MergeReport {
        frames: n,
        width,
        height,
        planes: stack_planes.iter().map(|p| p.0.clone()).collect(),
        stack: stack_path,
        index: index_path,
        contact_sheet: sheet_path,
    })
}
