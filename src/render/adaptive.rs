//! Adaptive image sampling (`render.sampling = "adaptive"`): most pixels
//! lie inside one facet with one history and need one sample; the pixels
//! an edge crosses need many.
//!
//! 1. **Coarse pass.** One sample per output pixel: the sample of the
//!    `n`×`n` grid nearest its centre (`n` = `render.supersample`, the
//!    refined density), traced, given its history and solved (steps 1-4)
//!    in blocks of 16×16 pixels, bands of pixel rows at a time.
//! 2. **Criterion.** A pixel is refined when its coarse sample and one of
//!    its 8 neighbours' differ ([`differ`]): one sees a surface and the
//!    other not (silhouettes against the sky), or their surfaces differ in
//!    material, plane (normals more than 1° apart, or parallel planes more
//!    than 5 cm + 10⁻⁴ of the range apart: silhouettes against a
//!    background, steps), sunlit flag (shadow edges now), kind or surface
//!    of a specular background, or surface temperature by more than
//!    `render.refine_threshold_k` (shadow edges of the past, which the
//!    history leaves in the temperature; the per-point sky view). Both
//!    pixels of a differing pair are refined, so an edge between two
//!    coarse samples is refined in whichever pixel it crosses. The
//!    image's border pixels are always refined (an edge between a border
//!    pixel's centre and the image's edge has no neighbour to show it).
//! 3. **Refinement.** A refined pixel traces the rest of its `n`×`n`
//!    stratified grid (its coarse sample is one of them and is reused) and
//!    takes the mean over all `n`² samples, as a uniform render does (the
//!    uniform-pixel collapse of [`super::pixel::representatives`]
//!    included). Geometry (primary and specular rays) is traced for every
//!    sample; sun/shadow histories only on a sub-grid of stride `n`/4
//!    (4×4 per pixel) and for every specular background: each other sample
//!    takes the history of the nearest sub-grid sample on its plane and
//!    material (the coarse sample included), or traces its own where none
//!    is. So an object edge is resolved at `n`×`n`, a shadow edge inside a
//!    plane at 4×4 (its temperature step is the smaller error: BENCHMARKS.md).
//!    An unrefined pixel is its coarse sample's value.
//!
//! What it leaves out: a feature that no coarse sample sees (narrower
//! than the pixel pitch and between two pixel centres, e.g. a thin pole
//! or wire) is missed, as in a 1-sample render; the mean-valued planes of
//! an unrefined pixel (range, ground point, view angle) are its centre
//! sample's, not the mean over the pixel (the same to second order in the
//! pixel's angular size on a plane).
//!
//! Deterministic: the coarse blocks, each refined pixel's list of samples
//! and the thermal and radiometric memos are functions of the pixel and
//! the key alone, never of the thread count.

use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use super::assemble::{FramePlanes, PixelValues};
use super::pixel::{self, EvalMemo, RadiometryContext};
use super::prepare::{Conditions, Static};
use super::{
    BLOCK, Counters, Frame, ProgressFn, Sample, Stage, StageProgress, Stats, Surface, band_target,
    block_pixels, cancel, sample_camera, solve_temperatures, trace_block, trace_geometry,
    trace_histories,
};
use crate::sensor::camera::Camera;

/// Two normals more than about 1° apart are two planes.
const SAME_PLANE_COS: f32 = 0.99985;
/// Two parallel planes farther apart than this (m) plus [`PLANE_TOL_REL`]
/// of the range are two planes.
const PLANE_TOL_M: f32 = 0.05;
const PLANE_TOL_REL: f32 = 1e-4;

/// Whether two surfaces (or their absence) may differ in value between
/// them: see the module docs, step 2.
fn surfaces_differ(a: Option<&Surface>, b: Option<&Surface>, threshold_k: f64) -> bool {
    match (a, b) {
        (None, None) => false,
        (Some(a), Some(b)) => {
            let offset_m = a.normal.dot(b.point - a.point).abs();
            a.material != b.material
                || a.normal.dot(b.normal) < SAME_PLANE_COS
                || offset_m > PLANE_TOL_M + PLANE_TOL_REL * a.range_m.max(b.range_m)
                || a.sun_now() != b.sun_now()
                // (NaN-safe: a NaN temperature differs)
                || (a.temp_k - b.temp_k).abs().partial_cmp(&threshold_k)
                    != Some(std::cmp::Ordering::Less)
        }
        _ => true,
    }
}

/// The refinement criterion between the coarse samples of two
/// neighbouring pixels (module docs, step 2).
pub fn differ(a: &Sample, b: &Sample, threshold_k: f64) -> bool {
    surfaces_differ(a.surface.as_ref(), b.surface.as_ref(), threshold_k)
        || match (&a.bounce, &b.bounce) {
            (None, None) => false,
            (Some((da, x)), Some((db, y))) => {
                // (a mirror ray that leaves the scene: sky above, ground below)
                let up = |d: &Vec3| d.z > 0.0;
                (x.is_none() && y.is_none() && up(da) != up(db))
                    || surfaces_differ(x.as_ref(), y.as_ref(), threshold_k)
            }
            _ => true,
        }
}

/// The 8 neighbours of a pixel.
const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// Output rows per coarse band: a multiple of [`BLOCK`], about
/// [`band_target`] samples.
fn coarse_rows(width: u32) -> u32 {
    (band_target() / width.max(1) / BLOCK * BLOCK).max(BLOCK)
}

/// The sample of output pixel (`x`, `y`)'s `n`×`n` grid nearest its
/// centre, in sample-image coordinates.
fn centre(x: u32, y: u32, n: u32) -> (u32, u32) {
    (x * n + n / 2, y * n + n / 2)
}

/// Steps 1-4 for the coarse samples of output rows `y0..y1` (`y0` a
/// multiple of [`BLOCK`]) of a `w`×`h` image, row-major.
#[allow(clippy::too_many_arguments)]
fn coarse_band(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    (w, h, n): (u32, u32, u32),
    (y0, y1): (u32, u32),
    c: &Counters,
    stats: &mut Stats,
    progress: &StageProgress,
) -> anyhow::Result<Vec<Sample>> {
    let t0 = Instant::now();
    let blocks: Vec<(u32, u32)> = (y0..y1)
        .step_by(BLOCK as usize)
        .flat_map(|by| (0..w).step_by(BLOCK as usize).map(move |bx| (bx, by)))
        .collect();
    type Traced = (Vec<(u32, u32)>, Vec<Sample>);
    let traced: Vec<Traced> = blocks
        .par_iter()
        .map(|&(bx, by)| {
            let px = block_pixels(bx, by, w, h);
            if cancel::cancelled() {
                return (px, Vec::new());
            }
            let fine: Vec<(u32, u32)> = px.iter().map(|&(x, y)| centre(x, y, n)).collect();
            let s = trace_block(st, cond, cam, &fine, c);
            (px, s)
        })
        .collect();
    cancel::check()?;
    let mut out = vec![Sample::default(); ((y1 - y0) * w) as usize];
    for (px, s) in traced {
        for (&(x, y), s) in px.iter().zip(s) {
            out[((y - y0) * w + x) as usize] = s;
        }
    }
    stats.seconds.trace += t0.elapsed().as_secs_f64();
    stats.samples += out.len() as u64;
    solve_temperatures(st, cond, &mut out, stats, progress)?;
    Ok(out)
}

/// Whether two surfaces lie on one plane of one material (a sample may
/// take the other's sun/shadow history: module docs, step 3).
fn same_plane(a: &Surface, b: &Surface) -> bool {
    a.material == b.material
        && a.normal.dot(b.normal) >= SAME_PLANE_COS
        && a.normal.dot(b.point - a.point).abs()
            <= PLANE_TOL_M + PLANE_TOL_REL * a.range_m.max(b.range_m)
}

/// Steps 1-3 for the samples `px` of one refined pixel (its `n`×`n` grid,
/// row-major, less the coarse sample `coarse`): every primary and
/// specular ray; the sun/shadow histories of the samples on a sub-grid
/// of stride `n`/4 (the coarse sample's row and column among them) and of
/// every specular background; each other sample takes the history of the
/// nearest sub-grid sample (or the coarse one) on its plane and material,
/// and traces its own where there is none.
fn refine_pixel(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    (px, centre): (&[(u32, u32)], (u32, u32)),
    n: u32,
    coarse: &Sample,
    c: &Counters,
) -> Vec<Sample> {
    let mut samples = trace_geometry(st, cam, px, c);
    let stride = (n / 4).max(1);
    let on_sub =
        |(x, y): (u32, u32)| x % n % stride == n / 2 % stride && y % n % stride == n / 2 % stride;
    super::trace_sample_histories(st, cond, &mut samples, |i| on_sub(px[i]), c);
    // The donors: the sub-grid samples and the coarse one, with their
    // grid positions.
    let mut donors: Vec<((u32, u32), &Surface)> = coarse
        .surface
        .as_ref()
        .map(|s| (centre, s))
        .into_iter()
        .collect();
    donors.extend(
        samples
            .iter()
            .zip(px)
            .filter(|&(_, &p)| on_sub(p))
            .filter_map(|(s, &p)| s.surface.as_ref().map(|s| (p, s))),
    );
    let given: Vec<Option<super::sunflags::SunFlags>> = samples
        .iter()
        .zip(px)
        .map(|(s, &p)| {
            let surf = s.surface.as_ref().filter(|_| !on_sub(p))?;
            let dist = |q: (u32, u32)| p.0.abs_diff(q.0).pow(2) + p.1.abs_diff(q.1).pow(2);
            donors
                .iter()
                .filter(|(_, d)| same_plane(surf, d))
                .min_by_key(|(q, _)| dist(*q))
                .map(|(_, d)| d.history.clone())
        })
        .collect();
    let mut targets: Vec<&mut Surface> = Vec::new();
    for ((s, &p), h) in samples.iter_mut().zip(px).zip(given) {
        if on_sub(p) {
            continue;
        }
        if let Some(surf) = s.surface.as_mut() {
            match h {
                Some(h) => surf.history = h,
                None => targets.push(surf),
            }
        }
    }
    trace_histories(st, cond, &mut targets, c);
    samples
}

/// Renders one frame with adaptive sampling (module docs); `n` =
/// `render.supersample` > 1. The frame keeps no samples.
pub fn render_adaptive(
    st: &Static,
    cond: &Conditions,
    progress: ProgressFn,
) -> anyhow::Result<Frame> {
    let mut stats = Stats {
        spectral_bins: st.band.len(),
        ..Default::default()
    };
    let cam = sample_camera(st);
    let n = st.scene.scene.render.supersample.max(1);
    let threshold_k = st.scene.scene.render.refine_threshold_k;
    let (sw, sh) = (cam.width_px, cam.height_px);
    let (w, h) = (sw / n, sh / n);
    let wu = w as usize;
    let ctx = RadiometryContext::new(st, cond)?;
    let mut planes = FramePlanes::new(st, cond, w, h);
    let rows = coarse_rows(w);
    let bands: Vec<(u32, u32)> = (0..h)
        .step_by(rows as usize)
        .map(|y0| (y0, (y0 + rows).min(h)))
        .collect();
    let trace_progress = StageProgress::new(progress, Stage::Trace, bands.len() as u64);
    let therm_progress = StageProgress::new(progress, Stage::Thermal, (w * h) as u64);
    let radiometry = StageProgress::new(progress, Stage::Radiometry, (w * h) as u64);
    let quiet = StageProgress::new(None, Stage::Thermal, 0);
    let counters = Counters::default();
    let c = ((n / 2) * n + n / 2) as usize;
    let per = (n * n - 1) as usize;
    let chunk_pixels = (band_target() as usize / (n * n) as usize).max(1);
    let dims = (w, h, n);
    let mut cur = match bands.first() {
        Some(&b) => coarse_band(
            st,
            cond,
            &cam,
            dims,
            b,
            &counters,
            &mut stats,
            &therm_progress,
        )?,
        None => Vec::new(),
    };
    let mut prev_row: Vec<Sample> = Vec::new();
    for (b, &(y0, y1)) in bands.iter().enumerate() {
        let next = match bands.get(b + 1) {
            Some(&nb) => Some(coarse_band(
                st,
                cond,
                &cam,
                dims,
                nb,
                &counters,
                &mut stats,
                &therm_progress,
            )?),
            None => None,
        };
        let band_rows = (y1 - y0) as usize;
        // The coarse sample of pixel (x, y), if in the image.
        let at = |x: i64, y: i64| -> Option<&Sample> {
            if x < 0 || x >= w as i64 || y < 0 || y >= h as i64 {
                return None;
            }
            let (x, y) = (x as usize, y as u32);
            if y < y0 {
                prev_row.get(x)
            } else if y >= y1 {
                next.as_ref().and_then(|s| s.get(x))
            } else {
                cur.get((y - y0) as usize * wu + x)
            }
        };
        let refined: Vec<usize> = (0..band_rows * wu)
            .into_par_iter()
            .filter(|&i| {
                let (x, y) = ((i % wu) as i64, (y0 as usize + i / wu) as i64);
                // (the image's border pixels: no neighbour sees the part
                // of the pixel between its centre and the border)
                let border = x == 0 || y == 0 || x + 1 == w as i64 || y + 1 == h as i64;
                border
                    || NEIGHBOURS.iter().any(|&(dx, dy)| {
                        at(x + dx, y + dy).is_some_and(|o| differ(&cur[i], o, threshold_k))
                    })
            })
            .collect();
        stats.adaptive_pixels_refined += refined.len() as u64;
        stats.adaptive_pixels_coarse += (band_rows * wu - refined.len()) as u64;
        // The refined pixels' values, a chunk of pixels (about a band of
        // samples) at a time.
        let mut values: Vec<PixelValues> = Vec::with_capacity(refined.len());
        for chunk in refined.chunks(chunk_pixels) {
            let t0 = Instant::now();
            let traced: Vec<Vec<Sample>> = chunk
                .par_iter()
                .map(|&i| {
                    if cancel::cancelled() {
                        return Vec::new();
                    }
                    let (x, y) = ((i % wu) as u32, y0 + (i / wu) as u32);
                    let px: Vec<(u32, u32)> = (0..n)
                        .flat_map(|j| (0..n).map(move |k| (x * n + k, y * n + j)))
                        .filter(|&p| p != centre(x, y, n))
                        .collect();
                    refine_pixel(
                        st,
                        cond,
                        &cam,
                        (&px, centre(x, y, n)),
                        n,
                        &cur[i],
                        &counters,
                    )
                })
                .collect();
            cancel::check()?;
            let mut fine: Vec<Sample> = traced.into_iter().flatten().collect();
            stats.seconds.trace += t0.elapsed().as_secs_f64();
            stats.samples += fine.len() as u64;
            solve_temperatures(st, cond, &mut fine, &mut stats, &quiet)?;
            let t2 = Instant::now();
            let maker = planes.maker();
            let vals: Vec<PixelValues> = chunk
                .par_iter()
                .enumerate()
                .map_init(EvalMemo::default, |memo, (k, &i)| {
                    let mine = &fine[k * per..(k + 1) * per];
                    let px: Vec<&Sample> = (0..=per)
                        .map(|j| match j.cmp(&c) {
                            std::cmp::Ordering::Less => &mine[j],
                            std::cmp::Ordering::Equal => &cur[i],
                            std::cmp::Ordering::Greater => &mine[j - 1],
                        })
                        .collect();
                    maker.pixel(&ctx, &px, n as usize, memo)
                })
                .collect::<anyhow::Result<_>>()?;
            values.extend(vals);
            stats.seconds.radiometry += t2.elapsed().as_secs_f64();
        }
        let mut slot = vec![u32::MAX; band_rows * wu];
        for (k, &i) in refined.iter().enumerate() {
            slot[i] = k as u32;
        }
        let t2 = Instant::now();
        let band = &cur;
        let row_done = || radiometry.add(w as u64);
        stats.radiometry_samples +=
            planes.fill_rows(y0, band_rows, &row_done, &|maker, x, r, memo| {
                let i = r * wu + x;
                match slot[i] {
                    u32::MAX => maker.pixel(&ctx, &[&band[i]], 1, memo),
                    k => Ok(values[k as usize]),
                }
            })?;
        stats.seconds.radiometry += t2.elapsed().as_secs_f64();
        trace_progress.add(1);
        prev_row = cur.split_off((band_rows - 1) * wu);
        cur = next.unwrap_or_default();
    }
    counters.flush(&mut stats);
    stats.adaptive_refined_density = n;
    let t3 = Instant::now();
    let planes = planes.finish()?;
    pixel::check_finite(&planes)?;
    stats.seconds.sensor = t3.elapsed().as_secs_f64();
    Ok(Frame {
        planes,
        stats,
        samples: Vec::new(),
        sample_width: sw,
    })
}
