//! Standing objects on the terrain (`z = "terrain"`, `anchor`, `align`;
//! src/scene/placement.rs): the ground look-ups against analytic planes
//! and ridges (exact to 1e-12 m), holes and edges, the standing rules on a
//! plane; then through the scene loader on the terrain-km DEM, against
//! the loaded terrain mesh's own heights.

use std::path::{Path, PathBuf};

use glam::{DAffine3, DVec3};
use irsig::scene::mesh::Mesh;
use irsig::scene::placement::{Ground, Stand, stand};
use irsig::scene::{Align, Anchor};

/// A terrain of n × n cells of `cell` m over [0, n·cell]², heights h(x, y).
fn terrain(n: usize, cell: f64, h: impl Fn(f64, f64) -> f64) -> Mesh {
    let mut m = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 * cell, j as f64 * cell);
            m.positions.push([x, y, h(x, y)]);
        }
    }
    let v = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            let q = [v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)];
            m.triangles.push([q[0], q[1], q[2]]);
            m.triangles.push([q[0], q[2], q[3]]);
        }
    }
    m
}

/// A unit cube [−0.5, 0.5]² × [0, 1] (12 triangles).
fn cube() -> Mesh {
    let mut m = Mesh::default();
    for k in 0..8 {
        m.positions.push([
            if k & 1 == 0 { -0.5 } else { 0.5 },
            if k & 2 == 0 { -0.5 } else { 0.5 },
            if k & 4 == 0 { 0.0 } else { 1.0 },
        ]);
    }
    m.triangles = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    m
}

#[test]
fn heights_are_exact_on_planes_and_missing_off_the_terrain() {
    // A plane z = 2 + 0.1 x − 0.05 y is reproduced exactly by the mesh.
    let t = [terrain(20, 5.0, |x, y| 2.0 + 0.1 * x - 0.05 * y)];
    let g = Ground::new(&t, [0.0; 3]);
    for (x, y) in [(0.0, 0.0), (37.3, 61.9), (100.0, 100.0), (12.5, 87.5)] {
        let (z, n) = g.at(x, y).unwrap();
        assert!(
            (z - (2.0 + 0.1 * x - 0.05 * y)).abs() < 1e-12,
            "{x} {y} {z}"
        );
        let want = DVec3::new(-0.1, 0.05, 1.0).normalize();
        assert!((n - want).length() < 1e-12);
    }
    assert_eq!(g.at(-0.1, 50.0), None);
    assert_eq!(g.at(50.0, 100.1), None);
    // The frame's origin is taken off.
    let t2 = [terrain(4, 10.0, |_, _| 7.0)];
    let g2 = Ground::new(&t2, [10.0, 10.0, 5.0]);
    assert!((g2.at(0.0, 0.0).unwrap().0 - 2.0).abs() < 1e-12);
    assert_eq!(g2.at(-10.5, 0.0), None);
}

/// Two overlapping terrains: the higher one is the ground; none: no ground.
#[test]
fn overlapping_terrains_give_the_highest_and_none_gives_nothing() {
    let t = [
        terrain(4, 10.0, |_, _| 1.0),
        terrain(2, 10.0, |x, _| 3.0 + 0.01 * x),
    ];
    let g = Ground::new(&t, [0.0; 3]);
    assert!((g.at(5.0, 5.0).unwrap().0 - 3.05).abs() < 1e-12);
    assert!((g.at(35.0, 5.0).unwrap().0 - 1.0).abs() < 1e-12);
    let none: [Mesh; 0] = [];
    let g = Ground::new(&none, [0.0; 3]);
    assert_eq!(g.at(0.0, 0.0), None);
    assert_eq!(g.under([0.0, 0.0], [1.0, 1.0]), Err([0.5, 0.5]));
}

#[test]
fn the_lowest_point_under_a_footprint_is_exact() {
    // A ridge z = |x − 50| sampled every 10 m; the box [42, 61] × [0, 5]
    // reaches down to the vertex at x = 50 (z = 0) ... and a box off the
    // vertices, [52, 58], has its minimum on its edge x = 52: z = 2.
    let t = [terrain(10, 10.0, |x, _| (x - 50.0).abs())];
    let g = Ground::new(&t, [0.0; 3]);
    let u = g.under([42.0, 0.0], [61.0, 5.0]).unwrap();
    assert!(u.min_z_m.abs() < 1e-12, "{u:?}");
    let u = g.under([52.0, 3.0], [58.0, 7.0]).unwrap();
    assert!((u.min_z_m - 2.0).abs() < 1e-12, "{u:?}");
    assert!((u.normal - DVec3::new(-1.0, 0.0, 1.0).normalize()).length() < 1e-12);
    // Symmetric box: mean normal straight up.
    let u = g.under([40.0, 0.0], [60.0, 5.0]).unwrap();
    assert!((u.normal - DVec3::Z).length() < 1e-12, "{u:?}");
    // Past the edge: the corner that misses is named.
    assert_eq!(g.under([95.0, 0.0], [105.0, 5.0]), Err([105.0, 0.0]));
}

#[test]
fn a_hole_under_the_footprint_is_found() {
    let mut t = terrain(10, 10.0, |_, _| 0.0);
    // Remove cell (4, 4)'s two triangles: a 10 m hole at [40, 50]².
    let cell = 4 * 10 + 4;
    t.triangles.drain(2 * cell..2 * cell + 2);
    let t = [t];
    let g = Ground::new(&t, [0.0; 3]);
    let e = g.under([35.0, 35.0], [55.0, 55.0]).unwrap_err();
    assert!(
        (40.0..=50.0).contains(&e[0]) && (40.0..=50.0).contains(&e[1]),
        "{e:?}"
    );
    assert!(g.under([10.0, 10.0], [30.0, 30.0]).is_ok());
}

#[test]
fn stands_on_base_origin_and_slope() {
    let slope = 0.2;
    let t = [terrain(20, 5.0, |x, _| slope * x)];
    let g = Ground::new(&t, [0.0; 3]);
    let m = cube();
    let at = |x: f64, y: f64, z: f64| DAffine3::from_translation(DVec3::new(x, y, z));
    let up = |xf: &DAffine3| {
        let p = xf.transform_point3(DVec3::ZERO);
        (p, xf.transform_vector3(DVec3::Z))
    };
    // Base: the lowest corner of the footprint, x = 49.5, holds the base.
    let s = Stand {
        anchor: Anchor::Base,
        align: Align::Upright,
        offset_m: 0.0,
    };
    let xf = stand(&m, at(50.0, 50.0, 123.0), &s, &g).unwrap();
    assert!((up(&xf).0.z - slope * 49.5).abs() < 1e-12);
    // Origin anchor, 2 m above the ground.
    let s = Stand {
        anchor: Anchor::Origin,
        offset_m: 2.0,
        ..s
    };
    let xf = stand(&m, at(50.0, 50.0, -7.0), &s, &g).unwrap();
    assert!((up(&xf).0.z - (slope * 50.0 + 2.0)).abs() < 1e-12);
    // Slope: up follows the normal, the base centre sits on the ground.
    for anchor in [Anchor::Base, Anchor::Origin] {
        let s = Stand {
            anchor,
            align: Align::Slope,
            offset_m: 0.0,
        };
        let xf = stand(&m, at(50.0, 50.0, 3.0), &s, &g).unwrap();
        let (p, u) = up(&xf);
        assert!((u - DVec3::new(-slope, 0.0, 1.0).normalize()).length() < 1e-12);
        assert!((p.z - slope * p.x).abs() < 1e-9, "{anchor:?} {p}");
        // Every bottom corner touches the plane.
        for k in 0..4 {
            let q = xf.transform_point3(DVec3::from(m.positions[k]));
            assert!((q.z - slope * q.x).abs() < 1e-9, "{q}");
        }
    }
    // Off the terrain: the origin, or a footprint reaching past the edge.
    let e = stand(&m, at(200.0, 50.0, 0.0), &s, &g).unwrap_err();
    assert_eq!((e.what, e.at_m), ("its origin", [200.0, 50.0]));
    let s = Stand {
        anchor: Anchor::Base,
        ..s
    };
    let e = stand(&m, at(99.8, 50.0, 0.0), &s, &g).unwrap_err();
    assert_eq!((e.what, e.at_m), ("its footprint", [100.3, 49.5]));
}

// ------------------------------------------------- through the scene loader

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `dir/scene.toml`: terrain-km's site, weather and sensor, a 600 m patch
/// of its DEM meshed at 20 m (object `terrain`, last), and the `[[object]]`
/// bodies `objects`.
fn terrain_scene(dir: &Path, objects: &[&str]) -> PathBuf {
    let km = std::fs::read_to_string(root().join("scenes/terrain-km/scene.toml")).unwrap();
    let head = &km[..km.find("[[terrain]]").unwrap()];
    let head = head
        .replace(
            "[\"../materials.toml\"]",
            &format!("[\"{}\"]", root().join("scenes/materials.toml").display()),
        )
        .replace("allow = [\"..\"]", "allow = [\"/\"]");
    let mut s = format!(
        "{head}[[terrain]]\nname = \"terrain\"\nfile = \"{}\"\nextent_m = 600.0\n\
         resolution_m = 20.0\nmaterial = \"grass_irrigated\"\n",
        root()
            .join("scenes/terrain-km/dem/terrain-utm18n.tif")
            .display()
    );
    for o in objects {
        s.push_str(&format!("[[object]]\n{o}\n"));
    }
    let p = dir.join("scene.toml");
    std::fs::write(&p, s).unwrap();
    p
}

fn vehicle() -> String {
    format!(
        "file = \"{}\"",
        root().join("scenes/airfield/obj/vehicle.obj").display()
    )
}

/// The height of the loaded terrain mesh (object `obj`) at world (x, y)
/// (as tests/terrain.rs reads it: the triangle holding the point).
fn mesh_z(s: &irsig::scene::LoadedScene, obj: usize, x: f64, y: f64) -> Option<f64> {
    let o = &s.objects[obj];
    let (x, y) = (x - s.frame.origin_m[0], y - s.frame.origin_m[1]);
    let first = o.first_triangle as usize;
    for t in &s.triangles[first..first + o.triangle_count as usize] {
        let p = t.map(|i| s.positions[i as usize].map(f64::from));
        let d =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        let b1 = ((x - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (y - p[0][1])) / d;
        let b2 = ((p[1][0] - p[0][0]) * (y - p[0][1]) - (x - p[0][0]) * (p[1][1] - p[0][1])) / d;
        if b1 >= -1e-9 && b2 >= -1e-9 && b1 + b2 <= 1.0 + 1e-9 {
            let z = p[0][2] + b1 * (p[1][2] - p[0][2]) + b2 * (p[2][2] - p[0][2]);
            return Some(z + s.frame.origin_m[2]);
        }
    }
    None
}

/// The world positions of object `k`'s vertices.
fn vertices(s: &irsig::scene::LoadedScene, k: usize) -> Vec<[f64; 3]> {
    let o = &s.objects[k];
    let first = o.first_triangle as usize;
    s.triangles[first..first + o.triangle_count as usize]
        .iter()
        .flatten()
        .map(|&i| s.frame.to_world(s.positions[i as usize].map(f64::from)))
        .collect()
}

/// The lowest terrain height under an object's footprint, sampled on a
/// 61 × 61 grid (the exact minimum is at most slope × 5 cm lower).
fn lowest_ground(s: &irsig::scene::LoadedScene, t: usize, k: usize) -> f64 {
    let (lo, hi) = (s.objects[k].bounds_min_m, s.objects[k].bounds_max_m);
    let mut g = f64::INFINITY;
    for j in 0..=60 {
        for i in 0..=60 {
            let x = lo[0] + (hi[0] - lo[0]) * i as f64 / 60.0;
            let y = lo[1] + (hi[1] - lo[1]) * j as f64 / 60.0;
            g = g.min(mesh_z(s, t, x, y).expect("on the terrain"));
        }
    }
    g
}

/// `z = "terrain"` stands objects on the meshed DEM: the base on the
/// lowest ground under the footprint;
/// `anchor = "origin"` with z 1.5 puts the model's origin 1.5 m above the
/// ground under it (measured against the same model placed at z = 0); a
/// `[[object.instance]]` may stand while its sibling keeps its z; with
/// `align = "slope"` a 12 m box's lowest corner touches the ground and none
/// is below it.
#[test]
fn objects_stand_on_the_terrain_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let v = vehicle();
    let (x, y) = (113.0, -47.0);
    let box_glb = root().join("tests/data/wild/meshes/trimesh/box.glb");
    let p = terrain_scene(
        dir.path(),
        &[
            &format!("name = \"base\"\n{v}\nz = \"terrain\"\ntranslate_m = [{x}, {y}, 0.0]"),
            &format!("name = \"flat\"\n{v}\ntranslate_m = [{x}, {y}, 0.0]"),
            &format!(
                "name = \"origin\"\n{v}\nz = \"terrain\"\nanchor = \"origin\"\n\
                 translate_m = [{x}, {y}, 1.5]\nrotate_deg = [0, 0, 30]"
            ),
            &format!(
                "name = \"pair\"\n{v}\n[[object.instance]]\ntranslate_m = [-200, 150, 0]\n\
                 z = \"terrain\"\n[[object.instance]]\ntranslate_m = [-180, 150, 40]"
            ),
            &format!(
                "name = \"box\"\nfile = \"{}\"\nmaterials = {{ \"*\" = \"concrete\" }}\n\
                 scale = 12.0\nz = \"terrain\"\nalign = \"slope\"\ntranslate_m = [-150, -220, 0]",
                box_glb.display()
            ),
        ],
    );
    let s = irsig::scene::load(&p).unwrap_or_else(|e| panic!("{e}"));
    let idx = |n: &str| s.objects.iter().position(|o| o.name == n).unwrap();
    let t = idx("terrain");

    let b = idx("base");
    let (lo, g) = (s.objects[b].bounds_min_m[2], lowest_ground(&s, t, b));
    assert!(lo <= g + 1e-3 && lo > g - 5e-3, "base {lo} m, ground {g} m");

    // The origin variant: its lowest point is the flat one's (rotation
    // about z keeps it) moved by the ground under the origin + 1.5 m.
    let (f, o) = (idx("flat"), idx("origin"));
    let want = s.objects[f].bounds_min_m[2] + mesh_z(&s, t, x, y).unwrap() + 1.5;
    let got = s.objects[o].bounds_min_m[2];
    assert!((got - want).abs() < 1e-3, "origin: {got} m, want {want} m");

    let (p1, p2) = (idx("pair#1"), idx("pair#2"));
    let (lo1, g1) = (s.objects[p1].bounds_min_m[2], lowest_ground(&s, t, p1));
    assert!(
        lo1 <= g1 + 1e-3 && lo1 > g1 - 5e-3,
        "pair#1 {lo1} m, ground {g1} m"
    );
    let lo2 = s.objects[p2].bounds_min_m[2];
    assert!((lo2 - 40.0).abs() < 1e-3, "pair#2 {lo2} m");

    let k = idx("box");
    let d: Vec<f64> = vertices(&s, k)
        .iter()
        .map(|p| p[2] - mesh_z(&s, t, p[0], p[1]).unwrap())
        .collect();
    let dmin = d.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(
        dmin.abs() < 0.03,
        "box: lowest vertex {dmin} m from the ground"
    );
}

/// Standing where there is no terrain is an error at the `z` key naming
/// the object, the point and the terrains' cover; so is a scene without
/// `[[terrain]]`, and an `anchor`/`align` without `z = "terrain"`.
#[test]
fn standing_without_terrain_under_it_is_an_error_at_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let v = vehicle();
    let p = terrain_scene(
        dir.path(),
        &[&format!(
            "name = \"car\"\n{v}\n[[object.instance]]\ntranslate_m = [0, 0, 0]\n\
             [[object.instance]]\ntranslate_m = [299, 0, 0]\nz = \"terrain\""
        )],
    );
    let e = irsig::scene::load(&p).unwrap_err().to_string();
    let text = std::fs::read_to_string(&p).unwrap();
    let line = text.lines().position(|l| l == "z = \"terrain\"").unwrap() + 1;
    assert!(e.starts_with(&format!("{}:{line}:", p.display())), "{e}");
    assert!(
        e.contains("object `car#2` stands on the terrain (`z = \"terrain\"`), but there is no terrain under its footprint at scene (300.2, ")
            && e.contains("the terrains cover x -300.0 to 300.0 m, y -300.0 to 300.0 m"),
        "{e}"
    );

    // No terrain at all.
    let text = std::fs::read_to_string(&p).unwrap();
    let cut = text[..text.find("[[terrain]]").unwrap()].to_string()
        + &text[text.find("[[object]]").unwrap()..];
    std::fs::write(&p, cut).unwrap();
    let e = irsig::scene::load(&p).unwrap_err().to_string();
    assert!(e.contains("but the scene has no `[[terrain]]`"), "{e}");

    // `anchor` without `z`.
    let p = terrain_scene(
        dir.path(),
        &[&format!("name = \"car\"\n{v}\nanchor = \"origin\"")],
    );
    let e = irsig::scene::load(&p).unwrap_err().to_string();
    assert!(
        e.contains(
            "`anchor` says how an object stands on the terrain, but `z = \"terrain\"` is not set"
        ),
        "{e}"
    );
    // An unknown value names the choices.
    let p = terrain_scene(
        dir.path(),
        &[&format!("name = \"car\"\n{v}\nz = \"ground\"")],
    );
    let e = irsig::scene::load(&p).unwrap_err().to_string();
    assert!(e.contains("expected `terrain`"), "{e}");
}
