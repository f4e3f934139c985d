//! A rendered frame's files: the EXR with every plane, the PNG quicklook of
//! `sensor_radiance` (2-98 % stretch, stated in the PNG and the JSON), the
//! JSON summary and optionally an ENVI cube, all beside one another.

use std::path::Path;

use anyhow::{Context, bail};
use serde::Serialize;

use super::{envi::write_envi, exr::write_exr, quicklook::write_png};
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

/// Writes a frame's outputs: the EXR at `exr` (which must end in `.exr`;
/// its folder is created), the PNG quicklook, the JSON summary that
/// `summary_of` makes from the quicklook's description, and with `envi` an
/// ENVI cube, all beside it.
pub fn write_frame(
    exr: &Path,
    frame: &Frame,
    summary_of: impl FnOnce(String) -> anyhow::Result<String>,
    envi: bool,
) -> anyhow::Result<()> {
    if exr.extension().and_then(|e| e.to_str()) != Some("exr") {
        bail!("-o {}: the output must be an .exr path", exr.display());
    }
    if let Some(d) = exr.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    write_exr(exr, &frame.planes)?;
    let p = &frame.planes;
    let ql = p
        .get("sensor_radiance")
        .expect("render writes sensor_radiance");
    let s = write_png(
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
        write_envi(&exr.with_extension("img"), p, None, "irsig render planes")?;
    }
    let json = summary_of(quicklook)?;
    super::write_atomic(&exr.with_extension("json"), |w| {
        std::io::Write::write_all(w, json.as_bytes()).map_err(|e| e.to_string())
    })?;
    Ok(())
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
        |quicklook| {
            let summary = Summary {
                scene: r.scene.clone(),
                image_time_utc: r.image_time_utc.to_rfc3339(),
                sun_zenith_deg: r.sun_zenith_deg,
                sun_azimuth_deg: r.sun_azimuth_deg,
                band: r.band.clone(),
                estimators: r.estimators.clone(),
                atmosphere: &r.atmosphere,
                quicklook,
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
