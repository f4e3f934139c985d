//! The render: the paper's Fig. 11 as a data flow. Per block of pixels
//! (rayon over blocks, 4x4 tiles of 16-wide packets inside):
//!
//! 1. primary rays → facet, point, normal, range;
//! 2. specular-bounce rays for specular materials → sky direction or a
//!    background facet;
//! 3. solar-history rays from every surface point (primary and background),
//!    one packet per tile and sun sample, skipped with the sun below the
//!    horizon or behind the facet → the pixel's sun/shadow history;
//! 4. temperatures from the memoised thermal model, keyed by (material,
//!    orientation, history);
//! 5. radiometry by the paper's four cases, bin by bin over the band, then
//!    the sensor (supersampling, PSF, noise, quantisation).
//!
//! Everything is deterministic: results depend on pixel, key and seed only,
//! never on thread scheduling.

pub mod pixel;
pub mod prepare;

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use serde::Serialize;

use crate::output::Planes;
use crate::sensor::camera::Camera;
use crate::therm::balance::Orientation;
use crate::therm::slab::SunHistory;
use crate::trace::offset::offset_origin;
use crate::trace::{Hit, Ray};
pub use prepare::{Conditions, Reused, Static, derive_static, prepare_conditions, prepare_static};

/// A surface point seen by a ray.
#[derive(Clone, Debug)]
pub struct Surface {
    pub prim: u32,
    pub material: u32,
    pub point: Vec3,
    /// Unit geometric normal, facing the incoming ray.
    pub normal: Vec3,
    /// Distance along the incoming ray, m.
    pub range_m: f32,
    /// Sun/shadow flag per history sample (true = sunlit).
    pub history: Vec<bool>,
    /// Surface temperature at the image time, K (filled in step 4).
    pub temp_k: f64,
}

impl Surface {
    /// Sunlit at the image time (the last history sample).
    pub fn sun_now(&self) -> bool {
        self.history.last().copied().unwrap_or(false)
    }
}

/// What a (sub-)pixel's ray found.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Unit direction of the primary ray.
    pub dir: Vec3,
    pub surface: Option<Surface>,
    /// For specular materials: the reflected direction and the background
    /// facet it hits (`None`: the sky).
    pub bounce: Option<(Vec3, Option<Surface>)>,
}

/// Counters reported by `--stats`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Stats {
    pub samples: u64,
    pub primary_rays: u64,
    pub primary_hits: u64,
    pub specular_rays: u64,
    pub specular_skipped_diffuse: u64,
    pub solar_rays: u64,
    pub solar_skipped_sun_down: u64,
    pub solar_skipped_facing_away: u64,
    pub thermal_solves: u64,
    pub thermal_cache_hits: u64,
    pub spectral_bins: usize,
    pub seconds: StageTimes,
}

/// Wall time per stage, s.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StageTimes {
    pub trace: f64,
    pub thermal: f64,
    pub radiometry: f64,
    pub sensor: f64,
}

#[derive(Default)]
struct Counters {
    primary: AtomicU64,
    hits: AtomicU64,
    specular: AtomicU64,
    spec_skipped: AtomicU64,
    solar: AtomicU64,
    sun_down: AtomicU64,
    away: AtomicU64,
}

fn add(c: &AtomicU64, n: usize) {
    c.fetch_add(n as u64, Ordering::Relaxed);
}

/// Pixels per block side (in supersampled pixels) handed to one rayon task.
const BLOCK: u32 = 16;

/// The supersampled camera: n×n rays per output pixel.
fn sample_camera(st: &Static) -> Camera {
    let n = st.scene.scene.render.supersample.max(1);
    let mut cam = Camera::from_geometry(&st.scene.camera);
    cam.width *= n;
    cam.height *= n;
    cam
}

/// Surface record of a hit.
fn surface_of(st: &Static, ray: &Ray, h: &Hit) -> Surface {
    let g = &st.geometry;
    let n = g.normals[h.prim as usize];
    let normal = if n.dot(ray.dir) > 0.0 { -n } else { n };
    Surface {
        prim: h.prim,
        material: st.scene.tri_material[h.prim as usize],
        point: g.point(h.prim, h.u, h.v),
        normal,
        range_m: h.t * ray.dir.length(),
        history: Vec::new(),
        temp_k: f64::NAN,
    }
}

/// Steps 1-3 for one block of (supersampled) pixels, in 4x4 tile order.
fn trace_block(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    pixels: &[(u32, u32)],
    c: &Counters,
) -> Vec<Sample> {
    let tracer = st.tracer.as_ref();
    let rays: Vec<Ray> = pixels
        .iter()
        .map(|&(x, y)| cam.ray(x as f64 + 0.5, y as f64 + 0.5))
        .collect();
    let mut hits = vec![None; rays.len()];
    tracer.intersect(&rays, &mut hits);
    add(&c.primary, rays.len());
    let mut samples: Vec<Sample> = rays
        .iter()
        .zip(&hits)
        .map(|(r, h)| Sample {
            dir: r.dir.normalize(),
            surface: h.as_ref().map(|h| surface_of(st, r, h)),
            bounce: None,
        })
        .collect();
    add(
        &c.hits,
        samples.iter().filter(|s| s.surface.is_some()).count(),
    );

    // Specular bounces (only for specular materials).
    let mut bounce_rays = Vec::new();
    let mut bounce_of = Vec::new();
    for (i, s) in samples.iter().enumerate() {
        if let Some(surf) = &s.surface {
            if st.specularity[surf.material as usize] > 0.0 {
                let d = s.dir - 2.0 * s.dir.dot(surf.normal) * surf.normal;
                bounce_rays.push(Ray::new(
                    offset_origin(surf.point, surf.normal),
                    d.normalize(),
                ));
                bounce_of.push(i);
            } else {
                add(&c.spec_skipped, 1);
            }
        }
    }
    let mut bhits = vec![None; bounce_rays.len()];
    tracer.intersect(&bounce_rays, &mut bhits);
    add(&c.specular, bounce_rays.len());
    for ((r, h), &i) in bounce_rays.iter().zip(&bhits).zip(&bounce_of) {
        samples[i].bounce = Some((r.dir, h.as_ref().map(|h| surface_of(st, r, h))));
    }

    // Solar-history rays from every surface point; packets of 16 points
    // share one sun direction.
    let mut points: Vec<(usize, bool)> = Vec::new(); // (sample, is_background)
    for (i, s) in samples.iter().enumerate() {
        if s.surface.is_some() {
            points.push((i, false));
        }
        if let Some((_, Some(_))) = &s.bounce {
            points.push((i, true));
        }
    }
    let surf = |samples: &[Sample], (i, bg): (usize, bool)| -> Surface {
        if bg {
            samples[i]
                .bounce
                .as_ref()
                .and_then(|b| b.1.clone())
                .expect("background point")
        } else {
            samples[i].surface.clone().expect("surface point")
        }
    };
    let pts: Vec<Surface> = points.iter().map(|&p| surf(&samples, p)).collect();
    let nsun = cond.suns.len();
    let mut lit = vec![vec![false; nsun]; pts.len()];
    for chunk in (0..pts.len()).collect::<Vec<_>>().chunks(16) {
        for (k, sun) in cond.suns.iter().enumerate() {
            if !sun.up {
                add(&c.sun_down, chunk.len());
                continue;
            }
            let mut rays = Vec::with_capacity(16);
            let mut which = Vec::with_capacity(16);
            for &p in chunk {
                if pts[p].normal.dot(sun.dir) > 0.0 {
                    rays.push(Ray::new(
                        offset_origin(pts[p].point, pts[p].normal),
                        sun.dir,
                    ));
                    which.push(p);
                } else {
                    add(&c.away, 1);
                }
            }
            if rays.is_empty() {
                continue;
            }
            let mut blocked = vec![false; rays.len()];
            tracer.occluded(&rays, &mut blocked);
            add(&c.solar, rays.len());
            for (&p, b) in which.iter().zip(blocked) {
                lit[p][k] = !b;
            }
        }
    }
    for ((i, bg), history) in points.into_iter().zip(lit) {
        let target = if bg {
            samples[i].bounce.as_mut().and_then(|b| b.1.as_mut())
        } else {
            samples[i].surface.as_mut()
        };
        if let Some(s) = target {
            s.history = history;
        }
    }
    samples
}

/// Step 4: the temperature of a surface from the memoised thermal model.
fn temperature(st: &Static, cond: &Conditions, s: &Surface) -> anyhow::Result<f64> {
    let hist = SunHistory {
        start_s: 0,
        interval_s: cond.interval_s,
        sunlit: s.history.clone(),
    };
    let o = Orientation::from_normal_enu(s.normal.as_dvec3().to_array());
    let m = s.material as usize;
    cond.cache
        .surface_temp_k(s.material, &st.slabs[m], o, Some(&hist), 0, &cond.forcing)
        .map_err(|e| {
            anyhow::anyhow!(
                "thermal model, material {}: {e}",
                st.scene.materials[m].name
            )
        })
}

/// A rendered frame: the output planes (at output resolution) and stats.
pub struct Frame {
    pub planes: Planes,
    pub stats: Stats,
    /// Per supersampled sample (tile order is undone: row-major).
    pub samples: Vec<Sample>,
    pub sample_width: u32,
}

/// Traces a frame's geometry and histories and solves temperatures
/// (steps 1-4); returns the samples in row-major order of the supersampled
/// image.
pub fn trace_frame(
    st: &Static,
    cond: &Conditions,
    stats: &mut Stats,
) -> anyhow::Result<(Vec<Sample>, u32, u32)> {
    let cam = sample_camera(st);
    let (w, h) = (cam.width, cam.height);
    let t0 = Instant::now();
    // Blocks of BLOCK×BLOCK pixels, each in 4x4 tile order.
    let mut blocks = Vec::new();
    for by in (0..h).step_by(BLOCK as usize) {
        for bx in (0..w).step_by(BLOCK as usize) {
            let (bw, bh) = (BLOCK.min(w - bx), BLOCK.min(h - by));
            let px: Vec<(u32, u32)> = crate::sensor::camera::tile_order(bw, bh, 4)
                .into_iter()
                .map(|(x, y)| (bx + x, by + y))
                .collect();
            blocks.push(px);
        }
    }
    let counters = Counters::default();
    let traced: Vec<Vec<Sample>> = blocks
        .par_iter()
        .map(|px| trace_block(st, cond, &cam, px, &counters))
        .collect();
    let mut samples: Vec<Option<Sample>> = vec![None; (w * h) as usize];
    for (px, ss) in blocks.iter().zip(traced) {
        for (&(x, y), s) in px.iter().zip(ss) {
            samples[(y * w + x) as usize] = Some(s);
        }
    }
    let mut samples: Vec<Sample> = samples
        .into_iter()
        .map(|s| s.expect("every pixel traced"))
        .collect();
    stats.seconds.trace = t0.elapsed().as_secs_f64();
    stats.samples = samples.len() as u64;
    stats.primary_rays = counters.primary.load(Ordering::Relaxed);
    stats.primary_hits = counters.hits.load(Ordering::Relaxed);
    stats.specular_rays = counters.specular.load(Ordering::Relaxed);
    stats.specular_skipped_diffuse = counters.spec_skipped.load(Ordering::Relaxed);
    stats.solar_rays = counters.solar.load(Ordering::Relaxed);
    stats.solar_skipped_sun_down = counters.sun_down.load(Ordering::Relaxed);
    stats.solar_skipped_facing_away = counters.away.load(Ordering::Relaxed);

    let t1 = Instant::now();
    let before = cond.cache.stats();
    samples
        .par_iter_mut()
        .try_for_each(|s| -> anyhow::Result<()> {
            if let Some(surf) = s.surface.as_mut() {
                surf.temp_k = temperature(st, cond, surf)?;
            }
            if let Some((_, Some(bg))) = s.bounce.as_mut() {
                bg.temp_k = temperature(st, cond, bg)?;
            }
            Ok(())
        })?;
    let after = cond.cache.stats();
    stats.thermal_solves = after.misses - before.misses;
    stats.thermal_cache_hits = after.hits - before.hits;
    stats.seconds.thermal = t1.elapsed().as_secs_f64();
    Ok((samples, w, h))
}

/// Renders one frame (steps 1-5 and the sensor).
pub fn render(st: &Static, cond: &Conditions) -> anyhow::Result<Frame> {
    let mut stats = Stats {
        spectral_bins: st.band.len(),
        ..Default::default()
    };
    let (samples, w, h) = trace_frame(st, cond, &mut stats)?;
    let t2 = Instant::now();
    let ctx = pixel::RadiometryContext::new(st, cond)?;
    let results: Vec<pixel::SampleResult> = samples
        .par_iter()
        .map(|s| ctx.evaluate(s))
        .collect::<anyhow::Result<_>>()?;
    stats.seconds.radiometry = t2.elapsed().as_secs_f64();
    let t3 = Instant::now();
    let n = st.scene.scene.render.supersample.max(1);
    let planes = pixel::assemble(st, &samples, &results, w, h, n, cond)?;
    stats.seconds.sensor = t3.elapsed().as_secs_f64();
    Ok(Frame {
        planes,
        stats,
        samples,
        sample_width: w,
    })
}

/// Angle between two unit vectors, degrees.
pub fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    (a.as_dvec3().dot(b.as_dvec3()))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// Zenith angle of a direction, degrees.
pub fn zenith_deg(d: Vec3) -> f64 {
    angle_deg(d.normalize(), Vec3::Z)
}

/// Azimuth of a direction, clockwise from north, degrees in [0, 360).
pub fn azimuth_deg(d: DVec3) -> f64 {
    d.x.atan2(d.y).to_degrees().rem_euclid(360.0)
}
