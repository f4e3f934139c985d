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
    /// An OBJ mesh (a camera is generated looking at it obliquely).
    pub input: PathBuf,
    /// Image width of the generated camera, pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub width: u32,
    /// Image height of the generated camera, pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub height: u32,
    /// Number of solar-history directions (a summer day's arc).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=96))]
    pub sun_samples: u32,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Loads an OBJ file as one triangle soup (all models, triangulated).
pub fn load_obj(path: &std::path::Path) -> anyhow::Result<Geometry> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(path, &opts)
        .map_err(|e| anyhow::anyhow!("{}: cannot read OBJ: {e}", path.display()))?;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for m in &models {
        let base = positions.len() as u32;
        positions.extend(
            m.mesh
                .positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
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

pub fn run(a: Args) -> anyhow::Result<i32> {
    let geometry = Arc::new(load_obj(&a.input)?);
    let embree = EmbreeTracer::new(geometry.clone(), QueryMode::Packet16)?;
    let bvh = BvhTracer::new(geometry.clone());
    let camera = oblique_camera(geometry.bounds(), a.width, a.height);
    let report = crosscheck::run(
        &geometry,
        &embree,
        &bvh,
        &camera,
        &sun_arc(a.sun_samples),
        Tolerances::default(),
    );
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.to_text());
    }
    Ok(if report.unexplained() == 0 { 0 } else { 2 })
}
