//! glTF 2.0 meshes (issue 14 item 3): the Khronos sample models, a
//! gltf-rs test file and trimesh exports under tests/data/wild/meshes/
//! (provenance and licences in tests/data/README.md) load with trimesh's
//! triangle counts, bounds, areas and volumes (tools/gen_trimesh_exports.py
//! wrote `gltf_ref.csv`); node transforms, instancing, the +Y-up default,
//! material maps and a render of a known area; bad files are refused
//! naming the file and what is wrong.

mod common;

use std::path::Path;

use glam::DVec3;
use irsig::scene::mesh::{self, Mesh};

use common::{mesh_scene as scene_with, wild_mesh as wild, wild_mesh_key as file_key};

/// Triangle corners of the faces whose `src` satisfies `keep`.
fn corners(m: &Mesh, keep: impl Fn(usize) -> bool) -> Vec<[DVec3; 3]> {
    (m.triangles.iter().zip(&m.tri_face))
        .filter(|(_, f)| keep(m.faces[**f as usize].src))
        .map(|(t, _)| t.map(|i| DVec3::from(m.positions[i as usize])))
        .collect()
}

fn bounds(tris: &[[DVec3; 3]]) -> (DVec3, DVec3) {
    let pts = tris.iter().flatten();
    let lo = pts.clone().fold(DVec3::INFINITY, |a, p| a.min(*p));
    let hi = pts.fold(DVec3::NEG_INFINITY, |a, p| a.max(*p));
    (lo, hi)
}

/// Total area and signed volume (Σ a·(b×c)/6: positive for a closed
/// surface wound counter-clockwise seen from outside).
fn area_volume(tris: &[[DVec3; 3]]) -> (f64, f64) {
    tris.iter().fold((0.0, 0.0), |(a, v), [p, q, r]| {
        (
            a + 0.5 * (*q - *p).cross(*r - *p).length(),
            v + p.dot(q.cross(*r)) / 6.0,
        )
    })
}

/// Every corpus file against trimesh (SimpleSparseAccessor: pygltflib and
/// numpy, trimesh ignoring sparse accessors): equal triangle counts;
/// bounds, area and signed volume to 1e-9 of the model's size.
#[test]
fn corpus_matches_trimesh() {
    let text = std::fs::read_to_string(wild("gltf_ref.csv")).unwrap();
    let mut rows = 0;
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let file = f[0];
        let num = |k: usize| f[k].parse::<f64>().unwrap();
        let m = mesh::load(&wild(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        let tris = corners(&m, |_| true);
        assert_eq!(tris.len(), f[1].parse::<usize>().unwrap(), "{file}");
        let (lo, hi) = bounds(&tris);
        let size = (hi - lo).length();
        let want_lo = DVec3::new(num(2), num(3), num(4));
        let want_hi = DVec3::new(num(5), num(6), num(7));
        assert!(
            (lo - want_lo).abs().max_element() <= 1e-9 * size
                && (hi - want_hi).abs().max_element() <= 1e-9 * size,
            "{file}: bounds {lo} {hi}, trimesh {want_lo} {want_hi}"
        );
        let (area, volume) = area_volume(&tris);
        assert!(
            (area - num(8)).abs() <= 1e-9 * num(8),
            "{file}: area {area}, ref {}",
            num(8)
        );
        if !num(9).is_nan() {
            assert!(
                (volume - num(9)).abs() <= 1e-9 * num(9).abs(),
                "{file}: volume {volume}, ref {}",
                num(9)
            );
        }
        // GLB and glTF + .bin of the same model agree exactly
        rows += 1;
    }
    assert_eq!(rows, 12);
    let a = mesh::load(&wild("khronos/Box.gltf")).unwrap();
    let b = mesh::load(&wild("khronos/Box.glb")).unwrap();
    assert_eq!((a.positions, a.triangles), (b.positions, b.triangles));
}

/// SimpleMeshes: one mesh on two nodes, the second translated by
/// (1, 0, 0): two instances, each named by its node.
#[test]
fn simple_meshes_instances_one_mesh_per_node() {
    let m = mesh::load(&wild("khronos/SimpleMeshes.gltf")).unwrap();
    assert_eq!(
        m.parts,
        vec![
            "node 0 (mesh 0, primitive 0)",
            "node 1 (mesh 0, primitive 0)"
        ]
    );
    let a = corners(&m, |s| s == 0);
    let b = corners(&m, |s| s == 1);
    assert_eq!((a.len(), b.len()), (1, 1));
    for k in 0..3 {
        assert_eq!(b[0][k], a[0][k] + DVec3::X);
    }
    assert_eq!(a[0], [DVec3::ZERO, DVec3::X, DVec3::Y]);
    // the place of a face names its node
    assert!(
        m.place(1)
            .ends_with("SimpleMeshes.gltf: node 1 (mesh 0, primitive 0)")
    );
}

/// Node transforms against the analytically transformed shapes: the
/// trimesh box (extents 2 × 3 × 4 m) turned 30° about z and moved to
/// (5, 1, −2); the Cameras sample's quad turned about x by its
/// quaternion (−0.383, 0, 0, 0.924), normalised: θ with cos θ = (w² − x²)
/// / (w² + x²), sin θ = 2xw / (w² + x²).
#[test]
fn node_transforms_match_the_analytic_boxes() {
    let m = mesh::load(&wild("trimesh/scene.glb")).unwrap();
    assert_eq!(m.parts[0], "node 0 `box` (mesh 0 `box`, primitive 0)");
    let (lo, hi) = bounds(&corners(&m, |s| s == 0));
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let half = DVec3::new(1.0 * c + 1.5 * s, 1.0 * s + 1.5 * c, 2.0);
    let centre = DVec3::new(5.0, 1.0, -2.0);
    assert!((lo - (centre - half)).abs().max_element() < 1e-12, "{lo}");
    assert!((hi - (centre + half)).abs().max_element() < 1e-12, "{hi}");
    // the child node's ring and the mirrored ring are closed surfaces that
    // keep their outward winding (positive volumes: π (R² − r²) h-ish)
    for (part, want) in [
        (1, "node 1 `ring_a` (mesh 1 `ring_painted`, primitive 0)"),
        (2, "node 2 `ring_b` (mesh 2 `ring`, primitive 0)"),
    ] {
        assert_eq!(m.parts[part], want);
        let (_, v) = area_volume(&corners(&m, |s| s == part));
        let scale = if part == 1 { 1.5 } else { 1.0 };
        let n = 24.0f64;
        let polygon = |r: f64| n / 2.0 * (2.0 * std::f64::consts::PI / n).sin() * r * r;
        let want_v = (polygon(2.0) - polygon(1.0)) * 0.5 * scale;
        assert!(
            (v - want_v).abs() < 1e-5 * want_v,
            "{want}: volume {v}, analytic {want_v}"
        );
    }

    let m = mesh::load(&wild("khronos/Cameras.gltf")).unwrap();
    let (x, w) = (-0.383f64, 0.924f64);
    let (cos, sin) = (
        (w * w - x * x) / (w * w + x * x),
        2.0 * x * w / (w * w + x * x),
    );
    let (lo, hi) = bounds(&corners(&m, |_| true));
    assert!(
        (lo - DVec3::new(0.0, 0.0, sin)).abs().max_element() < 1e-7,
        "{lo}"
    );
    assert!(
        (hi - DVec3::new(1.0, cos, 0.0)).abs().max_element() < 1e-7,
        "{hi}"
    );
}

/// glTF is +Y up: with no `up_axis` a glTF model stands up in irsig's Z-up
/// frame, (x, y, z) → (x, −z, y); `up_axis = "z"` keeps its coordinates;
/// scale and translation apply after.
#[test]
fn gltf_models_stand_up_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let star = "materials = { \"*\" = \"concrete\" }";
    let objects = vec![
        format!("{}\n{star}", file_key("trimesh/box.glb")),
        format!("{}\n{star}\nup_axis = \"z\"", file_key("trimesh/box.glb")),
        format!(
            "{}\n{star}\nscale = 2.0\ntranslate_m = [0.0, 0.0, 10.0]",
            file_key("khronos/SimpleMeshes.gltf")
        ),
    ];
    let s = irsig::scene::load(&scene_with(dir.path(), &objects)).unwrap();
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-6);
    // the box's glTF bounds (tools/gen_trimesh_exports.py): x 3.384..6.616,
    // y −0.799..2.799 (up), z −4..0
    let (x0, x1, y0, y1) = (
        3.3839745962155616,
        6.616025403784438,
        -0.799038105676658,
        2.799038105676658,
    );
    let up = &s.objects[0];
    assert!(
        close(up.bounds_min_m, [x0, 0.0, y0]),
        "{:?}",
        up.bounds_min_m
    );
    assert!(
        close(up.bounds_max_m, [x1, 4.0, y1]),
        "{:?}",
        up.bounds_max_m
    );
    let flat = &s.objects[1];
    assert!(
        close(flat.bounds_min_m, [x0, y0, -4.0]),
        "{:?}",
        flat.bounds_min_m
    );
    assert!(
        close(flat.bounds_max_m, [x1, y1, 0.0]),
        "{:?}",
        flat.bounds_max_m
    );
    // SimpleMeshes' two triangles in glTF's x-y plane stand in irsig's x-z
    let tri = &s.objects[2];
    assert!(
        close(tri.bounds_min_m, [0.0, 0.0, 10.0]),
        "{:?}",
        tri.bounds_min_m
    );
    assert!(
        close(tri.bounds_max_m, [4.0, 0.0, 12.0]),
        "{:?}",
        tri.bounds_max_m
    );
    assert_eq!(tri.triangle_count, 2);
}

/// glTF material names go through the object's `materials` map like OBJ
/// names; unmapped ones are listed with their node, mesh and primitive.
#[test]
fn material_maps_and_unmapped_names() {
    let dir = tempfile::tempdir().unwrap();
    let objects = vec![format!(
        "{}\nmaterials = {{ \"brick\" = \"concrete\", \"*\" = \"painted_steel\" }}",
        file_key("trimesh/scene.glb")
    )];
    let s = irsig::scene::load(&scene_with(dir.path(), &objects)).unwrap();
    let name = |t: usize| s.materials[s.tri_material[t] as usize].name.as_str();
    let o = &s.objects[0];
    let names: Vec<&str> = (o.first_triangle..o.first_triangle + o.triangle_count)
        .map(|t| name(t as usize))
        .collect();
    // box (12 triangles) is brick → concrete; both rings (192 each) `*`
    assert_eq!(names.len(), 12 + 2 * 192);
    assert!(names[..12].iter().all(|n| *n == "concrete"));
    assert!(names[12..].iter().all(|n| *n == "painted_steel"));

    let objects = vec![file_key("trimesh/scene.glb")];
    let e = irsig::scene::load(&scene_with(dir.path(), &objects))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(
            "scene.glb: node 0 `box` (mesh 0 `box`, primitive 0): material `brick` is not \
             defined in the material libraries"
        ),
        "{e}"
    );
    assert!(
        e.contains("Unmapped material names of this file: `brick` (",)
            && e.contains("scene.glb: node 1 `ring_a` (mesh 1 `ring_painted`, primitive 0))")
            && e.contains("`materials = { \"brick\" = "),
        "{e}"
    );
    // the unnamed-material ring with `brick` mapped but no `*`
    let objects = vec![format!(
        "{}\nmaterials = {{ \"brick\" = \"concrete\", \"ring_paint\" = \"concrete\" }}",
        file_key("trimesh/scene.glb")
    )];
    let e = irsig::scene::load(&scene_with(dir.path(), &objects))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(
            "scene.glb: node 2 `ring_b` (mesh 2 `ring`, primitive 0): the primitive has no \
             `material`, and object 1 ("
        ),
        "{e}"
    );
}

/// A flat 64-gon ring (radii 10 and 30 m) lying in glTF's horizontal x-z
/// plane, its node at glTF (15, 0, −15) = irsig (15, 15, 0), seen from
/// nadir: hit pixels = area / GSD² within 1 % (area N/2 sin(2π/N) (R² −
/// r²), which trimesh's area in gltf_ref.csv also gives); the hole at the
/// centre stays empty. Had the +Y-up default not turned it, the ring would
/// stand on edge and cover almost nothing.
#[test]
fn a_gltf_ring_renders_its_true_area() {
    let dir = tempfile::tempdir().unwrap();
    let (h_m, half_width_m, width_px) = (300.0f64, 32.0f64, 256u32);
    let fov_deg = 2.0 * (half_width_m / h_m).atan().to_degrees();
    let scene = common::nadir_scene_head(
        width_px,
        fov_deg,
        h_m,
        &format!(
            "target_m = [15.0, 15.0, 0.0]\n[render]\nhistory_hours = 2\n\
             [[object]]\n{}\nmaterials = {{ \"tarmac\" = \"asphalt\" }}\n",
            file_key("trimesh/ring.glb")
        ),
    );
    let scene_path = dir.path().join("ring.toml");
    std::fs::write(&scene_path, scene).unwrap();
    let img = common::render(dir.path(), &scene_path, "ring", &[]);
    let hits = img.plane("material").iter().filter(|&&m| m >= 0.0).count() as f64;
    let gsd_m = 2.0 * h_m * (fov_deg.to_radians() / 2.0).tan() / width_px as f64;
    let n = 64.0f64;
    let area =
        n / 2.0 * (2.0 * std::f64::consts::PI / n).sin() * (30.0f64.powi(2) - 10.0f64.powi(2));
    let expected = area / (gsd_m * gsd_m);
    assert!(
        (hits - expected).abs() <= 0.01 * expected,
        "{hits} hit pixels, expected {expected:.0} (GSD {gsd_m} m)"
    );
    let c = width_px / 2;
    assert!(img.at("material", c, c) < 0.0, "the hole is filled");
    // 20 m east of the centre: on the ring
    let px = (20.0 / gsd_m) as u32;
    assert!(img.at("material", c + px, c) >= 0.0);
}

/// Bad files: refused naming the file and what is wrong, never a panic.
#[test]
fn bad_gltf_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let err = |p: &Path| mesh::load(p).unwrap_err().to_string();
    // a .gltf without its .bin
    std::fs::copy(wild("khronos/Box.gltf"), d.join("Box.gltf")).unwrap();
    let e = err(&d.join("Box.gltf"));
    assert!(
        e.contains("Box.gltf: node 1 (mesh 0 `Mesh`, primitive 0): POSITION accessor 2: buffer view 1: buffer 0: cannot read `")
            && e.contains("Box0.bin`"),
        "{e}"
    );
    // a truncated .bin
    let bin = std::fs::read(wild("khronos/Box0.bin")).unwrap();
    std::fs::write(d.join("Box0.bin"), &bin[..600]).unwrap();
    assert!(
        err(&d.join("Box.gltf"))
            .contains("buffer 0 holds 600 bytes, less than its `byteLength` 648")
    );
    // truncated GLBs
    let glb = std::fs::read(wild("khronos/Box.glb")).unwrap();
    for n in [2, 12, 30, 500, 1000, glb.len() - 4] {
        let p = d.join("t.glb");
        std::fs::write(&p, &glb[..n]).unwrap();
        let e = err(&p);
        assert!(e.starts_with(&format!("{}", p.display())), "{n}: {e}");
    }
    // JSON syntax: the line and column
    let text = std::fs::read_to_string(wild("khronos/Box.gltf")).unwrap();
    std::fs::write(
        d.join("bad.gltf"),
        text.replacen("\"nodes\": [", "\"nodes\": [,", 1),
    )
    .unwrap();
    let e = err(&d.join("bad.gltf"));
    assert!(
        e.contains("bad.gltf:9:23:") && e.contains("invalid glTF JSON"),
        "{e}"
    );
    // a GLB under another name is sniffed by its magic
    std::fs::write(d.join("box.bin3d"), &glb).unwrap();
    assert_eq!(
        mesh::load(&d.join("box.bin3d")).unwrap().triangles.len(),
        12
    );
    // Draco-compressed geometry is refused with what to do
    std::fs::write(
        d.join("draco.gltf"),
        text.replacen("{", "{\"extensionsUsed\": [\"KHR_draco_mesh_compression\"], \"extensionsRequired\": [\"KHR_draco_mesh_compression\"],", 1),
    )
    .unwrap();
    let e = err(&d.join("draco.gltf"));
    assert!(
        e.contains("requires the extension `KHR_draco_mesh_compression`")
            && e.contains("re-export"),
        "{e}"
    );
}

/// `irsig check` takes a scene with a glTF object and reports its
/// triangles.
#[test]
fn check_reports_a_gltf_object() {
    let dir = tempfile::tempdir().unwrap();
    let objects = vec![format!(
        "{}\nmaterials = {{ \"*\" = \"concrete\" }}",
        file_key("gltf-rs/box_sparse.glb")
    )];
    let scene = scene_with(dir.path(), &objects);
    let (code, out, err) = common::irsig_out(&["check", scene.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    let all = format!("{out}{err}");
    assert!(all.contains("box_sparse"), "{all}");
    assert!(
        all.contains("morph targets are ignored") && all.contains("animations are ignored"),
        "{all}"
    );
}
