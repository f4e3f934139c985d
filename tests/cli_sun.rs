//! `irsig sun` end to end: the Reda & Andreas (2004) worked example through
//! the CLI (zenith 50.11162°, azimuth 194.34024°, printed to 5 decimals), JSON
//! output, and the errors for a bad time string and an out-of-range latitude.

use std::process::Command;

fn irsig(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
        .args(args)
        .output()
        .unwrap()
}

const EXAMPLE: [&str; 15] = [
    "sun",
    "--lat",
    "39.742476",
    "--lon",
    "-105.1786",
    "--elevation",
    "1830.14",
    "--time",
    "2003-10-17T12:30:30-07:00",
    "--pressure-hpa",
    "820",
    "--temp-c",
    "11",
    "--delta-t",
    "67",
];

#[test]
fn sun_text_output_matches_published_example() {
    let o = irsig(&EXAMPLE);
    assert!(o.status.success());
    let s = String::from_utf8(o.stdout).unwrap();
    assert!(s.contains("zenith_deg             50.11162"), "{s}");
    assert!(s.contains("azimuth_deg            194.34024"), "{s}");
    assert!(
        s.contains("time_utc               2003-10-17T19:30:30Z"),
        "{s}"
    );
}

#[test]
fn sun_json_output() {
    let mut args = EXAMPLE.to_vec();
    args.push("--json");
    let o = irsig(&args);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let z = v["zenith_deg"].as_f64().unwrap();
    let az = v["azimuth_deg"].as_f64().unwrap();
    assert!((z - 50.11162).abs() < 5e-6 && (az - 194.34024).abs() < 5e-6);
    let e: Vec<f64> = v["sun_dir_enu"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    // ENU from the angles: (cos e sin A, cos e cos A, sin e), to 1e-9.
    let (el, a) = ((90.0 - z).to_radians(), az.to_radians());
    assert!((e[0] - el.cos() * a.sin()).abs() < 1e-9);
    assert!((e[1] - el.cos() * a.cos()).abs() < 1e-9);
    assert!((e[2] - el.sin()).abs() < 1e-9);
}

#[test]
fn sun_bad_time_says_expected_format() {
    let o = irsig(&[
        "sun",
        "--lat",
        "10",
        "--lon",
        "10",
        "--time",
        "2024-06-21 12:00",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("RFC 3339") && err.contains("2024-06-21T12:00:00Z"),
        "{err}"
    );
}

#[test]
fn sun_out_of_range_lat_lon() {
    let o = irsig(&[
        "sun",
        "--lat",
        "-91",
        "--lon",
        "10",
        "--time",
        "2024-06-21T12:00:00Z",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(err.contains("latitude -91 is out of range"), "{err}");
    let o = irsig(&[
        "sun",
        "--lat",
        "10",
        "--lon",
        "181",
        "--time",
        "2024-06-21T12:00:00Z",
    ]);
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(err.contains("longitude 181 is out of range"), "{err}");
}
