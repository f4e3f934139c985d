//! Memoising cache of slab solutions (DESIGN.md §4 "Memoising").
//!
//! A pixel's temperature depends only on (material, facet orientation,
//! sun/shadow history, weather); many pixels share such a key, so each key
//! is solved once. The orientation is quantised to
//! [`ThermCache::orientation_quantum_deg`] and the solve uses the
//! *quantised* orientation, so a result is a function of its key alone: the
//! output does not depend on which pixel (or thread) asked first, i.e. it is
//! deterministic whatever the thread count.
//!
//! Concurrency: 64 shards, each a `Mutex<HashMap<key, Arc<OnceLock<…>>>>`.
//! The shard lock is held only to find or insert the entry; the solve runs
//! outside it, inside `OnceLock::get_or_init`, so every key is solved exactly
//! once and concurrent askers of the same key wait for that one solve.

use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use super::balance::Orientation;
use super::forcing::Forcing;
use super::slab::{SlabMaterial, SlabModel, SunHistory, ThermError, ThermSettings, ThermSolution};

const SHARDS: usize = 64;

/// The memoisation key. Built by [`ThermCache::key`].
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct ThermKey {
    pub material_id: u32,
    /// Quantised slope and aspect, in units of the cache's quantum.
    pub slope_q: i32,
    pub aspect_q: i32,
    /// Shadow history (all zeros / empty = always sunlit).
    pub shadow_start_s: i64,
    pub shadow_interval_s: i64,
    pub shadow_len: u32,
    pub shadow_bits: Box<[u64]>,
    /// Caller's identity of the forcing series (weather + site + time window).
    pub weather_id: u64,
}

/// Hit/miss counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CacheStats {
    pub hits: u64,
    pub misses: u64,
    pub entries: u64,
}

type Slot = Arc<OnceLock<Result<Arc<ThermSolution>, ThermError>>>;

/// Concurrent memoising cache of [`ThermSolution`]s for one set of
/// [`ThermSettings`].
pub struct ThermCache {
    settings: ThermSettings,
    orientation_quantum_deg: f64,
    with_series: bool,
    shards: Vec<Mutex<HashMap<ThermKey, Slot>>>,
    hits: AtomicU64,
    misses: AtomicU64,
}

impl ThermCache {
    /// Default orientation quantum, degrees (a 0.5° slope error changes
    /// cos(incidence) by < 0.9 %).
    pub const DEFAULT_QUANTUM_DEG: f64 = 0.5;

    /// `with_series`: keep the per-forcing-sample series in every entry
    /// (the render needs only the final temperature).
    pub fn new(settings: ThermSettings, orientation_quantum_deg: f64, with_series: bool) -> ThermCache {
        ThermCache {
            settings,
            orientation_quantum_deg: if orientation_quantum_deg > 0.0 {
                orientation_quantum_deg
            } else {
                Self::DEFAULT_QUANTUM_DEG
            },
            with_series,
            shards: (0..SHARDS).map(|_| Mutex::new(HashMap::new())).collect(),
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
        }
    }

    pub fn settings(&self) -> &ThermSettings {
        &self.settings
    }

    pub fn orientation_quantum_deg(&self) -> f64 {
        self.orientation_quantum_deg
    }

    /// Quantises an orientation: slope and aspect rounded to the quantum,
    /// aspect wrapped to [0°, 360°), and aspect set to 0 on a horizontal
    /// facet (where it does not matter). Returns the integer key parts and
    /// the orientation they stand for.
    pub fn quantise(&self, o: Orientation) -> (i32, i32, Orientation) {
        let q = self.orientation_quantum_deg;
        let slope_q = (o.slope_deg / q).round() as i32;
        let full = (360.0 / q).round() as i32;
        let mut aspect_q = ((o.aspect_deg / q).round() as i32).rem_euclid(full.max(1));
        if slope_q == 0 || slope_q as f64 * q >= 180.0 {
            aspect_q = 0;
        }
        (
            slope_q,
            aspect_q,
            Orientation {
                slope_deg: slope_q as f64 * q,
                aspect_deg: aspect_q as f64 * q,
            },
        )
    }

    /// The key of a (material, orientation, history, weather) combination.
    pub fn key(&self, material_id: u32, o: Orientation, shadow: Option<&SunHistory>, weather_id: u64) -> ThermKey {
        let (slope_q, aspect_q, _) = self.quantise(o);
        let (start, interval, len, bits) = match shadow {
            // An all-sunlit history is the same as no history.
            Some(h) if h.sunlit.iter().any(|b| !b) => (
                h.start_s,
                h.interval_s,
                h.sunlit.len() as u32,
                h.packed_bits().into_boxed_slice(),
            ),
            _ => (0, 0, 0, Box::default()),
        };
        ThermKey {
            material_id,
            slope_q,
            aspect_q,
            shadow_start_s: start,
            shadow_interval_s: interval,
            shadow_len: len,
            shadow_bits: bits,
            weather_id,
        }
    }

    /// The solution for this key, solving it (once) on a miss. `material`
    /// must be the material that `material_id` names and `forcing` the
    /// series that `weather_id` names: the cache trusts the ids.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &self,
        material_id: u32,
        material: &SlabMaterial,
        orientation: Orientation,
        shadow: Option<&SunHistory>,
        weather_id: u64,
        forcing: &[Forcing],
    ) -> Result<Arc<ThermSolution>, ThermError> {
        let key = self.key(material_id, orientation, shadow, weather_id);
        let mut hasher = DefaultHasher::new();
        key.hash(&mut hasher);
        let shard = &self.shards[(hasher.finish() as usize) % SHARDS];
        let slot: Slot = {
            let mut map = shard.lock().unwrap_or_else(|e| e.into_inner());
            match map.get(&key) {
                Some(s) => {
                    self.hits.fetch_add(1, Ordering::Relaxed);
                    s.clone()
                }
                None => {
                    self.misses.fetch_add(1, Ordering::Relaxed);
                    let s: Slot = Arc::new(OnceLock::new());
                    map.insert(key, s.clone());
                    s
                }
            }
        };
        slot.get_or_init(|| {
            let (_, _, oq) = self.quantise(orientation);
            let history = shadow.filter(|h| h.sunlit.iter().any(|b| !b));
            SlabModel::new(material, oq, &self.settings)
                .and_then(|m| m.solve(forcing, history, self.with_series))
                .map(Arc::new)
        })
        .clone()
    }

    /// Surface temperature at the last forcing time (the image time), K.
    pub fn surface_temp_k(
        &self,
        material_id: u32,
        material: &SlabMaterial,
        orientation: Orientation,
        shadow: Option<&SunHistory>,
        weather_id: u64,
        forcing: &[Forcing],
    ) -> Result<f64, ThermError> {
        self.solve(material_id, material, orientation, shadow, weather_id, forcing)
            .map(|s| s.surface_temp_k)
    }

    pub fn stats(&self) -> CacheStats {
        let entries = self
            .shards
            .iter()
            .map(|s| s.lock().unwrap_or_else(|e| e.into_inner()).len() as u64)
            .sum();
        CacheStats {
            hits: self.hits.load(Ordering::Relaxed),
            misses: self.misses.load(Ordering::Relaxed),
            entries,
        }
    }
}
