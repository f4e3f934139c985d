//! Georeferencing: where the scene frame is on the Earth and in a map
//! coordinate reference system (CRS), for the outputs.
//!
//! The scene frame is a local east-north-up (ENU) frame whose origin is the
//! site (`[site]` latitude, longitude and elevation, taken as WGS 84
//! ellipsoidal height). A scene point p = (e, n, u) is converted to
//! geocentric coordinates by the topocentric relation of EPSG method 9836
//! (IOGP Guidance Note 7-2, §4.1.2):
//!
//! X = X₀ − sinλ₀·e − sinφ₀·cosλ₀·n + cosφ₀·cosλ₀·u
//! Y = Y₀ + cosλ₀·e − sinφ₀·sinλ₀·n + cosφ₀·sinλ₀·u
//! Z = Z₀ + cosφ₀·n + sinφ₀·u
//!
//! with (X₀, Y₀, Z₀) the site's geocentric coordinates; geocentric →
//! geodetic and geodetic → map projection are PROJ's formulas as ported by
//! the `proj4rs` crate (UTM: Poder/Engsager extended transverse Mercator,
//! PROJ's `etmerc`; local: PROJ's ellipsoidal orthographic).
//!
//! Output CRS (`site.crs`): `utm` (default), the WGS 84 / UTM zone of the
//! site (EPSG 326zz north, 327zz south); `enu`, an orthographic projection
//! centred on the site, whose x, y are the scene frame's east and north on
//! the ellipsoid (within millimetres of the scene frame near the site).

use glam::DVec3;
use proj4rs::proj::Proj;
use serde::Serialize;

use crate::scene::camera::Camera;
use crate::scene::spec::OutputCrs;
use crate::sun::Site;

/// A map CRS as the outputs state it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CrsInfo {
    /// e.g. "WGS 84 / UTM zone 18N".
    pub name: String,
    /// EPSG code (UTM), none for the local orthographic CRS.
    pub epsg: Option<u32>,
    /// PROJ string.
    pub proj: String,
    /// OGC WKT 1 (what ENVI's `coordinate system string` holds).
    pub wkt: String,
    /// UTM zone and hemisphere (`true`: north), for ENVI's `map info`.
    #[serde(skip)]
    pub utm: Option<(u32, bool)>,
    /// Latitude and longitude of the projection origin (orthographic), deg.
    #[serde(skip)]
    pub origin_deg: Option<(f64, f64)>,
}

const GEOGCS_WGS84: &str = "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563,AUTHORITY[\"EPSG\",\"7030\"]],AUTHORITY[\"EPSG\",\"6326\"]],PRIMEM[\"Greenwich\",0,AUTHORITY[\"EPSG\",\"8901\"]],UNIT[\"degree\",0.0174532925199433,AUTHORITY[\"EPSG\",\"9122\"]],AUTHORITY[\"EPSG\",\"4326\"]]";

impl CrsInfo {
    /// WGS 84 / UTM of the zone holding `lon_deg` (the standard 6° zones;
    /// the Norway and Svalbard exceptions are not applied).
    pub fn utm(lat_deg: f64, lon_deg: f64) -> CrsInfo {
        let zone = (((lon_deg + 180.0) / 6.0).floor() as i64).clamp(0, 59) as u32 + 1;
        let north = lat_deg >= 0.0;
        let epsg = if north { 32600 + zone } else { 32700 + zone };
        let name = format!("WGS 84 / UTM zone {zone}{}", if north { 'N' } else { 'S' });
        let cm = zone as f64 * 6.0 - 183.0;
        let fnorth = if north { 0 } else { 10_000_000 };
        CrsInfo {
            wkt: format!(
                "PROJCS[\"{name}\",{GEOGCS_WGS84},PROJECTION[\"Transverse_Mercator\"],\
                 PARAMETER[\"latitude_of_origin\",0],PARAMETER[\"central_meridian\",{cm}],\
                 PARAMETER[\"scale_factor\",0.9996],PARAMETER[\"false_easting\",500000],\
                 PARAMETER[\"false_northing\",{fnorth}],UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],\
                 AXIS[\"Easting\",EAST],AXIS[\"Northing\",NORTH],AUTHORITY[\"EPSG\",\"{epsg}\"]]"
            ),
            proj: format!(
                "+proj=utm +zone={zone}{} +datum=WGS84 +units=m +no_defs",
                if north { "" } else { " +south" }
            ),
            name,
            epsg: Some(epsg),
            utm: Some((zone, north)),
            origin_deg: None,
        }
    }

    /// The orthographic projection centred on (`lat_deg`, `lon_deg`):
    /// x east and y north on the tangent plane, metres.
    pub fn local(lat_deg: f64, lon_deg: f64) -> CrsInfo {
        let name = format!("irsig local ENU: WGS 84 orthographic at {lat_deg}, {lon_deg}");
        CrsInfo {
            wkt: format!(
                "PROJCS[\"{name}\",{GEOGCS_WGS84},PROJECTION[\"Orthographic\"],\
                 PARAMETER[\"latitude_of_origin\",{lat_deg}],PARAMETER[\"central_meridian\",{lon_deg}],\
                 PARAMETER[\"false_easting\",0],PARAMETER[\"false_northing\",0],\
                 UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],AXIS[\"Easting\",EAST],AXIS[\"Northing\",NORTH]]"
            ),
            proj: format!(
                "+proj=ortho +lat_0={lat_deg} +lon_0={lon_deg} +x_0=0 +y_0=0 +datum=WGS84 +units=m +no_defs"
            ),
            name,
            epsg: None,
            utm: None,
            origin_deg: Some((lat_deg, lon_deg)),
        }
    }
}

/// Converts scene-frame points to geodetic and map coordinates.
pub struct Geo {
    lat0: f64,
    lon0: f64,
    /// The site's geocentric position, m.
    origin_ecef: DVec3,
    /// The outputs' map CRS.
    pub crs: CrsInfo,
    longlat: Proj,
    geocent: Proj,
    map: Proj,
}

fn proj(s: &str) -> anyhow::Result<Proj> {
    Proj::from_proj_string(s).map_err(|e| anyhow::anyhow!("PROJ definition `{s}`: {e}"))
}

impl Geo {
    /// The converter of a site and an output CRS choice.
    pub fn new(site: &Site, crs: &OutputCrs) -> anyhow::Result<Geo> {
        let (lat0, lon0) = (site.latitude_deg, site.longitude_deg);
        let crs = match crs {
            OutputCrs::Utm => CrsInfo::utm(lat0, lon0),
            OutputCrs::Enu => CrsInfo::local(lat0, lon0),
        };
        Geo::with_crs(lat0, lon0, site.elevation_m, crs)
    }

    /// The converter of a frame's georeferencing.
    pub fn for_georef(g: &Georef) -> anyhow::Result<Geo> {
        Geo::with_crs(
            g.site_lat_deg,
            g.site_lon_deg,
            g.site_height_m,
            g.crs.clone(),
        )
    }

    fn with_crs(lat0: f64, lon0: f64, height_m: f64, crs: CrsInfo) -> anyhow::Result<Geo> {
        let longlat = proj("+proj=longlat +datum=WGS84 +no_defs")?;
        let geocent = proj("+proj=geocent +datum=WGS84 +units=m +no_defs")?;
        let map = proj(&crs.proj)?;
        let mut p = (lon0.to_radians(), lat0.to_radians(), height_m);
        proj4rs::transform::transform(&longlat, &geocent, &mut p)
            .map_err(|e| anyhow::anyhow!("site to geocentric: {e}"))?;
        Ok(Geo {
            lat0,
            lon0,
            origin_ecef: DVec3::new(p.0, p.1, p.2),
            crs,
            longlat,
            geocent,
            map,
        })
    }

    /// Geodetic latitude and longitude (degrees) and ellipsoidal height
    /// (m) of scene point `p` (EPSG 9836, then PROJ's geocentric inverse).
    pub fn geodetic(&self, p: [f64; 3]) -> Option<(f64, f64, f64)> {
        let (sp, cp) = self.lat0.to_radians().sin_cos();
        let (sl, cl) = self.lon0.to_radians().sin_cos();
        let [e, n, u] = p;
        let x = self.origin_ecef
            + DVec3::new(
                -sl * e - sp * cl * n + cp * cl * u,
                cl * e - sp * sl * n + cp * sl * u,
                cp * n + sp * u,
            );
        let mut q = (x.x, x.y, x.z);
        proj4rs::transform::transform(&self.geocent, &self.longlat, &mut q).ok()?;
        Some((q.1.to_degrees(), q.0.to_degrees(), q.2))
    }

    /// The scene point of geodetic latitude and longitude (degrees) and
    /// ellipsoidal height `h_m` (m): PROJ's geocentric forward, then the
    /// inverse of EPSG 9836 (the transpose of the rotation above):
    ///
    /// e = −sinλ₀·ΔX + cosλ₀·ΔY
    /// n = −sinφ₀·cosλ₀·ΔX − sinφ₀·sinλ₀·ΔY + cosφ₀·ΔZ
    /// u = cosφ₀·cosλ₀·ΔX + cosφ₀·sinλ₀·ΔY + sinφ₀·ΔZ
    pub fn scene_point(&self, lat_deg: f64, lon_deg: f64, h_m: f64) -> Option<[f64; 3]> {
        let mut q = (lon_deg.to_radians(), lat_deg.to_radians(), h_m);
        proj4rs::transform::transform(&self.longlat, &self.geocent, &mut q).ok()?;
        let d = DVec3::new(q.0, q.1, q.2) - self.origin_ecef;
        let (sp, cp) = self.lat0.to_radians().sin_cos();
        let (sl, cl) = self.lon0.to_radians().sin_cos();
        let p = [
            -sl * d.x + cl * d.y,
            -sp * cl * d.x - sp * sl * d.y + cp * d.z,
            cp * cl * d.x + cp * sl * d.y + sp * d.z,
        ];
        p.iter().all(|v| v.is_finite()).then_some(p)
    }

    /// Map coordinates (x, y), metres, of latitude and longitude (degrees).
    pub fn map_xy(&self, lat_deg: f64, lon_deg: f64) -> Option<[f64; 2]> {
        let mut q = (lon_deg.to_radians(), lat_deg.to_radians(), 0.0);
        proj4rs::transform::transform(&self.longlat, &self.map, &mut q).ok()?;
        Some([q.0, q.1])
    }

    /// Map coordinates of scene point `p`.
    pub fn scene_to_map(&self, p: [f64; 3]) -> Option<[f64; 2]> {
        let (lat, lon, _) = self.geodetic(p)?;
        self.map_xy(lat, lon)
    }
}

/// One image corner on the reference plane.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Corner {
    /// Image position, pixels ((0, 0): the top-left corner of the image).
    pub pixel: [f64; 2],
    /// Scene frame, metres.
    pub scene_m: [f64; 3],
    /// Latitude (WGS 84), degrees.
    pub lat_deg: f64,
    /// Longitude (WGS 84), degrees.
    pub lon_deg: f64,
    /// Output CRS, metres.
    pub map_m: [f64; 2],
}

/// A frame's georeferencing, as recorded in every output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Georef {
    /// The outputs' map CRS.
    pub crs: CrsInfo,
    /// The site, the scene frame's origin: its latitude, degrees.
    pub site_lat_deg: f64,
    /// The site's longitude, degrees.
    pub site_lon_deg: f64,
    /// The site's height above the WGS 84 ellipsoid, m.
    pub site_height_m: f64,
    /// The `ground_x/y/z` planes are scene (world) metres minus this
    /// origin: the tracer's local frame origin (the camera target rounded
    /// to whole metres, z 0; [`crate::scene::frame`]), so float32 planes
    /// keep 0.5 mm within 16 km of it, UTM-scale scenes included.
    pub ground_origin_m: [f64; 3],
    /// Height z of the reference plane (the pose's target), scene metres:
    /// the footprint and the affine transform are on it.
    pub reference_z_m: f64,
    /// Straight-down view: the image maps to the reference plane by an
    /// exact affine transform.
    pub nadir: bool,
    /// Pixel → map affine transform in GDAL's order (x = g0 + col·g1 +
    /// row·g2, y = g3 + col·g4 + row·g5; pixel corners), nadir views only:
    /// for oblique views a plane-to-image mapping is not affine and the
    /// geolocation (lat/lon per pixel) takes its place.
    pub geotransform: Option<[f64; 6]>,
    /// Image corners (top-left, top-right, bottom-right, bottom-left) on
    /// the reference plane; a corner whose ray misses the plane is absent.
    pub footprint: Vec<Option<Corner>>,
    /// Ground sample distance at the image centre on the reference plane,
    /// m per pixel (across, along).
    pub centre_gsd_m: Option<[f64; 2]>,
}

/// The georeferencing of an image of `camera` (world coordinates) at a
/// site: the CRS, the reference plane z = `reference_z_m`, the footprint,
/// the ground origin of the geolocation planes and, for nadir views, the
/// affine transform.
pub fn georeference(
    geo: &Geo,
    site: &Site,
    camera: &Camera,
    reference_z_m: f64,
    ground_origin_m: [f64; 3],
) -> anyhow::Result<Georef> {
    let corner = |c: f64, r: f64| -> Option<Corner> {
        let p = camera.ground_point(c, r, reference_z_m)?;
        let (lat, lon, _) = geo.geodetic(p)?;
        Some(Corner {
            pixel: [c, r],
            scene_m: p,
            lat_deg: lat,
            lon_deg: lon,
            map_m: geo.map_xy(lat, lon)?,
        })
    };
    let (w, h) = (camera.width_px as f64, camera.height_px as f64);
    let footprint: Vec<Option<Corner>> = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)]
        .iter()
        .map(|&(c, r)| corner(c, r))
        .collect();
    let nadir = camera.forward[2] <= -1.0 + 1e-12;
    let geotransform = if nadir {
        match (&footprint[0], &footprint[1], &footprint[3]) {
            (Some(tl), Some(tr), Some(bl)) => Some([
                tl.map_m[0],
                (tr.map_m[0] - tl.map_m[0]) / w,
                (bl.map_m[0] - tl.map_m[0]) / h,
                tl.map_m[1],
                (tr.map_m[1] - tl.map_m[1]) / w,
                (bl.map_m[1] - tl.map_m[1]) / h,
            ]),
            _ => None,
        }
    } else {
        None
    };
    Ok(Georef {
        crs: geo.crs.clone(),
        site_lat_deg: site.latitude_deg,
        site_lon_deg: site.longitude_deg,
        site_height_m: site.elevation_m,
        ground_origin_m,
        reference_z_m,
        nadir,
        geotransform,
        footprint,
        centre_gsd_m: camera.centre_gsd_m(reference_z_m),
    })
}

/// Per-pixel geolocation in full precision: latitude, longitude (deg),
/// map x, y (m) of each pixel's hit point (NaN where the ray hit nothing).
pub struct Geolocation {
    /// Latitude of each pixel's hit point, degrees.
    pub lat_deg: Vec<f64>,
    /// Longitude, degrees.
    pub lon_deg: Vec<f64>,
    /// Map x in the outputs' CRS, m.
    pub map_x_m: Vec<f64>,
    /// Map y, m.
    pub map_y_m: Vec<f64>,
}

/// The geolocation of the planes `ground_x/y/z` (offsets from
/// `origin_m`, as the render writes them).
pub fn geolocate(geo: &Geo, origin_m: [f64; 3], x: &[f32], y: &[f32], z: &[f32]) -> Geolocation {
    use rayon::prelude::*;
    let ((lat_deg, lon_deg), (map_x_m, map_y_m)) = (0..x.len())
        .into_par_iter()
        .map(|i| {
            let p = [
                origin_m[0] + x[i] as f64,
                origin_m[1] + y[i] as f64,
                origin_m[2] + z[i] as f64,
            ];
            let nan = ((f64::NAN, f64::NAN), (f64::NAN, f64::NAN));
            if !p.iter().all(|v| v.is_finite()) {
                return nan;
            }
            match geo.geodetic(p) {
                Some((lat, lon, _)) => {
                    let m = geo.map_xy(lat, lon).unwrap_or([f64::NAN; 2]);
                    ((lat, lon), (m[0], m[1]))
                }
                None => nan,
            }
        })
        .unzip();
    Geolocation {
        lat_deg,
        lon_deg,
        map_x_m,
        map_y_m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn site(lat: f64, lon: f64) -> Site {
        Site {
            latitude_deg: lat,
            longitude_deg: lon,
            elevation_m: 169.0,
        }
    }

    #[test]
    fn utm_zones_and_codes() {
        let r = CrsInfo::utm(43.1566, -77.6088);
        assert_eq!((r.epsg, r.utm), (Some(32618), Some((18, true))));
        let s = CrsInfo::utm(-33.9, 18.4);
        assert_eq!((s.epsg, s.utm), (Some(32734), Some((34, false))));
        assert!(s.wkt.contains("\"false_northing\",10000000"));
    }

    /// The site itself maps to its own latitude and longitude, and 1 km
    /// east/north moves the latitude by 1 km / M and the longitude by
    /// 1 km / (N cos φ) (meridian and prime-vertical radii of WGS 84).
    #[test]
    fn enu_offsets_follow_the_ellipsoid_radii() {
        let g = Geo::new(&site(43.1566, -77.6088), &OutputCrs::Utm).unwrap();
        let (lat, lon, h) = g.geodetic([0.0, 0.0, 0.0]).unwrap();
        assert!((lat - 43.1566).abs() < 1e-10 && (lon + 77.6088).abs() < 1e-10);
        assert!((h - 169.0).abs() < 1e-6);
        let (a, e2) = (6_378_137.0f64, 6.694_379_990_14e-3);
        let phi = 43.1566f64.to_radians();
        let w = (1.0 - e2 * phi.sin().powi(2)).sqrt();
        let (m, n) = (a * (1.0 - e2) / w.powi(3), a / w);
        let (lat_n, _, _) = g.geodetic([0.0, 100.0, 0.0]).unwrap();
        let (_, lon_e, _) = g.geodetic([100.0, 0.0, 0.0]).unwrap();
        let dlat = (lat_n - 43.1566).to_radians() * (m + 169.0);
        let dlon = (lon_e + 77.6088).to_radians() * (n + 169.0) * phi.cos();
        assert!(
            (dlat - 100.0).abs() < 1e-3 && (dlon - 100.0).abs() < 1e-3,
            "{dlat} {dlon}"
        );
    }

    /// `scene_point` inverts `geodetic` (to 0.1 mm over 10 km and 1 km of
    /// height), and the ellipsoid falls below the tangent plane by d²/2R
    /// (R the radius of curvature along the direction, WGS 84).
    #[test]
    fn scene_point_inverts_geodetic_and_follows_the_curvature() {
        let g = Geo::new(&site(43.1566, -77.6088), &OutputCrs::Utm).unwrap();
        for p in [
            [0.0, 0.0, 0.0],
            [10_000.0, -7_000.0, 950.0],
            [-3.5, 2.25, -40.0],
        ] {
            let (lat, lon, h) = g.geodetic(p).unwrap();
            let q = g.scene_point(lat, lon, h).unwrap();
            let d = (0..3).map(|i| (p[i] - q[i]).abs()).fold(0.0, f64::max);
            assert!(d < 1e-4, "{p:?} -> {q:?}");
        }
        let (a, e2) = (6_378_137.0f64, 6.694_379_990_14e-3);
        let phi = 43.1566f64.to_radians();
        let w = (1.0 - e2 * phi.sin().powi(2)).sqrt();
        let (m, n) = (a * (1.0 - e2) / w.powi(3), a / w);
        for (dir, r) in [([2000.0, 0.0], n), ([0.0, 2000.0], m)] {
            let (lat, lon, _) = g.geodetic([dir[0], dir[1], 0.0]).unwrap();
            let z = g.scene_point(lat, lon, 169.0).unwrap()[2];
            let want = -2000.0f64.powi(2) / (2.0 * r);
            assert!((z - want).abs() < 2e-3, "{dir:?}: {z} vs {want}");
        }
    }

    /// Planes relative to the ground origin keep millimetres at UTM-scale
    /// scene coordinates, where absolute float32 coordinates are 0.25-0.5 m
    /// coarse.
    #[test]
    fn ground_origin_keeps_precision_far_from_the_frame_origin() {
        let o = [350_400.0, 4_780_701.0, 0.0];
        let p = [350_412.345_678, 4_780_688.765_432, 12.5];
        let rel = p.map(|v| v as f32);
        let off = [
            (p[0] - o[0]) as f32,
            (p[1] - o[1]) as f32,
            (p[2] - o[2]) as f32,
        ];
        assert!((off[1] as f64 + o[1] - p[1]).abs() < 1e-4);
        assert!(
            (rel[1] as f64 - p[1]).abs() > 0.05,
            "f32 absolute would be coarse"
        );
        let g = Geo::new(&site(43.0, -75.0), &OutputCrs::Enu).unwrap();
        let loc = geolocate(&g, o, &[off[0]], &[off[1]], &[off[2]]);
        let (lat, lon, _) = g.geodetic(p).unwrap();
        // 1e-9 deg is 0.1 mm.
        assert!((loc.lat_deg[0] - lat).abs() < 1e-9 && (loc.lon_deg[0] - lon).abs() < 1e-9);
    }
}
