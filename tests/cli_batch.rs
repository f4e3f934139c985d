//! `irsig batch` end to end on tiny frames: a spec expands into the
//! expected manifest; bad specs fail at `plan` with file, line and key; a
//! run killed with SIGKILL half-way resumes to the same frames, bit for
//! bit, as an uninterrupted run; shards partition the frames; status and
//! merge report what they should; the merged NetCDF stack holds every
//! frame's planes exactly.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use irsig::output::exr::read_exr;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

mod common;
use common::irsig_out as irsig;

/// A spec of 3 times × 2 wind speeds on the airfield at 24x24 px.
fn spec(dir: &Path) -> PathBuf {
    let scene = root().join("scenes/airfield/scene-constant.toml");
    let text = format!(
        r#"name = "t"
shards = 3

[[scene]]
path = "{}"
id = "af"
set = {{ "sensor.width_px" = 24, "sensor.height_px" = 24, "render.history_hours" = 6 }}

[time]
at = ["09:00", "12:00", "15:00"]

[[sweep]]
key = "weather.constant.wind_m_s"
values = [0.0, 6.0]
"#,
        scene.display()
    );
    let p = dir.join("spec.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn plan_expands_the_product_in_scene_major_order() {
    let t = tempfile::tempdir().unwrap();
    let sp = spec(t.path());
    let b = t.path().join("b");
    let (rc, out, err) = irsig(&["batch", "plan", s(&sp), "-o", s(&b)]);
    assert_eq!(rc, 0, "{err}");
    assert!(out.contains("6 frames"), "{out}");
    let batch = irsig::batch::Batch::open(&b).unwrap();
    let ids: Vec<&str> = batch.frames.iter().map(|f| f.id.as_str()).collect();
    assert_eq!(
        ids,
        [
            "af_wind_m_s-0.0_0900",
            "af_wind_m_s-0.0_1200",
            "af_wind_m_s-0.0_1500",
            "af_wind_m_s-6.0_0900",
            "af_wind_m_s-6.0_1200",
            "af_wind_m_s-6.0_1500"
        ]
    );
    assert_eq!(
        batch.info.dimensions,
        ["scene", "time", "weather.constant.wind_m_s"]
    );
    let f = &batch.frames[4];
    assert_eq!(f.local_time.as_deref(), Some("2001-08-08T12:00:00"));
    assert!(
        f.overrides
            .contains(&("weather.constant.wind_m_s".into(), "6.0".into()))
    );
    // Planning again into the same folder is a no-op; another spec is refused.
    assert_eq!(irsig(&["batch", "plan", s(&sp), "-o", s(&b)]).0, 0);
    let other = t.path().join("other.toml");
    std::fs::write(
        &other,
        std::fs::read_to_string(&sp)
            .unwrap()
            .replace("[0.0, 6.0]", "[1.0]"),
    )
    .unwrap();
    let (rc, _, err) = irsig(&["batch", "plan", s(&other), "-o", s(&b)]);
    assert_ne!(rc, 0);
    assert!(err.contains("already holds another batch"), "{err}");
}

#[test]
fn random_draws_are_reproducible_and_within_range() {
    let t = tempfile::tempdir().unwrap();
    let scene = root().join("scenes/airfield/scene-constant.toml");
    let text = format!(
        r#"[[scene]]
path = "{}"
[random]
count = 50
seed = 7
[[random.vary]]
key = "time"
range = ["08:00", "16:00"]
[[random.vary]]
key = "weather.constant.wind_m_s"
range = [0.5, 9.5]
[[random.vary]]
key = "weather.constant.cloud_fraction"
choice = [0.0, 0.5]
"#,
        scene.display()
    );
    std::fs::write(t.path().join("r.toml"), text).unwrap();
    let a = irsig::batch::plan(&t.path().join("r.toml")).unwrap();
    let b = irsig::batch::plan(&t.path().join("r.toml")).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.frames.len(), 50);
    let mut winds = Vec::new();
    for f in &a.frames {
        let t = f.local_time.as_deref().unwrap();
        assert!(
            ("2001-08-08T08:00:00"..="2001-08-08T16:00:00").contains(&t),
            "{t}"
        );
        let w: f64 = f.labels["weather.constant.wind_m_s"].parse().unwrap();
        assert!((0.5..=9.5).contains(&w), "{w}");
        winds.push(w);
        assert!(["0.0", "0.5"].contains(&f.labels["weather.constant.cloud_fraction"].as_str()));
    }
    // 50 uniform draws over [0.5, 9.5]: mean 5 ± 4 standard errors (0.37 each).
    let mean = winds.iter().sum::<f64>() / 50.0;
    assert!((mean - 5.0).abs() < 1.5, "{mean}");
}

#[test]
fn bad_specs_fail_at_plan_with_file_line_and_key() {
    let t = tempfile::tempdir().unwrap();
    let sp = spec(t.path());
    let good = std::fs::read_to_string(&sp).unwrap();
    let cases: &[(&str, &str, &str)] = &[
        // (what to replace, replacement, expected in the error)
        (
            "shards = 3",
            "shards = 3\nthreads = 4",
            "unknown field `threads`",
        ),
        (
            "values = [0.0, 6.0]",
            "values = []",
            "values = [] gives no frames",
        ),
        (
            "at = [\"09:00\", \"12:00\", \"15:00\"]",
            "at = []",
            "at = []",
        ),
        (
            "key = \"weather.constant.wind_m_s\"",
            "key = \"weather.constant.wind_speed\"",
            "wind_speed",
        ),
        (
            "values = [0.0, 6.0]",
            "values = [6.0, 6.0]",
            "would both write",
        ),
        (
            "at = [\"09:00\", \"12:00\", \"15:00\"]",
            "at = [\"25:00\"]",
            "25:00",
        ),
        // the bound of `irsig render --quicklook-min-span-k`
        (
            "shards = 3",
            "shards = 3\nquicklook_min_span_k = 1e9",
            "`quicklook_min_span_k` = 1e9 is out of range",
        ),
    ];
    for (from, to, want) in cases {
        let p = t.path().join("bad.toml");
        assert!(good.contains(from), "{from}");
        std::fs::write(&p, good.replace(from, to)).unwrap();
        let (rc, _, err) = irsig(&["batch", "plan", s(&p), "-o", s(&t.path().join("x"))]);
        assert_ne!(rc, 0, "{to}");
        assert!(err.contains(want), "{to}: {err}");
        assert!(err.contains("bad.toml"), "{to}: {err}");
        // A line number: `bad.toml:<line>`.
        assert!(
            err.contains("bad.toml:") || err.contains("line "),
            "{to}: no line in {err}"
        );
    }
}

/// Frame files of a batch folder (name → bytes), without temp files.
fn frame_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "exr"))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn a_killed_run_resumes_to_the_same_frames_and_merges() {
    let t = tempfile::tempdir().unwrap();
    let sp = spec(t.path());
    let (a, b) = (t.path().join("a"), t.path().join("b"));
    for d in [&a, &b] {
        assert_eq!(irsig(&["batch", "plan", s(&sp), "-o", s(d)]).0, 0);
    }
    // Uninterrupted, in three shards with different thread counts.
    for (sh, th) in [("0/3", "1"), ("1/3", "2"), ("2/3", "1")] {
        let (rc, out, err) = irsig(&["batch", "run", s(&a), "--shard", sh, "--threads", th]);
        assert_eq!(rc, 0, "{out}{err}");
        assert!(out.contains("2 frames: 2 rendered"), "{out}");
    }
    // Killed with SIGKILL once the first frame is complete, then resumed.
    let mut child = Command::new(env!("CARGO_BIN_EXE_irsig"))
        .args(["batch", "run", s(&b), "--threads", "2"])
        .stderr(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let first = b.join("frames/af_wind_m_s-0.0_0900.json");
    let t0 = Instant::now();
    while !first.exists() && t0.elapsed() < Duration::from_secs(300) {
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let st = irsig::batch::Batch::open(&b).unwrap().status();
    assert!(st.done >= 1 && st.done < 6, "{st:?}");
    // Every frame is complete or absent: no JSON without its EXR.
    let (rc, out, _) = irsig(&["batch", "status", s(&b)]);
    assert_eq!(rc, 1, "{out}");
    assert!(out.contains(&format!("{} done", st.done)), "{out}");
    let (rc, out, err) = irsig(&["batch", "run", s(&b), "--threads", "1"]);
    assert_eq!(rc, 0, "{err}");
    assert!(
        out.contains(&format!(
            "{} rendered, {} done already",
            6 - st.done,
            st.done
        )),
        "{out}"
    );
    let (fa, fb) = (frame_files(&a), frame_files(&b));
    assert_eq!(fa.len(), 6);
    assert!(fa == fb, "frames differ after the resume");
    // No temp files left in frames/.
    let stray: Vec<_> = std::fs::read_dir(b.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".irsig-partial"))
        .collect();
    // (the killed write's temporary file is removed by the resumed run)
    assert!(stray.is_empty(), "{stray:?}");

    // Merge: the stack holds every frame's planes exactly.
    let (rc, out, err) = irsig(&["batch", "merge", s(&b)]);
    assert_eq!(rc, 0, "{err}");
    assert!(out.contains("6 frames of 24x24 px"), "{out}");
    // The contact sheet is drawn as a single render's quicklook: RGB, the
    // frames above a colour bar, the stretch widened to 2 K (issue 32).
    let ix: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(b.join("merged/index.json")).unwrap())
            .unwrap();
    let stretch = ix["contact_sheet_stretch"].as_str().unwrap();
    assert!(
        stretch.contains("at least 2 K") && stretch.contains("colour bar"),
        "{stretch}"
    );
    let dec = png::Decoder::new(std::fs::File::open(b.join("merged/contact_sheet.png")).unwrap());
    let r = dec.read_info().unwrap();
    assert_eq!(r.info().color_type, png::ColorType::Rgb);
    // 6 frames: 3 columns x 2 rows of 24 px with 4-px gaps, then the bar
    assert!(r.info().height > 2 * 24 + 4 + 10, "{}", r.info().height);
    let nc = netcdf::open(b.join("merged/stack.nc")).unwrap();
    let batch = irsig::batch::Batch::open(&b).unwrap();
    let v = nc.variable("apparent_temperature").unwrap();
    assert_eq!(
        v.attribute_value("units").unwrap().unwrap(),
        netcdf::AttributeValue::Str("K".into())
    );
    // The product (1 scene × 3 times × 2 winds) is the stack's dimensions.
    let dims: Vec<(String, usize)> = v.dimensions().iter().map(|d| (d.name(), d.len())).collect();
    let want_dims = [
        ("scene", 1),
        ("time", 3),
        ("weather.constant.wind_m_s", 2),
        ("y", 24),
        ("x", 24),
    ];
    assert_eq!(
        dims,
        want_dims.map(|(n, l)| (n.to_string(), l)).to_vec(),
        "{dims:?}"
    );
    let frame_of: Vec<i32> = nc.variable("frame").unwrap().get_values(..).unwrap();
    for (k, f) in batch.frames.iter().enumerate() {
        let (_, _, chans) = read_exr(&b.join(&f.outputs.exr)).unwrap();
        let want = &chans
            .iter()
            .find(|c| c.0 == "apparent_temperature")
            .unwrap()
            .1;
        // The manifest runs the times innermost; the stack has (time, wind).
        let (t, w) = (k % 3, k / 3);
        assert_eq!(frame_of[t * 2 + w], k as i32);
        let got: Vec<f32> = v
            .get_values([0..1, t..t + 1, w..w + 1, 0..24, 0..24])
            .unwrap();
        assert!(
            got.iter()
                .zip(want)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "frame {k}"
        );
    }
    // The resumed batch's stack equals the uninterrupted one's, bit for bit.
    assert_eq!(irsig(&["batch", "merge", s(&a)]).0, 0);
    let nc_a = netcdf::open(a.join("merged/stack.nc")).unwrap();
    for var in nc_a.variables() {
        // The planes: (scene, time, wind, y, x).
        if var.dimensions().len() == 5 {
            let x: Vec<f32> = var.get_values(..).unwrap();
            let y: Vec<f32> = nc.variable(&var.name()).unwrap().get_values(..).unwrap();
            let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            assert!(bits(&x) == bits(&y), "{}", var.name());
        }
    }
    let wind: Vec<f64> = nc
        .variable("weather.constant.wind_m_s")
        .unwrap()
        .get_values(..)
        .unwrap();
    assert_eq!(wind, [0.0, 6.0]);
    let local: Vec<f64> = nc.variable("time").unwrap().get_values(..).unwrap();
    // 2001-08-08 09:00, 12:00, 15:00 local, as seconds since 1970.
    assert_eq!(local, [997261200.0, 997272000.0, 997282800.0]);
    // The class planes carry CF flags; index.json the material table.
    let attr = |var: &str, a: &str| {
        nc.variable(var)
            .unwrap()
            .attribute_value(a)
            .unwrap_or_else(|| panic!("{var} has no {a}"))
            .unwrap()
    };
    assert_eq!(
        attr("case", "flag_meanings"),
        netcdf::AttributeValue::Str(
            "outside_scene diffuse specular_sky specular_background sky".into()
        )
    );
    assert_eq!(
        attr("case", "flag_values"),
        netcdf::AttributeValue::Floats(vec![0.0, 1.0, 2.0, 3.0, 4.0])
    );
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(b.join("merged/index.json")).unwrap())
            .unwrap();
    assert_eq!(index["frames"].as_array().unwrap().len(), 6);
    assert_eq!(
        index["stack_dimensions"],
        serde_json::json!(["scene", "time", "weather.constant.wind_m_s"])
    );
    let table = index["materials"].as_array().expect("one material table");
    assert!(table.len() >= 2, "{table:?}");
    let fj: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(b.join(&batch.frames[0].outputs.json)).unwrap(),
    )
    .unwrap();
    assert_eq!(index["materials"], fj["materials"]);
    assert_eq!(index["materials_by_scene"]["af"], fj["materials"]);
    let mut want_values = vec![-1.0f32];
    let mut want_words = vec!["none".to_string()];
    for m in table {
        want_values.push(m["index"].as_i64().unwrap() as f32);
        want_words.push(m["name"].as_str().unwrap().replace(' ', "_"));
    }
    assert_eq!(
        attr("material", "flag_values"),
        netcdf::AttributeValue::Floats(want_values)
    );
    assert_eq!(
        attr("material", "flag_meanings"),
        netcdf::AttributeValue::Str(want_words.join(" "))
    );
    // Wind cools the sunlit surfaces: the 12:00 frame's mean apparent
    // temperature is lower at 6 m/s than at calm.
    let mean = |i: usize| {
        index["frames"][i]["apparent_temperature_k"]["mean"]
            .as_f64()
            .unwrap()
    };
    assert!(mean(4) < mean(1), "{} {}", mean(4), mean(1));
}

#[test]
fn merge_refuses_an_unfinished_batch_and_status_names_failures() {
    let t = tempfile::tempdir().unwrap();
    let sp = spec(t.path());
    let b = t.path().join("b");
    assert_eq!(irsig(&["batch", "plan", s(&sp), "-o", s(&b)]).0, 0);
    let (rc, _, err) = irsig(&["batch", "merge", s(&b)]);
    assert_ne!(rc, 0);
    assert!(err.contains("0 of 6 frames are done"), "{err}");
    // A scene broken after planning: every frame fails, is recorded, and
    // the run exits 1.
    let mut batch = irsig::batch::Batch::open(&b).unwrap();
    let broken = t.path().join("broken.toml");
    std::fs::write(&broken, "[site]\nlatitude_deg = 95\n").unwrap();
    for f in &mut batch.frames {
        f.scene = broken.clone();
    }
    let text: String = batch
        .frames
        .iter()
        .map(|f| serde_json::to_string(f).unwrap() + "\n")
        .collect();
    std::fs::write(b.join("manifest.jsonl"), text).unwrap();
    let (rc, out, _) = irsig(&["batch", "run", s(&b), "--shard", "0/3"]);
    assert_eq!(rc, 1, "{out}");
    assert!(out.contains("2 failed"), "{out}");
    let (rc, out, _) = irsig(&["batch", "status", s(&b)]);
    assert_eq!(rc, 1);
    assert!(out.contains("2 failed, 4 missing"), "{out}");
    assert!(out.contains("broken.toml"), "{out}");
}

#[test]
fn slurm_scripts_map_array_tasks_to_shards() {
    let t = tempfile::tempdir().unwrap();
    let sp = spec(t.path());
    let b = t.path().join("b");
    assert_eq!(irsig(&["batch", "plan", s(&sp), "-o", s(&b)]).0, 0);
    let (rc, out, err) = irsig(&[
        "batch",
        "slurm",
        s(&b),
        "--partition",
        "cpu",
        "--time",
        "00:30:00",
        "--cpus-per-task",
        "4",
        "--max-running",
        "2",
    ]);
    assert_eq!(rc, 0, "{err}");
    assert!(out.contains("3 array tasks"), "{out}");
    let array = std::fs::read_to_string(b.join("slurm/array.sh")).unwrap();
    for want in [
        "#SBATCH --array=0-2%2",
        "#SBATCH --cpus-per-task=4",
        "#SBATCH --partition=cpu",
        "#SBATCH --time=00:30:00",
        "--shard \"${SLURM_ARRAY_TASK_ID}/3\"",
        "--threads \"${SLURM_CPUS_PER_TASK:-4}\"",
    ] {
        assert!(array.contains(want), "{want} not in\n{array}");
    }
    let submit = std::fs::read_to_string(b.join("slurm/submit.sh")).unwrap();
    assert!(submit.contains("--dependency=afterok:"), "{submit}");
    let (rc, _, err) = irsig(&["batch", "slurm", s(&b), "--partition", "a b"]);
    assert_ne!(rc, 0);
    assert!(err.contains("without spaces"), "{err}");
}

#[test]
fn the_docs_specs_plan_as_written() {
    // Each ```toml block of docs/batch.md, saved beside a `scenes` link so
    // that its `../scenes/...` paths resolve as in the repository.
    let doc = std::fs::read_to_string(root().join("docs/batch.md")).unwrap();
    let blocks: Vec<&str> = doc
        .split("```toml\n")
        .skip(1)
        .map(|b| b.split("```").next().unwrap())
        .collect();
    assert_eq!(blocks.len(), 3, "docs/batch.md should hold three specs");
    let t = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(root().join("scenes"), t.path().join("scenes")).unwrap();
    std::fs::create_dir(t.path().join("docs")).unwrap();
    let mut counts = Vec::new();
    for (i, b) in blocks.iter().enumerate() {
        let p = t.path().join("docs").join(format!("spec{i}.toml"));
        std::fs::write(&p, b).unwrap();
        let plan = irsig::batch::plan(&p).unwrap_or_else(|e| panic!("spec {i}: {e:#}\n{b}"));
        counts.push(plan.frames.len());
    }
    // Figs. 12-13: 8 times x 4 winds; Fig. 14: 6 zeniths; training: 2 x 2500.
    assert_eq!(counts, [32, 6, 5000]);
}

// The stack's product layout and CF flags (batch::merge).
use irsig::batch::merge::{MaterialEntry, flag_word, material_flags, product_layout};

fn job(index: usize, labels: &[(&str, &str)], draw: Option<usize>) -> irsig::batch::FrameJob {
    irsig::batch::FrameJob {
        id: format!("f{index}"),
        index,
        scene: PathBuf::from("s.toml"),
        overrides: Vec::new(),
        local_time: None,
        labels: labels
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        draw,
        outputs: irsig::batch::Outputs {
            exr: "a".into(),
            png: "b".into(),
            json: "c".into(),
        },
    }
}

/// A full product (in any frame order) is regular: its axes' values in
/// order of first appearance and each frame's row-major place; a missing
/// or repeated combination makes it irregular (flat `frame` stack).
#[test]
fn product_layout_finds_regular_products_only() {
    let axes = [
        "scene".to_string(),
        "time".into(),
        "k".into(),
        "draw".into(),
    ];
    let mut frames = Vec::new();
    for k in ["1", "2"] {
        for d in 0..2 {
            for t in ["09", "12", "15"] {
                let i = frames.len();
                frames.push(job(i, &[("scene", "a"), ("time", t), ("k", k)], Some(d)));
            }
        }
    }
    let p = product_layout(&axes, &frames).expect("regular");
    assert_eq!(p.axes[1].1, ["09", "12", "15"]);
    assert_eq!(p.axes[2].1, ["1", "2"]);
    assert_eq!(p.size(), 12);
    // Frame 4: k=1, draw 1, time 12 -> (0, 1, 0, 1) -> 1*4 + 0*2 + 1.
    assert_eq!(p.positions[4], [0, 1, 0, 1]);
    assert_eq!(p.offset(&p.positions[4]), 5);
    let mut offsets: Vec<usize> = p.positions.iter().map(|q| p.offset(q)).collect();
    offsets.sort_unstable();
    assert_eq!(offsets, (0..12).collect::<Vec<_>>());
    // One frame fewer, or one repeated: not a product.
    assert!(product_layout(&axes, &frames[..11]).is_none());
    let mut dup = frames.clone();
    dup[11] = dup[10].clone();
    assert!(product_layout(&axes, &dup).is_none());
    // A frame without the draw an axis asks for: not a product.
    let mut nodraw = frames;
    nodraw[0].draw = None;
    assert!(product_layout(&axes, &nodraw).is_none());
    assert!(product_layout(&[], &nodraw).is_none());
}

#[test]
fn flag_words_and_material_flags() {
    assert_eq!(flag_word("dry asphalt (old)"), "dry_asphalt__old_");
    let t = vec![
        MaterialEntry {
            index: 0,
            name: "grass".into(),
            class: 1,
        },
        MaterialEntry {
            index: 1,
            name: "dry concrete".into(),
            class: 2,
        },
    ];
    let (v, m) = material_flags(&t);
    assert_eq!(v, [-1.0, 0.0, 1.0]);
    assert_eq!(m, "none grass dry_concrete");
}

/// Issue 32: a batch spec sweeps a key inside an `[[object]]` entry (by
/// name or index, a key the entry does not write): the plan loads every
/// value, and each frame's overrides place the object where the value
/// says.
#[test]
fn a_spec_sweeps_an_objects_position() {
    let t = tempfile::tempdir().unwrap();
    let scene = root().join("scenes/terrain-km/scene.toml");
    let text = format!(
        r#"name = "pos"

[[scene]]
path = "{}"
id = "km"
set = {{ "sensor.width_px" = 8, "sensor.height_px" = 8 }}

[[sweep]]
key = "object.vehicle.translate_m"
values = [[0, 0, 0], [25, 0, 0]]
"#,
        scene.display()
    );
    let sp = t.path().join("spec.toml");
    std::fs::write(&sp, text).unwrap();
    let plan = irsig::batch::plan(&sp).unwrap();
    assert_eq!(plan.frames.len(), 2);
    let min_x: Vec<f64> = plan
        .frames
        .iter()
        .map(|f| {
            assert!(
                f.overrides
                    .iter()
                    .any(|(k, _)| k == "object.vehicle.translate_m"),
                "{:?}",
                f.overrides
            );
            let s = irsig::scene::load_with_overrides(&f.scene, &f.overrides).unwrap();
            s.objects
                .iter()
                .find(|o| o.name == "vehicle#1")
                .unwrap()
                .bounds_min_m[0]
        })
        .collect();
    assert!((min_x[1] - min_x[0] - 25.0).abs() < 1e-3, "{min_x:?}");
    // an entry that does not exist: refused at plan, naming the spec
    std::fs::write(
        &sp,
        std::fs::read_to_string(&sp)
            .unwrap()
            .replace("object.vehicle.", "object.truck."),
    )
    .unwrap();
    let e = format!("{:#}", irsig::batch::plan(&sp).unwrap_err());
    assert!(
        e.contains("spec.toml") && e.contains("no entry of `object` is named `truck`"),
        "{e}"
    );
}
