//! `irsig crosscheck` end to end: the committed sample meshes agree between
//! backends (exit 0), and bad input gives a clear error, not a panic.

use std::path::Path;
use std::process::Command;

use irsig::trace::meshgen;

fn irsig() -> Command {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn committed_meshes_match_their_generator() {
    for (name, m) in [
        ("mixed", meshgen::mixed_scene()),
        ("bench", meshgen::bench_scene()),
    ] {
        let committed =
            std::fs::read_to_string(root().join(format!("scenes/meshes/{name}.obj"))).unwrap();
        assert!(
            committed == m.to_obj(),
            "scenes/meshes/{name}.obj is stale: cargo run --example gen_meshes"
        );
    }
}

#[test]
fn crosscheck_sample_meshes_has_no_unexplained_difference() {
    for name in ["mixed", "bench"] {
        let out = irsig()
            .args(["crosscheck", "--json", "--width", "128", "--height", "128"])
            .arg(root().join(format!("scenes/meshes/{name}.obj")))
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{name}: {text}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert!(v["primary"]["compared"].as_u64().unwrap() == 128 * 128);
        assert!(v["solar"]["compared"].as_u64().unwrap() > 1000);
    }
}

fn run_err(args: &[&str], file: Option<(&str, &str)>) -> (i32, String) {
    let dir = tempfile::tempdir().unwrap();
    let mut cmd = irsig();
    cmd.args(args);
    if let Some((name, text)) = file {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        cmd.arg(&p);
    }
    let out = cmd.output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "panic: {err}");
    (out.status.code().unwrap_or(-1), err)
}

#[test]
fn bad_input_gives_clear_errors() {
    let (code, err) = run_err(&["crosscheck", "/nonexistent/mesh.obj"], None);
    assert_eq!(code, 1);
    assert!(
        err.contains("/nonexistent/mesh.obj") && err.contains("cannot read file"),
        "{err}"
    );

    let (code, err) = run_err(
        &["crosscheck"],
        Some(("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")),
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("nan.obj:2:") && err.contains("expected a finite number"),
        "{err}"
    );

    let (code, err) = run_err(
        &["crosscheck"],
        Some(("oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")),
    );
    assert_eq!(code, 1);
    assert!(err.contains("oob.obj:4"), "{err}");

    let (code, err) = run_err(&["crosscheck"], Some(("junk.obj", "v 0 zero 0\nf a b c\n")));
    assert_eq!(code, 1);
    assert!(err.contains("junk.obj:1"), "{err}");

    // Zero-area triangles are a counted skip, not an error.
    let out = irsig()
        .arg("crosscheck")
        .arg("--json")
        .arg({
            let p =
                std::env::temp_dir().join(format!("irsig-degenerate-{}.obj", std::process::id()));
            std::fs::write(&p, "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n").unwrap();
            p
        })
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["skipped_degenerate"], 1);

    let (code, err) = run_err(&["crosscheck", "--width", "0", "x.obj"], None);
    assert_eq!(code, 2, "clap usage error");
    assert!(err.contains("--width"), "{err}");
}

/// The paper's demo scene, with its own camera and the sun directions of
/// its 24-h shadow history: zero unexplained differences.
#[test]
fn crosscheck_airfield_scene_has_no_unexplained_difference() {
    let out = irsig()
        .args(["crosscheck", "--json"])
        .arg(root().join("scenes/airfield/scene.toml"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["primary"]["compared"].as_u64().unwrap(), 512 * 512);
    assert!(v["solar"]["compared"].as_u64().unwrap() > 1_000_000);
    assert!(v["triangles"].as_u64().unwrap() > 4000);
}

/// A mesh at UTM-like coordinates (500 km east, 4,800 km north) is traced
/// in a local frame at its centre: the cross-check's counts are those of
/// the same mesh at the origin, with no unexplained difference, and the
/// report gives the frame's origin in world coordinates.
#[test]
fn crosscheck_of_a_far_mesh_equals_the_near_one() {
    let text = std::fs::read_to_string(root().join("scenes/meshes/mixed.obj")).unwrap();
    let far: String = text
        .lines()
        .map(
            |l| match l.split_whitespace().collect::<Vec<_>>().as_slice() {
                ["v", x, y, z] => {
                    let (x, y): (f64, f64) = (x.parse().unwrap(), y.parse().unwrap());
                    format!("v {} {} {z}\n", x + 500e3, y + 4800e3)
                }
                _ => format!("{l}\n"),
            },
        )
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let mut reports = Vec::new();
    for (name, t) in [("near.obj", &text), ("far.obj", &far)] {
        let p = dir.path().join(name);
        std::fs::write(&p, t).unwrap();
        let out = irsig()
            .args(["crosscheck", "--json", "--width", "96", "--height", "96"])
            .arg(&p)
            .output()
            .unwrap();
        let s = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(out.status.success(), "{name}: {s}");
        let mut v: serde_json::Value = serde_json::from_str(&s).unwrap();
        let origin = v["local_origin_m"].take();
        reports.push((v, origin));
    }
    let (near, far) = (&reports[0], &reports[1]);
    assert_eq!(near.0, far.0, "the far mesh's cross-check differs");
    for k in 0..2 {
        let d = far.1[k].as_f64().unwrap() - near.1[k].as_f64().unwrap();
        assert_eq!(d, [500e3, 4800e3][k], "{:?} vs {:?}", far.1, near.1);
    }
}
