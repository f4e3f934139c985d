//! Steps 1-3 of the render: primary rays, specular bounces and the
//! sun/shadow histories of the surface points, block by block.

use glam::Vec3;
use rayon::prelude::*;

use super::blocks::{BLOCK, block_pixels};
use super::cancel;
use super::frame::{Counters, StageProgress, Stats, add};
use super::prepare::{Conditions, Static};
use super::sample::{Sample, Surface};
use super::sunflags::SunFlags;
use crate::sensor::camera::Camera;
use crate::trace::offset::offset_origin;
use crate::trace::{Hit, Ray};

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
pub(super) fn trace_block(
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
pub(super) fn trace_sample_histories(
    st: &Static,
    cond: &Conditions,
    samples: &mut [Sample],
    pick: impl Fn(usize) -> bool,
    c: &Counters,
) {
    trace_sample_histories_guided(st, cond, samples, pick, |_, _| None, &[], c);
}

/// [`trace_sample_histories`] with the guides `guide(i, surface)` gives
/// the surface point of sample `i` (backgrounds unguided) and the traced
/// samples `force` always traced ([`trace_histories_guided`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn trace_sample_histories_guided<'g>(
    st: &Static,
    cond: &Conditions,
    samples: &mut [Sample],
    pick: impl Fn(usize) -> bool,
    guide: impl Fn(usize, &Surface) -> Option<Guides<'g>>,
    force: &[usize],
    c: &Counters,
) {
    let mut targets: Vec<&mut Surface> = Vec::with_capacity(samples.len());
    let mut guides: Vec<Option<Guides>> = Vec::with_capacity(samples.len());
    for (i, s) in samples.iter_mut().enumerate() {
        if pick(i)
            && let Some(surf) = s.surface.as_mut()
        {
            guides.push(guide(i, surf));
            targets.push(surf);
        }
        if let Some((_, Some(bg))) = s.bounce.as_deref_mut() {
            guides.push(None);
            targets.push(bg);
        }
    }
    if guides.iter().all(Option::is_none) {
        guides.clear();
    }
    trace_histories_guided(st, cond, &mut targets, &guides, force, c);
}

/// Steps 1-2 for a list of (supersampled) pixels: primary rays and
/// specular bounces, no histories yet.
pub(super) fn trace_geometry(
    st: &Static,
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
        samples[i].bounce = Some(Box::new((r.dir, h.as_ref().map(|h| surface_of(st, r, h)))));
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
    trace_histories_guided(st, cond, targets, &[], &[], c);
}

/// The histories of four points around a surface point, on its plane,
/// whose agreement stands for the point's own flag (see
/// [`trace_histories_guided`]).
pub(super) type Guides<'a> = [&'a SunFlags; 4];

/// For each of `n` points, packed `nw` words to a point: the history
/// samples at which the point's guides all agree (the point lies inside
/// their square, so a straight shadow edge that leaves all four on one side
/// leaves the point there too), and their flag there; both empty when no
/// point is guided.
fn guide_words<'g>(
    n: usize,
    nw: usize,
    guide: impl Fn(usize) -> Option<Guides<'g>>,
) -> (Vec<u64>, Vec<u64>) {
    let mut agree = Vec::new();
    let mut flag = Vec::new();
    for p in 0..n {
        let Some(g) = guide(p) else { continue };
        if agree.is_empty() {
            agree = vec![0u64; n * nw];
            flag = vec![0u64; n * nw];
        }
        let (a, f) = (
            &mut agree[p * nw..(p + 1) * nw],
            &mut flag[p * nw..(p + 1) * nw],
        );
        for (w, x) in g[0].flags().words().enumerate() {
            f[w] = x;
            a[w] = !0;
        }
        for other in &g[1..] {
            for (w, x) in other.flags().words().enumerate() {
                a[w] &= !(f[w] ^ x);
            }
        }
    }
    (agree, flag)
}

/// The one transition index that all `guides` have inside the fine
/// interval (`lo`, `hi`], if they all have exactly that one there.
fn guided_switch(guides: &Guides, lo: usize, hi: usize) -> Option<u32> {
    let one = |g: &SunFlags| -> Option<u32> {
        let mut inside = (g.switches().iter()).filter(|&&s| s as usize > lo && s as usize <= hi);
        let s = *inside.next()?;
        inside.next().is_none().then_some(s)
    };
    let s = one(guides[0])?;
    guides[1..].iter().all(|g| one(g) == Some(s)).then_some(s)
}

/// Step 3 for surface points, some of them guided: where a point's four
/// `guides` (same plane and material, the point inside their square) agree
/// at a traced history sample, that sample is not traced and takes their
/// flag, and a transition that all four make at one fine sample between
/// two such samples is theirs; the traced samples in `force` (the last
/// hour's, whose flags a donated history was checked against) are always
/// traced. An empty `guides` (or a `None`) traces every sample.
pub(super) fn trace_histories_guided(
    st: &Static,
    cond: &Conditions,
    targets: &mut [&mut Surface],
    guides: &[Option<Guides>],
    force: &[usize],
    c: &Counters,
) {
    if targets.is_empty() {
        return; // (nothing to trace or count)
    }
    let guide = |p: usize| guides.get(p).copied().flatten();
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
    // Per guided point, packed as its history's words: the samples whose
    // flag its four guides agree on, and their flag there (a bit test per
    // sample instead of four searches of the guides' transitions).
    let (agree, given_flag) = guide_words(targets.len(), nw, guide);
    let agreed = |p: usize, k: usize| -> Option<bool> {
        let (w, b) = (p * nw + k / 64, k % 64);
        (agree.get(w).is_some_and(|a| a >> b & 1 == 1)).then(|| given_flag[w] >> b & 1 == 1)
    };
    let (mut away, mut solar) = (0, 0);
    let down = targets.len() * (nsun.div_ceil(every) - up.len());
    let mut active = vec![0u16; up.len()];
    let mut blocked = vec![0u16; up.len()];
    let mut known_lit = vec![0u16; up.len()];
    for start in (0..targets.len()).step_by(16) {
        let chunk = start..(start + 16).min(targets.len());
        // The points of the group that face each sun (lane bits), less
        // those whose guides give the flag.
        for ((act, lit), (&dir, &k)) in
            (active.iter_mut().zip(&mut known_lit)).zip(dirs.iter().zip(&up))
        {
            let facing: u16 = (normals[chunk.clone()].iter().enumerate())
                .filter(|(_, n)| n.dot(dir) > 0.0)
                .fold(0, |m, (lane, _)| m | 1 << lane);
            let mut known = 0u16;
            *lit = 0;
            if !guides.is_empty() && !force.contains(&k) {
                for lane in 0..chunk.len() {
                    if let Some(f) = agreed(start + lane, k) {
                        known |= 1 << lane;
                        *lit |= (f as u16) << lane;
                    }
                }
            }
            *lit &= facing;
            *act = facing & !known;
            let traced = act.count_ones() as usize;
            solar += traced;
            away += chunk.len() - facing.count_ones() as usize;
        }
        tracer.occluded_fan(&origins[chunk.clone()], &dirs, &active, &mut blocked);
        for (((&k, &act), &b), &lit) in up.iter().zip(&active).zip(&blocked).zip(&known_lit) {
            let (word, bit) = (k / 64, 1u64 << (k % 64));
            let mut open = (act & !b) | lit;
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
        // (about four transitions a point: sunrise and sunset on two days)
        let mut pending: Vec<(usize, usize, bool, usize)> = Vec::with_capacity(4 * targets.len());
        // (a transition that the guides make at one sample, between two
        // samples whose flags they gave, is theirs)
        let given = |p: usize, k: usize| !force.contains(&k) && agreed(p, k).is_some();
        let coarse = CoarsePairs::new(nsun, every);
        for p in 0..targets.len() {
            coarse.changes(&words[p * nw..(p + 1) * nw], |k| {
                let a = bit(p, k);
                let theirs = (given(p, k) && given(p, k + every))
                    .then(|| guide(p).and_then(|g| guided_switch(&g, k, k + every)))
                    .flatten();
                match theirs {
                    Some(s) => pending.push((s as usize - 1, s as usize, a, p)),
                    None => pending.push((k, k + every, a, p)),
                }
            });
        }
        let mut rays = Vec::with_capacity(pending.len());
        let mut ray_of = Vec::with_capacity(pending.len());
        let mut blocked = Vec::with_capacity(pending.len());
        let mut lit = vec![false; pending.len()];
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
            lit.fill(false);
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
        // Pending intervals were pushed in sample order per target, the
        // targets in order.
        let mut rest = &pending[..];
        let mut sw: Vec<u32> = Vec::new();
        for (p, t) in targets.iter_mut().enumerate() {
            let mine = rest.iter().take_while(|e| e.3 == p).count();
            sw.clear();
            sw.extend(rest[..mine].iter().map(|e| e.1 as u32));
            rest = &rest[mine..];
            t.history = SunFlags::from_switches(bit(p, 0), &sw, nsun);
        }
    }
    add(&c.sun_down, down);
    add(&c.away, away);
    add(&c.solar, solar);
}

/// The sun flags of surface points at the history samples `idx` (traced
/// samples: multiples of `coarse_every`), as [`trace_histories`] sets
/// them: sunlit when the sun is up, the point's side faces it and nothing
/// blocks the ray. Point `p`'s flag at `idx[j]` is `[p * idx.len() + j]`.
pub(super) fn sun_flags_at(
    st: &Static,
    cond: &Conditions,
    points: &[&Surface],
    idx: &[usize],
    c: &Counters,
) -> Vec<bool> {
    let mut flags = vec![false; points.len() * idx.len()];
    let (mut rays, mut of) = (
        Vec::with_capacity(flags.len()),
        Vec::with_capacity(flags.len()),
    );
    for (p, s) in points.iter().enumerate() {
        let origin = offset_origin(s.point, s.normal);
        for (j, &k) in idx.iter().enumerate() {
            let sun = &cond.suns[k];
            if sun.up && s.normal.dot(sun.dir) > 0.0 {
                rays.push(Ray::new(origin, sun.dir));
                of.push(p * idx.len() + j);
            }
        }
    }
    let mut blocked = vec![false; rays.len()];
    st.tracer.occluded(&rays, &mut blocked);
    add(&c.solar, rays.len());
    for (&i, &b) in of.iter().zip(&blocked) {
        flags[i] = !b;
    }
    flags
}

/// The pairs of traced history samples (`k`, `k + every`), `k` a multiple
/// of `every` and `k + every` < `nsun`, as bit masks over a point's packed
/// words: [`CoarsePairs::changes`] finds those whose two flags differ with
/// a few word operations instead of two bit tests per pair.
struct CoarsePairs {
    every: usize,
    /// Per word: the bits of the pairs' first samples.
    firsts: Vec<u64>,
}

impl CoarsePairs {
    fn new(nsun: usize, every: usize) -> Self {
        let nw = nsun.div_ceil(64);
        let mut firsts = vec![0u64; nw];
        let mut k = 0;
        while k + every < nsun {
            firsts[k / 64] |= 1 << (k % 64);
            k += every;
        }
        CoarsePairs { every, firsts }
    }

    /// Calls `f(k)` for each pair whose flags differ in `words` (bits set
    /// at traced samples only), in ascending `k`.
    fn changes(&self, words: &[u64], mut f: impl FnMut(usize)) {
        let e = self.every;
        let bit = |k: usize| words.get(k / 64).is_some_and(|w| w >> (k % 64) & 1 == 1);
        for (w, &first) in self.firsts.iter().enumerate() {
            if first == 0 {
                continue;
            }
            let x = words[w];
            // The flags `every` samples later, moved onto their pair's first.
            let later = if e < 64 {
                x >> e | words.get(w + 1).map_or(0, |n| n << (64 - e))
            } else {
                (0..64).fold(0u64, |m, b| m | u64::from(bit(64 * w + b + e)) << b)
            };
            let mut d = (x ^ later) & first;
            while d != 0 {
                f(64 * w + d.trailing_zeros() as usize);
                d &= d - 1;
            }
        }
    }
}

/// Steps 1-3 over blocks of sample pixels (rayon over blocks), each
/// block's samples in its tile order; fills the ray counters of `stats`
/// (added to what is there).
pub(super) fn trace_blocks(
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

/// Steps 1-3 for sample rows `y0..y1` (`y0` a multiple of [`BLOCK`]) into
/// `out`, in row-major order: rows of blocks in parallel, the blocks of a row in
/// parallel, each block's task moving its samples straight to their places
/// (no whole-frame reorder).
pub(super) fn trace_band(
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The word-parallel search finds exactly the pairs whose two flags
    /// differ, in order, against a bit-by-bit scan (lengths across word
    /// boundaries, intervals below and above 64).
    #[test]
    fn coarse_pairs_match_a_bit_by_bit_scan() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for nsun in [2usize, 3, 63, 64, 65, 145, 200, 433] {
            for every in [1usize, 2, 3, 6, 12, 63, 64, 70] {
                let nw = nsun.div_ceil(64);
                for _ in 0..20 {
                    // Bits at traced samples only, as the tracer leaves them.
                    let mut words = vec![0u64; nw];
                    let mut k = 0;
                    while k < nsun {
                        if next() % 3 == 0 {
                            words[k / 64] |= 1 << (k % 64);
                        }
                        k += every;
                    }
                    let bit = |k: usize| words[k / 64] >> (k % 64) & 1 == 1;
                    let mut want = Vec::new();
                    let mut k = 0;
                    while k + every < nsun {
                        if bit(k) != bit(k + every) {
                            want.push(k);
                        }
                        k += every;
                    }
                    let mut got = Vec::new();
                    CoarsePairs::new(nsun, every).changes(&words, |k| got.push(k));
                    assert_eq!(got, want, "nsun {nsun}, every {every}");
                }
            }
        }
    }
}
