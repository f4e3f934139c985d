//! `irsig crosscheck <scene.toml | mesh.obj>`: traces primary, specular and
//! solar-history rays with Embree and obvhs and reports the differences.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Context;
use glam::{DVec3, Vec3};

use crate::sensor::camera::Camera;
use crate::trace::bvh::BvhTracer;
use crate::trace::crosscheck::{self, Tolerances};
use crate::trace::embree::EmbreeTracer;
use crate::trace::{Geometry, QueryMode};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// A scene file (.toml: its sensor camera and the sun directions of its
    /// shadow history are used) or an OBJ mesh (a camera is generated
    /// looking at it obliquely, with a summer day's sun arc).
    pub input: PathBuf,
    /// Image width of the generated camera (OBJ input), pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub width: u32,
    /// Image height of the generated camera (OBJ input), pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub height: u32,
    /// Number of solar-history directions (OBJ input: a summer day's arc).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=96))]
    pub sun_samples: u32,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Loads an OBJ file as one triangle soup (faces fan-triangulated), with
/// the scene loader's line-numbered errors.
pub fn load_obj(path: &std::path::Path) -> anyhow::Result<Geometry> {
    let m = crate::scene::obj::load_obj(path)?;
    let positions = m.positions.iter().map(|p| Vec3::from(*p)).collect();
    let triangles = m
        .faces
        .iter()
        .flat_map(|f| (1..f.verts.len() - 1).map(move |k| [f.verts[0], f.verts[k], f.verts[k + 1]]))
        .collect();
    Geometry::new(positions, triangles).with_context(|| format!("{}: bad geometry", path.display()))
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
                sc.site.latitude_deg,
                sc.site.longitude_deg,
                sc.site.elevation_m,
            );
            (p.elevation_deg > 0.0).then(|| DVec3::from(p.sun_dir_enu).as_vec3())
        })
        .collect()
}

pub fn run(a: Args) -> anyhow::Result<i32> {
    let is_scene = a
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let (geometry, camera, suns) = if is_scene {
        let s = crate::scene::load(&a.input)?;
        let positions = s.positions.iter().map(|p| Vec3::from(*p)).collect();
        let g = Geometry::new(positions, s.triangles.clone())
            .with_context(|| format!("{}: bad geometry", a.input.display()))?;
        (g, Camera::from_geometry(&s.camera), scene_sun_dirs(&s))
    } else {
        let g = load_obj(&a.input)?;
        let cam = oblique_camera(g.bounds(), a.width, a.height);
        (g, cam, sun_arc(a.sun_samples))
    };
    let geometry = Arc::new(geometry);
    let embree = EmbreeTracer::new(geometry.clone(), QueryMode::Packet16)?;
    let bvh = BvhTracer::new(geometry.clone());
    let report = crosscheck::run(
        &geometry,
        &embree,
        &bvh,
        &camera,
        &suns,
        Tolerances::default(),
    );
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.to_text());
    }
    Ok(if report.unexplained() == 0 { 0 } else { 2 })
}
