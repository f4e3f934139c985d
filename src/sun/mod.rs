//! Sun ephemeris: the NREL Solar Position Algorithm (SPA).
//!
//! I. Reda and A. Andreas, "Solar position algorithm for solar radiation
//! applications", Solar Energy 76(5), 577-589 (2004); revised NREL report
//! NREL/TP-560-34302 (2008). Stated uncertainty ±0.0003° for years -2000 to
//! 6000. Equation numbers below ("eq. N") refer to section 3 of that report.
//!
//! The implementation follows the report step by step, with the same
//! conventions as pvlib's `pvlib.spa` (the reference of the tests):
//! azimuth is measured clockwise from north (eastward), angles are in degrees,
//! and the atmospheric refraction correction is applied only while the
//! geometric sun is above −(0.26667° + `atmos_refract_deg`) (eq. 42-43).
//!
//! Inputs are plain data: a UTC instant, a site (geodetic latitude and
//! longitude in degrees, east positive; elevation in metres above sea level),
//! and [`SpaOptions`] (air pressure and temperature for refraction, ΔT).
//! Outputs are a plain [`SolarPosition`].

use chrono::{DateTime, Datelike, Utc};
use serde::{Deserialize, Serialize};

pub mod approx;
pub mod report;
mod tables;

/// Options of the SPA beyond time and site.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpaOptions {
    /// Annual-mean local air pressure for the refraction correction, hPa (mbar).
    pub pressure_hpa: f64,
    /// Annual-mean local air temperature for the refraction correction, °C.
    pub temp_c: f64,
    /// ΔT = TT − UT, seconds. `None` uses [`delta_t_s`] (Espenak & Meeus
    /// polynomial model), which is what pvlib does with `delta_t=None`.
    pub delta_t_s: Option<f64>,
    /// Refraction of the sun at sunrise/sunset, degrees (SPA default 0.5667°).
    pub atmos_refract_deg: f64,
}

impl Default for SpaOptions {
    /// Standard atmosphere 1013.25 hPa, 12 °C (pvlib's defaults), modelled ΔT,
    /// 0.5667° horizon refraction.
    fn default() -> Self {
        Self {
            pressure_hpa: 1013.25,
            temp_c: 12.0,
            delta_t_s: None,
            atmos_refract_deg: 0.5667,
        }
    }
}

/// Where the sun is, seen from a site on the ground.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolarPosition {
    /// Topocentric zenith angle with the refraction correction (apparent), deg.
    pub zenith_deg: f64,
    /// Topocentric zenith angle without refraction (true, geometric), deg.
    pub true_zenith_deg: f64,
    /// Apparent topocentric elevation angle, deg (= 90 − `zenith_deg`).
    pub elevation_deg: f64,
    /// True (geometric) topocentric elevation angle, deg.
    pub true_elevation_deg: f64,
    /// Topocentric azimuth, clockwise from north, in [0, 360), deg.
    pub azimuth_deg: f64,
    /// Earth–sun distance (heliocentric radius vector R), astronomical units.
    pub earth_sun_distance_au: f64,
    /// Topocentric declination of the sun, deg.
    pub declination_deg: f64,
    /// Equation of time (apparent minus mean solar time), minutes.
    pub equation_of_time_min: f64,
    /// Unit vector towards the apparent sun, local ENU (x east, y north, z up).
    pub sun_dir_enu: [f64; 3],
}

/// ΔT = TT − UT in seconds for a calendar year and month, from the polynomial
/// expressions of Espenak & Meeus (NASA, "Polynomial expressions for Delta T",
/// eclipse.gsfc.nasa.gov/SEcat5/deltatpoly.html), evaluated at the decimal
/// year y = year + (month − 0.5)/12. This is the same model as
/// `pvlib.spa.calculate_deltat`. Against observed values (IERS) it is within
/// 2.5 s over 1950-2025 (71.6 s vs 69.4 s in 2020); 1 s of ΔT is 0.004° of
/// solar hour angle. Pass a measured ΔT in [`SpaOptions`] for more.
pub fn delta_t_s(year: i32, month: u32) -> f64 {
    let yr = year as f64;
    let y = yr + (month as f64 - 0.5) / 12.0;
    if year < -500 {
        let u = (y - 1820.0) / 100.0;
        -20.0 + 32.0 * u * u
    } else if year < 500 {
        let u = y / 100.0;
        10583.6 - 1014.41 * u + 33.78311 * u.powi(2) - 5.952053 * u.powi(3) - 0.1798452 * u.powi(4)
            + 0.022174192 * u.powi(5)
            + 0.0090316521 * u.powi(6)
    } else if year < 1600 {
        let u = (y - 1000.0) / 100.0;
        1574.2 - 556.01 * u + 71.23472 * u.powi(2) + 0.319781 * u.powi(3)
            - 0.8503463 * u.powi(4)
            - 0.005050998 * u.powi(5)
            + 0.0083572073 * u.powi(6)
    } else if year < 1700 {
        let t = y - 1600.0;
        120.0 - 0.9808 * t - 0.01532 * t * t + t.powi(3) / 7129.0
    } else if year < 1800 {
        let t = y - 1700.0;
        8.83 + 0.1603 * t - 0.0059285 * t * t + 0.00013336 * t.powi(3) - t.powi(4) / 1_174_000.0
    } else if year < 1860 {
        let t = y - 1800.0;
        13.72 - 0.332447 * t + 0.0068612 * t * t + 0.0041116 * t.powi(3) - 0.00037436 * t.powi(4)
            + 0.0000121272 * t.powi(5)
            - 0.0000001699 * t.powi(6)
            + 0.000000000875 * t.powi(7)
    } else if year < 1900 {
        let t = y - 1860.0;
        7.62 + 0.5737 * t - 0.251754 * t * t + 0.01680668 * t.powi(3) - 0.0004473624 * t.powi(4)
            + t.powi(5) / 233_174.0
    } else if year < 1920 {
        let t = y - 1900.0;
        -2.79 + 1.494119 * t - 0.0598939 * t * t + 0.0061966 * t.powi(3) - 0.000197 * t.powi(4)
    } else if year < 1941 {
        let t = y - 1920.0;
        21.20 + 0.84493 * t - 0.076100 * t * t + 0.0020936 * t.powi(3)
    } else if year < 1961 {
        let t = y - 1950.0;
        29.07 + 0.407 * t - t * t / 233.0 + t.powi(3) / 2547.0
    } else if year < 1986 {
        let t = y - 1975.0;
        45.45 + 1.067 * t - t * t / 260.0 - t.powi(3) / 718.0
    } else if year < 2005 {
        let t = y - 2000.0;
        63.86 + 0.3345 * t - 0.060374 * t * t
            + 0.0017275 * t.powi(3)
            + 0.000651814 * t.powi(4)
            + 0.00002373599 * t.powi(5)
    } else if year < 2050 {
        let t = y - 2000.0;
        62.92 + 0.32217 * t + 0.005589 * t * t
    } else if year < 2150 {
        let u = (y - 1820.0) / 100.0;
        -20.0 + 32.0 * u * u - 0.5628 * (2150.0 - y)
    } else {
        let u = (y - 1820.0) / 100.0;
        -20.0 + 32.0 * u * u
    }
}

/// Checks a site for [`solar_position`]: latitude in [−90, 90], longitude in
/// [−180, 180], elevation finite and above −1000 m. Returns a message saying
/// what was expected.
pub fn validate_site(lat_deg: f64, lon_deg: f64, elevation_m: f64) -> Result<(), String> {
    if !(-90.0..=90.0).contains(&lat_deg) {
        return Err(format!(
            "latitude {lat_deg} is out of range: expected degrees in [-90, 90], north positive"
        ));
    }
    if !(-180.0..=180.0).contains(&lon_deg) {
        return Err(format!(
            "longitude {lon_deg} is out of range: expected degrees in [-180, 180], east positive"
        ));
    }
    if !elevation_m.is_finite() || elevation_m < -1000.0 {
        return Err(format!(
            "elevation {elevation_m} m is out of range: expected metres above sea level, >= -1000"
        ));
    }
    Ok(())
}

/// Solar position with the default [`SpaOptions`] (1013.25 hPa, 12 °C,
/// modelled ΔT). See [`solar_position_with`].
pub fn solar_position(
    time: DateTime<Utc>,
    lat_deg: f64,
    lon_deg: f64,
    elevation_m: f64,
) -> SolarPosition {
    solar_position_with(time, lat_deg, lon_deg, elevation_m, &SpaOptions::default())
}

/// Σ A·cos(B + C·x) over a periodic-term table (SPA eq. 9).
fn periodic_sum(table: &[[f64; 3]], x: f64) -> f64 {
    table.iter().map(|r| r[0] * (r[1] + r[2] * x).cos()).sum()
}

/// Julian day of a UTC instant (SPA eq. 4; for Gregorian dates identical to
/// JD = Unix time / 86400 + 2440587.5).
pub fn julian_day(time: DateTime<Utc>) -> f64 {
    let unix_s = time.timestamp() as f64 + time.timestamp_subsec_nanos() as f64 * 1e-9;
    unix_s / 86400.0 + 2440587.5
}

/// NREL SPA topocentric solar position (Reda & Andreas 2004, §3.1-3.15).
///
/// `lat_deg` geodetic latitude (north positive), `lon_deg` longitude (east
/// positive), `elevation_m` above sea level. Valid for years −2000..6000;
/// inputs are expected to pass [`validate_site`] (NaN in gives NaN out).
pub fn solar_position_with(
    time: DateTime<Utc>,
    lat_deg: f64,
    lon_deg: f64,
    elevation_m: f64,
    opts: &SpaOptions,
) -> SolarPosition {
    let delta_t = opts
        .delta_t_s
        .unwrap_or_else(|| delta_t_s(time.year(), time.month()));
    // §3.1 time scales: JD (eq. 4), JDE (eq. 5), JC (eq. 6), JCE (eq. 7), JME (eq. 8).
    let jd = julian_day(time);
    let jde = jd + delta_t / 86400.0;
    let jc = (jd - 2451545.0) / 36525.0;
    let jce = (jde - 2451545.0) / 36525.0;
    let jme = jce / 10.0;

    // §3.2 Earth heliocentric longitude L (eq. 9-12), latitude B (eq. 13), radius R (eq. 14).
    let poly = |terms: &[f64]| -> f64 {
        terms
            .iter()
            .enumerate()
            .map(|(i, t)| t * jme.powi(i as i32))
            .sum::<f64>()
            / 1e8
    };
    let l_rad = poly(&[
        periodic_sum(&tables::L0, jme),
        periodic_sum(&tables::L1, jme),
        periodic_sum(&tables::L2, jme),
        periodic_sum(&tables::L3, jme),
        periodic_sum(&tables::L4, jme),
        periodic_sum(&tables::L5, jme),
    ]);
    let l_deg = l_rad.to_degrees().rem_euclid(360.0);
    let b_deg = poly(&[
        periodic_sum(&tables::B0, jme),
        periodic_sum(&tables::B1, jme),
    ])
    .to_degrees();
    let r_au = poly(&[
        periodic_sum(&tables::R0, jme),
        periodic_sum(&tables::R1, jme),
        periodic_sum(&tables::R2, jme),
        periodic_sum(&tables::R3, jme),
        periodic_sum(&tables::R4, jme),
    ]);

    // §3.3 geocentric longitude Θ (eq. 16) and latitude β (eq. 17).
    let theta_deg = (l_deg + 180.0).rem_euclid(360.0);
    let beta_deg = -b_deg;

    // §3.4 nutation in longitude Δψ and obliquity Δε (eq. 15-23).
    let x = [
        297.85036 + 445267.111480 * jce - 0.0019142 * jce * jce + jce.powi(3) / 189474.0,
        357.52772 + 35999.050340 * jce - 0.0001603 * jce * jce - jce.powi(3) / 300000.0,
        134.96298 + 477198.867398 * jce + 0.0086972 * jce * jce + jce.powi(3) / 56250.0,
        93.27191 + 483202.017538 * jce - 0.0036825 * jce * jce + jce.powi(3) / 327270.0,
        125.04452 - 1934.136261 * jce + 0.0020708 * jce * jce + jce.powi(3) / 450000.0,
    ];
    let (mut dpsi, mut deps) = (0.0, 0.0);
    for (y, abcd) in tables::NUT_Y.iter().zip(tables::NUT_ABCD.iter()) {
        let arg = (0..5).map(|j| y[j] * x[j]).sum::<f64>().to_radians();
        dpsi += (abcd[0] + abcd[1] * jce) * arg.sin();
        deps += (abcd[2] + abcd[3] * jce) * arg.cos();
    }
    let dpsi_deg = dpsi / 36_000_000.0;
    let deps_deg = deps / 36_000_000.0;

    // §3.5 true obliquity of the ecliptic ε (eq. 24-25).
    let u = jme / 10.0;
    let eps0_arcsec = 84381.448 - 4680.93 * u - 1.55 * u.powi(2) + 1999.25 * u.powi(3)
        - 51.38 * u.powi(4)
        - 249.67 * u.powi(5)
        - 39.05 * u.powi(6)
        + 7.12 * u.powi(7)
        + 27.87 * u.powi(8)
        + 5.79 * u.powi(9)
        + 2.45 * u.powi(10);
    let eps_deg = eps0_arcsec / 3600.0 + deps_deg;
    let eps = eps_deg.to_radians();

    // §3.6 aberration Δτ (eq. 26); §3.7 apparent sun longitude λ (eq. 27).
    let dtau_deg = -20.4898 / (3600.0 * r_au);
    let lambda_deg = theta_deg + dpsi_deg + dtau_deg;
    let lambda = lambda_deg.to_radians();

    // §3.8 apparent sidereal time at Greenwich ν (eq. 28-29).
    let nu0_deg = (280.46061837 + 360.98564736629 * (jd - 2451545.0) + 0.000387933 * jc * jc
        - jc.powi(3) / 38_710_000.0)
        .rem_euclid(360.0);
    let nu_deg = nu0_deg + dpsi_deg * eps.cos();

    // §3.9 geocentric right ascension α (eq. 30); §3.10 declination δ (eq. 31).
    let beta = beta_deg.to_radians();
    let alpha_deg = (lambda.sin() * eps.cos() - beta.tan() * eps.sin())
        .atan2(lambda.cos())
        .to_degrees()
        .rem_euclid(360.0);
    let delta = (beta.sin() * eps.cos() + beta.cos() * eps.sin() * lambda.sin()).asin();

    // §3.11 observer local hour angle H (eq. 32), westward from south.
    let h_deg = (nu_deg + lon_deg - alpha_deg).rem_euclid(360.0);
    let h = h_deg.to_radians();

    // §3.12 topocentric sun right ascension α' and declination δ' (eq. 33-38).
    let xi = (8.794 / (3600.0 * r_au)).to_radians();
    let lat = lat_deg.to_radians();
    let uu = (0.99664719 * lat.tan()).atan();
    let xx = uu.cos() + elevation_m / 6_378_140.0 * lat.cos();
    let yy = 0.99664719 * uu.sin() + elevation_m / 6_378_140.0 * lat.sin();
    let dalpha = (-xx * xi.sin() * h.sin()).atan2(delta.cos() - xx * xi.sin() * h.cos());
    let delta_p =
        ((delta.sin() - yy * xi.sin()) * dalpha.cos()).atan2(delta.cos() - xx * xi.sin() * h.cos());

    // §3.13 topocentric local hour angle H' (eq. 39).
    let hp = h - dalpha;

    // §3.14 topocentric zenith angle θ (eq. 40-44).
    let e0_deg = (lat.sin() * delta_p.sin() + lat.cos() * delta_p.cos() * hp.cos())
        .asin()
        .to_degrees();
    let de_deg = if e0_deg >= -(0.26667 + opts.atmos_refract_deg) {
        (opts.pressure_hpa / 1010.0) * (283.0 / (273.0 + opts.temp_c)) * 1.02
            / (60.0 * (e0_deg + 10.3 / (e0_deg + 5.11)).to_radians().tan())
    } else {
        0.0
    };
    let e_deg = e0_deg + de_deg;

    // §3.15 topocentric azimuth Φ (eq. 45-46), eastward from north.
    let gamma_deg = hp
        .sin()
        .atan2(hp.cos() * lat.sin() - delta_p.tan() * lat.cos())
        .to_degrees()
        .rem_euclid(360.0);
    let az_deg = (gamma_deg + 180.0).rem_euclid(360.0);

    // Equation of time (eq. A1-A2), minutes, limited to ±20 min.
    let m_deg = 280.4664567 + 360007.6982779 * jme + 0.03032028 * jme * jme + jme.powi(3) / 49931.0
        - jme.powi(4) / 15300.0
        - jme.powi(5) / 2_000_000.0;
    let mut eot_min =
        4.0 * (m_deg - 0.0057183 - alpha_deg + dpsi_deg * eps.cos()).rem_euclid(360.0);
    if eot_min > 20.0 {
        eot_min -= 1440.0;
    }

    SolarPosition {
        zenith_deg: 90.0 - e_deg,
        true_zenith_deg: 90.0 - e0_deg,
        elevation_deg: e_deg,
        true_elevation_deg: e0_deg,
        azimuth_deg: az_deg,
        earth_sun_distance_au: r_au,
        declination_deg: delta_p.to_degrees(),
        equation_of_time_min: eot_min,
        sun_dir_enu: enu_from_angles(e_deg, az_deg),
    }
}

/// ENU unit vector for an elevation and an azimuth clockwise from north:
/// (cos e·sin A, cos e·cos A, sin e).
pub fn enu_from_angles(elevation_deg: f64, azimuth_deg: f64) -> [f64; 3] {
    let (se, ce) = elevation_deg.to_radians().sin_cos();
    let (sa, ca) = azimuth_deg.to_radians().sin_cos();
    [ce * sa, ce * ca, se]
}

/// A site on the ground: geodetic latitude (north positive) and longitude
/// (east positive) in degrees, elevation above sea level in metres. The one
/// site type: the scene's `[site]` table holds one
/// (`crate::scene::spec::Site::location`, its keys these field names), the
/// thermal forcing and the sun samples take it as read.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Site {
    /// Geodetic latitude, degrees, north positive, [-90, 90].
    pub latitude_deg: f64,
    /// Longitude, degrees, east positive, [-180, 180].
    pub longitude_deg: f64,
    /// Elevation above sea level, m.
    pub elevation_m: f64,
}

/// Sun transit, rise and set around an instant (see [`sun_events_near`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SunEvents {
    /// Local solar noon (topocentric hour angle 0) nearest the instant asked.
    pub transit: DateTime<Utc>,
    /// Sunrise before that transit; `None` in polar day or polar night.
    pub sunrise: Option<DateTime<Utc>>,
    /// Sunset after that transit; `None` in polar day or polar night.
    pub sunset: Option<DateTime<Utc>>,
    /// True elevation of the sun at transit, degrees (< −0.8333: polar night).
    pub transit_elevation_deg: f64,
}

/// Sunrise/sunset elevation of the sun's centre, degrees: −(0.5667° refraction
/// + 0.26667° semi-diameter) = −0.8333°, the SPA's h0' (Reda & Andreas, A.2).
pub const RISE_SET_ELEVATION_DEG: f64 = -0.8333;

fn add_seconds(t: DateTime<Utc>, s: f64) -> DateTime<Utc> {
    t + chrono::Duration::nanoseconds((s * 1e9).round() as i64)
}

/// Solar transit, sunrise and sunset around `time` at a site, by root
/// finding on the SPA itself: transit is where the topocentric local hour
/// angle is zero (fixed-point iteration from the equation of time), rise and
/// set are where the true topocentric elevation crosses −0.8333°
/// (bisection to 0.1 s within the 12 h before/after transit). This matches
/// the SPA's own rise/transit/set appendix (A.2) to well under a minute.
pub fn sun_events_near(time: DateTime<Utc>, lat_deg: f64, lon_deg: f64) -> SunEvents {
    let opts = SpaOptions::default();
    let elev =
        |t: DateTime<Utc>| solar_position_with(t, lat_deg, lon_deg, 0.0, &opts).true_elevation_deg;
    // Mean solar noon (12:00 − lon/15 h UTC) nearest `time`, then the
    // fixed point transit = mean noon − EOT(transit).
    let jd = julian_day(time);
    let day0 = (jd + 0.5).floor() - 0.5; // JD of 00:00 UTC of the date of `time`
    let mut noon = day0 + 0.5 - lon_deg / 360.0;
    for cand in [noon - 1.0, noon + 1.0] {
        if (cand - jd).abs() < (noon - jd).abs() {
            noon = cand;
        }
    }
    let mean_noon = add_seconds(time, (noon - jd) * 86400.0);
    let mut transit = mean_noon;
    for _ in 0..3 {
        let p = solar_position_with(transit, lat_deg, lon_deg, 0.0, &opts);
        transit = add_seconds(mean_noon, -p.equation_of_time_min * 60.0);
    }
    let e_transit = elev(transit);
    let e_night = elev(add_seconds(transit, -43200.0));
    let e_night2 = elev(add_seconds(transit, 43200.0));
    let h0 = RISE_SET_ELEVATION_DEG;
    let bisect = |mut lo: DateTime<Utc>, mut hi: DateTime<Utc>, rising: bool| {
        while (hi - lo).num_milliseconds() > 100 {
            let mid = lo + (hi - lo) / 2;
            let above = elev(mid) > h0;
            if above == rising {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo + (hi - lo) / 2
    };
    let (sunrise, sunset) = if e_transit <= h0 || (e_night > h0 && e_night2 > h0) {
        (None, None)
    } else {
        let rise = (e_night <= h0).then(|| bisect(add_seconds(transit, -43200.0), transit, true));
        let set = (e_night2 <= h0).then(|| bisect(transit, add_seconds(transit, 43200.0), false));
        (rise, set)
    };
    SunEvents {
        transit,
        sunrise,
        sunset,
        transit_elevation_deg: e_transit,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chrono::TimeZone;

    /// The worked example of Reda & Andreas (2004/2008), Table A5.1:
    /// 2003-10-17 12:30:30 local time (UTC−7), lat 39.742476°,
    /// lon −105.1786°, elevation 1830.14 m, 820 mbar, 11 °C, ΔT = 67 s,
    /// refraction 0.5667°. Published: zenith 50.11162°, azimuth 194.34024°,
    /// R = 0.9965422974 AU, δ' = −9.316179°, EOT 14.641503 min.
    #[test]
    fn reda_andreas_worked_example() {
        let t = Utc.with_ymd_and_hms(2003, 10, 17, 19, 30, 30).unwrap();
        assert!((julian_day(t) - 2452930.312847).abs() < 1e-6);
        let opts = SpaOptions {
            pressure_hpa: 820.0,
            temp_c: 11.0,
            delta_t_s: Some(67.0),
            atmos_refract_deg: 0.5667,
        };
        let p = solar_position_with(t, 39.742476, -105.1786, 1830.14, &opts);
        // The report prints 5 decimals; the stated tolerance is half a unit of the last digit.
        assert!((p.zenith_deg - 50.11162).abs() < 5e-6, "{}", p.zenith_deg);
        assert!(
            (p.azimuth_deg - 194.34024).abs() < 5e-6,
            "{}",
            p.azimuth_deg
        );
        assert!((p.earth_sun_distance_au - 0.9965422974).abs() < 1e-9);
        assert!((p.declination_deg - -9.316179).abs() < 5e-6);
        // EOT: pvlib gives 14.641511 like us; the report's 14.641503 differs by
        // 8e-6 min (0.5 ms), so the tolerance here is 2e-5 min.
        assert!(
            (p.equation_of_time_min - 14.641503).abs() < 2e-5,
            "{}",
            p.equation_of_time_min
        );
        let v = p.sun_dir_enu;
        assert!(((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt() - 1.0).abs() < 1e-12);
        assert!((v[2] - p.zenith_deg.to_radians().cos()).abs() < 1e-12);
    }

    /// ΔT model against observed ΔT (IERS / Espenak & Meeus tables):
    /// 1950.0 29.15 s, 1975.0 45.48 s, 2000.0 63.83 s, 2020.0 69.36 s.
    /// Tolerance 0.2 s where the polynomial was fitted to data (≤ 2000) and
    /// 2.5 s for the 2005-2050 extrapolation.
    #[test]
    fn delta_t_model_vs_observed() {
        assert!((delta_t_s(1950, 1) - 29.15).abs() < 0.2);
        assert!((delta_t_s(1975, 1) - 45.48).abs() < 0.2);
        assert!((delta_t_s(2000, 1) - 63.83).abs() < 0.2);
        assert!((delta_t_s(2020, 1) - 69.36).abs() < 2.5);
    }

    #[test]
    fn site_validation_messages() {
        assert!(validate_site(45.0, 10.0, 0.0).is_ok());
        let e = validate_site(91.0, 0.0, 0.0).unwrap_err();
        assert!(e.contains("latitude") && e.contains("[-90, 90]"), "{e}");
        let e = validate_site(0.0, 200.0, 0.0).unwrap_err();
        assert!(e.contains("longitude"), "{e}");
        assert!(validate_site(f64::NAN, 0.0, 0.0).is_err());
    }
}
