//! A rendered frame's files: the EXR with every plane, the PNG quicklook of
//! `sensor_radiance` (2-98 % stretch, stated in the PNG and the JSON), the
//! JSON summary and optionally an ENVI cube, all beside one another, as one
//! [`OutputSet`] whose marker is the JSON.

use std::path::Path;

use anyhow::bail;
use serde::Serialize;

use super::{OutputSet, envi::write_envi, exr::write_exr, quicklook::write_png};
use crate::render::{Frame, Rendered, Stats};

/// The JSON summary written beside the image.
#[derive(Serialize)]
pub struct Summary<'a> {
    pub scene: String,
    pub image_time_utc: String,
    pub sun_zenith_deg: f64,
    pub sun_azimuth_deg: f64,
    pub band: String,
    pub estimators: String,
    /// The atmosphere table, why, and how it followed the weather.
    pub atmosphere: &'a crate::render::atmosphere::AtmosphereReport,
    /// What the quicklook shows and its stretch.
    pub quicklook: String,
    /// The other files of this output set (names beside this JSON, which
    /// is written last: a JSON whose files all exist is a complete set).
    pub files: Vec<String>,
    /// (name, unit) of every plane, in EXR order.
    pub planes: Vec<(String, String)>,
    pub stats: &'a Stats,
}

/// (name, unit) of every plane of `frame`.
pub fn plane_list(frame: &Frame) -> Vec<(String, String)> {
    frame
        .planes
        .planes
        .iter()
        .map(|p| (p.name.clone(), p.unit.clone()))
        .collect()
}

/// Writes a frame's outputs as one [`OutputSet`]: the EXR at `exr` (which
/// must end in `.exr`; its folder is created), the PNG quicklook, with
/// `envi` an ENVI cube, and last the JSON summary (the set's marker) that
/// `summary_of(quicklook description, file names of the others)` makes.
pub fn write_frame(
    exr: &Path,
    frame: &Frame,
    summary_of: impl FnOnce(String, Vec<String>) -> anyhow::Result<String>,
    envi: bool,
) -> anyhow::Result<()> {
    if exr.extension().and_then(|e| e.to_str()) != Some("exr") {
        bail!("-o {}: the output must be an .exr path", exr.display());
    }
    let json_path = exr.with_extension("json");
    let mut set = OutputSet::new(&json_path)?;
    let p = &frame.planes;
    write_exr(&mut set, exr, p)?;
    let ql = p
        .get("sensor_radiance")
        .expect("render writes sensor_radiance");
    let s = write_png(
        &mut set,
        &exr.with_extension("png"),
        p.width,
        p.height,
        &ql.data,
        "sensor_radiance W m-2 sr-1 um-1",
    )?;
    let quicklook = format!(
        "sensor_radiance, linear 2-98 percentile stretch {} .. {} W m-2 sr-1 um-1",
        s.lo, s.hi
    );
    if envi {
        write_envi(
            &mut set,
            &exr.with_extension("img"),
            p,
            None,
            "irsig render planes",
        )?;
    }
    let files = set
        .files()
        .filter_map(|f| f.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    let json = summary_of(quicklook, files)?;
    set.stage(&json_path, |w| {
        std::io::Write::write_all(w, json.as_bytes()).map_err(|e| e.to_string())
    })?;
    set.commit()?;
    Ok(())
}

/// The JSON summary at `json` when its output set is complete: the file
/// exists and parses, and every file its `files` list names exists beside
/// it; `None` otherwise (no set, or an interrupted one).
pub fn read_complete(json: &Path) -> Option<serde_json::Value> {
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).ok()?).ok()?;
    let dir = json.parent()?;
    let all_there = v
        .get("files")?
        .as_array()?
        .iter()
        .all(|f| f.as_str().is_some_and(|n| dir.join(n).is_file()));
    all_there.then_some(v)
}

/// Writes a rendered image's files as `irsig render` does: the EXR at
/// `exr`, the PNG quicklook, the JSON [`Summary`] and with `envi` an ENVI
/// cube beside it. `frame_info` (a sequence frame's description) is added
/// to the summary as its `frame` key (the summary's keys are then sorted).
pub fn write_rendered(
    exr: &Path,
    r: &Rendered,
    envi: bool,
    frame_info: Option<serde_json::Value>,
) -> anyhow::Result<()> {
    write_frame(
        exr,
        &r.frame,
        |quicklook, files| {
            let summary = Summary {
                scene: r.scene.clone(),
                image_time_utc: r.image_time_utc.to_rfc3339(),
                sun_zenith_deg: r.sun_zenith_deg,
                sun_azimuth_deg: r.sun_azimuth_deg,
                band: r.band.clone(),
                estimators: r.estimators.clone(),
                atmosphere: &r.atmosphere,
                quicklook,
                files,
                planes: plane_list(&r.frame),
                stats: &r.frame.stats,
            };
            Ok(match frame_info {
                None => serde_json::to_string_pretty(&summary)?,
                Some(info) => {
                    let mut v = serde_json::to_value(summary)?;
                    v["frame"] = info;
                    serde_json::to_string_pretty(&v)?
                }
            })
        },
        envi,
    )
}
