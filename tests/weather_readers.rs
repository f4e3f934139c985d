//! Weather readers vs pvlib's readers (`tools/ref_weather.py`):
//! the committed TMY3 and EPW excerpts must give, at each record's stamp,
//! pvlib's instantaneous values, and at the middle of the record's hour,
//! pvlib's hour-averaged irradiances. Tolerance 1e-9 (same decimal numbers
//! parsed; only unit conversions in between).

use std::path::Path;

use chrono::{DateTime, Duration, Utc};
use irsig::therm::weather::{
    ReadOptions, WeatherFormat, read_weather_file, read_weather_file_with,
};
use irsig::units::{STEFAN_BOLTZMANN_W_M2K4, ZERO_C_K};

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// One reference row: (time_end_utc, named values).
type Row = (DateTime<Utc>, Vec<(String, f64)>);

/// The rows of a reference CSV.
fn reference(name: &str) -> Vec<Row> {
    let text = std::fs::read_to_string(data(name)).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let t = DateTime::parse_from_rfc3339(f[0])
                .unwrap()
                .with_timezone(&Utc);
            (
                t,
                header[1..]
                    .iter()
                    .cloned()
                    .zip(f[1..].iter().map(|x| x.parse().unwrap()))
                    .collect(),
            )
        })
        .collect()
}

fn get(row: &[(String, f64)], k: &str) -> f64 {
    row.iter().find(|(n, _)| n == k).unwrap().1
}

const TOL: f64 = 1e-9;

#[test]
fn tmy3_matches_pvlib_read_tmy3() {
    let f = read_weather_file_with(
        &data("tmy3_723170_greensboro_jun18-22.csv"),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(f.format, WeatherFormat::Tmy3);
    let st = f.station.unwrap();
    assert_eq!(
        (st.lat_deg, st.lon_deg, st.elevation_m, st.utc_offset_h),
        (36.1, -79.95, 273.0, -5.0)
    );
    let h = &f.history;
    let rows = reference("tmy3_greensboro_pvlib.csv");
    assert_eq!(rows.len(), 120);
    // 120 stamps + 119 hour midpoints.
    assert_eq!(h.times.len(), 239);
    assert_eq!(h.start(), rows[0].0);
    assert_eq!(h.end(), rows[119].0);
    for (i, (t, r)) in rows.iter().enumerate() {
        let s = h.at(*t);
        assert!(
            (s.air_temp_k - ZERO_C_K - get(r, "temp_air")).abs() < TOL,
            "{t}"
        );
        assert!(
            (s.dew_point_k - ZERO_C_K - get(r, "temp_dew")).abs() < TOL,
            "{t}"
        );
        assert!(
            (s.pressure_pa / 100.0 - get(r, "pressure")).abs() < TOL,
            "{t}"
        );
        assert!((s.wind_speed_m_s - get(r, "wind_speed")).abs() < TOL, "{t}");
        assert!(
            (s.cloud_fraction.unwrap() * 10.0 - get(r, "TotCld (tenths)")).abs() < TOL,
            "{t}"
        );
        if i > 0 {
            let m = h.at(*t - Duration::minutes(30));
            assert!((m.ghi_w_m2.unwrap() - get(r, "ghi")).abs() < TOL, "{t}");
            assert!((m.dni_w_m2.unwrap() - get(r, "dni")).abs() < TOL, "{t}");
            assert!((m.dhi_w_m2.unwrap() - get(r, "dhi")).abs() < TOL, "{t}");
            assert!(
                (m.precip_mm_h - get(r, "Lprecip depth (mm)")).abs() < TOL,
                "{t}"
            );
            // Instantaneous fields at the midpoint: mean of the two stamps.
            let prev = h.at(rows[i - 1].0);
            assert!((m.air_temp_k - (prev.air_temp_k + s.air_temp_k) / 2.0).abs() < TOL);
            // Period fields at a stamp: mean of the two neighbouring hours.
            if i + 1 < rows.len() {
                let want = (get(r, "ghi") + get(&rows[i + 1].1, "ghi")) / 2.0;
                assert!((s.ghi_w_m2.unwrap() - want).abs() < TOL, "{t}");
            }
        }
    }
    assert!(
        h.samples.iter().all(|s| s.sky_temp_k.is_none()),
        "TMY3 has no sky temperature"
    );
    // Sunny June days in Greensboro: peak GHI is several hundred W/m² around 17 UTC.
    let peak = h
        .samples
        .iter()
        .filter_map(|s| s.ghi_w_m2)
        .fold(0.0, f64::max);
    assert!(peak > 600.0 && peak < 1200.0, "{peak}");
}

#[test]
fn epw_matches_pvlib_read_epw() {
    let f = read_weather_file_with(
        &data("epw_amsterdam_iwec_jun18-22.epw"),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(f.format, WeatherFormat::Epw);
    let st = f.station.unwrap();
    assert_eq!(
        (st.lat_deg, st.lon_deg, st.elevation_m, st.utc_offset_h),
        (52.3, 4.77, -2.0, 1.0)
    );
    let h = &f.history;
    let rows = reference("epw_amsterdam_pvlib.csv");
    assert_eq!(rows.len(), 120);
    assert_eq!(h.start(), rows[0].0);
    for (i, (t, r)) in rows.iter().enumerate() {
        let s = h.at(*t);
        assert!(
            (s.air_temp_k - ZERO_C_K - get(r, "temp_air")).abs() < TOL,
            "{t}"
        );
        assert!(
            (s.dew_point_k - ZERO_C_K - get(r, "temp_dew")).abs() < TOL,
            "{t}"
        );
        assert!(
            (s.pressure_pa - get(r, "atmospheric_pressure")).abs() < TOL,
            "{t}"
        );
        assert!((s.wind_speed_m_s - get(r, "wind_speed")).abs() < TOL, "{t}");
        assert!(
            (s.cloud_fraction.unwrap() * 10.0 - get(r, "total_sky_cover")).abs() < TOL,
            "{t}"
        );
        if i > 0 {
            let m = h.at(*t - Duration::minutes(30));
            assert!((m.ghi_w_m2.unwrap() - get(r, "ghi")).abs() < TOL, "{t}");
            assert!((m.dni_w_m2.unwrap() - get(r, "dni")).abs() < TOL, "{t}");
            assert!((m.dhi_w_m2.unwrap() - get(r, "dhi")).abs() < TOL, "{t}");
            // Sky temperature from the infrared field: σT⁴ = L (to 1e-9 W/m²).
            let tk = m.sky_temp_k.unwrap();
            assert!(
                (STEFAN_BOLTZMANN_W_M2K4 * tk.powi(4) - get(r, "ghi_infrared")).abs() < 1e-9,
                "{t}"
            );
        }
    }
}

#[test]
fn read_weather_file_default_api() {
    let h = read_weather_file(&data("tmy3_723170_greensboro_jun18-22.csv"), None).unwrap();
    assert!(h.source.ends_with("tmy3_723170_greensboro_jun18-22.csv"));
    // Covers June 19-21 local, not June 17.
    let t = |s: &str| DateTime::parse_from_rfc3339(s).unwrap().with_timezone(&Utc);
    assert!(
        h.check_covers(t("1989-06-19T00:00:00Z"), t("1989-06-21T00:00:00Z"))
            .is_ok()
    );
    let e = h
        .check_covers(t("1989-06-17T12:00:00Z"), t("1989-06-19T00:00:00Z"))
        .unwrap_err()
        .to_string();
    // The first record ends at 1989-06-18T01:00 local = 06:00 UTC.
    assert!(
        e.contains("18 h from 1989-06-17T12:00Z to 1989-06-18T06:00Z"),
        "{e}"
    );
}

#[test]
fn missing_file_names_it() {
    let e = read_weather_file(Path::new("/nonexistent/wx.csv"), None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("/nonexistent/wx.csv") && e.contains("cannot read"),
        "{e}"
    );
}
