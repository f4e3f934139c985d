//! Real weather files as users have them (issue 14): excerpts under
//! tests/data/wild/weather/ (provenance and licences in tests/data/README.md)
//! read by irsig and by pvlib's `iotools` (`tools/ref_weather_wild.py`), and
//! each way such a file used to fail.

mod common;

use std::path::{Path, PathBuf};

use chrono::{DateTime, Duration, Utc};
use irsig::therm::weather::{ReadOptions, WeatherHistory, YearSpan, ZERO_C_K, read_weather};

fn wild(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/wild/weather")
        .join(name)
}

fn utc(s: &str) -> DateTime<Utc> {
    DateTime::parse_from_rfc3339(s).unwrap().with_timezone(&Utc)
}

/// One reference row: the UTC time and the named values.
struct Row {
    t: DateTime<Utc>,
    v: Vec<(String, f64)>,
}

impl Row {
    fn get(&self, k: &str) -> f64 {
        self.v.iter().find(|(n, _)| n == k).unwrap().1
    }
}

fn reference(name: &str) -> Vec<Row> {
    let text = std::fs::read_to_string(wild(name)).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            Row {
                t: utc(f[0]),
                v: header[1..]
                    .iter()
                    .cloned()
                    .zip(f[1..].iter().map(|x| x.parse().unwrap()))
                    .collect(),
            }
        })
        .collect()
}

/// Same decimal numbers parsed; only unit conversions in between.
const TOL: f64 = 1e-9;

fn close(a: f64, b: f64, what: &str, t: DateTime<Utc>) {
    assert!((a - b).abs() < TOL, "{what} at {t}: irsig {a}, pvlib {b}");
}

/// The TMY3 hour-ending convention: instantaneous fields at the stamp,
/// irradiances averaged over the hour before it (checked at its middle
/// where the previous hour is in the file).
fn check_tmy3_like(h: &WeatherHistory, rows: &[Row]) {
    for (i, r) in rows.iter().enumerate() {
        let t = r.t;
        assert!(h.times.binary_search(&t).is_ok(), "no record at {t}");
        let s = h.at(t);
        close(s.air_temp_k - ZERO_C_K, r.get("temp_air"), "air", t);
        close(s.dew_point_k - ZERO_C_K, r.get("temp_dew"), "dew point", t);
        close(s.pressure_pa / 100.0, r.get("pressure"), "pressure", t);
        close(s.wind_speed_m_s, r.get("wind_speed"), "wind", t);
        close(
            s.cloud_fraction.unwrap() * 10.0,
            r.get("TotCld (tenths)"),
            "cloud",
            t,
        );
        if i > 0 && rows[i - 1].t == t - Duration::hours(1) {
            let m = h.at(t - Duration::minutes(30));
            close(m.ghi_w_m2.unwrap(), r.get("ghi"), "GHI", t);
            close(m.dni_w_m2.unwrap(), r.get("dni"), "DNI", t);
            close(m.dhi_w_m2.unwrap(), r.get("dhi"), "DHI", t);
        }
    }
}

/// A typical-year TMY3 (January from 1988, December from 1980) laid on
/// 1990-1991: every record where pvlib puts it in each year, and the night
/// of 31 December 1990 runs straight into the file's own 1 January (no
/// missing hours across the year end).
#[test]
fn typical_year_wraps_at_the_year_end() {
    let opts = ReadOptions {
        typical_year: Some(YearSpan {
            first: 1990,
            last: 1991,
        }),
        // The excerpt skips 3 January to 29 December.
        max_gap_s: 400.0 * 86400.0,
        ..ReadOptions::default()
    };
    let f = read_weather(&wild("tmy3_723170_yearend.csv"), &opts).unwrap();
    let rows = reference("tmy3_723170_yearend_pvlib.csv");
    assert_eq!(rows.len(), 192);
    check_tmy3_like(&f.history, &rows);
    // 31 Dec 1990 12:00 to 1 Jan 1991 12:00 UTC is covered with hourly records.
    let (a, b) = (utc("1990-12-31T12:00:00Z"), utc("1991-01-01T12:00:00Z"));
    f.history.check_covers(a, b).unwrap();
    // The record of 1 January 01:00 local (06:00 UTC) follows 31 December
    // 24:00 (05:00 UTC) one hour later.
    let jan1 = rows
        .iter()
        .position(|r| r.t == utc("1991-01-01T06:00:00Z"))
        .unwrap();
    assert_eq!(rows[jan1 - 1].t, utc("1991-01-01T05:00:00Z"));
    // Mid-hour irradiance of that first January hour is the file's January value.
    let m = f.history.at(utc("1991-01-01T05:30:00Z"));
    close(
        m.ghi_w_m2.unwrap(),
        rows[jan1].get("ghi"),
        "GHI",
        rows[jan1].t,
    );
}

/// Without `typical_year` the same file is refused where its source year
/// changes, naming the scene key and the CLI flag (no internal API names).
#[test]
fn typical_year_file_without_the_key_names_key_and_flag() {
    let p = wild("tmy3_723170_yearend.csv");
    let e = read_weather(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tmy3_723170_yearend.csv:51:")
            && e.contains("from 1988-01-02 (line 50) to 1980-12-30")
            && e.contains("typical_year = true")
            && e.contains("--typical-year")
            && !e.contains("coerce"),
        "{e}"
    );
    // irsig therm says the same.
    let (code, _, err) = common::irsig_out(&[
        "therm",
        "--materials",
        concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/materials.toml"),
        "--material",
        "concrete",
        "--weather",
        p.to_str().unwrap(),
        "--lat",
        "36.1",
        "--lon",
        "-79.95",
        "--from",
        "1988-01-02T12:00:00Z",
        "--to",
        "1988-01-02T13:00:00Z",
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("--typical-year") && !err.contains("coerce"),
        "{err}"
    );
}

/// `irsig check` reads the weather: a scene whose weather file cannot be
/// read (here a typical year without the key) fails with the reader's
/// message, and one whose weather does not cover the history fails too.
#[test]
fn check_fails_on_unreadable_weather() {
    let p = wild("tmy3_723170_yearend.csv");
    let scene = common::airfield();
    let set = format!("weather.file.path=\"{}\"", p.display());
    let (code, _, err) = common::irsig_out(&["check", scene.to_str().unwrap(), "--set", &set]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("typical_year = true"), "{err}");
    let (code, _, err) = common::irsig_out(&[
        "check",
        scene.to_str().unwrap(),
        "--set",
        &set,
        "--set",
        "weather.file.typical_year=true",
    ]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("gap of"), "{err}");
    // The sample scene itself passes.
    let (code, _, err) = common::irsig_out(&["check", scene.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
}

/// A CSV saved by Excel as "CSV UTF-8" starts with a byte-order mark: it
/// reads as the same file without one.
#[test]
fn utf8_bom_is_stripped() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/stations/bon-19950510.csv");
    let text = std::fs::read(&src).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (plain, bom) = (dir.path().join("wx.csv"), dir.path().join("wx-bom.csv"));
    std::fs::write(&plain, &text).unwrap();
    std::fs::write(&bom, [b"\xEF\xBB\xBF".as_slice(), &text].concat()).unwrap();
    let a = read_weather(&plain, &ReadOptions::default()).unwrap();
    let b = read_weather(&bom, &ReadOptions::default()).unwrap();
    assert_eq!(a.history.samples, b.history.samples);
    assert_eq!(a.history.times, b.history.times);
}

/// A plain CSV with measured sky temperature and irradiances but no cloud
/// column reads, and drives the forcing without any cloud estimate in the
/// sky term (the measured sky temperature is used) and with cloud derived
/// from the measured GHI where it would be needed.
#[test]
fn csv_without_cloud_but_with_measured_sky_temperature() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/stations/bon-19950510.csv");
    let text = std::fs::read_to_string(&src).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !header[i].starts_with("cloud"))
        .collect();
    assert!(keep.len() < header.len() && header.contains(&"sky_temp_c"));
    let cut = |l: &str| {
        let f: Vec<&str> = l.split(',').collect();
        keep.iter().map(|&i| f[i]).collect::<Vec<_>>().join(",")
    };
    let mut out: Vec<String> = text
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(String::from)
        .collect();
    out.extend(text.lines().filter(|l| !l.starts_with('#')).map(cut));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("no-cloud.csv");
    std::fs::write(&p, out.join("\n")).unwrap();
    let f = read_weather(&p, &ReadOptions::default()).unwrap();
    assert!(f.history.samples.iter().all(|s| s.cloud_fraction.is_none()));
    let site = irsig::sun::Site {
        lat_deg: 40.05,
        lon_deg: -88.37,
        elevation_m: 213.0,
    };
    let start = f.history.start();
    let n = ((f.history.end() - start).num_seconds() / 1800) as usize;
    let (forcing, rep) =
        irsig::therm::forcing::build_forcing(&f.history, &site, start, 1800.0, n).unwrap();
    assert_eq!(rep.sky_temp_measured, n + 1);
    assert_eq!(rep.clear_sky_cloud, 0);
    for (k, x) in forcing.iter().enumerate() {
        let want = f.history.at(start + Duration::seconds(1800 * k as i64));
        assert_eq!(x.sky_temp_k, want.sky_temp_k.unwrap());
    }
}
