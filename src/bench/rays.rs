//! Ray throughput of the tracer backends (`irsig bench rays`) on the
//! ~5,000-triangle benchmark scene ([`meshgen::bench_scene`]): primary and
//! shadow rays, single rays against 16-wide packets, Embree against obvhs.

use std::sync::Arc;

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::{intersect_all, occluded_all, shadow_ray, tile_rays, time_best};
use crate::render::thread_pool;
use crate::sensor::camera::Camera;
use crate::trace::bvh::BvhTracer;
use crate::trace::embree::EmbreeTracer;
use crate::trace::{Geometry, QueryMode, Ray, Tracer, meshgen};

/// What [`rays`] measures.
#[derive(Debug, Clone, Copy)]
pub struct RaysOptions {
    /// Image width and height, pixels.
    pub size: u32,
    /// Worker threads (None: all cores).
    pub threads: Option<u32>,
    /// Timed repetitions per row (the best is reported).
    pub repeat: u32,
}

impl Default for RaysOptions {
    fn default() -> RaysOptions {
        RaysOptions {
            size: 512,
            threads: None,
            repeat: 5,
        }
    }
}

/// One row: a workload (primary or shadow rays) on one backend and mode.
#[derive(Debug, Clone, Serialize)]
pub struct RayRow {
    /// `primary` or `shadow`.
    pub workload: String,
    /// The tracer backend's name.
    pub backend: String,
    /// Query mode (single rays or packets).
    pub mode: String,
    /// Rays per repeat.
    pub rays: usize,
    /// Best time over the repeats, s.
    pub best_s: f64,
    /// Million rays per second at the best time.
    pub mrays_per_s: f64,
}

/// [`rays`]'s result: the rows and what they were measured on.
#[derive(Debug, Clone, Serialize)]
pub struct RaysReport {
    /// Triangles of the scene.
    pub triangles: usize,
    /// Image width and height of the camera, pixels.
    pub size: u32,
    /// Threads used.
    pub threads: usize,
    /// Embree's version.
    pub embree_version: String,
    /// Repeats per row (the best is kept).
    pub repeat: u32,
    /// The rows.
    pub rows: Vec<RayRow>,
}

/// Times primary and shadow rays through Embree (single and packet) and
/// obvhs (single), each the best of `repeat` runs.
pub fn rays(a: &RaysOptions) -> anyhow::Result<RaysReport> {
    anyhow::ensure!(
        (16..=8192).contains(&a.size) && (1..=100).contains(&a.repeat),
        "bench rays: size {} (expected 16..=8192 px) or repeat {} (expected 1..=100) out of range",
        a.size,
        a.repeat
    );
    let pool = thread_pool(a.threads)?;

    let (p, t) = meshgen::bench_scene().finish();
    let g = Arc::new(Geometry::new(p, t)?);
    let packet = EmbreeTracer::new(g.clone(), QueryMode::Packet16)?;
    let single = EmbreeTracer::new(g.clone(), QueryMode::Single)?;
    let bvh = BvhTracer::new(g.clone());
    let cam = Camera::look_at(
        DVec3::new(0.0, -160.0, 230.0),
        DVec3::ZERO,
        60.0,
        a.size,
        a.size,
    );
    let primary = tile_rays(&cam);
    let hits = pool.install(|| intersect_all(&packet, &primary));
    // Shadow rays: one sun direction for the whole image, from each hit,
    // kept in tile order so packets stay coherent.
    let sun = Vec3::new(0.35, -0.45, 0.82).normalize();
    let shadow: Vec<Ray> = primary
        .iter()
        .zip(&hits)
        .map(|(r, h)| match h {
            Some(h) => shadow_ray(&g, r, h, sun),
            // Misses still cast a (trivially unoccluded) ray, as a render would not.
            None => Ray::new(r.org, sun),
        })
        .collect();
    let tracers: [(&dyn Tracer, &str); 3] =
        [(&single, "single"), (&packet, "packet16"), (&bvh, "single")];
    let mut rows = Vec::new();
    for (name, set) in [("primary", &primary), ("shadow", &shadow)] {
        for (tracer, mode) in tracers {
            let best = pool.install(|| {
                time_best(a.repeat, || {
                    if name == "primary" {
                        std::hint::black_box(intersect_all(tracer, set));
                    } else {
                        std::hint::black_box(occluded_all(tracer, set));
                    }
                })
            });
            rows.push(RayRow {
                workload: name.into(),
                backend: tracer.backend().to_string(),
                mode: mode.into(),
                rays: set.len(),
                best_s: best,
                mrays_per_s: set.len() as f64 / best / 1e6,
            });
        }
    }
    Ok(RaysReport {
        triangles: g.triangles.len(),
        size: a.size,
        threads: pool.current_num_threads(),
        embree_version: EmbreeTracer::version_string().to_string(),
        repeat: a.repeat,
        rows,
    })
}
