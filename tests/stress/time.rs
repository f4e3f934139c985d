//! Time extremes: the sun at polar day and night (lat ±89.9° at the
//! solstices), in 1950 and 2100, on DST change days and leap days; date
//! parsing of leap days (scene `[time] local`, `irsig sun --time`, weather
//! files); weather interpolation across a DST change written with explicit
//! offsets, and a local-clock file that repeats an hour.

use chrono::{DateTime, Duration, TimeZone, Utc};
use irsig::scene::parse_scene;
use irsig::sun::report::parse_time;
use irsig::sun::{solar_position, sun_events_near};
use irsig::weather::{ReadOptions, parse_plain_csv};
use proptest::prelude::*;

fn utc(y: i32, mo: u32, d: u32, h: u32, mi: u32) -> DateTime<Utc> {
    Utc.with_ymd_and_hms(y, mo, d, h, mi, 0).unwrap()
}

/// Asserts the physical bounds of one solar position.
fn check_sun(t: DateTime<Utc>, lat: f64, lon: f64, elev_m: f64) -> irsig::sun::SolarPosition {
    let p = solar_position(t, lat, lon, elev_m);
    let ctx = format!("{t} lat {lat} lon {lon} elev {elev_m}: {p:?}");
    let all = [
        p.zenith_deg,
        p.true_zenith_deg,
        p.elevation_deg,
        p.true_elevation_deg,
        p.azimuth_deg,
        p.earth_sun_distance_au,
        p.declination_deg,
        p.equation_of_time_min,
    ];
    assert!(all.iter().all(|x| x.is_finite()), "{ctx}");
    assert!((0.0..=180.0).contains(&p.zenith_deg), "{ctx}: zenith");
    assert!(
        (0.0..=180.0).contains(&p.true_zenith_deg),
        "{ctx}: true zenith"
    );
    assert!((0.0..360.0).contains(&p.azimuth_deg), "{ctx}: azimuth");
    assert!(
        (0.98..=1.02).contains(&p.earth_sun_distance_au),
        "{ctx}: distance"
    );
    assert!(p.declination_deg.abs() <= 23.5, "{ctx}: declination");
    assert!(
        p.equation_of_time_min.abs() <= 20.0,
        "{ctx}: equation of time"
    );
    // refraction only lifts the sun, by at most ~0.6° (plus a margin)
    let refr = p.elevation_deg - p.true_elevation_deg;
    assert!((0.0..=1.0).contains(&refr), "{ctx}: refraction {refr}");
    let v = p.sun_dir_enu;
    assert!(v.iter().all(|x| x.is_finite()), "{ctx}");
    let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    assert!((norm - 1.0).abs() < 1e-9, "{ctx}: |sun_dir| = {norm}");
    assert!(
        (v[2] - p.zenith_deg.to_radians().cos()).abs() < 1e-9,
        "{ctx}: sun_dir up component vs zenith"
    );
    p
}

/// Polar day and night at lat ±89.9° on both solstices of 1950, 2000, 2024
/// and 2100, every 30 min for a day, at longitudes −180, 0, 179.99 and 180:
/// all outputs finite and in bounds; at 89.9° the sun's elevation hardly
/// changes over the day and it stays up (summer) or down (winter) all day;
/// sunrise and sunset do not exist.
#[test]
fn polar_day_and_night_at_the_solstices() {
    for year in [1950, 2000, 2024, 2100] {
        for (month, day) in [(6, 21), (12, 21)] {
            for lat in [89.9, -89.9] {
                let summer = (month == 6) == (lat > 0.0);
                for lon in [-180.0, 0.0, 179.99, 180.0] {
                    let t0 = utc(year, month, day, 0, 0);
                    let mut els = Vec::new();
                    for k in 0..48 {
                        let p = check_sun(t0 + Duration::minutes(30 * k), lat, lon, 0.0);
                        els.push(p.elevation_deg);
                        if summer {
                            assert!(p.elevation_deg > 20.0, "{year}-{month} lat {lat}: {p:?}");
                        } else {
                            assert!(p.elevation_deg < -20.0, "{year}-{month} lat {lat}: {p:?}");
                        }
                    }
                    let (lo, hi) = els
                        .iter()
                        .fold((f64::MAX, f64::MIN), |(a, b), e| (a.min(*e), b.max(*e)));
                    assert!(
                        hi - lo < 0.5,
                        "{year}-{month} lat {lat}: elevation range {lo}..{hi}"
                    );
                    let ev = sun_events_near(t0 + Duration::hours(12), lat, lon);
                    assert!(ev.sunrise.is_none() && ev.sunset.is_none(), "{ev:?}");
                    assert!(ev.transit_elevation_deg.is_finite());
                }
            }
        }
    }
    // the poles themselves and the date line
    for lat in [90.0, -90.0] {
        for lon in [-180.0, 180.0] {
            check_sun(utc(2024, 3, 20, 3, 6), lat, lon, 0.0);
        }
    }
}

/// The ends of the supported dates (1950-01-01 00:00 and 2100-12-31 23:59
/// UTC), leap days (2000-02-29, 2024-02-29, the day after a leap day) and
/// US/EU DST change days (in UTC, DST is only a clock label), every 20 min
/// over the day at eight latitudes from −89.9 to 89.9 and four longitudes,
/// from sea level to 8,848 m and down to −430 m: every output finite and in
/// bounds; the sun moves continuously across the days (≤ 5.7° per 20 min:
/// 5° of hour angle plus the SPA's refraction step of ≤ 0.6° at the horizon).
#[test]
fn sun_on_date_extremes_leap_and_dst_days() {
    let days = [
        (1950, 1, 1),
        (1950, 6, 21),
        (2100, 12, 31),
        (2100, 2, 28),
        (2100, 3, 1),
        (2000, 2, 29),
        (2024, 2, 29),
        (2024, 3, 1),
        (2024, 3, 10),
        (2024, 3, 31),
        (2024, 10, 27),
        (2024, 11, 3),
    ];
    let lats = [-89.9, -66.56, -45.0, -0.01, 0.0, 23.44, 66.56, 89.9];
    for (y, m, d) in days {
        for &lat in &lats {
            for lon in [-180.0, -77.6, 0.0, 180.0] {
                for elev in [-430.0, 0.0, 8848.0] {
                    let t0 = utc(y, m, d, 0, 0);
                    let mut prev: Option<[f64; 3]> = None;
                    for k in 0..=72 {
                        let t = t0 + Duration::minutes(20 * k);
                        let t = if k == 72 { t - Duration::seconds(1) } else { t };
                        let p = check_sun(t, lat, lon, elev);
                        if let Some(q) = prev {
                            let v = p.sun_dir_enu;
                            let c = (q[0] * v[0] + q[1] * v[1] + q[2] * v[2]).clamp(-1.0, 1.0);
                            let step = c.acos().to_degrees();
                            assert!(
                                step <= 5.7,
                                "{t} lat {lat} elev {elev}: jump {step} deg {p:?}"
                            );
                        }
                        prev = Some(p.sun_dir_enu);
                    }
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    /// Random instants 1950-2100 (to the second), anywhere on earth, from
    /// −1000 m to 9000 m: every output finite and in bounds.
    #[test]
    fn sun_random_instants_in_bounds(
        secs in utc(1950, 1, 1, 0, 0).timestamp()..utc(2100, 12, 31, 23, 59).timestamp(),
        lat in -90.0..=90.0f64,
        lon in -180.0..=180.0f64,
        elev in -1000.0..9000.0f64,
    ) {
        check_sun(Utc.timestamp_opt(secs, 0).unwrap(), lat, lon, elev);
    }
}

/// Leap days where a date is parsed: `irsig sun --time` and the scene's
/// `[time] local` accept Feb 29 of leap years (2000, 2024) and refuse it in
/// other years (2023, 2100, 1900), and refuse Feb 30, Apr 31 and 24:00:01,
/// with a message that names the bad value (the
/// scene: its file, line and that the date is invalid).
#[test]
fn leap_days_parsed_or_refused() {
    for ok in [
        "2000-02-29T12:00:00Z",
        "2024-02-29T23:59:59+14:00",
        "1950-01-01T00:00:00-12:00",
        "2100-12-31T23:59:59Z",
    ] {
        assert!(parse_time(ok).is_ok(), "{ok}");
    }
    for bad in [
        "2023-02-29T12:00:00Z",
        "2100-02-29T12:00:00Z",
        "1900-02-29T12:00:00Z",
        "2024-02-30T12:00:00Z",
        "2024-04-31T12:00:00Z",
        "2024-06-21T24:00:01Z",
    ] {
        let e = parse_time(bad).unwrap_err();
        assert!(e.contains(bad), "{bad}: {e}");
    }
    let plate = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/plate/scene.toml");
    let text = std::fs::read_to_string(&plate).unwrap();
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("local"))
        .expect("plate scene has a [time] local line");
    let with = |v: &str| text.replace(line, &format!("local = {v}"));
    for ok in [
        "2000-02-29T12:00:00",
        "2024-02-29T00:00:00",
        "\"2024-02-29 06:30:00\"",
    ] {
        let s = parse_scene(&plate, &with(ok)).unwrap_or_else(|e| panic!("{ok}: {e}"));
        assert_eq!(s.time.local.format("%m-%d").to_string(), "02-29", "{ok}");
    }
    for bad in [
        "2023-02-29T12:00:00",
        "2100-02-29T12:00:00",
        "\"2023-02-29 12:00:00\"",
    ] {
        let e = parse_scene(&plate, &with(bad)).unwrap_err().to_string();
        let at = format!(
            "scene.toml:{}:",
            text.lines().position(|l| l == line).unwrap() + 1
        );
        assert!(
            e.contains(&at),
            "{bad}: the error names the file and line: {e}"
        );
        assert!(
            e.contains("date"),
            "{bad}: the error says what is wrong: {e}"
        );
    }
}

const HEADER: &str = "time,air_temp_c,dew_point_c,wind_m_s,cloud_fraction,ghi_w_m2\n";

/// Weather across US DST changes written with explicit offsets (EST −05:00
/// → EDT −04:00 on 2024-03-10; back on 2024-11-03, where the local hour
/// 01:00-02:00 happens twice): the reader orders the records in UTC, and
/// interpolation every 5 min across the change is finite and within the
/// neighbouring records' values. A file in local clock time with a fixed
/// offset that repeats the hour (a DST clock logged as if it were
/// standard time) is refused with the line named; Feb 29 of a non-leap
/// year is refused with the line named.
#[test]
fn weather_across_dst_changes_and_leap_days() {
    let spring = [
        "2024-03-10T00:00:00-05:00,1.0,-3.0,2.0,0.1,0",
        "2024-03-10T01:00:00-05:00,0.5,-3.5,2.5,0.2,0",
        "2024-03-10T03:00:00-04:00,0.0,-4.0,3.0,0.3,0",
        "2024-03-10T04:00:00-04:00,-0.5,-4.5,3.5,0.4,0",
    ];
    let fall = [
        "2024-11-03T00:30:00-04:00,8.0,2.0,1.0,0.0,0",
        "2024-11-03T01:00:00-04:00,7.5,2.0,1.5,0.0,0",
        "2024-11-03T01:30:00-04:00,7.0,2.0,2.0,0.0,0",
        "2024-11-03T01:00:00-05:00,6.5,2.0,2.5,0.0,0",
        "2024-11-03T01:30:00-05:00,6.0,2.0,3.0,0.0,0",
        "2024-11-03T02:00:00-05:00,5.5,2.0,3.5,0.0,0",
    ];
    for (name, rows) in [("spring.csv", &spring[..]), ("fall.csv", &fall[..])] {
        let text = format!("{HEADER}{}\n", rows.join("\n"));
        let h = parse_plain_csv(&text, name, &ReadOptions::default())
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .history;
        assert_eq!(h.times.len(), rows.len(), "{name}");
        assert!(h.times.windows(2).all(|w| w[1] > w[0]), "{name}");
        // one hour of UTC between each pair in spring, 30 min in fall
        let step = if name == "spring.csv" { 3600 } else { 1800 };
        for w in h.times.windows(2) {
            assert_eq!((w[1] - w[0]).num_seconds(), step, "{name}");
        }
        let mut t = h.start() - Duration::minutes(30);
        while t <= h.end() + Duration::minutes(30) {
            let s = h.at(t);
            let i = h
                .times
                .partition_point(|&x| x <= t)
                .clamp(1, h.times.len() - 1);
            let (a, b) = (&h.samples[i - 1], &h.samples[i]);
            for (v, lo, hi) in [
                (
                    s.air_temp_k,
                    a.air_temp_k.min(b.air_temp_k),
                    a.air_temp_k.max(b.air_temp_k),
                ),
                (
                    s.wind_speed_m_s,
                    a.wind_speed_m_s.min(b.wind_speed_m_s),
                    a.wind_speed_m_s.max(b.wind_speed_m_s),
                ),
                (
                    s.dew_point_k,
                    a.dew_point_k.min(b.dew_point_k),
                    a.dew_point_k.max(b.dew_point_k),
                ),
            ] {
                assert!(
                    v.is_finite() && v >= lo - 1e-9 && v <= hi + 1e-9,
                    "{name} at {t}: {v} not in [{lo}, {hi}]"
                );
            }
            assert!(s.pressure_pa.is_finite() && s.cloud_fraction.is_some_and(f64::is_finite));
            t += Duration::minutes(5);
        }
    }
    // local clock with a fixed offset, the fall-back hour logged twice
    let text = format!(
        "# utc_offset: -05:00\n{HEADER}2024-11-03T00:30,8,2,1,0,0\n2024-11-03T01:30,7,2,1,0,0\n2024-11-03T01:00,6,2,1,0,0\n"
    );
    let e = parse_plain_csv(&text, "dst-local.csv", &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("dst-local.csv"), "{e}");
    // Feb 29 of a non-leap year, with and without offsets
    for (row, line) in [
        ("2023-02-29T12:00:00Z,1,0,1,0,0", 3),
        ("2023-02-29T12:00,1,0,1,0,0", 3),
    ] {
        let text = format!("# utc_offset: +00:00\n{HEADER}{row}\n");
        let e = parse_plain_csv(&text, "leap.csv", &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("leap.csv:{line}")), "{row}: {e}");
        assert!(e.contains("2023-02-29"), "{row}: {e}");
    }
    // the real leap day is fine
    let text = format!(
        "{HEADER}2024-02-28T23:00:00Z,1,0,1,0,0\n2024-02-29T00:00:00Z,1,0,1,0,0\n2024-02-29T01:00:00Z,1,0,1,0,0\n"
    );
    let h = parse_plain_csv(&text, "leap.csv", &ReadOptions::default())
        .unwrap()
        .history;
    assert_eq!(h.times[1], utc(2024, 2, 29, 0, 0));
}
