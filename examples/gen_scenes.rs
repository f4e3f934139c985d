//! Generates the OBJ geometry of the sample scenes in `scenes/`:
//! `cargo run --example gen_scenes` (rewrites scenes/*/obj/*.obj and
//! scenes/terrain-km/scene.toml and dem/*.tif; the airfield and plate scene files and
//! scenes/materials.toml are hand-written).
//!
//! Coordinates: metres, local ENU (x east, y north, z up). Models are built
//! with their nose/front towards +y (north). Faces are wound
//! counter-clockwise seen from outside (outward normals).

use std::fmt::Write as _;
use std::path::Path;

type V3 = [f64; 3];

/// A mesh being built: vertices and named parts with materials.
#[derive(Default)]
struct Mesh {
    v: Vec<V3>,
    /// (part name, material, faces as vertex indices)
    parts: Vec<(String, String, Vec<Vec<usize>>)>,
}

impl Mesh {
    fn part(&mut self, name: &str, mat: &str) {
        self.parts
            .push((name.to_string(), mat.to_string(), Vec::new()));
    }
    fn vert(&mut self, p: V3) -> usize {
        self.v.push(p);
        self.v.len() - 1
    }
    fn face(&mut self, f: Vec<usize>) {
        self.parts.last_mut().expect("part").2.push(f);
    }
    fn quad(&mut self, a: V3, b: V3, c: V3, d: V3) {
        let i = [a, b, c, d].map(|p| self.vert(p));
        self.face(i.to_vec());
    }
    fn tris(&self) -> usize {
        self.parts
            .iter()
            .flat_map(|p| &p.2)
            .map(|f| f.len() - 2)
            .sum()
    }

    /// Axis-aligned box; `bottom`: include the bottom face.
    fn boxx(&mut self, lo: V3, hi: V3, bottom: bool) {
        let [x0, y0, z0] = lo;
        let [x1, y1, z1] = hi;
        self.quad([x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]); // top
        self.quad([x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]); // south
        self.quad([x1, y1, z0], [x0, y1, z0], [x0, y1, z1], [x1, y1, z1]); // north
        self.quad([x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]); // east
        self.quad([x0, y1, z0], [x0, y0, z0], [x0, y0, z1], [x0, y1, z1]); // west
        if bottom {
            self.quad([x0, y1, z0], [x1, y1, z0], [x1, y0, z0], [x0, y0, z0]);
        }
    }

    /// Horizontal grid of nx×ny quads facing up.
    fn grid(&mut self, lo: [f64; 2], hi: [f64; 2], z: f64, nx: usize, ny: usize) {
        let base = self.v.len();
        for j in 0..=ny {
            for i in 0..=nx {
                let x = lo[0] + (hi[0] - lo[0]) * i as f64 / nx as f64;
                let y = lo[1] + (hi[1] - lo[1]) * j as f64 / ny as f64;
                self.vert([x, y, z]);
            }
        }
        let id = |i: usize, j: usize| base + j * (nx + 1) + i;
        for j in 0..ny {
            for i in 0..nx {
                self.face(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }

    /// A raised slab: top grid at z, and four vertical edge faces down to 0.
    fn slab(&mut self, lo: [f64; 2], hi: [f64; 2], z: f64, nx: usize, ny: usize) {
        self.grid(lo, hi, z, nx, ny);
        let (a, b) = ([lo[0], lo[1], 0.0], [hi[0], hi[1], z]);
        let [x0, y0, z0] = a;
        let [x1, y1, z1] = b;
        self.quad([x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1]);
        self.quad([x1, y1, z0], [x0, y1, z0], [x0, y1, z1], [x1, y1, z1]);
        self.quad([x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [x1, y0, z1]);
        self.quad([x0, y1, z0], [x0, y0, z0], [x0, y0, z1], [x0, y1, z1]);
    }

    /// Vertical cylinder (n sides) from z0 to z1, with a top cap (n-gon).
    fn cylinder_z(&mut self, c: [f64; 2], r: f64, z0: f64, z1: f64, n: usize) {
        let ring = |z: f64, m: &mut Mesh| -> Vec<usize> {
            (0..n)
                .map(|k| {
                    let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                    m.vert([c[0] + r * a.cos(), c[1] + r * a.sin(), z])
                })
                .collect()
        };
        let lo = ring(z0, self);
        let hi = ring(z1, self);
        for k in 0..n {
            let k1 = (k + 1) % n;
            self.face(vec![lo[k], lo[k1], hi[k1], hi[k]]);
        }
        self.face(hi.clone());
    }

    /// A body of revolution along +y: stations (y, radius) with centre
    /// height zc, n sides; zero radius at an end gives a point (cone tip).
    fn loft_y(&mut self, x: f64, zc: f64, stations: &[(f64, f64)], n: usize) {
        let rings: Vec<Vec<usize>> = stations
            .iter()
            .map(|&(y, r)| {
                if r == 0.0 {
                    vec![self.vert([x, y, zc])]
                } else {
                    (0..n)
                        .map(|k| {
                            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                            self.vert([x + r * a.cos(), y, zc + r * a.sin()])
                        })
                        .collect()
                }
            })
            .collect();
        for w in rings.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            for k in 0..n {
                let k1 = (k + 1) % n;
                // the ring angle runs from +x towards +z, so a[k], b[k],
                // b[k+1], a[k+1] is counter-clockwise seen from outside
                match (a.len(), b.len()) {
                    (1, _) => self.face(vec![a[0], b[k], b[k1]]),
                    (_, 1) => self.face(vec![a[k], b[0], a[k1]]),
                    _ => self.face(vec![a[k], b[k], b[k1], a[k1]]),
                }
            }
        }
        // flat caps where an end ring has a radius: the first faces -y
        // (ring order is counter-clockwise seen from -y), the last +y
        if let Some(first) = rings.first().filter(|r| r.len() > 1) {
            self.face(first.clone());
        }
        if let Some(last) = rings.last().filter(|r| r.len() > 1) {
            let mut f = last.clone();
            f.reverse();
            self.face(f);
        }
    }

    /// A thin tapered plate (wing, stabiliser) from root to tip: root
    /// leading/trailing edge y, tip offset, span along ±x, thickness t.
    #[allow(clippy::too_many_arguments)]
    fn wing(
        &mut self,
        root_x: f64,
        tip_x: f64,
        z_root: f64,
        z_tip: f64,
        root: [f64; 2],
        tip: [f64; 2],
        t: f64,
    ) {
        // root: [y_trailing, y_leading]; tip likewise
        let h = t / 2.0;
        let p = [
            [root_x, root[0], z_root - h],
            [root_x, root[1], z_root - h],
            [tip_x, tip[1], z_tip - h],
            [tip_x, tip[0], z_tip - h],
            [root_x, root[0], z_root + h],
            [root_x, root[1], z_root + h],
            [tip_x, tip[1], z_tip + h],
            [tip_x, tip[0], z_tip + h],
        ];
        let i: Vec<usize> = p.iter().map(|&q| self.vert(q)).collect();
        let right = tip_x > root_x;
        let mut faces = vec![
            vec![i[4], i[7], i[6], i[5]], // top (for right wing)
            vec![i[0], i[1], i[2], i[3]], // bottom
            vec![i[1], i[5], i[6], i[2]], // leading edge
            vec![i[0], i[3], i[7], i[4]], // trailing edge
            vec![i[3], i[2], i[6], i[7]], // tip
        ];
        if !right {
            for f in &mut faces {
                f.reverse();
            }
        }
        for f in faces {
            self.face(f);
        }
    }

    /// A vertical fin in the x = x0 plane: root chord [y0, y1] at z0, tip
    /// chord [y2, y3] at z1, thickness t.
    fn fin(&mut self, x0: f64, root: [f64; 2], tip: [f64; 2], z0: f64, z1: f64, t: f64) {
        let h = t / 2.0;
        let pts = |x: f64| {
            [
                [x, root[0], z0],
                [x, root[1], z0],
                [x, tip[1], z1],
                [x, tip[0], z1],
            ]
        };
        let w: Vec<usize> = pts(x0 - h).iter().map(|&q| self.vert(q)).collect();
        let e: Vec<usize> = pts(x0 + h).iter().map(|&q| self.vert(q)).collect();
        self.face(vec![e[0], e[1], e[2], e[3]]); // east side
        self.face(vec![w[3], w[2], w[1], w[0]]); // west side
        self.face(vec![w[1], w[2], e[2], e[1]]); // leading edge
        self.face(vec![w[3], w[0], e[0], e[3]]); // trailing edge
        self.face(vec![w[2], w[3], e[3], e[2]]); // top
    }

    /// Applies a map to all vertices from index `from`.
    fn map_from(&mut self, from: usize, f: impl Fn(V3) -> V3) {
        for p in &mut self.v[from..] {
            *p = f(*p);
        }
    }

    fn write(&self, path: &Path, header: &str) {
        let mut s = String::new();
        for l in header.lines() {
            let _ = writeln!(s, "# {l}");
        }
        let _ = writeln!(
            s,
            "# {} vertices, {} faces, {} triangles",
            self.v.len(),
            self.parts.iter().map(|p| p.2.len()).sum::<usize>(),
            self.tris()
        );
        for p in &self.v {
            let _ = writeln!(s, "v {} {} {}", fmt(p[0]), fmt(p[1]), fmt(p[2]));
        }
        for (name, mat, faces) in &self.parts {
            if faces.is_empty() {
                continue;
            }
            let _ = writeln!(s, "o {name}\nusemtl {mat}");
            for f in faces {
                let idx: Vec<String> = f.iter().map(|i| (i + 1).to_string()).collect();
                let _ = writeln!(s, "f {}", idx.join(" "));
            }
        }
        std::fs::create_dir_all(path.parent().expect("dir")).expect("mkdir");
        std::fs::write(path, s).expect("write obj");
        println!("{}: {} triangles", path.display(), self.tris());
    }
}

fn fmt(x: f64) -> String {
    let r = (x * 1e4).round() / 1e4;
    let s = format!("{r:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    if s == "-0" { "0".into() } else { s }
}

// ---------------------------------------------------------------- airfield

/// Large transport aircraft (~44 m long, 40 m span), nose +y, origin on
/// the ground under the fuselage centre.
fn large_aircraft() -> Mesh {
    let mut m = Mesh::default();
    let zc = 4.0;
    m.part("fuselage", "aircraft_skin");
    m.loft_y(
        0.0,
        zc,
        &[
            (-22.0, 0.0),
            (-20.0, 0.9),
            (-17.0, 1.8),
            (-13.0, 2.5),
            (-8.0, 2.8),
            (-3.0, 2.8),
            (2.0, 2.8),
            (7.0, 2.8),
            (11.0, 2.7),
            (14.0, 2.4),
            (17.0, 1.8),
            (19.0, 1.0),
            (20.0, 0.5),
        ],
        12,
    );
    m.part("nose_glass", "glass");
    m.loft_y(0.0, zc + 0.2, &[(20.0, 0.5), (21.2, 0.0)], 12);
    m.part("wings", "aircraft_skin");
    for s in [1.0, -1.0] {
        m.wing(
            s * 2.5,
            s * 20.0,
            zc - 1.6,
            zc - 0.8,
            [-4.0, 3.5],
            [-6.0, -3.5],
            0.45,
        );
    }
    m.part("horizontal_tail", "aircraft_skin");
    for s in [1.0, -1.0] {
        m.wing(
            s * 0.8,
            s * 8.0,
            zc + 0.5,
            zc + 0.9,
            [-21.5, -17.5],
            [-22.5, -20.5],
            0.25,
        );
    }
    m.part("vertical_tail", "aircraft_skin");
    m.fin(
        0.0,
        [-21.5, -15.0],
        [-23.0, -20.5],
        zc + 2.0,
        zc + 10.0,
        0.35,
    );
    m.part("engines", "aircraft_skin");
    for x in [-12.0, -6.5, 6.5, 12.0] {
        m.loft_y(
            x,
            zc - 2.4,
            &[(-2.5, 0.6), (-1.0, 0.9), (1.5, 0.95), (2.5, 0.95)],
            8,
        );
    }
    m.part("engine_inlets", "bare_aluminium");
    for x in [-12.0, -6.5, 6.5, 12.0] {
        m.loft_y(x, zc - 2.4, &[(2.5, 0.95), (2.6, 0.7)], 8);
    }
    m.part("wheels", "rubber");
    for (x, y) in [(0.0, 15.0), (-3.5, -2.0), (3.5, -2.0)] {
        m.boxx([x - 0.6, y - 0.7, 0.0], [x + 0.6, y + 0.7, 1.4], false);
    }
    m
}

/// Small jet (~15 m long, 11 m span), nose +y.
fn small_aircraft() -> Mesh {
    let mut m = Mesh::default();
    let zc = 1.6;
    m.part("fuselage", "aircraft_skin");
    m.loft_y(
        0.0,
        zc,
        &[
            (-7.5, 0.25),
            (-6.0, 0.6),
            (-3.0, 0.9),
            (0.0, 1.0),
            (3.0, 1.0),
            (5.0, 0.8),
            (6.5, 0.45),
            (7.5, 0.0),
        ],
        12,
    );
    m.part("canopy", "glass");
    m.loft_y(
        0.0,
        zc + 0.8,
        &[(1.5, 0.0), (2.5, 0.45), (4.0, 0.4), (5.0, 0.0)],
        8,
    );
    m.part("wings", "aircraft_skin");
    for s in [1.0, -1.0] {
        m.wing(
            s * 0.8,
            s * 5.6,
            zc - 0.5,
            zc - 0.3,
            [-1.5, 1.5],
            [-1.8, -0.2],
            0.2,
        );
    }
    m.part("tail", "aircraft_skin");
    for s in [1.0, -1.0] {
        m.wing(
            s * 0.3,
            s * 2.4,
            zc + 0.3,
            zc + 0.35,
            [-7.3, -5.8],
            [-7.6, -6.8],
            0.1,
        );
    }
    m.fin(0.0, [-7.3, -5.5], [-7.8, -7.0], zc + 0.6, zc + 3.0, 0.15);
    m.part("wheels", "rubber");
    for (x, y) in [(0.0, 4.5), (-1.2, -0.5), (1.2, -0.5)] {
        m.boxx([x - 0.15, y - 0.3, 0.0], [x + 0.15, y + 0.3, 0.6], false);
    }
    m
}

/// Hangar: 80 m (x) × 60 m (y, door side south), arched roof, 8 m walls.
fn hangar() -> Mesh {
    let mut m = Mesh::default();
    let (hx, hy, wall, rise) = (40.0, 30.0, 8.0, 10.0);
    m.part("walls", "painted_steel");
    // end walls (north, south) under the arch; side walls east/west
    let n_arch = 24;
    let arch = |k: usize| -> (f64, f64) {
        let a = std::f64::consts::PI * k as f64 / n_arch as f64;
        (hx * a.cos(), wall + rise * a.sin())
    };
    for (y, outward_south) in [(-hy, true), (hy, false)] {
        // wall rectangle
        if outward_south {
            m.quad([-hx, y, 0.0], [hx, y, 0.0], [hx, y, wall], [-hx, y, wall]);
        } else {
            m.quad([hx, y, 0.0], [-hx, y, 0.0], [-hx, y, wall], [hx, y, wall]);
        }
        // arch gable as a polygon
        let mut f: Vec<usize> = (0..=n_arch)
            .map(|k| {
                let (x, z) = arch(k);
                m.vert([x, y, z])
            })
            .collect();
        // east -> over the top -> west is counter-clockwise seen from the
        // south; the north gable is seen from the other side
        if !outward_south {
            f.reverse();
        }
        m.face(f);
    }
    m.quad(
        [hx, -hy, 0.0],
        [hx, hy, 0.0],
        [hx, hy, wall],
        [hx, -hy, wall],
    );
    m.quad(
        [-hx, hy, 0.0],
        [-hx, -hy, 0.0],
        [-hx, -hy, wall],
        [-hx, hy, wall],
    );
    m.part("roof", "painted_steel_roof");
    let ny = 6;
    for j in 0..ny {
        let y0 = -hy + 2.0 * hy * j as f64 / ny as f64;
        let y1 = -hy + 2.0 * hy * (j + 1) as f64 / ny as f64;
        for k in 0..n_arch {
            let (xa, za) = arch(k);
            let (xb, zb) = arch(k + 1);
            // outward: normal away from the axis; order a(y0) a(y1) b(y1) b(y0)
            m.quad([xa, y0, za], [xa, y1, za], [xb, y1, zb], [xb, y0, zb]);
        }
    }
    m
}

fn fuel_tank() -> Mesh {
    let mut m = Mesh::default();
    m.part("shell", "fuel_tank");
    m.cylinder_z([0.0, 0.0], 6.0, 0.0, 9.0, 24);
    m
}

/// Truck (~8 m): cargo box, cab, engine hood (heated), wheels.
fn vehicle() -> Mesh {
    let mut m = Mesh::default();
    m.part("body", "painted_steel");
    m.boxx([-1.2, -4.0, 0.8], [1.2, 1.5, 3.2], true);
    m.boxx([-1.2, 1.7, 0.8], [1.2, 3.2, 2.9], true);
    m.part("hood", "vehicle_engine");
    m.boxx([-1.1, 3.2, 0.8], [1.1, 4.2, 1.9], true);
    m.part("windscreen", "glass");
    m.quad(
        [1.0, 3.21, 2.0],
        [-1.0, 3.21, 2.0],
        [-1.0, 3.21, 2.7],
        [1.0, 3.21, 2.7],
    );
    m.part("wheels", "rubber");
    for (x, y) in [(-1.05, 3.0), (1.05, 3.0), (-1.05, -2.5), (1.05, -2.5)] {
        m.boxx([x - 0.2, y - 0.5, 0.0], [x + 0.2, y + 0.5, 1.0], false);
    }
    m
}

fn control_tower() -> Mesh {
    let mut m = Mesh::default();
    m.part("shaft", "concrete_wall");
    m.boxx([-3.0, -3.0, 0.0], [3.0, 3.0, 18.0], false);
    m.part("cab_glass", "glass");
    m.boxx([-4.0, -4.0, 18.0], [4.0, 4.0, 21.0], true);
    m.part("cab_roof", "concrete_wall");
    m.boxx([-4.5, -4.5, 21.0], [4.5, 4.5, 21.6], true);
    m
}

fn office() -> Mesh {
    let mut m = Mesh::default();
    m.part("walls_roof", "concrete_wall");
    m.boxx([-15.0, -8.0, 0.0], [15.0, 8.0, 7.0], false);
    m.part("windows", "glass");
    for k in 0..5 {
        let x = -12.0 + 6.0 * k as f64;
        m.quad(
            [x, -8.02, 2.0],
            [x + 3.0, -8.02, 2.0],
            [x + 3.0, -8.02, 5.0],
            [x, -8.02, 5.0],
        );
    }
    m
}

fn crates() -> Mesh {
    let mut m = Mesh::default();
    m.part("crates", "wood");
    m.boxx([-1.0, -1.0, 0.0], [1.0, 1.0, 1.5], false);
    m.boxx([1.2, -1.0, 0.0], [3.2, 1.0, 1.5], false);
    m.boxx([0.1, -0.8, 1.5], [2.1, 0.8, 2.7], true);
    m
}

/// The flat airfield ground: grass field, runway, taxiway, apron, pond,
/// bare-soil patch, as separate objects (files).
fn airfield(root: &Path) -> usize {
    let hdr = "irsig sample scene `airfield` (the seed paper's demonstration scene)\n\
               generated by `cargo run --example gen_scenes`; metres, x east, y north, z up";
    let mut total = 0;
    let mut w = |name: &str, m: Mesh| {
        total += m.tris();
        m.write(&root.join("obj").join(format!("{name}.obj")), hdr);
    };
    // Grass field 700 m × 600 m.
    let mut g = Mesh::default();
    g.part("grass", "grass_irrigated");
    g.grid([-350.0, -300.0], [350.0, 300.0], 0.0, 22, 16);
    w("grass", g);
    // Runway (east-west) 600 m × 45 m asphalt, 0.15 m above the grass.
    let mut r = Mesh::default();
    r.part("runway", "asphalt");
    r.slab([-300.0, -172.5], [300.0, -127.5], 0.15, 32, 3);
    w("runway", r);
    // Taxiway north from the runway to the apron, 20 m wide.
    let mut t = Mesh::default();
    t.part("taxiway", "asphalt");
    t.slab([-10.0, -127.5], [10.0, -60.0], 0.15, 2, 6);
    w("taxiway", t);
    // Concrete apron 200 m × 120 m in 12.5 m × 15 m slabs.
    let mut a = Mesh::default();
    a.part("apron", "concrete");
    a.slab([-100.0, -60.0], [100.0, 60.0], 0.15, 16, 8);
    w("apron", a);
    // Pond (water) and bare-soil patch, a little above the grass.
    let mut p = Mesh::default();
    p.part("pond", "pond");
    let n = 20;
    let c = [200.0, 120.0];
    let ring: Vec<usize> = (0..n)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            p.vert([c[0] + 35.0 * a.cos(), c[1] + 22.0 * a.sin(), 0.05])
        })
        .collect();
    p.face(ring);
    w("pond", p);
    let mut s = Mesh::default();
    s.part("soil", "soil_bare");
    s.grid([-260.0, 80.0], [-180.0, 160.0], 0.05, 4, 4);
    w("soil_patch", s);
    w("hangar", hangar());
    w("aircraft_large", large_aircraft());
    w("aircraft_small", small_aircraft());
    w("fuel_tank", fuel_tank());
    w("vehicle", vehicle());
    w("control_tower", control_tower());
    w("office", office());
    w("crates", crates());
    total
}

// ------------------------------------------------------------------ plate

fn plate(root: &Path) {
    let hdr = "irsig sample scene `plate`: a tilted specular plate over a ground plane\n\
               generated by `cargo run --example gen_scenes`; metres, x east, y north, z up";
    let mut g = Mesh::default();
    g.part("ground", "concrete");
    g.grid([-20.0, -20.0], [20.0, 20.0], 0.0, 8, 8);
    g.write(&root.join("obj/ground.obj"), hdr);
    // 4 m × 4 m plate, centre (0, 0, 3), tilted 70° from horizontal,
    // facing south (normal (0, -sin 70°, cos 70°)); 0.02 m thick.
    let mut p = Mesh::default();
    p.part("plate", "painted_steel_roof");
    let from = p.v.len();
    p.boxx([-2.0, -2.0, -0.01], [2.0, 2.0, 0.01], true);
    let tilt = 70f64.to_radians();
    p.map_from(from, |[x, y, z]| {
        // rotate about x by +tilt: the top face normal (0,0,1) -> (0,-sin,cos)
        let (s, c) = (tilt.sin(), tilt.cos());
        [x, y * c - z * s, y * s + z * c + 3.0]
    });
    p.write(&root.join("obj/plate.obj"), hdr);
}

// ------------------------------------------------------------- terrain-km

/// Terrain height (m) at (x, y): a few gentle long-wavelength undulations.
fn terrain_z(x: f64, y: f64) -> f64 {
    6.0 * (x / 700.0).sin() * (y / 900.0).cos()
        + 4.0 * ((x + 2.0 * y) / 1300.0).sin()
        + 2.5 * ((x - y) / 420.0).cos()
}

/// The site of `terrain-km`.
fn terrain_site() -> irsig::sun::Site {
    irsig::sun::Site {
        latitude_deg: 43.1566,
        longitude_deg: -77.6088,
        elevation_m: 150.0,
    }
}

/// Writes a one-band f32 GeoTIFF in UTM (`crs`) of n×n north-up pixels of
/// `pixel_m` whose upper left corner is (`e0`, `n0`); `f` gives the value
/// at a pixel centre's scene point (x, y).
fn utm_geotiff(
    path: &Path,
    crs: &irsig::scene::georef::CrsInfo,
    (e0, n0, pixel_m, n): (f64, f64, f64, u32),
    (band, unit, what): (&str, &str, &str),
    f: impl Fn(f64, f64) -> f32,
) {
    use irsig::output::geotiff::{Band, Placement, write_geotiff};
    let site = terrain_site();
    let geo = irsig::scene::georef::Geo::new(&site, &irsig::scene::OutputCrs::Utm).expect("geo");
    let longlat = proj4rs::proj::Proj::from_proj_string("+proj=longlat +datum=WGS84 +no_defs")
        .expect("longlat");
    let utm = proj4rs::proj::Proj::from_proj_string(&crs.proj).expect("utm");
    let mut data = Vec::with_capacity((n * n) as usize);
    for r in 0..n {
        for c in 0..n {
            let mut q = (
                e0 + (c as f64 + 0.5) * pixel_m,
                n0 - (r as f64 + 0.5) * pixel_m,
                0.0,
            );
            proj4rs::transform::transform(&utm, &longlat, &mut q).expect("inverse UTM");
            let p = geo
                .scene_point(q.1.to_degrees(), q.0.to_degrees(), site.elevation_m)
                .expect("scene point");
            data.push(f(p[0], p[1]));
        }
    }
    let mut set = irsig::output::OutputSet::new(path).expect("output set");
    write_geotiff(
        &mut set,
        path,
        (n, n),
        &[Band {
            name: band,
            unit,
            data: &data,
        }],
        Some(crs),
        &Placement::Affine([e0, pixel_m, 0.0, n0, 0.0, -pixel_m]),
        &[(
            "source".to_string(),
            format!("irsig sample scene terrain-km: {what}; generated by `cargo run --example gen_scenes`"),
        )],
        &[],
    )
    .expect("write GeoTIFF");
    set.commit().expect("commit GeoTIFF");
    let size = std::fs::metadata(path).map_or(0, |m| m.len());
    println!(
        "{}: {n}x{n} pixels of {pixel_m} m, {size} bytes",
        path.display()
    );
}

fn terrain(root: &Path) {
    // The DEM and the land cover: GeoTIFFs in the site's UTM zone (18N)
    // covering the 4 km square of the scene with a margin for the grid
    // convergence (1.8°). Heights: site elevation + terrain_z at the pixel
    // centre's scene point; classes: 1 grass, 2 bare soil (fields of a
    // smooth pattern on the 150 x 150 grid of 26.67 m cells; the land-cover
    // pixels are half a cell, so each cell's centre finds its own class).
    let site = terrain_site();
    let crs = irsig::scene::georef::CrsInfo::utm(site.latitude_deg, site.longitude_deg);
    let geo = irsig::scene::georef::Geo::new(&site, &irsig::scene::OutputCrs::Utm).expect("geo");
    let [es, ns] = geo
        .map_xy(site.latitude_deg, site.longitude_deg)
        .expect("site UTM");
    let (e0, n0) = (
        (es / 10.0).round() * 10.0 - 2160.0,
        (ns / 10.0).round() * 10.0 + 2160.0,
    );
    let dem_path = root.join("dem/terrain-utm18n.tif");
    std::fs::create_dir_all(dem_path.parent().expect("dir")).expect("mkdir");
    utm_geotiff(
        &dem_path,
        &crs,
        (e0, n0, 30.0, 144),
        ("height", "m", "synthetic DEM, heights in the site's datum"),
        |x, y| (site.elevation_m + terrain_z(x, y)) as f32,
    );
    let (half, n) = (2000.0, 150usize);
    let cell = 2.0 * half / n as f64;
    let soil = |i: usize, j: usize| {
        let (x, y) = (i as f64, j as f64);
        ((x / 11.0).sin() * (y / 7.0).cos() + (x + y) / 300.0) > 0.75
    };
    utm_geotiff(
        &root.join("dem/landcover-utm18n.tif"),
        &crs,
        (e0, n0, cell / 2.0, 324),
        ("class", "", "synthetic land cover, 1 grass, 2 bare soil"),
        |x, y| {
            let (i, j) = ((x + half) / cell, (y + half) / cell);
            let inside = (0.0..n as f64).contains(&i) && (0.0..n as f64).contains(&j);
            if inside && soil(i as usize, j as usize) {
                2.0
            } else {
                1.0
            }
        },
    );
    // Objects sit on the DEM surface as the scene places it (sunk 0.5 m so
    // that a flat base never floats over the slope).
    let dem = irsig::scene::terrain::raster::read_raster(&dem_path).expect("read DEM");
    let surface = irsig::scene::terrain::Surface::new(&dem, &site).expect("surface");
    let ground_z = |x: f64, y: f64| surface.point(x, y).expect("inside the DEM")[2];

    let hdr = "irsig sample scene `terrain-km`: 4 km × 4 km of undulating ground\n\
               generated by `cargo run --example gen_scenes`; metres, x east, y north, z up";
    let mut b = Mesh::default();
    b.part("building", "concrete_wall");
    b.boxx([-10.0, -6.0, -2.0], [10.0, 6.0, 8.0], false);
    b.write(&root.join("obj/building.obj"), hdr);

    // Scene file with instances placed on the terrain.
    let mut s = String::new();
    s.push_str(
        "# irsig sample scene `terrain-km`: 4 km x 4 km of gently undulating grass and\n\
         # soil (150x150 cells, 45,000 triangles, ±12 m relief) with scattered\n\
         # buildings, fuel tanks and vehicles, for precision and scale tests\n\
         # (km-scale coordinates, long shadows, large footprints). The terrain\n\
         # is meshed from a DEM and a land-cover raster (GeoTIFFs in UTM 18N,\n\
         # dem/) that the generator writes from a synthetic height field.\n\
         # GENERATED by `cargo run --example gen_scenes`: edit the generator, not this file.\n\
         # Keys: docs/scene-format.md.\n\n\
         materials = [\"../materials.toml\"]\n\n\
         # The path policy (docs/reliability.md): a scene reads files in its own\n\
         # folder tree; the shared material library lies one folder up.\n\
         [files]\nallow = [\"..\"]\n\n\
         [site]\nname = \"Rochester NY (synthetic terrain)\"\nlatitude_deg = 43.1566\nlongitude_deg = -77.6088\n\
         elevation_m = 150.0\nutc_offset_h = -4.0\n\n\
         [time]\nlocal = 2001-08-08T14:00:00\n\n\
         [weather.constant]\nwind_m_s = 3.0\nair_min_c = 17.0\nair_max_c = 29.0\ndew_point_c = 14.0\ncloud_fraction = 0.1\n\n\
         [atmosphere]\nmodel = \"mid-latitude-summer\"\nvisibility_km = 23.0\n\n\
         [sensor]\nwidth_px = 1024\nheight_px = 1024\nfov_h_deg = 30.0\nband = \"lwir\"\n\n\
         [sensor.pose.altitude]\naltitude_m = 5000.0\nview_zenith_deg = 20.0\nazimuth_deg = 200.0\ntarget_m = [0.0, 0.0, 0.0]\n\n\
         [render]\nshadow_interval_min = 30.0\nhistory_hours = 24.0\n\n\
         [[terrain]]\nname = \"terrain\"\nfile = \"dem/terrain-utm18n.tif\"\nextent_m = 4000.0\n\
         resolution_m = 26.7\n\
         [terrain.land_cover]\nfile = \"dem/landcover-utm18n.tif\"\n\
         classes = { \"1\" = \"grass_irrigated\", \"2\" = \"soil_bare\" }\n",
    );
    let place = |s: &mut String, name: &str, file: &str, pts: &[(f64, f64, f64)]| {
        let _ = write!(s, "\n[[object]]\nname = \"{name}\"\nfile = \"{file}\"\n");
        for &(x, y, rot) in pts {
            // sink 0.5 m so the flat base never floats over the slope
            let z = ground_z(x, y) - 0.5;
            let _ = write!(
                s,
                "[[object.instance]]\ntranslate_m = [{}, {}, {}]\nrotate_deg = [0.0, 0.0, {}]\n",
                fmt(x),
                fmt(y),
                fmt(z),
                fmt(rot)
            );
        }
    };
    place(
        &mut s,
        "building",
        "obj/building.obj",
        &[
            (-1500.0, 1200.0, 0.0),
            (-300.0, 250.0, 30.0),
            (400.0, -700.0, 90.0),
            (1250.0, 900.0, 15.0),
            (1700.0, -1600.0, 45.0),
            (-900.0, -1300.0, 60.0),
        ],
    );
    place(
        &mut s,
        "fuel_tank",
        "../airfield/obj/fuel_tank.obj",
        &[
            (600.0, 500.0, 0.0),
            (630.0, 520.0, 0.0),
            (-1100.0, 300.0, 0.0),
        ],
    );
    place(
        &mut s,
        "vehicle",
        "../airfield/obj/vehicle.obj",
        &[
            (10.0, 20.0, 0.0),
            (35.0, -40.0, 90.0),
            (-800.0, 900.0, 135.0),
            (1500.0, -200.0, 270.0),
        ],
    );
    std::fs::write(root.join("scene.toml"), s).expect("write scene");
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let n = airfield(&root.join("airfield"));
    println!("airfield parts: {n} triangles (before instancing)");
    plate(&root.join("plate"));
    terrain(&root.join("terrain-km"));
}
