//! The solar position of a site and instant with the inputs that gave it
//! (what `irsig sun` prints), checked inputs included.

use chrono::{DateTime, Utc};
use serde::Serialize;

use super::{SolarPosition, SpaOptions, solar_position_with, validate_site};

/// What `--time` accepts, repeated in error messages.
pub const TIME_FORMAT_HELP: &str = "an RFC 3339 time with a UTC offset, e.g. 2024-06-21T12:00:00Z or 2024-06-21T14:00+02:00 (seconds optional)";

/// `s` with `:00` seconds added where its clock time has hours and
/// minutes only (`2001-08-07T00:00-04:00`, `...T14:30Z`), else as is.
fn with_seconds(s: &str) -> std::borrow::Cow<'_, str> {
    let Some(t) = s.find(['T', 't', ' ']) else {
        return s.into();
    };
    let clock = s.get(t + 1..t + 6).map(str::as_bytes);
    let hh_mm = clock.is_some_and(|c| {
        c[0].is_ascii_digit()
            && c[1].is_ascii_digit()
            && c[2] == b':'
            && c[3].is_ascii_digit()
            && c[4].is_ascii_digit()
    });
    if hh_mm && s.as_bytes().get(t + 6) != Some(&b':') {
        format!("{}:00{}", &s[..t + 6], &s[t + 6..]).into()
    } else {
        s.into()
    }
}

/// Parses an RFC 3339 time with a UTC offset (`irsig sun --time`, `irsig
/// therm --from/--to`); the seconds may be left out (`14:00+02:00`); the
/// error says what format is expected.
/// Years outside [`crate::bounds::time::YEAR`] are refused.
pub fn parse_time(s: &str) -> Result<DateTime<Utc>, String> {
    use chrono::Datelike;
    let t = DateTime::parse_from_rfc3339(&with_seconds(s.trim()))
        .map(|t| t.with_timezone(&Utc))
        .map_err(|e| format!("cannot read time '{s}' ({e}): expected {TIME_FORMAT_HELP}"))?;
    crate::bounds::time::YEAR
        .check(t.year().into())
        .map_err(|m| format!("time '{s}': {m}"))?;
    Ok(t)
}

/// The solar position and its inputs; serialises as `irsig sun --json`
/// prints it.
#[derive(Clone, Debug, Serialize)]
pub struct SunReport {
    /// The instant, UTC (RFC 3339).
    pub time_utc: String,
    /// The site: latitude (degrees north), longitude (degrees east) and
    /// elevation above sea level (m).
    pub lat_deg: f64,
    /// See [`Self::lat_deg`].
    pub lon_deg: f64,
    /// See [`Self::lat_deg`].
    pub elevation_m: f64,
    /// Topocentric zenith angle with refraction, degrees.
    pub zenith_deg: f64,
    /// Topocentric zenith angle without refraction, degrees.
    pub true_zenith_deg: f64,
    /// Azimuth clockwise from north, degrees.
    pub azimuth_deg: f64,
    /// Elevation with refraction (90° − zenith), degrees.
    pub elevation_deg: f64,
    /// Earth-sun distance, astronomical units.
    pub earth_sun_distance_au: f64,
    /// Unit vector to the sun, local east-north-up.
    pub sun_dir_enu: [f64; 3],
    /// ΔT used (the options' or the Espenak & Meeus model's), s.
    pub delta_t_s: f64,
    /// The SPA options the position was computed with.
    pub options: SpaOptions,
    /// The position itself.
    #[serde(skip)]
    pub position: SolarPosition,
}

/// The solar position (NREL SPA) at `time` for a site (latitude and
/// longitude in degrees, east positive; elevation in metres); checks the
/// site and the refraction inputs (pressure in (0, 2000) hPa, temperature
/// in [-100, 100] °C).
pub fn sun_report(
    time: DateTime<Utc>,
    lat_deg: f64,
    lon_deg: f64,
    elevation_m: f64,
    opts: &SpaOptions,
) -> anyhow::Result<SunReport> {
    validate_site(lat_deg, lon_deg, elevation_m).map_err(anyhow::Error::msg)?;
    use crate::bounds::args;
    for (a, v) in [
        (args::ELEVATION, elevation_m),
        (args::SUN_PRESSURE, opts.pressure_hpa),
        (args::SUN_TEMP, opts.temp_c),
        (args::SUN_DELTA_T, opts.delta_t_s.unwrap_or(0.0)),
    ] {
        a.check(v).map_err(anyhow::Error::msg)?;
    }
    let p = solar_position_with(time, lat_deg, lon_deg, elevation_m, opts);
    Ok(SunReport {
        time_utc: time.to_rfc3339_opts(chrono::SecondsFormat::AutoSi, true),
        lat_deg,
        lon_deg,
        elevation_m,
        zenith_deg: p.zenith_deg,
        true_zenith_deg: p.true_zenith_deg,
        azimuth_deg: p.azimuth_deg,
        elevation_deg: p.elevation_deg,
        earth_sun_distance_au: p.earth_sun_distance_au,
        sun_dir_enu: p.sun_dir_enu,
        delta_t_s: opts.delta_t_s.unwrap_or_else(|| {
            super::delta_t_s(
                chrono::Datelike::year(&time),
                chrono::Datelike::month(&time),
            )
        }),
        options: *opts,
        position: p,
    })
}
