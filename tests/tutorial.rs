//! docs/tutorial.md runs (issue 32 item 10): its fenced blocks, in order,
//! in a scratch folder that sees the repository's `scenes/` and `tests/`
//! (the tutorial's commands are written from the repository root) —
//! ```` ```toml file=PATH ```` blocks are written to PATH, ```` ```sh ````
//! blocks run in bash (`set -euo pipefail`) with this build's `irsig`
//! first on the PATH, ```` ```python ```` blocks run with the project's
//! `.venv/bin/python` (skipped, saying so, when there is no `.venv`). Then
//! the outputs the page promises are checked: the GeoTIFF set, the target
//! standing where `irsig check` says, and three sweep frames in which the
//! target moves.

use std::path::PathBuf;
use std::process::Command;

/// One fenced block of the page: its info string and its text, with the
/// line it starts on.
struct Block {
    info: String,
    text: String,
    line: usize,
}

fn blocks(md: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, l) in md.lines().enumerate() {
        match (&mut open, l.strip_prefix("```")) {
            (None, Some(info)) => {
                open = Some(Block {
                    info: info.trim().to_string(),
                    text: String::new(),
                    line: i + 1,
                })
            }
            (Some(_), Some(_)) => out.push(open.take().unwrap()),
            (Some(b), None) => {
                b.text.push_str(l);
                b.text.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(
        open.is_none(),
        "docs/tutorial.md: a fenced block is not closed"
    );
    out
}

fn run(what: &str, c: &mut Command) {
    let out = c.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n--- stdout\n{}\n--- stderr\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_tutorial_runs_end_to_end() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let md = std::fs::read_to_string(root.join("docs/tutorial.md")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for sub in ["scenes", "tests"] {
        std::os::unix::fs::symlink(root.join(sub), d.join(sub)).unwrap();
    }
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_irsig"));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let python = root.join(".venv/bin/python");
    let (mut sh, mut toml, mut py) = (0, 0, 0);
    for b in blocks(&md) {
        let what = format!("docs/tutorial.md:{} ({})", b.line, b.info);
        let lang = b.info.split_whitespace().next().unwrap_or("");
        match lang {
            "sh" => {
                sh += 1;
                run(
                    &what,
                    Command::new("bash")
                        .args(["-euo", "pipefail", "-c", &b.text])
                        .current_dir(d)
                        .env("PATH", &path),
                );
            }
            "toml" => {
                let file = b
                    .info
                    .split_whitespace()
                    .find_map(|w| w.strip_prefix("file="))
                    .unwrap_or_else(|| panic!("{what}: a toml block needs file=PATH"));
                toml += 1;
                std::fs::write(d.join(file), &b.text).unwrap();
            }
            "python" => {
                py += 1;
                if !python.exists() {
                    eprintln!(
                        "{what}: skipped: no {} (bash scripts/setup.sh makes it)",
                        python.display()
                    );
                    continue;
                }
                run(
                    &what,
                    Command::new(&python)
                        .args(["-c", &b.text])
                        .current_dir(d)
                        .env("PATH", &path),
                );
            }
            other => panic!("{what}: unknown block type `{other}` (sh, toml file=..., python)"),
        }
    }
    assert_eq!((sh, toml, py), (4, 1, 1), "the page's steps changed");

    // What the page promises.
    let site = d.join("mysite");
    for f in [
        "noon.tif",
        "noon_geo.tif",
        "noon_map.tif",
        "noon.png",
        "noon.json",
    ] {
        assert!(site.join("out").join(f).is_file(), "no out/{f}");
    }
    let check: serde_json::Value =
        serde_json::from_slice(&std::fs::read(site.join("check.json")).unwrap()).unwrap();
    let target = check["object_list"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["name"] == "target")
        .unwrap();
    let base: Vec<f64> = (0..3)
        .map(|k| target["base_centre_m"][k].as_f64().unwrap())
        .collect();
    assert!(
        (base[0] - 30.0).abs() < 0.01 && (base[1] + 20.0).abs() < 0.01,
        "{base:?}"
    );
    // Stood on the ground: the terrain here lies a few metres from z = 0,
    // not at the 0 the scene's translate_m gives.
    assert!(base[2].abs() > 0.1 && base[2].abs() < 15.0, "{base:?}");
    let ix: serde_json::Value =
        serde_json::from_slice(&std::fs::read(site.join("sweep/index.json")).unwrap()).unwrap();
    let frames = ix["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    // The target (painted_steel_roof) moves east by 30 m (9 px) a frame.
    let steel = {
        let s = irsig::scene::load(&site.join("scene.toml")).unwrap();
        s.material_index("painted_steel_roof").unwrap() as f32
    };
    let cols: Vec<f64> = frames
        .iter()
        .map(|f| {
            let exr = site.join("sweep").join(f["exr"].as_str().unwrap());
            let (w, _, ch) = irsig::output::exr::read_exr(&exr).unwrap();
            let m = &ch.iter().find(|(n, _)| n == "material").unwrap().1;
            let xs: Vec<f64> = (0..m.len())
                .filter(|&i| m[i] == steel)
                .map(|i| (i % w as usize) as f64)
                .collect();
            assert!(!xs.is_empty(), "{}: no target pixels", exr.display());
            xs.iter().sum::<f64>() / xs.len() as f64
        })
        .collect();
    for k in 1..3 {
        let step = cols[k] - cols[k - 1];
        assert!((7.0..=11.0).contains(&step), "target columns {cols:?}");
    }
}
