//! The scene's geometry: every mesh (OBJ, glTF and the terrains, one
//! [`Mesh`] type) placed into one triangle soup in the tracer's local
//! frame, with per-triangle material, object and facet ids. Each part is
//! its own loader: the terrains meshed first (objects may stand on them),
//! then each `[[object]]`'s face materials, its instances stood on the
//! terrain and added, then the terrains added. Zero-area triangles are
//! left out here, once ([`crate::trace::has_area`]).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::scene::error::SceneError;
use crate::scene::frame;
use crate::scene::material::SceneMaterials;
use crate::scene::mesh::{self, Mesh};
use crate::scene::paths::{referenced_file, resolve};
use crate::scene::placement;
use crate::scene::spec::{ObjectSpec, Scene};
use crate::scene::terrain;
use crate::scene::tomlsrc::{Seg, TomlSource};

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
    /// Number of its triangles.
    pub triangle_count: u32,
    /// Faces (polygons) of the object.
    pub face_count: u32,
    /// Zero-area triangles skipped.
    pub degenerate_skipped: u32,
    /// Axis-aligned bounds' minimum, world coordinates, m.
    pub bounds_min_m: [f64; 3],
    /// Axis-aligned bounds' maximum, world coordinates, m.
    pub bounds_max_m: [f64; 3],
}

/// The placed geometry of a scene, its objects and the notes of its mesh
/// files.
#[derive(Default)]
pub(crate) struct Placed {
    pub geometry: Geometry,
    pub objects: Vec<ObjectInfo>,
    pub warnings: Vec<String>,
    /// Zero-area triangles left out over the whole scene.
    pub degenerate_skipped: usize,
    /// The largest absolute local coordinate of a vertex in use, m.
    pub extent_m: f64,
}

/// A key path segment.
fn key(k: &str) -> Seg {
    Seg::Key(k.to_string())
}

/// Meshes the terrains, places every object's instances (standing on the
/// terrains where asked) and then the terrains, in the local frame of
/// `origin` (world coordinates); `path` is the scene file.
pub(crate) fn load_geometry(
    src: &TomlSource,
    path: &Path,
    scene: &Scene,
    lib: &SceneMaterials,
    origin: [f64; 3],
) -> Result<Placed, SceneError> {
    let terrains = mesh_terrains(src, scene, lib)?;
    let mut ground: Option<placement::Ground> = None;
    let mut cache: HashMap<PathBuf, Mesh> = HashMap::new();
    let mut out = Placed::default();
    for (oi, o) in scene.objects.iter().enumerate() {
        let file = referenced_file(
            src,
            &scene.files.allow,
            &o.file,
            &[key("object"), Seg::Index(oi), key("file")],
            "mesh file",
        )?;
        if !cache.contains_key(&file) {
            let m = mesh::load(&file)?;
            out.warnings.extend(m.warnings.iter().cloned());
            cache.insert(file.clone(), m);
        }
        let mesh = &cache[&file];
        let face_mat = face_materials(src, oi, o, mesh, lib)?;
        let base_name = o.name.clone().unwrap_or_else(|| {
            file.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| format!("object{}", oi + 1))
        });
        let transforms = stand(src, oi, o, mesh, &base_name, &terrains, &mut ground, origin)?;
        add_instances(
            src,
            oi,
            &file,
            mesh,
            &transforms,
            &face_mat,
            &base_name,
            origin,
            &mut out,
        )?;
    }
    add_terrains(src, path, scene, &terrains, lib, origin, &mut out)?;
    out.degenerate_skipped = (out.objects.iter())
        .map(|o| o.degenerate_skipped as usize)
        .sum();
    let g = &out.geometry;
    out.extent_m = (g.triangles.iter().flatten())
        .map(|&i| g.positions[i as usize])
        .fold(0.0f64, |m, p| {
            p.iter().fold(m, |m, c| m.max(c.abs() as f64))
        });
    Ok(out)
}

/// Meshes every `[[terrain]]` (world coordinates).
fn mesh_terrains(
    src: &TomlSource,
    scene: &Scene,
    lib: &SceneMaterials,
) -> Result<Vec<Mesh>, SceneError> {
    (scene.terrain.iter().enumerate())
        .map(|(ti, t)| {
            terrain::load(
                src,
                ti,
                t,
                &scene.site.location,
                &scene.files.allow,
                &|name, at| lib.id(src, at, name),
            )
        })
        .collect()
}

/// The material id of each face of `mesh` for `[[object]]` `oi` (`o`):
/// the mesh's material names mapped by the object's `materials` table,
/// else the same-named library material, else its `*` entry; a face with
/// no material takes the object's `material`, else `*`.
fn face_materials(
    src: &TomlSource,
    oi: usize,
    o: &ObjectSpec,
    mesh: &Mesh,
    lib: &SceneMaterials,
) -> Result<Vec<u32>, SceneError> {
    let at = [key("object"), Seg::Index(oi)];
    // Map the mesh's material names to material ids: the object's
    // `materials` map, else the same-named library material, else `*`.
    let mut map = HashMap::new();
    for (from, to) in &o.materials {
        let at = [key("object"), Seg::Index(oi), key("materials"), key(from)];
        map.insert(from.as_str(), lib.id(src, &at, to)?);
    }
    let ids: Vec<Option<u32>> = mesh
        .material_names
        .iter()
        .map(|(name, _)| {
            let name = name.as_str();
            (map.get(name).or(lib.by_name.get(name)).or(map.get("*"))).copied()
        })
        .collect();
    let used: Vec<bool> = (0..ids.len())
        .map(|k| mesh.faces.iter().any(|f| f.material == Some(k as u32)))
        .collect();
    let unmapped: Vec<usize> = (0..ids.len())
        .filter(|&k| ids[k].is_none() && used[k])
        .collect();
    if !unmapped.is_empty() {
        let library: Vec<&str> = lib.materials.iter().map(|m| m.name.as_str()).collect();
        return Err(mesh.unmapped_error(&unmapped, &library, &lib.files, &src.loc_of(&at)));
    }
    let default_id = match &o.material {
        Some(n) => Some(lib.id(src, &[key("object"), Seg::Index(oi), key("material")], n)?),
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
    Ok(face_mat)
}

/// The local transforms of the instances of `[[object]]` `oi`, those with
/// `z = "terrain"` stood on the terrains (`ground`, binned on first use).
#[allow(clippy::too_many_arguments)]
fn stand<'t>(
    src: &TomlSource,
    oi: usize,
    o: &ObjectSpec,
    mesh: &Mesh,
    base_name: &str,
    terrains: &'t [Mesh],
    ground: &mut Option<placement::Ground<'t>>,
    origin: [f64; 3],
) -> Result<Vec<glam::DAffine3>, SceneError> {
    let mut transforms = o.local_transforms(origin, mesh.default_up);
    let n_inst = transforms.len();
    let stands = placement::stands(src, oi, o)?;
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
        let g = ground.get_or_insert_with(|| placement::Ground::new(terrains, origin));
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
    Ok(transforms)
}

/// Adds the instances (`transforms`) of `[[object]]` `oi` to `out`.
#[allow(clippy::too_many_arguments)]
fn add_instances(
    src: &TomlSource,
    oi: usize,
    file: &Path,
    mesh: &Mesh,
    transforms: &[glam::DAffine3],
    face_mat: &[u32],
    base_name: &str,
    origin: [f64; 3],
    out: &mut Placed,
) -> Result<(), SceneError> {
    let at = [key("object"), Seg::Index(oi)];
    let n_inst = transforms.len();
    for (k, xf) in transforms.iter().enumerate() {
        let object_id = out.objects.len() as u32;
        let first = out.geometry.triangles.len() as u32;
        let skipped = (out.geometry)
            .add(mesh, xf, origin, face_mat, object_id)
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
        let count = out.geometry.triangles.len() as u32 - first;
        let (lo, hi) = out.geometry.world_bounds(first, origin);
        out.objects.push(ObjectInfo {
            name: if n_inst > 1 {
                format!("{base_name}#{}", k + 1)
            } else {
                base_name.to_string()
            },
            file: file.to_path_buf(),
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
    Ok(())
}

/// Adds the terrain meshes to `out`, after the objects.
fn add_terrains(
    src: &TomlSource,
    path: &Path,
    scene: &Scene,
    terrains: &[Mesh],
    lib: &SceneMaterials,
    origin: [f64; 3],
    out: &mut Placed,
) -> Result<(), SceneError> {
    for (ti, (t, mesh)) in scene.terrain.iter().zip(terrains).enumerate() {
        let first = out.geometry.triangles.len() as u32;
        let object_id = out.objects.len() as u32;
        let face_mat: Vec<u32> = (mesh.faces.iter())
            .map(|f| {
                f.material.map_or(0, |k| {
                    lib.by_name[mesh.material_names[k as usize].0.as_str()]
                })
            })
            .collect();
        let skipped = out.geometry.add_terrain(mesh, origin, &face_mat, object_id).map_err(|far_m| {
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
        let (lo, hi) = out.geometry.world_bounds(first, origin);
        let file = resolve(path, &t.file);
        out.objects.push(ObjectInfo {
            name: t.name.clone().unwrap_or_else(|| {
                file.file_stem()
                    .map_or("terrain".into(), |s| s.to_string_lossy().into_owned())
            }),
            file,
            spec_index: ti,
            instance: 0,
            first_triangle: first,
            triangle_count: out.geometry.triangles.len() as u32 - first,
            face_count: mesh.faces.iter().filter(|f| f.material.is_some()).count() as u32,
            degenerate_skipped: skipped,
            bounds_min_m: lo,
            bounds_max_m: hi,
        });
    }
    Ok(())
}

/// Bounds (min, max) of points; infinite for none.
pub(crate) fn bounds(points: impl Iterator<Item = [f32; 3]>) -> ([f32; 3], [f32; 3]) {
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

/// The triangle soup in the local frame, single precision.
#[derive(Default)]
pub(crate) struct Geometry {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub tri_material: Vec<u32>,
    pub tri_object: Vec<u32>,
    pub tri_facet: Vec<u32>,
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
    /// `origin` (`face_mat`: the material id of each face); returns the
    /// zero-area triangles skipped, or `Err(distance)` when a vertex lies
    /// beyond [`frame::MAX_EXTENT_M`] from the origin.
    fn add_terrain(
        &mut self,
        mesh: &mesh::Mesh,
        origin: [f64; 3],
        face_mat: &[u32],
        object: u32,
    ) -> Result<u32, f64> {
        let local: Vec<glam::DVec3> = mesh
            .positions
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
        Ok(self.append(mesh, &local, face_mat, object))
    }

    /// Appends the triangles of `mesh` with its vertices placed at `local`
    /// (the local frame, rounded here to single precision), each with the
    /// material of its face (`face_mat`) and its face as facet, leaving out
    /// the zero-area ones ([`crate::trace::has_area`], as the tracer sees
    /// them: the one place a scene's triangles are filtered); returns how
    /// many were left out.
    fn append(
        &mut self,
        mesh: &mesh::Mesh,
        local: &[glam::DVec3],
        face_mat: &[u32],
        object: u32,
    ) -> u32 {
        let local: Vec<glam::Vec3> = local.iter().map(|l| l.as_vec3()).collect();
        let base = self.positions.len() as u32;
        let mut skipped = 0;
        for (t, &face) in mesh.triangles.iter().zip(&mesh.tri_face) {
            if !crate::trace::has_area(t.map(|i| local[i as usize])) {
                skipped += 1;
                continue;
            }
            self.triangles.push(t.map(|i| base + i));
            self.tri_material.push(face_mat[face as usize]);
            self.tri_object.push(object);
            self.tri_facet.push(face);
        }
        self.positions.extend(local.iter().map(|l| l.to_array()));
        skipped
    }
}

/// World coordinates beyond this (metres) are refused (projected
/// coordinate systems stay within ±2.1e7 m; the pose is bounded alike).
const MAX_COORD_M: f64 = crate::bounds::scene_keys::COORD;

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
        Ok(self.append(mesh, &local, face_mat, object))
    }
}
