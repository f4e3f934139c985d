//! Terrain from a digital elevation model: a `[[terrain]]` table names a
//! GeoTIFF DEM ([`raster`]), an extent of the scene frame and a mesh
//! spacing; the loader meshes the DEM there into a triangle mesh with one
//! material per cell (one library material, or a land-cover raster of
//! class ids and a class → material table): a [`Mesh`] like an OBJ
//! file's, which the scene places like an object.
//!
//! Placement. The scene frame is the site's east-north-up frame
//! ([`crate::scene::georef`]: EPSG 9836 topocentric coordinates about the
//! site at `site.elevation_m`). A mesh vertex at scene (x, y) is the DEM's
//! surface point above the geodetic position (φ, λ) of scene point
//! (x, y, 0): its height H is the DEM's bilinear interpolation between
//! pixel centres at (φ, λ) (mapped to the DEM's CRS by PROJ's formulas in
//! `proj4rs`), and the vertex is the scene point of (φ, λ, H). So every
//! vertex lies on the DEM surface, z ≈ H − `site.elevation_m` near the
//! site, and the Earth's curvature is kept (the ground falls d²/2R below
//! the tangent plane: 0.31 m at 2 km). The DEM's heights are taken in the
//! vertical datum of `site.elevation_m` (which the georeferencing takes as
//! the WGS 84 ellipsoidal height); the geoid undulation, constant to
//! centimetres over a few km, cancels in z.
//!
//! Mesh. The extent is split into nx × ny cells of at most `resolution_m`
//! (nx = ⌈width / resolution_m⌉), each cell two triangles (counter-clockwise
//! from above, normal up) sharing one facet id. Between vertices the mesh
//! is linear, so it departs from the DEM's bilinear surface by at most
//! about r²/8·|h''| (r the cell size, h'' the surface's second derivative).

pub mod raster;
pub mod spec;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use proj4rs::proj::Proj;
use rayon::prelude::*;

use crate::bounds::terrain as B;
use crate::scene::error::SceneError;
use crate::scene::georef::Geo;
use crate::scene::material::Check;
use crate::scene::spec::OutputCrs;
use crate::scene::tomlsrc::{Seg, TomlSource};
use crate::sun::Site;
use raster::{Raster, RasterCrs, Sample};
pub use spec::{Extent, LandCover, NoData, TerrainSpec};

use crate::scene::mesh::{Face, Mesh};

/// Maps geodetic coordinates into a raster's CRS.
struct CrsMap {
    longlat: Proj,
    utm: Option<Proj>,
}

impl CrsMap {
    fn new(crs: RasterCrs) -> CrsMap {
        let proj = |s: &str| Proj::from_proj_string(s).expect("a valid PROJ string");
        CrsMap {
            longlat: proj("+proj=longlat +datum=WGS84 +no_defs"),
            utm: match crs {
                RasterCrs::Geographic => None,
                RasterCrs::Utm { zone, north } => Some(proj(&format!(
                    "+proj=utm +zone={zone}{} +datum=WGS84 +units=m +no_defs",
                    if north { "" } else { " +south" }
                ))),
            },
        }
    }

    /// CRS coordinates (x, y) of latitude and longitude, degrees.
    fn forward(&self, lat_deg: f64, lon_deg: f64) -> Option<[f64; 2]> {
        match &self.utm {
            None => Some([lon_deg, lat_deg]),
            Some(utm) => {
                let mut q = (lon_deg.to_radians(), lat_deg.to_radians(), 0.0);
                proj4rs::transform::transform(&self.longlat, utm, &mut q).ok()?;
                Some([q.0, q.1])
            }
        }
    }

    /// Latitude and longitude (degrees) of CRS coordinates.
    fn inverse(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        match &self.utm {
            None => Some((y, x)),
            Some(utm) => {
                let mut q = (x, y, 0.0);
                proj4rs::transform::transform(utm, &self.longlat, &mut q).ok()?;
                Some((q.1.to_degrees(), q.0.to_degrees()))
            }
        }
    }
}

/// Why a scene point has no surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Miss {
    /// Outside the raster.
    Outside,
    /// A DEM pixel (col, row) the interpolation needs has no data.
    NoData([u32; 2]),
}

/// A DEM placed in a site's scene frame.
pub struct Surface<'a> {
    dem: &'a Raster,
    geo: Geo,
    map: CrsMap,
    /// The site's height (`site.elevation_m`), m.
    site_height_m: f64,
}

impl<'a> Surface<'a> {
    /// The DEM `dem` placed at `site`.
    pub fn new(dem: &'a Raster, site: &Site) -> anyhow::Result<Surface<'a>> {
        Ok(Surface {
            dem,
            geo: Geo::new(site, &OutputCrs::Enu)?,
            map: CrsMap::new(dem.crs),
            site_height_m: site.elevation_m,
        })
    }

    /// The CRS point of a raster with map `map` under scene point (x, y, 0).
    fn crs_point(geo: &Geo, map: &CrsMap, x: f64, y: f64) -> Option<[f64; 2]> {
        let (lat, lon, _) = geo.geodetic([x, y, 0.0])?;
        map.forward(lat, lon)
    }

    /// The DEM surface point above scene point (x, y, 0), scene metres
    /// (see the module notes).
    pub fn point(&self, x: f64, y: f64) -> Result<[f64; 3], Miss> {
        let (lat, lon, _) = self.geo.geodetic([x, y, 0.0]).ok_or(Miss::Outside)?;
        let [cx, cy] = self.map.forward(lat, lon).ok_or(Miss::Outside)?;
        match self.dem.bilinear(cx, cy) {
            Sample::Value(h) => self.geo.scene_point(lat, lon, h).ok_or(Miss::Outside),
            Sample::NoData(px) => Err(Miss::NoData(px)),
            Sample::Outside => Err(Miss::Outside),
        }
    }

    /// The bounding box of a raster's corners in the scene frame
    /// `[x_min, y_min, x_max, y_max]` (at the site's elevation).
    fn coverage(&self, r: &Raster) -> Option<[f64; 4]> {
        let map = CrsMap::new(r.crs);
        let mut b = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for [x, y] in r.corners() {
            let (lat, lon) = map.inverse(x, y)?;
            let p = self.geo.scene_point(lat, lon, self.site_height_m)?;
            b = [
                b[0].min(p[0]),
                b[1].min(p[1]),
                b[2].max(p[0]),
                b[3].max(p[1]),
            ];
        }
        Some(b)
    }
}

/// The grid of an extent: (nx, ny) cells of at most `resolution_m`.
pub fn grid_cells(extent: [f64; 4], resolution_m: f64) -> (usize, usize) {
    let n = |a: f64, b: f64| (((b - a) / resolution_m).ceil() as usize).max(1);
    (n(extent[0], extent[2]), n(extent[1], extent[3]))
}

/// Range checks of a `[[terrain]]` table (index `i`).
pub(crate) fn validate(c: &Check, i: usize, t: &TerrainSpec) -> Result<(), SceneError> {
    let at = |k: &str| {
        vec![
            Seg::Key("terrain".into()),
            Seg::Index(i),
            Seg::Key(k.into()),
        ]
    };
    c.bound(&at("resolution_m"), &B::RESOLUTION, t.resolution_m)?;
    match t.extent_m {
        Extent::Square(s) => c.bound(&at("extent_m"), &B::EXTENT_SIDE, s)?,
        Extent::Box(b) => {
            for (k, v) in b.iter().enumerate() {
                let mut p = at("extent_m");
                p.push(Seg::Index(k));
                c.bound(&p, &B::EXTENT, *v)?;
            }
            if !(b[0] < b[2] && b[1] < b[3]) {
                return Err(c.src.invalid(
                    &at("extent_m"),
                    format!(
                        "`extent_m` = {b:?}: expected [x_min, y_min, x_max, y_max] with \
                         x_min < x_max and y_min < y_max"
                    ),
                ));
            }
        }
    }
    let (nx, ny) = grid_cells(t.extent_m.bbox(), t.resolution_m);
    let vertices = (nx as f64 + 1.0) * (ny as f64 + 1.0);
    let max = crate::bounds::sizes::MAX_TERRAIN_VERTICES;
    if vertices > max as f64 {
        return Err(c.src.invalid(
            &at("resolution_m"),
            format!(
                "`resolution_m` = {} over `extent_m` gives {vertices:.0} vertices, more than \
                 the {max} a terrain may have: use a coarser resolution_m or a smaller extent",
                t.resolution_m
            ),
        ));
    }
    match (&t.material, &t.land_cover) {
        (Some(_), None) => {}
        (None, Some(lc)) => {
            for k in lc.classes.keys() {
                if k != "*" && k.trim().parse::<i64>().is_err() {
                    let mut p = at("land_cover");
                    p.extend([Seg::Key("classes".into()), Seg::Key(k.clone())]);
                    return Err(c.src.invalid(
                        &p,
                        format!(
                            "land-cover class `{k}`: expected an integer class id (e.g. \"41\") \
                             or \"*\" (every other class)"
                        ),
                    ));
                }
            }
        }
        _ => {
            return Err(c.src.invalid(
                &[Seg::Key("terrain".into()), Seg::Index(i)],
                "a terrain needs exactly one of `material` (one material for all of it) and \
                 `land_cover` (a class raster and a class → material table)"
                    .into(),
            ));
        }
    }
    Ok(())
}

/// A material's id by name, or the error naming it at a key.
pub(crate) type MaterialId<'a> = dyn Fn(&str, &[Seg]) -> Result<u32, SceneError> + 'a;

/// Reads, places and meshes `[[terrain]]` table `i` of the scene `src`
/// (its `site`); `material` gives a material's id or the error naming it
/// at a key.
pub(crate) fn load(
    src: &TomlSource,
    i: usize,
    t: &TerrainSpec,
    site: &Site,
    allow: &[PathBuf],
    material: &MaterialId,
) -> Result<Mesh, SceneError> {
    let at = |k: &[&str]| {
        let mut p = vec![Seg::Key("terrain".into()), Seg::Index(i)];
        p.extend(k.iter().map(|s| Seg::Key(s.to_string())));
        p
    };
    let must_exist = |p: &Path, key: &[&str], what: &str| {
        super::paths::referenced_file(src, allow, p, &at(key), what)
    };
    let dem_file = must_exist(&t.file, &["file"], "DEM file")?;
    let zone = |e| raster::with_site_zone(e, site.latitude_deg, site.longitude_deg);
    let dem = raster::read_raster(&dem_file).map_err(zone)?;
    let hb = crate::bounds::terrain::HEIGHT;
    if let Some(i) = dem
        .data
        .iter()
        .position(|&h| !h.is_nan() && !hb.contains(h.into()))
    {
        let w = dem.width.max(1) as usize;
        return Err(SceneError::Data {
            loc: crate::scene::error::Location::file(&dem_file),
            msg: format!(
                "DEM pixel (column {}, row {}) holds the height {} m (read as f32): expected {} \
                 or the no-data value",
                i % w,
                i / w,
                match dem.data[i] {
                    v if v.is_finite() && v.abs() >= 1e6 => format!("{v:e}"),
                    v => format!("{v}"),
                },
                hb.expected()
            ),
        });
    }
    let surface =
        Surface::new(&dem, site).map_err(|e| src.invalid(&at(&["file"]), e.to_string()))?;
    let extent = t.extent_m.bbox();
    let (nx, ny) = grid_cells(extent, t.resolution_m);
    let gx = |i: usize| extent[0] + (extent[2] - extent[0]) * i as f64 / nx as f64;
    let gy = |j: usize| extent[1] + (extent[3] - extent[1]) * j as f64 / ny as f64;
    let outside = |what: &str, file: &Path, r: &Raster, x: f64, y: f64, key: &[&str]| {
        let cover = surface
            .coverage(r)
            .map(|b| {
                format!(
                    "; it covers scene x {:.0} to {:.0} m, y {:.0} to {:.0} m",
                    b[0], b[2], b[1], b[3]
                )
            })
            .unwrap_or_default();
        src.invalid(
            &at(key),
            format!(
                "`extent_m` {extent:?} reaches outside the {what} {}: scene point ({x:.1}, \
                 {y:.1}) m is not in it{cover}",
                file.display()
            ),
        )
    };

    // Vertices, row by row (rows in parallel: each vertex on its own).
    let verts: Vec<Result<[f64; 3], Miss>> = (0..=ny)
        .into_par_iter()
        .flat_map_iter(|j| {
            let s = &surface;
            (0..=nx).map(move |i| s.point(gx(i), gy(j)))
        })
        .collect();
    let mut index = vec![u32::MAX; verts.len()];
    let mut positions_m = Vec::with_capacity(verts.len());
    for (k, v) in verts.iter().enumerate() {
        match *v {
            Ok(p) => {
                index[k] = positions_m.len() as u32;
                positions_m.push(p);
            }
            Err(Miss::Outside) => {
                let (x, y) = (gx(k % (nx + 1)), gy(k / (nx + 1)));
                return Err(outside("DEM", &dem_file, &dem, x, y, &["extent_m"]));
            }
            Err(Miss::NoData([c, r])) if t.nodata == NoData::Error => {
                let (x, y) = (gx(k % (nx + 1)), gy(k / (nx + 1)));
                return Err(src.invalid(
                    &at(&["extent_m"]),
                    format!(
                        "{}: DEM pixel (col {c}, row {r}) has no data, and the terrain needs it \
                         at scene point ({x:.1}, {y:.1}) m inside `extent_m`; set `nodata = \
                         \"hole\"` to leave holes there, fill the DEM first (e.g. \
                         `gdal_fillnodata.py`), or choose another extent",
                        dem_file.display()
                    ),
                ));
            }
            Err(Miss::NoData(_)) => {}
        }
    }

    // Cell materials (library ids), and the name of each id used.
    let names = std::cell::RefCell::new(BTreeMap::<u32, String>::new());
    let material = |name: &str, at: &[Seg]| {
        let id = material(name, at)?;
        names.borrow_mut().insert(id, name.to_string());
        Ok::<u32, SceneError>(id)
    };
    let cell_material: Vec<u32> = match (&t.material, &t.land_cover) {
        (Some(m), _) => vec![material(m, &at(&["material"]))?; nx * ny],
        (None, Some(lc)) => {
            let file = must_exist(&lc.file, &["land_cover", "file"], "land-cover file")?;
            let cover = raster::read_raster(&file).map_err(zone)?;
            let map = CrsMap::new(cover.crs);
            let geo = &surface.geo;
            let classes: Vec<Option<f32>> = (0..ny)
                .into_par_iter()
                .flat_map_iter(|j| {
                    let (map, cover) = (&map, &cover);
                    (0..nx).map(move |i| {
                        let (x, y) = ((gx(i) + gx(i + 1)) / 2.0, (gy(j) + gy(j + 1)) / 2.0);
                        let [cx, cy] = Surface::crs_point(geo, map, x, y)?;
                        cover.nearest(cx, cy)
                    })
                })
                .collect();
            let key = |k: &str| at(&["land_cover", "classes", k]);
            let mut ids: BTreeMap<i64, u32> = BTreeMap::new();
            let mut default = None;
            for (k, name) in &lc.classes {
                let id = material(name, &key(k))?;
                match k.trim().parse::<i64>() {
                    Ok(c) => {
                        ids.insert(c, id);
                    }
                    Err(_) => default = Some(id),
                }
            }
            let mut unmapped: BTreeSet<String> = BTreeSet::new();
            let mut out = Vec::with_capacity(classes.len());
            for (k, c) in classes.iter().enumerate() {
                let Some(c) = *c else {
                    let (i, j) = (k % nx, k / nx);
                    let (x, y) = ((gx(i) + gx(i + 1)) / 2.0, (gy(j) + gy(j + 1)) / 2.0);
                    return Err(outside(
                        "land-cover raster",
                        &file,
                        &cover,
                        x,
                        y,
                        &["land_cover", "file"],
                    ));
                };
                let id = if c.is_nan() {
                    default.ok_or_else(|| "no-data".to_string())
                } else if c.fract() != 0.0 {
                    return Err(src.invalid(
                        &at(&["land_cover", "file"]),
                        format!(
                            "{}: class {c} is not an integer: expected integer class ids",
                            file.display()
                        ),
                    ));
                } else {
                    ids.get(&(c as i64))
                        .copied()
                        .or(default)
                        .ok_or_else(|| format!("{}", c as i64))
                };
                match id {
                    Ok(id) => out.push(id),
                    Err(name) => {
                        unmapped.insert(name);
                        out.push(0);
                    }
                }
            }
            if !unmapped.is_empty() {
                let list: Vec<&str> = unmapped.iter().map(String::as_str).collect();
                return Err(src.invalid(
                    &at(&["land_cover", "classes"]),
                    format!(
                        "land-cover classes {} of {} (inside `extent_m`) have no material: map \
                         each in `classes` (e.g. \"{}\" = \"grass_irrigated\") or give a default \
                         \"*\" = \"...\"",
                        list.join(", "),
                        file.display(),
                        list[0]
                    ),
                ));
            }
            out
        }
        (None, None) => unreachable!("validate requires material or land_cover"),
    };

    // Cells: one face each (holes too, with no triangles, so that a face's
    // index is its cell), two triangles each, counter-clockwise seen from
    // above; the faces name their materials as a mesh file's do.
    let names = names.into_inner();
    let local: BTreeMap<u32, u32> = names
        .keys()
        .enumerate()
        .map(|(k, &id)| (id, k as u32))
        .collect();
    let mut m = Mesh {
        path: dem_file,
        positions: positions_m,
        material_names: names.into_values().map(|n| (n, 0)).collect(),
        ..Mesh::default()
    };
    m.faces.reserve(nx * ny);
    let v = |i: usize, j: usize| index[j * (nx + 1) + i];
    for j in 0..ny {
        for i in 0..nx {
            let cell = (j * nx + i) as u32;
            let q = [v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)];
            let hole = q.contains(&u32::MAX);
            m.faces.push(Face {
                verts: Vec::new(),
                material: (!hole).then(|| local[&cell_material[cell as usize]]),
                src: cell as usize,
            });
            if hole {
                continue;
            }
            for t in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
                m.triangles.push(t);
                m.tri_face.push(cell);
            }
        }
    }
    Ok(m)
}
