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
use crate::therm::cache::{FacetParts, HistoryRef, ThermCache, ThermMemo, ThermQuery};
use crate::therm::slab::{SlabMaterial, ThermError, ThermSolution};

/// Samples per progress report in the thermal and radiometry stages.
const PROGRESS_CHUNK: usize = 1024;

/// Step 4: the memoised thermal solution of a surface (with the whole
/// series of flux terms when the cache keeps series).
pub fn thermal_solution(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
) -> anyhow::Result<Arc<ThermSolution>> {
    with_key(st, cond, s, &mut KeyMemo::default(), |q, slab| {
        cond.cache.solve_query(q, slab, &cond.forcing)
    })
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

/// A worker's memo for step 4: the thermal cache's last-key memo and the
/// key parts' ([`KeyMemo`]).
#[derive(Default)]
struct TempMemo {
    therm: ThermMemo,
    keys: KeyMemo,
}

/// Step 4: the temperature of a surface at the image time, K (through
/// the worker's memo).
fn temperature(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
    memo: &mut TempMemo,
) -> anyhow::Result<f64> {
    with_key(st, cond, s, &mut memo.keys, |q, slab| {
        cond.cache
            .surface_temp_k_memo(q, slab, &cond.forcing, &mut memo.therm)
    })
}

/// The thermal key of surface `s` (its history keyed to
/// `cond.key_recent`, [`key_history`]; its facet parts through `keys`),
/// handed with its material's slab to `solve`; a solver error names the
/// material.
fn with_key<R>(
    st: &Static,
    cond: &Conditions,
    s: &Surface,
    keys: &mut KeyMemo,
    solve: impl FnOnce(&ThermQuery, &SlabMaterial) -> Result<R, ThermError>,
) -> anyhow::Result<R> {
    let m = s.material as usize;
    let keyed = key_history(&s.history, cond.key_recent);
    let q = therm_query(st, cond, s, keyed.as_ref().unwrap_or(&s.history), keys);
    solve(&q, &cond.slabs[m]).map_err(|e| therm_error(st, m, e))
}

/// Step 4 for every surface (primary and background) of `samples`.
pub(super) fn solve_temperatures(
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
