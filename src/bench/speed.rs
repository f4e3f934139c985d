//! Render stage times against the pure-Embree ray floor, peak memory, over
//! image sizes and facet counts (`irsig bench speed`).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use serde::Serialize;

use super::{
    intersect_all, occluded_all, peak_rss_mib, reset_peak_rss, shadow_ray, tile_rays, time_best,
};
use crate::render::{prepare_conditions, prepare_static, render, thread_pool};
use crate::sensor::camera::Camera;
use crate::trace::embree::EmbreeTracer;
use crate::trace::{Geometry, QueryMode, Ray};

/// What [`speed`] measures.
#[derive(Debug, Clone)]
pub struct SpeedOptions {
    /// The scene file.
    pub scene: PathBuf,
    /// Image sizes (square), pixels.
    pub sizes: Vec<u32>,
    /// Facet multipliers: each triangle split into n² (1, 9 ≈ 10x, 100).
    pub subdivide: Vec<u32>,
    /// Image size of the facet-count rows.
    pub facet_size: u32,
    /// Scene-key overrides (as `render --set`).
    pub overrides: Vec<(String, String)>,
    /// Worker threads (None: all cores).
    pub threads: Option<u32>,
}

impl SpeedOptions {
    /// The defaults of `irsig bench speed SCENE`.
    pub fn new(scene: impl Into<PathBuf>) -> SpeedOptions {
        SpeedOptions {
            scene: scene.into(),
            sizes: vec![256, 512, 1024, 2048],
            subdivide: vec![1, 3, 10],
            facet_size: 512,
            overrides: Vec::new(),
            threads: None,
        }
    }
}

/// One row of `bench speed`.
#[derive(Debug, Clone, Serialize)]
pub struct SpeedRow {
    /// Image width and height, pixels.
    pub size: u32,
    /// Triangles of the (subdivided) scene.
    pub triangles: usize,
    /// Loading the scene and building the BVH, s.
    pub load_bvh_s: f64,
    /// The frame's conditions (weather, atmosphere, sun samples), s.
    pub conditions_s: f64,
    /// Tracing (primary, bounce and solar-history rays), s.
    pub trace_s: f64,
    /// Thermal solves, s.
    pub thermal_s: f64,
    /// Radiometry, s.
    pub radiometry_s: f64,
    /// The sensor chain, s.
    pub sensor_s: f64,
    /// Load, conditions and the four stages, s.
    pub total_s: f64,
    /// Writing the frame as `irsig render` does (EXR with every plane at the
    /// scene's `output.exr_compression`, PNG
    /// quicklook, JSON summary), into a temporary folder, s.
    pub output_s: f64,
    /// `total_s` + `output_s`.
    pub total_with_output_s: f64,
    /// Rays traced.
    pub rays: u64,
    /// Million rays (primary, solar, specular) per second of the trace stage.
    pub mrays_per_s: f64,
    /// Time of the same numbers of primary and shadow rays at the
    /// pure-Embree packet rate measured on this scene and camera.
    pub embree_floor_s: f64,
    /// The four stages' time (trace, thermal, radiometry, sensor) / `embree_floor_s`.
    pub ratio_to_floor: f64,
    /// Thermal solves (cache misses).
    pub thermal_solves: u64,
    /// Peak resident memory of the process, MiB.
    pub peak_rss_mib: f64,
}

/// Splits every triangle into n² (midpoint grid), keeping its material,
/// object and facet.
fn subdivide(s: &mut crate::scene::LoadedScene, n: u32) {
    if n <= 1 {
        return;
    }
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    let (mut mat, mut obj, mut fac) = (Vec::new(), Vec::new(), Vec::new());
    let nf = n as f32;
    for (t, tri) in s.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|k| Vec3::from(s.positions[k as usize]));
        // Vertices (i, j) with i + j <= n: a + (b−a)·i/n + (c−a)·j/n.
        let mut id = vec![vec![0u32; (n + 1) as usize]; (n + 1) as usize];
        for i in 0..=n {
            for j in 0..=(n - i) {
                id[i as usize][j as usize] = pos.len() as u32;
                pos.push((a + (b - a) * (i as f32 / nf) + (c - a) * (j as f32 / nf)).to_array());
            }
        }
        for i in 0..n as usize {
            for j in 0..(n as usize - i) {
                let mut push = |q: [u32; 3]| {
                    tris.push(q);
                    mat.push(s.tri_material[t]);
                    obj.push(s.tri_object[t]);
                    fac.push(s.tri_facet[t]);
                };
                push([id[i][j], id[i + 1][j], id[i][j + 1]]);
                if j + 1 < n as usize - i {
                    push([id[i + 1][j], id[i + 1][j + 1], id[i][j + 1]]);
                }
            }
        }
    }
    s.positions = pos;
    s.triangles = tris;
    s.tri_material = mat;
    s.tri_object = obj;
    s.tri_facet = fac;
}

/// Pure-Embree packet throughput (primary, shadow) in rays/s for the
/// scene's geometry and a camera, tile-ordered as the render traces.
fn embree_rates(g: &Arc<Geometry>, cam: &Camera, sun: Vec3) -> anyhow::Result<(f64, f64)> {
    let packet = EmbreeTracer::new(g.clone(), QueryMode::Packet16)?;
    let primary = tile_rays(cam);
    let hits = intersect_all(&packet, &primary);
    let shadow: Vec<Ray> = primary
        .iter()
        .zip(&hits)
        .filter_map(|(r, h)| h.as_ref().map(|h| shadow_ray(g, r, h, sun)))
        .collect();
    let tp = time_best(3, || {
        std::hint::black_box(intersect_all(&packet, &primary));
    });
    let ts = time_best(3, || {
        std::hint::black_box(occluded_all(&packet, &shadow));
    });
    Ok((primary.len() as f64 / tp, shadow.len().max(1) as f64 / ts))
}

/// Renders the scene at each size (facets as they are) and at
/// `facet_size` with each facet multiplier > 1, timing every stage against
/// the pure-Embree ray floor of the same rays; `progress` hears each row
/// when it is done.
pub fn speed(
    a: &SpeedOptions,
    progress: &mut dyn FnMut(&SpeedRow),
) -> anyhow::Result<Vec<SpeedRow>> {
    let overrides = a.overrides.clone();
    let pool = thread_pool(a.threads)?;
    let mut jobs: Vec<(u32, u32)> = a.sizes.iter().map(|&s| (s, 1)).collect();
    jobs.extend(
        a.subdivide
            .iter()
            .filter(|&&n| n > 1)
            .map(|&n| (a.facet_size, n)),
    );
    let mut rows = Vec::new();
    for (size, n) in jobs {
        let mut ov = overrides.clone();
        ov.push(("sensor.width_px".into(), size.to_string()));
        ov.push(("sensor.height_px".into(), size.to_string()));
        // Each row reports its own peak.
        reset_peak_rss();
        let row = pool.install(|| -> anyhow::Result<SpeedRow> {
            let t0 = Instant::now();
            let mut scene = crate::scene::load_with_overrides(&a.scene, &ov)?;
            subdivide(&mut scene, n);
            let st = prepare_static(scene, None)?;
            let load = t0.elapsed().as_secs_f64();
            let t1 = Instant::now();
            let t = st.scene.scene.time.utc(&st.scene.scene.site);
            let cond = prepare_conditions(&st, t)?;
            let conditions = t1.elapsed().as_secs_f64();
            let frame = render(&st, &cond)?;
            let s = &frame.stats;
            let tmp = tempfile::tempdir()?;
            let t2 = Instant::now();
            crate::output::frame::write_frame(
                &tmp.path().join("speed.exr"),
                &frame,
                |_, _| Ok("{}".into()),
                false,
                st.scene.scene.output.exr_compression,
            )?;
            let output = t2.elapsed().as_secs_f64();
            // The peak of the render and its write (before the floor's own
            // ray buffers below).
            let peak_rss_mib = peak_rss_mib();
            let cam = st.scene.local_camera;
            let sun = glam::DVec3::from(cond.sun_now.sun_dir_enu).as_vec3();
            let (rp, rs) = embree_rates(&st.geometry, &cam, sun)?;
            let floor = s.primary_rays as f64 / rp + (s.solar_rays + s.specular_rays) as f64 / rs;
            let stages =
                s.seconds.trace + s.seconds.thermal + s.seconds.radiometry + s.seconds.sensor;
            let total = load + conditions + stages;
            let rays = s.primary_rays + s.solar_rays + s.specular_rays;
            Ok(SpeedRow {
                size,
                triangles: st.geometry.triangles.len(),
                load_bvh_s: load,
                conditions_s: conditions,
                trace_s: s.seconds.trace,
                thermal_s: s.seconds.thermal,
                radiometry_s: s.seconds.radiometry,
                sensor_s: s.seconds.sensor,
                total_s: total,
                output_s: output,
                total_with_output_s: total + output,
                rays,
                mrays_per_s: rays as f64 / s.seconds.trace / 1e6,
                embree_floor_s: floor,
                ratio_to_floor: stages / floor,
                thermal_solves: s.thermal_solves,
                peak_rss_mib,
            })
        })?;
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}
