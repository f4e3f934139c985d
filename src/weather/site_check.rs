//! Whether a weather record belongs to the site: the station's distance
//! from the site, the shift that applies a stand-in record in the site's
//! solar time, and measured sunlight that disagrees with the site's sun.

use chrono::{DateTime, Duration, Utc};

use super::{WeatherHistory, WeatherStation};

/// Largest difference in latitude or longitude between a weather file's
/// station and the site before irsig warns (or, with `--strict`, refuses),
/// degrees.
pub const MAX_STATION_OFFSET_DEG: f64 = 0.5;

/// A warning when `station` lies more than [`MAX_STATION_OFFSET_DEG`] in
/// latitude or longitude from the site: the file's measured irradiance and
/// weather then belong to another place than the sun computed for the site.
pub fn station_mismatch(
    station: &WeatherStation,
    file: &str,
    site_lat_deg: f64,
    site_lon_deg: f64,
) -> Option<String> {
    let dlat = (station.lat_deg - site_lat_deg).abs();
    let dlon = ((station.lon_deg - site_lon_deg + 540.0).rem_euclid(360.0) - 180.0).abs();
    (dlat > MAX_STATION_OFFSET_DEG || dlon > MAX_STATION_OFFSET_DEG).then(|| {
        format!(
            "the weather file {file} is for {} at {:.3}, {:.3} but the site is at {:.3}, {:.3} \
             ({dlat:.2} deg in latitude, {dlon:.2} deg in longitude; more than {MAX_STATION_OFFSET_DEG} deg): \
             its measured sun and weather belong elsewhere; move the site, use a nearer file, or \
             leave out site.latitude_deg/longitude_deg to take the file's",
            if station.name.is_empty() { "its station" } else { &station.name },
            station.lat_deg,
            station.lon_deg,
            site_lat_deg,
            site_lon_deg
        )
    })
}

/// The shift that applies a stand-in record (`weather.file.stand_in`)
/// in the site's solar time: a record measured at the station's longitude
/// λ_st meets the sun at the same hour angle at the site's longitude λ
/// `(λ − λ_st)/15°` hours earlier (east of the station) or later (west),
/// so each sample is moved by `−(λ − λ_st)/15` h (the longitude difference
/// wrapped to ±180°; rounded to the second). The equation of time is the
/// same at both places on one date, so the shift is exact for the sun's
/// hour angle; a difference in *latitude* (day length, noon elevation) is
/// not a shift and stays ([`sunlight_mismatch`] names the hours it
/// leaves). A file that names no station (a plain CSV) cannot be moved:
/// the error says why, for the user.
pub fn stand_in_solar_shift(
    station: Option<&WeatherStation>,
    file: &str,
    site_lon_deg: f64,
) -> Result<Duration, String> {
    let Some(st) = station else {
        return Err(format!(
            "weather.file.stand_in: {file} names no station longitude, so its record cannot be \
             moved to the site's solar time and is applied at its own UTC times (if it was \
             measured at another longitude, shift its times by (site − station longitude)/15° h)"
        ));
    };
    let dlon = (site_lon_deg - st.lon_deg + 540.0).rem_euclid(360.0) - 180.0;
    Ok(Duration::seconds((-dlon / 15.0 * 3600.0).round() as i64))
}

/// Measured sunlight above which a record taken while the site's sun is
/// down is reported, W/m² (well above the twilight and sensor-offset
/// level of a few W/m²).
pub const SUNLIGHT_WHILE_DOWN_W_M2: f64 = 50.0;
/// Sun elevation below which the site's sun is down for that check, deg.
pub const SUN_DOWN_ELEVATION_DEG: f64 = -2.0;
/// Sun elevation above which a record with no sunlight (GHI < 1 W/m²) is
/// reported: the site's sun is well up while the record is dark, deg.
pub const SUN_UP_ELEVATION_DEG: f64 = 10.0;

/// The records of `history` between `from` and `to` whose measured
/// sunlight disagrees with the sun of the site at (`lat_deg`, `lon_deg`):
/// GHI above [`SUNLIGHT_WHILE_DOWN_W_M2`] while the site's sun is below
/// [`SUN_DOWN_ELEVATION_DEG`], or GHI below 1 W/m² while it is above
/// [`SUN_UP_ELEVATION_DEG`] — in both cases over the whole hour before the
/// record's time and the half hour after (t − 60, − 30, 0, + 30 min), so
/// that hour-ending averages and instantaneous stamps both pass near
/// sunrise and sunset. This happens when a record measured at another
/// longitude stands in for the site: its sunlight follows the station's
/// solar time (15° of longitude = 1 h), which irsig does not shift (the
/// forcing is applied at the same UTC instant; the direct beam is taken
/// with the site's sun). Returns a warning naming the hours (UTC), or
/// `None`. Records without GHI are skipped.
pub fn sunlight_mismatch(
    history: &WeatherHistory,
    lat_deg: f64,
    lon_deg: f64,
    from: DateTime<Utc>,
    to: DateTime<Utc>,
) -> Option<String> {
    let elev =
        |t: DateTime<Utc>| crate::sun::solar_position(t, lat_deg, lon_deg, 0.0).true_elevation_deg;
    let around = |t: DateTime<Utc>| [-60i64, -30, 0, 30].map(|m| elev(t + Duration::minutes(m)));
    let (mut lit_down, mut dark_up) = (Vec::new(), Vec::new());
    for (t, s) in history.times.iter().zip(&history.samples) {
        if *t < from || *t > to {
            continue;
        }
        let Some(ghi) = s.ghi_w_m2 else { continue };
        if ghi > SUNLIGHT_WHILE_DOWN_W_M2 && around(*t).iter().all(|e| *e < SUN_DOWN_ELEVATION_DEG)
        {
            lit_down.push(*t);
        } else if ghi < 1.0 && around(*t).iter().all(|e| *e > SUN_UP_ELEVATION_DEG) {
            dark_up.push(*t);
        }
    }
    if lit_down.is_empty() && dark_up.is_empty() {
        return None;
    }
    let list = |v: &[DateTime<Utc>]| {
        v.iter()
            .map(|t| t.format("%Y-%m-%dT%H:%MZ").to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut parts = Vec::new();
    if !lit_down.is_empty() {
        parts.push(format!(
            "measured sunlight (GHI > {SUNLIGHT_WHILE_DOWN_W_M2} W/m²) while the site's sun is down at {}",
            list(&lit_down)
        ));
    }
    if !dark_up.is_empty() {
        parts.push(format!(
            "no measured sunlight while the site's sun is above {SUN_UP_ELEVATION_DEG}° at {}",
            list(&dark_up)
        ));
    }
    Some(format!(
        "weather {}: {} — the record follows another place's sun (a stand-in record with a named station is applied in the site's solar time, any other at its own UTC times; a difference in latitude is not undone by a shift): pick a station nearer the site, set weather.file.stand_in = true, or shift the record's times",
        history.source,
        parts.join("; ")
    ))
}
