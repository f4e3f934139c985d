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
//!    history leaves in the temperature; the per-point sky view). Where
//!    the pair differs in anything but the temperature, the sample halfway
//!    between their centres (on their shared edge or corner; [`criterion::Midpoints`],
//!    geometry and the sun flag now only) tells which half the edge
//!    crosses, and only that pixel is refined ([`criterion::pixel_refined`]: a straight
//!    edge that crosses a pixel crosses one of the 8 segments from its
//!    centre to its neighbours' midpoints); where the midpoint differs from
//!    neither, and for a difference in temperature alone, both pixels are
//!    refined. The image's border pixels are always refined (an edge
//!    between a border pixel's centre and the image's edge has no
//!    neighbour to show it).
//! 3. **Refinement, in two levels.** A refined pixel's `n`×`n` grid is
//!    cut into 4×4 cells (of (`n`/4)² samples; single samples when `n` is
//!    not a multiple of 4). First level: the sample nearest each cell's
//!    centre, traced and solved — with its own history, or with the one
//!    history that the coarse samples of the pixel's 3×3 neighbourhood on
//!    its plane and material share, if its sun rays of the last hour agree
//!    (as in step 4: no history edge crosses the neighbourhood there). A cell is refined
//!    when its first-level sample differs ([`cells_differ`]: [`differ`]
//!    with the temperature criterion ×[`CELL_THRESHOLD_FACTOR`], a
//!    temperature difference counting only where the two histories differ
//!    within the last hour) from a neighbouring cell's, from
//!    the neighbouring pixel's coarse sample across the pixel's edge, or
//!    from the coarse sample at its corner; a refined cell traces all its
//!    samples (second level), an unrefined one stands for its cell with its
//!    one sample (weighted by the cell's samples). The pixel's value is the
//!    mean over the `n`×`n` positions, as a uniform render's (the
//!    uniform-pixel collapse of [`super::pixel::representatives`]
//!    included), each shared sample's radiometry evaluated once. So an
//!    object edge is resolved at `n`×`n` where it crosses, at a quarter or
//!    less of the samples.
//! 4. **Histories of the second level.** Geometry (primary and specular
//!    rays) is traced for every second-level sample; its sun/shadow
//!    history is that of the nearest first-level or coarse sample on its
//!    plane and material — if the sample's own sun rays at the traced
//!    history samples of the last hour ([`RECENT_CHECK_S`]: the image time
//!    and, at the default 60-min sampling, 60 min before it) give the same flags. Otherwise
//!    (a shadow edge of now or of the last hour between the two, or no
//!    donor) and for every specular background it traces its own. An
//!    older shadow edge inside a cell is left at the first level's
//!    resolution (its temperature step has decayed; BENCHMARKS.md). A
//!    sample that takes its donor's history and the same kind of specular
//!    view also takes its temperature and band integral ([`level_two`]; a
//!    first-level sample the pixel's own coarse sample's, [`level_one`]).
//!    An unrefined pixel is its coarse sample's value.
//! 5. **Guided histories.** A refined sample that traces its own history
//!    inside a square of four samples on its plane traces only the history
//!    samples where they disagree
//!    ([`super::tracing::trace_histories_guided`]).
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

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use rayon::prelude::*;

use super::assemble::{FramePlanes, PixelValues};
use super::blocks::{BLOCK, band_target, block_pixels};
use super::cancel;
use super::frame::{Counters, Frame, ProgressFn, Stage, StageProgress, StageTimes, Stats, add};
use super::pixel::{EvalMemo, RadiometryContext};
use super::prepare::{Conditions, Static};
use super::sample::{Sample, Surface};
use super::thermal::{
    SampleMemo, add_cache_stats, solve_samples, solve_temperatures, solve_temperatures_except,
};
use super::tracing::{
    Guides, sample_camera, sun_flags_at, trace_block, trace_geometry, trace_sample_histories_guided,
};
use crate::sensor::camera::Camera;

mod criterion;

use criterion::{Midpoints, NEIGHBOURS, centre, pixel_refined, wanted_midpoints};
pub use criterion::{differ, same_plane};

/// Output rows per coarse band: a multiple of [`BLOCK`], about
/// [`band_target`] samples.
fn coarse_rows(width: u32) -> u32 {
    (band_target() / width.max(1) / BLOCK * BLOCK).max(BLOCK)
}

/// Steps 1-4 for the coarse samples of output rows `y0..y1` (`y0` a
/// multiple of [`BLOCK`]) of a `w`×`h` image, row-major.
/// Each worker's time goes to `stage_ns` (the caller splits the wall time).
#[allow(clippy::too_many_arguments)]
fn coarse_band(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    (w, h, n): (u32, u32, u32),
    (y0, y1): (u32, u32),
    c: &Counters,
    stage_ns: &StageNs,
    progress: &StageProgress,
) -> anyhow::Result<Vec<Sample>> {
    let blocks: Vec<(u32, u32)> = (y0..y1)
        .step_by(BLOCK as usize)
        .flat_map(|by| (0..w).step_by(BLOCK as usize).map(move |bx| (bx, by)))
        .collect();
    // Each block traced and solved by one worker (its samples stay in the
    // worker's cache).
    type Traced = (Vec<(u32, u32)>, Vec<Sample>);
    let traced: Vec<Traced> = blocks
        .par_iter()
        .map_init(SampleMemo::default, |memo, &(bx, by)| {
            let px = block_pixels(bx, by, w, h);
            cancel::check()?;
            let mut clock = StageClock::new(stage_ns);
            let fine: Vec<(u32, u32)> = px.iter().map(|&(x, y)| centre(x, y, n)).collect();
            let mut s = trace_block(st, cond, cam, &fine, c);
            clock.lap(TRACE);
            solve_samples(st, cond, &mut s, &[], memo)?;
            memo.absorb(cond);
            clock.lap(THERMAL);
            progress.add(s.len() as u64);
            Ok((px, s))
        })
        .collect::<anyhow::Result<_>>()?;
    // The blocks' samples into rows, a row of blocks (BLOCK output rows)
    // per task: `blocks` runs along each row of blocks, then down.
    let per_row = w.div_ceil(BLOCK) as usize;
    let mut rows_of_blocks: Vec<Vec<Traced>> = Vec::with_capacity(traced.len() / per_row + 1);
    let mut traced = traced.into_iter();
    loop {
        let row: Vec<Traced> = traced.by_ref().take(per_row).collect();
        if row.is_empty() {
            break;
        }
        rows_of_blocks.push(row);
    }
    let mut out = vec![Sample::default(); ((y1 - y0) * w) as usize];
    out.par_chunks_mut((BLOCK * w) as usize)
        .zip(rows_of_blocks)
        .enumerate()
        .for_each(|(k, (dst, row))| {
            let top = y0 + k as u32 * BLOCK;
            for (px, s) in row {
                for (&(x, y), s) in px.iter().zip(s) {
                    dst[((y - top) * w + x) as usize] = s;
                }
            }
        });
    Ok(out)
}

/// The stages a worker's time on a coarse block or a refined pixel is
/// split into ([`StageClock`]).
const TRACE: usize = 0;
const THERMAL: usize = 1;
const RADIOMETRY: usize = 2;

/// The workers' time in each stage (ns), summed over the pieces of work
/// of a frame ([`StageClock`]).
#[derive(Default)]
struct StageNs([AtomicU64; 3]);

impl StageNs {
    /// Adds the wall time `wall_s` to `seconds`, split between the
    /// stages in the proportions of the workers' time in each, and clears
    /// the counters.
    fn split_into(&mut self, wall_s: f64, seconds: &mut StageTimes) {
        let ns = self
            .0
            .each_mut()
            .map(|a| std::mem::take(a.get_mut()) as f64);
        let total = ns.iter().sum::<f64>().max(1.0);
        seconds.trace += wall_s * ns[TRACE] / total;
        seconds.thermal += wall_s * ns[THERMAL] / total;
        seconds.radiometry += wall_s * ns[RADIOMETRY] / total;
    }
}

/// A worker's clock over one piece of work (a coarse block, a refined
/// pixel): each lap's time (ns) is added to its stage's counter.
struct StageClock<'a> {
    ns: &'a StageNs,
    last: Instant,
}

impl<'a> StageClock<'a> {
    fn new(ns: &'a StageNs) -> Self {
        StageClock {
            ns,
            last: Instant::now(),
        }
    }

    /// Adds the time since the last lap to `stage`.
    fn lap(&mut self, stage: usize) {
        let now = Instant::now();
        let d = now.duration_since(self.last).as_nanos() as u64;
        self.ns.0[stage].fetch_add(d, Ordering::Relaxed);
        self.last = now;
    }
}

/// Cells per axis of a refined pixel's first level (module docs, step 3).
const CELLS: u32 = 4;

/// A cell's temperature criterion is `refine_threshold_k` times this: a
/// cell is 1/16 of its pixel, so a temperature step left inside an
/// unrefined cell moves the pixel's mean by at most a 16th of it (measured:
/// 10 % fewer samples than 1x, the same error at 48², BENCHMARKS.md).
const CELL_THRESHOLD_FACTOR: f64 = 4.0;

/// How far back (s) a sample that takes a neighbour's sun/shadow history
/// checks it against its own sun rays (module docs, step 4).
const RECENT_CHECK_S: i64 = 3600;

/// A refined pixel's `n`×`n` grid as cells: (cells per axis, cell side in
/// samples). `n` a multiple of [`CELLS`]: 4×4 cells; otherwise every
/// sample is a cell.
fn layout(n: u32) -> (u32, u32) {
    if n.is_multiple_of(CELLS) {
        (CELLS, n / CELLS)
    } else {
        (n, 1)
    }
}

/// The grid position (0..n, along one axis) of cell `i`'s first-level
/// sample, for cells of side `s`: the grid sample nearest its centre.
fn cell_centre(i: u32, s: u32) -> u32 {
    i * s + s / 2
}

/// The history samples a donated history is checked at: the traced ones
/// within [`RECENT_CHECK_S`] of the image time (the image time included).
fn recent_samples(cond: &Conditions) -> Vec<usize> {
    let Some(last) = cond.suns.len().checked_sub(1) else {
        return Vec::new();
    };
    let every = cond.coarse_every.max(1);
    let t_last = cond.suns[last].t_s;
    (0..=last / every)
        .map(|q| last - q * every)
        .take_while(|&k| t_last - cond.suns[k].t_s <= RECENT_CHECK_S)
        .collect()
}

/// Step 3's first level for refined pixel (`x`, `y`): the sample nearest
/// the centre of each of its cells (row-major over the cells), each with
/// its own history — or, where the pixel's 3×3 neighbourhood of coarse
/// samples (`hood`: the pixel's own and its [`NEIGHBOURS`]) shows no
/// history edge on the sample's plane, the history those samples share
/// (module docs, step 4).
fn level_one(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    (x, y): (u32, u32),
    n: u32,
    (hood, recent): (&[Option<&Sample>; 9], &[usize]),
    c: &Counters,
) -> (Vec<Sample>, Vec<bool>) {
    let (m, s) = layout(n);
    let pos: Vec<(u32, u32)> = (0..m)
        .flat_map(|j| (0..m).map(move |i| (x * n + cell_centre(i, s), y * n + cell_centre(j, s))))
        .collect();
    let mut out = trace_geometry(st, cam, &pos, c);
    let coarse: Vec<&Surface> = hood
        .iter()
        .flatten()
        .filter_map(|smp| smp.surface.as_ref())
        .collect();
    let given = shared_histories(&out, &coarse);
    let own = check_recent(st, cond, &mut out, &given, recent, c);
    // The pixel's own coarse sample as a donor of values (module docs,
    // step 3): same plane and material, the shared history, the same kind
    // of mirror view.
    let me = hood[0];
    let donated: Vec<bool> = (out.iter_mut().zip(&given).zip(&own))
        .map(|((smp, g), &o)| {
            let Some(me) = me else { return false };
            if g.is_none() || o || !same_bounce(smp, me) {
                return false;
            }
            match (smp.surface.as_mut(), me.surface.as_ref()) {
                (Some(surf), Some(d)) if same_plane(surf, d) => {
                    surf.temp_k = d.temp_k;
                    true
                }
                _ => false,
            }
        })
        .collect();
    add(&c.donor_values, donated.iter().filter(|&&d| d).count());
    // A sample that traces its own history is guided by the four coarse
    // samples of the square around it, when all four are on its plane.
    let c0 = (n / 2) as i64;
    let side = |v: u32| if (v as i64) < c0 { -1 } else { 1 };
    let hood_at = |dx: i64, dy: i64| -> Option<&Sample> {
        match (dx, dy) {
            (0, 0) => hood[0],
            _ => hood[1 + NEIGHBOURS.iter().position(|&q| q == (dx, dy))?],
        }
    };
    let guide = |i: usize, surf: &Surface| -> Option<Guides> {
        let (sx, sy) = (
            side(cell_centre(i as u32 % m, s)),
            side(cell_centre(i as u32 / m, s)),
        );
        let g = [(0, 0), (sx, 0), (0, sy), (sx, sy)].map(|(dx, dy)| {
            hood_at(dx, dy)
                .and_then(|smp| smp.surface.as_ref())
                .filter(|d| same_plane(surf, d))
        });
        let [Some(a), Some(b), Some(c), Some(d)] = g else {
            return None;
        };
        Some([&a.history, &b.history, &c.history, &d.history])
    };
    trace_sample_histories_guided(st, cond, &mut out, |i| own[i], guide, recent, c);
    (out, donated)
}

/// Whether two samples see the same kind of specular view for a shared
/// value: neither is a mirror, or both are mirrors that see the sky on the
/// same side of the horizon (the sky dome varies smoothly between their
/// directions; a background surface has its own history).
fn same_bounce(a: &Sample, b: &Sample) -> bool {
    match (a.bounce.as_deref(), b.bounce.as_deref()) {
        (None, None) => true,
        (Some((da, None)), Some((db, None))) => (da.z > 0.0) == (db.z > 0.0),
        _ => false,
    }
}

/// A pixel's 3×3 neighbourhood of coarse samples: its own (`own`) and
/// those of its [`NEIGHBOURS`] (`at(dx, dy)`, `None` outside the image).
fn hood_of<'a>(
    own: &'a Sample,
    at: impl Fn(i64, i64) -> Option<&'a Sample>,
) -> [Option<&'a Sample>; 9] {
    let mut hood = [None; 9];
    hood[0] = Some(own);
    for (k, &(dx, dy)) in NEIGHBOURS.iter().enumerate() {
        hood[k + 1] = at(dx, dy);
    }
    hood
}

/// For each sample of `fine`: the history of the coarse samples on its
/// plane and material (`coarse`), when there is at least one and all of
/// them have the same history (no history edge crosses the neighbourhood
/// on that plane: a shadow edge that swept across it gave its coarse
/// samples different transition times); `None` otherwise. (A specular
/// background always traces its own.)
fn shared_histories<'a>(fine: &[Sample], coarse: &[&'a Surface]) -> Vec<Option<&'a Surface>> {
    fine.iter()
        .map(|smp| {
            let surf = smp.surface.as_ref()?;
            let mut on_plane = coarse.iter().filter(|d| same_plane(surf, d));
            let first = *on_plane.next()?;
            on_plane
                .all(|d| d.history == first.history)
                .then_some(first)
        })
        .collect()
}

/// Gives each sample of `fine` its donor's history (`given`) if its own
/// sun rays at the `recent` history samples agree with it; returns which
/// samples must trace their own history (no donor, or a disagreement).
fn check_recent(
    st: &Static,
    cond: &Conditions,
    fine: &mut [Sample],
    given: &[Option<&Surface>],
    recent: &[usize],
    c: &Counters,
) -> Vec<bool> {
    let checked: Vec<&Surface> = fine
        .iter()
        .zip(given)
        .filter(|(_, g)| g.is_some())
        .filter_map(|(smp, _)| smp.surface.as_ref())
        .collect();
    let flags = sun_flags_at(st, cond, &checked, recent, c);
    let r = recent.len();
    let mut agree = flags
        .chunks(r.max(1))
        .zip(given.iter().flatten())
        .map(|(f, d)| {
            f.iter()
                .zip(recent)
                .all(|(&lit, &k)| d.history.get(k) == lit)
        });
    let own: Vec<bool> = given
        .iter()
        .map(|g| match g {
            Some(_) => !agree.next().unwrap_or(false),
            None => true,
        })
        .collect();
    let mut donated = 0;
    for ((smp, g), &o) in fine.iter_mut().zip(given).zip(&own) {
        if let (Some(d), false) = (g, o) {
            donated += 1;
            if let Some(surf) = smp.surface.as_mut() {
                surf.history = d.history.clone();
            }
        }
    }
    add(&c.donated, donated);
    own
}

/// The cell criterion ([`refined_cells`]): [`differ`], except that a
/// temperature difference alone between two surfaces whose sun/shadow
/// histories agree at the `recent` history samples does not refine. Such a
/// difference comes from an older shadow edge (or the sky view, or the
/// height, which vary smoothly): the second level would give its samples
/// the nearest first-level sample's history (module docs, step 4), which
/// is the cell's own first-level sample — the same value the unrefined
/// cell stands for. A recent difference (a shadow edge of the last hour
/// between the two) still refines, as do specular backgrounds (whose
/// second-level samples trace their own histories).
fn cells_differ(a: &Sample, b: &Sample, threshold_k: f64, recent: &[usize]) -> bool {
    if differ(a, b, f64::INFINITY) {
        return true;
    }
    if !differ(a, b, threshold_k) {
        return false;
    }
    match (
        &a.surface,
        &b.surface,
        a.bounce.as_deref(),
        b.bounce.as_deref(),
    ) {
        (Some(x), Some(y), None, None) => {
            recent.iter().any(|&k| x.history.get(k) != y.history.get(k))
        }
        _ => true,
    }
}

/// Which cells of a refined pixel are refined (module docs, step 3): a
/// cell whose first-level sample differs from a neighbouring cell's — a
/// neighbour beyond the pixel's edge is that neighbouring pixel's coarse
/// sample (`nb`, in [`NEIGHBOURS`] order; `None` outside the image) — or
/// from the coarse sample at its corner.
fn refined_cells(
    l1: &[Sample],
    coarse: &Sample,
    nb: &[Option<&Sample>; 8],
    n: u32,
    (threshold_k, recent): (f64, &[usize]),
) -> Vec<bool> {
    let differ = |a: &Sample, b: &Sample, t: f64| cells_differ(a, b, t, recent);
    let (m, s) = layout(n);
    let mi = m as i64;
    let at = |i: i64, j: i64| &l1[(j * mi + i) as usize];
    let side = |v: i64| (v >= mi) as i64 - (v < 0) as i64;
    let beyond = |i: i64, j: i64| -> Option<&Sample> {
        let k = NEIGHBOURS.iter().position(|&q| q == (side(i), side(j)))?;
        nb[k]
    };
    let mut out = vec![false; (m * m) as usize];
    for j in 0..mi {
        for i in 0..mi {
            let a = at(i, j);
            out[(j * mi + i) as usize] = NEIGHBOURS.iter().any(|&(dx, dy)| {
                let (ii, jj) = (i + dx, j + dy);
                if (0..mi).contains(&ii) && (0..mi).contains(&jj) {
                    differ(a, at(ii, jj), threshold_k)
                } else {
                    beyond(ii, jj).is_some_and(|o| differ(a, o, threshold_k))
                }
            });
        }
    }
    // The coarse sample lies at the corner of the cells around the centre
    // (or inside one when the cells are single samples).
    let c0 = n / 2;
    let hi = (c0 / s).min(m - 1);
    let lo = if c0.is_multiple_of(s) {
        hi.saturating_sub(1)
    } else {
        hi
    };
    for j in lo..=hi {
        for i in lo..=hi {
            let k = (j * m + i) as usize;
            out[k] |= differ(coarse, &l1[k], threshold_k);
        }
    }
    out
}

/// Where the sample of each grid position of a refined pixel is, in the
/// list [coarse, first level (cells row-major), second level].
type Slot = u32;

/// The sample a [`Slot`] names: the coarse sample, a first-level sample
/// (`l1`) or a second-level one (`l2`).
fn slot_sample<'a>(sl: Slot, coarse: &'a Sample, l1: &'a [Sample], l2: &'a [Sample]) -> &'a Sample {
    match sl as usize {
        0 => coarse,
        j if j <= l1.len() => &l1[j - 1],
        j => &l2[j - 1 - l1.len()],
    }
}

/// Step 3's second level and step 4 for refined pixel (`x`, `y`): every
/// other sample of its refined cells, traced (primary and specular rays);
/// each takes the sun/shadow history of the nearest first-level or coarse
/// sample on its plane and material if its own sun rays at the `recent`
/// history samples agree with it, and traces its own otherwise (every
/// specular background traces its own).
///
/// A sample that takes its donor's history and sees no specular
/// background surface (nor does the donor; a mirror that sees the sky on
/// the donor's side of the horizon does) also takes the donor's surface
/// temperature and, in the pixel, the donor's radiometry ([`Level2::donor`],
/// [`grid_owners`]): it differs from the donor only by where it lies on
/// the plane (sky view, height, view angle and range inside a quarter of a
/// pixel), as an unrefined cell's positions differ from its one sample;
/// what it adds is the edge's coverage. Its own geometry (range, point)
/// still goes into the pixel's mean planes.
#[allow(clippy::too_many_arguments)]
fn level_two(
    st: &Static,
    cond: &Conditions,
    cam: &Camera,
    (x, y): (u32, u32),
    n: u32,
    (coarse, l1, cells): (&Sample, &[Sample], &[bool]),
    recent: &[usize],
    c: &Counters,
) -> Level2 {
    let (m, s) = layout(n);
    let c0 = n / 2;
    let first = 1 + (m * m) as Slot;
    let mut slots = Vec::with_capacity((n * n) as usize);
    let mut pos = Vec::with_capacity((n * n) as usize);
    for gy in 0..n {
        for gx in 0..n {
            let (i, j) = (gx / s, gy / s);
            let cell = j * m + i;
            let at_centre = gx == cell_centre(i, s) && gy == cell_centre(j, s);
            slots.push(if (gx, gy) == (c0, c0) {
                0
            } else if at_centre || !cells[cell as usize] {
                1 + cell
            } else {
                pos.push((x * n + gx, y * n + gy));
                first + (pos.len() - 1) as Slot
            });
        }
    }
    let mut fine = trace_geometry(st, cam, &pos, c);
    // The donors: the first-level samples and the coarse one, with their
    // grid positions (within the pixel) and slots.
    let donors: Vec<((u32, u32), Slot, &Sample, &Surface)> = (0..m * m)
        .map(|k| {
            (
                (cell_centre(k % m, s), cell_centre(k / m, s)),
                1 + k,
                &l1[k as usize],
            )
        })
        .chain(std::iter::once(((c0, c0), 0, coarse)))
        .filter_map(|(p, sl, smp)| smp.surface.as_ref().map(|surf| (p, sl, smp, surf)))
        .collect();
    let nearest: Vec<Option<(Slot, &Sample, &Surface)>> = fine
        .iter()
        .zip(&pos)
        .map(|(smp, &(px, py))| {
            let surf = smp.surface.as_ref()?;
            let p = (px - x * n, py - y * n);
            let dist = |q: (u32, u32)| p.0.abs_diff(q.0).pow(2) + p.1.abs_diff(q.1).pow(2);
            donors
                .iter()
                .filter(|(_, _, _, d)| same_plane(surf, d))
                .min_by_key(|(q, _, _, _)| dist(*q))
                .map(|&(_, sl, smp, d)| (sl, smp, d))
        })
        .collect();
    // A sample that traces its own history is guided by the four
    // first-level samples of the square of cell centres around it, when
    // the square lies in the pixel and all four are on its plane.
    let cell_of = |v: u32| -> Option<(u32, u32)> {
        let ci = v / s;
        let other = if v < cell_centre(ci, s) {
            ci.checked_sub(1)?
        } else {
            ci + 1
        };
        (other < m).then_some((ci, other))
    };
    let guide = |i: usize, surf: &Surface| -> Option<Guides> {
        let (px, py) = (pos[i].0 - x * n, pos[i].1 - y * n);
        let ((a, b), (c, d)) = (cell_of(px)?, cell_of(py)?);
        let g = [(a, c), (b, c), (a, d), (b, d)].map(|(i, j)| {
            l1[(j * m + i) as usize]
                .surface
                .as_ref()
                .filter(|o| same_plane(surf, o))
        });
        let [Some(p), Some(q), Some(r), Some(t)] = g else {
            return None;
        };
        Some([&p.history, &q.history, &r.history, &t.history])
    };
    let given: Vec<Option<&Surface>> = nearest.iter().map(|d| d.map(|(_, _, s)| s)).collect();
    // A sample whose guide square's four histories all have its donor's
    // flags at the last hour's samples takes the donor's history without
    // its own check (a shadow edge of the last hour that leaves all four
    // on one side leaves it there too).
    let free: Vec<bool> = (fine.iter().enumerate().zip(&given))
        .map(|((i, smp), g)| {
            let (Some(surf), Some(d)) = (smp.surface.as_ref(), g) else {
                return false;
            };
            guide(i, surf).is_some_and(|gs| {
                gs.iter()
                    .all(|h| recent.iter().all(|&k| h.get(k) == d.history.get(k)))
            })
        })
        .collect();
    let checked: Vec<Option<&Surface>> = (given.iter().zip(&free))
        .map(|(g, &f)| if f { None } else { *g })
        .collect();
    let mut own = check_recent(st, cond, &mut fine, &checked, recent, c);
    for ((smp, g), (&f, o)) in (fine.iter_mut().zip(&given)).zip(free.iter().zip(&mut own)) {
        if let (true, Some(d), Some(surf)) = (f, g, smp.surface.as_mut()) {
            surf.history = d.history.clone();
            *o = false;
        }
    }
    add(&c.donated, free.iter().filter(|&&f| f).count());
    let donor: Vec<Option<Slot>> = (fine.iter_mut().zip(&nearest).zip(&own))
        .map(|((smp, d), &o)| {
            let (sl, dsmp, dsurf) = (*d)?;
            if o || !same_bounce(smp, dsmp) {
                return None;
            }
            let surf = smp.surface.as_mut()?;
            surf.temp_k = dsurf.temp_k;
            Some(sl)
        })
        .collect();
    add(&c.donor_values, donor.iter().flatten().count());
    trace_sample_histories_guided(st, cond, &mut fine, |i| own[i], guide, recent, c);
    Level2 { fine, slots, donor }
}

/// What [`level_two`] gives a refined pixel.
#[derive(Default)]
struct Level2 {
    /// The second-level samples.
    fine: Vec<Sample>,
    /// The [`Slot`] of each of the `n`×`n` positions (row-major).
    slots: Vec<Slot>,
    /// Per second-level sample: the slot of the donor whose temperature
    /// (already set) and radiometry it takes, if it does.
    donor: Vec<Option<Slot>>,
}

/// The position whose radiometry each of a refined pixel's grid positions
/// uses: the first position of its slot's sample, or, for a sample that
/// takes its donor's values (a first-level one the coarse sample's,
/// `l1_donated`; a second-level one its [`Level2::donor`]'s), the donor's
/// (each owner is its own owner).
fn grid_owners(slots: &[Slot], l1_donated: &[bool], donor: &[Option<Slot>]) -> Vec<usize> {
    let first_fine = 1 + l1_donated.len();
    let alias = |sl: Slot| -> Slot {
        match (sl as usize).checked_sub(first_fine) {
            Some(j) => donor[j].unwrap_or(sl),
            None if sl > 0 && l1_donated[sl as usize - 1] => 0,
            None => sl,
        }
    };
    let mut first = vec![usize::MAX; first_fine + donor.len()];
    for (q, &sl) in slots.iter().enumerate() {
        let f = &mut first[sl as usize];
        if *f == usize::MAX {
            *f = q;
        }
    }
    slots
        .iter()
        .map(|&sl| first[alias(alias(sl)) as usize])
        .collect()
}

/// A band's coarse samples and their neighbours in the rows above and
/// below: the coarse sample of pixel (`x`, `y`), if in the image and known.
struct Coarse<'a> {
    w: u32,
    h: u32,
    /// The band's rows `y0..y1` and their samples (row-major).
    y0: u32,
    y1: u32,
    cur: &'a [Sample],
    /// The last row of the band above, and the band below (`None` while it
    /// is being traced: only the band's rows but its last may be refined).
    prev_row: &'a [Sample],
    next: Option<&'a [Sample]>,
}

impl<'a> Coarse<'a> {
    fn at(&self, x: i64, y: i64) -> Option<&'a Sample> {
        if x < 0 || x >= self.w as i64 || y < 0 || y >= self.h as i64 {
            return None;
        }
        let (x, y) = (x as usize, y as u32);
        if y < self.y0 {
            self.prev_row.get(x)
        } else if y >= self.y1 {
            self.next.and_then(|s| s.get(x))
        } else {
            self.cur.get((y - self.y0) as usize * self.w as usize + x)
        }
    }
}

/// What the refinement of a band's rows shares (steps 2-4 and the
/// radiometry: [`Refiner::rows`]).
struct Refiner<'a> {
    st: &'a Static,
    cond: &'a Conditions,
    cam: &'a Camera,
    ctx: &'a RadiometryContext<'a>,
    dims: (u32, u32, u32),
    threshold_k: f64,
    recent: &'a [usize],
    counters: &'a Counters,
    stage_ns: &'a StageNs,
    samples_refined: &'a AtomicU64,
    radiometry: &'a StageProgress<'a>,
}

impl Refiner<'_> {
    /// Steps 2-4 and the radiometry for rows `r0..r1` of the band (`r`
    /// counted from its first row), filled into `planes`; the workers' time
    /// goes to the stage counters.
    fn rows(
        &self,
        coarse: &Coarse,
        (r0, r1): (usize, usize),
        planes: &mut FramePlanes,
    ) -> anyhow::Result<RowsDone> {
        let (st, cond, cam, c) = (self.st, self.cond, self.cam, self.counters);
        let (w, h, n) = self.dims;
        let wu = w as usize;
        let (y0, cur) = (coarse.y0, coarse.cur);
        let pixel_xy = |i: usize| ((i % wu) as u32, y0 + (i / wu) as u32);
        let nb_of = |i: usize| {
            let (x, y) = pixel_xy(i);
            NEIGHBOURS.map(|(dx, dy)| coarse.at(x as i64 + dx, y as i64 + dy))
        };
        let span = r0 * wu..r1 * wu;
        // The samples halfway between pixels whose coarse samples differ in
        // geometry or sun state: which side the edge lies on.
        let mut clock = StageClock::new(self.stage_ns);
        let wanted: Vec<(u32, u32)> = (span.clone())
            .into_par_iter()
            .flat_map_iter(|i| wanted_midpoints(pixel_xy(i), n, &cur[i], nb_of(i)))
            .collect();
        let mids = Midpoints::trace(st, cond, cam, wanted, c);
        clock.lap(TRACE);
        let refined: Vec<usize> = (span.clone())
            .into_par_iter()
            .filter(|&i| {
                let here = (pixel_xy(i), (w, h, n));
                pixel_refined(here, &cur[i], &nb_of(i), &mids, self.threshold_k)
            })
            .collect();
        let mut done = RowsDone {
            refined: refined.len() as u64,
            coarse: (span.len() - refined.len()) as u64,
            radiometry_samples: 0,
        };
        // The refined pixels' values, each pixel by one worker from its
        // first level to its radiometry (its samples stay in the worker's
        // cache): first level, its temperatures, second level, its
        // temperatures, radiometry.
        let cell_threshold_k = self.threshold_k * CELL_THRESHOLD_FACTOR;
        let recent = self.recent;
        let maker = planes.maker();
        let values: Vec<PixelValues> = refined
            .par_iter()
            .map_init(
                || (SampleMemo::default(), EvalMemo::default()),
                |(tm, memo), &i| {
                    cancel::check()?;
                    let (x, y) = pixel_xy(i);
                    let mut clock = StageClock::new(self.stage_ns);
                    let hood = hood_of(&cur[i], |dx, dy| coarse.at(x as i64 + dx, y as i64 + dy));
                    let (mut l1, l1_donated) =
                        level_one(st, cond, cam, (x, y), n, (&hood, recent), c);
                    clock.lap(TRACE);
                    solve_samples(st, cond, &mut l1, &l1_donated, tm)?;
                    clock.lap(THERMAL);
                    let nb = nb_of(i);
                    let cells = refined_cells(&l1, &cur[i], &nb, n, (cell_threshold_k, recent));
                    let refined_here = cells.iter().filter(|&&r| r).count();
                    add(&c.cells_refined, refined_here);
                    add(&c.cells_coarse, cells.len() - refined_here);
                    let cx = (&cur[i], &l1[..], &cells[..]);
                    let mut two = level_two(st, cond, cam, (x, y), n, cx, recent, c);
                    let solved: Vec<bool> = two.donor.iter().map(|d| d.is_some()).collect();
                    clock.lap(TRACE);
                    solve_samples(st, cond, &mut two.fine, &solved, tm)?;
                    tm.absorb(cond);
                    clock.lap(THERMAL);
                    add(self.samples_refined, l1.len() + two.fine.len());
                    let owners = grid_owners(&two.slots, &l1_donated, &two.donor);
                    let px: Vec<&Sample> = (two.slots.iter())
                        .map(|&sl| slot_sample(sl, &cur[i], &l1, &two.fine))
                        .collect();
                    let v = maker.pixel_shared(self.ctx, &px, Some(&owners), n as usize, memo);
                    clock.lap(RADIOMETRY);
                    v
                },
            )
            .collect::<anyhow::Result<_>>()?;
        let mut slot = vec![u32::MAX; span.len()];
        for (k, &i) in refined.iter().enumerate() {
            slot[i - span.start] = k as u32;
        }
        let row_done = || self.radiometry.add(w as u64);
        let mut clock = StageClock::new(self.stage_ns);
        done.radiometry_samples =
            planes.fill_rows(y0 + r0 as u32, r1 - r0, &row_done, &|maker, x, r, memo| {
                let i = (r0 + r) * wu + x;
                match slot[i - span.start] {
                    u32::MAX => maker.pixel(self.ctx, &[&cur[i]], 1, memo),
                    k => Ok(values[k as usize]),
                }
            })?;
        clock.lap(RADIOMETRY);
        Ok(done)
    }
}

/// What [`Refiner::rows`] counts: pixels refined and left coarse, samples
/// whose band integral was evaluated.
struct RowsDone {
    refined: u64,
    coarse: u64,
    radiometry_samples: u64,
}

impl RowsDone {
    fn add_to(&self, stats: &mut Stats) {
        stats.adaptive_pixels_refined += self.refined;
        stats.adaptive_pixels_coarse += self.coarse;
        stats.radiometry_samples += self.radiometry_samples;
    }
}

/// Renders one frame with adaptive sampling (module docs); `n` =
/// `render.supersample` > 1. With [`Static::keep_samples`] the frame keeps
/// its coarse samples (one per pixel: `sample_width` = the image's width),
/// else none.
///
/// The bands are pipelined: while the coarse pass traces and solves the
/// band below, the rows of the band above but its last are refined and
/// filled (their neighbours are all known); the last row follows once the
/// band below is done. Every value is a function of its pixel and the
/// keys alone, so the overlap changes no bit. The stage seconds split the
/// frame's wall time in the proportions of the workers' time in each stage
/// (a parallel step that no worker clocks itself — the side test's
/// midpoints, a band's fill — counts with its wall time).
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
    let n = st.scene.scene.render.supersample().max(1);
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
    let counters = Counters::default();
    let recent = recent_samples(cond);
    let dims = (w, h, n);
    let before = cond.cache.stats();
    let mut stage_ns = StageNs::default();
    let samples_refined = AtomicU64::new(0);
    let refiner = Refiner {
        st,
        cond,
        cam: &cam,
        ctx: &ctx,
        dims,
        threshold_k,
        recent: &recent,
        counters: &counters,
        stage_ns: &stage_ns,
        samples_refined: &samples_refined,
        radiometry: &radiometry,
    };
    let trace_coarse = |b: (u32, u32)| {
        coarse_band(
            st,
            cond,
            &cam,
            dims,
            b,
            &counters,
            &stage_ns,
            &therm_progress,
        )
    };
    let t0 = Instant::now();
    let mut cur = match bands.first() {
        Some(&b) => trace_coarse(b)?,
        None => Vec::new(),
    };
    let mut prev_row: Vec<Sample> = Vec::new();
    let mut kept: Vec<Sample> = Vec::new();
    for (b, &(y0, y1)) in bands.iter().enumerate() {
        stats.samples += cur.len() as u64;
        let band_rows = (y1 - y0) as usize;
        let coarse = Coarse {
            w,
            h,
            y0,
            y1,
            cur: &cur[..],
            prev_row: &prev_row[..],
            next: None,
        };
        // The band below traced beside the rows of this one that do not
        // border it.
        let (next, last) = match bands.get(b + 1) {
            Some(&nb) => {
                let (next, done) = rayon::join(
                    || trace_coarse(nb),
                    || refiner.rows(&coarse, (0, band_rows - 1), &mut planes),
                );
                done?.add_to(&mut stats);
                (Some(next?), band_rows - 1)
            }
            None => (None, 0),
        };
        let around = Coarse {
            next: next.as_deref(),
            ..coarse
        };
        refiner
            .rows(&around, (last, band_rows), &mut planes)?
            .add_to(&mut stats);
        trace_progress.add(1);
        if st.keep_samples {
            kept.extend(cur.iter().cloned());
        }
        prev_row = cur.split_off((band_rows - 1) * wu);
        cur = next.unwrap_or_default();
    }
    stage_ns.split_into(t0.elapsed().as_secs_f64(), &mut stats.seconds);
    add_cache_stats(&mut stats, &before, &cond.cache.stats());
    counters.flush(&mut stats);
    stats.samples += samples_refined.into_inner();
    stats.adaptive_refined_density = n;
    planes.into_frame(stats, kept, if st.keep_samples { w } else { sw })
}

/// The samples of output pixel (`x`, `y`) as [`render_adaptive`] uses them
/// (for `irsig probe`): the coarse samples of the pixel and its
/// neighbours, traced in their blocks as the coarse pass traces them, and,
/// if the pixel is refined, its first and second levels. Returns the
/// samples of its grid positions (row-major; a shared sample repeated),
/// the grid's side (1 for an unrefined pixel, its coarse sample alone; `n`
/// for a refined one) and, for a refined pixel, the position whose
/// radiometry each position uses ([`grid_owners`]).
pub fn pixel_samples(
    st: &Static,
    cond: &Conditions,
    (x, y): (u32, u32),
    stats: &mut Stats,
) -> anyhow::Result<(Vec<Sample>, u32, Option<Vec<usize>>)> {
    let cam = sample_camera(st);
    let n = st.scene.scene.render.supersample().max(1);
    let threshold_k = st.scene.scene.render.refine_threshold_k;
    let (w, h) = (cam.width_px / n, cam.height_px / n);
    let c = Counters::default();
    let quiet = StageProgress::new(None, Stage::Thermal, 0);
    // The coarse samples of the 3×3 neighbourhood (None outside the image).
    let mut coarse: Vec<Option<Sample>> = Vec::with_capacity(9);
    // (the 3×3 neighbourhood spans at most 4 blocks: each traced once)
    type Traced = ((u32, u32), Vec<(u32, u32)>, Vec<Sample>);
    let mut blocks: Vec<Traced> = Vec::new();
    for (dx, dy) in std::iter::once((0, 0)).chain(NEIGHBOURS) {
        let (px, py) = (x as i64 + dx, y as i64 + dy);
        if px < 0 || py < 0 || px >= w as i64 || py >= h as i64 {
            coarse.push(None);
            continue;
        }
        let (px, py) = (px as u32, py as u32);
        let origin = (px / BLOCK * BLOCK, py / BLOCK * BLOCK);
        let b = match blocks.iter().position(|(o, _, _)| *o == origin) {
            Some(b) => b,
            None => {
                let block = block_pixels(origin.0, origin.1, w, h);
                let fine: Vec<(u32, u32)> = block.iter().map(|&(a, b)| centre(a, b, n)).collect();
                let traced = trace_block(st, cond, &cam, &fine, &c);
                blocks.push((origin, block, traced));
                blocks.len() - 1
            }
        };
        let (_, block, traced) = &blocks[b];
        let k = block
            .iter()
            .position(|&q| q == (px, py))
            .expect("a pixel lies in its block");
        let mut s = vec![traced[k].clone()];
        solve_temperatures(st, cond, &mut s, stats, &quiet)?;
        coarse.push(s.pop());
    }
    let me = coarse[0].clone().expect("the pixel is in the image");
    let nb: [Option<&Sample>; 8] = std::array::from_fn(|k| coarse[k + 1].as_ref());
    // (the render's criterion, its midpoints traced the same way)
    let wanted = wanted_midpoints((x, y), n, &me, nb).collect();
    let mids = Midpoints::trace(st, cond, &cam, wanted, &c);
    if !pixel_refined(((x, y), (w, h, n)), &me, &nb, &mids, threshold_k) {
        c.flush(stats);
        return Ok((vec![me], 1, None));
    }
    let recent = recent_samples(cond);
    let hood = hood_of(&me, |dx, dy| {
        let k = NEIGHBOURS.iter().position(|&q| q == (dx, dy))?;
        nb[k]
    });
    let (mut l1, l1_donated) = level_one(st, cond, &cam, (x, y), n, (&hood, &recent), &c);
    solve_temperatures_except(st, cond, &mut l1, &l1_donated, stats, &quiet)?;
    let cells = refined_cells(
        &l1,
        &me,
        &nb,
        n,
        (threshold_k * CELL_THRESHOLD_FACTOR, &recent),
    );
    let two = level_two(st, cond, &cam, (x, y), n, (&me, &l1, &cells), &recent, &c);
    let owners = grid_owners(&two.slots, &l1_donated, &two.donor);
    let skip: Vec<bool> = two.donor.iter().map(|d| d.is_some()).collect();
    let mut fine = two.fine;
    solve_temperatures_except(st, cond, &mut fine, &skip, stats, &quiet)?;
    let out = (two.slots.iter())
        .map(|&sl| slot_sample(sl, &me, &l1, &fine).clone())
        .collect();
    c.flush(stats);
    Ok((out, n, Some(owners)))
}
