//! Merging a finished batch (`irsig batch merge`) into one result set in
//! `merged/`:
//! - `stack.nc`: a NetCDF-4 file (CF-1.8 conventions). Where the frames
//!   form the batch's product (every combination of scene, time, each sweep
//!   key and random draw once: [`product_layout`]), those are its
//!   dimensions, each with its coordinate (`scene` text, `time` the local
//!   image time, sweep keys float64 or text, `draw` the draw number), then
//!   `y`, `x`; otherwise one flat `frame` dimension. Every plane is a float32
//!   variable over them with `units` and `long_name`; per frame: `frame`
//!   (manifest index), `id`, the UTC image time (`time` in the flat layout,
//!   `image_time` in the product one; seconds since 1970-01-01),
//!   `local_time`, the sun's zenith and azimuth and the random keys; `y`/`x`
//!   are pixel rows and columns (row 0 at the top). `material` and `case`
//!   carry CF `flag_values`/`flag_meanings` (material: when every frame has
//!   the same material table);
//! - `index.json`: the layout, the material table (per scene), and per
//!   frame its labels, times, sun and the statistics of band radiance and
//!   apparent temperature;
//! - `contact_sheet.png`: `sensor_radiance` of up to [`SHEET_MAX`] frames
//!   (evenly spaced through the manifest) under one common stretch.
//!
//! Each file is written under a temporary name and renamed, so a killed
//! merge leaves the previous result set or none.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Serialize;

use super::{Batch, FrameJob};
pub use crate::output::frame::MaterialEntry;
use crate::output::sequence::{
    GAP_PX, band_of, contact_sheet, median_of, sheet_min_span, write_contact_sheet,
};
use crate::output::set::OutputSet;
use crate::output::{PlaneStats, plane_stats};

/// Most frames on the contact sheet.
pub const SHEET_MAX: usize = 100;

/// What [`merge`] wrote.
#[derive(Debug, Clone, Serialize)]
pub struct MergeReport {
    /// Frames merged.
    pub frames: usize,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The planes stacked.
    pub planes: Vec<String>,
    /// The stacked planes' file.
    pub stack: PathBuf,
    /// The merged `index.json`.
    pub index: PathBuf,
    /// The contact sheet's PNG.
    pub contact_sheet: PathBuf,
}

/// One frame of the merged `index.json`.
#[derive(Debug, Clone, Serialize)]
pub struct MergedFrame {
    /// The frame's id.
    pub id: String,
    /// Its position in the manifest.
    pub index: usize,
    /// Its labels (scene, time, sweep keys, draw).
    pub labels: std::collections::BTreeMap<String, String>,
    /// Local image time.
    pub local_time: String,
    /// Image time, RFC 3339 UTC.
    pub image_time_utc: String,
    /// Sun zenith angle, degrees.
    pub sun_zenith_deg: f64,
    /// Sun azimuth, degrees clockwise from north.
    pub sun_azimuth_deg: f64,
    /// The frame's EXR, relative to the batch folder.
    pub exr: PathBuf,
    /// Statistics of the band radiance, W m⁻² sr⁻¹ µm⁻¹.
    pub band_radiance_w_m2_sr_um: PlaneStats,
    /// Statistics of the apparent temperature, K.
    pub apparent_temperature_k: PlaneStats,
}

/// The merged `index.json`.
#[derive(Debug, Clone, Serialize)]
pub struct MergedIndex {
    /// The batch's name.
    pub name: String,
    /// The spec it was planned from.
    pub spec: PathBuf,
    /// The label keys that vary across frames.
    pub dimensions: Vec<String>,
    /// The stack's dimensions before `y`, `x`: the product's axes, or
    /// `["frame"]` where the frames are not a regular product.
    pub stack_dimensions: Vec<String>,
    /// The material table (the `material` plane's values) when every frame
    /// has the same one, else `None` (see `materials_by_scene`).
    pub materials: Option<Vec<MaterialEntry>>,
    /// Each scene's material table (by its `scene` label).
    pub materials_by_scene: std::collections::BTreeMap<String, Vec<MaterialEntry>>,
    /// The band.
    pub band: String,
    /// The stacked planes' file.
    pub stack: String,
    /// The contact sheet's PNG.
    pub contact_sheet: String,
    /// The frames the contact sheet shows, in order.
    pub contact_sheet_frames: Vec<String>,
    /// How the contact sheet's stretch was chosen.
    pub contact_sheet_stretch: String,
    /// Every frame, in manifest order.
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
    materials: Vec<MaterialEntry>,
}

/// CF `flag_values`/`flag_meanings` of the `case` plane (docs/render.md).
pub const CASE_FLAGS: [(f32, &str); 5] = [
    (0.0, "outside_scene"),
    (1.0, "diffuse"),
    (2.0, "specular_sky"),
    (3.0, "specular_background"),
    (4.0, "sky"),
];

/// A CF flag meaning: the name with every run of characters other than
/// letters, digits, `_`, `-`, `.` replaced by `_` (meanings are
/// blank-separated words).
pub fn flag_word(name: &str) -> String {
    let w: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '_' | '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if w.is_empty() { "_".into() } else { w }
}

/// The `material` plane's CF flags: -1 `none`, then each material.
pub fn material_flags(table: &[MaterialEntry]) -> (Vec<f32>, String) {
    let mut values = vec![-1.0f32];
    let mut words = vec!["none".to_string()];
    for m in table {
        values.push(m.index as f32);
        words.push(flag_word(&m.name));
    }
    (values, words.join(" "))
}

/// The stack's product layout: the axes (name, values as labels) and each
/// frame's position on them.
#[derive(Debug, Clone, PartialEq)]
pub struct Product {
    /// Each axis: its name and its values (as labels), in order.
    pub axes: Vec<(String, Vec<String>)>,
    /// Per frame (manifest order), its index on each axis.
    pub positions: Vec<Vec<usize>>,
}

impl Product {
    /// The frame's row-major offset in the axes' array.
    pub fn offset(&self, pos: &[usize]) -> usize {
        pos.iter()
            .zip(&self.axes)
            .fold(0, |acc, (&p, (_, v))| acc * v.len() + p)
    }

    /// The number of cells (frames) of the product.
    pub fn size(&self) -> usize {
        self.axes.iter().map(|a| a.1.len()).product()
    }
}

/// The frames' product layout over `axes` (the batch's product axes:
/// `scene`, `time`, each sweep key, `draw`), values in order of first
/// appearance, or `None` where the frames are not exactly every
/// combination once (e.g. scenes on different dates, so the local times
/// differ), or there are no axes.
pub fn product_layout(axes: &[String], frames: &[FrameJob]) -> Option<Product> {
    if axes.is_empty() || frames.is_empty() {
        return None;
    }
    let label = |f: &FrameJob, a: &str| -> Option<String> {
        if a == "draw" {
            f.draw.map(|d| d.to_string())
        } else {
            f.labels.get(a).cloned()
        }
    };
    let mut values: Vec<Vec<String>> = vec![Vec::new(); axes.len()];
    let mut positions = Vec::with_capacity(frames.len());
    for f in frames {
        let mut pos = Vec::with_capacity(axes.len());
        for (a, vals) in axes.iter().zip(values.iter_mut()) {
            let l = label(f, a)?;
            let i = match vals.iter().position(|v| *v == l) {
                Some(i) => i,
                None => {
                    vals.push(l);
                    vals.len() - 1
                }
            };
            pos.push(i);
        }
        positions.push(pos);
    }
    let p = Product {
        axes: axes.iter().cloned().zip(values).collect(),
        positions,
    };
    if p.size() != frames.len() {
        return None;
    }
    let mut seen = vec![false; p.size()];
    for pos in &p.positions {
        let o = p.offset(pos);
        if std::mem::replace(&mut seen[o], true) {
            return None;
        }
    }
    Some(p)
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
        materials: match v.get("materials") {
            None => Vec::new(),
            Some(m) => serde_json::from_value(m.clone())
                .with_context(|| format!("{}: materials: not a material table", p.display()))?,
        },
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
    let mut sheet_medians_k: Vec<f32> = Vec::new();
    let layout = product_layout(&batch.info.axes, &batch.frames);
    let mut materials_by_scene = std::collections::BTreeMap::new();
    for (f, m) in batch.frames.iter().zip(&metas) {
        let sid = f.labels.get("scene").cloned().unwrap_or_default();
        materials_by_scene
            .entry(sid)
            .or_insert_with(|| m.materials.clone());
    }
    let shared_materials: Option<Vec<MaterialEntry>> = metas
        .iter()
        .all(|m| m.materials == first.materials)
        .then(|| first.materials.clone());
    let (width, height) = {
        let tp = tmp.path();
        let mut file = nc(netcdf::create(tp), "create", tp)?;
        // The first frame is read once: its size shapes the stack, and the
        // loop below takes its planes.
        let (w0, h0, chans0) =
            crate::output::exr::read_exr(&dir.join(&batch.frames[0].outputs.exr))
                .map_err(anyhow::Error::msg)?;
        let mut first_chans = Some(chans0);
        // The frame dimensions: the product's axes, or `frame`.
        let frame_dims: Vec<String> = match &layout {
            Some(p) => p.axes.iter().map(|a| a.0.clone()).collect(),
            None => vec!["frame".into()],
        };
        match &layout {
            Some(p) => {
                for (a, vals) in &p.axes {
                    nc(file.add_dimension(a, vals.len()), a, tp)?;
                }
            }
            None => {
                nc(file.add_dimension("frame", n), "frame", tp)?;
            }
        }
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
        let fdims: Vec<&str> = frame_dims.iter().map(String::as_str).collect();
        // Per-frame values laid out over the frame dimensions.
        let cell = |k: usize| match &layout {
            Some(p) => p.offset(&p.positions[k]),
            None => k,
        };
        let cells = layout.as_ref().map_or(n, Product::size);
        let spread = |vals: &[f64]| -> Vec<f64> {
            let mut out = vec![f64::NAN; cells];
            for (k, v) in vals.iter().enumerate() {
                out[cell(k)] = *v;
            }
            out
        };
        let index_of = |c: usize| -> Vec<usize> {
            let mut idx = vec![0; fdims.len()];
            if let Some(p) = &layout {
                let mut r = c;
                for (i, (_, v)) in p.axes.iter().enumerate().rev() {
                    idx[i] = r % v.len();
                    r /= v.len();
                }
            } else {
                idx[0] = c;
            }
            idx
        };
        {
            let mut v = nc(file.add_variable::<i32>("frame", &fdims), "frame", tp)?;
            nc(
                v.put_attribute("long_name", "frame index in the manifest"),
                "frame",
                tp,
            )?;
            let idx: Vec<i32> = spread(&(0..n).map(|k| k as f64).collect::<Vec<_>>())
                .iter()
                .map(|&f| f as i32)
                .collect();
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
        // The product's axis coordinates.
        if let Some(p) = &layout {
            for (a, vals) in &p.axes {
                let nums: Option<Vec<f64>> = vals.iter().map(|s| s.parse::<f64>().ok()).collect();
                if a == "time" {
                    let secs: Vec<f64> = vals
                        .iter()
                        .map(|l| {
                            chrono::NaiveDateTime::parse_from_str(l, super::plan::LOCAL_FORMAT)
                                .map(|t| t.and_utc().timestamp() as f64)
                                .map_err(|e| anyhow::anyhow!("time label {l:?}: {e}"))
                        })
                        .collect::<anyhow::Result<_>>()?;
                    let mut v = nc(file.add_variable::<f64>(a, &[a]), a, tp)?;
                    nc(v.put_attribute("standard_name", "time"), a, tp)?;
                    nc(
                        v.put_attribute(
                            "long_name",
                            "local image time at the site (the scene's time zone)",
                        ),
                        a,
                        tp,
                    )?;
                    nc(
                        v.put_attribute("units", "seconds since 1970-01-01 00:00:00"),
                        a,
                        tp,
                    )?;
                    nc(v.put_attribute("calendar", "standard"), a, tp)?;
                    nc(v.put_values(&secs, ..), a, tp)?;
                } else if a == "draw" {
                    let mut v = nc(file.add_variable::<i32>(a, &[a]), a, tp)?;
                    nc(v.put_attribute("long_name", "random draw number"), a, tp)?;
                    let d: Vec<i32> = nums.unwrap_or_default().iter().map(|&f| f as i32).collect();
                    nc(v.put_values(&d, ..), a, tp)?;
                } else if let (Some(nums), false) = (nums, a == "scene") {
                    let mut v = nc(file.add_variable::<f64>(a, &[a]), a, tp)?;
                    nc(
                        v.put_attribute("long_name", format!("scene key {a}")),
                        a,
                        tp,
                    )?;
                    nc(v.put_values(&nums, ..), a, tp)?;
                } else {
                    let mut v = nc(file.add_string_variable(a, &[a]), a, tp)?;
                    for (k, s) in vals.iter().enumerate() {
                        nc(v.put_string(s, [k]), a, tp)?;
                    }
                }
            }
        }
        {
            let tname = if layout.is_some() {
                "image_time"
            } else {
                "time"
            };
            let mut v = nc(file.add_variable::<f64>(tname, &fdims), tname, tp)?;
            if layout.is_none() {
                nc(v.put_attribute("standard_name", "time"), tname, tp)?;
            }
            nc(v.put_attribute("long_name", "image time (UTC)"), tname, tp)?;
            nc(
                v.put_attribute("units", "seconds since 1970-01-01 00:00:00"),
                tname,
                tp,
            )?;
            nc(v.put_attribute("calendar", "standard"), tname, tp)?;
            let t: Vec<f64> = metas
                .iter()
                .map(|m| {
                    m.image_time_utc.timestamp() as f64
                        + m.image_time_utc.timestamp_subsec_nanos() as f64 * 1e-9
                })
                .collect();
            nc(v.put_values(&spread(&t), ..), tname, tp)?;
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
            let mut v = nc(file.add_variable::<f64>(name, &fdims), name, tp)?;
            nc(v.put_attribute("units", unit), name, tp)?;
            nc(v.put_attribute("long_name", long_name(name)), name, tp)?;
            nc(v.put_values(&spread(&vals), ..), name, tp)?;
        }
        // Text values per frame: id, local time, and each dimension that is
        // not an axis (numbers as float64 when every value is one).
        let mut per_frame: Vec<String> = vec![
            if layout.is_some() {
                "image_time"
            } else {
                "time"
            }
            .to_string(),
            "sun_zenith".into(),
            "sun_azimuth".into(),
        ];
        let mut frame_text: Vec<(String, Vec<String>)> = vec![
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
            if d == "time" || frame_dims.contains(d) {
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
                    let mut v = nc(file.add_variable::<f64>(d, &fdims), d, tp)?;
                    nc(
                        v.put_attribute("long_name", format!("scene key {d}")),
                        d,
                        tp,
                    )?;
                    nc(v.put_values(&spread(&nums), ..), d, tp)?;
                    per_frame.push(d.clone());
                }
                _ => frame_text.push((d.clone(), vals)),
            }
        }
        for (name, vals) in &frame_text {
            let mut v = nc(file.add_string_variable(name, &fdims), name, tp)?;
            for (k, s) in vals.iter().enumerate() {
                let idx = index_of(cell(k));
                nc(v.put_string(s, idx.as_slice()), name, tp)?;
            }
            per_frame.push(name.clone());
        }
        // CF: the per-frame variables are auxiliary coordinates of every
        // plane.
        let coordinates = per_frame.join(" ");
        let mut plane_dims = fdims.clone();
        plane_dims.extend(["y", "x"]);
        let mut chunk = vec![1usize; fdims.len()];
        chunk.extend([h0 as usize, w0 as usize]);
        for (name, unit) in &stack_planes {
            let mut v = nc(file.add_variable::<f32>(name, &plane_dims), name, tp)?;
            // One chunk per frame, deflated (level 1 with byte shuffle:
            // lossless, deterministic).
            nc(v.set_chunking(&chunk), name, tp)?;
            nc(v.set_compression(1, true), name, tp)?;
            nc(
                v.put_attribute("coordinates", coordinates.as_str()),
                name,
                tp,
            )?;
            nc(v.put_attribute("units", unit.as_str()), name, tp)?;
            nc(v.put_attribute("long_name", long_name(name)), name, tp)?;
            let flags = match name.as_str() {
                "case" => Some((
                    CASE_FLAGS.iter().map(|f| f.0).collect::<Vec<f32>>(),
                    CASE_FLAGS.map(|f| f.1).join(" "),
                )),
                "material" => shared_materials.as_deref().map(material_flags),
                _ => None,
            };
            if let Some((values, meanings)) = flags {
                nc(v.put_attribute("flag_values", values), name, tp)?;
                nc(v.put_attribute("flag_meanings", meanings), name, tp)?;
            }
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
                let mut ext: Vec<std::ops::Range<usize>> =
                    index_of(cell(k)).into_iter().map(|i| i..i + 1).collect();
                ext.extend([0..h as usize, 0..w as usize]);
                nc(v.put_values(data, ext), name, tp)?;
            }
            let sr = get("sensor_radiance")?;
            if sheet_pick.binary_search(&k).is_ok() {
                sheet_data.push((w, h, sr.clone()));
                sheet_medians_k.push(median_of(get("apparent_temperature")?));
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
    let opts = batch.info.quicklook();
    let band_um = batch
        .frames
        .get(sheet_pick.first().copied().unwrap_or(0))
        .map_or((0.0, 0.0), |f| band_of(&dir.join(&f.outputs.json)));
    let min_span = sheet_min_span(&sheet_medians_k, band_um, opts);
    let sheet = contact_sheet(&views, min_span);
    let stretch = format!(
        "linear, 2-98 percentile of the sheet's frames together widened to at least {} K of \
         apparent temperature ({min_span} W m-2 sr-1 um-1): {} .. {} W m-2 sr-1 um-1; colour map \
         {}, colour bar below the frames",
        opts.min_span_k,
        sheet.stretch.lo,
        sheet.stretch.hi,
        opts.colormap.name()
    );
    let sheet_path = out.join("contact_sheet.png");
    write_contact_sheet(
        &mut set,
        &sheet_path,
        &sheet,
        min_span,
        opts,
        "sensor_radiance [W m-2 sr-1 um-1]",
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
        stack_dimensions: match &layout {
            Some(p) => p.axes.iter().map(|a| a.0.clone()).collect(),
            None => vec!["frame".into()],
        },
        materials: shared_materials.clone(),
        materials_by_scene,
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
