//! Radiometry extremes: Planck over 0.25-20 µm × 1-6000 K, band integrals and
//! band apparent temperatures at the table edges, Fresnel emissivity to
//! grazing incidence, the atmosphere at the edges of its grids, and the
//! seed's eqs. 1-4 with ε → 0 and → 1, grazing sun and every source
//! temperature extreme.

use irsig::atmos::{Atmosphere, SpectralAtmosphere, list_builtin};
use irsig::radiometry::planck::planck_dt_w_m2_sr_um_k;
use irsig::radiometry::{
    Background, Band, Emissivity, EmissivityTable, PathRadiance, RadianceTerms, SkyRadiance,
    SpectralGrid, SpectralResponse, SunIllumination, brightness_temp_k, case1_diffuse,
    case2_specular_sky, case3_specular_background, case4_sky, fresnel_reflectance, integrate_terms,
    planck_band_integral_w_m2_sr, planck_radiance_w_m2_sr_cm1, planck_radiance_w_m2_sr_um,
};

/// Stefan-Boltzmann constant, W m⁻² K⁻⁴ (CODATA 2018).
const SIGMA: f64 = 5.670_374_419e-8;

/// Hottest layer of any shipped LOWTRAN-7 model atmosphere (tropical surface,
/// 299.7 K) with a margin: no atmospheric emission may exceed Planck at this
/// temperature.
const T_ATMOS_MAX_K: f64 = 310.0;

/// Hottest source allowed in the stress cases (the sun's photosphere is
/// ~5772 K; its disk radiance is below Planck at 6000 K at every wavelength
/// here, and reflected or scattered sunlight is far below the disk radiance).
const T_SUN_BOUND_K: f64 = 6000.0;

/// `n` points from `lo` to `hi` (both included), evenly spaced in log.
fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let mut v: Vec<f64> = (0..n)
        .map(|i| (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1) as f64).exp())
        .collect();
    v[0] = lo;
    v[n - 1] = hi;
    v
}

fn temps() -> Vec<f64> {
    let mut t = log_grid(1.0, 6000.0, 90);
    t.extend([1.0 + 1e-9, 2.7, 77.0, 273.15, 300.0, 5772.0, 6000.0 - 1e-9]);
    t.sort_by(f64::total_cmp);
    t
}

fn wavelengths_um() -> Vec<f64> {
    let mut l = log_grid(0.25, 20.0, 80);
    // the atmosphere tables' own edges, 40000 and 500 cm⁻¹, and one bin inside
    l.extend([1e4 / 40000.0, 1e4 / 39980.0, 1e4 / 520.0, 1e4 / 500.0]);
    l
}

/// Planck per µm and per cm⁻¹, its T-derivative and its inverse over
/// 0.25-20 µm × 1-6000 K: finite, ≥ 0, non-decreasing in T, the two forms
/// consistent (L_ν = L_λ λ²/10⁴, relative 1e-12 where L is a normal f64),
/// and the brightness temperature of every representable radiance returns
/// T (relative 1e-9); an underflowed (zero) radiance has no brightness
/// temperature.
#[test]
fn planck_extremes_finite_monotone_and_invertible() {
    let ts = temps();
    let mut checked_inverse = 0usize;
    for &lam in &wavelengths_um() {
        let mut prev = 0.0f64;
        for &t in &ts {
            let l = planck_radiance_w_m2_sr_um(lam, t);
            let ctx = format!("lambda {lam} um, T {t} K");
            assert!(l.is_finite() && l >= 0.0, "{ctx}: L = {l}");
            assert!(l >= prev, "{ctx}: L fell with T ({prev} -> {l})");
            prev = l;
            let lnu = planck_radiance_w_m2_sr_cm1(1e4 / lam, t);
            assert!(lnu.is_finite() && lnu >= 0.0, "{ctx}: L_nu = {lnu}");
            if l > 1e-290 && lnu > 1e-290 {
                assert!(
                    (lnu / (l * lam * lam / 1e4) - 1.0).abs() < 1e-12,
                    "{ctx}: per-um and per-cm-1 forms disagree"
                );
            }
            let d = planck_dt_w_m2_sr_um_k(lam, t);
            assert!(d.is_finite() && d >= 0.0, "{ctx}: dL/dT = {d}");
            match brightness_temp_k(lam, l) {
                Some(bt) => {
                    assert!(l > 0.0, "{ctx}");
                    assert!(bt.is_finite() && bt > 0.0, "{ctx}: Tb = {bt}");
                    if l > 1e-290 {
                        assert!((bt / t - 1.0).abs() < 1e-9, "{ctx}: Tb = {bt}");
                        checked_inverse += 1;
                    }
                }
                None => assert_eq!(l, 0.0, "{ctx}: no brightness temperature for L > 0"),
            }
        }
    }
    assert!(checked_inverse > 5000, "{checked_inverse}");
    // bad input is zero radiance / no temperature, never NaN
    for (lam, t) in [
        (0.0, 300.0),
        (-1.0, 300.0),
        (10.0, 0.0),
        (10.0, -5.0),
        (f64::NAN, 300.0),
        (10.0, f64::NAN),
        (10.0, f64::INFINITY),
    ] {
        assert_eq!(planck_radiance_w_m2_sr_um(lam, t), 0.0, "{lam} {t}");
        assert_eq!(planck_radiance_w_m2_sr_cm1(1e4 / lam, t), 0.0, "{lam} {t}");
    }
    for l in [0.0, -1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(brightness_temp_k(10.0, l), None, "{l}");
    }
}

/// Exact band integrals of Planck over bands at the table edges and the
/// whole 0.25-20 µm, 1-6000 K: finite, ≥ 0, non-decreasing in T, never more
/// than the total σT⁴/π, and equal to σT⁴/π (relative 1e-9) for a band
/// wide enough to hold all of it.
#[test]
fn planck_band_integrals_bounded_by_stefan_boltzmann() {
    let bands = [
        (0.25, 20.0),
        (0.25, 0.2501),
        (0.25, 0.3),
        (19.99, 20.0),
        (18.0, 20.0),
        (3.0, 5.0),
        (8.0, 14.0),
    ];
    for (a, b) in bands {
        let mut prev = 0.0f64;
        for &t in &temps() {
            let l = planck_band_integral_w_m2_sr(a, b, t);
            let total = SIGMA * t.powi(4) / std::f64::consts::PI;
            assert!(l.is_finite() && l >= 0.0, "{a}-{b} um {t} K: {l}");
            assert!(l <= total * (1.0 + 1e-9), "{a}-{b} um {t} K: {l} > {total}");
            assert!(l >= prev * (1.0 - 1e-12), "{a}-{b} um {t} K: fell with T");
            prev = l;
        }
    }
    for t in [1.0f64, 10.0, 300.0, 6000.0] {
        let all = planck_band_integral_w_m2_sr(1e-3 * 300.0 / t.max(300.0), 1e9, t);
        let total = SIGMA * t.powi(4) / std::f64::consts::PI;
        assert!((all / total - 1.0).abs() < 1e-9, "{t} K: {all} vs {total}");
    }
}

/// The shipped tables' grid: 500-40000 cm⁻¹ (20-0.25 µm) every 20 cm⁻¹.
fn table_grid() -> SpectralGrid {
    SpectralGrid::uniform(500.0, 20.0, 1976)
}

fn edge_bands() -> Vec<SpectralResponse> {
    vec![
        SpectralResponse::ideal(0.25, 0.3).unwrap(),
        SpectralResponse::ideal(0.25, 20.0).unwrap(),
        SpectralResponse::mwir(),
        SpectralResponse::lwir(),
        SpectralResponse::ideal(18.0, 20.0).unwrap(),
        // a band wider than the grid: only the overlapping bins count
        SpectralResponse::ideal(0.2, 30.0).unwrap(),
    ]
}

/// Band apparent temperature at the table edges, 1-6000 K: the band
/// radiance of a blackbody at T inverts to T (relative 1e-6) wherever it is
/// a normal f64; zero, negative, non-finite and out-of-range radiances have
/// none (never NaN, never a panic).
#[test]
fn band_apparent_temperature_round_trips_at_table_edges() {
    let grid = table_grid();
    for resp in edge_bands() {
        let band = Band::new(&grid, &resp).unwrap();
        let wsum: f64 = band.weights.iter().sum();
        assert!(
            (wsum - 1.0).abs() < 1e-12,
            "{}: weights sum {wsum}",
            band.label
        );
        assert!(band.weights.iter().all(|w| w.is_finite() && *w >= 0.0));
        let mut prev = 0.0f64;
        for &t in &temps() {
            let l = band.planck_w_m2_sr_um(t);
            let ctx = format!("{} at {t} K", band.label);
            assert!(l.is_finite() && l >= 0.0 && l >= prev, "{ctx}: {l}");
            prev = l;
            match band.apparent_temp_k(l) {
                Some(ta) => {
                    assert!(ta.is_finite() && ta > 0.0, "{ctx}: {ta}");
                    if l > 1e-290 {
                        assert!((ta / t - 1.0).abs() < 1e-6, "{ctx}: apparent {ta}");
                    }
                }
                None => assert_eq!(l, 0.0, "{ctx}: no apparent temperature for L = {l}"),
            }
        }
        for l in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e300] {
            assert_eq!(band.apparent_temp_k(l), None, "{}: {l}", band.label);
        }
    }
    // bands outside the grid are an error, not an empty band
    for (a, b) in [(0.2, 0.24), (21.0, 30.0)] {
        assert!(Band::new(&grid, &SpectralResponse::ideal(a, b).unwrap()).is_err());
    }
}

/// Fresnel reflectances and emissivity for refractive indices over the
/// range a scene may give (n 1e-6 to 1e4, k 0 to 1e4), at incidence 0° to
/// grazing (89.9°, 89.99°, 90°) and beyond (clamped): Rs, Rp, R and ε are
/// finite and in [0, 1] (within 1e-12). Tabulated emissivities outside
/// their grid clamp to edge values in [0, 1]; tables with values outside
/// [0, 1] or NaN are refused.
#[test]
fn emissivity_extremes_stay_in_unit_interval() {
    let ns = [
        1e-6,
        0.01,
        0.5,
        1.0 - 1e-9,
        1.0,
        1.0 + 1e-9,
        1.33,
        4.0,
        50.0,
        1e4,
    ];
    let ks = [0.0, 1e-9, 1e-3, 0.1, 1.0, 30.0, 1e4];
    let mut angles: Vec<f64> = (0..=89).map(f64::from).collect();
    angles.extend([89.5, 89.9, 89.99, 89.999_999, 90.0, -5.0, 95.0, 180.0]);
    let within = |x: f64| x.is_finite() && (-1e-12..=1.0 + 1e-12).contains(&x);
    for &n in &ns {
        for &k in &ks {
            for &a in &angles {
                let (rs, rp, r) = fresnel_reflectance(n, k, a);
                let e = Emissivity::Fresnel { n, k }.at(a, 10.0);
                let ctx = format!("n {n} k {k} at {a} deg: Rs {rs} Rp {rp} R {r} eps {e}");
                assert!(within(rs) && within(rp) && within(r) && within(e), "{ctx}");
                assert!((e + r - 1.0).abs() < 1e-12, "{ctx}");
            }
            // grazing incidence reflects (almost) everything for any interface
            // that is not index-matched (N = 1)
            if (n - 1.0).abs() > 1e-3 || k > 1e-3 {
                let (_, _, r) = fresnel_reflectance(n, k, 89.999_999);
                assert!(r > 0.99, "n {n} k {k}: R at grazing {r}");
            }
        }
    }
    let t = EmissivityTable::new(
        vec![0.0, 60.0, 85.0],
        vec![3.0, 10.0],
        vec![0.0, 1.0, 0.5, 0.9, 1.0, 0.0],
    )
    .unwrap();
    for a in [-10.0, 0.0, 45.0, 85.0, 89.9, 90.0, 1e9] {
        for l in [0.0, 0.25, 3.0, 7.5, 20.0, 1e9] {
            let e = Emissivity::Table(t.clone()).at(a, l);
            assert!(within(e), "table at {a} deg {l} um: {e}");
        }
    }
    for bad in [1.0 + 1e-9, -1e-9, f64::NAN, f64::INFINITY] {
        assert!(
            EmissivityTable::new(vec![0.0], vec![10.0], vec![bad]).is_err(),
            "{bad}"
        );
    }
}

/// All shipped atmospheres.
fn atmospheres() -> Vec<Atmosphere> {
    let list = list_builtin().unwrap();
    assert!(list.len() >= 2, "expected the shipped atmosphere tables");
    list.iter()
        .map(|(n, _, _)| Atmosphere::builtin(n).unwrap())
        .collect()
}

fn axis(atm: &Atmosphere, q: &str, name: &str) -> Vec<f64> {
    atm.table
        .quantity(q)
        .unwrap()
        .axes
        .iter()
        .find(|a| a.name == name)
        .unwrap()
        .values
        .clone()
}

/// (min, max) of the altitudes every path quantity covers.
fn altitude_range(atm: &Atmosphere) -> (f64, f64) {
    let a = axis(atm, "tau_path", "altitude_km");
    let b = axis(atm, "l_us", "altitude_km");
    (a[0].max(b[0]), a[a.len() - 1].min(b[b.len() - 1]))
}

fn view_zenith_max(atm: &Atmosphere) -> f64 {
    let a = axis(atm, "tau_path", "view_zenith_deg");
    let b = axis(atm, "l_us", "view_zenith_deg");
    a[a.len() - 1].min(b[b.len() - 1])
}

fn finite_nonneg(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite() && *x >= 0.0)
}

fn in_unit(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x))
}

/// Every atmosphere quantity at the corners and edges of its grids (lowest
/// and highest sensor altitude, nadir and the last view zenith, sun at the
/// zenith, near and at the horizon and below it, sky to the horizon,
/// relative azimuths beyond ±360°), on bands at both ends of the table:
/// transmissions in [0, 1], radiances finite and ≥ 0, sun terms exactly 0
/// with the sun at or below the horizon, ground sun irradiance ≤ the
/// exo-atmospheric value; atmospheric emission (L_DE, L_UE) within Planck at
/// the hottest atmosphere layer (L_UE ≤ (1 − τ₂)·B, Kirchhoff for the path).
/// Geometry outside the grids is an error (never a panic, never NaN).
#[test]
fn atmosphere_at_grid_edges() {
    let grid = table_grid();
    for atm in atmospheres() {
        let (alt_lo, alt_hi) = altitude_range(&atm);
        let vz_max = view_zenith_max(&atm);
        for resp in edge_bands() {
            let band = Band::new(&grid, &resp).unwrap();
            let sa = atm.resample(&band.wavenumber_cm1).unwrap();
            let n = sa.len();
            let b_atm: Vec<f64> = band
                .wavenumber_cm1
                .iter()
                .map(|nu| planck_radiance_w_m2_sr_um(1e4 / nu, T_ATMOS_MAX_K))
                .collect();
            let ctx0 = format!("{} {}", atm.name(), band.label);
            assert!(finite_nonneg(sa.e_sun_exo()), "{ctx0}: E_sun");
            assert!(finite_nonneg(sa.sky_dome_l_de()), "{ctx0}: dome L_DE");
            for (i, (l, b)) in sa.sky_dome_l_de().iter().zip(&b_atm).enumerate() {
                assert!(
                    *l <= b * 1.001 + 1e-12,
                    "{ctx0}: dome L_DE[{i}] {l} > B {b}"
                );
            }
            let mut buf = vec![0.0; n];
            for sun_z in [0.0, 30.0, 88.0, 89.0, 89.9, 90.0, 90.1, 135.0, 180.0] {
                sa.tau_sun(sun_z, &mut buf).unwrap();
                assert!(in_unit(&buf), "{ctx0}: tau_sun({sun_z})");
                sa.sun_irradiance_ground(sun_z, &mut buf).unwrap();
                assert!(finite_nonneg(&buf), "{ctx0}: E_ground({sun_z})");
                for (g, e) in buf.iter().zip(sa.e_sun_exo()) {
                    assert!(*g <= *e * (1.0 + 1e-12), "{ctx0}: E_ground > E_exo");
                }
                if sun_z >= 90.0 {
                    assert!(buf.iter().all(|v| *v == 0.0), "{ctx0}: sun down at {sun_z}");
                }
                let dome = sa.sky_dome_l_ds(sun_z).unwrap();
                assert!(finite_nonneg(&dome), "{ctx0}: dome L_DS({sun_z})");
                if sun_z >= 90.0 {
                    assert!(dome.iter().all(|v| *v == 0.0));
                }
                for sky_z in [0.0, 45.0, 89.0, 89.9, 90.0] {
                    for rel in [0.0, 180.0, -180.0, 359.9, -720.0] {
                        sa.l_ds(sun_z, rel, sky_z, &mut buf).unwrap();
                        assert!(finite_nonneg(&buf), "{ctx0}: L_DS({sun_z},{rel},{sky_z})");
                        if sun_z >= 90.0 {
                            assert!(buf.iter().all(|v| *v == 0.0));
                        }
                    }
                }
                for alt in [alt_lo, alt_hi] {
                    for vz in [0.0, vz_max] {
                        for rel in [0.0, 180.0, 540.0, -90.0] {
                            let ctx =
                                format!("{ctx0}: path({alt} km, {vz} deg, sun {sun_z}, {rel})");
                            let p = sa.path(alt, vz, sun_z, rel).unwrap();
                            assert!(in_unit(&p.tau2), "{ctx}: tau2");
                            assert!(finite_nonneg(&p.l_ue_w_m2_sr_um), "{ctx}: L_UE");
                            assert!(finite_nonneg(&p.l_us_w_m2_sr_um), "{ctx}: L_US");
                            if sun_z >= 90.0 {
                                assert!(p.l_us_w_m2_sr_um.iter().all(|v| *v == 0.0), "{ctx}");
                            }
                            for (i, ((l_ue, tau2), b)) in p
                                .l_ue_w_m2_sr_um
                                .iter()
                                .zip(&p.tau2)
                                .zip(&b_atm)
                                .enumerate()
                            {
                                let bound = (1.0 - tau2) * b;
                                assert!(
                                    *l_ue <= bound * 1.001 + 1e-9 * b + 1e-12,
                                    "{ctx}: L_UE[{i}] = {l_ue} > (1 - tau2) B = {bound} (tau2 {tau2})"
                                );
                            }
                        }
                    }
                }
            }
            for sky_z in [0.0, 89.0, 89.9, 90.0] {
                sa.l_de(sky_z, &mut buf).unwrap();
                assert!(finite_nonneg(&buf), "{ctx0}: L_DE({sky_z})");
                for (i, (l, b)) in buf.iter().zip(&b_atm).enumerate() {
                    assert!(
                        *l <= b * 1.001 + 1e-12,
                        "{ctx0}: L_DE({sky_z})[{i}] {l} > B {b}"
                    );
                }
            }
            // outside the grids: errors
            // Above the top: a table reaching the top of the atmosphere
            // (100 km) gives the top's path (a satellite, issue 32); a lower
            // table refuses it like any other out-of-grid altitude.
            let above = sa.path(alt_hi * 1.01, 0.0, 30.0, 0.0);
            if alt_hi >= irsig::atmos::TOP_OF_ATMOSPHERE_KM {
                let (a, t) = (above.unwrap(), sa.path(alt_hi, 0.0, 30.0, 0.0).unwrap());
                assert_eq!(a.tau2, t.tau2, "{ctx0}: tau2 above the top");
                assert_eq!(
                    a.l_ue_w_m2_sr_um, t.l_ue_w_m2_sr_um,
                    "{ctx0}: L_UE above the top"
                );
                assert_eq!(
                    a.l_us_w_m2_sr_um, t.l_us_w_m2_sr_um,
                    "{ctx0}: L_US above the top"
                );
            } else {
                assert!(
                    above.is_err(),
                    "{ctx0}: path above a table's top below 100 km"
                );
            }
            let bad_path = [
                (alt_lo * 0.99, 0.0),
                (alt_lo, vz_max + 0.1),
                (alt_lo, 90.0),
                (alt_lo, -0.1),
                (f64::NAN, 0.0),
                (alt_lo, f64::NAN),
                (f64::INFINITY, 0.0),
            ];
            for (alt, vz) in bad_path {
                assert!(
                    sa.path(alt, vz, 30.0, 0.0).is_err(),
                    "{ctx0}: path({alt}, {vz})"
                );
            }
            for sky_z in [90.1, -0.1, f64::NAN] {
                assert!(sa.l_de(sky_z, &mut buf).is_err(), "{ctx0}: L_DE({sky_z})");
                assert!(sa.l_ds(30.0, 0.0, sky_z, &mut buf).is_err());
            }
            for sun_z in [-0.1, f64::NAN] {
                assert!(
                    sa.tau_sun(sun_z, &mut buf).is_err(),
                    "{ctx0}: tau_sun({sun_z})"
                );
            }
            assert!(sa.l_ds(30.0, f64::NAN, 10.0, &mut buf).is_err());
        }
        // wavenumbers off the table
        for w in [499.0, 40001.0, f64::NAN] {
            assert!(atm.resample(&[1000.0, w]).is_err(), "{}: {w}", atm.name());
        }
    }
}

/// Checks one set of terms at one wavelength bin.
fn check_terms(t: &RadianceTerms, bound: f64, solar_basis_max: f64, ctx: &dyn Fn() -> String) {
    let all = t.values();
    assert!(
        all.iter().all(|x| x.is_finite() && *x >= 0.0),
        "{}: {t:?}",
        ctx()
    );
    let total = t.total();
    assert!(
        total.is_finite() && total <= bound,
        "{}: total {total} > {bound}",
        ctx()
    );
    assert!(
        t.reflected_solar <= solar_basis_max && t.reflected_background_solar <= solar_basis_max,
        "{}: reflected sun above E_S tau1 / pi",
        ctx()
    );
}

/// The geometry corners at which the equations are evaluated for one
/// atmosphere and band: lowest/highest sensor, nadir/last view zenith, sun
/// at the zenith, at 89.9° and set, sky ray at grazing 89.9°.
struct Corner {
    label: String,
    path: irsig::atmos::PathSpectra,
    l_de: Vec<f64>,
    l_ds: Vec<f64>,
    dome_ds: Vec<f64>,
    tau1: Vec<f64>,
}

fn corners(atm: &Atmosphere, sa: &SpectralAtmosphere) -> Vec<Corner> {
    let (alt_lo, alt_hi) = altitude_range(atm);
    let vz_max = view_zenith_max(atm);
    let n = sa.len();
    let mut out = Vec::new();
    let suns = [0.0, 89.9, 90.0];
    let domes: Vec<Vec<f64>> = suns.iter().map(|&z| sa.sky_dome_l_ds(z).unwrap()).collect();
    for alt in [alt_lo, alt_hi] {
        for vz in [0.0, vz_max] {
            for (si, &sun_z) in suns.iter().enumerate() {
                let sky_z = 89.9;
                let mut c = Corner {
                    label: format!("{alt} km, view {vz}, sun {sun_z}, sky {sky_z}"),
                    path: sa.path(alt, vz, sun_z, 180.0).unwrap(),
                    l_de: vec![0.0; n],
                    l_ds: vec![0.0; n],
                    dome_ds: domes[si].clone(),
                    tau1: vec![0.0; n],
                };
                sa.l_de(sky_z, &mut c.l_de).unwrap();
                sa.l_ds(sun_z, 0.0, sky_z, &mut c.l_ds).unwrap();
                sa.tau_sun(sun_z, &mut c.tau1).unwrap();
                out.push(c);
            }
        }
    }
    out
}

/// Eqs. 1-4 with the extremes: target ε 0, 1e-12, 0.5, 1 − 1e-12, 1,
/// background ε 0 and 1; target and background 1 K and 6000 K (target also 300 K); sun incidence
/// 0°, 89.9°, behind the facet; lit and shadowed; every atmosphere, on
/// bands at both table edges, at the geometry corners. Every term is finite
/// and ≥ 0 at every wavelength; the total is at most the Planck radiance of
/// the hottest thermal source present (target, background or atmosphere)
/// plus Planck at 6000 K bounding everything solar (relative 1e-3 for the
/// 16-bit table mantissas); reflected sun ≤ E_S τ₁/π; the band apparent
/// temperature (lit, normal incidence) exists, is finite and ≤ 1e5 K
/// wherever the band total is positive.
#[test]
fn equations_1_to_4_with_extremes() {
    let grid = table_grid();
    let eps = [0.0, 1e-12, 0.5, 1.0 - 1e-12, 1.0];
    let temps = [1.0, 300.0, 6000.0];
    let cosines = [1.0, 89.9f64.to_radians().cos(), -1.0];
    let mut n_apparent = 0usize;
    for atm in atmospheres() {
        for resp in [
            SpectralResponse::ideal(0.25, 0.3).unwrap(),
            SpectralResponse::mwir(),
            SpectralResponse::lwir(),
            SpectralResponse::ideal(18.0, 20.0).unwrap(),
        ] {
            let band = Band::new(&grid, &resp).unwrap();
            let sa = atm.resample(&band.wavenumber_cm1).unwrap();
            let lam: Vec<f64> = band.wavenumber_cm1.iter().map(|nu| 1e4 / nu).collect();
            let planck = |t: f64| -> Vec<f64> {
                lam.iter()
                    .map(|l| planck_radiance_w_m2_sr_um(*l, t))
                    .collect()
            };
            let b_t: Vec<Vec<f64>> = temps.iter().map(|&t| planck(t)).collect();
            let b_sun = planck(T_SUN_BOUND_K);
            let b_atm = planck(T_ATMOS_MAX_K);
            let es = sa.e_sun_exo();
            let dome_de = sa.sky_dome_l_de();
            for c in corners(&atm, &sa) {
                for case in 1..=4u8 {
                    // case 4 has no surface; only case 3 has a background
                    let surf = if case == 4 { 1 } else { temps.len() };
                    let bgs: &[usize] = if case == 3 { &[0, 2] } else { &[0] };
                    let e_list: &[f64] = if case == 4 { &[1.0] } else { &eps };
                    let e_bg_list: &[f64] = if case == 3 { &[0.0, 1.0] } else { &[1.0] };
                    for ti in 0..surf {
                        for &bi in bgs {
                            for &e in e_list {
                                for &e_bg in e_bg_list {
                                    for &cos in &cosines {
                                        for flag in [0.0, 1.0] {
                                            check_case(
                                                &Case {
                                                    case,
                                                    e,
                                                    e_bg,
                                                    t_target: temps[ti],
                                                    t_bg: if case == 3 { temps[bi] } else { 1.0 },
                                                    b_target: &b_t[ti],
                                                    b_bg: &b_t[bi],
                                                    cos,
                                                    flag,
                                                    corner: &c,
                                                    es,
                                                    dome_de,
                                                    b_sun: &b_sun,
                                                    b_atm: &b_atm,
                                                    lam: &lam,
                                                    band: &band,
                                                    label: &format!(
                                                        "{} {}",
                                                        atm.name(),
                                                        band.label
                                                    ),
                                                },
                                                &mut n_apparent,
                                            );
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(n_apparent > 500, "{n_apparent}");
}

/// One evaluation of eqs. 1-4 over a band.
struct Case<'a> {
    case: u8,
    e: f64,
    e_bg: f64,
    t_target: f64,
    t_bg: f64,
    b_target: &'a [f64],
    b_bg: &'a [f64],
    cos: f64,
    flag: f64,
    corner: &'a Corner,
    es: &'a [f64],
    dome_de: &'a [f64],
    b_sun: &'a [f64],
    b_atm: &'a [f64],
    lam: &'a [f64],
    band: &'a Band,
    label: &'a str,
}

fn check_case(k: &Case, n_apparent: &mut usize) {
    let c = k.corner;
    let sun = |i: usize| SunIllumination {
        e_sun_exo_w_m2_um: k.es[i],
        tau1: c.tau1[i],
        cos_incidence: k.cos,
        sun_flag: k.flag,
    };
    let path = |i: usize| PathRadiance {
        tau2: c.path.tau2[i],
        l_ue_w_m2_sr_um: c.path.l_ue_w_m2_sr_um[i],
        l_us_w_m2_sr_um: c.path.l_us_w_m2_sr_um[i],
    };
    let eval = |i: usize| -> RadianceTerms {
        match k.case {
            1 => case1_diffuse(
                k.e,
                k.b_target[i],
                &sun(i),
                &SkyRadiance {
                    l_de_w_m2_sr_um: k.dome_de[i],
                    l_ds_w_m2_sr_um: c.dome_ds[i],
                },
                &path(i),
            ),
            2 => case2_specular_sky(
                k.e,
                k.b_target[i],
                &sun(i),
                &SkyRadiance {
                    l_de_w_m2_sr_um: c.l_de[i],
                    l_ds_w_m2_sr_um: c.l_ds[i],
                },
                &path(i),
            ),
            3 => case3_specular_background(
                k.e,
                k.b_target[i],
                &sun(i),
                &Background {
                    emissivity: k.e_bg,
                    blackbody_w_m2_sr_um: k.b_bg[i],
                    sun: sun(i),
                },
                &path(i),
            ),
            _ => case4_sky(&SkyRadiance {
                l_de_w_m2_sr_um: c.l_de[i],
                l_ds_w_m2_sr_um: c.l_ds[i],
            }),
        }
    };
    let ctx = |i: usize| {
        format!(
            "{} {}: case {}, {} um, eps {}, T {}, bg eps {} T {}, cos {}, I {}",
            k.label, c.label, k.case, k.lam[i], k.e, k.t_target, k.e_bg, k.t_bg, k.cos, k.flag
        )
    };
    for i in 0..k.lam.len() {
        // Planck is monotone in T: the hottest source's radiance is the
        // largest of the sources' radiances at this wavelength.
        let mut b_hot = k.b_atm[i];
        if k.case != 4 {
            b_hot = b_hot.max(k.b_target[i]);
        }
        if k.case == 3 {
            b_hot = b_hot.max(k.b_bg[i]);
        }
        let bound = (b_hot + k.b_sun[i]) * (1.0 + 1e-3) + 1e-300;
        let basis = k.es[i] * c.tau1[i] / std::f64::consts::PI * (1.0 + 1e-12);
        check_terms(&eval(i), bound, basis, &|| ctx(i));
    }
    let total = integrate_terms(k.band, eval).total();
    assert!(total.is_finite() && total >= 0.0, "{}", ctx(0));
    // the apparent temperature (a Newton solve over the band) for lit,
    // normal-incidence cases only, to keep the suite fast
    if total > 0.0 && k.flag == 1.0 && k.cos == 1.0 {
        let ta = k.band.apparent_temp_k(total);
        let ta = ta.unwrap_or_else(|| panic!("{}: no apparent T for {total}", ctx(0)));
        assert!(ta.is_finite() && ta > 0.0 && ta <= 1e5, "{}: {ta}", ctx(0));
        *n_apparent += 1;
    }
}
