//! A frame, band by band: steps 1-4 ([`super::tracing`],
//! [`super::thermal`]) then the radiometry straight into the plane rows
//! ([`super::assemble`]), or the adaptive render ([`super::adaptive`]).

use std::time::Instant;

use super::blocks::{BLOCK, bands, block_pixels};
use super::frame::{Counters, Frame, ProgressFn, Stage, StageProgress, Stats};
use super::prepare::{Conditions, Static};
use super::sample::Sample;
use super::thermal::solve_temperatures;
use super::tracing::{sample_camera, trace_band, trace_blocks};
use super::{adaptive, assemble, cancel, pixel};

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
    planes.into_frame(stats, kept, sw)
}
