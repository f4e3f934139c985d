//! Faults while writing outputs, with real child processes: an `irsig
//! render` or `irsig sequence` killed (SIGKILL) at named points of writing
//! its output sets (the `IRSIG_STALL_AT` hook, between files included) and
//! at arbitrary moments leaves either the previous complete set or a set
//! without its JSON marker, never a JSON beside another set's files; the
//! next run replaces it, removes the temporary files and, for a sequence,
//! goes on from the finished frames and ends with a complete `index.json`
//! whose frames and contact sheet equal an uninterrupted run's byte for
//! byte. A write the OS refuses (a file size limit: EFBIG) says
//! `cannot write <path>: <OS reason>` once and leaves no temporary file.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

const SCENE: &str = "scenes/airfield/scene.toml";
const SMALL: [&str; 8] = [
    "--set",
    "sensor.width_px=32",
    "--set",
    "sensor.height_px=32",
    "--set",
    "render.history_hours=6",
    "--threads",
    "1",
];

fn irsig() -> Command {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
}

/// `irsig render` of the small airfield in `band` to `exr`.
fn render_args(exr: &Path, band: &str) -> Vec<String> {
    let mut a: Vec<String> = ["render", SCENE, "-o", exr.to_str().unwrap()]
        .map(String::from)
        .into();
    a.extend(SMALL.map(String::from));
    a.extend(["--set".into(), format!("sensor.band={band}")]);
    a
}

/// Runs irsig to completion; panics on failure; returns stdout.
fn run_ok(args: &[String]) -> String {
    let o = irsig().args(args).output().unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Runs irsig with `IRSIG_STALL_AT=point`, waits until it says it stalled
/// there, and kills it with SIGKILL.
fn kill_at(args: &[String], point: &str) {
    let mut child = irsig()
        .args(args)
        .env("IRSIG_STALL_AT", point)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut seen = String::new();
    loop {
        let mut line = String::new();
        if err.read_line(&mut line).unwrap() == 0 {
            panic!("{point}: irsig ended without stalling: {seen}");
        }
        seen += &line;
        if line.contains("stalled at") {
            break;
        }
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
}

/// Temporary files left in `dir`.
fn partials(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".irsig-partial-"))
        .collect()
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The band of the complete render set at `exr` (its JSON present), after
/// checking that its EXR and PNG are byte for byte those of the reference
/// render of that band in `refs`; `None` when the JSON is absent.
fn complete_band(exr: &Path, refs: &Path) -> Option<String> {
    let json = exr.with_extension("json");
    let text = std::fs::read_to_string(&json).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).expect("a JSON marker is complete");
    // The band identifier: "mwir 3-5 um" -> "mwir".
    let key = v["band"]
        .as_str()
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .to_lowercase();
    for ext in ["exr", "png"] {
        assert!(
            read(&exr.with_extension(ext)) == read(&refs.join(format!("{key}.{ext}"))),
            "{}: the {ext} is not the {key} set's",
            exr.display()
        );
    }
    Some(key)
}

#[test]
fn killed_render_leaves_old_or_incomplete_set_and_next_run_replaces_it() {
    let dir = tempfile::tempdir().unwrap();
    let refs = dir.path().join("refs");
    for band in ["mwir", "lwir"] {
        run_ok(&render_args(&refs.join(format!("{band}.exr")), band));
    }
    let out = dir.path().join("out");
    let exr = out.join("x.exr");
    // (stall point, the set's state after the kill: Some(band) = that
    // complete set, None = no JSON, an incomplete set).
    let points = [
        ("staged-1", Some("mwir")),
        ("staged-2", Some("mwir")),
        ("staged", Some("mwir")),
        ("marker-removed", None),
        ("renamed-1", None),
        ("renamed-2", None),
        ("renamed-3", Some("lwir")),
    ];
    for (point, after) in points {
        run_ok(&render_args(&exr, "mwir"));
        assert_eq!(complete_band(&exr, &refs).as_deref(), Some("mwir"));
        kill_at(&render_args(&exr, "lwir"), point);
        assert_eq!(complete_band(&exr, &refs).as_deref(), after, "{point}");
        run_ok(&render_args(&exr, "lwir"));
        assert_eq!(
            complete_band(&exr, &refs).as_deref(),
            Some("lwir"),
            "{point}"
        );
        assert!(partials(&out).is_empty(), "{point}: {:?}", partials(&out));
    }
    // Kills at arbitrary moments of whole runs: whatever is there is a
    // complete set of one render or has no JSON.
    for delay_ms in [5, 40, 80, 120, 160, 200, 260] {
        run_ok(&render_args(&exr, "mwir"));
        let mut child = irsig()
            .args(render_args(&exr, "lwir"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill();
        child.wait().unwrap();
        let _ = complete_band(&exr, &refs); // checks a present set
        run_ok(&render_args(&exr, "lwir"));
        assert_eq!(complete_band(&exr, &refs).as_deref(), Some("lwir"));
        assert!(
            partials(&out).is_empty(),
            "{delay_ms} ms: {:?}",
            partials(&out)
        );
    }
}

#[test]
fn refused_write_says_cannot_write_once_and_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let refs = dir.path().join("refs");
    run_ok(&render_args(&refs.join("mwir.exr"), "mwir"));
    let out = dir.path().join("out");
    let exr = out.join("x.exr");
    run_ok(&render_args(&exr, "mwir"));
    // A file size limit of 10-20 kB (the EXR is ~40 kB): the kernel refuses
    // the write with EFBIG once SIGXFSZ is ignored.
    let args = render_args(&exr, "lwir").join(" ");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f 20; exec {} {args}",
            env!("CARGO_BIN_EXE_irsig")
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let want = format!(
        "cannot write {}: File too large (os error 27)",
        exr.display()
    );
    assert!(err.contains(&want), "expected {want:?} in {err}");
    assert_eq!(err.matches("cannot write").count(), 1, "{err}");
    assert_eq!(err.matches("File too large").count(), 1, "{err}");
    // The previous set is untouched and nothing temporary is left.
    assert_eq!(complete_band(&exr, &refs).as_deref(), Some("mwir"));
    assert!(partials(&out).is_empty(), "{:?}", partials(&out));
}

/// `irsig sequence` of three frames (09:00, 11:00, 13:00) into `dir`.
fn sequence_args(dir: &Path, band: &str) -> Vec<String> {
    let mut a: Vec<String> = [
        "sequence",
        SCENE,
        "--from",
        "09:00",
        "--to",
        "13:00",
        "--step",
        "2h",
        "-o",
        dir.to_str().unwrap(),
    ]
    .map(String::from)
    .into();
    a.extend(SMALL.map(String::from));
    a.extend(["--set".into(), format!("sensor.band={band}")]);
    a
}

const STEMS: [&str; 3] = ["frame_0900", "frame_1100", "frame_1300"];

/// The folder holds a complete sequence equal to the reference's: the
/// index lists the three frames, every frame's EXR and PNG and the contact
/// sheet are byte for byte the reference's, no temporary file.
fn assert_same_sequence(dir: &Path, reference: &Path) {
    let ix: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("index.json")).unwrap()).unwrap();
    let frames = ix["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    for (k, (f, stem)) in frames.iter().zip(STEMS).enumerate() {
        assert_eq!(f["index"], k);
        assert_eq!(f["exr"], format!("{stem}.exr"));
        for ext in ["exr", "png"] {
            let name = format!("{stem}.{ext}");
            assert!(
                read(&dir.join(&name)) == read(&reference.join(&name)),
                "{name} differs"
            );
        }
    }
    assert!(read(&dir.join("contact_sheet.png")) == read(&reference.join("contact_sheet.png")));
    let ref_ix: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(reference.join("index.json")).unwrap())
            .unwrap();
    assert_eq!(ix["contact_sheet"], ref_ix["contact_sheet"]);
    assert!(partials(dir).is_empty(), "{:?}", partials(dir));
}

fn kept_and_written(stdout: &str) -> (usize, usize) {
    (
        stdout.matches("is complete, kept").count(),
        stdout.lines().filter(|l| l.contains(": wrote ")).count(),
    )
}

#[test]
fn killed_sequence_resumes_from_its_finished_frames() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("ref");
    assert_eq!(
        kept_and_written(&run_ok(&sequence_args(&reference, "mwir"))),
        (0, 3)
    );
    let out = dir.path().join("out");

    // Killed between the files of the second frame: the first is complete,
    // the second has no JSON, there is no index.
    kill_at(&sequence_args(&out, "mwir"), "renamed-1@frame_1100.json");
    assert!(out.join("frame_0900.json").is_file());
    assert!(!out.join("frame_1100.json").exists());
    assert!(!out.join("index.json").exists());
    let stdout = run_ok(&sequence_args(&out, "mwir"));
    assert_eq!(kept_and_written(&stdout), (1, 2), "{stdout}");
    assert_same_sequence(&out, &reference);

    // Killed with every frame written and the index staged: the index of
    // the finished run is gone (the folder was being rewritten), the
    // temporary files are there; the next run renders nothing.
    kill_at(&sequence_args(&out, "mwir"), "staged@index.json");
    assert!(!out.join("index.json").exists());
    assert!(!partials(&out).is_empty());
    let stdout = run_ok(&sequence_args(&out, "mwir"));
    assert_eq!(kept_and_written(&stdout), (3, 0), "{stdout}");
    assert_same_sequence(&out, &reference);

    // --no-resume renders every frame; killed between the third frame's
    // files, the next run keeps the two it rewrote.
    let mut a = sequence_args(&out, "mwir");
    a.push("--no-resume".into());
    kill_at(&a, "renamed-2@frame_1300.json");
    let stdout = run_ok(&sequence_args(&out, "mwir"));
    assert_eq!(kept_and_written(&stdout), (2, 1), "{stdout}");
    assert_same_sequence(&out, &reference);
    let stdout = run_ok(&a);
    assert_eq!(kept_and_written(&stdout), (0, 3), "{stdout}");
    assert_same_sequence(&out, &reference);

    // Frames of another scene are not taken for this one's.
    let stdout = run_ok(&sequence_args(&out, "lwir"));
    assert_eq!(kept_and_written(&stdout), (0, 3), "{stdout}");
    let ix: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("index.json")).unwrap()).unwrap();
    assert_eq!(ix["band"], "lwir 8-14 um");
}
