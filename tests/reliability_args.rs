//! Regression tests of issue 33 (docs/reliability.md): what an independent
//! campaign found outside the file parsers. Each test fails without its
//! fix: arguments that panicked or aborted (`irsig therm --step 1e-9`), a
//! batch folder name that ran a command from the generated Slurm script,
//! glTF buffer URIs that read files outside the model's folder, devices and
//! FIFOs read as files, atmosphere tables out of physics, two `batch run`s
//! rendering every frame twice, and the DEM's self-contradicting message.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/");

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn irsig(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

/// Runs irsig with a time limit; (exit code, stderr). A run past the limit
/// is killed and fails the test (a hang).
fn irsig_within(args: &[&str], limit: Duration) -> (i32, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_irsig"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    loop {
        if let Some(st) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (st.code().unwrap_or(-1), err);
        }
        if t0.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("irsig {args:?} ran past {limit:?} (a hang)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// An error exit (1), not a panic (101) or an abort (134), with a message.
fn refused(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        !err.contains("panicked") && !err.contains("memory allocation"),
        "{err}"
    );
    err
}

const MATS: &str = r#"
[material.asphalt]
density_kg_m3 = 2100.0
specific_heat_j_kgk = 920.0
conductivity_w_mk = 0.75
thickness_m = 0.3
solar_absorptivity = 0.9
thermal_emissivity = 0.93
back = { deep_ground = { temp_c = 16.85 } }
"#;

fn therm_args<'a>(mats: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec![
        "therm",
        "--materials",
        mats,
        "--material",
        "asphalt",
        "--weather",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/tmy3_723170_greensboro_jun18-22.csv"
        ),
        "--lat",
        "36.1",
        "--lon",
        "-79.95",
        "--from",
        "1989-06-19T05:00:00Z",
        "--to",
        "1989-06-19T08:00:00Z",
        "--csv",
    ];
    v.extend_from_slice(extra);
    v
}

/// Finding 1: `--step 1e-9` aborted allocating 403 TB, `1e-320` panicked
/// with `capacity overflow`, `1e308` and `--spin-up-h 1e12` panicked in
/// chrono's arithmetic. Each is now refused under its flag with the range;
/// a step count beyond the bound is refused before any forcing is built.
#[test]
fn therm_arguments_out_of_range_are_refused_not_panics() {
    let d = tempfile::tempdir().unwrap();
    let mats = d.path().join("m.toml");
    std::fs::write(&mats, MATS).unwrap();
    let m = mats.to_str().unwrap();
    for (flag, v) in [
        ("--step", "1e-9"),
        ("--step", "1e-320"),
        ("--step", "1e308"),
        ("--step", "0"),
        ("--step", "nan"),
        ("--spin-up-h", "1e12"),
        ("--spin-up-h", "-1e-3"),
        ("--facet-height-m", "inf"),
        ("--slope", "1e308"),
        ("--elevation", "1e300"),
    ] {
        let arg = format!("{flag}={v}");
        let err = refused(&irsig(&therm_args(m, &[&arg])));
        assert!(
            err.contains(flag) && err.contains("out of range"),
            "{flag} {v}: {err}"
        );
    }
    // In range each, but 300 years of 1-min steps: refused by the count.
    let long: Vec<&str> = therm_args(m, &["--step", "1"])
        .into_iter()
        .map(|a| match a {
            "1989-06-19T05:00:00Z" => "1901-01-01T00:00:00Z",
            "1989-06-19T08:00:00Z" => "2199-01-01T00:00:00Z",
            a => a,
        })
        .collect();
    let err = refused(&irsig(&long));
    assert!(err.contains("steps") && err.contains("more than"), "{err}");
    // The library (and Python) name the argument, not the flag.
    let run = irsig::therm::series::FacetRun {
        material_name: "asphalt".into(),
        material: irsig::scene::lookup::load_material(&mats, "asphalt").unwrap(),
        forcing: irsig::therm::series::ForcingSource::Weather {
            path: PathBuf::from(DATA).join("tmy3_723170_greensboro_jun18-22.csv"),
            typical_year: false,
            stand_in: false,
        },
        site: irsig::sun::Site {
            latitude_deg: 36.1,
            longitude_deg: -79.95,
            elevation_m: 0.0,
        },
        orientation: irsig::therm::balance::Orientation {
            slope_deg: 0.0,
            aspect_deg: 180.0,
        },
        from: irsig::therm::series::parse_time("1989-06-19T05:00:00Z").unwrap(),
        to: irsig::therm::series::parse_time("1989-06-19T08:00:00Z").unwrap(),
        step_min: 1e-9,
        spin_up_h: 24.0,
        spin_up_start: irsig::therm::slab::SpinUpStart::MeanForcing,
        convection: irsig::therm::balance::Convection::mcadams(),
        facet_height_m: 0.0,
        shadow: Vec::new(),
        sky_view: None,
    };
    let e = format!(
        "{:#}",
        irsig::therm::series::facet_series(&run).unwrap_err()
    );
    assert!(
        e.contains("`step_min` = 1e-9") && !e.contains("--step"),
        "{e}"
    );
    // In range: still runs.
    let out = irsig(&therm_args(m, &["--step", "60", "--spin-up-h", "6"]));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `irsig sequence`'s step words and the batch spec's: the library names
/// the step as its caller does (`--step` for the CLI, `step` for Python and
/// the spec); a step of 1e308 h is refused (it overflowed to i64::MAX).
#[test]
fn time_steps_name_their_caller_and_bound_the_step() {
    use irsig::render::sequence::{parse_step_s, parse_step_s_named};
    let e = parse_step_s_named("step", "0h").unwrap_err().to_string();
    assert!(e.starts_with("step \"0h\"") && !e.contains("--step"), "{e}");
    assert!(
        parse_step_s("0h")
            .unwrap_err()
            .to_string()
            .contains("--step")
    );
    assert!(parse_step_s("1e308h").is_err());
    assert!(parse_step_s("367d").is_err());
    assert_eq!(parse_step_s("24h").unwrap(), 86_400);
}

// ---------------------------------------------------------------- Slurm

fn batch_spec(dir: &Path, name: &str, values: &[&str]) -> PathBuf {
    batch_spec_of(
        &root().join("scenes/airfield/scene-constant.toml"),
        dir,
        name,
        values,
    )
}

/// A batch spec in `dir` over `scene` (8x8 px, 2 h of history), named
/// `name`, at two local times, sweeping `site.name` over `values`.
fn batch_spec_of(scene: &Path, dir: &Path, name: &str, values: &[&str]) -> PathBuf {
    let vals: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    let text = format!(
        "name = {name:?}\nshards = 2\n\n[[scene]]\npath = {:?}\nid = \"af\"\n\
         set = {{ \"sensor.width_px\" = 8, \"sensor.height_px\" = 8, \"render.history_hours\" = 2 }}\n\n\
         [time]\nat = [\"09:00\", \"12:00\"]\n\n[[sweep]]\nkey = \"site.name\"\nvalues = [{}]\n",
        scene.display().to_string(),
        vals.join(", ")
    );
    let p = dir.join("spec.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// Finding 2: a batch folder named `r7\ntouch /tmp/PWNED #` broke out of
/// the `#SBATCH --output=` line of array.sh and ran the rest as a command.
/// Such a folder is now refused by `batch slurm` (nothing written).
#[test]
fn a_newline_in_the_batch_folder_cannot_reach_the_slurm_scripts() {
    let d = tempfile::tempdir().unwrap();
    let canary = d.path().join("PWNED");
    let sp = batch_spec(d.path(), "t", &["a"]);
    let b = d.path().join(format!("r7\ntouch {} #", canary.display()));
    let out = irsig(&[
        "batch",
        "plan",
        sp.to_str().unwrap(),
        "-o",
        b.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = refused(&irsig(&["batch", "slurm", b.to_str().unwrap()]));
    assert!(err.contains("control character"), "{err}");
    assert!(!b.join("slurm/array.sh").exists());
    assert!(!canary.exists());
}

/// Item 2's fuzz: random folder names, batch names and sweep values (with
/// newlines, quotes, `$(…)`, backticks, `;`, `%`, `#`, spaces, non-ASCII)
/// through `batch plan` and `batch slurm`, in process (the library calls
/// the commands make). Every script written must pass `bash -n` and, run
/// with stub `irsig` and `sbatch` commands, execute nothing but them: the
/// canary file is never created and the stub gets the batch folder as one
/// argument.
///
/// `IRSIG_FUZZ_CASES` cases (default 200; scripts/fuzz.sh's `--cases`),
/// seed `IRSIG_FUZZ_SEED`. Every case plans and writes a batch in the same
/// case folder, so a script's bytes depend only on what the case varies; a
/// script byte-identical to one already checked in this run (same folder,
/// same stubs, same bytes, so the same `bash -n` verdict and the same
/// run) is not run again: each distinct script text is checked once. A
/// progress line goes out every 10 000 cases.
#[test]
fn generated_scripts_keep_every_name_quoted() {
    use rand::{Rng, SeedableRng};
    use std::collections::HashSet;
    let cases: usize = std::env::var("IRSIG_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200);
    let seed: u64 = std::env::var("IRSIG_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(33);
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let d = tempfile::tempdir().unwrap();
    let canary = d.path().join("CANARY");
    let c = canary.display().to_string();
    let pieces: Vec<String> = vec![
        "\n".into(),
        "\r".into(),
        "\t".into(),
        " ".into(),
        "'".into(),
        "\"".into(),
        "`".into(),
        "$".into(),
        format!("$(touch {c})"),
        format!("`touch {c}`"),
        format!(";touch {c};"),
        format!("\ntouch {c}\n#"),
        format!("'\ntouch {c}\n'"),
        "%".into(),
        "%a".into(),
        "#".into(),
        "\\".into(),
        "*".into(),
        "&".into(),
        "|".into(),
        "é".into(),
        "\u{1b}[1m".into(),
        "x".into(),
        "run".into(),
        "-".into(),
    ];
    let pick = |rng: &mut rand::rngs::StdRng| -> String {
        (0..rng.random_range(1..5))
            .map(|_| pieces[rng.random_range(0..pieces.len())].clone())
            .collect()
    };
    // Stubs (POSIX sh, which starts faster than bash): `irsig` records its
    // arguments (NUL-separated), `sbatch` prints a job id.
    let bin = d.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    let args_log = d.path().join("args.log");
    std::fs::write(
        bin.join("irsig-stub"),
        format!(
            "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\0' \"$a\"; done > '{}'\n",
            args_log.display()
        ),
    )
    .unwrap();
    std::fs::write(bin.join("sbatch"), "#!/bin/sh\necho 1234\n").unwrap();
    for f in ["irsig-stub", "sbatch"] {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(bin.join(f), std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    // A one-triangle scene: what the scripts hold does not depend on the
    // scene, and planning loads it once per sweep value and once more, so
    // a small one keeps a case to about a millisecond.
    let sdir = d.path().join("scene");
    std::fs::create_dir(&sdir).unwrap();
    std::fs::write(sdir.join("mats.toml"), MATS).unwrap();
    std::fs::write(sdir.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::write(
        sdir.join("scene.toml"),
        "materials = [\"mats.toml\"]\n\
         [site]\nname = \"s\"\nlatitude_deg = 43.0\nlongitude_deg = -77.0\nelevation_m = 100.0\n\
         utc_offset_h = -4.0\n[time]\nlocal = 2001-08-08T13:00:00\n\
         [weather.constant]\nwind_m_s = 2.0\nair_min_c = 17.0\nair_max_c = 29.0\n\
         dew_point_c = 14.0\ncloud_fraction = 0.0\n\
         [sensor]\nwidth_px = 8\nheight_px = 8\nfov_h_deg = 30.0\nband = \"lwir\"\n\
         [sensor.pose.slant_range]\nslant_range_m = 60.0\nview_zenith_deg = 30.0\n\
         azimuth_deg = 180.0\ntarget_m = [0.0, 0.0, 0.0]\n\
         [[object]]\nfile = \"t.obj\"\nmaterial = \"asphalt\"\n",
    )
    .unwrap();
    let scene = sdir.join("scene.toml");
    irsig::scene::load_with_overrides(&scene, &[]).expect("the fuzz's scene loads");
    let case = d.path().join("case");
    let mut checked: HashSet<String> = HashSet::new();
    let (mut written, mut refused_n, mut runs) = (0usize, 0usize, 0usize);
    let t0 = Instant::now();
    for k in 0..cases {
        if k > 0 && k % 10_000 == 0 {
            println!(
                "fuzz slurm-scripts: {k}/{cases} cases, {written} written, {refused_n} refused, \
                 {} distinct scripts checked, 0 failures, {:.0} s",
                checked.len(),
                t0.elapsed().as_secs_f64()
            );
        }
        let folder = format!("b{}", pick(&mut rng)).replace('/', "_");
        let name = pick(&mut rng);
        let values = [pick(&mut rng), pick(&mut rng)];
        if case.exists() {
            std::fs::remove_dir_all(&case).unwrap();
        }
        std::fs::create_dir(&case).unwrap();
        let sp = batch_spec_of(&scene, &case, &name, &[&values[0], &values[1]]);
        let b = case.join(&folder);
        if irsig::batch::plan(&sp)
            .and_then(|p| irsig::batch::write_plan(&b, &p))
            .is_err()
        {
            refused_n += 1;
            continue;
        }
        let o = irsig::batch::slurm::SlurmOptions {
            irsig: Some(bin.join("irsig-stub")),
            ..Default::default()
        };
        let s = match irsig::batch::slurm::slurm(&b, &o, false) {
            Err(e) => {
                let e = format!("{e:#}");
                assert!(e.contains("batch folder") || e.contains("control"), "{e}");
                refused_n += 1;
                continue;
            }
            Ok(s) => s,
        };
        written += 1;
        for script in [&s.array_script, &s.merge_script, &s.submit_script] {
            let text = std::fs::read_to_string(script).unwrap();
            if checked.contains(&text) {
                continue;
            }
            runs += 1;
            let n = Command::new("bash").arg("-n").arg(script).output().unwrap();
            assert!(
                n.status.success(),
                "bash -n {}: {}\n{text}",
                script.display(),
                String::from_utf8_lossy(&n.stderr),
            );
            let _ = std::fs::remove_file(&args_log);
            let run = Command::new("bash")
                .arg(script)
                .env("PATH", &path)
                .env("SLURM_ARRAY_TASK_ID", "0")
                .current_dir(&case)
                .output()
                .unwrap();
            assert!(
                !canary.exists(),
                "{} ran a command: folder {folder:?}, name {name:?}",
                script.display()
            );
            assert!(
                run.status.success(),
                "{}",
                String::from_utf8_lossy(&run.stderr)
            );
            if script != &s.submit_script {
                let got = std::fs::read(&args_log).unwrap();
                let args: Vec<&[u8]> = got.split(|&c| c == 0).collect();
                let dir = std::path::absolute(&b).unwrap();
                assert_eq!(args[2], dir.as_os_str().as_encoded_bytes(), "{folder:?}");
            }
            checked.insert(text);
        }
    }
    println!(
        "fuzz slurm-scripts: {cases} cases, {written} written, {refused_n} refused, \
         {} distinct scripts checked ({runs} under bash -n and run with stubs), 0 failures, \
         seed {seed}, {:.0} s",
        checked.len(),
        t0.elapsed().as_secs_f64()
    );
    assert!(written > 0);
}

// ---------------------------------------------------------------- paths

fn gltf_with_uri(dir: &Path, uri: &str) -> PathBuf {
    let p = dir.join("m.gltf");
    let text = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":36,"uri":"{uri}"}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    );
    std::fs::write(&p, text).unwrap();
    p
}

/// Finding 3: a glTF buffer `uri` of `../../../../etc/passwd`,
/// `/etc/passwd` or `file:///etc/passwd` was opened and its bytes leaked
/// through the errors or became vertices. Now refused before it is read,
/// the error naming the glTF file and the URI and none of the bytes.
#[test]
fn gltf_uris_cannot_leave_the_models_folder() {
    let d = tempfile::tempdir().unwrap();
    let m = d.path().join("model");
    std::fs::create_dir(&m).unwrap();
    std::fs::write(d.path().join("secret.bin"), b"root:x:0:0:SECRET").unwrap();
    std::os::unix::fs::symlink(d.path().join("secret.bin"), m.join("link.bin")).unwrap();
    for uri in [
        "../../../../etc/passwd",
        "/etc/passwd",
        "file:///etc/passwd",
        "../secret.bin",
        "file:../secret.bin",
        "sub/../../secret.bin",
        "%2E%2E/secret.bin",
        "link.bin",
        "/dev/zero",
    ] {
        let p = gltf_with_uri(&m, uri);
        let e = irsig::scene::mesh::gltf::load_gltf(&p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.gltf") && e.contains(uri), "{uri}: {e}");
        assert!(e.contains("path policy"), "{uri}: {e}");
        assert!(
            !e.contains("SECRET") && !e.contains("114") && !e.contains("root"),
            "{e}"
        );
    }
    // Inside the folder: read.
    std::fs::create_dir(m.join("bin")).unwrap();
    let tri: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(m.join("bin/t.bin"), &tri).unwrap();
    let p = gltf_with_uri(&m, "bin/t.bin");
    let mesh = irsig::scene::mesh::gltf::load_gltf(&p).unwrap();
    assert_eq!(mesh.faces.len(), 1);
}

/// Finding 4: `irsig check /dev/zero` read 4.2 GB before running out of
/// memory, a FIFO as the scene blocked forever, a batch spec's scene
/// `/dev/zero` ran past 60 s; libraries named `/dev/zero` said "not found".
/// Each is now refused at once, saying what the path is.
#[test]
fn devices_fifos_and_folders_are_refused_at_once() {
    let d = tempfile::tempdir().unwrap();
    let fifo = d.path().join("scene.toml");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let limit = Duration::from_secs(20);
    for (path, what) in [
        ("/dev/zero", "character device"),
        ("/dev/urandom", "character device"),
        (fifo.to_str().unwrap(), "FIFO"),
        ("/tmp", "folder"),
    ] {
        let (code, err) = irsig_within(&["check", path], limit);
        assert_eq!(code, 1, "{path}: {err}");
        assert!(
            err.contains(what) && err.contains("regular file"),
            "{path}: {err}"
        );
    }
    // A scene naming a device as its material library, a mesh or its
    // band's response file (each said "`/dev/zero` not found").
    let plate = d.path().join("plate");
    std::fs::create_dir(&plate).unwrap();
    let original = std::fs::read_to_string(root().join("scenes/plate/scene.toml"))
        .unwrap()
        .replace("allow = [\"..\"]", "allow = [\"/\"]");
    let mats = format!("\"{}\"", root().join("scenes/materials.toml").display());
    let objs = format!("\"{}/", root().join("scenes/plate/obj").display());
    for (from, to) in [
        ("\"../materials.toml\"", "\"/dev/zero\""),
        ("\"obj/plate.obj\"", "\"/dev/zero\""),
        (
            "band = \"lwir\"",
            "band = { response_file = \"/dev/zero\" }",
        ),
    ] {
        assert!(original.contains(from), "{from}");
        let scene = original
            .replace(from, to)
            .replace("\"../materials.toml\"", &mats)
            .replace("\"obj/", &objs);
        std::fs::write(plate.join("scene.toml"), scene).unwrap();
        let (code, err) = irsig_within(
            &["check", plate.join("scene.toml").to_str().unwrap()],
            limit,
        );
        assert_eq!(code, 1, "{to}: {err}");
        assert!(
            err.contains("/dev/zero") && err.contains("character device"),
            "{to}: {err}"
        );
    }
    // A batch spec whose scene is /dev/zero.
    let spec = d.path().join("spec.toml");
    std::fs::write(
        &spec,
        "name = \"t\"\n[[scene]]\npath = \"/dev/zero\"\nid = \"z\"\n",
    )
    .unwrap();
    let b = d.path().join("b");
    let (code, err) = irsig_within(
        &[
            "batch",
            "plan",
            spec.to_str().unwrap(),
            "-o",
            b.to_str().unwrap(),
        ],
        limit,
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("character device"), "{err}");
}

/// Finding 3 for the scene's own files: a downloaded scene naming
/// `/etc/passwd`, `../../..` or a `file:` URI as its weather, a material
/// library or a mesh (or a library naming such an emissivity table) is
/// refused before the file is opened, naming the scene file, its line and
/// the key, and showing none of the file's bytes; `files.allow` lets a
/// trusted scene read there. A symbolic link out of the folder counts as
/// outside.
#[test]
fn scene_paths_stay_in_the_scenes_folder_unless_allowed() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path().join("s");
    std::fs::create_dir_all(dir.join("obj")).unwrap();
    for f in ["ground.obj", "plate.obj"] {
        std::fs::copy(
            root().join("scenes/plate/obj").join(f),
            dir.join("obj").join(f),
        )
        .unwrap();
    }
    std::fs::copy(
        root().join("scenes/materials.toml"),
        dir.join("materials.toml"),
    )
    .unwrap();
    let plate = std::fs::read_to_string(root().join("scenes/plate/scene.toml"))
        .unwrap()
        .replace("\"../materials.toml\"", "\"materials.toml\"")
        .replace("[files]\nallow = [\"..\"]\n", "");
    assert!(
        !plate.contains("[files]"),
        "the plate scene changed: update this test"
    );
    let secret = d.path().join("secret.csv");
    std::fs::write(&secret, "SECRET-BYTES,1,2\n").unwrap();
    std::os::unix::fs::symlink(&secret, dir.join("link.csv")).unwrap();
    let check = |text: &str| {
        let f = dir.join("scene.toml");
        std::fs::write(&f, text).unwrap();
        let (code, err) = irsig_within(&["check", f.to_str().unwrap()], Duration::from_secs(30));
        (code, err)
    };
    let weather = |p: &str| {
        let a = plate.find("[weather.constant]").unwrap();
        let b = a + plate[a..].find("\n[sensor]").unwrap();
        format!(
            "{}[weather.file]\npath = \"{p}\"\nformat = \"csv\"\n{}",
            &plate[..a],
            &plate[b..]
        )
    };
    // The plate's constant weather replaced by a file.
    for (p, why) in [
        ("/etc/passwd", "absolute path"),
        (secret.to_str().unwrap(), "absolute path"),
        ("../secret.csv", "climbs out"),
        ("obj/../../secret.csv", "climbs out"),
        ("file:///etc/passwd", "`file:` URI"),
        ("link.csv", "symbolic link"),
    ] {
        let (code, err) = check(&weather(p));
        assert_eq!(code, 1, "{p}: {err}");
        assert!(
            err.contains("scene.toml:") && err.contains(why) && err.contains("files.allow"),
            "{p}: {err}"
        );
        assert!(
            !err.contains("SECRET") && !err.contains("root:"),
            "{p}: {err}"
        );
    }
    // A material library and a mesh outside the folder.
    let lib = plate.replace("\"materials.toml\"", "\"../secret.csv\"");
    let (code, err) = check(&lib);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("material library") && err.contains("climbs out"),
        "{err}"
    );
    let mesh = plate.replacen("\"obj/plate.obj\"", "\"/etc/passwd\"", 1);
    assert_ne!(mesh, plate, "the plate scene changed: update this test");
    let (code, err) = check(&mesh);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("mesh file") && err.contains("absolute path"),
        "{err}"
    );
    // Allowed: the file is read (and refused as weather, naming its line).
    let allowed = format!("{}\n[files]\nallow = [\"..\"]\n", weather("../secret.csv"));
    let (code, err) = check(&allowed);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("secret.csv") && !err.contains("files.allow"),
        "{err}"
    );
    // A library's emissivity table must lie in the library's folder.
    let mats = std::fs::read_to_string(dir.join("materials.toml")).unwrap();
    let at = mats.find("\nthermal_emissivity").unwrap() + 1;
    let line_end = at + mats[at..].find('\n').unwrap();
    let bad = format!(
        "{}\nemissivity = {{ table_file = \"../secret.csv\" }}{}",
        &mats[..line_end],
        &mats[line_end..]
    );
    std::fs::write(dir.join("materials.toml"), bad).unwrap();
    let (code, err) = check(&plate);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("materials.toml:")
            && err.contains("emissivity table")
            && err.contains("climbs out"),
        "{err}"
    );
    assert!(!err.contains("SECRET"), "{err}");
}

/// From issue 32's small things: a TIFF (or anything not glTF) named
/// `.glb` says what it is, not "invalid glTF JSON".
#[test]
fn a_tiff_named_glb_says_it_is_a_tiff() {
    let d = tempfile::tempdir().unwrap();
    for (bytes, what) in [
        (&b"II*\0\x08\0\0\0rest of a tiff"[..], "TIFF"),
        (&b"\x89PNG\r\n\x1a\n...."[..], "PNG"),
        (&b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"[..], "OBJ"),
        (&b"\x00\x01\x02\x03binary"[..], "binary data"),
    ] {
        let p = d.path().join("model.glb");
        std::fs::write(&p, bytes).unwrap();
        let e = irsig::scene::mesh::gltf::load_gltf(&p)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("model.glb") && e.contains("not a glTF file"),
            "{e}"
        );
        assert!(e.contains(what) && !e.contains("invalid glTF JSON"), "{e}");
    }
}

// ---------------------------------------------------------------- physics

/// A small valid IRSIG-ATMOS table whose quantity `q` (all its values) is
/// `v`; every other value 0.5.
fn table_with(q: &str, v: f32) -> Vec<u8> {
    let mut h = String::from(
        "IRSIG-ATMOS 1\nname tiny\ndescription t\ncommand none\nwavenumber_cm1 500 20 4\n",
    );
    let mut data = Vec::new();
    for (name, axes) in irsig::atmos::table::REQUIRED {
        let mut line = format!("quantity {name} unit=W_m-2");
        for a in *axes {
            line += &format!(" {a}=0,45");
        }
        h += &line;
        h.push('\n');
        let n = 4 << axes.len();
        let x = if *name == q { v } else { 0.5 };
        data.extend((0..n).flat_map(|_| x.to_le_bytes()));
    }
    h += "data f32le\n";
    let mut b = h.into_bytes();
    b.extend(data);
    b
}

/// Finding 5: tables were checked for finiteness only; `tau_path = 5` and
/// `l_ue = -1` rendered without a word and `l_ue = 3e38` passed `check`,
/// then ended the render in the "please report" NaN message. Each is now
/// refused at load naming the file, the quantity's header line, the grid
/// node, the wavenumber and the value.
#[test]
fn atmosphere_tables_out_of_physics_are_refused_at_load() {
    use irsig::atmos::AtmosTable;
    assert!(AtmosTable::from_bytes(&table_with("l_ue", 0.5), "t.atm").is_ok());
    for (q, v, line) in [
        ("tau_path", 5.0f32, 6),
        ("tau_sun", -0.1, 11),
        ("l_ue", -1.0, 7),
        ("l_ue", 3e38, 7),
        ("l_ds", 2e6, 10),
        ("e_sun_exo", 1e30, 12),
    ] {
        let e = AtmosTable::from_bytes(&table_with(q, v), "t.atm")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("t.atm: header line {line}:")),
            "{q}: {e}"
        );
        assert!(e.contains(q) && e.contains("out of range"), "{q}: {e}");
        assert!(e.contains("500 cm⁻¹"), "{e}");
    }
    // The shipped tables hold.
    for (name, _, _) in irsig::atmos::list_builtin().unwrap() {
        irsig::atmos::Atmosphere::builtin(&name).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

// ---------------------------------------------------------------- batch

/// Finding 6: two `batch run`s on one folder each rendered every frame.
/// Three runners started together now share the 4 frames: each frame is
/// rendered once (the runners' counts add up to 4) and the batch is done.
#[test]
fn three_concurrent_runners_render_each_frame_once() {
    let d = tempfile::tempdir().unwrap();
    let sp = batch_spec(d.path(), "t", &["a", "b"]);
    let b = d.path().join("b");
    let out = irsig(&[
        "batch",
        "plan",
        sp.to_str().unwrap(),
        "-o",
        b.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let runners: Vec<_> = (0..3)
        .map(|_| {
            Command::new(env!("CARGO_BIN_EXE_irsig"))
                .args(["batch", "run", b.to_str().unwrap(), "--threads", "1"])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut rendered = 0;
    for r in runners {
        let o = r.wait_with_output().unwrap();
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(
            o.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        let n: usize = text
            .split(" rendered")
            .next()
            .and_then(|s| s.rsplit(' ').next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("{text}"));
        rendered += n;
    }
    assert_eq!(rendered, 4);
    let st = irsig::batch::Batch::open(&b).unwrap().status();
    assert_eq!((st.done, st.total), (4, 4));
}

// ---------------------------------------------------------------- DEM

/// Finding 7: a DEM with `inf` (or 1e300, inf as f32) heights was refused
/// with "scene point (-900, 1000) is not in it; it covers x -911 to -820":
/// a point inside what it covers. Now the pixel and its height are named.
#[test]
fn a_dem_with_absurd_heights_names_the_pixel() {
    let d = tempfile::tempdir().unwrap();
    let (lat, lon) = (43.1566, -77.6088);
    // GDAL writes 1e300 as the largest f32.
    for (bad, shown) in [("1e30", "1e30"), ("1e300", "3.4028235e38")] {
        let mut asc = format!(
            "ncols 41\nnrows 41\nxllcorner {}\nyllcorner {}\ncellsize 0.001\nNODATA_value -9999\n",
            lon - 0.0205,
            lat - 0.0205
        );
        for r in 0..41 {
            let row: Vec<&str> = (0..41)
                .map(|c| if (r, c) == (20, 20) { bad } else { "150" })
                .collect();
            asc += &row.join(" ");
            asc.push('\n');
        }
        let a = d.path().join("dem.asc");
        std::fs::write(&a, asc).unwrap();
        let tif = d.path().join("dem.tif");
        let _ = std::fs::remove_file(&tif);
        let ok = Command::new("gdal_translate")
            .args(["-q", "-ot", "Float32", "-a_srs", "EPSG:4326"])
            .arg(&a)
            .arg(&tif)
            .status()
            .unwrap();
        assert!(ok.success());
        let scene = format!(
            "materials = [\"{}\"]\n[files]\nallow = [\"/\"]\n\
             [site]\nlatitude_deg = {lat}\nlongitude_deg = {lon}\nelevation_m = 150.0\nutc_offset_h = -4.0\n\
             [time]\nlocal = 2001-08-08T14:00:00\n\
             [weather.constant]\nwind_m_s = 3.0\nair_min_c = 17.0\nair_max_c = 29.0\ndew_point_c = 14.0\n\
             [atmosphere]\nmodel = \"mid-latitude-summer\"\n\
             [sensor]\nwidth_px = 8\nheight_px = 8\nfov_h_deg = 50.0\nband = \"lwir\"\n\
             [sensor.pose.altitude]\naltitude_m = 700.0\nview_zenith_deg = 0.0\nazimuth_deg = 0.0\ntarget_m = [0.0, 0.0, 0.0]\n\
             [render]\nsupersample = 1\nhistory_hours = 6.0\nshadow_interval_min = 60.0\n\
             [[terrain]]\nfile = \"{}\"\nextent_m = 800.0\nresolution_m = 20.0\nmaterial = \"grass_irrigated\"\n",
            root().join("scenes/materials.toml").display(),
            tif.display()
        );
        let f = d.path().join("scene.toml");
        std::fs::write(&f, scene).unwrap();
        let e = match irsig::scene::load(&f) {
            Ok(_) => panic!("accepted a DEM height of {bad}"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains("dem.tif") && e.contains("column 20, row 20"),
            "{e}"
        );
        assert!(e.contains(shown) && !e.contains("is not in it"), "{e}");
    }
}

// ---------------------------------------------------------------- plausibility

/// Finding 5 (materials): an in-range `internal_power_w_m2 = -1000` gave
/// surfaces of 16-182 K in 294-304 K air with exit 0. A render's surface
/// temperatures are now checked against a plausible range (150-600 K in
/// `irsig render`, a warning, an error with `--strict`); the report names
/// the count, the most extreme pixel, its material and its dominant flux
/// term. Checked here on the plate scene with the range narrowed below
/// its sunlit plate (~311 K) and with the real range (no warning).
#[test]
fn implausible_surface_temperatures_are_reported() {
    use irsig::render::plausible::{PLAUSIBLE_K, surface_temperature_warnings_in};
    let text = std::fs::read_to_string(root().join("scenes/plate/scene.toml"))
        .unwrap()
        .replace("width_px = 256", "width_px = 8")
        .replace("height_px = 256", "height_px = 8");
    let scene = irsig::scene::load_text(&root().join("scenes/plate/scene.toml"), text).unwrap();
    let st = irsig::render::prepare_static(scene, None).unwrap();
    let t = st.scene.scene.time.utc(&st.scene.scene.site);
    let cond = irsig::render::prepare_conditions(&st, t).unwrap();
    let img = irsig::render::render_conditions(&st, &cond, None).unwrap();
    let planes = &img.frame.planes;
    assert!(
        surface_temperature_warnings_in(&st, &cond, planes, PLAUSIBLE_K)
            .unwrap()
            .is_empty()
    );
    let narrow = irsig::bounds::Bound::new("surface temperature", 150.0, 300.0, "K");
    let w = surface_temperature_warnings_in(&st, &cond, planes, narrow).unwrap();
    assert_eq!(w.len(), 1, "{w:?}");
    let w = &w[0];
    assert!(w.contains("outside the plausible 150 to 300 K"), "{w}");
    assert!(w.contains("K on material `"), "{w}");
    assert!(
        w.contains("largest flux term is") && w.contains("_w_m2 = "),
        "{w}"
    );
}

/// Finding 5 (materials), the real range: the issue's in-range
/// `internal_power_w_m2 = -1000` (on the plate scene's concrete ground, a
/// calm night at −20 to −10 °C air) cools the ground to ~100 K. `irsig
/// render` warns, naming the plausible 150-600 K range, the material and
/// the dominant flux term (the internal power), and still writes the image
/// (exit 0); with `--strict` it is refused and nothing is written. Before,
/// such a render ended with exit 0 and no word.
#[test]
fn a_material_cooled_below_150_k_is_named_with_its_flux_term() {
    let d = tempfile::tempdir().unwrap();
    let plate = root().join("scenes/plate");
    std::fs::create_dir(d.path().join("obj")).unwrap();
    for f in ["ground.obj", "plate.obj"] {
        std::fs::copy(plate.join("obj").join(f), d.path().join("obj").join(f)).unwrap();
    }
    let edit = |text: String, pairs: &[(&str, &str)]| {
        pairs.iter().fold(text, |t, (from, to)| {
            assert!(t.contains(from), "{from} not in the sample file");
            t.replacen(from, to, 1)
        })
    };
    let mats = std::fs::read_to_string(root().join("scenes/materials.toml")).unwrap();
    let at = mats.find("[material.concrete]").unwrap();
    let (head, tail) = mats.split_at(at);
    let tail = edit(
        tail.to_string(),
        &[(
            "\nspecularity",
            "\ninternal_power_w_m2 = -1000.0\nspecularity",
        )],
    );
    std::fs::write(d.path().join("mats.toml"), format!("{head}{tail}")).unwrap();
    let scene = edit(
        std::fs::read_to_string(plate.join("scene.toml")).unwrap(),
        &[
            ("\"../materials.toml\"", "\"mats.toml\""),
            ("local = 2001-08-08T13:00:00", "local = 2001-08-08T04:00:00"),
            ("wind_m_s = 2.0", "wind_m_s = 0.0"),
            ("air_min_c = 17.0", "air_min_c = -20.0"),
            ("air_max_c = 29.0", "air_max_c = -10.0"),
            ("dew_point_c = 14.0", "dew_point_c = -25.0"),
            ("width_px = 256", "width_px = 8"),
            ("height_px = 256", "height_px = 8"),
        ],
    );
    let f = d.path().join("scene.toml");
    std::fs::write(&f, scene).unwrap();
    let out = d.path().join("cold.tif");
    let args = [
        "render",
        f.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "-q",
    ];
    let run = irsig(&args);
    let err = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "{err}");
    assert!(out.is_file());
    for want in [
        "warning: ",
        "outside the plausible 150 to 600 K",
        "on material `concrete`",
        "largest flux term is internal_w_m2 = -1000 W/m²",
    ] {
        assert!(err.contains(want), "no `{want}` in: {err}");
    }
    // The reported pixel's temperature is below the range.
    let k: f64 = err
        .split(" K on material")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no temperature in: {err}"));
    assert!(k < 150.0, "{err}");
    let strict = d.path().join("strict.tif");
    let mut args = args.to_vec();
    args[3] = strict.to_str().unwrap();
    args.push("--strict");
    let err = refused(&irsig(&args));
    assert!(
        err.contains("refused with --strict") && err.contains("material `concrete`"),
        "{err}"
    );
    assert!(!strict.exists(), "--strict wrote {}", strict.display());
}

/// Finding 4 (decompression): a gzip-compressed table is inflated only up
/// to the size its trailer declares, and a declared size above the 2 GiB
/// bound is refused before inflating.
#[test]
fn gzip_tables_inflate_no_further_than_they_declare() {
    use std::io::Write;
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(&vec![b'#'; 8 << 20]).unwrap();
    let good = gz.finish().unwrap();
    let n = good.len();
    for (isize, want) in [
        (100u32, "declares"),
        (3u32 << 30, "declares 3221225472 bytes"),
    ] {
        let mut b = good.clone();
        b[n - 4..].copy_from_slice(&isize.to_le_bytes());
        let e = irsig::atmos::AtmosTable::from_bytes(&b, "bomb.atm.gz")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bomb.atm.gz") && e.contains(want), "{e}");
    }
}

/// A little-endian GeoTIFF (WGS 84 geographic, 0.001° pixels at 43° N,
/// 77.6° W) of `width`×`height` 32-bit float samples in one strip of
/// `strip` (already compressed with `compression`).
fn float_tiff(width: u32, height: u32, compression: u16, strip: &[u8]) -> Vec<u8> {
    let short = |v: &[u16]| {
        (
            3u16,
            v.len() as u32,
            v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        )
    };
    let long = |v: u32| (4u16, 1u32, v.to_le_bytes().to_vec());
    let double = |v: &[f64]| {
        (
            12u16,
            v.len() as u32,
            v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        )
    };
    let n = 13u32;
    let ifd_end = 8 + 2 + 12 * n + 4;
    // Values longer than 4 bytes follow the IFD: pixel scale (24 bytes),
    // tie point (48), GeoKey directory (32); then the strip.
    let data_at = ifd_end + 24 + 48 + 32;
    // (tag, (field type, count, value bytes)).
    type Entry = (u16, (u16, u32, Vec<u8>));
    let entries: Vec<Entry> = vec![
        (256, long(width)),
        (257, long(height)),
        (258, short(&[32])),
        (259, short(&[compression])),
        (262, short(&[1])),
        (273, long(data_at)),
        (277, short(&[1])),
        (278, long(height)),
        (279, long(strip.len() as u32)),
        (339, short(&[3])),
        (33550, double(&[0.001, 0.001, 0.0])),
        (33922, double(&[0.0, 0.0, 0.0, -77.6, 43.0, 0.0])),
        (
            34735,
            short(&[1, 1, 0, 3, 1024, 0, 1, 2, 1025, 0, 1, 1, 2048, 0, 1, 4326]),
        ),
    ];
    assert_eq!(entries.len() as u32, n);
    let mut b = b"II*\0".to_vec();
    b.extend_from_slice(&8u32.to_le_bytes());
    b.extend_from_slice(&(n as u16).to_le_bytes());
    let mut extra = Vec::new();
    for (tag, (ty, count, bytes)) in &entries {
        b.extend_from_slice(&tag.to_le_bytes());
        b.extend_from_slice(&ty.to_le_bytes());
        b.extend_from_slice(&count.to_le_bytes());
        if bytes.len() <= 4 {
            let mut v = bytes.clone();
            v.resize(4, 0);
            b.extend_from_slice(&v);
        } else {
            b.extend_from_slice(&(ifd_end + extra.len() as u32).to_le_bytes());
            extra.extend_from_slice(bytes);
        }
    }
    b.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&extra);
    assert_eq!(b.len(), data_at as usize);
    b.extend_from_slice(strip);
    b
}

/// Finding 4 (DEM): a 3 MB deflate bomb in a DEM was refused only after
/// the decoder had allocated and inflated ~2.1 GB. The declared decoded
/// size is now checked against what the compressed strips can hold before
/// anything is allocated or inflated: a deflate strip of under 1 kB declaring
/// 8192×16384 float pixels (512 MiB, inside the 2²⁷-pixel bound) is refused
/// with both sizes; an uncompressed strip shorter than declared, and one
/// that runs past the end of the file, likewise. (Without the check the
/// decoder allocated the 512 MiB and failed only at the end of the
/// inflated data.) Well-formed small rasters, deflate and uncompressed,
/// are read.
#[test]
fn a_dem_deflate_bomb_is_refused_before_inflating() {
    use std::io::Write;
    let parse =
        |b: &[u8]| match irsig::scene::terrain::raster::parse_raster(Path::new("bomb.tif"), b) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        };
    let zlib = |raw: &[u8]| {
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
        z.write_all(raw).unwrap();
        z.finish().unwrap()
    };
    let bomb = zlib(&vec![0u8; 64 << 10]);
    assert!(bomb.len() < 1000, "{}", bomb.len());
    let e = parse(&float_tiff(8192, 16384, 8, &bomb));
    assert!(
        e.contains("bomb.tif")
            && e.contains("declare 536870912 bytes")
            && e.contains("refused before inflating"),
        "{e}"
    );
    // Uncompressed: the strip must hold every declared byte.
    let e = parse(&float_tiff(64, 64, 1, &[0u8; 4 * 64 * 63]));
    assert!(
        e.contains("declare 16384 bytes") && e.contains("16128 bytes"),
        "{e}"
    );
    // A strip that runs past the end of the file.
    let mut b = float_tiff(4, 4, 1, &[0u8; 64]);
    b.truncate(b.len() - 1);
    let e = parse(&b);
    assert!(e.contains("runs past the end of the"), "{e}");
    // Well-formed (deflate and uncompressed): read.
    let heights: Vec<u8> = (0..64 * 64)
        .flat_map(|i| (100.0f32 + i as f32).to_le_bytes())
        .collect();
    for b in [
        float_tiff(64, 64, 8, &zlib(&heights)),
        float_tiff(64, 64, 1, &heights),
    ] {
        let r = irsig::scene::terrain::raster::parse_raster(Path::new("ok.tif"), &b)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((r.width, r.height), (64, 64));
        assert_eq!(r.data[64 * 64 - 1], 100.0 + 4095.0);
    }
}

/// Found while bounding the arguments: `irsig sun --delta-t 1e308` printed
/// NaN angles and `--elevation 1e308` a zenith of 180°, both with exit 0;
/// the library named CLI flags (`--pressure-hpa`) to Python callers.
#[test]
fn sun_arguments_are_bounded_and_named_as_their_caller_names_them() {
    let t = "2001-06-21T12:00:00Z";
    for (flag, v) in [
        ("--delta-t", "1e308"),
        ("--elevation", "1e308"),
        ("--pressure-hpa", "-5"),
        ("--temp-c", "nan"),
    ] {
        let arg = format!("{flag}={v}");
        let err = refused(&irsig(&[
            "sun", "--lat", "43", "--lon", "-77", "--time", t, &arg,
        ]));
        assert!(err.contains(flag) && err.contains("out of range"), "{err}");
    }
    let time = irsig::sun::report::parse_time(t).unwrap();
    let opts = irsig::sun::SpaOptions {
        delta_t_s: Some(1e308),
        ..Default::default()
    };
    let e = irsig::sun::report::sun_report(time, 43.0, -77.0, 0.0, &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`delta_t_s` = 1e308") && !e.contains("--"),
        "{e}"
    );
}
