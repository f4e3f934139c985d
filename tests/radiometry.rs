//! Radiometry against independent references (issue 5 acceptance).

use irsig::radiometry::planck::{
    brightness_temp_k, planck_band_integral_w_m2_sr, planck_dt_w_m2_sr_um_k,
    planck_radiance_w_m2_sr_cm1, planck_radiance_w_m2_sr_um,
};
use irsig::radiometry::{
    Band, PathRadiance, SkyRadiance, SpectralGrid, SpectralResponse, SunIllumination, case1_diffuse,
};

/// Band integrals ∫L_λ dλ vs scipy.integrate.quad (tools/ref_planck.py → tests/data/planck_band_ref.csv),
/// tolerance 1e-9 relative.
#[test]
fn planck_band_integrals_match_scipy_quadrature() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/planck_band_ref.csv"
    ))
    .unwrap();
    let mut n = 0;
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("lambda"))
    {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let got = planck_band_integral_w_m2_sr(f[0], f[1], f[2]);
        let rel = (got / f[3] - 1.0).abs();
        assert!(
            rel < 1e-9,
            "band {}-{} um at {} K: {got:e} vs {:e} (rel {rel:e})",
            f[0],
            f[1],
            f[2],
            f[3]
        );
        n += 1;
    }
    assert!(n >= 50, "only {n} reference rows");
}

/// The band quadrature on the 20 cm⁻¹ table grid (exact response weights, Planck
/// sampled at bin centres) approximates the exact band integral: 8-14 µm and
/// 3-5 µm at 200-400 K within 1e-3 relative. The midpoint-rule error is about
/// (c2 Δν / T)² / 24 ≈ 9e-4 for Δν = 20 cm⁻¹ at 200 K (Wien regime).
#[test]
fn grid_band_average_matches_exact_integral() {
    let g = SpectralGrid::uniform(500.0, 20.0, 1976);
    for (resp, lo, hi) in [
        (SpectralResponse::lwir(), 8.0, 14.0),
        (SpectralResponse::mwir(), 3.0, 5.0),
    ] {
        let b = Band::new(&g, &resp).unwrap();
        for t in [200.0, 300.0, 400.0] {
            let exact = planck_band_integral_w_m2_sr(lo, hi, t) / (hi - lo);
            let got = b.planck_w_m2_sr_um(t);
            assert!(
                (got / exact - 1.0).abs() < 1e-3,
                "{lo}-{hi} {t}: {got} vs {exact}"
            );
        }
    }
}

/// Band apparent temperature inverts the band Planck radiance to 1e-6 K, for
/// ideal and tabulated responses, wherever the band radiance is representable
/// (LWIR 20-6000 K, MWIR 60-6000 K: lower temperatures underflow f64 in those bands).
#[test]
fn band_apparent_temperature_round_trip() {
    let g = SpectralGrid::uniform(500.0, 20.0, 1976);
    let csv = SpectralResponse::from_csv_str("7.5,0\n8,0.6\n10,1\n12,0.8\n13,0\n", "test").unwrap();
    for (resp, tmin) in [
        (SpectralResponse::lwir(), 20.0),
        (SpectralResponse::mwir(), 60.0),
        (csv, 20.0),
    ] {
        let b = Band::new(&g, &resp).unwrap();
        let mut t = tmin;
        while t <= 6000.0 {
            let l = b.planck_w_m2_sr_um(t);
            let back = b.apparent_temp_k(l).unwrap();
            assert!((back - t).abs() < 1e-6, "{}: {t} -> {back}", resp.label);
            t *= 1.37;
        }
    }
    let b = Band::new(&g, &SpectralResponse::lwir()).unwrap();
    assert!(b.apparent_temp_k(0.0).is_none() && b.apparent_temp_k(f64::NAN).is_none());
}

/// No overflow, underflow to garbage, or NaN anywhere in 0.25-28 µm × 1-6000 K:
/// radiance finite, ≥ 0, monotone in T; brightness temperature round-trips where L > 0.
#[test]
fn planck_grid_is_finite_everywhere() {
    let n = 400;
    for i in 0..=n {
        let lam = 0.25 * (28.0f64 / 0.25).powf(i as f64 / n as f64);
        let mut prev = 0.0;
        for j in 0..=n {
            let t = 6000.0f64.powf(j as f64 / n as f64); // 1 .. 6000 K
            let l = planck_radiance_w_m2_sr_um(lam, t);
            let lnu = planck_radiance_w_m2_sr_cm1(1e4 / lam, t);
            let d = planck_dt_w_m2_sr_um_k(lam, t);
            assert!(
                l.is_finite()
                    && l >= 0.0
                    && lnu.is_finite()
                    && lnu >= 0.0
                    && d.is_finite()
                    && d >= 0.0
            );
            assert!(l >= prev, "not monotone at {lam} um {t} K");
            prev = l;
            if l > 1e-300 {
                let tb = brightness_temp_k(lam, l).unwrap();
                assert!((tb / t - 1.0).abs() < 1e-12, "{lam} {t} {tb}");
            }
        }
    }
    // the hottest, shortest corner is large but finite; the coldest is exactly 0
    assert!(planck_radiance_w_m2_sr_um(0.25, 6000.0) > 1e6);
    assert_eq!(planck_radiance_w_m2_sr_um(0.25, 1.0), 0.0);
}

/// A blackbody at air temperature seen through a transparent path: the band
/// radiance of eq. 1 equals the band Planck radiance (to 1e-12), for MWIR and LWIR.
#[test]
fn blackbody_transparent_path_gives_planck() {
    let g = SpectralGrid::uniform(500.0, 20.0, 1976);
    let t_air = 293.15;
    for resp in [SpectralResponse::lwir(), SpectralResponse::mwir()] {
        let b = Band::new(&g, &resp).unwrap();
        let mut band = 0.0;
        for (w, nu) in b.weights.iter().zip(&b.wavenumber_cm1) {
            let bb = planck_radiance_w_m2_sr_um(1e4 / nu, t_air);
            let sky = SkyRadiance {
                l_de_w_m2_sr_um: 0.7 * bb,
                l_ds_w_m2_sr_um: 0.01,
            };
            let sun = SunIllumination {
                e_sun_exo_w_m2_um: 10.0,
                tau1: 0.8,
                cos_incidence: 0.9,
                sun_flag: 1.0,
            };
            band += w * case1_diffuse(1.0, bb, &sun, &sky, &PathRadiance::TRANSPARENT).total();
        }
        let expect = b.planck_w_m2_sr_um(t_air);
        assert!((band / expect - 1.0).abs() < 1e-12, "{band} {expect}");
        assert!((b.apparent_temp_k(band).unwrap() - t_air).abs() < 1e-6);
    }
}

/// The memoised band coefficients of `RadiometryContext::evaluate` (a
/// diffuse sample = band sums per (material, path) and a Hermite table in
/// temperature) against the spectral loop of `evaluate_with`, the
/// reference, for every sample of a small render: each term within 1e-6
/// relative of the loop's (or 1e-12 W m⁻² sr⁻¹ µm⁻¹ where the term is
/// about zero), the apparent temperature within 0.001 K; the emissivity,
/// view angle and case identical. The sky (case 4), the ground beyond the
/// scene (case 0) and specular samples are the loop's own sums:
/// bit-identical. Scenes: airfield LWIR and MWIR near nadir at 1.5 km, an
/// oblique low view (150 m, below the tables' 0.3 km, view zeniths
/// 55-95°: sky and ground beyond), and terrain-km (a DEM, 5 km up).
#[test]
fn memoised_band_coefficients_match_the_spectral_loop() {
    use irsig::render::pixel::{RadiometryContext, SampleResult};
    use irsig::render::prepare::{prepare_conditions, prepare_static};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let airfield = root.join("scenes/airfield/scene.toml");
    let terrain = root.join("scenes/terrain-km/scene.toml");
    // (1 sample per pixel: the samples traced below are the image's pixels)
    let small = |px: u32| {
        vec![
            ("sensor.width_px".to_string(), px.to_string()),
            ("sensor.height_px".to_string(), px.to_string()),
            ("render.supersample".to_string(), "1".to_string()),
        ]
    };
    let with = |mut v: Vec<(String, String)>, kv: &[(&str, &str)]| {
        v.extend(kv.iter().map(|(k, x)| (k.to_string(), x.to_string())));
        v
    };
    let cases = [
        (
            "airfield lwir",
            &airfield,
            with(small(96), &[("sensor.band", "lwir")]),
        ),
        (
            "airfield mwir",
            &airfield,
            with(small(96), &[("sensor.band", "mwir")]),
        ),
        (
            "airfield oblique 150 m",
            &airfield,
            with(
                small(96),
                &[
                    ("sensor.band", "lwir"),
                    ("sensor.fov_h_deg", "40.0"),
                    ("sensor.pose.altitude.altitude_m", "150.0"),
                    ("sensor.pose.altitude.view_zenith_deg", "75.0"),
                ],
            ),
        ),
        ("terrain-km", &terrain, small(64)),
    ];
    for (name, scene, sets) in cases {
        let st = prepare_static(
            irsig::scene::load_with_overrides(scene, &sets).unwrap(),
            None,
        )
        .unwrap();
        let t = st.scene.scene.time.utc(&st.scene.scene.site);
        let cond = prepare_conditions(&st, t).unwrap();
        let (w, h) = (st.scene.camera.width_px, st.scene.camera.height_px);
        let pixels: Vec<(u32, u32)> = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).collect();
        let mut stats = Default::default();
        let samples = irsig::render::trace_samples(&st, &cond, &pixels, &mut stats).unwrap();
        let ctx = RadiometryContext::new(&st, &cond).unwrap();
        let terms = |r: &SampleResult| {
            let mut v = r.terms.values().to_vec();
            v.push(r.radiance_w_m2_sr_um);
            v
        };
        let (mut worst_rel, mut worst_k) = (0.0f64, 0.0f64);
        let mut count = [0usize; 5];
        for s in &samples {
            let fast = ctx.evaluate(s).unwrap();
            let reference = ctx.evaluate_with(s, |_, _| {}).unwrap();
            count[fast.case as usize] += 1;
            assert_eq!(fast.case, reference.case, "{name}");
            assert_eq!(
                fast.view_angle_deg.to_bits(),
                reference.view_angle_deg.to_bits(),
                "{name}"
            );
            if fast.case != 1 {
                // Memoised sums of the loop itself, or the loop.
                assert_eq!(
                    terms(&fast),
                    terms(&reference),
                    "{name}: case {}",
                    fast.case
                );
                assert_eq!(fast.emissivity.to_bits(), reference.emissivity.to_bits());
                continue;
            }
            assert!(
                (fast.emissivity - reference.emissivity).abs() < 1e-15,
                "{name}"
            );
            for (a, b) in terms(&fast).into_iter().zip(terms(&reference)) {
                let d = (a - b).abs();
                assert!(
                    d <= 1e-6 * b.abs() || d <= 1e-12,
                    "{name}: {a} vs {b} (terms {:?} vs {:?})",
                    fast.terms,
                    reference.terms
                );
                if b.abs() > 1e-12 {
                    worst_rel = worst_rel.max(d / b.abs());
                }
            }
            let ta = st.band.apparent_temp_k(fast.radiance_w_m2_sr_um).unwrap();
            let tb = st
                .band
                .apparent_temp_k(reference.radiance_w_m2_sr_um)
                .unwrap();
            worst_k = worst_k.max((ta - tb).abs());
        }
        eprintln!(
            "{name}: samples per case 0-4 {count:?}; worst relative term difference \
             {worst_rel:.2e}, worst apparent temperature difference {worst_k:.2e} K"
        );
        assert!(worst_k <= 1e-3, "{name}: {worst_k} K");
        assert!(count[1] > 1000, "{name}: diffuse samples {count:?}");
    }
}
