//! A rendered frame and what a render reports about it: the frame record,
//! the `--stats` counters and the progress callback.

use std::sync::atomic::{AtomicU64, Ordering};

use serde::Serialize;

use super::planes::Planes;
use super::sample::Sample;

/// A rendered frame: the output planes (at output resolution) and stats.
pub struct Frame {
    /// The output planes, at output resolution.
    pub planes: Planes,
    /// The render's counters and stage times.
    pub stats: Stats,
    /// Per supersampled sample (tile order is undone: row-major).
    pub samples: Vec<Sample>,
    /// Width of the supersampled sample grid (`samples` is row-major).
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
    /// The stage in progress.
    pub stage: Stage,
    /// Units of it finished.
    pub done: u64,
    /// Units of it in all.
    pub total: u64,
}

/// An optional progress callback (called from worker threads, in any
/// order; `None` costs nothing).
pub type ProgressFn<'a> = Option<&'a (dyn Fn(Progress) + Sync)>;

/// Counters reported by `--stats`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Stats {
    /// Samples traced (output pixels × supersampling).
    pub samples: u64,
    /// Primary rays cast.
    pub primary_rays: u64,
    /// Primary rays that hit the scene.
    pub primary_hits: u64,
    /// Specular-bounce rays cast.
    pub specular_rays: u64,
    /// Specular bounces not cast: the surface has no specular part.
    pub specular_skipped_diffuse: u64,
    /// Sun rays cast (the sun/shadow histories).
    pub solar_rays: u64,
    /// Sun rays not cast: the sun below the horizon.
    pub solar_skipped_sun_down: u64,
    /// Sun rays not cast: the facet faces away from the sun.
    pub solar_skipped_facing_away: u64,
    /// Adaptive histories (`render.adaptive_histories`): output pixels
    /// whose history came from their 4 corner samples alone, and pixels
    /// refined to every one of their n×n samples.
    pub history_pixels_corners: u64,
    /// Pixels whose history was refined to every sample.
    pub history_pixels_refined: u64,
    /// Adaptive sampling (`render.sampling = "adaptive"`): output pixels
    /// that kept their one coarse sample, pixels refined to every sample of
    /// their grid, and that grid's side (`render.supersample`; 0 for a
    /// uniform render).
    pub adaptive_pixels_coarse: u64,
    /// Pixels refined to every sample of their grid.
    pub adaptive_pixels_refined: u64,
    /// Side of the refined grid (samples per pixel edge).
    pub adaptive_refined_density: u32,
    /// Adaptive sampling: cells (4×4 per refined pixel) refined to every
    /// sample, cells that kept their one first-level sample, and samples
    /// that took a neighbouring sample's sun/shadow history after their own
    /// sun rays of the last hour agreed with it.
    pub adaptive_cells_refined: u64,
    /// Cells that kept their one first-level sample.
    pub adaptive_cells_coarse: u64,
    /// Samples that took a neighbour's sun/shadow history.
    pub adaptive_histories_shared: u64,
    /// Refined samples (first and second level) that also took their
    /// donor's temperature and radiometry (same plane and material, the
    /// donor's history, no specular background surface): their own
    /// geometry, the donor's values.
    pub adaptive_values_shared: u64,
    /// Distinct thermal solves (cache misses).
    pub thermal_solves: u64,
    /// Thermal lookups answered from the cache or a worker's memo.
    pub thermal_cache_hits: u64,
    /// Over the distinct solves: accepted and rejected march steps, Newton
    /// iterations, and the core-seconds spent solving (summed over
    /// threads; the rest of `seconds.thermal` is keys and lookups).
    pub thermal_steps: u64,
    /// Rejected march steps.
    pub thermal_steps_rejected: u64,
    /// Newton iterations (surface-balance evaluations).
    pub thermal_newton_iterations: u64,
    /// Core-seconds spent solving.
    pub thermal_solve_core_s: f64,
    /// March states kept at checkpoints, and solves resumed from one
    /// (`therm::cache`: histories that begin alike share their march).
    pub thermal_checkpoints: u64,
    /// Solves resumed from a checkpoint.
    pub thermal_resumed: u64,
    /// Samples whose band integral was evaluated (uniform pixels evaluate
    /// one of their n×n samples).
    pub radiometry_samples: u64,
    /// Spectral bins of the band integral.
    pub spectral_bins: usize,
    /// Wall time per stage, s.
    pub seconds: StageTimes,
}

/// Wall time per stage, s. Where one worker runs several stages for one
/// piece of work (adaptive sampling: a coarse block traced and solved, a
/// refined pixel from its first level to its radiometry), that part's
/// wall time is split between the stages in the proportions of the
/// workers' time in each.
#[derive(Clone, Debug, Default, Serialize)]
pub struct StageTimes {
    /// Steps 1-3: the rays, s.
    pub trace: f64,
    /// Step 4: the temperatures, s.
    pub thermal: f64,
    /// Step 5: the radiometry, s.
    pub radiometry: f64,
    /// The sensor chain, s.
    pub sensor: f64,
}

#[derive(Default)]
pub(super) struct Counters {
    pub(super) primary: AtomicU64,
    pub(super) hits: AtomicU64,
    pub(super) specular: AtomicU64,
    pub(super) spec_skipped: AtomicU64,
    pub(super) solar: AtomicU64,
    pub(super) sun_down: AtomicU64,
    pub(super) away: AtomicU64,
    pub(super) pixels_corners: AtomicU64,
    pub(super) pixels_refined: AtomicU64,
    pub(super) cells_refined: AtomicU64,
    pub(super) cells_coarse: AtomicU64,
    pub(super) donated: AtomicU64,
    pub(super) donor_values: AtomicU64,
}

pub(super) fn add(c: &AtomicU64, n: usize) {
    c.fetch_add(n as u64, Ordering::Relaxed);
}

/// A stage's progress, counted across the bands of a frame.
pub(super) struct StageProgress<'a> {
    report: ProgressFn<'a>,
    stage: Stage,
    done: AtomicU64,
    total: u64,
}

impl<'a> StageProgress<'a> {
    pub(super) fn new(report: ProgressFn<'a>, stage: Stage, total: u64) -> Self {
        StageProgress {
            report,
            stage,
            done: AtomicU64::new(0),
            total,
        }
    }

    /// `n` more units done.
    pub(super) fn add(&self, n: u64) {
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
    pub(super) fn flush(&self, stats: &mut Stats) {
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
        stats.adaptive_values_shared += get(&self.donor_values);
    }
}
