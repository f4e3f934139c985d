//! `irsig` as a batch job and an installed program sees it: a binary
//! copied away from the source tree renders (the atmosphere tables are
//! embedded; `IRSIG_DATA` adds tables), the output path is checked before
//! any work, progress goes to stderr as plain lines off a terminal (none
//! with `-q`), `--stats` puts JSON alone on stdout, a closed pipe ends the
//! program quietly, `--version` names the commit and Embree, and the shell
//! completions and man page are generated.

mod common;
use common::succeed;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn irsig() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_irsig"));
    c.env_remove("IRSIG_DATA");
    c
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn plate() -> PathBuf {
    root().join("scenes/plate/scene.toml")
}

const SMALL: [&str; 4] = [
    "--set",
    "sensor.width_px=16",
    "--set",
    "sensor.height_px=16",
];

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let t = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &t);
        } else {
            std::fs::copy(e.path(), t).unwrap();
        }
    }
}

/// The binary copied into an empty folder (no source tree beside it)
/// renders a scene there: the atmosphere tables come from the binary.
#[test]
fn a_copied_binary_renders_from_any_folder() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("irsig");
    std::fs::copy(env!("CARGO_BIN_EXE_irsig"), &bin).unwrap();
    copy_dir(&root().join("scenes"), &dir.path().join("scenes"));
    succeed(
        Command::new(&bin)
            .current_dir(dir.path())
            .env_remove("IRSIG_DATA")
            .args(["render", "scenes/plate/scene.toml", "-o", "out/p.exr"])
            .args(SMALL)
            .args(["--set", "atmosphere.model=\"mid-latitude-summer\""]),
    );
    assert!(dir.path().join("out/p.exr").is_file());
    let list = Command::new(&bin)
        .current_dir(dir.path())
        .env_remove("IRSIG_DATA")
        .args(["atmos", "list"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&list.stdout);
    for name in ["mls", "mlw", "sas", "saw", "tropical", "us1976"] {
        assert!(text.contains(name), "{name} missing: {text}");
    }
    assert!(text.contains("embedded in the irsig binary"), "{text}");
}

/// `IRSIG_DATA/atmos` adds tables to the embedded ones; a folder that
/// cannot be read is an error naming it and the variable.
#[test]
fn irsig_data_adds_atmosphere_tables() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("atmos")).unwrap();
    std::fs::copy(
        root().join("data/atmos/mlw.atm.gz"),
        dir.path().join("atmos/mywinter.atm.gz"),
    )
    .unwrap();
    let out = irsig()
        .env("IRSIG_DATA", dir.path())
        .args(["atmos", "list"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("mywinter"), "{text}");
    assert!(text.contains("mywinter.atm.gz") && text.contains("us1976"));
    let show = |data: &Path, name: &str| {
        irsig()
            .env("IRSIG_DATA", data)
            .args(["atmos", "show", name, "--altitude", "1", "--zenith", "0"])
            .output()
            .unwrap()
    };
    let a = show(dir.path(), "mywinter");
    let b = show(dir.path(), "mlw");
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    // The same table under another name gives the same numbers.
    let numbers = |o: &std::process::Output| {
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter(|l| !l.starts_with("atmosphere") && !l.starts_with("table"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(numbers(&a), numbers(&b));
    let missing = dir.path().join("nothing");
    let e = show(&missing, "mls");
    let err = String::from_utf8_lossy(&e.stderr);
    assert!(
        !e.status.success() && err.contains("IRSIG_DATA") && err.contains("nothing"),
        "{err}"
    );
}

/// A bad output path is refused before the scene is even loaded.
#[test]
fn the_output_path_is_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("x.exr");
    std::fs::create_dir(&folder).unwrap();
    let file = dir.path().join("plain");
    std::fs::write(&file, "not a folder").unwrap();
    let cases = [
        (folder.clone(), "is a folder"),
        (file.join("y.exr"), "is not a folder"),
    ];
    for (path, want) in cases {
        let out = irsig()
            .args(["render", plate().to_str().unwrap(), "-o"])
            .arg(&path)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(want), "{err}");
        assert!(
            !err.contains("loading scene") && !err.contains("panicked"),
            "{err}"
        );
    }
    let out = irsig()
        .args(["sequence", plate().to_str().unwrap(), "-o"])
        .arg(file.join("seq"))
        .args(["--from", "10:00", "--to", "11:00", "--step", "1h"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("is not a folder"),
        "{err}"
    );
}

/// Off a terminal, progress is plain lines on stderr (stdout keeps only
/// the result); `-q` silences them; `--stats` prints JSON alone.
#[test]
fn batch_progress_quiet_and_stats() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("p.exr");
    let run = |extra: &[&str]| {
        let out = succeed(
            irsig()
                .args(["render", plate().to_str().unwrap(), "-o"])
                .arg(&exr)
                .args(SMALL)
                .args(extra),
        );
        (
            String::from_utf8(out.stdout).unwrap(),
            String::from_utf8(out.stderr).unwrap(),
        )
    };
    let (stdout, stderr) = run(&[]);
    assert!(
        stdout.starts_with("wrote ") && stdout.lines().count() == 1,
        "{stdout}"
    );
    for want in [
        "irsig: loading scene",
        "tracing (blocks)",
        "(100 %)",
        "radiometry",
    ] {
        assert!(stderr.contains(want), "{want} missing from {stderr}");
    }
    assert!(
        !stderr.contains('\r') && !stderr.contains("\x1b["),
        "{stderr:?}"
    );
    let (stdout, stderr) = run(&["-q"]);
    assert!(stderr.is_empty(), "{stderr}");
    assert!(stdout.starts_with("wrote "));
    let (stdout, stderr) = run(&["--stats"]);
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("stdout is JSON alone");
    assert!(v["primary_rays"].as_u64().unwrap() >= 256);
    assert!(stderr.contains("wrote "), "{stderr}");
}

/// `irsig atmos show --csv | head -0`: the reader is gone before the
/// first line (the table takes ~0.1 s to load, so the pipe is closed before
/// anything is written); the program ends by SIGPIPE with nothing on
/// stderr (no panic message).
#[test]
fn a_closed_pipe_ends_quietly() {
    let mut child = irsig()
        .args([
            "atmos",
            "show",
            "mls",
            "--altitude",
            "1",
            "--zenith",
            "0",
            "--csv",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.is_empty(), "{err}");
    use std::os::unix::process::ExitStatusExt;
    assert_eq!(out.status.signal(), Some(13), "{:?}", out.status);
}

#[test]
fn version_completions_and_man_page() {
    let out = irsig().arg("--version").output().unwrap();
    let v = String::from_utf8_lossy(&out.stdout);
    assert!(
        v.starts_with(&format!("irsig {}", env!("CARGO_PKG_VERSION"))),
        "{v}"
    );
    assert!(
        v.contains("commit ") && (v.contains("Embree 3.") || v.contains("Embree 4.")),
        "{v}"
    );
    let commit = v
        .split("commit ")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap();
    let head = Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .current_dir(root())
        .output();
    if let Some(h) = head.ok().filter(|h| h.status.success()) {
        assert_eq!(commit, String::from_utf8_lossy(&h.stdout).trim());
    }
    for shell in ["bash", "zsh", "fish"] {
        let out = irsig().args(["completions", shell]).output().unwrap();
        let s = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && s.contains("render") && s.contains("sequence"),
            "{shell}"
        );
    }
    let out = irsig().arg("man").output().unwrap();
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(s.starts_with(".ie") || s.contains(".TH irsig 1"), "{s}");
    assert!(s.contains("render") && s.contains("\\-\\-quiet"), "{s}");
}

/// Every `.md` file that a `--help` text, a doc page, the README or a
/// source comment names exists in the repository (nothing cites a design
/// note kept elsewhere).
#[test]
fn cited_documents_are_in_the_repository() {
    let mut texts: Vec<(String, String)> = Vec::new();
    let cmds = [
        "render",
        "sequence",
        "sweep",
        "probe",
        "check",
        "crosscheck",
        "sun",
        "therm",
        "atmos",
        "bench",
        "batch",
    ];
    for c in cmds {
        let out = irsig().args([c, "--help"]).output().unwrap();
        if out.status.success() {
            texts.push((
                format!("irsig {c} --help"),
                String::from_utf8_lossy(&out.stdout).into(),
            ));
        }
    }
    let mut files = vec![root().join("README.md"), root().join("BENCHMARKS.md")];
    for dir in ["docs", "src", "tools"] {
        let mut stack = vec![root().join(dir)];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    // not hidden folders (a git-ignored tools/.venv)
                    if !e.file_name().to_string_lossy().starts_with('.') {
                        stack.push(p);
                    }
                } else if p
                    .extension()
                    .is_some_and(|x| x == "md" || x == "rs" || x == "py")
                {
                    files.push(p);
                }
            }
        }
    }
    for f in files {
        if let Ok(t) = std::fs::read_to_string(&f) {
            texts.push((f.display().to_string(), t));
        }
    }
    let mut missing = Vec::new();
    for (what, text) in &texts {
        for word in text.split(|c: char| c.is_whitespace() || "()[]`'\",;:".contains(c)) {
            let Some(name) = word.strip_suffix(".md").filter(|n| !n.is_empty()) else {
                continue;
            };
            let file = Path::new(name)
                .file_name()
                .map(|f| format!("{}.md", f.to_string_lossy()))
                .unwrap();
            let found = [
                root().to_path_buf(),
                root().join("docs"),
                root().join("tools/lowtran"),
            ]
            .iter()
            .any(|d| d.join(&file).is_file())
                || root().join(format!("{name}.md")).is_file();
            if !found {
                missing.push(format!("{what}: {word}"));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "documents cited but not in the repository: {missing:#?}"
    );
}

// Progress lines off a terminal (cli::log).
use irsig::cli::log::ProgressLines;
use irsig::render::{Progress, Stage};

/// What `render_with` reports for a frame of `bands` bands: per band,
/// the trace blocks, then the thermal and radiometry samples in chunks.
fn frame_reports(bands: u64) -> Vec<Progress> {
    let (blocks, samples, chunk) = (16 * bands, 262_144 * bands, 1024);
    let mut v = Vec::new();
    let mut d = [0u64; 3];
    for _ in 0..bands {
        for (i, stage, total, step) in [
            (0, Stage::Trace, blocks, 1),
            (1, Stage::Thermal, samples, chunk),
            (2, Stage::Radiometry, samples, chunk),
        ] {
            for _ in 0..(total / bands / step) {
                d[i] += step;
                v.push(Progress {
                    stage,
                    done: d[i],
                    total,
                });
            }
        }
    }
    v
}

/// A 2048² frame (16 bands): three start lines and ten tenth lines per
/// stage, nothing else (the issue counted 826 lines before).
#[test]
fn one_line_per_stage_start_and_tenth() {
    let mut p = ProgressLines::new(false);
    let lines: Vec<String> = frame_reports(16)
        .into_iter()
        .flat_map(|r| p.lines(r))
        .collect();
    assert_eq!(lines.len(), 3 + 30, "{lines:#?}");
    assert_eq!(lines.iter().filter(|l| l.contains("started")).count(), 3);
    for stage in [Stage::Trace, Stage::Thermal, Stage::Radiometry] {
        let name = irsig::cli::log::stage_name(stage);
        let pct: Vec<&str> = lines
            .iter()
            .filter(|l| l.starts_with(name) && l.ends_with("%)"))
            .map(|l| l.rsplit('(').next().unwrap())
            .collect();
        let want: Vec<String> = (1..=10).map(|t| format!("{} %)", t * 10)).collect();
        assert_eq!(pct, want, "{name}: {lines:#?}");
    }
}

/// Out-of-order reports never move a stage back or repeat a tenth;
/// `-v` adds a line per return to a stage (16 bands: 15 returns each).
#[test]
fn out_of_order_and_verbose() {
    let mut p = ProgressLines::new(false);
    let at = |done| Progress {
        stage: Stage::Thermal,
        done,
        total: 100,
    };
    assert_eq!(p.lines(at(25)).len(), 2); // started + 20 %
    assert!(p.lines(at(21)).is_empty());
    assert!(p.lines(at(29)).is_empty());
    assert_eq!(
        p.lines(at(30)),
        vec!["temperatures (samples) 30/100 (30 %)"]
    );
    let mut v = ProgressLines::new(true);
    let n = frame_reports(16)
        .into_iter()
        .flat_map(|r| v.lines(r))
        .count();
    assert_eq!(n, 3 + 30 + 3 * 15);
}
