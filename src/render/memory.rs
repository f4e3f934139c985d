//! The peak memory a render will need, estimated from the scene before
//! anything is allocated (issue 17, item 5), and the limit it is checked
//! against (`render.max_memory_mib`, default the machine's memory).
//!
//! The render streams its samples band by band (`render::band_samples`,
//! about 2^17 samples), so at its peak it holds, per sample of one band:
//! the [`Sample`] (its sun/shadow history inline up to
//! [`super::sunflags::INLINE_SWITCHES`] transitions, on the heap beyond) and the output
//! pixel's plane values; per output pixel the output planes; per triangle
//! the geometry and the BVH; per spectral bin the atmosphere spectra; plus
//! the process itself (code, Embree, the atmosphere table: [`BASE_MIB`]).
//! Memory therefore grows with the output pixels (planes), not with the
//! supersampled samples beyond one band. The estimate is checked against the
//! measured peak resident set of real renders in `tests/memory_limit.rs`
//! (within 30 %, docs/reliability.md).

use serde::Serialize;

use super::sample::Sample;
use crate::scene::LoadedScene;

const MIB: f64 = 1024.0 * 1024.0;

/// The process before any scene-sized allocation: code, Embree, the
/// atmosphere table and its resampling, MiB (measured: a 64x64 render of
/// the plate scene peaks at 31 MiB).
pub const BASE_MIB: f64 = 30.0;

/// Output planes per pixel (every plane of a render, f32, and the sensor's
/// working copy) and what the writers add (EXR blocks in flight, PNG
/// quicklook; the EXR is written from the planes themselves): measured
/// 544 MiB peak for airfield 2048² with EXR + PNG + JSON (BENCHMARKS.md).
const PLANE_BYTES_PER_PIXEL: f64 = 24.0 * 4.0 * 1.25;

/// Geometry, BVH (Embree or obvhs) and per-triangle tables, bytes per
/// triangle.
const TRIANGLE_BYTES: f64 = 400.0;

/// A render's estimated peak memory, by part.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MemoryEstimate {
    /// Supersampled samples (width·n × height·n).
    pub samples: u64,
    /// Samples held at once (one band).
    pub samples_held: u64,
    /// Bytes per sample (structs, history, results).
    pub bytes_per_sample: f64,
    /// The samples held, MiB.
    pub samples_mib: f64,
    /// The output planes, MiB.
    pub planes_mib: f64,
    /// The geometry and the tracer's BVH, MiB.
    pub geometry_mib: f64,
    /// The atmosphere spectra of the cached directions ([`spectral_mib`]), MiB.
    pub spectral_mib: f64,
    /// The process before any scene-sized allocation ([`BASE_MIB`]), MiB.
    pub base_mib: f64,
    /// The estimated peak, MiB.
    pub total_mib: f64,
    /// The limit it is checked against, MiB, and where it comes from.
    pub limit_mib: Option<f64>,
    /// Where the limit comes from (`render.max_memory_mib` or the machine's memory).
    pub limit_from: String,
}

/// The band grid the render will use: uniform in wavenumber at
/// `render.spectral_step_cm1` over the response's support; returns the first
/// wavenumber (cm⁻¹), the step and the number of bins (as f64: it is
/// bounded before it is used as a size).
pub fn band_grid(scene: &LoadedScene) -> (f64, f64, f64) {
    let (lo_um, hi_um) = scene.response.support_um();
    let step = scene.scene.render.spectral_step_cm1;
    let first = (1e4 / hi_um / step).floor() * step;
    (first, step, ((1e4 / lo_um - first) / step).ceil() + 1.0)
}

/// Atmosphere spectra held per bin: sky and path spectra of ~100 cached
/// directions, four f64 each, MiB.
pub fn spectral_mib(bins: f64) -> f64 {
    bins * 8.0 * 4.0 * 100.0 / MIB
}

/// The machine's physical memory, MiB (`/proc/meminfo` MemTotal), if known.
pub fn machine_memory_mib() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// The workers an adaptive render's estimate allows for, each holding the
/// samples of one refined pixel at a time ([`estimate`]).
const REFINING_WORKERS: f64 = 256.0;

/// Estimates the peak memory of rendering `scene` (one frame).
pub fn estimate(scene: &LoadedScene) -> MemoryEstimate {
    let sc = &scene.scene;
    let n = sc.render.supersample().max(1) as f64;
    let (w, h) = (sc.sensor.width_px as f64, sc.sensor.height_px as f64);
    let band = super::blocks::band_samples(sc.sensor.width_px * n as u32, n as u32) as f64;
    let adaptive = sc.render.sampling == crate::scene::spec::Sampling::Adaptive && n > 1.0;
    let (samples, held) = if adaptive {
        // Adaptive sampling ([`super::adaptive`]) holds two bands of coarse
        // samples (one per pixel) and, per worker, the samples of the one
        // refined pixel it carries (its n×n grid and 16 first-level
        // samples; up to [`REFINING_WORKERS`] workers allowed for); which
        // pixels are refined is not known before the render, so `samples`
        // counts the coarse ones.
        let bt = super::blocks::band_target() as f64;
        let coarse_band = ((bt / w).floor() / 16.0).floor().max(1.0) * 16.0 * w;
        let refined = (REFINING_WORKERS * (n * n + 16.0)).min(w * h * (n * n + 16.0));
        (w * h, (w * h).min(2.0 * coarse_band) + refined)
    } else {
        let samples = w * n * h * n;
        (samples, samples.min(band))
    };
    // A history holds its transitions inline up to `INLINE_SWITCHES` (a
    // point with more takes a heap block; few do: sunrise, sunset and a
    // shadow or two a day), whatever its number of samples.
    let bytes_per_sample = std::mem::size_of::<Sample>() as f64 + 19.0 * 4.0;
    let bins = band_grid(scene).2;
    let (limit_mib, limit_from) = match sc.render.max_memory_mib {
        Some(m) => (Some(m), "render.max_memory_mib".to_string()),
        None => (
            machine_memory_mib(),
            "the machine's memory (set render.max_memory_mib to change)".to_string(),
        ),
    };
    let samples_mib = held * bytes_per_sample / MIB;
    let planes_mib = w * h * PLANE_BYTES_PER_PIXEL / MIB;
    let geometry_mib = scene.triangles.len() as f64 * TRIANGLE_BYTES / MIB;
    let spectral_mib = spectral_mib(bins);
    MemoryEstimate {
        samples: samples as u64,
        samples_held: held as u64,
        bytes_per_sample,
        samples_mib,
        planes_mib,
        geometry_mib,
        spectral_mib,
        base_mib: BASE_MIB,
        total_mib: BASE_MIB + samples_mib + planes_mib + geometry_mib + spectral_mib,
        limit_mib,
        limit_from,
    }
}

/// The estimate, or an error when it exceeds the limit: the render is
/// refused before anything scene-sized is allocated.
pub fn check(scene: &LoadedScene) -> anyhow::Result<MemoryEstimate> {
    let e = estimate(scene);
    if let Some(limit) = e.limit_mib
        && e.total_mib > limit
    {
        anyhow::bail!(
            "{}: the render needs an estimated {:.0} MiB ({} samples, {} at a time, of {:.0} bytes: {:.0} MiB; \
             planes {:.0} MiB; geometry {:.0} MiB; spectra {:.0} MiB; base {:.0} MiB), more than \
             the {:.0} MiB allowed by {}: reduce sensor.width_px/height_px, \
             render.supersample or render.history_hours, or raise render.max_memory_mib",
            scene.path.display(),
            e.total_mib,
            e.samples,
            e.samples_held,
            e.bytes_per_sample,
            e.samples_mib,
            e.planes_mib,
            e.geometry_mib,
            e.spectral_mib,
            e.base_mib,
            limit,
            e.limit_from
        );
    }
    Ok(e)
}

/// What `irsig check` reports (and Python's `Scene.check()`): the scene's
/// summary and the render's memory estimate, one object.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CheckReport {
    #[serde(flatten)]
    /// The scene's summary (objects, facets, materials, bounds, sensor).
    pub summary: crate::scene::summary::SceneSummary,
    /// The render's memory estimate.
    pub memory: MemoryEstimate,
}

/// The [`CheckReport`] of a loaded scene.
pub fn check_report(scene: &LoadedScene) -> CheckReport {
    CheckReport {
        summary: crate::scene::summary::summarize(scene),
        memory: estimate(scene),
    }
}
