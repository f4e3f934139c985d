//! Scene description: the scene file (TOML), material libraries, mesh
//! geometry ([`mesh`]), and the loaded triangle soup the tracer builds from, in the
//! tracer's local frame ([`frame`]: world coordinates in f64, shifted to
//! an origin at the camera target before they become f32). Reference:
//! docs/scene-format.md.
//!
//! ```no_run
//! let s = irsig::scene::load(std::path::Path::new("scenes/airfield/scene.toml"))?;
//! println!("{} triangles, {} materials", s.triangles.len(), s.materials.len());
//! # Ok::<(), irsig::scene::SceneError>(())
//! ```

pub mod camera;
pub mod error;
pub mod frame;
mod geometry;
pub mod georef;
pub mod lookup;
pub mod material;
pub mod mesh;
mod paths;
pub mod placement;
pub mod spec;
pub mod summary;
pub mod terrain;
pub mod tomlsrc;
mod validate;

use std::path::{Path, PathBuf};

use serde::Serialize;

pub use crate::radiometry::SpectralResponse;
pub use camera::{Camera, camera_geometry};
pub use error::{Location, SceneError};
pub use frame::LocalFrame;
pub use material::{
    BackBoundary, Emissivity, EmissivitySpec, EmissivityTable, Material, OpticsSpec,
};
pub use spec::*;

use crate::files::csv_numbers as parse_csv_numbers;
use tomlsrc::{Seg, TomlSource};
use validate::validate;

pub use geometry::ObjectInfo;
use geometry::bounds;
use material::SceneMaterials;
use paths::resolve;

/// A square convolution kernel (odd size), weights normalised to sum 1.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PsfKernel {
    /// Rows and columns (odd).
    pub size: usize,
    /// Row-major weights.
    pub weights: Vec<f64>,
}

/// A scene ready to render: options, materials and one triangle soup (in
/// the tracer's local frame) with per-triangle material, object and facet.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoadedScene {
    /// The scene file.
    pub path: PathBuf,
    /// The parsed options.
    pub scene: Scene,
    /// All materials of the libraries (index = material id).
    pub materials: Vec<Material>,
    /// Vertices in the tracer's local frame, metres: world ENU coordinates
    /// minus [`LocalFrame::origin_m`] (computed in f64, then rounded).
    pub positions: Vec<[f32; 3]>,
    /// The local frame: its origin in world coordinates and the precision
    /// of the f32 positions.
    pub frame: LocalFrame,
    /// Triangles (indices into `positions`), counter-clockwise as in the mesh file.
    pub triangles: Vec<[u32; 3]>,
    /// Material id of each triangle.
    pub tri_material: Vec<u32>,
    /// Object id (index into `objects`) of each triangle.
    pub tri_object: Vec<u32>,
    /// Facet id of each triangle: the index of its mesh face within its
    /// object (the triangles of a polygon keep one facet id).
    pub tri_facet: Vec<u32>,
    /// Every object (instances and terrains): name, file, triangles, bounds.
    pub objects: Vec<ObjectInfo>,
    /// The sensor camera in world coordinates (as the scene gives it).
    pub camera: Camera,
    /// The same camera in the local frame: what the tracer's rays use.
    pub local_camera: Camera,
    /// The sensor's relative spectral response.
    pub response: SpectralResponse,
    /// The PSF kernel when `psf = { kernel_file = ... }`.
    pub psf_kernel: Option<PsfKernel>,
    /// Zero-area triangles skipped over the whole scene.
    pub degenerate_skipped: usize,
    /// The `key = value` overrides applied to the file's text (`--set`).
    pub overrides: Vec<(String, String)>,
    /// Notes on the inputs that do not stop the load (e.g. a mesh's
    /// objects with no faces); the CLI prints them.
    pub warnings: Vec<String>,
    /// The weather file's record, read once and kept (the load's station,
    /// the warnings, the atmosphere choice and every frame share it;
    /// [`LoadedScene::weather_history`]).
    #[serde(skip)]
    pub weather_record: crate::weather::WeatherRecord,
}

impl LoadedScene {
    /// Resolves a path named in the scene file (relative to its folder).
    pub fn resolve(&self, p: &Path) -> PathBuf {
        resolve(&self.path, p)
    }
    /// Bounds of all triangles (min, max) in world coordinates, metres.
    pub fn bounds_m(&self) -> ([f64; 3], [f64; 3]) {
        let (lo, hi) = bounds(
            self.triangles
                .iter()
                .flatten()
                .map(|&i| self.positions[i as usize]),
        );
        (
            self.frame.to_world(lo.map(f64::from)),
            self.frame.to_world(hi.map(f64::from)),
        )
    }
    /// Index of a material by name.
    pub fn material_index(&self, name: &str) -> Option<usize> {
        self.materials.iter().position(|m| m.name == name)
    }
}

fn key(s: &str) -> Seg {
    Seg::Key(s.to_string())
}

/// Parses a scene file's text into [`Scene`] and validates its values
/// (ranges, pose); does not read any other file.
pub fn parse_scene(path: &Path, text: &str) -> Result<Scene, SceneError> {
    let src = TomlSource::from_text(path, text.to_string());
    let scene: Scene = src.parse()?;
    validate(&src, &scene)?;
    Ok(scene)
}

/// Loads a scene file, its material libraries and its mesh files.
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    load_source(path, TomlSource::read(path)?)
}

/// Loads a scene file with `key = value` overrides applied to its text
/// first (`key` a dotted TOML path such as `sensor.band` or
/// `weather.constant.wind_m_s`; `value` a TOML value such as `"lwir"` or
/// `4.47` — a bare word that is not valid TOML is taken as a string).
/// Errors name the override.
pub fn load_with_overrides(
    path: &Path,
    overrides: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    if overrides.is_empty() {
        return load(path);
    }
    let text = SceneError::read_text(path)?;
    let edited = apply_overrides(path, &text, overrides)?;
    let src = TomlSource::from_edited(path, text, edited, overrides);
    let mut scene = load_source(path, src)?;
    scene.overrides = overrides.to_vec();
    Ok(scene)
}

/// Loads a scene file with the keys `unset` removed from its text
/// ([`remove_keys`], `--unset`) and then the `overrides` applied
/// ([`load_with_overrides`], `--set`); errors name the file's own line or
/// the override.
pub fn load_with_edits(
    path: &Path,
    unset: &[String],
    overrides: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    if unset.is_empty() {
        return load_with_overrides(path, overrides);
    }
    let text = std::fs::read_to_string(path).map_err(|e| SceneError::Io {
        path: path.to_path_buf(),
        error: e,
    })?;
    let edited = apply_overrides(path, &remove_keys(path, &text, unset)?, overrides)?;
    let mut scene = load_edited(path, edited, overrides)?;
    scene.overrides = overrides.to_vec();
    Ok(scene)
}

/// Applies `key = value` overrides to scene text (see [`load_with_overrides`]).
pub fn apply_overrides(
    path: &Path,
    text: &str,
    overrides: &[(String, String)],
) -> Result<String, SceneError> {
    let bad = |msg: String| SceneError::Invalid {
        loc: error::Location::file(path),
        msg,
    };
    let mut doc: toml_edit::DocumentMut = text
        .parse()
        .map_err(|e| bad(format!("cannot apply overrides: {e}")))?;
    for (k, v) in overrides {
        let value: toml_edit::Value = v
            .parse()
            .unwrap_or_else(|_| toml_edit::Value::from(v.as_str()));
        let path =
            tomlsrc::override_path(doc.as_item(), k).map_err(|e| bad(format!("override {e}")))?;
        tomlsrc::set_at(doc.as_item_mut(), &path, value)
            .map_err(|e| bad(format!("override `{k}`: {e}")))?;
    }
    Ok(doc.to_string())
}

/// Removes dotted keys (a value, or a whole table such as
/// `sensor.pose.altitude`) from scene text, e.g. before overriding into
/// another pose table. A key that is not in the text is an error.
pub fn remove_keys(path: &Path, text: &str, keys: &[String]) -> Result<String, SceneError> {
    let bad = |msg: String| SceneError::Invalid {
        loc: error::Location::file(path),
        msg,
    };
    let mut doc: toml_edit::DocumentMut = text
        .parse()
        .map_err(|e| bad(format!("cannot remove keys: {e}")))?;
    for k in keys {
        let path =
            tomlsrc::override_path(doc.as_item(), k).map_err(|e| bad(format!("unset {e}")))?;
        tomlsrc::remove_at(doc.as_item_mut(), &path)
            .map_err(|e| bad(format!("unset `{k}`: {e}")))?;
    }
    Ok(doc.to_string())
}

/// Loads a scene from its text (e.g. edited by [`apply_overrides`]);
/// `path` names the file in errors and anchors relative paths.
pub fn load_text(path: &Path, text: String) -> Result<LoadedScene, SceneError> {
    load_source(path, TomlSource::from_text(path, text))
}

/// Loads a scene from `edited`, the text of the file `path` after
/// [`remove_keys`] and [`apply_overrides`] with `overrides`: errors are
/// reported at the item's line in the file as it is on disk, or as the
/// `--set key=value` override that set the item (line numbers of the
/// edited text would point at the wrong line, or past the file's end). If
/// the file cannot be read again, errors are located in `edited` itself.
pub fn load_edited(
    path: &Path,
    edited: String,
    overrides: &[(String, String)],
) -> Result<LoadedScene, SceneError> {
    let src = match crate::files::read_text(path, crate::bounds::sizes::MAX_TEXT_FILE_BYTES) {
        Ok(original) => TomlSource::from_edited(path, original, edited, overrides),
        Err(_) => TomlSource::from_text(path, edited),
    };
    load_source(path, src)
}

fn load_source(path: &Path, src: TomlSource) -> Result<LoadedScene, SceneError> {
    let mut scene: Scene = src.parse()?;
    let weather_record = crate::weather::WeatherRecord::default();
    site_from_weather(&src, &mut scene, &weather_record)?;
    validate(&src, &scene)?;
    let camera = camera_geometry(&scene.sensor)
        .map_err(|m| src.invalid(&[key("sensor"), key("pose")], m))?;
    let origin = LocalFrame::origin_for_target(scene.sensor.pose.target_m());
    let local_camera = camera::camera_geometry_at(&scene.sensor, origin)
        .map_err(|m| src.invalid(&[key("sensor"), key("pose")], m))?;

    let lib = SceneMaterials::load(&src, &scene.materials, &scene.files.allow)?;
    let (response, psf_kernel) = load_files(&src, &scene)?;
    let placed = geometry::load_geometry(&src, path, &scene, &lib, origin)?;
    let g = placed.geometry;
    Ok(LoadedScene {
        path: path.to_path_buf(),
        scene,
        materials: lib.materials,
        positions: g.positions,
        frame: LocalFrame::new(origin, placed.extent_m),
        triangles: g.triangles,
        tri_material: g.tri_material,
        tri_object: g.tri_object,
        tri_facet: g.tri_facet,
        objects: placed.objects,
        camera,
        local_camera,
        response,
        psf_kernel,
        degenerate_skipped: placed.degenerate_skipped,
        overrides: Vec::new(),
        warnings: placed.warnings,
        weather_record,
    })
}

/// The scene's data files: the weather file and atmosphere table checked
/// to be there (read later), the sensor's response (a boxcar for the
/// named bands) and PSF kernel read.
fn load_files(
    src: &TomlSource,
    scene: &Scene,
) -> Result<(SpectralResponse, Option<PsfKernel>), SceneError> {
    // Referenced files: inside the path policy, existing, regular; each
    // refusal reported at its scene-file key.
    let must_exist = |p: &Path, at: &[Seg], what: &str| {
        paths::referenced_file(src, &scene.files.allow, p, at, what)
    };
    if let spec::WeatherSpec::File { path: w, .. } = &scene.weather {
        must_exist(
            w,
            &[key("weather"), key("file"), key("path")],
            "weather file",
        )?;
    }
    if let spec::AtmosphereModel::TableFile(t) = &scene.atmosphere.model {
        must_exist(
            t,
            &[key("atmosphere"), key("model"), key("table_file")],
            "atmosphere table",
        )?;
    }
    let response = match &scene.sensor.band {
        Band::Lwir => boxcar(8.0, 14.0),
        Band::Mwir => boxcar(3.0, 5.0),
        Band::RangeUm([lo, hi]) => boxcar(*lo, *hi),
        Band::ResponseFile(f) => {
            let file = must_exist(
                f,
                &[key("sensor"), key("band"), key("response_file")],
                "response file",
            )?;
            read_response(&file)?
        }
    };
    // The band's label: a lower-case identifier and its limits, e.g.
    // `lwir 8-14 um`, `range 8.1-9.2 um`, `response_file r.csv 7.6-12.1 um`.
    let (lo_um, hi_um) = response.support_um();
    let response = SpectralResponse {
        label: match &scene.sensor.band {
            Band::Lwir => format!("lwir {lo_um}-{hi_um} um"),
            Band::Mwir => format!("mwir {lo_um}-{hi_um} um"),
            Band::RangeUm(_) => format!("range {lo_um}-{hi_um} um"),
            Band::ResponseFile(f) => {
                format!("response_file {} {lo_um:.3}-{hi_um:.3} um", f.display())
            }
        },
        ..response
    };
    let psf_kernel = match &scene.sensor.psf {
        Psf::KernelFile(f) => {
            let file = must_exist(
                f,
                &[key("sensor"), key("psf"), key("kernel_file")],
                "PSF kernel file",
            )?;
            Some(read_kernel(&file)?)
        }
        _ => None,
    };
    Ok((response, psf_kernel))
}

fn boxcar(lo: f64, hi: f64) -> SpectralResponse {
    SpectralResponse {
        wavelength_um: vec![lo, hi],
        response: vec![1.0, 1.0],
        label: String::new(),
    }
}

/// Reads a response CSV (`sensor.band = { response_file }`) with the one
/// reader, [`SpectralResponse::from_csv_str`] (its format and messages).
pub fn read_response(file: &Path) -> Result<SpectralResponse, SceneError> {
    let text = SceneError::read_text(file)?;
    parse_response(file, &text)
}

/// As [`read_response`], from the file's text (`file` names it in errors):
/// the reader's message at `file:line`.
pub fn parse_response(file: &Path, text: &str) -> Result<SpectralResponse, SceneError> {
    SpectralResponse::from_csv_str(text, &file.display().to_string())
        .map_err(|e| SceneError::from_data(file, e))
}

/// Reads a PSF kernel CSV: `#` comments; n rows of n weights, n odd.
pub fn read_kernel(file: &Path) -> Result<PsfKernel, SceneError> {
    let text = SceneError::read_text(file)?;
    parse_kernel(file, &text)
}

/// As [`read_kernel`], from the file's text (`file` names it in errors).
pub fn parse_kernel(file: &Path, text: &str) -> Result<PsfKernel, SceneError> {
    let err = |line: usize, msg: String| SceneError::Data {
        loc: Location::line(file, line),
        msg,
    };
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let row = parse_csv_numbers(line)
            .map_err(|(c, f)| err(i + 1, format!("column {c}: `{f}` is not a finite number")))?;
        if let Some(r0) = rows.first()
            && row.len() != r0.len()
        {
            return Err(err(
                i + 1,
                format!(
                    "expected {} weights as on the first row, found {}",
                    r0.len(),
                    row.len()
                ),
            ));
        }
        for w in &row {
            crate::bounds::data::KERNEL_WEIGHT
                .check(*w)
                .map_err(|m| err(i + 1, m))?;
        }
        rows.push(row);
        crate::bounds::data::KERNEL_SIZE
            .check(rows.len().max(rows[0].len()) as f64)
            .map_err(|m| err(i + 1, m))?;
    }
    let n = rows.len();
    if n == 0 || n.is_multiple_of(2) || rows[0].len() != n {
        return Err(err(
            0,
            format!(
                "expected a square kernel with an odd size, found {n} rows of {} weights",
                rows.first().map_or(0, Vec::len)
            ),
        ));
    }
    let sum: f64 = rows.iter().flatten().sum();
    if sum.is_nan() || sum <= 0.0 {
        return Err(err(
            0,
            "the kernel weights must sum to a positive number".into(),
        ));
    }
    Ok(PsfKernel {
        size: n,
        weights: rows.into_iter().flatten().map(|w| w / sum).collect(),
    })
}

/// Fills a site latitude/longitude left out of the scene with the weather
/// file's station (TMY2/TMY3/EPW/PSM3/PVGIS headers); an error when the
/// weather gives none.
fn site_from_weather(
    src: &TomlSource,
    scene: &mut Scene,
    record: &crate::weather::WeatherRecord,
) -> Result<(), SceneError> {
    let site = &mut scene.site.location;
    if !(site.latitude_deg.is_nan() || site.longitude_deg.is_nan()) {
        return Ok(());
    }
    let at = [key("site")];
    let station = match &scene.weather {
        spec::WeatherSpec::File {
            path: w,
            typical_year,
            ..
        } => {
            let file = paths::referenced_file(
                src,
                &scene.files.allow,
                w,
                &[key("weather"), key("file"), key("path")],
                "weather file",
            )?;
            let opts = crate::weather::station_options(*typical_year);
            record
                .parsed(&file, &opts)
                .map(|f| f.station.clone())
                .map_err(|e| {
                    src.invalid(
                        &at,
                        format!("site.latitude_deg/longitude_deg left out, and {e}"),
                    )
                })?
        }
        spec::WeatherSpec::Constant(_) => None,
    };
    let Some(st) = station else {
        return Err(src.invalid(
            &at,
            "site.latitude_deg and site.longitude_deg are required: the weather gives no station \
             coordinates (only TMY2/TMY3/EPW/PSM3/PVGIS files do)"
                .into(),
        ));
    };
    if site.latitude_deg.is_nan() {
        site.latitude_deg = st.lat_deg;
    }
    if site.longitude_deg.is_nan() {
        site.longitude_deg = st.lon_deg;
    }
    Ok(())
}
