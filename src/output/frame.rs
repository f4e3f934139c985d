//! A rendered frame's files, as one [`OutputSet`] whose marker is the JSON
//! summary (written last): the PNG quicklook of `sensor_radiance` (2-98 %
//! stretch, stated in the PNG and the JSON), and in the formats asked for
//!
//! * EXR: every plane (`x.exr`), channels `radiance.*`, `terms.*`,
//!   `truth.*`, integer planes as UINT, units/time/sun/band/CRS in the
//!   header;
//! * GeoTIFF: every plane as float32 bands (`x.tif`) and the geolocation in
//!   float64 (`x_geo.tif`: lat, lon, map x, map y), georeferenced; for a
//!   nadir view with a rotated transform also the planes resampled onto a
//!   north-up map grid at the GSD (`x_map.tif`);
//! * ENVI: the radiance cube (`x.img`: the radiances at the sensor band,
//!   with wavelength, fwhm, acquisition time, sun angles, map info), the
//!   truth cube in float64 (`x_truth.img`: material, facet, case, sun,
//!   range, angles, temperatures, ground x/y/z, lat/lon, map x/y, with
//!   units), the DN (`x_dn.img`) and the material classification
//!   (`x_class.img`: class names and colours); no data is -9999.
//!
//! docs/render.md documents every file and field.

use std::path::{Path, PathBuf};

use anyhow::bail;
use serde::Serialize;

use super::envi::{EnviSample, list, write_cube};
use super::exr::{Attr, ExrCompression, write_exr, write_exr_planes};
use super::geotiff::{
    Band, Placement, is_class_plane, north_up_grid, placement, resample_affine, write_geotiff,
};
use super::quicklook::{Colormap, QuicklookStyle, percentile_stretch, write_quicklook};
use super::{OutputError, OutputSet};
use crate::render::{Frame, Rendered, Stats};
use crate::scene::georef::{Geo, Geolocation, Georef, geolocate};

/// The formats of a render's output (the PNG and the JSON are always
/// written).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Formats {
    /// Write the EXR (`x.exr`).
    pub exr: bool,
    /// Write the GeoTIFFs (`x.tif`, `x_geo.tif`, `x_map.tif`).
    pub geotiff: bool,
    /// Write the ENVI cubes (`x.img`, `x_truth.img`, `x_dn.img`, `x_class.img`).
    pub envi: bool,
    /// The planes the EXR and the GeoTIFF hold (`None`: all; the ENVI
    /// cubes, the PNG and the geolocation are not affected).
    pub planes: Option<Vec<String>>,
    /// The EXR's compression (lossless); `None`: the scene's
    /// (`output.exr_compression`, default zips).
    pub exr_compression: Option<ExrCompression>,
    /// Whether a GeoTIFF's nadir view also gets the north-up map grid
    /// (`x_map.tif`).
    pub map_grid: MapGrid,
    /// How the PNG quicklook is drawn.
    pub quicklook: QuicklookOptions,
}

/// The PNG quicklook's colour map and smallest stretch span.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuicklookOptions {
    /// The colour map.
    pub colormap: Colormap,
    /// The stretch spans at least this many kelvin of apparent temperature
    /// about the scene's median (converted to radiance, see
    /// [`min_span_radiance`]); 0: the plain 2-98 % stretch.
    pub min_span_k: f64,
}

impl Default for QuicklookOptions {
    fn default() -> Self {
        QuicklookOptions {
            colormap: Colormap::Grey,
            min_span_k: 2.0,
        }
    }
}

/// The band-averaged radiance span (W m⁻² sr⁻¹ µm⁻¹) of `span_k` kelvin
/// centred on the median of the finite `apparent_temp_k` values:
/// B̄(T + span/2) − B̄(T − span/2), B̄(T) = ∫_lo^hi B_λ(λ, T) dλ / (hi − lo)
/// (Planck's law over the band's support, a flat response; for a
/// `response_file` band the slope differs by the response's weighting, a
/// display choice, not a measurement). 0 when there is no finite
/// temperature.
pub fn min_span_radiance(apparent_temp_k: &[f32], (lo_um, hi_um): (f64, f64), span_k: f64) -> f32 {
    let mut t: Vec<f32> = apparent_temp_k
        .iter()
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    let usable = span_k > 0.0 && hi_um > lo_um;
    if t.is_empty() || !usable {
        return 0.0;
    }
    t.sort_by(f32::total_cmp);
    let med = t[t.len() / 2] as f64;
    let b = |temp_k: f64| {
        crate::radiometry::planck::planck_band_integral_w_m2_sr(lo_um, hi_um, temp_k)
            / (hi_um - lo_um)
    };
    (b(med + 0.5 * span_k) - b((med - 0.5 * span_k).max(1.0))) as f32
}

/// Writes the PNG quicklook of the `sensor_radiance` plane of `p` at
/// `path` (see [`write_quicklook`]); returns the summary's description of
/// it.
fn write_sensor_quicklook(
    set: &mut OutputSet,
    path: &Path,
    p: &crate::render::planes::Planes,
    band_um: (f64, f64),
    opts: QuicklookOptions,
) -> anyhow::Result<String> {
    let ql = p
        .get("sensor_radiance")
        .expect("render writes sensor_radiance");
    let unit = "W m-2 sr-1 um-1";
    let min_span = p.get("apparent_temperature").map_or(0.0, |t| {
        min_span_radiance(&t.data, band_um, opts.min_span_k)
    });
    let style = QuicklookStyle {
        colormap: opts.colormap,
        min_span,
        caption: format!("sensor_radiance [{unit}]"),
    };
    let s = write_quicklook(set, path, (p.width, p.height), &ql.data, &style)?;
    Ok(format!(
        "sensor_radiance, linear 2-98 percentile stretch widened to at least {} K of apparent temperature ({min_span} {unit}): {} .. {} {unit}; colour map {}, colour bar below the image",
        opts.min_span_k,
        s.lo,
        s.hi,
        serde_json::to_value(opts.colormap)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default()
    ))
}

/// When the GeoTIFF output adds the planes resampled onto a north-up map
/// grid (`x_map.tif`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum MapGrid {
    /// For nadir views whose affine transform is rotated (a north-up one
    /// is a map grid already; an oblique view has no affine transform).
    #[default]
    Auto,
    /// Never.
    Off,
}

impl Formats {
    /// The formats of `-o path` (its extension: `.exr`, `.tif`/`.tiff`)
    /// plus those asked for with flags.
    pub fn of_path(path: &Path, exr: bool, geotiff: bool, envi: bool) -> anyhow::Result<Formats> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let mut f = Formats {
            exr,
            geotiff,
            envi,
            ..Default::default()
        };
        match ext.as_deref() {
            Some("exr") => f.exr = true,
            Some("tif" | "tiff") => f.geotiff = true,
            _ => bail!(
                "-o {}: the output must be an .exr or a .tif path",
                path.display()
            ),
        }
        Ok(f)
    }

    /// Keeps only `planes` (names from
    /// [`crate::render::planes::PLANE_NAMES`]) in the EXR and the GeoTIFF;
    /// an empty list keeps all.
    pub fn with_planes(mut self, planes: &[String]) -> anyhow::Result<Formats> {
        use crate::render::planes::PLANE_NAMES;
        if planes.is_empty() {
            return Ok(self);
        }
        for p in planes {
            if !PLANE_NAMES.contains(&p.as_str()) {
                bail!(
                    "--planes {p}: no such plane; the planes are {}",
                    PLANE_NAMES.join(", ")
                );
            }
        }
        self.planes = Some(planes.to_vec());
        Ok(self)
    }

    /// Whether the EXR and the GeoTIFF hold the plane `name`.
    pub fn keeps(&self, name: &str) -> bool {
        self.planes
            .as_ref()
            .is_none_or(|l| l.iter().any(|p| p == name))
    }
}

/// The planes of the radiance cube, radiances at the sensor's band (all in
/// W m⁻² sr⁻¹ µm⁻¹): the band radiance, the terms of eqs. 1-4 and the
/// sensor's radiance. Temperatures go to the truth cube, DN to its own.
pub fn radiance_cube_planes() -> impl Iterator<Item = &'static str> {
    ["band_radiance"]
        .into_iter()
        .chain(crate::render::planes::TERM_PLANES)
        .chain(["sensor_radiance"])
}

/// The value that stands for "no data" in the float ENVI cubes (ENVI's
/// `data ignore value` must be a number; NaN samples are written as it).
pub const ENVI_IGNORE: f64 = -9999.0;

/// The ENVI cubes' samples with NaN replaced by [`ENVI_IGNORE`].
fn envi_f32(d: &[f32]) -> Vec<f32> {
    d.iter()
        .map(|&v| if v.is_nan() { ENVI_IGNORE as f32 } else { v })
        .collect()
}

/// One entry of the material table (the one type: the frame's JSON summary
/// writes it, `batch::merge` reads it back).
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct MaterialEntry {
    /// The `material` plane's value (-1: no surface).
    pub index: i64,
    /// The material's name.
    pub name: String,
    /// The classification's class (0: no surface).
    pub class: u32,
}

/// What built this image and from what (recorded in every output).
#[derive(Serialize)]
pub struct Summary<'a> {
    /// The build (version, commit).
    pub irsig: crate::version::BuildInfo,
    /// The scene file.
    pub scene: String,
    /// The `--set` overrides applied, `key=value`.
    pub overrides: Vec<String>,
    /// RFC 3339, UTC (`Z`).
    pub image_time_utc: String,
    /// Sun zenith angle at the image time, degrees.
    pub sun_zenith_deg: f64,
    /// Sun azimuth, degrees clockwise from north.
    pub sun_azimuth_deg: f64,
    /// Sun elevation, degrees (90 − zenith).
    pub sun_elevation_deg: f64,
    /// Lower-case identifier and limits, e.g. `lwir 8-14 um`.
    pub band: String,
    /// The band's spectral support, µm.
    pub band_um: [f64; 2],
    /// How the planes were estimated (sampling, supersampling).
    pub estimators: String,
    /// The atmosphere table, why, and how it followed the weather.
    pub atmosphere: &'a crate::render::atmosphere::AtmosphereReport,
    /// The sensor's pose (as the scene states it) and camera.
    pub pose: &'a crate::scene::spec::SensorPose,
    /// The camera the rays came from.
    pub camera: &'a crate::scene::Camera,
    /// CRS, footprint, GSD, affine transform, ground origin.
    pub georef: &'a Georef,
    /// The material table (the `material` plane and the classification).
    pub materials: Vec<MaterialEntry>,
    /// What the quicklook shows and its stretch.
    pub quicklook: String,
    /// The other files of this output set (names beside this JSON, which
    /// is written last: a JSON whose files all exist is a complete set).
    pub files: Vec<String>,
    /// (name, unit) of every plane of the EXR/GeoTIFF (all, or those of
    /// `--planes`), in render order.
    pub planes: Vec<(String, String)>,
    /// Counters and timings of the render.
    pub stats: &'a Stats,
}

/// Writes a bare frame's outputs as one [`OutputSet`]: the EXR at `exr`
/// (with `compression`),
/// the PNG quicklook, with `envi` an ENVI cube of every plane, and last
/// the JSON that `summary_of(quicklook description, file names of the
/// others)` makes. (A render's full set, georeferenced, is
/// [`write_rendered`]'s; this is for frames without their description,
/// e.g. `irsig bench speed`'s output timing.)
pub fn write_frame(
    exr: &Path,
    frame: &Frame,
    summary_of: impl FnOnce(String, Vec<String>) -> anyhow::Result<String>,
    envi: bool,
    compression: ExrCompression,
) -> anyhow::Result<()> {
    let json_path = exr.with_extension("json");
    let mut set = OutputSet::new(&json_path)?;
    let p = &frame.planes;
    write_exr(&mut set, exr, p, &[], compression)?;
    let quicklook = write_sensor_quicklook(
        &mut set,
        &exr.with_extension("png"),
        p,
        (0.0, 0.0),
        QuicklookOptions {
            min_span_k: 0.0,
            ..Default::default()
        },
    )?;
    if envi {
        super::envi::write_envi(
            &mut set,
            &exr.with_extension("img"),
            p,
            None,
            "irsig planes",
        )?;
    }
    commit_with_json(set, &json_path, |files| summary_of(quicklook, files))
}

/// Stages the JSON marker `json_path`, made by `make(file names of the
/// set's other files)`, and commits the set.
fn commit_with_json(
    mut set: OutputSet,
    json_path: &Path,
    make: impl FnOnce(Vec<String>) -> anyhow::Result<String>,
) -> anyhow::Result<()> {
    let files = set
        .files()
        .filter_map(|f| f.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    let json = make(files)?;
    set.stage(json_path, |w| {
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

/// `base` with `suffix` added to its file stem and extension `ext`
/// (`out/x.exr`, `_geo`, `tif` → `out/x_geo.tif`).
fn sibling(base: &Path, suffix: &str, ext: &str) -> PathBuf {
    let stem = base
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    base.with_file_name(format!("{stem}{suffix}.{ext}"))
}

/// A distinct colour per class (golden-angle hues), class 0 black.
fn class_colour(class: u32) -> [u8; 3] {
    if class == 0 {
        return [0, 0, 0];
    }
    let h = (class as f64 * 137.507_764) % 360.0 / 60.0;
    let x = (1.0 - (h % 2.0 - 1.0).abs()) * 200.0 + 40.0;
    let (c, x) = (240.0, x);
    let (r, g, b) = match h as u32 {
        0 => (c, x, 40.0),
        1 => (x, c, 40.0),
        2 => (40.0, c, x),
        3 => (40.0, x, c),
        4 => (x, 40.0, c),
        _ => (c, 40.0, x),
    };
    [r as u8, g as u8, b as u8]
}

/// GDAL's `GEOLOCATION` metadata (RFC 4) for an image whose pixels' map
/// coordinates are bands 3 (`map_x`) and 4 (`map_y`) of the file `geo_name`
/// beside it, one value per pixel centre, in `g`'s CRS.
fn geolocation_metadata(g: &Georef, geo_name: &str) -> Vec<(String, String)> {
    [
        ("SRS", g.crs.wkt.as_str()),
        ("X_DATASET", geo_name),
        ("X_BAND", "3"),
        ("Y_DATASET", geo_name),
        ("Y_BAND", "4"),
        ("PIXEL_OFFSET", "0"),
        ("LINE_OFFSET", "0"),
        ("PIXEL_STEP", "1"),
        ("LINE_STEP", "1"),
        ("GEOREFERENCING_CONVENTION", "PIXEL_CENTER"),
    ]
    .iter()
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .collect()
}

/// ENVI `map info` (and `coordinate system string`) for an affine
/// transform, or `geo points` (pixel → lat/lon tie points, ENVI's 1-based
/// pixel coordinates) for an oblique view.
fn envi_georef_fields(g: &Georef, geoloc: &Geolocation, width: u32) -> Vec<(String, String)> {
    let mut f = Vec::new();
    match g.geotransform {
        Some(gt) => {
            // Rotation counter-clockwise, degrees, as GDAL reads it.
            let rot = gt[4].atan2(gt[1]).to_degrees();
            let (xs, ys) = (gt[1].hypot(gt[4]), gt[2].hypot(gt[5]));
            let proj = match g.crs.utm {
                Some((zone, north)) => format!(
                    "UTM, 1, 1, {:.4}, {:.4}, {xs:.9}, {ys:.9}, {zone}, {}, WGS-84",
                    gt[0],
                    gt[3],
                    if north { "North" } else { "South" }
                ),
                None => format!(
                    "Orthographic, 1, 1, {:.4}, {:.4}, {xs:.9}, {ys:.9}, WGS-84",
                    gt[0], gt[3]
                ),
            };
            f.push((
                "map info".into(),
                format!("{{{proj}, units=Meters, rotation={rot:.9}}}"),
            ));
            f.push((
                "coordinate system string".into(),
                format!("{{{}}}", g.crs.wkt),
            ));
        }
        None => {
            if let Placement::TiePoints(tp) =
                placement(g, width, &geoloc.lat_deg, &geoloc.lon_deg, 8)
            {
                // placement() gives (col, row, lat, lon) for these inputs.
                let v: Vec<String> = tp
                    .iter()
                    .flat_map(|p| {
                        [
                            format!("{:.4}", p[0] + 1.0),
                            format!("{:.4}", p[1] + 1.0),
                            format!("{:.9}", p[2]),
                            format!("{:.9}", p[3]),
                        ]
                    })
                    .collect();
                f.push(("geo points".into(), format!("{{{}}}", v.join(", "))));
            }
        }
    }
    f
}

/// Writes a rendered image's files as `irsig render` does, beside `path`
/// (whose extension is that of the main format): see the module docs.
/// `frame_info` (a sequence frame's description) is added to the summary
/// as its `frame` key (the summary's keys are then sorted). Each format
/// is written by its own function ([`write_exr_files`],
/// [`write_geotiff_files`], [`write_envi_files`]) into the one set.
pub fn write_rendered(
    path: &Path,
    r: &Rendered,
    formats: Formats,
    frame_info: Option<serde_json::Value>,
) -> anyhow::Result<()> {
    let json_path = path.with_extension("json");
    let mut set = OutputSet::new(&json_path)?;
    let c = Ctx::new(path, r, &formats)?;
    let quicklook = write_sensor_quicklook(
        &mut set,
        &path.with_extension("png"),
        c.p,
        r.band_um,
        formats.quicklook,
    )?;
    if formats.exr {
        write_exr_files(&mut set, &c)?;
    }
    if formats.geotiff {
        write_geotiff_files(&mut set, &c)?;
    }
    if formats.envi {
        write_envi_files(&mut set, &c)?;
    }
    let (g, time, sun_el, kept) = (c.g, c.time, c.sun_el, c.kept);
    let materials = c.materials;
    commit_with_json(set, &json_path, |files| {
        let summary = Summary {
            irsig: crate::version::build_info(),
            scene: r.scene.clone(),
            overrides: r
                .overrides
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect(),
            image_time_utc: time,
            sun_zenith_deg: r.sun_zenith_deg,
            sun_azimuth_deg: r.sun_azimuth_deg,
            sun_elevation_deg: sun_el,
            band: r.band.clone(),
            band_um: [r.band_um.0, r.band_um.1],
            estimators: r.estimators.clone(),
            atmosphere: &r.atmosphere,
            pose: &r.pose,
            camera: &r.camera,
            georef: g,
            materials,
            quicklook,
            files,
            planes: kept
                .iter()
                .map(|pl| (pl.name.clone(), pl.unit.clone()))
                .collect(),
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
    })
}

/// What every format of a rendered frame shares: the planes kept, the
/// time, sun and band, the metadata common to all files, and the
/// per-pixel geolocation (made on first use: GeoTIFF and ENVI carry it).
struct Ctx<'a> {
    path: &'a Path,
    r: &'a Rendered,
    formats: &'a Formats,
    p: &'a crate::render::planes::Planes,
    w: u32,
    h: u32,
    g: &'a Georef,
    time: String,
    sun_el: f64,
    materials: Vec<MaterialEntry>,
    kept: Vec<&'a crate::render::planes::Plane>,
    common_meta: Vec<(String, String)>,
    nan: Vec<f32>,
    geo: Geo,
    geoloc: std::cell::OnceCell<Geolocation>,
}

impl<'a> Ctx<'a> {
    fn new(path: &'a Path, r: &'a Rendered, formats: &'a Formats) -> anyhow::Result<Ctx<'a>> {
        let p = &r.frame.planes;
        let (w, h) = (p.width, p.height);
        let g = &r.georef;
        let time = r
            .image_time_utc
            .to_rfc3339_opts(chrono::SecondsFormat::Secs, true);
        let sun_el = 90.0 - r.sun_zenith_deg;
        let materials: Vec<MaterialEntry> = r
            .materials
            .iter()
            .enumerate()
            .map(|(i, n)| MaterialEntry {
                index: i as i64,
                name: n.clone(),
                class: i as u32 + 1,
            })
            .collect();
        let common_meta: Vec<(String, String)> = vec![
            ("irsig_version".into(), crate::version::LONG_VERSION.into()),
            ("scene".into(), r.scene.clone()),
            ("image_time_utc".into(), time.clone()),
            ("sun_azimuth_deg".into(), format!("{}", r.sun_azimuth_deg)),
            ("sun_elevation_deg".into(), format!("{sun_el}")),
            ("band".into(), r.band.clone()),
            (
                "ground_origin_m".into(),
                format!(
                    "{} {} {}",
                    g.ground_origin_m[0], g.ground_origin_m[1], g.ground_origin_m[2]
                ),
            ),
            ("crs".into(), g.crs.name.clone()),
            (
                "materials".into(),
                serde_json::to_string(&materials).unwrap_or_default(),
            ),
        ];
        let kept: Vec<&crate::render::planes::Plane> = p
            .planes
            .iter()
            .filter(|pl| formats.keeps(&pl.name))
            .collect();
        Ok(Ctx {
            path,
            r,
            formats,
            p,
            w,
            h,
            g,
            time,
            sun_el,
            materials,
            kept,
            common_meta,
            nan: vec![f32::NAN; (w * h) as usize],
            geo: Geo::for_georef(g)?,
            geoloc: std::cell::OnceCell::new(),
        })
    }

    /// A plane's values, if the frame has it.
    fn plane(&self, name: &str) -> Option<&'a [f32]> {
        self.p.get(name).map(|pl| pl.data.as_slice())
    }

    /// The ground point planes (scene frame, relative to the ground
    /// origin), NaN where absent.
    fn ground(&self) -> [&[f32]; 3] {
        ["ground_x", "ground_y", "ground_z"].map(|n| self.plane(n).unwrap_or(&self.nan))
    }

    /// Every pixel's latitude/longitude and map coordinates (four f64
    /// planes, a projection per pixel), made on first use.
    fn geoloc(&self) -> &Geolocation {
        self.geoloc.get_or_init(|| {
            let [gx, gy, gz] = self.ground();
            geolocate(&self.geo, self.g.ground_origin_m, gx, gy, gz)
        })
    }
}

/// EXR: every kept plane in `x.exr`, the metadata as header attributes.
fn write_exr_files(set: &mut OutputSet, c: &Ctx) -> anyhow::Result<()> {
    let (path, r, formats, g) = (c.path, c.r, c.formats, c.g);
    let (w, h, sun_el, kept) = (c.w, c.h, c.sun_el, &c.kept);
    let common_meta = &c.common_meta;
    let mut attrs: Vec<(String, Attr)> = common_meta
        .iter()
        .filter(|(k, _)| {
            !matches!(
                k.as_str(),
                "irsig_version" | "sun_azimuth_deg" | "sun_elevation_deg"
            )
        })
        .map(|(k, v)| (k.clone(), Attr::Text(v.clone())))
        .collect();
    attrs.extend([
        ("sun_zenith_deg".into(), Attr::F64(r.sun_zenith_deg)),
        ("sun_azimuth_deg".into(), Attr::F64(r.sun_azimuth_deg)),
        ("sun_elevation_deg".into(), Attr::F64(sun_el)),
        ("band_lo_um".into(), Attr::F64(r.band_um.0)),
        ("band_hi_um".into(), Attr::F64(r.band_um.1)),
        ("crs_wkt".into(), Attr::Text(g.crs.wkt.clone())),
        ("crs_proj".into(), Attr::Text(g.crs.proj.clone())),
    ]);
    if let Some(epsg) = g.crs.epsg {
        attrs.push(("crs_epsg".into(), Attr::Text(format!("EPSG:{epsg}"))));
    }
    if let Some(t) = g.geotransform {
        let t: Vec<String> = t.iter().map(|v| v.to_string()).collect();
        attrs.push(("geotransform".into(), Attr::Text(t.join(" "))));
    }
    write_exr_planes(
        set,
        &path.with_extension("exr"),
        (w, h),
        kept,
        &attrs,
        formats.exr_compression.unwrap_or(r.output.exr_compression),
    )?;
    Ok(())
}

/// GeoTIFF: the kept planes (`x.tif`), the geolocation (`x_geo.tif`) and,
/// for a rotated nadir view, the planes on a north-up map grid
/// (`x_map.tif`).
fn write_geotiff_files(set: &mut OutputSet, c: &Ctx) -> anyhow::Result<()> {
    let (path, formats, g, w) = (c.path, c.formats, c.g, c.w);
    let (h, kept, common_meta) = (c.h, &c.kept, &c.common_meta);
    let bands: Vec<Band<f32>> = kept
        .iter()
        .map(|pl| Band {
            name: &pl.name,
            unit: &pl.unit,
            data: &pl.data,
        })
        .collect();
    let place = placement(g, w, &c.geoloc().map_x_m, &c.geoloc().map_y_m, 10);
    // Without an affine transform GDAL's GEOLOCATION metadata points
    // to the per-pixel map coordinates in `x_geo.tif` (GDAL RFC 4
    // geolocation arrays; `gdalwarp -geoloc`, `gdaltransform -geoloc`).
    let geo_name = sibling(path, "_geo", "tif")
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let domains = if g.geotransform.is_none() {
        vec![("GEOLOCATION", geolocation_metadata(g, &geo_name))]
    } else {
        Vec::new()
    };
    write_geotiff(
        set,
        &path.with_extension("tif"),
        (w, h),
        &bands,
        Some(&g.crs),
        &place,
        common_meta,
        &domains,
    )?;
    let geo_bands = [
        Band {
            name: "lat",
            unit: "deg",
            data: c.geoloc().lat_deg.as_slice(),
        },
        Band {
            name: "lon",
            unit: "deg",
            data: c.geoloc().lon_deg.as_slice(),
        },
        Band {
            name: "map_x",
            unit: "m",
            data: c.geoloc().map_x_m.as_slice(),
        },
        Band {
            name: "map_y",
            unit: "m",
            data: c.geoloc().map_y_m.as_slice(),
        },
    ];
    write_geotiff(
        set,
        &sibling(path, "_geo", "tif"),
        (w, h),
        &geo_bands,
        Some(&g.crs),
        &place,
        common_meta,
        &[],
    )?;
    // A nadir view whose transform is rotated (UTM grid convergence, a
    // yawed camera) also gets the planes on a north-up map grid at its
    // GSD, which GIS tools turn into x/y coordinates.
    if let Some((gt, ogt, ow, oh)) = g
        .geotransform
        .filter(|_| formats.map_grid == MapGrid::Auto)
        .and_then(|gt| north_up_grid(gt, w, h).map(|(o, ow, oh)| (gt, o, ow, oh)))
    {
        let data: Vec<Vec<f32>> = kept
            .iter()
            .map(|pl| {
                resample_affine(
                    &pl.data,
                    (w, h),
                    gt,
                    ogt,
                    (ow, oh),
                    is_class_plane(&pl.name),
                )
            })
            .collect();
        let bands: Vec<Band<f32>> = kept
            .iter()
            .zip(&data)
            .map(|(pl, d)| Band {
                name: &pl.name,
                unit: &pl.unit,
                data: d,
            })
            .collect();
        let mut meta = common_meta.clone();
        meta.push((
            "resampling".into(),
            format!(
                "north-up map grid at the GSD {} m from the image grid {}: bilinear, nearest for material facet case dn; NaN off the image",
                ogt[1],
                gt.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(" ")
            ),
        ));
        write_geotiff(
            set,
            &sibling(path, "_map", "tif"),
            (ow, oh),
            &bands,
            Some(&g.crs),
            &Placement::Affine(ogt),
            &meta,
            &[],
        )?;
    }
    Ok(())
}

/// The DN cube (`x_dn.img`): one band `d` of uint16 counts or float32.
fn write_dn<T: EnviSample>(
    set: &mut OutputSet,
    path: &Path,
    size: (u32, u32),
    d: &[T],
    desc: &str,
    fields: &[(String, String)],
) -> Result<(), OutputError> {
    write_cube(
        set,
        path,
        size,
        &[("dn [counts]", d)],
        "ENVI Standard",
        desc,
        fields,
    )
}

/// ENVI: the radiance cube (`x.img`), the truth cube (`x_truth.img`), the
/// counts (`x_dn.img`) and the material classification (`x_class.img`).
fn write_envi_files(set: &mut OutputSet, c: &Ctx) -> anyhow::Result<()> {
    let (path, r, p, g) = (c.path, c.r, c.p, c.g);
    let (w, h, time, sun_el) = (c.w, c.h, &c.time, c.sun_el);
    let plane = |name: &str| c.plane(name);
    let nan = &c.nan;
    let [gx, gy, gz] = c.ground();
    let (centre, fwhm) = r.band_centre_fwhm_um;
    // ENVI's default display stretch: the quicklook's 2-98 % percentiles.
    let s = p
        .get("sensor_radiance")
        .map(|pl| percentile_stretch(&pl.data))
        .unwrap_or(super::quicklook::Stretch { lo: 0.0, hi: 1.0 });
    let geo_fields = envi_georef_fields(g, c.geoloc(), w);
    let mut common = vec![
        ("acquisition time".to_string(), time.clone()),
        ("sun azimuth".into(), format!("{:.6}", r.sun_azimuth_deg)),
        ("sun elevation".into(), format!("{sun_el:.6}")),
        ("sensor type".into(), format!("irsig {}", r.band)),
        ("data ignore value".into(), format!("{ENVI_IGNORE}")),
        ("irsig version".into(), crate::version::LONG_VERSION.into()),
    ];
    common.extend(geo_fields);
    // Radiance cube: the radiances at the sensor's band, each band
    // labelled with the response-weighted centre and the FWHM.
    let rad: Vec<_> = radiance_cube_planes().filter_map(|n| p.get(n)).collect();
    let names: Vec<String> = rad
        .iter()
        .map(|pl| format!("{} [{}]", pl.name, pl.unit))
        .collect();
    let rad_data: Vec<Vec<f32>> = rad.iter().map(|pl| envi_f32(&pl.data)).collect();
    let bands: Vec<(&str, &[f32])> = names
        .iter()
        .zip(&rad_data)
        .map(|(n, d)| (n.as_str(), d.as_slice()))
        .collect();
    let mut fields = vec![
        ("wavelength units".to_string(), "Micrometers".to_string()),
        (
            "wavelength".into(),
            list(rad.iter().map(|_| format!("{centre:.6}"))),
        ),
        (
            "fwhm".into(),
            list(rad.iter().map(|_| format!("{fwhm:.6}"))),
        ),
        ("data units".into(), "W m-2 sr-1 um-1".into()),
        (
            "default stretch".into(),
            format!("{:.6} {:.6} linear", s.lo, s.hi),
        ),
    ];
    fields.extend(common.iter().cloned());
    write_cube(
        set,
        &path.with_extension("img"),
        (w, h),
        &bands,
        "ENVI Standard",
        &format!("irsig radiance cube, {}, {time}", r.band),
        &fields,
    )?;
    // Truth cube, float64: exact indices and full-precision positions.
    let to64 = |name: &str| -> Vec<f64> {
        plane(name).map_or_else(
            || vec![ENVI_IGNORE; (w * h) as usize],
            |d| {
                d.iter()
                    .map(|&v| if v.is_nan() { ENVI_IGNORE } else { v as f64 })
                    .collect()
            },
        )
    };
    let abs = |d: &[f32], o: f64| -> Vec<f64> {
        d.iter()
            .map(|&v| {
                if v.is_nan() {
                    ENVI_IGNORE
                } else {
                    v as f64 + o
                }
            })
            .collect()
    };
    let fill = |d: &[f64]| -> Vec<f64> {
        d.iter()
            .map(|&v| if v.is_nan() { ENVI_IGNORE } else { v })
            .collect()
    };
    let o = g.ground_origin_m;
    let mut truth: Vec<(String, String, Vec<f64>)> = [
        "material",
        "facet",
        "case",
        "sun_now",
        "hours_sunlit",
        "range",
        "view_angle",
        "surface_temperature",
        "apparent_temperature",
    ]
    .iter()
    .filter_map(|n| p.get(n).map(|pl| (n.to_string(), pl.unit.clone(), to64(n))))
    .collect();
    let scene_m = "m scene frame".to_string();
    truth.push(("ground_x".into(), scene_m.clone(), abs(gx, o[0])));
    truth.push(("ground_y".into(), scene_m.clone(), abs(gy, o[1])));
    truth.push(("ground_z".into(), scene_m, abs(gz, o[2])));
    truth.push(("lat".into(), "deg".into(), fill(&c.geoloc().lat_deg)));
    truth.push(("lon".into(), "deg".into(), fill(&c.geoloc().lon_deg)));
    let map_m = format!("m {}", g.crs.name);
    truth.push(("map_x".into(), map_m.clone(), fill(&c.geoloc().map_x_m)));
    truth.push(("map_y".into(), map_m, fill(&c.geoloc().map_y_m)));
    let truth_names: Vec<String> = truth.iter().map(|(n, u, _)| format!("{n} [{u}]")).collect();
    let bands: Vec<(&str, &[f64])> = truth_names
        .iter()
        .zip(&truth)
        .map(|(n, t)| (n.as_str(), t.2.as_slice()))
        .collect();
    let mut fields = vec![(
        "band units".to_string(),
        list(truth.iter().map(|t| t.1.replace([',', '{', '}'], ";"))),
    )];
    fields.extend(common.iter().cloned());
    write_cube(
        set,
        &sibling(path, "_truth", "img"),
        (w, h),
        &bands,
        "ENVI Standard",
        &format!("irsig truth cube, {time}"),
        &fields,
    )?;
    // DN, alone: uint16 counts where every value is one, else float32.
    if let Some(dn) = p.get("dn") {
        let common_int: Vec<(String, String)> = common
            .iter()
            .filter(|(k, _)| k != "data ignore value")
            .cloned()
            .collect();
        let mut fields = vec![
            ("data units".to_string(), "counts".to_string()),
            ("wavelength units".into(), "Micrometers".into()),
            ("wavelength".into(), list([format!("{centre:.6}")])),
            ("fwhm".into(), list([format!("{fwhm:.6}")])),
        ];
        let dn_path = sibling(path, "_dn", "img");
        let desc = format!("irsig sensor counts, {}, {time}", r.band);
        let counts = dn
            .data
            .iter()
            .all(|&v| v.fract() == 0.0 && (0.0..=65535.0).contains(&v));
        if counts {
            fields.extend(common_int);
            let d: Vec<u16> = dn.data.iter().map(|&v| v as u16).collect();
            write_dn(set, &dn_path, (w, h), &d, &desc, &fields)?;
        } else {
            fields.extend(common.iter().cloned());
            write_dn(set, &dn_path, (w, h), &envi_f32(&dn.data), &desc, &fields)?;
        }
    }
    // Material classification: class = material index + 1, 0 = none.
    let class: Vec<u16> = plane("material")
        .unwrap_or(nan)
        .iter()
        .map(|&m| if m >= 0.0 { m as u16 + 1 } else { 0 })
        .collect();
    let mut names = vec!["no surface".to_string()];
    names.extend(r.materials.iter().map(|n| n.replace([',', '{', '}'], ";")));
    let lookup: Vec<u8> = (0..names.len() as u32).flat_map(class_colour).collect();
    let mut fields = vec![
        ("classes".to_string(), names.len().to_string()),
        ("class names".into(), list(&names)),
        ("class lookup".into(), list(&lookup)),
    ];
    // Class 0 is "no surface"; there are no missing values.
    fields.extend(
        common
            .iter()
            .filter(|(k, _)| k != "data ignore value")
            .cloned(),
    );
    write_cube(
        set,
        &sibling(path, "_class", "img"),
        (w, h),
        &[("material", class.as_slice())],
        "ENVI Classification",
        &format!("irsig material classification, {time}"),
        &fields,
    )?;
    Ok(())
}
