//! `irsig bench accuracy` and `bench speed`: the accuracy harness's table is consistent (the reference
//! row has zero error, every requested ladder row is there) and its errors
//! behave as the numerics say they must: the spectral integration error
//! falls as the step is refined (trapezoid rule, O(Δν²)), and at least
//! 10x from 40 to 5 cm⁻¹.

mod common;
use common::{airfield, irsig, run, succeed};

fn csv_rows(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn accuracy_ladder_for_one_knob() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("acc");
    let args: Vec<String> = [
        "bench",
        "accuracy",
        airfield().to_str().unwrap(),
        "--size",
        "8",
        "--knob",
        "spectral_step_cm1",
        "--others-at-default",
        "--threads",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let stdout = run(&args);
    let file = std::fs::read_to_string(out.join("accuracy.csv")).unwrap();
    assert_eq!(stdout, file, "stdout is the CSV");
    assert!(out.join("accuracy.json").is_file());
    let svg = std::fs::read_to_string(out.join("accuracy.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("spectral_step_cm1"));
    let rows = csv_rows(&file);
    let col = |name: &str| {
        file.lines()
            .next()
            .unwrap()
            .split(',')
            .position(|c| c == name)
            .unwrap()
    };
    let (knob, value, rad) = (col("knob"), col("value"), col("radiance_rms_pct"));
    assert_eq!(rows[0][knob], "reference");
    assert_eq!(rows[0][rad].parse::<f64>().unwrap(), 0.0);
    let ladder: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r[knob] == "render.spectral_step_cm1")
        .map(|r| (r[value].parse().unwrap(), r[rad].parse().unwrap()))
        .collect();
    assert_eq!(
        ladder.iter().map(|l| l.0).collect::<Vec<_>>(),
        vec![40.0, 20.0, 10.0, 5.0]
    );
    for w in ladder.windows(2) {
        assert!(
            w[1].1 <= w[0].1,
            "error must fall with the step: {ladder:?}"
        );
    }
    assert!(ladder[3].1 * 10.0 < ladder[0].1, "{ladder:?}");
    assert_eq!(rows.last().unwrap()[knob], "default");
    // Every row: RMS ≤ p99 ≤ max is not a law (RMS may exceed p99), but
    // p99 ≤ max is, and the shadow-edge pixels are a subset of all pixels.
    let n_px = 8 * 8;
    for r in &rows {
        let v = |name: &str| r[col(name)].parse::<f64>().unwrap();
        for q in ["surface_temp", "apparent_temp"] {
            assert!(
                v(&format!("{q}_p99_k")) <= v(&format!("{q}_max_k")),
                "{r:?}"
            );
            assert!(
                v(&format!("{q}_rms_k")) <= v(&format!("{q}_max_k")),
                "{r:?}"
            );
            for e in ["edge", "object_edge"] {
                let edge_max = v(&format!("{e}_{q}_max_k"));
                assert!(
                    edge_max.is_nan() || edge_max <= v(&format!("{q}_max_k")),
                    "{r:?}"
                );
            }
        }
        assert!(v("radiance_p99_pct") <= v("radiance_max_pct"), "{r:?}");
        let edges: usize = r[col("edge_pixels")].parse().unwrap();
        assert!(edges <= n_px, "{r:?}");
        // (the airfield at 8×8: runway, apron and buildings leave object
        // edges in some pixels, not in all)
        let objects: usize = r[col("object_edge_pixels")].parse().unwrap();
        assert!(objects > 0 && objects < n_px, "{r:?}");
    }
}

#[test]
fn accuracy_rejects_an_unknown_knob() {
    let out = irsig()
        .args([
            "bench",
            "accuracy",
            airfield().to_str().unwrap(),
            "--knob",
            "supersampling",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("knob supersampling: not a knob") && err.contains("supersample"),
        "{err}"
    );
}

#[test]
fn accuracy_ladder_needs_one_knob() {
    let out = irsig()
        .args([
            "bench",
            "accuracy",
            airfield().to_str().unwrap(),
            "--ladder",
            "60,30",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--ladder needs exactly one --knob"), "{err}");
}

#[test]
fn speed_reports_the_write_stage() {
    let out = succeed(irsig().args([
        "bench",
        "speed",
        airfield().to_str().unwrap(),
        "--sizes",
        "32",
        "--subdivide",
        "1",
        "--set",
        "render.history_hours=6",
        "--json",
    ]));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let r = &rows[0];
    let f = |k: &str| r[k].as_f64().unwrap_or_else(|| panic!("{k} in {r}"));
    assert!(f("output_s") > 0.0);
    assert!((f("total_with_output_s") - f("total_s") - f("output_s")).abs() < 1e-9);
    assert!(f("peak_rss_mib") > 10.0, "{r}");
    assert_eq!(r["size"], 32);
}
