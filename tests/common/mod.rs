//! Shared helpers of the render integration tests: run the `irsig` binary,
//! read its EXR planes back.
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

pub fn airfield() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/airfield/scene.toml")
}

pub fn irsig() -> Command {
    Command::new(env!("CARGO_BIN_EXE_irsig"))
}

/// Runs `c`; panics with its stderr unless it succeeded; returns its
/// output.
pub fn succeed(c: &mut Command) -> std::process::Output {
    let out = c.output().unwrap_or_else(|e| panic!("{c:?}: {e}"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs `irsig` with `args`: (exit code, stdout, stderr), whatever the
/// outcome.
pub fn irsig_out(args: &[&str]) -> (i32, String, String) {
    let o = irsig().args(args).output().expect("run irsig");
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into(),
        String::from_utf8_lossy(&o.stderr).into(),
    )
}

/// Runs `irsig` with `args`; panics with its stderr on failure; returns
/// stdout.
pub fn run(args: &[String]) -> String {
    let out = irsig().args(args).output().expect("run irsig");
    assert!(
        out.status.success(),
        "irsig {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 output")
}

/// Runs a command (e.g. GDAL's tools); panics with its stderr on failure;
/// returns stdout.
pub fn run_command(c: &mut Command) -> String {
    let out = c
        .output()
        .unwrap_or_else(|e| panic!("{c:?}: {e} (is gdal-bin installed?)"));
    assert!(
        out.status.success(),
        "{c:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// `gdalinfo -json` of a raster.
pub fn gdalinfo(p: &Path) -> serde_json::Value {
    serde_json::from_str(&run_command(Command::new("gdalinfo").arg("-json").arg(p))).unwrap()
}

/// `gdaltransform ARGS` of points (each line: the point's coordinates,
/// 6 decimals); the output coordinates of each point.
pub fn gdaltransform<const N: usize>(args: &[&str], pts: &[[f64; N]]) -> Vec<Vec<f64>> {
    use std::io::Write;
    let mut child = Command::new("gdaltransform")
        .args(args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("gdaltransform (gdal-bin)");
    {
        let mut stdin = child.stdin.take().unwrap();
        for p in pts {
            let line: Vec<String> = p.iter().map(|v| format!("{v:.6}")).collect();
            writeln!(stdin, "{}", line.join(" ")).unwrap();
        }
    }
    let out = child.wait_with_output().unwrap();
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// `--set k=v` arguments.
pub fn sets(kv: &[&str]) -> Vec<String> {
    kv.iter()
        .flat_map(|s| ["--set".to_string(), s.to_string()])
        .collect()
}

/// Decoded EXR planes.
pub struct Img {
    pub w: u32,
    pub h: u32,
    pub planes: HashMap<String, Vec<f32>>,
}

impl Img {
    pub fn read(path: &Path) -> Img {
        let (w, h, ch) = irsig::output::exr::read_exr(path).expect("read EXR");
        Img {
            w,
            h,
            planes: ch.into_iter().collect(),
        }
    }

    pub fn plane(&self, name: &str) -> &[f32] {
        self.planes
            .get(name)
            .unwrap_or_else(|| panic!("no plane {name}"))
    }

    pub fn at(&self, name: &str, x: u32, y: u32) -> f32 {
        self.plane(name)[(y * self.w + x) as usize]
    }
}

/// Renders `scene` with the overrides into `dir/name.exr` and reads it back.
pub fn render(dir: &Path, scene: &Path, name: &str, kv: &[&str]) -> Img {
    let exr = dir.join(format!("{name}.exr"));
    let mut args = vec![
        "render".to_string(),
        scene.display().to_string(),
        "-o".into(),
        exr.display().to_string(),
    ];
    args.extend(sets(kv));
    run(&args);
    Img::read(&exr)
}

/// Material index by name in the scene (as loaded with these overrides).
pub fn material_index(scene: &Path, name: &str) -> f32 {
    let s = irsig::scene::load_with_overrides(scene, &[]).expect("load scene");
    s.materials
        .iter()
        .position(|m| m.name == name)
        .unwrap_or_else(|| panic!("no material {name}")) as f32
}

/// A file of the mesh corpus, tests/data/wild/meshes/.
pub fn wild_mesh(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/wild/meshes")
        .join(rel)
}

/// `file = "<absolute path of a corpus mesh>"`.
pub fn wild_mesh_key(rel: &str) -> String {
    format!("file = \"{}\"", wild_mesh(rel).display())
}

/// The scene head shared by the mesh tests (the sample materials, a
/// constant-weather noon in August at 43° N, the LWIR band) with the given
/// `[sensor]` size and field of view, an `[sensor.pose.altitude]` nadir
/// view from `altitude_m` (azimuth 180°: image top is north) and `extra`
/// lines after the pose table.
pub fn nadir_scene_head(width_px: u32, fov_deg: f64, altitude_m: f64, extra: &str) -> String {
    format!(
        "materials = [\"{}\"]\n[files]\nallow = [\"/\"]\n\
         [site]\nlatitude_deg = 43.0\nlongitude_deg = -77.0\nutc_offset_h = -4.0\n\
         [time]\nlocal = 2001-08-08T12:00:00\n\
         [weather.constant]\nwind_m_s = 1.0\nair_min_c = 15.0\nair_max_c = 25.0\ndew_point_c = 10.0\n\
         [sensor]\nwidth_px = {width_px}\nheight_px = {width_px}\nfov_h_deg = {fov_deg}\nband = \"lwir\"\n\
         [sensor.pose.altitude]\naltitude_m = {altitude_m}\nview_zenith_deg = 0.0\nazimuth_deg = 180.0\n\
         {extra}",
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/materials.toml")
            .display()
    )
}

/// `dir/scene.toml`: a small nadir scene whose `[[object]]`s have the
/// bodies `objects`.
pub fn mesh_scene(dir: &Path, objects: &[String]) -> PathBuf {
    let mut s = nadir_scene_head(16, 10.0, 100.0, "");
    for o in objects {
        s.push_str(&format!("[[object]]\n{o}\n"));
    }
    let p = dir.join("scene.toml");
    std::fs::write(&p, s).unwrap();
    p
}
