//! A rendered frame and what a render reports about it: the frame record,
//! the `--stats` counters and the progress callback.

use std::sync::atomic::{AtomicU64, Ordering};

use serde::Serialize;

use super::planes::Planes;
use super::sample::Sample;

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
    }
}
