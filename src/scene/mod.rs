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

use std::collections::HashMap;
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

/// Per-object facts after loading (one per instance of each `[[object]]`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObjectInfo {
    /// Object name; instances get `name#k` (k = 1, 2, ...).
    pub name: String,
    /// The mesh file (as resolved from the scene file's folder); for a
    /// terrain, the DEM file.
    pub file: PathBuf,
    /// Index of the `[[object]]` entry in the scene file (for a terrain,
    /// of its `[[terrain]]` entry; terrains follow the objects).
    pub spec_index: usize,
    /// Instance number within that entry (0 without `instance` tables).
    pub instance: usize,
    /// Its triangles are `first_triangle .. first_triangle + triangle_count`.
    pub first_triangle: u32,
    pub triangle_count: u32,
    /// Faces (polygons) of the object.
    pub face_count: u32,
    /// Zero-area triangles skipped.
    pub degenerate_skipped: u32,
    /// Axis-aligned bounds in world coordinates, metres.
    pub bounds_min_m: [f64; 3],
    pub bounds_max_m: [f64; 3],
}

/// A square convolution kernel (odd size), weights normalised to sum 1.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PsfKernel {
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

fn resolve(scene_file: &Path, p: &Path) -> PathBuf {
    scene_file.parent().unwrap_or(Path::new("")).join(p)
}

fn bounds(points: impl Iterator<Item = [f32; 3]>) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    (lo, hi)
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

    // Referenced files: inside the path policy, existing, regular; each
    // refusal reported at its scene-file key.
    let must_exist = |p: &Path, at: &[Seg], what: &str| {
        paths::referenced_file(&src, &scene.files.allow, p, at, what)
    };

    // Materials: later libraries override earlier ones of the same name.
    let mut materials: Vec<Material> = Vec::new();
    let mut libs = Vec::new();
    for (i, lib) in scene.materials.iter().enumerate() {
        let file = must_exist(lib, &[key("materials"), Seg::Index(i)], "material library")?;
        for m in material::load_library(&file)? {
            match materials.iter().position(|x| x.name == m.name) {
                Some(j) => materials[j] = m,
                None => materials.push(m),
            }
        }
        libs.push(file);
    }
    let by_name: HashMap<String, u32> = materials
        .iter()
        .enumerate()
        .map(|(i, m)| (m.name.clone(), i as u32))
        .collect();
    let undefined = |loc: Location, name: &str| SceneError::UndefinedMaterial {
        loc,
        name: name.to_string(),
        libraries: libs.clone().into(),
        suggestion: error::closest(name, materials.iter().map(|m| m.name.as_str())),
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

    // Geometry. Terrains are meshed first: objects may stand on them.
    let terrains: Vec<terrain::TerrainMesh> = (scene.terrain.iter().enumerate())
        .map(|(ti, t)| {
            terrain::load(
                &src,
                ti,
                t,
                &scene.site.location,
                &scene.files.allow,
                &|name, at| {
                    by_name
                        .get(name)
                        .copied()
                        .ok_or_else(|| undefined(src.loc_of(at), name))
                },
            )
        })
        .collect::<Result<_, _>>()?;
    let mut ground: Option<placement::Ground> = None;
    let mut cache: HashMap<PathBuf, mesh::Mesh> = HashMap::new();
    let mut warnings = Vec::new();
    let mut out = Geometry::default();
    let mut objects = Vec::new();
    for (oi, o) in scene.objects.iter().enumerate() {
        let at = [key("object"), Seg::Index(oi)];
        let file = must_exist(
            &o.file,
            &[key("object"), Seg::Index(oi), key("file")],
            "mesh file",
        )?;
        if !cache.contains_key(&file) {
            let m = mesh::load(&file)?;
            warnings.extend(m.warnings.iter().cloned());
            cache.insert(file.clone(), m);
        }
        let mesh = &cache[&file];
        // Map the mesh's material names to material ids: the object's
        // `materials` map, else the same-named library material, else `*`.
        let mut map = HashMap::new();
        for (from, to) in &o.materials {
            let at = [key("object"), Seg::Index(oi), key("materials"), key(from)];
            let id = by_name
                .get(to)
                .ok_or_else(|| undefined(src.loc_of(&at), to))?;
            map.insert(from.as_str(), *id);
        }
        let ids: Vec<Option<u32>> = mesh
            .material_names
            .iter()
            .map(|(name, _)| {
                let name = name.as_str();
                (map.get(name).or(by_name.get(name)).or(map.get("*"))).copied()
            })
            .collect();
        let used: Vec<bool> = (0..ids.len())
            .map(|k| mesh.faces.iter().any(|f| f.material == Some(k as u32)))
            .collect();
        let unmapped: Vec<usize> = (0..ids.len())
            .filter(|&k| ids[k].is_none() && used[k])
            .collect();
        if !unmapped.is_empty() {
            let library: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
            return Err(mesh.unmapped_error(&unmapped, &library, &libs, &src.loc_of(&at)));
        }
        let default_id = match &o.material {
            Some(n) => Some(*by_name.get(n).ok_or_else(|| {
                undefined(
                    src.loc_of(&[key("object"), Seg::Index(oi), key("material")]),
                    n,
                )
            })?),
            None => map.get("*").copied(),
        };
        let mut face_mat = Vec::with_capacity(mesh.faces.len());
        for f in &mesh.faces {
            let id = match f.material {
                Some(k) => ids[k as usize].expect("unmapped names refused above"),
                None => default_id.ok_or_else(|| {
                    mesh.error(
                        f.src,
                        format!(
                            "{}, and object {} ({}) sets no `material` (nor a `materials` entry \"*\")",
                            if mesh.parts.is_empty() {
                                "face has no material: no `usemtl` before it"
                            } else {
                                "the primitive has no `material`"
                            },
                            oi + 1,
                            src.loc_of(&at)
                        ),
                    )
                })?,
            };
            face_mat.push(id);
        }
        let base_name = o.name.clone().unwrap_or_else(|| {
            file.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| format!("object{}", oi + 1))
        });
        let mut transforms = o.local_transforms(origin, mesh.default_up);
        let n_inst = transforms.len();
        let stands = placement::stands(&src, oi, o)?;
        for (k, (xf, st)) in transforms.iter_mut().zip(&stands).enumerate() {
            let Some((st, z_at)) = st else { continue };
            let who = if n_inst > 1 {
                format!("object `{base_name}#{}`", k + 1)
            } else {
                format!("object `{base_name}`")
            };
            if terrains.is_empty() {
                return Err(src.invalid(
                    z_at,
                    format!(
                        "{who} stands on the terrain (`z = \"terrain\"`), but the scene has no \
                         `[[terrain]]`: add one, or give its height in `translate_m`"
                    ),
                ));
            }
            let g = ground.get_or_insert_with(|| placement::Ground::new(&terrains, origin));
            *xf = placement::stand(mesh, *xf, st, g).map_err(|e| {
                let ([x0, y0], [x1, y1]) = g.cover();
                src.invalid(
                    z_at,
                    format!(
                        "{who} stands on the terrain (`z = \"terrain\"`), but there is no \
                         terrain under {} at scene ({:.1}, {:.1}) m: the terrains cover x {:.1} \
                         to {:.1} m, y {:.1} to {:.1} m (less any holes); move it onto the \
                         terrain or widen the terrain's `extent_m`",
                        e.what,
                        e.at_m[0] + origin[0],
                        e.at_m[1] + origin[1],
                        x0 + origin[0],
                        x1 + origin[0],
                        y0 + origin[1],
                        y1 + origin[1],
                    ),
                )
            })?;
        }
        for (k, xf) in transforms.iter().enumerate() {
            let object_id = objects.len() as u32;
            let first = out.triangles.len() as u32;
            let skipped = out
                .add(mesh, xf, origin, &face_mat, object_id)
                .map_err(|(face_src, far)| {
                    let place = mesh.place(face_src);
                    src.invalid(
                        &at,
                        if far {
                            format!(
                                "the transform of object `{base_name}` places the vertex of {place} more \
                                 than {:.0} m from the tracer's origin at the camera target ({:.0}, {:.0}) m, \
                                 where single precision keeps no better than {:.2} cm; split the scene or \
                                 aim the camera nearer its centre",
                                frame::MAX_EXTENT_M,
                                origin[0],
                                origin[1],
                                frame::f32_error_m(frame::MAX_EXTENT_M) * 100.0
                            )
                        } else {
                            format!(
                                "the transform of object `{base_name}` maps the vertex of {place} to a \
                                 non-finite or out-of-range position (|x| must stay below {MAX_COORD_M:e} m)"
                            )
                        },
                    )
                })?;
            let count = out.triangles.len() as u32 - first;
            let (lo, hi) = out.world_bounds(first, origin);
            objects.push(ObjectInfo {
                name: if n_inst > 1 {
                    format!("{base_name}#{}", k + 1)
                } else {
                    base_name.clone()
                },
                file: file.clone(),
                spec_index: oi,
                instance: k,
                first_triangle: first,
                triangle_count: count,
                face_count: mesh.faces.len() as u32,
                degenerate_skipped: skipped,
                bounds_min_m: lo,
                bounds_max_m: hi,
            });
        }
    }
    for (ti, (t, mesh)) in scene.terrain.iter().zip(&terrains).enumerate() {
        let first = out.triangles.len() as u32;
        let object_id = objects.len() as u32;
        let skipped = out.add_terrain(mesh, origin, object_id).map_err(|far_m| {
            src.invalid(
                &[key("terrain"), Seg::Index(ti), key("extent_m")],
                format!(
                    "the terrain reaches {far_m:.0} m from the tracer's origin at the camera target \
                     ({:.0}, {:.0}) m, more than {:.0} m; use a smaller extent_m or aim the camera \
                     nearer its centre",
                    origin[0],
                    origin[1],
                    frame::MAX_EXTENT_M
                ),
            )
        })?;
        let (lo, hi) = out.world_bounds(first, origin);
        let file = resolve(path, &t.file);
        objects.push(ObjectInfo {
            name: t.name.clone().unwrap_or_else(|| {
                file.file_stem()
                    .map_or("terrain".into(), |s| s.to_string_lossy().into_owned())
            }),
            file,
            spec_index: ti,
            instance: 0,
            first_triangle: first,
            triangle_count: out.triangles.len() as u32 - first,
            face_count: mesh.cells - mesh.holes,
            degenerate_skipped: skipped,
            bounds_min_m: lo,
            bounds_max_m: hi,
        });
    }
    let degenerate_skipped = objects.iter().map(|o| o.degenerate_skipped as usize).sum();
    let extent_m = out
        .triangles
        .iter()
        .flatten()
        .map(|&i| out.positions[i as usize])
        .fold(0.0f64, |m, p| {
            p.iter().fold(m, |m, c| m.max(c.abs() as f64))
        });
    Ok(LoadedScene {
        path: path.to_path_buf(),
        scene,
        materials,
        positions: out.positions,
        frame: LocalFrame::new(origin, extent_m),
        triangles: out.triangles,
        tri_material: out.tri_material,
        tri_object: out.tri_object,
        tri_facet: out.tri_facet,
        objects,
        camera,
        local_camera,
        response,
        psf_kernel,
        degenerate_skipped,
        overrides: Vec::new(),
        warnings,
        weather_record,
    })
}

#[derive(Default)]
struct Geometry {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    tri_material: Vec<u32>,
    tri_object: Vec<u32>,
    tri_facet: Vec<u32>,
}

impl Geometry {
    /// Bounds (world coordinates, m) of the triangles from `first` on.
    fn world_bounds(&self, first: u32, origin: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let (lo, hi) = bounds(
            self.triangles[first as usize..]
                .iter()
                .flatten()
                .map(|&i| self.positions[i as usize]),
        );
        (
            std::array::from_fn(|i| lo[i] as f64 + origin[i]),
            std::array::from_fn(|i| hi[i] as f64 + origin[i]),
        )
    }

    /// Appends a terrain mesh (world coordinates) in the local frame of
    /// `origin`; returns the zero-area triangles skipped, or `Err(distance)`
    /// when a vertex lies beyond [`frame::MAX_EXTENT_M`] from the origin.
    fn add_terrain(
        &mut self,
        mesh: &terrain::TerrainMesh,
        origin: [f64; 3],
        object: u32,
    ) -> Result<u32, f64> {
        let local: Vec<glam::DVec3> = mesh
            .positions_m
            .iter()
            .map(|p| glam::DVec3::from(*p) - glam::DVec3::from(origin))
            .collect();
        if let Some(far) = local
            .iter()
            .map(|l| l.abs().max_element())
            .find(|&d| d > frame::MAX_EXTENT_M)
        {
            return Err(far);
        }
        let local: Vec<glam::Vec3> = local.iter().map(|l| l.as_vec3()).collect();
        let tris = (mesh.triangles.iter().zip(&mesh.tri_material))
            .zip(&mesh.tri_facet)
            .map(|((t, &m), &f)| (*t, m, f));
        Ok(self.append(&local, tris, object))
    }

    /// Appends the vertices `local` (the local frame, single precision) and
    /// the triangles (indices into `local`, material, facet) of one object,
    /// skipping zero-area ones (at single precision, as the tracer sees
    /// them); returns how many were skipped.
    fn append(
        &mut self,
        local: &[glam::Vec3],
        tris: impl Iterator<Item = ([u32; 3], u32, u32)>,
        object: u32,
    ) -> u32 {
        let base = self.positions.len() as u32;
        let mut skipped = 0;
        for (t, material, facet) in tris {
            let q = t.map(|i| local[i as usize].as_dvec3());
            let area2 = (q[1] - q[0]).cross(q[2] - q[0]).length();
            if area2.is_nan() || area2 <= 0.0 {
                skipped += 1;
                continue;
            }
            self.triangles.push(t.map(|i| base + i));
            self.tri_material.push(material);
            self.tri_object.push(object);
            self.tri_facet.push(facet);
        }
        self.positions.extend(local.iter().map(|l| l.to_array()));
        skipped
    }
}

/// World coordinates beyond this (metres) are refused (projected
/// coordinate systems stay within ±2.1e7 m; the pose is bounded alike).
const MAX_COORD_M: f64 = 1e8;

impl Geometry {
    /// Appends one instance placed by `xf` in the local frame of `origin`
    /// (world = local + origin); returns the number of zero-area triangles
    /// skipped, or `Err((face src, far))` of a face whose vertex leaves the
    /// world range (`far` false) or the frame's [`frame::MAX_EXTENT_M`]
    /// (`far` true).
    fn add(
        &mut self,
        mesh: &mesh::Mesh,
        xf: &glam::DAffine3,
        origin: [f64; 3],
        face_mat: &[u32],
        object: u32,
    ) -> Result<u32, (usize, bool)> {
        let origin = glam::DVec3::from(origin);
        let local: Vec<glam::DVec3> = mesh
            .positions
            .iter()
            .map(|p| xf.transform_point3(glam::DVec3::from(*p)))
            .collect();
        for f in &mesh.faces {
            for &v in &f.verts {
                let l = local[v as usize];
                if !l.is_finite() || (l + origin).abs().max_element() > MAX_COORD_M {
                    return Err((f.src, false));
                }
                if l.abs().max_element() > frame::MAX_EXTENT_M {
                    return Err((f.src, true));
                }
            }
        }
        let local: Vec<glam::Vec3> = local.iter().map(|l| l.as_vec3()).collect();
        let tris = (mesh.triangles.iter().zip(&mesh.tri_face))
            .map(|(t, &fi)| (*t, face_mat[fi as usize], fi));
        Ok(self.append(&local, tris, object))
    }
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
