//! Tests of the memoising cache and its checkpoints.

use super::*;
use crate::therm::slab::{BackBoundary, solve_surface};
use rayon::prelude::*;

/// A facet's key with `shadow` as its history.
fn shaded_key<'a>(k: FacetKey<'a>, shadow: &'a SunHistory) -> FacetKey<'a> {
    FacetKey {
        shadow: Some(shadow.into()),
        ..k
    }
}

/// The solution of facet `k` through `cache`.
fn solve(
    cache: &ThermCache,
    k: FacetKey,
    m: &SlabMaterial,
    f: &[Forcing],
) -> Result<Arc<ThermSolution>, ThermError> {
    cache.solve_query(&cache.query(&k), m, f)
}

/// The owned key of facet `k`.
fn key(cache: &ThermCache, k: FacetKey) -> ThermKey {
    cache.query(&k).to_key()
}

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
            back: BackBoundary::Insulated,
            ..SlabMaterial::with_defaults(2000.0, 900.0, k, l, 0.7, 0.9)
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

/// 48 h of the test forcing's diurnal cycle, every 30 min, starting
/// 12 h into it (so the sun is up over hours 12-24 and 36-48).
fn two_days() -> Vec<Forcing> {
    let day = forcing();
    (0..=96)
        .map(|i| Forcing {
            t_s: i as f64 * 1800.0,
            ..day[(2 * i + 48) % 96]
        })
        .collect()
}

/// A history over [`two_days`] (30-min samples) shaded over `shade`.
fn shaded(shade: std::ops::Range<usize>) -> SunHistory {
    SunHistory {
        start_s: 0,
        interval_s: 1800,
        sunlit: (0..=96).map(|i| !shade.contains(&i)).collect(),
    }
}

#[test]
fn a_march_resumed_from_a_checkpoint_is_the_march_that_did_not_stop() {
    let f = two_days();
    let m = mats()[0];
    let flat = Orientation {
        slope_deg: 0.0,
        aspect_deg: 0.0,
    };
    // Histories alike until the last hours (a shadow arriving at 42 h
    // or 44 h), and one that differs on the first day.
    let (a, b, c) = (shaded(84..97), shaded(88..97), shaded(30..36));
    let k = FacetKey::new(0, flat, 1);
    let cache = ThermCache::new(ThermSettings::default(), 0.5, false);
    let sa = solve(&cache, shaded_key(k, &a), &m, &f).unwrap();
    let after_a = cache.stats();
    assert!(after_a.checkpoints >= 3, "{after_a:?}");
    assert_eq!(after_a.resumed, 0);
    let sb = solve(&cache, shaded_key(k, &b), &m, &f).unwrap();
    let sc = solve(&cache, shaded_key(k, &c), &m, &f).unwrap();
    let st = cache.stats();
    assert_eq!(
        st.resumed, 1,
        "b resumes from a's checkpoint, c cannot: {st:?}"
    );
    assert!(
        3 * sb.steps_accepted < 2 * sa.steps_accepted,
        "b marches only its last hours: {} vs {} steps",
        sb.steps_accepted,
        sa.steps_accepted
    );
    // Bit for bit what a cache that solves b alone, and the plain
    // march, give.
    for (h, s) in [(&b, &sb), (&a, &sa), (&c, &sc)] {
        let alone = solve(
            &ThermCache::new(ThermSettings::default(), 0.5, false),
            shaded_key(k, h),
            &m,
            &f,
        )
        .unwrap();
        let plain = solve_surface(&m, flat, Some(h), &f, &ThermSettings::default(), false).unwrap();
        assert_eq!(s.profile_k, alone.profile_k);
        assert_eq!(s.profile_k, plain.profile_k);
        assert_eq!(s.surface_temp_k.to_bits(), plain.surface_temp_k.to_bits());
    }
    // The shadow changes the answer (the test is not vacuous).
    assert!((sa.surface_temp_k - sb.surface_temp_k).abs() > 0.05);
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
    let temp_k = |o| {
        solve(&cache, FacetKey::new(0, o, 7), &m, &f)
            .unwrap()
            .surface_temp_k
    };
    let (ta, tb) = (temp_k(a), temp_k(b));
    assert_eq!(ta.to_bits(), tb.to_bits());
    let st = cache.stats();
    assert_eq!((st.hits, st.misses, st.entries), (1, 1, 1));
    assert!(st.steps > 0 && st.newton_iterations >= st.steps);
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
    let (sunlit, shade) = (history(48), history(40));
    assert_eq!(
        key(&cache, FacetKey::new(0, h0, 7)),
        key(&cache, shaded_key(FacetKey::new(0, h1, 7), &sunlit))
    );
    // Different history, material or weather: different keys.
    let ka = key(&cache, FacetKey::new(0, a, 7));
    assert_ne!(ka, key(&cache, shaded_key(FacetKey::new(0, a, 7), &shade)));
    assert_ne!(ka, key(&cache, FacetKey::new(1, a, 7)));
    assert_ne!(ka, key(&cache, FacetKey::new(0, a, 8)));
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
                    let h = history(s);
                    let k = shaded_key(FacetKey::new(m, o, 1), &h);
                    solve(&cache, k, &mats[m as usize], &f)
                        .unwrap()
                        .surface_temp_k
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
    let blocked = |blocked_sky| {
        let k = FacetKey {
            blocked_sky,
            ..FacetKey::new(0, o, 0)
        };
        solve(&cache, k, &m, &f).unwrap()
    };
    let open = blocked(0.0);
    let tiny = blocked(0.004);
    assert!(Arc::ptr_eq(&open, &tiny));
    let walled = blocked(0.301);
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

/// The render's sky-view nodes ([`ThermCache::sky_nodes`], 0.1 of the
/// hemisphere apart): the surface temperature interpolated linearly
/// between the two nodes around a blocked fraction, against the slab
/// model solved at that fraction itself (the converged reference: the
/// same march at 0.001 K), for a massive slab, a thin conducting plate and
/// an insulating layer, horizontal (fractions to 0.93) and vertical (to
/// 0.41: a wall's sky is half its hemisphere), sunlit and shaded since
/// noon, every 30 min of the second day: RMS ≤ 0.03 K, max ≤ 0.15 K (the
/// largest where a shaded plate crosses the air temperature between two
/// nodes and its convection changes regime) — and better than keying on
/// the 0.02 quantum alone, as the render did before (max 0.29, RMS 0.13 K).
#[test]
fn sky_nodes_interpolate_the_blocked_sky() {
    let f = two_days();
    let settings = ThermSettings {
        tol_k: Some(0.001),
        ..ThermSettings::default()
    };
    let cache = ThermCache::new(settings, 5.0, false);
    let node = SKY_QUANTUM * SKY_NODE_QUANTA as f64;
    let (mut worst, mut sq, mut worst_q, mut sq_q, mut n) = (0.0f64, 0.0, 0.0f64, 0.0, 0.0);
    let wall = Orientation {
        slope_deg: 90.0,
        aspect_deg: 180.0,
    };
    for m in mats() {
        for o in [Orientation::HORIZONTAL, wall] {
            for h in [None, Some(history(30))] {
                let model = SlabModel::new(&m, o, cache.settings()).unwrap();
                let at = |b: f64| {
                    model
                        .clone()
                        .with_blocked_sky(b)
                        .solve(&f, h.as_ref(), true)
                        .unwrap()
                };
                let nodes: Vec<ThermSolution> = (0..=(1.0 / node).round() as usize)
                    .map(|k| at(k as f64 * node))
                    .collect();
                let top = if o == wall { 0.5 } else { 1.0 };
                for b in [0.03, 0.07, 0.13, 0.26, 0.41, 0.55, 0.77, 0.93] {
                    if b > top {
                        continue;
                    }
                    let (lo, hi, w) = cache.sky_nodes(o, b);
                    let k = (lo.blocked_q() / SKY_NODE_QUANTA) as usize;
                    assert_eq!(hi.blocked_q(), lo.blocked_q() + SKY_NODE_QUANTA);
                    assert!((b - (k as f64 + w) * node).abs() < 1e-12);
                    let direct = at(b);
                    let quantised = at((b / SKY_QUANTUM).round() * SKY_QUANTUM);
                    for (j, r) in direct.series.iter().enumerate().skip(48) {
                        let (a, c) = (&nodes[k].series[j], &nodes[k + 1].series[j]);
                        let t = a.surface_temp_k + w * (c.surface_temp_k - a.surface_temp_k);
                        let e = (t - r.surface_temp_k).abs();
                        let eq = (quantised.series[j].surface_temp_k - r.surface_temp_k).abs();
                        (worst, worst_q) = (worst.max(e), worst_q.max(eq));
                        (sq, sq_q, n) = (sq + e * e, sq_q + eq * eq, n + 1.0);
                    }
                }
            }
        }
    }
    let (rms, rms_q) = ((sq / n).sqrt(), (sq_q / n).sqrt());
    assert!(
        rms <= 0.03 && worst <= 0.15,
        "interpolated: RMS {rms} K, max {worst} K"
    );
    assert!(
        rms < rms_q && worst < worst_q,
        "quantised: RMS {rms_q}, max {worst_q}"
    );
    // On a node: that node alone.
    let (lo, hi, w) = cache.sky_nodes(Orientation::HORIZONTAL, 0.0);
    assert_eq!((lo, w), (hi, 0.0));
    assert_eq!(lo.blocked_q(), 0);
    let (lo, hi, w) = cache.sky_nodes(Orientation::HORIZONTAL, 0.3);
    assert_eq!((lo.blocked_q(), hi.blocked_q(), w), (15, 15, 0.0));
}
