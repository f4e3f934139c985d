//! The cross-check of a scene or mesh file (`irsig crosscheck`): its
//! geometry, a camera and sun directions, traced with both backends
//! ([`super::crosscheck::run`]).

use std::path::Path;
use std::sync::Arc;

use anyhow::Context;
use glam::{DVec3, Vec3};

use super::crosscheck::{self, Report, Tolerances};
use crate::sensor::camera::Camera;
use crate::trace::bvh::BvhTracer;
use crate::trace::embree::EmbreeTracer;
use crate::trace::{Geometry, QueryMode};

/// The camera and sun directions of a mesh input (a scene has its own).
#[derive(Clone, Copy, Debug)]
pub struct MeshView {
    /// Image width of the generated oblique camera, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Number of solar-history directions (a summer day's arc).
    pub sun_samples: u32,
}

/// Loads a mesh file as one triangle soup (faces triangulated as the
/// scene loader does, [`crate::scene::mesh`]), with
/// the scene loader's line-numbered errors, in a local frame whose origin
/// is the centre of its bounds rounded to whole metres (see
/// `scene::frame`: so that far-off coordinates keep their precision).
/// Returns the geometry and the world coordinates of that origin.
pub fn load_obj(path: &Path) -> anyhow::Result<(Geometry, [f64; 3])> {
    let m = crate::scene::mesh::load(path)?;
    let (lo, hi) = m
        .positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(DVec3::from(*p)), hi.max(DVec3::from(*p)))
        });
    let origin = if m.positions.is_empty() {
        DVec3::ZERO
    } else {
        ((lo + hi) / 2.0).round()
    };
    let positions = m
        .positions
        .iter()
        .map(|p| (DVec3::from(*p) - origin).as_vec3())
        .collect();
    let g = Geometry::new(positions, m.triangles)
        .with_context(|| format!("{}: bad geometry", path.display()))?;
    Ok((g, origin.to_array()))
}

/// A camera looking at the centre of `bounds` from the south-west, 35° off
/// nadir, framing the whole bounding box.
pub fn oblique_camera(bounds: (Vec3, Vec3), width: u32, height: u32) -> Camera {
    let (lo, hi) = (bounds.0.as_dvec3(), bounds.1.as_dvec3());
    let center = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(1.0);
    let dir = DVec3::new(-0.4, -0.5, 1.0).normalize();
    let fov_deg: f64 = 50.0;
    let dist = radius / (fov_deg.to_radians() / 2.0).sin();
    Camera::look_at(center + dir * dist, center, fov_deg, width, height)
}

/// `n` sun directions along a mid-latitude summer arc (elevation 8°-65°,
/// azimuth 70°-290°), ENU.
pub fn sun_arc(n: u32) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let f = if n > 1 {
                i as f32 / (n - 1) as f32
            } else {
                0.5
            };
            let az = (70.0 + 220.0 * f).to_radians();
            let el = (8.0 + 57.0 * (std::f32::consts::PI * f).sin()).to_radians();
            Vec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin())
        })
        .collect()
}

/// Sun directions (ENU) of a scene's shadow history: every
/// `shadow_interval_min` over `history_hours` before the image time, sun
/// above the horizon.
pub fn scene_sun_dirs(s: &crate::scene::LoadedScene) -> Vec<Vec3> {
    let sc = &s.scene;
    let end = sc.time.utc(&sc.site);
    let step_s = (sc.render.shadow_interval_min * 60.0).round() as i64;
    let n = (sc.render.history_hours * 3600.0 / step_s as f64).round() as i64;
    (0..=n)
        .filter_map(|k| {
            let t = end - chrono::Duration::seconds(step_s * (n - k));
            let p = crate::sun::solar_position(
                t,
                sc.site.location.latitude_deg,
                sc.site.location.longitude_deg,
                sc.site.location.elevation_m,
            );
            (p.elevation_deg > 0.0).then(|| DVec3::from(p.sun_dir_enu).as_vec3())
        })
        .collect()
}

/// Cross-checks the backends on `input`: a scene file (`.toml`: its
/// sensor camera and the sun directions of its shadow history) or an OBJ
/// mesh (an oblique camera and a sun arc from `mesh`).
pub fn crosscheck_file(input: &Path, mesh: MeshView) -> anyhow::Result<Report> {
    let is_scene = input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    if is_scene {
        return crosscheck_scene(&crate::scene::load(input)?);
    }
    let (g, origin) = load_obj(input)?;
    let cam = oblique_camera(g.bounds(), mesh.width, mesh.height);
    let mut report = crosscheck_geometry(g, &cam, &sun_arc(mesh.sun_samples))?;
    report.local_origin_m = origin;
    Ok(report)
}

/// Cross-checks the backends on a loaded scene: its geometry in the
/// tracer's local frame, its sensor camera and the sun directions of its
/// shadow history.
pub fn crosscheck_scene(s: &crate::scene::LoadedScene) -> anyhow::Result<Report> {
    let positions = s.positions.iter().map(|p| Vec3::from(*p)).collect();
    let g = Geometry::new(positions, s.triangles.clone())
        .with_context(|| format!("{}: bad geometry", s.path.display()))?;
    let mut report = crosscheck_geometry(g, &s.local_camera, &scene_sun_dirs(s))?;
    report.local_origin_m = s.frame.origin_m;
    Ok(report)
}

fn crosscheck_geometry(
    geometry: Geometry,
    camera: &Camera,
    suns: &[Vec3],
) -> anyhow::Result<Report> {
    let geometry = Arc::new(geometry);
    let embree = EmbreeTracer::new(geometry.clone(), QueryMode::Packet16)?;
    let bvh = BvhTracer::new(geometry.clone());
    Ok(crosscheck::run(
        &geometry,
        &embree,
        &bvh,
        camera,
        suns,
        Tolerances::default(),
    ))
}
