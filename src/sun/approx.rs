//! A cheap approximate solar elevation (NOAA's Fourier series), for
//! telling day from night where the full SPA is not needed.

/// Approximate solar elevation (degrees, no refraction) from the NOAA
/// "General Solar Position Calculations" (fractional-year Fourier series
/// for the declination and the equation of time, Spencer 1971), good to
/// about 0.3°. Only used to tell day from night in this summary; the
/// renderer uses `crate::sun` (NREL SPA).
pub fn approx_sun_elevation_deg(
    t: chrono::DateTime<chrono::Utc>,
    lat_deg: f64,
    lon_deg: f64,
) -> f64 {
    use chrono::{Datelike, Timelike};
    let hour = t.hour() as f64 + t.minute() as f64 / 60.0 + t.second() as f64 / 3600.0;
    let days = if t.date_naive().leap_year() {
        366.0
    } else {
        365.0
    };
    let g = 2.0 * std::f64::consts::PI / days * (t.ordinal() as f64 - 1.0 + (hour - 12.0) / 24.0);
    let eqtime_min = 229.18
        * (0.000075 + 0.001868 * g.cos()
            - 0.032077 * g.sin()
            - 0.014615 * (2.0 * g).cos()
            - 0.040849 * (2.0 * g).sin());
    let decl = 0.006918 - 0.399912 * g.cos() + 0.070257 * g.sin() - 0.006758 * (2.0 * g).cos()
        + 0.000907 * (2.0 * g).sin()
        - 0.002697 * (3.0 * g).cos()
        + 0.00148 * (3.0 * g).sin();
    let true_solar_min = hour * 60.0 + eqtime_min + 4.0 * lon_deg;
    let ha = (true_solar_min / 4.0 - 180.0).to_radians();
    let lat = lat_deg.to_radians();
    let cos_zen = lat.sin() * decl.sin() + lat.cos() * decl.cos() * ha.cos();
    90.0 - cos_zen.clamp(-1.0, 1.0).acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against NREL SPA (pvlib 0.16, `spa_python`, geometric elevation
    /// without refraction): tests/data/sun_elevation_pvlib.csv, generated
    /// by tools/sun_elevation_ref.py. Tolerance 0.5° (the NOAA series is
    /// good to ~0.3°; day/night only needs the sign away from the horizon).
    #[test]
    fn approximate_sun_elevation_matches_spa() {
        let text = include_str!("../../tests/data/sun_elevation_pvlib.csv");
        let mut n = 0;
        for line in text.lines().skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            let t = chrono::NaiveDateTime::parse_from_str(f[0], "%Y-%m-%dT%H:%M:%S")
                .unwrap()
                .and_utc();
            let (lat, lon, want): (f64, f64, f64) = (
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
            );
            let got = approx_sun_elevation_deg(t, lat, lon);
            assert!((got - want).abs() < 0.5, "{line}: got {got}");
            n += 1;
        }
        assert_eq!(n, 10);
    }
}
