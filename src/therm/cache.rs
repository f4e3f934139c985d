//! Memoising cache of slab solutions (docs/models.md, "Memoising").
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
    /// Facet height above the ground, quantised by [`ThermCache::quantise_height`].
    pub height_q: i32,
    /// Fraction of the hemisphere's sky hidden by the scene, in units of
    /// [`SKY_QUANTUM`] (0: unobstructed).
    pub blocked_q: i32,
}

/// Quantum of the blocked sky fraction in the cache key (and the solve):
/// ±0.01 of the hemisphere, about ±1 W/m² of longwave, ≤ 0.1 K.
pub const SKY_QUANTUM: f64 = 0.02;

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
    pub fn new(
        settings: ThermSettings,
        orientation_quantum_deg: f64,
        with_series: bool,
    ) -> ThermCache {
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

    /// Quantises a facet's height above the ground: steps of 5 % in
    /// `ln((z + 2 m)/2 m)` (the log-law wind changes by well under 1 % per
    /// step); returns the key part and the height it stands for, m.
    pub fn quantise_height(height_m: f64) -> (i32, f64) {
        let z = if height_m.is_finite() {
            height_m.clamp(0.0, 1e4)
        } else {
            0.0
        };
        let q = (((z + 2.0) / 2.0).ln() / 0.05).round() as i32;
        (q, (2.0 * (0.05 * q as f64).exp() - 2.0).max(0.0))
    }

    /// The key of a (material, orientation, history, weather) combination
    /// for a facet at ground level.
    pub fn key(
        &self,
        material_id: u32,
        o: Orientation,
        shadow: Option<&SunHistory>,
        weather_id: u64,
    ) -> ThermKey {
        self.key_at(material_id, o, shadow, weather_id, 0.0)
    }

    /// [`ThermCache::key`] for a facet `height_m` above the ground.
    pub fn key_at(
        &self,
        material_id: u32,
        o: Orientation,
        shadow: Option<&SunHistory>,
        weather_id: u64,
        height_m: f64,
    ) -> ThermKey {
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
            height_q: Self::quantise_height(height_m).0,
            blocked_q: 0,
        }
    }

    /// The solution for this key, solving it (once) on a miss. `material`
    /// must be the material that `material_id` names and `forcing` the
    /// series that `weather_id` names: the cache trusts the ids.
    pub fn solve(
        &self,
        material_id: u32,
        material: &SlabMaterial,
        orientation: Orientation,
        shadow: Option<&SunHistory>,
        weather_id: u64,
        forcing: &[Forcing],
    ) -> Result<Arc<ThermSolution>, ThermError> {
        self.solve_at(
            material_id,
            material,
            orientation,
            shadow,
            weather_id,
            forcing,
            0.0,
        )
    }

    /// [`ThermCache::solve`] for a facet `height_m` above the ground (the
    /// wind at the facet; the solve uses the quantised height).
    #[allow(clippy::too_many_arguments)]
    pub fn solve_at(
        &self,
        material_id: u32,
        material: &SlabMaterial,
        orientation: Orientation,
        shadow: Option<&SunHistory>,
        weather_id: u64,
        forcing: &[Forcing],
        height_m: f64,
    ) -> Result<Arc<ThermSolution>, ThermError> {
        self.solve_in_scene(
            material_id,
            material,
            orientation,
            shadow,
            weather_id,
            forcing,
            height_m,
            0.0,
        )
    }

    /// [`ThermCache::solve_at`] for a facet whose sky is partly hidden by
    /// the scene (`blocked_sky`, see `trace::sky_view`; the solve uses the
    /// fraction quantised to [`SKY_QUANTUM`]).
    #[allow(clippy::too_many_arguments)]
    pub fn solve_in_scene(
        &self,
        material_id: u32,
        material: &SlabMaterial,
        orientation: Orientation,
        shadow: Option<&SunHistory>,
        weather_id: u64,
        forcing: &[Forcing],
        height_m: f64,
        blocked_sky: f64,
    ) -> Result<Arc<ThermSolution>, ThermError> {
        let mut key = self.key_at(material_id, orientation, shadow, weather_id, height_m);
        key.blocked_q = if blocked_sky.is_finite() {
            (blocked_sky.clamp(0.0, 1.0) / SKY_QUANTUM).round() as i32
        } else {
            0
        };
        let blocked_q = key.blocked_q;
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
            let (_, zq) = Self::quantise_height(height_m);
            SlabModel::new(material, oq, &self.settings)
                .and_then(|m| {
                    m.with_height(zq)
                        .with_blocked_sky(blocked_q as f64 * SKY_QUANTUM)
                        .solve(forcing, history, self.with_series)
                })
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
        self.solve(
            material_id,
            material,
            orientation,
            shadow,
            weather_id,
            forcing,
        )
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::therm::slab::BackBoundary;
    use rayon::prelude::*;

    fn forcing() -> Vec<Forcing> {
        (0..=96)
            .map(|i| {
                let t = i as f64 * 900.0;
                let ph = (t / 86400.0 * std::f64::consts::TAU).sin();
                Forcing {
                    t_s: t,
                    air_temp_k: 290.0 + 6.0 * ph,
                    sky_temp_k: 265.0,
                    wind_speed_m_s: 2.0,
                    dni_w_m2: (700.0 * ph).max(0.0),
                    dhi_w_m2: (80.0 * ph).max(0.0),
                    ghi_w_m2: (600.0 * ph).max(0.0),
                    sun_dir_enu: [0.3 * ph, -0.5, ph],
                    dew_point_k: crate::therm::forcing::DRY_AIR_DEW_POINT_K,
                    pressure_pa: 101_325.0,
                    precip_mm_h: 0.0,
                    ground_temp_k: None,
                }
            })
            .collect()
    }

    fn mats() -> Vec<SlabMaterial> {
        [(0.2, 1.4), (0.0005, 200.0), (0.05, 0.3)]
            .iter()
            .map(|&(l, k)| SlabMaterial {
                density_kg_m3: 2000.0,
                specific_heat_j_kgk: 900.0,
                conductivity_w_mk: k,
                thickness_m: l,
                solar_absorptivity: 0.7,
                thermal_emissivity: 0.9,
                back: BackBoundary::Insulated,
                internal_power_w_m2: 0.0,
                ground_albedo: None,
                surface: crate::therm::surface::SurfaceKind::default(),
            })
            .collect()
    }

    fn history(shade_from: usize) -> SunHistory {
        SunHistory {
            start_s: 86400 - 47 * 1800,
            interval_s: 1800,
            sunlit: (0..48).map(|i| i < shade_from).collect(),
        }
    }

    #[test]
    fn quantised_orientations_share_an_entry_and_solve_the_quantised_facet() {
        let f = forcing();
        let m = mats()[0];
        let cache = ThermCache::new(ThermSettings::default(), 0.5, false);
        let a = Orientation {
            slope_deg: 30.1,
            aspect_deg: 179.9,
        };
        let b = Orientation {
            slope_deg: 29.9,
            aspect_deg: 180.2,
        };
        let ta = cache.surface_temp_k(0, &m, a, None, 7, &f).unwrap();
        let tb = cache.surface_temp_k(0, &m, b, None, 7, &f).unwrap();
        assert_eq!(ta.to_bits(), tb.to_bits());
        assert_eq!(
            cache.stats(),
            CacheStats {
                hits: 1,
                misses: 1,
                entries: 1
            }
        );
        // Equals a direct solve at the quantised orientation (30°, 180°).
        let direct = SlabModel::new(
            &m,
            Orientation {
                slope_deg: 30.0,
                aspect_deg: 180.0,
            },
            &ThermSettings::default(),
        )
        .unwrap()
        .solve(&f, None, false)
        .unwrap();
        assert_eq!(direct.surface_temp_k.to_bits(), ta.to_bits());
        // Horizontal facets ignore aspect; an all-sunlit history is no history.
        let h0 = Orientation {
            slope_deg: 0.1,
            aspect_deg: 90.0,
        };
        let h1 = Orientation {
            slope_deg: 0.0,
            aspect_deg: 270.0,
        };
        assert_eq!(
            cache.key(0, h0, None, 7),
            cache.key(0, h1, Some(&history(48)), 7)
        );
        // Different history, material or weather: different keys.
        assert_ne!(
            cache.key(0, a, None, 7),
            cache.key(0, a, Some(&history(40)), 7)
        );
        assert_ne!(cache.key(0, a, None, 7), cache.key(1, a, None, 7));
        assert_ne!(cache.key(0, a, None, 7), cache.key(0, a, None, 8));
    }

    #[test]
    fn concurrent_use_is_deterministic_and_solves_each_key_once() {
        let f = forcing();
        let mats = mats();
        // 600 requests over 3 materials × 4 orientations × 3 histories = 36 keys,
        // orientations jittered within the quantum.
        let reqs: Vec<(u32, Orientation, usize)> = (0..600)
            .map(|i| {
                let jitter = ((i * 37) % 9) as f64 * 0.02 - 0.08;
                (
                    (i % 3) as u32,
                    Orientation {
                        slope_deg: 15.0 * ((i / 3) % 4) as f64 + jitter,
                        aspect_deg: 90.0 + jitter,
                    },
                    [48, 44, 30][(i / 12) % 3],
                )
            })
            .collect();
        let run = |threads: usize| {
            let cache = ThermCache::new(ThermSettings::default(), 0.5, false);
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let temps: Vec<u64> = pool.install(|| {
                reqs.par_iter()
                    .map(|&(m, o, s)| {
                        cache
                            .surface_temp_k(m, &mats[m as usize], o, Some(&history(s)), 1, &f)
                            .unwrap()
                            .to_bits()
                    })
                    .collect()
            });
            (temps, cache.stats())
        };
        let (t1, s1) = run(1);
        let (t4, s4) = run(4);
        assert_eq!(t1, t4);
        assert_eq!(s1.misses, 36);
        assert_eq!(s4.misses, 36);
        assert_eq!(s4.hits + s4.misses, 600);
        assert_eq!(s4.entries, 36);
    }

    /// Height keys: ground level is 0 m exactly; a quantised height is
    /// within 2.5 % of the reference height z + 2 m; the wind at the
    /// facet then differs by < 1 % (log law, z0 = 0.03 m).
    #[test]
    fn height_quantum() {
        assert_eq!(ThermCache::quantise_height(0.0), (0, 0.0));
        for z in [0.3, 2.0, 8.5, 40.0, 300.0] {
            let (_, zq) = ThermCache::quantise_height(z);
            assert!(
                ((zq + 2.0) / (z + 2.0)).ln().abs() <= 0.025 + 1e-12,
                "{z} -> {zq}"
            );
            let u = |h: f64| ((h + 2.0) / 0.03f64).ln();
            assert!((u(zq) / u(z) - 1.0).abs() < 0.01);
        }
        assert_eq!(ThermCache::quantise_height(f64::NAN), (0, 0.0));
    }

    /// A facet whose sky is 30 % hidden (by walls at the ground's
    /// temperature, here the air's) loses less longwave to the 265-K sky
    /// than an open one and ends warmer; a hidden fraction below half a
    /// quantum shares the open facet's entry; the cached solve is the slab
    /// model's with the quantised fraction.
    #[test]
    fn blocked_sky_is_keyed_and_warms_at_night() {
        let f = forcing();
        let m = mats()[0];
        let cache = ThermCache::new(ThermSettings::default(), 5.0, false);
        let o = Orientation::HORIZONTAL;
        let open = cache
            .solve_in_scene(0, &m, o, None, 0, &f, 0.0, 0.0)
            .unwrap();
        let tiny = cache
            .solve_in_scene(0, &m, o, None, 0, &f, 0.0, 0.004)
            .unwrap();
        assert!(Arc::ptr_eq(&open, &tiny));
        let walled = cache
            .solve_in_scene(0, &m, o, None, 0, &f, 0.0, 0.301)
            .unwrap();
        assert!(
            walled.surface_temp_k > open.surface_temp_k + 0.5,
            "{} vs {}",
            walled.surface_temp_k,
            open.surface_temp_k
        );
        let direct = SlabModel::new(&m, o, cache.settings())
            .unwrap()
            .with_blocked_sky(0.30)
            .solve(&f, None, false)
            .unwrap();
        assert_eq!(walled.surface_temp_k, direct.surface_temp_k);
        assert_eq!(cache.stats().misses, 2);
    }
}
