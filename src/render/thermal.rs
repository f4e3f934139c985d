//! Step 4 of the render: the surface temperatures from the memoised
//! thermal model, keyed by (material, orientation, history).

use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;

use super::cancel;
use super::frame::{StageProgress, Stats};
use super::prepare::{Conditions, Static};
use super::sample::{LastKey, Sample, Surface};
use super::sunflags::{self, SunFlags};
use crate::therm::balance::Orientation;
use crate::therm::cache::{
    CacheStats, FacetParts, HistoryRef, SKY_NODE_QUANTA, SkyNodes, ThermCache, ThermMemo,
    ThermQuery,
};
use crate::therm::slab::{ThermError, ThermSolution};

/// Samples per progress report in the thermal and radiometry stages.
const PROGRESS_CHUNK: usize = 1024;

/// Step 4: the memoised thermal solution of a surface (with the whole
/// series of flux terms when the cache keeps series): the solution at its
/// sky-view node, or, between two nodes, the two nodes' solutions
/// interpolated as [`temperature`] interpolates their temperatures
/// ([`lerp_solution`]), so that the solution ends at the temperature the
/// render used.
pub fn thermal_solution(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
) -> anyhow::Result<Arc<ThermSolution>> {
    let blocked = st.blocked_sky(s.prim, s.normal, s.point);
    let (a, hi) = at_nodes(st, cond, (s, blocked), &mut KeyMemo::default(), |q, _| {
        cond.cache
            .solve_query(q, &cond.slabs[s.material as usize], &cond.forcing)
    })?;
    match hi {
        None => Ok(a),
        Some((b, w)) => Ok(Arc::new(lerp_solution(&a, &b, w)?)),
    }
}

/// `f` applied to the thermal key of surface `s` (whose blocked sky
/// fraction is `blocked`: [`Static::blocked_sky`]) at its sky-view node, or
/// at the two nodes around that fraction (the upper one's
/// result with its weight): the one place a render builds a key (its
/// keyed history [`key_history`], its nodes [`ThermCache::sky_nodes`]).
fn at_nodes<R>(
    st: &Static,
    cond: &Conditions,
    (s, blocked): (&Surface, f64),
    keys: &mut KeyMemo,
    mut f: impl FnMut(&ThermQuery, FacetParts) -> Result<R, ThermError>,
) -> anyhow::Result<(R, Option<(R, f64)>)> {
    let m = s.material as usize;
    let keyed = key_history(&s.history, cond.key_recent);
    let history = keyed.as_ref().unwrap_or(&s.history);
    let (lo, hi, w) = facet_nodes(cond, s, blocked, keys);
    let mut at = |facet: FacetParts| {
        let q = therm_query(cond, s, history, facet, keys);
        f(&q, facet).map_err(|e| therm_error(st, m, e))
    };
    let a = at(lo)?;
    if w == 0.0 {
        return Ok((a, None));
    }
    Ok((a, Some((at(hi)?, w))))
}

/// `a` + `w`·(`b` − `a`) of two solutions of one facet and history at two
/// sky-view nodes: the temperatures, the water store, the profile and
/// every number of every series record (through the records' serde form,
/// so a field added to them is interpolated too; a field that is not a
/// number is `a`'s); the step counts are both solves' together. Quantities
/// computed from a record on demand (the stability function from the
/// Richardson number) follow the interpolated record.
fn lerp_solution(a: &ThermSolution, b: &ThermSolution, w: f64) -> anyhow::Result<ThermSolution> {
    fn lerp_json(x: &mut serde_json::Value, y: &serde_json::Value, w: f64) {
        use serde_json::Value;
        match (x, y) {
            (Value::Number(p), Value::Number(q)) => {
                if let (Some(u), Some(v)) = (p.as_f64(), q.as_f64())
                    && let Some(n) = serde_json::Number::from_f64(u + w * (v - u))
                    && p.is_f64()
                {
                    *p = n;
                }
            }
            (Value::Array(p), Value::Array(q)) => {
                p.iter_mut().zip(q).for_each(|(u, v)| lerp_json(u, v, w));
            }
            (Value::Object(p), Value::Object(q)) => {
                for (k, u) in p.iter_mut() {
                    if let Some(v) = q.get(k) {
                        lerp_json(u, v, w);
                    }
                }
            }
            _ => {}
        }
    }
    let lerp = |u: f64, v: f64| u + w * (v - u);
    let mut series = serde_json::to_value(&a.series)?;
    lerp_json(&mut series, &serde_json::to_value(&b.series)?, w);
    Ok(ThermSolution {
        surface_temp_k: lerp(a.surface_temp_k, b.surface_temp_k),
        water_store_mm: lerp(a.water_store_mm, b.water_store_mm),
        profile_k: (a.profile_k.iter().zip(&b.profile_k))
            .map(|(&u, &v)| lerp(u, v))
            .collect(),
        series: serde_json::from_value(series)?,
        steps_accepted: a.steps_accepted + b.steps_accepted,
        steps_rejected: a.steps_rejected + b.steps_rejected,
        newton_iterations: a.newton_iterations + b.newton_iterations,
    })
}

/// The key parts of the last facet side and height a worker saw: pure
/// functions of [`Surface::side`] with its blocked sky, and of z, that
/// neighbouring samples mostly share (a repeat skips the orientation's
/// acos/atan2 and the height's log; the key is the same).
#[derive(Default)]
struct KeyMemo {
    facet: LastKey<((u32, [u32; 3]), u64), SkyNodes>,
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

/// The sky-view nodes of a surface's facet side and its point's blocked
/// sky fraction ([`ThermCache::sky_nodes`]: lower and upper node and the
/// upper's weight).
fn facet_nodes(cond: &Conditions, s: &Surface, blocked: f64, memo: &mut KeyMemo) -> SkyNodes {
    memo.facet.get_or((s.side(), blocked.to_bits()), || {
        cond.cache.sky_nodes(
            Orientation::from_normal_enu(s.normal.as_dvec3().to_array()),
            blocked,
        )
    })
}

/// The thermal cache's key of a surface at sky-view node `facet` (borrows
/// its history, or the keyed history [`key_history`] made of it, which the
/// caller keeps).
fn therm_query<'a>(
    cond: &Conditions,
    s: &Surface,
    history: &'a SunFlags,
    facet: FacetParts,
    memo: &mut KeyMemo,
) -> ThermQuery<'a> {
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

/// A worker's memo for step 4: the thermal cache's last-key memo and the
/// key parts' ([`KeyMemo`]).
#[derive(Default)]
struct TempMemo {
    /// The thermal cache's last-key memos of the even and the odd sky-view
    /// nodes (a point between two nodes asks for both, alternately).
    therm: [ThermMemo; 2],
    keys: KeyMemo,
    /// The last surface's temperature under what it is a function of
    /// (material, facet side, blocked sky and height; history):
    /// neighbouring samples mostly repeat all five, and a repeat skips the
    /// key.
    last: Option<(LastSurface, SunFlags, f64)>,
}

/// What [`temperature`] is a function of besides the history, for
/// [`TempMemo::last`].
#[derive(PartialEq)]
struct LastSurface {
    material: u32,
    side: (u32, [u32; 3]),
    blocked_bits: u64,
    z_bits: u32,
}

/// Step 4: the temperature of a surface at the image time, K (through
/// the worker's memo): the solve at its sky-view node, or the linear
/// interpolation of the solves at the two nodes around its blocked sky
/// fraction ([`ThermCache::sky_nodes`]).
fn temperature(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
    memo: &mut TempMemo,
) -> anyhow::Result<f64> {
    let blocked = st.blocked_sky(s.prim, s.normal, s.point);
    let key = LastSurface {
        material: s.material,
        side: s.side(),
        blocked_bits: blocked.to_bits(),
        z_bits: s.point.z.to_bits(),
    };
    if let Some((last, history, t)) = &memo.last
        && *last == key
        && *history == s.history
    {
        memo.therm[0].hits += 1;
        return Ok(*t);
    }
    let slab = &cond.slabs[s.material as usize];
    let therm = &mut memo.therm;
    let (t_lo, hi) = at_nodes(st, cond, (s, blocked), &mut memo.keys, |q, facet| {
        let node_memo = &mut therm[((facet.blocked_q() / SKY_NODE_QUANTA) & 1) as usize];
        cond.cache
            .surface_temp_k_memo(q, slab, &cond.forcing, node_memo)
    })?;
    let t = match hi {
        None => t_lo,
        Some((t_hi, w)) => t_lo + w * (t_hi - t_lo),
    };
    memo.last = Some((key, s.history.clone(), t));
    Ok(t)
}

/// Step 4 for every surface (primary and background) of `samples`.
pub(super) fn solve_temperatures(
    st: &Static,
    cond: &Conditions,
    samples: &mut [Sample],
    stats: &mut Stats,
    progress: &StageProgress,
) -> anyhow::Result<()> {
    solve_temperatures_except(st, cond, samples, &[], stats, progress)
}

/// [`solve_temperatures`] for the samples whose `skip` flag is not set
/// (a sample beyond `skip`'s end is solved): a skipped sample keeps the
/// temperatures it has (adaptive sampling's donated values).
pub(super) fn solve_temperatures_except(
    st: &Static,
    cond: &Conditions,
    samples: &mut [Sample],
    skip: &[bool],
    stats: &mut Stats,
    progress: &StageProgress,
) -> anyhow::Result<()> {
    let t1 = Instant::now();
    let before = cond.cache.stats();
    samples
        .par_chunks_mut(PROGRESS_CHUNK)
        .enumerate()
        .try_for_each(|(c, chunk)| -> anyhow::Result<()> {
            cancel::check()?;
            let mut memo = SampleMemo::default();
            let skip = skip.get(c * PROGRESS_CHUNK..).unwrap_or(&[]);
            let solved = solve_samples(st, cond, chunk, skip, &mut memo);
            memo.absorb(cond);
            solved?;
            progress.add(chunk.len() as u64);
            Ok(())
        })?;
    add_cache_stats(stats, &before, &cond.cache.stats());
    stats.seconds.thermal += t1.elapsed().as_secs_f64();
    Ok(())
}

/// A worker's memos for [`solve_samples`] (one per worker and run of
/// samples; neighbouring samples mostly repeat a key). Its hits reach the
/// cache's counters through [`SampleMemo::absorb`].
#[derive(Default)]
pub(super) struct SampleMemo(TempMemo);

impl SampleMemo {
    /// Adds the memo's hits to the thermal cache's counters (and clears
    /// them, so that a memo may be absorbed again later).
    pub(super) fn absorb(&mut self, cond: &Conditions) {
        for m in &mut self.0.therm {
            cond.cache.absorb_memo(m);
            m.hits = 0;
        }
    }
}

/// Step 4 for the samples of `samples` whose `skip` flag is not set (a
/// sample beyond `skip`'s end is solved), on the calling thread, through
/// the worker's `memo`: the temperatures of their surfaces and specular
/// backgrounds. A result is a function of the sample alone (the memos only
/// skip repeated work).
pub(super) fn solve_samples(
    st: &Static,
    cond: &Conditions,
    samples: &mut [Sample],
    skip: &[bool],
    memo: &mut SampleMemo,
) -> anyhow::Result<()> {
    for (k, s) in samples.iter_mut().enumerate() {
        if skip.get(k).copied().unwrap_or(false) {
            continue;
        }
        if let Some(surf) = s.surface.as_mut() {
            surf.temp_k = temperature(st, cond, surf, &mut memo.0)?;
        }
        if let Some((_, Some(bg))) = s.bounce.as_deref_mut() {
            bg.temp_k = temperature(st, cond, bg, &mut memo.0)?;
        }
    }
    Ok(())
}

/// Adds the thermal cache's work between two of its snapshots to `stats`.
pub(super) fn add_cache_stats(stats: &mut Stats, before: &CacheStats, after: &CacheStats) {
    stats.thermal_solves += after.misses - before.misses;
    stats.thermal_cache_hits += after.hits - before.hits;
    stats.thermal_steps += after.steps - before.steps;
    stats.thermal_steps_rejected += after.steps_rejected - before.steps_rejected;
    stats.thermal_newton_iterations += after.newton_iterations - before.newton_iterations;
    stats.thermal_solve_core_s += (after.solve_ns - before.solve_ns) as f64 * 1e-9;
    stats.thermal_checkpoints += after.checkpoints - before.checkpoints;
    stats.thermal_resumed += after.resumed - before.resumed;
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
