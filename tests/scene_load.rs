//! Scene loader acceptance tests: the sample scenes load; every error class
//! gives its exact message (file, line, column, what is wrong); a scene
//! round-trips through TOML; mutated inputs never panic.

use std::path::{Path, PathBuf};

use irsig::scene::{self, SceneError};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

// ------------------------------------------------------------ sample scenes

#[test]
fn sample_scenes_load_with_consistent_arrays() {
    for (file, objects, tri_range) in [
        ("scenes/airfield/scene.toml", 24, 4500..5100),
        ("scenes/airfield/scene-constant.toml", 24, 4500..5100),
        ("scenes/plate/scene.toml", 2, 100..200),
        ("scenes/terrain-km/scene.toml", 14, 45_000..50_001),
    ] {
        let s = scene::load(&root().join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(s.objects.len(), objects, "{file}");
        let n = s.triangles.len();
        assert!(tri_range.contains(&n), "{file}: {n} triangles");
        assert_eq!(s.tri_material.len(), n);
        assert_eq!(s.tri_object.len(), n);
        assert_eq!(s.tri_facet.len(), n);
        assert!(
            s.tri_material
                .iter()
                .all(|&m| (m as usize) < s.materials.len())
        );
        assert!(s.tri_object.iter().all(|&o| (o as usize) < s.objects.len()));
        assert!(
            s.triangles
                .iter()
                .flatten()
                .all(|&i| (i as usize) < s.positions.len())
        );
        assert!(s.positions.iter().flatten().all(|c| c.is_finite()));
        // objects own contiguous triangle ranges, in order
        let mut next = 0;
        for (k, o) in s.objects.iter().enumerate() {
            assert_eq!(o.first_triangle, next, "{file}");
            next += o.triangle_count;
            let r = o.first_triangle as usize..next as usize;
            assert!(s.tri_object[r].iter().all(|&x| x as usize == k));
        }
        assert_eq!(next as usize, n);
        assert_eq!(s.degenerate_skipped, 0, "{file}");
    }
}

#[test]
fn airfield_matches_the_paper_scene() {
    let s = scene::load(&root().join("scenes/airfield/scene.toml")).unwrap();
    // the hangar roof is specular painted metal
    let roof = s.material_index("painted_steel_roof").unwrap();
    assert_eq!(s.materials[roof].specularity, 1.0);
    let hangar = s.objects.iter().position(|o| o.name == "hangar").unwrap();
    let roof_tris = (0..s.triangles.len())
        .filter(|&t| s.tri_object[t] as usize == hangar && s.tri_material[t] as usize == roof)
        .count();
    assert!(roof_tris > 100, "{roof_tris}");
    // aircraft face north: each is longer along y than along x... for the
    // fuselage; their nose (max y) is further from the centre than the tail
    for o in s.objects.iter().filter(|o| o.name.starts_with("aircraft")) {
        let len_y = o.bounds_max_m[1] - o.bounds_min_m[1];
        assert!(len_y > 10.0, "{}", o.name);
    }
    // the vehicles carry an internal heat source
    let engine = s.material_index("vehicle_engine").unwrap();
    assert!(s.materials[engine].construction.internal_power_w_m2 > 0.0);
    assert!(s.tri_material.iter().any(|&m| m as usize == engine));
    // the weather record exists and is a TMY3 excerpt with its header
    let scene::WeatherSpec::File {
        path,
        format,
        typical_year,
        stand_in,
    } = &s.scene.weather
    else {
        panic!("weather file expected")
    };
    assert_eq!(*format, scene::WeatherFormat::Tmy3);
    assert!(!typical_year, "the excerpt is one real year");
    assert!(*stand_in, "Greensboro's record stands in for Rochester");
    let text = std::fs::read_to_string(s.resolve(path)).unwrap();
    assert!(text.starts_with("723170,\"GREENSBORO PIEDMONT TRIAD INT\""));
    assert_eq!(text.lines().count(), 2 + 144);
}

/// Outward normals: the divergence-theorem volume of each object, taken
/// from its lowest corner (bottomless boxes then miss nothing), is
/// positive for outward winding (and below 1.5x its bounding box: open
/// window quads add a little);
/// flat ground objects have no face pointing down.
#[test]
fn generated_meshes_have_outward_normals() {
    let s = scene::load(&root().join("scenes/airfield/scene.toml")).unwrap();
    for (k, o) in s.objects.iter().enumerate() {
        // Positions are in the tracer's local frame, bounds in world ones.
        let c = s.frame.to_local(o.bounds_min_m);
        let (mut vol, mut down) = (0.0f64, 0usize);
        for t in 0..s.triangles.len() {
            if s.tri_object[t] as usize != k {
                continue;
            }
            let p = s.triangles[t].map(|i| {
                let q = s.positions[i as usize];
                [q[0] as f64 - c[0], q[1] as f64 - c[1], q[2] as f64 - c[2]]
            });
            let cross = [
                p[1][1] * p[2][2] - p[1][2] * p[2][1],
                p[1][2] * p[2][0] - p[1][0] * p[2][2],
                p[1][0] * p[2][1] - p[1][1] * p[2][0],
            ];
            vol += (p[0][0] * cross[0] + p[0][1] * cross[1] + p[0][2] * cross[2]) / 6.0;
            let e1: Vec<f64> = (0..3).map(|i| p[1][i] - p[0][i]).collect();
            let e2: Vec<f64> = (0..3).map(|i| p[2][i] - p[0][i]).collect();
            if e1[0] * e2[1] - e1[1] * e2[0] < -1e-9 {
                down += 1;
            }
        }
        let height = o.bounds_max_m[2] - o.bounds_min_m[2];
        if height < 0.5 {
            assert_eq!(down, 0, "{}: faces pointing down", o.name);
        } else {
            let bbox: f64 = (0..3)
                .map(|i| o.bounds_max_m[i] - o.bounds_min_m[i])
                .product();
            assert!(
                vol > 0.0 && vol < 1.5 * bbox,
                "{}: volume {vol} (bbox {bbox})",
                o.name
            );
        }
    }
}

#[test]
fn round_trip_through_toml_is_identical() {
    for file in [
        "scenes/airfield/scene.toml",
        "scenes/airfield/scene-constant.toml",
        "scenes/plate/scene.toml",
        "scenes/terrain-km/scene.toml",
    ] {
        let path = root().join(file);
        let s = scene::load(&path).unwrap();
        let text = toml::to_string(&s.scene).unwrap();
        let back =
            scene::parse_scene(&path, &text).unwrap_or_else(|e| panic!("{file}: {e}\n{text}"));
        assert_eq!(back, s.scene, "{file}");
        // and the full load from the written text gives the same geometry
        let tmp = path.with_file_name(".roundtrip-test.toml");
        std::fs::write(&tmp, &text).unwrap();
        let again = scene::load(&tmp);
        let _ = std::fs::remove_file(&tmp);
        let again = again.unwrap();
        assert_eq!(again.triangles, s.triangles);
        assert_eq!(again.positions, s.positions);
        assert_eq!(again.materials, s.materials);
    }
}

// ------------------------------------------------------------ error classes

const MATS: &str = "[material.grass]
density_kg_m3 = 2050.0
specific_heat_j_kgk = 1840.0
conductivity_w_mk = 0.52
thickness_m = 0.5
solar_absorptivity = 0.78
thermal_emissivity = 0.93
back = { deep_ground = {} }

[material.asphalt]
density_kg_m3 = 2120.0
specific_heat_j_kgk = 920.0
conductivity_w_mk = 0.74
thickness_m = 0.3
solar_absorptivity = 0.88
thermal_emissivity = 0.93
";

const OBJ: &str = "o ground
v 0 0 0
v 10 0 0
v 10 10 0
v 0 10 0
usemtl grass
f 1 2 3 4
";

const SCENE: &str = "materials = [\"mats.toml\"]

[site]
latitude_deg = 43.0
longitude_deg = -77.0
utc_offset_h = -4.0

[time]
local = 2001-08-08T12:00:00

[weather.constant]
wind_m_s = 1.0
air_min_c = 15.0
air_max_c = 25.0
dew_point_c = 10.0

[sensor]
width_px = 16
height_px = 16
fov_h_deg = 10.0
band = \"lwir\"

[sensor.pose.altitude]
altitude_m = 100.0
view_zenith_deg = 0.0
azimuth_deg = 180.0

[[object]]
file = \"g.obj\"
";

/// The error of the test scene with `from` replaced by `to` (the test
/// library and mesh as they are).
fn scene_err(from: &str, to: &str) -> String {
    Fixture::new(&SCENE.replace(from, to), MATS, OBJ).err()
}

struct Fixture {
    dir: tempfile::TempDir,
}

impl Fixture {
    fn new(scene: &str, mats: &str, obj: &str) -> Self {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("scene.toml"), scene).unwrap();
        std::fs::write(dir.path().join("mats.toml"), mats).unwrap();
        std::fs::write(dir.path().join("g.obj"), obj).unwrap();
        Self { dir }
    }
    fn p(&self, f: &str) -> String {
        self.dir.path().join(f).display().to_string()
    }
    fn load(&self) -> Result<scene::LoadedScene, SceneError> {
        scene::load(&self.dir.path().join("scene.toml"))
    }
    /// The error message with the temp dir replaced by `D`.
    fn err(&self) -> String {
        self.err_with(&[])
    }
    /// [`Self::err`] of the scene loaded with `--set` overrides.
    fn err_with(&self, set: &[(&str, &str)]) -> String {
        let set: Vec<(String, String)> = set
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        let Err(e) = scene::load_with_overrides(&self.dir.path().join("scene.toml"), &set) else {
            panic!("expected an error")
        };
        let e = e.to_string();
        e.replace(&format!("{}/", self.dir.path().display()), "D/")
    }
}

/// An error in an item a `--set` override put there names the override
/// (the edited text's line would be the wrong line of the file, or one
/// past its end: a new key is inserted); an error elsewhere keeps its line
/// and column in the file as it is on disk although an override inserted
/// lines above it (independent reference: the same file's errors without
/// overrides).
#[test]
fn errors_with_overrides_name_the_override_or_the_files_own_line() {
    let f = Fixture::new(SCENE, MATS, OBJ);
    // Replaced value, new key in an existing table, new table, range check.
    assert_eq!(
        f.err_with(&[("sensor.band", "lwirr")]),
        "D/scene.toml (--set sensor.band=lwirr): unknown variant `lwirr`, expected one of \
         `lwir`, `mwir`, `range_um`, `response_file`; did you mean `lwir`?"
    );
    assert_eq!(
        f.err_with(&[("site.elevation", "3")]),
        "D/scene.toml (--set site.elevation=3): unknown field `elevation`, expected one of \
         `name`, `latitude_deg`, `longitude_deg`, `elevation_m`, `utc_offset_h`, `crs`; \
         did you mean `elevation_m`?"
    );
    assert_eq!(
        f.err_with(&[("output.exr_compression", "jpeg")]),
        "D/scene.toml (--set output.exr_compression=jpeg): unknown variant `jpeg`, expected \
         one of `none`, `rle`, `zips`, `zip`, `piz`"
    );
    assert_eq!(
        f.err_with(&[("site.latitude_deg", "95")]),
        "D/scene.toml (--set site.latitude_deg=95): `latitude_deg` = 95 is out of range: \
         expected -90 <= latitude_deg <= 90 degrees"
    );
    // Errors in the file's own text, with overrides that insert lines
    // above them: the same location as without overrides.
    let inserts = [("site.name", "x"), ("sensor.psf", "none")];
    for (from, to, want) in [
        (
            "latitude_deg = 43.0",
            "latitude_deg = 95.0",
            "D/scene.toml:4:16: ",
        ),
        ("band = \"lwir\"", "band = \"lwirr\"", "D/scene.toml:21:8: "),
        (
            "width_px = 16",
            "width_px = \"wide\"",
            "D/scene.toml:18:12: ",
        ),
        (
            "altitude_m = 100.0",
            "altitud_m = 100.0",
            "D/scene.toml:24:1: ",
        ),
    ] {
        let f = Fixture::new(&SCENE.replace(from, to), MATS, OBJ);
        let plain = f.err();
        assert!(plain.starts_with(want), "{plain}");
        assert_eq!(f.err_with(&inserts), plain);
    }
}

#[test]
fn fixture_loads() {
    let f = Fixture::new(SCENE, MATS, OBJ);
    let s = f.load().unwrap();
    assert_eq!(s.triangles.len(), 2);
    assert_eq!(s.tri_facet, vec![0, 0]);
    assert_eq!(s.materials.len(), 2);
    let _ = f.p("x");
}

#[test]
fn toml_syntax_error_names_line_and_column() {
    let f = Fixture::new(
        &SCENE.replace("latitude_deg = 43.0", "latitude_deg = = 43.0"),
        MATS,
        OBJ,
    );
    let e = f.err();
    assert!(e.starts_with("D/scene.toml:4:16: "), "{e}");
}

#[test]
fn unknown_key_is_rejected_with_a_suggestion() {
    assert_eq!(
        scene_err("latitude_deg = 43.0", "latitude = 43.0"),
        "D/scene.toml:4:1: unknown field `latitude`, expected one of `name`, `latitude_deg`, `longitude_deg`, \
         `elevation_m`, `utc_offset_h`, `crs`; did you mean `latitude_deg`?"
    );
    let f = Fixture::new(
        SCENE,
        &MATS.replace("thickness_m = 0.3", "thicknes_m = 0.3"),
        OBJ,
    );
    let e = f.err();
    assert!(
        e.starts_with("D/mats.toml:14:1: unknown field `thicknes_m`, expected one of "),
        "{e}"
    );
    assert!(e.ends_with("; did you mean `thickness_m`?"), "{e}");
}

#[test]
fn unknown_variant_is_rejected_with_a_suggestion() {
    let f = Fixture::new(
        &SCENE.replace("band = \"lwir\"", "band = \"lwirr\""),
        MATS,
        OBJ,
    );
    let e = f.err();
    assert!(
        e.starts_with("D/scene.toml:21:8: unknown variant `lwirr`, expected one of `lwir`, `mwir`"),
        "{e}"
    );
    assert!(e.ends_with("; did you mean `lwir`?"), "{e}");
}

#[test]
fn missing_key_names_the_table() {
    let f = Fixture::new(&SCENE.replace("fov_h_deg = 10.0\n", ""), MATS, OBJ);
    assert_eq!(f.err(), "D/scene.toml:17:1: missing field `fov_h_deg`");
}

#[test]
fn wrong_type_names_what_is_expected() {
    let f = Fixture::new(
        &SCENE.replace("width_px = 16", "width_px = \"wide\""),
        MATS,
        OBJ,
    );
    let e = f.err();
    assert!(
        e.starts_with("D/scene.toml:18:12: invalid type: string \"wide\", expected u32"),
        "{e}"
    );
}

#[test]
fn out_of_range_scene_value_names_its_line() {
    assert_eq!(
        scene_err("latitude_deg = 43.0", "latitude_deg = 95.0"),
        "D/scene.toml:4:16: `latitude_deg` = 95 is out of range: expected -90 <= latitude_deg <= 90 degrees"
    );
    assert_eq!(
        scene_err("dew_point_c = 10.0", "dew_point_c = 18.0"),
        "D/scene.toml:15:15: `dew_point_c` = 18 is out of range: expected -100 <= dew_point_c <= 15 °C \
         (the dew point cannot exceed the air temperature)"
    );
}

/// The scene's ranges are one table (`bounds::scene_keys::ALL`): its `*`
/// rows reach every `[[object]]` and `[[object.instance]]`, a number
/// array has each element checked at its index, and the message names the
/// element's line and column.
#[test]
fn out_of_range_array_element_of_an_instance_names_its_line_and_column() {
    let scene = format!(
        "{SCENE}[[object.instance]]\ntranslate_m = [0.0, 0.0, 0.0]\n\
         [[object.instance]]\ntranslate_m = [1.0, 2.0, 3.0]\nscale = [1.0, 0.0, 1.0]\n"
    );
    let f = Fixture::new(&scene, MATS, OBJ);
    assert_eq!(
        f.err(),
        "D/scene.toml:34:15: `scale` = 0 is out of range: expected 1e-9 <= scale <= 1e9"
    );
    assert_eq!(
        scene_err("view_zenith_deg = 0.0", "view_zenith_deg = 89.5"),
        "D/scene.toml:25:19: `view_zenith_deg` = 89.5 is out of range: expected 0 <= \
         view_zenith_deg <= 89 degrees"
    );
}

#[test]
fn out_of_range_material_value_names_the_library_line() {
    let f = Fixture::new(
        SCENE,
        &MATS.replace(
            "thermal_emissivity = 0.93\nback",
            "thermal_emissivity = 1.3\nback",
        ),
        OBJ,
    );
    assert_eq!(
        f.err(),
        "D/mats.toml:7:22: `thermal_emissivity` = 1.3 is out of range: expected 0 <= thermal_emissivity <= 1"
    );
    let f = Fixture::new(
        SCENE,
        &MATS.replace("thickness_m = 0.5", "thickness_m = 0.0"),
        OBJ,
    );
    assert_eq!(
        f.err(),
        "D/mats.toml:5:15: `thickness_m` = 0 is out of range: expected 1e-5 <= thickness_m <= 10 m"
    );
    let f = Fixture::new(
        SCENE,
        &MATS.replace("density_kg_m3 = 2120.0", "density_kg_m3 = -1.0"),
        OBJ,
    );
    assert_eq!(
        f.err(),
        "D/mats.toml:11:17: `density_kg_m3` = -1 is out of range: expected 1 <= density_kg_m3 <= 25000 kg/m³"
    );
}

/// A material table is read by three parts (construction, surface kind,
/// optics), each taking its own keys: errors in any part keep the key's
/// file:line:col, and an unknown key is matched against every part's keys.
#[test]
fn material_parts_report_errors_at_the_key() {
    let cases = [
        (
            "specularity = \"shiny\"",
            "invalid type: string \"shiny\", expected f64",
        ),
        (
            "specularty = 0.5",
            "unknown field `specularty`, expected one of ",
        ),
        (
            "emissivity = { fresnel = { n = 0.0, k = 0.1 } }",
            "`n` = 0 is out of range: expected 1e-6 <= n <= 10000",
        ),
        (
            "lai = 2.0",
            "`lai` does not apply to kind = \"solid\" (it is a parameter of vegetation)",
        ),
        (
            "back = { air = { exposed_area = 20.0 } }",
            "`exposed_area` = 20 is out of range: expected 1e-6 <= exposed_area <= 10",
        ),
        (
            "back = { deep_ground = { temp_c = 200.0 } }",
            "`temp_c` = 200 is out of range: expected -90 <= temp_c <= 100 °C",
        ),
    ];
    for (line, want) in cases {
        let mats = format!("{MATS}{line}\n");
        let f = Fixture::new(SCENE, &mats, OBJ);
        let e = f.err();
        let written = std::fs::read_to_string(f.dir.path().join("mats.toml")).unwrap();
        let n = written.lines().position(|l| l == line).unwrap() + 1;
        assert!(e.starts_with(&format!("D/mats.toml:{n}:")), "{line}: {e}");
        assert!(e.contains(want), "{line}: {e}");
    }
    let f = Fixture::new(SCENE, &format!("{MATS}specularty = 0.5\n"), OBJ);
    assert!(
        f.err().ends_with("; did you mean `specularity`?"),
        "{}",
        f.err()
    );
}

#[test]
fn undefined_material_names_obj_line_and_libraries() {
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("usemtl grass", "usemtl gras"));
    assert!(
        f.err().starts_with(
            "D/g.obj:6: material `gras` is not defined in the material libraries `D/mats.toml`; did you mean `grass`? \
             Unmapped material names of this file: `gras` (D/g.obj:6). The libraries define: asphalt, grass."
        ),
        "{}",
        f.err()
    );
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("usemtl grass", "usemtl marble"));
    assert!(
        f.err().starts_with(
            "D/g.obj:6: material `marble` is not defined in the material libraries `D/mats.toml`. Unmapped"
        ),
        "{}",
        f.err()
    );
}

#[test]
fn nan_and_infinite_vertices_are_rejected_with_their_line() {
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("v 10 10 0", "v 10 NaN 0"));
    assert_eq!(
        f.err(),
        "D/g.obj:4: vertex: coordinate `NaN` is NaN or infinite (or overflows 32-bit floating point): expected a \
         finite number"
    );
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("v 10 10 0", "v 10 inf 0"));
    assert!(
        f.err()
            .starts_with("D/g.obj:4: vertex: coordinate `inf` is NaN or infinite")
    );
}

#[test]
fn bad_face_and_garbage_lines_are_rejected_with_their_line() {
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("f 1 2 3 4", "f 1 2 3 9"));
    assert_eq!(
        f.err(),
        "D/g.obj:7: face vertex `9`: vertex index 9 is out of range: 4 vertices defined so far (indices are 1..=4 \
         or -1..=-4)"
    );
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("o ground", "\u{1}\u{2}garbage"));
    assert!(
        f.err().starts_with("D/g.obj:1: unknown OBJ statement"),
        "{}",
        f.err()
    );
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("v 0 10 0", "v 0 ten 0"));
    assert_eq!(
        f.err(),
        "D/g.obj:5: vertex: `ten` is not a number: expected a decimal number such as -1.5 or 2e3"
    );
}

#[test]
fn face_without_material_names_the_object() {
    let f = Fixture::new(SCENE, MATS, &OBJ.replace("usemtl grass\n", ""));
    assert_eq!(
        f.err(),
        "D/g.obj:6: face has no material: no `usemtl` before it, and object 1 (D/scene.toml:28:1) sets no `material` (nor a `materials` entry \"*\")"
    );
    // an object default material fixes it
    let f = Fixture::new(
        &SCENE.replace(
            "file = \"g.obj\"",
            "file = \"g.obj\"\nmaterial = \"asphalt\"",
        ),
        MATS,
        &OBJ.replace("usemtl grass\n", ""),
    );
    let s = f.load().unwrap();
    assert_eq!(s.materials[s.tri_material[0] as usize].name, "asphalt");
}

#[test]
fn missing_files_are_reported_at_their_scene_key() {
    let f = Fixture::new(
        &SCENE.replace("file = \"g.obj\"", "file = \"nope.obj\""),
        MATS,
        OBJ,
    );
    let e = f.err();
    assert!(
        e.starts_with("D/scene.toml:29:8: mesh file `nope.obj` not found"),
        "{e}"
    );
    let f = Fixture::new(
        &SCENE.replace("[\"mats.toml\"]", "[\"mats.toml\", \"other.toml\"]"),
        MATS,
        OBJ,
    );
    let e = f.err();
    assert!(
        e.starts_with("D/scene.toml:1:27: material library `other.toml` not found"),
        "{e}"
    );
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    let obj = format!("{OBJ}v 1 1 0\nv 2 2 0\nv 3 3 0\nf 5 6 7\nf 1 1 2\n");
    let f = Fixture::new(SCENE, MATS, &obj);
    let s = f.load().unwrap();
    assert_eq!(s.triangles.len(), 2);
    assert_eq!(s.degenerate_skipped, 2);
    assert_eq!(s.objects[0].degenerate_skipped, 2);
    assert_eq!(s.objects[0].face_count, 3);
}

#[test]
fn instances_and_transforms_place_geometry() {
    let scene = SCENE.replace(
        "file = \"g.obj\"",
        "file = \"g.obj\"\ntranslate_m = [100.0, 0.0, 0.0]\n[[object.instance]]\nrotate_deg = [0.0, 0.0, 90.0]\n\
         [[object.instance]]\nscale = 2.0\ntranslate_m = [0.0, 0.0, 1.0]",
    );
    let f = Fixture::new(&scene, MATS, OBJ);
    let s = f.load().unwrap();
    assert_eq!(s.objects.len(), 2);
    assert_eq!(s.objects[0].name, "g#1");
    // instance 1: rotate +90° about z (x -> y), then translate by 100 east
    let b = (s.objects[0].bounds_min_m, s.objects[0].bounds_max_m);
    let close = |a: [f64; 3], e: [f64; 3]| (0..3).all(|i| (a[i] - e[i]).abs() < 1e-4);
    assert!(
        close(b.0, [90.0, 0.0, 0.0]) && close(b.1, [100.0, 10.0, 0.0]),
        "{b:?}"
    );
    // instance 2: scale 2, lift 1 m, then translate
    let b = (s.objects[1].bounds_min_m, s.objects[1].bounds_max_m);
    assert!(
        close(b.0, [100.0, 0.0, 1.0]) && close(b.1, [120.0, 20.0, 1.0]),
        "{b:?}"
    );
}

#[test]
fn emissivity_table_is_read_and_validated() {
    let mats = MATS.replace(
        "thermal_emissivity = 0.93\nback",
        "thermal_emissivity = 0.93\nemissivity = { table_file = \"eps.csv\" }\nback",
    );
    let f = Fixture::new(SCENE, &mats, OBJ);
    std::fs::write(
        f.dir.path().join("eps.csv"),
        "# grass\nwavelength_um, 0, 60, 85\n8.0, 0.96, 0.94, 0.80\n12.0, 0.98, 0.96, 0.84\n",
    )
    .unwrap();
    let s = f.load().unwrap();
    let g = &s.materials[s.material_index("grass").unwrap()];
    let scene::Emissivity::Table(t) = &g.emissivity else {
        panic!()
    };
    // bilinear: midway in both angle (30°) and wavelength (10 µm)
    assert!((t.at(30.0, 10.0) - 0.96).abs() < 1e-12);
    assert!((t.at(0.0, 8.0) - 0.96).abs() < 1e-12);
    assert!((t.at(90.0, 20.0) - 0.84).abs() < 1e-12);
    std::fs::write(
        f.dir.path().join("eps.csv"),
        "wavelength_um, 0, 60, 85\n8.0, 0.96, 0.94, 0.80\n12.0, 0.98, 1.2, 0.84\n",
    )
    .unwrap();
    assert_eq!(
        f.err(),
        "D/eps.csv:3: `emissivity` = 1.2 is out of range: expected 0 <= emissivity <= 1"
    );
}

#[test]
fn io_errors_name_the_file() {
    let e = scene::load(Path::new("/nonexistent/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("/nonexistent/scene.toml: cannot read file: "),
        "{e}"
    );
}

// ------------------------------------------------------------ property test

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    /// Applies edits: (position fraction, kind, byte) to a text.
    fn mutate(text: &str, edits: &[(f64, u8, u8)]) -> String {
        let mut b: Vec<u8> = text.as_bytes().to_vec();
        for &(pos, kind, byte) in edits {
            if b.is_empty() {
                b.push(byte);
                continue;
            }
            let i = ((pos * b.len() as f64) as usize).min(b.len() - 1);
            match kind % 6 {
                0 => b[i] = byte,       // replace
                1 => b.insert(i, byte), // insert
                2 => {
                    b.remove(i); // delete
                }
                3 => {
                    // duplicate a line
                    let s = b[..i]
                        .iter()
                        .rposition(|&c| c == b'\n')
                        .map_or(0, |k| k + 1);
                    let e = b[i..]
                        .iter()
                        .position(|&c| c == b'\n')
                        .map_or(b.len(), |k| i + k + 1);
                    let line = b[s..e].to_vec();
                    b.splice(e..e, line);
                }
                4 => {
                    // delete a line
                    let s = b[..i]
                        .iter()
                        .rposition(|&c| c == b'\n')
                        .map_or(0, |k| k + 1);
                    let e = b[i..]
                        .iter()
                        .position(|&c| c == b'\n')
                        .map_or(b.len(), |k| i + k + 1);
                    b.drain(s..e);
                }
                _ => {
                    // insert a token that stresses parsers
                    let toks: [&[u8]; 8] = [
                        b"nan",
                        b"-1e39",
                        b"\"",
                        b"[",
                        b"=",
                        b"-0",
                        b"99999999999",
                        b"\xff",
                    ];
                    b.splice(i..i, toks[byte as usize % 8].iter().copied());
                }
            }
        }
        String::from_utf8_lossy(&b).into_owned()
    }

    fn edits() -> impl Strategy<Value = Vec<(f64, u8, u8)>> {
        prop::collection::vec((0.0..1.0f64, any::<u8>(), any::<u8>()), 1..6)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn mutated_inputs_never_panic(se in edits(), me in edits(), oe in edits(), which in 0u8..4) {
            let scene = if which & 1 == 1 { mutate(SCENE, &se) } else { SCENE.to_string() };
            let mats = if which == 2 { mutate(MATS, &me) } else { MATS.to_string() };
            let obj = if which & 1 == 0 { mutate(OBJ, &oe) } else { OBJ.to_string() };
            let f = Fixture::new(&scene, &mats, &obj);
            // Must return (Ok or a located error), never panic.
            match f.load() {
                Ok(s) => {
                    prop_assert!(s.positions.iter().flatten().all(|c| c.is_finite()));
                    prop_assert_eq!(s.triangles.len(), s.tri_material.len());
                }
                Err(e) => {
                    let msg = e.to_string();
                    prop_assert!(!msg.is_empty());
                }
            }
        }

        #[test]
        fn mutated_sample_obj_never_panics(oe in prop::collection::vec((0.0..1.0f64, any::<u8>(), any::<u8>()), 1..12)) {
            let text = std::fs::read_to_string(root().join("scenes/airfield/obj/aircraft_small.obj")).unwrap();
            let m = mutate(&text, &oe);
            if let Ok(mut m) = scene::mesh::obj::parse_obj(Path::new("a.obj"), &m) {
                let _ = m.triangulate();
            }
        }
    }
}

fn terrain_km() -> PathBuf {
    root().join("scenes/terrain-km/scene.toml")
}

fn with(set: &[(&str, &str)]) -> Result<scene::LoadedScene, SceneError> {
    let set: Vec<(String, String)> = set
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    scene::load_with_overrides(&terrain_km(), &set)
}

fn object<'a>(s: &'a scene::LoadedScene, name: &str) -> &'a scene::ObjectInfo {
    s.objects
        .iter()
        .find(|o| o.name == name)
        .unwrap_or_else(|| panic!("no object {name}"))
}

/// Overrides reach into `[[object]]`, `[[object.instance]]` and
/// `[[terrain]]` by index (`object[2]`, `object.2`) and by `name`
/// (`object.vehicle`), down to one element of an array
/// (`translate_m[0]`); the same edit by index and by name loads the same
/// geometry, and moves the instance's bounds by exactly the change (the
/// independent reference: the scene without the override). `--unset`
/// removes a whole entry.
#[test]
fn overrides_reach_into_arrays_of_tables_by_index_and_by_name() {
    let base = with(&[]).unwrap();
    let b0 = object(&base, "vehicle#1");
    let by_name = with(&[("object.vehicle.instance[0].translate_m", "[20, 20, 2.2368]")]).unwrap();
    let by_index = with(&[("object[2].instance.0.translate_m", "[20, 20, 2.2368]")]).unwrap();
    let element = with(&[("object.vehicle.instance[0].translate_m[0]", "20")]).unwrap();
    for s in [&by_name, &by_index, &element] {
        assert_eq!(s.positions, by_name.positions);
        let o = object(s, "vehicle#1");
        // moved 10 m east, to f32 rounding of the vertices
        assert!(((o.bounds_min_m[0] - b0.bounds_min_m[0]) - 10.0).abs() < 1e-3);
        assert_eq!(o.bounds_min_m[1], b0.bounds_min_m[1]);
    }
    // [[terrain]] by name and by index
    let t_name = with(&[("terrain.terrain.resolution_m", "100")]).unwrap();
    let t_index = with(&[("terrain[0].resolution_m", "100")]).unwrap();
    let t_dot = with(&[("terrain.0.resolution_m", "100")]).unwrap();
    assert_eq!(t_name.positions, t_index.positions);
    assert_eq!(t_name.positions, t_dot.positions);
    assert!(object(&t_name, "terrain").triangle_count < object(&base, "terrain").triangle_count);
    // the material key of one object, by name (the others keep theirs)
    let m = with(&[("object.vehicle.material", "asphalt")]).unwrap();
    assert_eq!(m.scene.objects[2].material.as_deref(), Some("asphalt"));
    assert_eq!(m.scene.objects[0].material, base.scene.objects[0].material);
    // --unset of a whole entry, by name
    let text = std::fs::read_to_string(terrain_km()).unwrap();
    let edited = scene::remove_keys(&terrain_km(), &text, &["object.fuel_tank".into()]).unwrap();
    let s = scene::load_edited(&terrain_km(), edited, &[]).unwrap();
    assert!(s.objects.iter().all(|o| !o.name.starts_with("fuel_tank")));
    assert!(s.objects.iter().any(|o| o.name.starts_with("vehicle")));
}

/// Errors of overrides into arrays name the override and what was there.
#[test]
fn overrides_into_arrays_give_clear_errors() {
    let err = |set: &[(&str, &str)]| match with(set) {
        Ok(_) => panic!("{set:?} loaded"),
        Err(e) => e.to_string(),
    };
    let e = err(&[("object.truck.translate_m", "[0, 0, 0]")]);
    assert!(
        e.contains("override `object.truck.translate_m`")
            && e.contains("no entry of `object` is named `truck`")
            && e.contains("names: building, fuel_tank, vehicle"),
        "{e}"
    );
    let e = err(&[("object[7].material", "asphalt")]);
    assert!(
        e.contains("`object[7].material`") && e.contains("`object` has 3 entries"),
        "{e}"
    );
    let e = err(&[("object[x].material", "asphalt")]);
    assert!(e.contains("expected an index in brackets"), "{e}");
    // a value error inside an entry names the override that put it there
    let e = err(&[("object.vehicle.instance[1].translate_m", "[1, 2]")]);
    assert!(
        e.contains("--set object.vehicle.instance[1].translate_m=[1, 2]"),
        "{e}"
    );
    let e = err(&[("terrain.terrain.resolution_m", "-5")]);
    assert!(e.contains("--set terrain.terrain.resolution_m=-5"), "{e}");
}

/// Issue 32: keys an `[[object]]` or `[[object.instance]]` entry does not
/// write are added by an override, by index or by name, and act as the
/// same key written in the file; the refusals of what cannot be added
/// (elements of an array the file lacks, instances an object lacks) say
/// what to write instead.
#[test]
fn overrides_add_keys_an_entry_does_not_write() {
    let text = std::fs::read_to_string(terrain_km()).unwrap();
    let doc: toml_edit::DocumentMut = text.parse().unwrap();
    let objects = doc["object"].as_array_of_tables().unwrap();
    let vehicle = objects.get(2).unwrap();
    assert_eq!(vehicle["name"].as_str(), Some("vehicle"));
    assert!(vehicle.get("translate_m").is_none() && vehicle.get("scale").is_none());
    let base = with(&[]).unwrap();
    // the object's own transform, applied after each instance's: every
    // vehicle moves 10 m east, the other objects stay
    let by_name = with(&[("object.vehicle.translate_m", "[10, 0, 0]")]).unwrap();
    let by_index = with(&[("object[2].translate_m", "[10, 0, 0]")]).unwrap();
    assert_eq!(by_name.positions, by_index.positions);
    for (o, o0) in by_name.objects.iter().zip(&base.objects) {
        let dx = o.bounds_min_m[0] - o0.bounds_min_m[0];
        let want = if o.name.starts_with("vehicle") {
            10.0
        } else {
            0.0
        };
        assert!((dx - want).abs() < 1e-3, "{}: moved {dx} m", o.name);
    }
    // the same key written into the file instead: the same geometry
    let written = text.replacen(
        "name = \"vehicle\"\n",
        "name = \"vehicle\"\ntranslate_m = [10, 0, 0]\n",
        1,
    );
    let in_file = scene::load_text(&terrain_km(), written).unwrap();
    assert_eq!(in_file.positions, by_name.positions);
    // an instance key the entry does not write (`scale`)
    let scaled = with(&[("object.vehicle.instance[1].scale", "2")]).unwrap();
    let (o, o0) = (object(&scaled, "vehicle#2"), object(&base, "vehicle#2"));
    let size = |o: &scene::ObjectInfo| o.bounds_max_m[2] - o.bounds_min_m[2];
    assert!((size(o) / size(o0) - 2.0).abs() < 1e-3, "{o:?}");

    let err = |set: &[(&str, &str)]| match with(set) {
        Ok(_) => panic!("{set:?} loaded"),
        Err(e) => e.to_string(),
    };
    // an element of an array the entry does not write
    let e = err(&[("object.vehicle.translate_m[0]", "5")]);
    assert!(
        e.contains("the scene has no `object[2].translate_m`") && e.contains("set the array whole"),
        "{e}"
    );
    // an entry past the end
    let e = err(&[("object[3].material", "asphalt")]);
    assert!(e.contains("adds no entries"), "{e}");
}
