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

pub mod adaptive;
pub mod assemble;
pub mod atmosphere;
pub mod cancel;
pub mod image;
pub mod memory;
pub mod pixel;
pub mod planes;
pub mod plausible;
pub mod prepare;
pub mod probe;
pub mod sequence;
pub mod sunflags;

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use serde::Serialize;

use crate::sensor::camera::Camera;
use crate::therm::balance::Orientation;
use crate::therm::cache::{FacetParts, HistoryRef, ThermCache, ThermMemo, ThermQuery};
use crate::therm::slab::{ThermError, ThermSolution};
use crate::trace::offset::offset_origin;
use crate::trace::{Hit, Ray};
pub use image::{Rendered, render_at, render_conditions, render_scene};
use planes::Planes;
pub use prepare::{Conditions, Reused, Static, derive_static, prepare_conditions, prepare_static};
use sunflags::SunFlags;

/// A surface point seen by a ray: a compact record (no heap allocation for
/// histories up to [`sunflags::INLINE_SWITCHES`] transitions).
#[derive(Clone, Debug, Default)]
pub struct Surface {
    pub prim: u32,
    pub material: u32,
    pub point: Vec3,
    /// Unit geometric normal, facing the incoming ray.
    pub normal: Vec3,
    /// Distance along the incoming ray, m.
    pub range_m: f32,
    /// Sun/shadow flag per history sample (sunlit or not).
    pub history: SunFlags,
    /// Surface temperature at the image time, K (filled in step 4).
    pub temp_k: f64,
}

impl Surface {
    /// Sunlit at the image time (the last history sample).
    pub fn sun_now(&self) -> bool {
        self.history.last().unwrap_or(false)
    }

    /// The facet side the record is on: its facet and the bits of its
    /// normal (which faces the incoming ray). What is a function of the
    /// side alone (orientation, blocked sky) may be kept under this key.
    pub fn side(&self) -> (u32, [u32; 3]) {
        (self.prim, self.normal.to_array().map(f32::to_bits))
    }
}

/// A worker's one-entry memo of a pure function: the value for the last
/// key asked for (neighbouring samples mostly repeat a key, so a repeat
/// skips the computation and gives the same value).
#[derive(Debug)]
pub(crate) struct LastKey<K, V>(Option<(K, V)>);

impl<K, V> Default for LastKey<K, V> {
    fn default() -> Self {
        LastKey(None)
    }
}

impl<K: PartialEq, V: Copy> LastKey<K, V> {
    /// The value for `key`: the kept one on a repeat, else `f()` (kept).
    pub(crate) fn get_or(&mut self, key: K, f: impl FnOnce() -> V) -> V {
        match &self.0 {
            Some((last, v)) if *last == key => *v,
            _ => {
                let v = f();
                self.0 = Some((key, v));
                v
            }
        }
    }
}

/// What a (sub-)pixel's ray found.
#[derive(Clone, Debug, Default)]
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
    /// Adaptive histories (`render.adaptive_histories`): output pixels
    /// whose history came from their 4 corner samples alone, and pixels
    /// refined to every one of their n×n samples.
    pub history_pixels_corners: u64,
    pub history_pixels_refined: u64,
    /// Adaptive sampling (`render.sampling = "adaptive"`): output pixels
    /// that kept their one coarse sample, pixels refined to every sample of
    /// their grid, and that grid's side (`render.supersample`; 0 for a
    /// uniform render).
    pub adaptive_pixels_coarse: u64,
    pub adaptive_pixels_refined: u64,
    pub adaptive_refined_density: u32,
    /// Adaptive sampling: cells (4×4 per refined pixel) refined to every
    /// sample, cells that kept their one first-level sample, and samples
    /// that took a neighbouring sample's sun/shadow history after their own
    /// sun rays of the last hour agreed with it.
    pub adaptive_cells_refined: u64,
    pub adaptive_cells_coarse: u64,
    pub adaptive_histories_shared: u64,
    pub thermal_solves: u64,
    pub thermal_cache_hits: u64,
    /// Over the distinct solves: accepted and rejected march steps, Newton
    /// iterations, and the core-seconds spent solving (summed over
    /// threads; the rest of `seconds.thermal` is keys and lookups).
    pub thermal_steps: u64,
    pub thermal_steps_rejected: u64,
    pub thermal_newton_iterations: u64,
    pub thermal_solve_core_s: f64,
    /// March states kept at checkpoints, and solves resumed from one
    /// (`therm::cache`: histories that begin alike share their march).
    pub thermal_checkpoints: u64,
    pub thermal_resumed: u64,
    /// Samples whose band integral was evaluated (uniform pixels evaluate
    /// one of their n×n samples).
    pub radiometry_samples: u64,
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
    pixels_corners: AtomicU64,
    pixels_refined: AtomicU64,
    cells_refined: AtomicU64,
    cells_coarse: AtomicU64,
    donated: AtomicU64,
}

fn add(c: &AtomicU64, n: usize) {
    c.fetch_add(n as u64, Ordering::Relaxed);
}

/// Pixels per block side (in supersampled pixels) handed to one rayon task.
const BLOCK: u32 = 16;

/// A rayon pool with FTZ/DAZ set in every worker (as Embree recommends);
/// `threads`: the number of workers (default: all cores). Renders give the
/// same result in any pool.
pub fn thread_pool(threads: Option<u32>) -> anyhow::Result<rayon::ThreadPool> {
    let mut b = rayon::ThreadPoolBuilder::new()
        .start_handler(|_| crate::trace::embree::set_thread_ftz_daz());
    if let Some(n) = threads {
        crate::bounds::args::THREADS
            .check(n.into())
            .map_err(anyhow::Error::msg)?;
        b = b.num_threads(n as usize);
    }
    Ok(b.build()?)
}

/// The supersampled camera in the tracer's local frame: n×n rays per
/// output pixel.
pub fn sample_camera(st: &Static) -> Camera {
    let n = st.scene.scene.render.supersample().max(1);
    st.scene.local_camera.supersampled(n)
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
        history: SunFlags::default(),
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
    let mut samples = trace_geometry(st, cam, pixels, c);
    // Solar histories: of every surface point, or (adaptive) of the
    // corner samples of each pixel first, then of the other samples only
    // in pixels whose corners differ.
    let n = st.scene.scene.render.supersample().max(1);
    let uniform = st.scene.scene.render.sampling == crate::scene::spec::Sampling::Uniform;
    if st.scene.scene.render.adaptive_histories && uniform && n >= 3 && BLOCK.is_multiple_of(n) {
        adaptive_histories(st, cond, pixels, n, &mut samples, c);
    } else {
        trace_sample_histories(st, cond, &mut samples, |_| true, c);
    }
    samples
}

/// Traces the sun/shadow histories of the surface points of the samples
/// `pick` selects (by index) and of every specular-bounce background point
/// (each needs its own), in sample order.
fn trace_sample_histories(
    st: &Static,
    cond: &Conditions,
    samples: &mut [Sample],
    pick: impl Fn(usize) -> bool,
    c: &Counters,
) {
    let mut targets: Vec<&mut Surface> = Vec::with_capacity(samples.len());
    for (i, s) in samples.iter_mut().enumerate() {
        if pick(i)
            && let Some(surf) = s.surface.as_mut()
        {
            targets.push(surf);
        }
        if let Some((_, Some(bg))) = s.bounce.as_mut() {
            targets.push(bg);
        }
    }
    trace_histories(st, cond, &mut targets, c);
}

/// Steps 1-2 for a list of (supersampled) pixels: primary rays and
/// specular bounces, no histories yet.
fn trace_geometry(st: &Static, cam: &Camera, pixels: &[(u32, u32)], c: &Counters) -> Vec<Sample> {
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
    let mut skipped = 0;
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
                skipped += 1;
            }
        }
    }
    add(&c.spec_skipped, skipped);
    let mut bhits = vec![None; bounce_rays.len()];
    tracer.intersect(&bounce_rays, &mut bhits);
    add(&c.specular, bounce_rays.len());
    for ((r, h), &i) in bounce_rays.iter().zip(&bhits).zip(&bounce_of) {
        samples[i].bounce = Some((r.dir, h.as_ref().map(|h| surface_of(st, r, h))));
    }
    samples
}

/// Adaptive solar histories for one block of `n`×`n`-sampled pixels
/// (`BLOCK` a multiple of `n`, so a block holds whole pixels): the four
/// corner samples of each pixel (and every specular background) are traced
/// first; a pixel whose samples all see one facet, none specular, and whose
/// corners have one history gives that history to its other samples
/// (an edge of a shadow that crossed the facet at any time of the history
/// would, unless narrower than the corners' spacing, have changed some
/// corner's history); every other pixel traces all its samples.
fn adaptive_histories(
    st: &Static,
    cond: &Conditions,
    pixels: &[(u32, u32)],
    n: u32,
    samples: &mut [Sample],
    c: &Counters,
) {
    let bx = pixels.iter().map(|p| p.0).min().unwrap_or(0);
    let by = pixels.iter().map(|p| p.1).min().unwrap_or(0);
    let per_row = (BLOCK / n) as usize;
    let pix_of = |i: usize| {
        let (x, y) = pixels[i];
        ((y - by) / n) as usize * per_row + ((x - bx) / n) as usize
    };
    let corner = |i: usize| {
        let (x, y) = pixels[i];
        (x % n == 0 || x % n == n - 1) && (y % n == 0 || y % n == n - 1)
    };
    trace_sample_histories(st, cond, samples, corner, c);
    let npix = per_row * per_row;
    // Each pixel's first corner sample with a surface.
    let mut first: Vec<Option<usize>> = vec![None; npix];
    for i in (0..samples.len()).filter(|&i| corner(i)) {
        let p = pix_of(i);
        if first[p].is_none() && samples[i].surface.is_some() {
            first[p] = Some(i);
        }
    }
    let mut uniform: Vec<bool> = first.iter().map(Option::is_some).collect();
    let mut count = vec![0usize; npix];
    for (i, s) in samples.iter().enumerate() {
        let p = pix_of(i);
        count[p] += 1;
        let Some(f) = first[p] else { continue };
        let r = samples[f]
            .surface
            .as_ref()
            .expect("a first corner has a surface");
        uniform[p] &= s.bounce.is_none()
            && s.surface.as_ref().is_some_and(|surf| {
                surf.prim == r.prim && (!corner(i) || surf.history == r.history)
            });
    }
    let (mut refined, mut coarse) = (0, 0);
    for (u, &k) in uniform.iter_mut().zip(&count) {
        // A pixel cut by the block's edge (none when BLOCK % n == 0) is
        // refined.
        *u &= k == (n * n) as usize;
        if *u {
            coarse += 1;
        } else if k > 0 {
            refined += 1;
        }
    }
    let shared: Vec<Option<SunFlags>> = (uniform.iter().zip(&first))
        .map(|(&u, f)| {
            f.filter(|_| u)
                .and_then(|f| samples[f].surface.as_ref())
                .map(|s| s.history.clone())
        })
        .collect();
    let mut targets: Vec<&mut Surface> = Vec::new();
    for (i, s) in samples.iter_mut().enumerate() {
        if corner(i) {
            continue;
        }
        let p = pix_of(i);
        if let Some(surf) = s.surface.as_mut() {
            match &shared[p] {
                Some(h) => surf.history = h.clone(),
                None => targets.push(surf),
            }
        }
    }
    trace_histories(st, cond, &mut targets, c);
    add(&c.pixels_corners, coarse);
    add(&c.pixels_refined, refined);
}

/// Step 3 for a set of surface points: their sun/shadow histories.
fn trace_histories(st: &Static, cond: &Conditions, targets: &mut [&mut Surface], c: &Counters) {
    // Solar-history rays from every surface point (primary and
    // background): groups of 16 points, one packet per group whose origins
    // are written once and traced toward each sun in turn (the points that
    // face it); each open answer sets a bit of the point's history (in a
    // flat word array, copied into each history at the end).
    let nsun = cond.suns.len();
    let tracer = st.tracer.as_ref();
    let origins: Vec<Vec3> = targets
        .iter()
        .map(|t| offset_origin(t.point, t.normal))
        .collect();
    let normals: Vec<Vec3> = targets.iter().map(|t| t.normal).collect();
    // The traced samples (every `coarse_every`-th) whose sun is up, and
    // its directions.
    let every = cond.coarse_every.max(1);
    let (up, dirs): (Vec<usize>, Vec<Vec3>) = (cond.suns.iter().enumerate())
        .filter(|(k, sun)| sun.up && k % every == 0)
        .map(|(k, sun)| (k, sun.dir))
        .unzip();
    let nw = nsun.div_ceil(64);
    let mut words = vec![0u64; targets.len() * nw];
    let (mut away, mut solar) = (0, 0);
    let down = targets.len() * (nsun.div_ceil(every) - up.len());
    let mut active = vec![0u16; up.len()];
    let mut blocked = vec![0u16; up.len()];
    for start in (0..targets.len()).step_by(16) {
        let chunk = start..(start + 16).min(targets.len());
        // The points of the group that face each sun (lane bits).
        for (act, &dir) in active.iter_mut().zip(&dirs) {
            *act = (normals[chunk.clone()].iter().enumerate())
                .filter(|(_, n)| n.dot(dir) > 0.0)
                .fold(0, |m, (lane, _)| m | 1 << lane);
            let facing = act.count_ones() as usize;
            solar += facing;
            away += chunk.len() - facing;
        }
        tracer.occluded_fan(&origins[chunk.clone()], &dirs, &active, &mut blocked);
        for ((&k, &act), &b) in up.iter().zip(&active).zip(&blocked) {
            let (word, bit) = (k / 64, 1u64 << (k % 64));
            let mut open = act & !b;
            while open != 0 {
                let lane = open.trailing_zeros() as usize;
                words[(start + lane) * nw + word] |= bit;
                open &= open - 1;
            }
        }
    }
    if every == 1 {
        for (p, t) in targets.iter_mut().enumerate() {
            t.history = SunFlags::from_words(&words[p * nw..(p + 1) * nw], nsun);
        }
    } else {
        let bit = |p: usize, k: usize| words[p * nw + k / 64] >> (k % 64) & 1 == 1;
        // Between two traced samples whose flags differ, the transition is
        // found by bisection on the fine grid: all pending intervals of the
        // block are halved together, one batch of shadow rays per round.
        // (lo, hi, flag at lo, target): flag(lo) != flag(hi), the switch is
        // at some index in (lo, hi].
        let mut pending: Vec<(usize, usize, bool, usize)> = Vec::new();
        let mut switches: Vec<Vec<u32>> = vec![Vec::new(); targets.len()];
        for p in 0..targets.len() {
            let mut k = 0;
            while k + every < nsun {
                let (a, b) = (bit(p, k), bit(p, k + every));
                if a != b {
                    pending.push((k, k + every, a, p));
                }
                k += every;
            }
        }
        let mut rays = Vec::new();
        let mut ray_of = Vec::new();
        let mut blocked = Vec::new();
        while pending.iter().any(|&(lo, hi, _, _)| hi - lo > 1) {
            rays.clear();
            ray_of.clear();
            for (j, &(lo, hi, _, p)) in pending.iter().enumerate() {
                if hi - lo <= 1 {
                    continue;
                }
                let sun = &cond.suns[(lo + hi) / 2];
                if sun.up && normals[p].dot(sun.dir) > 0.0 {
                    rays.push(Ray::new(origins[p], sun.dir));
                    ray_of.push(j);
                } else if sun.up {
                    away += 1;
                }
            }
            blocked.clear();
            blocked.resize(rays.len(), false);
            tracer.occluded(&rays, &mut blocked);
            solar += rays.len();
            let mut lit = vec![false; pending.len()];
            for (&j, &b) in ray_of.iter().zip(&blocked) {
                lit[j] = !b;
            }
            for (j, e) in pending.iter_mut().enumerate() {
                let (lo, hi, a, _) = *e;
                if hi - lo > 1 {
                    let mid = (lo + hi) / 2;
                    if lit[j] == a {
                        e.0 = mid;
                    } else {
                        e.1 = mid;
                    }
                }
            }
        }
        // Pending intervals were pushed in sample order per target.
        for &(_, hi, _, p) in &pending {
            switches[p].push(hi as u32);
        }
        for (p, t) in targets.iter_mut().enumerate() {
            t.history = SunFlags::from_switches(bit(p, 0), &switches[p], nsun);
        }
    }
    add(&c.sun_down, down);
    add(&c.away, away);
    add(&c.solar, solar);
}

/// Step 4: the memoised thermal solution of a surface (with the whole
/// series of flux terms when the cache keeps series).
pub fn thermal_solution(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
) -> anyhow::Result<Arc<ThermSolution>> {
    let m = s.material as usize;
    let keyed = key_history(&s.history, cond.key_recent);
    let q = therm_query(
        st,
        cond,
        s,
        keyed.as_ref().unwrap_or(&s.history),
        &mut KeyMemo::default(),
    );
    cond.cache
        .solve_query(&q, &cond.slabs[m], &cond.forcing)
        .map_err(|e| therm_error(st, m, e))
}

/// The key parts of the last facet side and height a worker saw: pure
/// functions of [`Surface::side`] with its blocked sky, and of z, that
/// neighbouring samples mostly share (a repeat skips the orientation's
/// acos/atan2 and the height's log; the key is the same).
#[derive(Default)]
struct KeyMemo {
    facet: LastKey<((u32, [u32; 3]), u64), FacetParts>,
    height: LastKey<u32, i32>,
}

/// The history a thermal key stands for: `h` with each transition older
/// than `recent` samples moved to the nearest multiple (in samples before
/// the image time) of a quantum that doubles with each doubling of its
/// age: `q = 2^j` samples for ages in `[recent·2^(j−1), recent·2^j)`. Two
/// transitions moved onto one sample cancel (a blip shorter than the
/// quantum is dropped); one moved before the first sample flips the first
/// flag. `recent` is a power of two ≥ 2 (so the band edges are multiples
/// of both quanta and the order is kept); 0 leaves `h` as it is (`None`).
///
/// Why: a shift δ of a transition of flux ΔF at age A changes the surface
/// temperature by about ΔF·δ/(e·√(πA)) (semi-infinite solid of thermal
/// effusivity e; Carslaw & Jaeger §2.9) while A is short against the
/// surface's coupling time, and faster than 1/√A beyond it; so the
/// tolerable δ grows with age, and the quantum can grow with it. Histories
/// that differ only in when an old shadow came or went then share one key
/// and one solve; the solve uses the keyed history, so the result is a
/// function of the key alone (deterministic).
pub fn key_history(h: &SunFlags, recent: usize) -> Option<SunFlags> {
    let sw = h.switches();
    let len = h.len();
    if recent < 2 || len < 2 || sw.is_empty() {
        return None;
    }
    let last = len - 1;
    if sw.iter().all(|&s| last - (s as usize) < recent) {
        return None;
    }
    let mut first = h.get(0);
    let mut out: smallvec::SmallVec<[u32; sunflags::INLINE_SWITCHES]> = smallvec::SmallVec::new();
    for &s in sw {
        let age = last - s as usize;
        let moved = if age < recent {
            age
        } else {
            // quantum 2^j with recent·2^(j−1) ≤ age < recent·2^j
            let j = (age / recent).ilog2() + 1;
            let q = 1usize << j;
            (age + q / 2) / q * q
        };
        if moved >= last {
            // Before the first sample: the first flag flips.
            first = !first;
            continue;
        }
        let s2 = (last - moved) as u32;
        if out.last() == Some(&s2) {
            out.pop();
        } else {
            out.push(s2);
        }
    }
    Some(SunFlags::from_switches(first, &out, len))
}

/// The thermal cache's key of a surface (borrows its history, or the keyed
/// history [`key_history`] made of it, which the caller keeps).
fn therm_query<'a>(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
    history: &'a SunFlags,
    memo: &mut KeyMemo,
) -> ThermQuery<'a> {
    let blocked = st.blocked_sky(s.prim, s.normal, s.point);
    let facet = memo.facet.get_or((s.side(), blocked.to_bits()), || {
        cond.cache.facet_parts(
            Orientation::from_normal_enu(s.normal.as_dvec3().to_array()),
            blocked,
        )
    });
    let height_q = memo.height.get_or(s.point.z.to_bits(), || {
        ThermCache::quantise_height(s.point.z as f64 - cond.ground_z_m).0
    });
    cond.cache.query_parts(
        s.material,
        facet,
        Some(HistoryRef {
            start_s: 0,
            interval_s: cond.interval_s,
            sunlit: history.flags(),
        }),
        0,
        height_q,
    )
}

fn therm_error(st: &Static, m: usize, e: ThermError) -> anyhow::Error {
    anyhow::anyhow!(
        "thermal model, material {}: {e}",
        st.scene.materials[m].name
    )
}

/// A worker's memo for step 4: the thermal cache's last-key memo, the
/// key parts' ([`KeyMemo`]) and the last surface's inputs ([`LastInputs`]).
#[derive(Default)]
struct TempMemo {
    therm: ThermMemo,
    keys: KeyMemo,
    last: Option<LastInputs>,
}

/// What the thermal key of a surface is a function of — its material, facet
/// side (orientation), quantised blocked sky and height, and raw history —
/// and the temperature they gave. A surface with the same inputs has the
/// same key (`key_history` and the key parts are pure functions of them),
/// so it takes the temperature without building the key: neighbouring
/// samples of one facet and one (often shared) history mostly repeat them.
struct LastInputs {
    material: u32,
    side: (u32, [u32; 3]),
    blocked_q: i32,
    height_q: i32,
    history: SunFlags,
    temp_k: f64,
}

/// Step 4: the temperature of a surface at the image time, K (through
/// the worker's memo).
fn temperature(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
    memo: &mut TempMemo,
) -> anyhow::Result<f64> {
    let side = s.side();
    let blocked_q = ThermCache::quantise_blocked(st.blocked_sky(s.prim, s.normal, s.point));
    let height_q = memo.keys.height.get_or(s.point.z.to_bits(), || {
        ThermCache::quantise_height(s.point.z as f64 - cond.ground_z_m).0
    });
    if let Some(l) = &memo.last
        && l.material == s.material
        && l.side == side
        && l.blocked_q == blocked_q
        && l.height_q == height_q
        && l.history == s.history
    {
        memo.therm.hits += 1;
        return Ok(l.temp_k);
    }
    let t = temperature_keyed(st, cond, s, memo)?;
    memo.last = Some(LastInputs {
        material: s.material,
        side,
        blocked_q,
        height_q,
        history: s.history.clone(),
        temp_k: t,
    });
    Ok(t)
}

/// [`temperature`] through the surface's thermal key.
fn temperature_keyed(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
    memo: &mut TempMemo,
) -> anyhow::Result<f64> {
    let m = s.material as usize;
    let keyed = key_history(&s.history, cond.key_recent);
    let q = therm_query(
        st,
        cond,
        s,
        keyed.as_ref().unwrap_or(&s.history),
        &mut memo.keys,
    );
    cond.cache
        .surface_temp_k_memo(&q, &cond.slabs[m], &cond.forcing, &mut memo.therm)
        .map_err(|e| therm_error(st, m, e))
}

/// A rendered frame: the output planes (at output resolution) and stats.
pub struct Frame {
    pub planes: Planes,
    pub stats: Stats,
    /// Per supersampled sample (tile order is undone: row-major).
    pub samples: Vec<Sample>,
    pub sample_width: u32,
}

/// A render stage, as reported to a progress callback.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Steps 1-3 (rays); counted in blocks.
    Trace,
    /// Step 4 (temperatures); counted in samples.
    Thermal,
    /// Step 5 (radiometry); counted in samples.
    Radiometry,
}

/// Progress of a render: `done` of `total` units of `stage` are finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    pub stage: Stage,
    pub done: u64,
    pub total: u64,
}

/// An optional progress callback (called from worker threads, in any
/// order; `None` costs nothing).
pub type ProgressFn<'a> = Option<&'a (dyn Fn(Progress) + Sync)>;

/// Samples per progress report in the thermal and radiometry stages.
const PROGRESS_CHUNK: usize = 1024;

/// The supersampled pixels of block (`bx`, `by`) (its top-left sample
/// pixel) of a `w`×`h` sample image, in 4x4 tile order: the packets a frame
/// traces.
fn block_pixels(bx: u32, by: u32, w: u32, h: u32) -> Vec<(u32, u32)> {
    let (bw, bh) = (BLOCK.min(w - bx), BLOCK.min(h - by));
    crate::sensor::camera::tile_order(bw, bh, 4)
        .into_iter()
        .map(|(x, y)| (bx + x, by + y))
        .collect()
}

/// A stage's progress, counted across the bands of a frame.
struct StageProgress<'a> {
    report: ProgressFn<'a>,
    stage: Stage,
    done: AtomicU64,
    total: u64,
}

impl<'a> StageProgress<'a> {
    fn new(report: ProgressFn<'a>, stage: Stage, total: u64) -> Self {
        StageProgress {
            report,
            stage,
            done: AtomicU64::new(0),
            total,
        }
    }

    /// `n` more units done.
    fn add(&self, n: u64) {
        if let Some(f) = self.report {
            let d = self.done.fetch_add(n, Ordering::Relaxed) + n;
            f(Progress {
                stage: self.stage,
                done: d,
                total: self.total,
            });
        }
    }
}

impl Counters {
    /// Adds the ray counters to `stats`.
    fn flush(&self, stats: &mut Stats) {
        let get = |c: &AtomicU64| c.load(Ordering::Relaxed);
        stats.primary_rays += get(&self.primary);
        stats.primary_hits += get(&self.hits);
        stats.specular_rays += get(&self.specular);
        stats.specular_skipped_diffuse += get(&self.spec_skipped);
        stats.solar_rays += get(&self.solar);
        stats.solar_skipped_sun_down += get(&self.sun_down);
        stats.solar_skipped_facing_away += get(&self.away);
        stats.history_pixels_corners += get(&self.pixels_corners);
        stats.history_pixels_refined += get(&self.pixels_refined);
        stats.adaptive_cells_refined += get(&self.cells_refined);
        stats.adaptive_cells_coarse += get(&self.cells_coarse);
        stats.adaptive_histories_shared += get(&self.donated);
    }
}

/// Steps 1-3 over blocks of sample pixels (rayon over blocks), each
/// block's samples in its tile order; fills the ray counters of `stats`
/// (added to what is there).
fn trace_blocks(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    blocks: &[Vec<(u32, u32)>],
    stats: &mut Stats,
) -> Vec<Vec<Sample>> {
    let counters = Counters::default();
    let traced = blocks
        .par_iter()
        .map(|px| {
            if cancel::cancelled() {
                return Vec::new();
            }
            trace_block(st, cond, cam, px, &counters)
        })
        .collect();
    counters.flush(stats);
    traced
}

/// Sample rows a band of a frame holds: a multiple of [`BLOCK`] and of
/// the supersampling `n`, about [`BAND_SAMPLES`] samples.
fn band_rows(sample_width: u32, n: u32) -> u32 {
    let gcd = |mut a: u32, mut b: u32| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let unit = BLOCK / gcd(BLOCK, n) * n;
    (band_target() / sample_width.max(1) / unit * unit).max(unit)
}

/// [`BAND_SAMPLES`], or the environment's `IRSIG_BAND_SAMPLES` (a test
/// knob: results do not depend on it, which tests check with small bands).
fn band_target() -> u32 {
    static TARGET: std::sync::OnceLock<u32> = std::sync::OnceLock::new();
    *TARGET.get_or_init(|| {
        std::env::var("IRSIG_BAND_SAMPLES")
            .ok()
            .and_then(|v| v.parse().ok())
            .filter(|&v| v > 0)
            .unwrap_or(BAND_SAMPLES)
    })
}

/// Samples a band of a frame `sample_width` samples wide holds with
/// supersampling `n` (the most samples a render holds at once).
pub fn band_samples(sample_width: u32, n: u32) -> u64 {
    band_rows(sample_width, n) as u64 * sample_width as u64
}

/// Samples per band: a frame is traced, solved and turned into plane rows
/// one band of sample rows at a time, so memory holds one band of
/// samples (about 15-30 MB; adaptive sampling: two coarse bands and a
/// chunk of refined pixels' samples) besides the planes. 2^17, not 2^18:
/// the default 2048² airfield render peaked at 645 MiB with 2^18 and
/// peaks at 578 MiB with 2^17 (the same bits; issue 29's 0.6 GiB target),
/// while a band still holds hundreds of blocks for the workers.
const BAND_SAMPLES: u32 = 1 << 17;

/// The bands of a frame's `sample_height` rows: (first, end) sample rows.
fn bands(sample_width: u32, sample_height: u32, n: u32) -> Vec<(u32, u32)> {
    let rows = band_rows(sample_width, n);
    (0..sample_height)
        .step_by(rows as usize)
        .map(|y0| (y0, (y0 + rows).min(sample_height)))
        .collect()
}

/// Steps 1-3 for sample rows `y0..y1` (`y0` a multiple of [`BLOCK`]) into
/// `out`, in row-major order: rows of blocks in parallel, the blocks of a row in
/// parallel, each block's task moving its samples straight to their places
/// (no whole-frame reorder).
fn trace_band(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    (y0, y1): (u32, u32),
    c: &Counters,
    progress: &StageProgress,
    out: &mut Vec<Sample>,
) {
    let (w, h) = (cam.width_px, cam.height_px);
    // The buffer of the band before is reused: every slot is overwritten,
    // so only a longer band allocates (and fills) new samples.
    out.resize(((y1 - y0) * w) as usize, Sample::default());
    out.par_chunks_mut((BLOCK * w) as usize)
        .enumerate()
        .for_each(|(r, rows)| {
            let by = y0 + r as u32 * BLOCK;
            // Each block's BLOCK-wide segment of each of these rows: the
            // block's task moves its samples there while they are hot.
            let mut segments: Vec<_> = rows
                .chunks_mut(w as usize)
                .map(|row| row.chunks_mut(BLOCK as usize))
                .collect();
            let blocks: Vec<(u32, Vec<&mut [Sample]>)> = (0..w)
                .step_by(BLOCK as usize)
                .map(|bx| {
                    let dest = segments.iter_mut().filter_map(Iterator::next).collect();
                    (bx, dest)
                })
                .collect();
            blocks.into_par_iter().for_each(|(bx, mut dest)| {
                if cancel::cancelled() {
                    return;
                }
                let px = block_pixels(bx, by, w, h);
                let traced = trace_block(st, cond, cam, &px, c);
                progress.add(1);
                for (&(x, y), s) in px.iter().zip(traced) {
                    dest[(y - by) as usize][(x - bx) as usize] = s;
                }
            });
        });
}

/// Step 4 for every surface (primary and background) of `samples`.
fn solve_temperatures(
    st: &Static,
    cond: &Conditions,
    samples: &mut [Sample],
    stats: &mut Stats,
    progress: &StageProgress,
) -> anyhow::Result<()> {
    let t1 = Instant::now();
    let before = cond.cache.stats();
    samples
        .par_chunks_mut(PROGRESS_CHUNK)
        .try_for_each(|chunk| -> anyhow::Result<()> {
            cancel::check()?;
            let mut memo = TempMemo::default();
            let solved = chunk.iter_mut().try_for_each(|s| -> anyhow::Result<()> {
                if let Some(surf) = s.surface.as_mut() {
                    surf.temp_k = temperature(st, cond, surf, &mut memo)?;
                }
                if let Some((_, Some(bg))) = s.bounce.as_mut() {
                    bg.temp_k = temperature(st, cond, bg, &mut memo)?;
                }
                Ok(())
            });
            cond.cache.absorb_memo(&memo.therm);
            solved?;
            progress.add(chunk.len() as u64);
            Ok(())
        })?;
    let after = cond.cache.stats();
    stats.thermal_solves += after.misses - before.misses;
    stats.thermal_cache_hits += after.hits - before.hits;
    stats.thermal_steps += after.steps - before.steps;
    stats.thermal_steps_rejected += after.steps_rejected - before.steps_rejected;
    stats.thermal_newton_iterations += after.newton_iterations - before.newton_iterations;
    stats.thermal_solve_core_s += (after.solve_ns - before.solve_ns) as f64 * 1e-9;
    stats.thermal_checkpoints += after.checkpoints - before.checkpoints;
    stats.thermal_resumed += after.resumed - before.resumed;
    stats.seconds.thermal += t1.elapsed().as_secs_f64();
    Ok(())
}

/// The bands of a frame, each traced (steps 1-3) and solved (step 4), handed
/// in order to `each` (band rows, samples); stage times and counters go to
/// `stats`.
fn for_each_band(
    st: &Static,
    cond: &Conditions,
    stats: &mut Stats,
    progress: ProgressFn,
    mut each: impl FnMut(&mut Stats, (u32, u32), &mut Vec<Sample>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let cam = sample_camera(st);
    let (w, h) = (cam.width_px, cam.height_px);
    let n = st.scene.scene.render.supersample().max(1);
    let blocks = (w.div_ceil(BLOCK) * h.div_ceil(BLOCK)) as u64;
    let trace_progress = StageProgress::new(progress, Stage::Trace, blocks);
    let therm_progress = StageProgress::new(progress, Stage::Thermal, (w * h) as u64);
    let counters = Counters::default();
    let mut band = Vec::new();
    for rows in bands(w, h, n) {
        let t0 = Instant::now();
        trace_band(st, cond, &cam, rows, &counters, &trace_progress, &mut band);
        cancel::check()?;
        stats.seconds.trace += t0.elapsed().as_secs_f64();
        stats.samples += band.len() as u64;
        solve_temperatures(st, cond, &mut band, stats, &therm_progress)?;
        each(stats, rows, &mut band)?;
    }
    counters.flush(stats);
    Ok(())
}

/// Traces a frame's geometry and histories and solves temperatures
/// (steps 1-4); returns the samples in row-major order of the supersampled
/// image.
pub fn trace_frame(
    st: &Static,
    cond: &Conditions,
    stats: &mut Stats,
) -> anyhow::Result<(Vec<Sample>, u32, u32)> {
    trace_frame_with(st, cond, stats, None)
}

/// [`trace_frame`] with a progress callback.
pub fn trace_frame_with(
    st: &Static,
    cond: &Conditions,
    stats: &mut Stats,
    progress: ProgressFn,
) -> anyhow::Result<(Vec<Sample>, u32, u32)> {
    let cam = sample_camera(st);
    let (w, h) = (cam.width_px, cam.height_px);
    let mut samples = Vec::with_capacity((w * h) as usize);
    for_each_band(st, cond, stats, progress, |_, _, band| {
        samples.append(band);
        Ok(())
    })?;
    Ok((samples, w, h))
}

/// The supersampled pixels of output pixel (`x`, `y`): n×n of them, row by
/// row (the order in which [`pixel::assemble`] averages them).
pub fn output_pixel_samples(st: &Static, x: u32, y: u32) -> Vec<(u32, u32)> {
    let n = st.scene.scene.render.supersample().max(1);
    (0..n)
        .flat_map(|j| (0..n).map(move |i| (x * n + i, y * n + j)))
        .collect()
}

/// Steps 1-4 for the given supersampled pixels only (e.g. one output
/// pixel's n×n samples, see [`output_pixel_samples`]); returns their
/// samples in the order asked for, exactly as [`trace_frame`] computes
/// them. To get the very same packets (the tracer groups rays by 16 and
/// answers small groups with single-ray queries), the rays of the blocks
/// that hold the pixels are traced (cheap); temperatures are solved for the
/// pixels asked for only.
pub fn trace_samples(
    st: &Static,
    cond: &Conditions,
    pixels: &[(u32, u32)],
    stats: &mut Stats,
) -> anyhow::Result<Vec<Sample>> {
    let cam = sample_camera(st);
    let (w, h) = (cam.width_px, cam.height_px);
    if let Some(&(x, y)) = pixels.iter().find(|&&(x, y)| x >= w || y >= h) {
        anyhow::bail!("sample pixel ({x}, {y}) is outside the {w}x{h} sample image");
    }
    let t0 = Instant::now();
    let origin = |(x, y): (u32, u32)| (x / BLOCK * BLOCK, y / BLOCK * BLOCK);
    let mut origins: Vec<(u32, u32)> = pixels.iter().map(|&p| origin(p)).collect();
    origins.sort_unstable();
    origins.dedup();
    let blocks: Vec<Vec<(u32, u32)>> = origins
        .iter()
        .map(|&(bx, by)| block_pixels(bx, by, w, h))
        .collect();
    let traced = trace_blocks(st, cond, &cam, &blocks, stats);
    cancel::check()?;
    let mut samples = Vec::with_capacity(pixels.len());
    for &p in pixels {
        let b = origins.binary_search(&origin(p)).expect("block traced");
        let k = blocks[b]
            .iter()
            .position(|&q| q == p)
            .expect("pixel in its block");
        samples.push(traced[b][k].clone());
    }
    stats.seconds.trace += t0.elapsed().as_secs_f64();
    stats.samples += samples.len() as u64;
    let quiet = StageProgress::new(None, Stage::Thermal, 0);
    solve_temperatures(st, cond, &mut samples, stats, &quiet)?;
    Ok(samples)
}

/// Renders one frame (steps 1-5 and the sensor).
pub fn render(st: &Static, cond: &Conditions) -> anyhow::Result<Frame> {
    render_with(st, cond, None)
}

/// [`render`] with a progress callback. The frame is rendered band by band
/// (trace, temperatures, then radiometry straight into the plane rows; see
/// [`assemble`]): only [`Static::keep_samples`] keeps the samples. With
/// `render.sampling = "adaptive"`, [`adaptive::render_adaptive`] renders it
/// (and keeps no samples).
pub fn render_with(st: &Static, cond: &Conditions, progress: ProgressFn) -> anyhow::Result<Frame> {
    if st.scene.scene.render.sampling == crate::scene::spec::Sampling::Adaptive
        && st.scene.scene.render.supersample() > 1
    {
        return adaptive::render_adaptive(st, cond, progress);
    }
    let mut stats = Stats {
        spectral_bins: st.band.len(),
        ..Default::default()
    };
    let cam = sample_camera(st);
    let sw = cam.width_px;
    let n = st.scene.scene.render.supersample().max(1);
    let ctx = pixel::RadiometryContext::new(st, cond)?;
    let mut planes = assemble::FramePlanes::new(st, cond, sw / n, cam.height_px / n);
    let radiometry = StageProgress::new(
        progress,
        Stage::Radiometry,
        sw as u64 * cam.height_px as u64,
    );
    let mut kept = Vec::new();
    for_each_band(st, cond, &mut stats, progress, |stats, (y0, _), band| {
        let t2 = Instant::now();
        stats.radiometry_samples +=
            planes.fill_band(&ctx, band, sw, y0 / n, n, &|k| radiometry.add(k))?;
        stats.seconds.radiometry += t2.elapsed().as_secs_f64();
        if st.keep_samples {
            kept.append(band);
        }
        Ok(())
    })?;
    let t3 = Instant::now();
    let planes = planes.finish()?;
    pixel::check_finite(&planes)?;
    stats.seconds.sensor = t3.elapsed().as_secs_f64();
    Ok(Frame {
        planes,
        stats,
        samples: kept,
        sample_width: sw,
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The keyed history: recent transitions kept, old ones moved to the
    /// quantum of their age band, blips shorter than the quantum dropped,
    /// and two histories that differ only in an old transition's sample
    /// share one key.
    #[test]
    fn key_history_coarsens_old_transitions_only() {
        let len = 1001; // last = 1000
        // recent = 8: ages < 8 kept; [8, 16) quantum 2; [16, 32) 4; [32, 64) 8 …
        let h = SunFlags::from_switches(false, &[100, 103, 950, 995], len);
        let k = key_history(&h, 8).expect("old transitions move");
        // ages 900 and 897 (band [512, 1024), quantum 128): both → 896, cancel;
        // age 50 (quantum 8) → 48; age 5 kept.
        assert_eq!(k.switches(), &[952, 995]);
        assert!(!k.get(0));
        // One sample earlier or later, same key.
        let h2 = SunFlags::from_switches(false, &[101, 103, 951, 995], len);
        assert_eq!(key_history(&h2, 8), Some(k.clone()));
        // All recent: unchanged; off: unchanged.
        let r = SunFlags::from_switches(true, &[996, 998], len);
        assert_eq!(key_history(&r, 8), None);
        assert_eq!(key_history(&h, 0), None);
        // A transition moved before the first sample flips the first flag.
        let e = SunFlags::from_switches(true, &[2, 500], len);
        let ke = key_history(&e, 8).unwrap();
        assert!(!ke.get(0));
        assert_eq!(ke.switches(), &[488]); // age 500, quantum 64 → 512
        // Order is kept and every result is a valid history, for every
        // single transition position.
        for s in 1..997u32 {
            for recent in [2usize, 4, 16, 64] {
                let h = SunFlags::from_switches(false, &[s, s + 3], len);
                if let Some(k) = key_history(&h, recent) {
                    assert!(k.switches().windows(2).all(|w| w[0] < w[1]));
                    assert_eq!(k.last(), h.last(), "the image-time flag is kept");
                }
            }
        }
    }
}
