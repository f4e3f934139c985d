//! Generated meshes for tests, the cross-check and benchmarks: grids with
//! shared edges, boxes, thin slivers, degenerate triangles, km-scale
//! terrain, and a ~5,000-triangle benchmark scene.

use glam::Vec3;

/// A triangle soup being assembled.
#[derive(Clone, Debug, Default)]
pub struct MeshBuilder {
    /// Vertex positions, m.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

impl MeshBuilder {
    /// An empty mesh.
    pub fn new() -> Self {
        Self::default()
    }

    fn vertex(&mut self, p: Vec3) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }

    /// Adds one triangle (counter-clockwise seen from the normal side).
    pub fn triangle(&mut self, a: Vec3, b: Vec3, c: Vec3) -> &mut Self {
        let t = [self.vertex(a), self.vertex(b), self.vertex(c)];
        self.triangles.push(t);
        self
    }

    /// A horizontal grid of `nx × ny` cells (two triangles each, sharing
    /// vertices and edges) from `origin` spanning `size` in x and y, with
    /// height `z(x, y)`; normals up.
    pub fn grid(
        &mut self,
        origin: Vec3,
        size: (f32, f32),
        n: (usize, usize),
        z: impl Fn(f32, f32) -> f32,
    ) -> &mut Self {
        let (nx, ny) = n;
        let base = self.positions.len() as u32;
        for j in 0..=ny {
            for i in 0..=nx {
                let x = origin.x + size.0 * i as f32 / nx as f32;
                let y = origin.y + size.1 * j as f32 / ny as f32;
                self.positions.push(Vec3::new(x, y, origin.z + z(x, y)));
            }
        }
        let w = (nx + 1) as u32;
        for j in 0..ny as u32 {
            for i in 0..nx as u32 {
                let a = base + j * w + i;
                let (b, c, d) = (a + 1, a + w + 1, a + w);
                self.triangles.push([a, b, c]);
                self.triangles.push([a, c, d]);
            }
        }
        self
    }

    /// An axis-aligned closed box (12 triangles, outward normals, shared
    /// corner vertices).
    pub fn cuboid(&mut self, lo: Vec3, hi: Vec3) -> &mut Self {
        let base = self.positions.len() as u32;
        for k in 0..8 {
            let p = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            self.positions.push(p);
        }
        const FACES: [[u32; 4]; 6] = [
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
        ];
        for f in FACES {
            self.triangles.push([base + f[0], base + f[1], base + f[2]]);
            self.triangles.push([base + f[0], base + f[2], base + f[3]]);
        }
        self
    }

    /// Thin slivers: `count` triangles of length `len` and width `len·aspect`
    /// fanned around `center` in the horizontal plane.
    pub fn slivers(&mut self, center: Vec3, len: f32, aspect: f32, count: usize) -> &mut Self {
        for k in 0..count {
            let a = k as f32 / count as f32 * std::f32::consts::TAU;
            let d = Vec3::new(a.cos(), a.sin(), 0.0);
            let side = Vec3::new(-a.sin(), a.cos(), 0.0) * (len * aspect);
            self.triangle(center, center + d * len, center + d * len + side);
        }
        self
    }

    /// Degenerate triangles (zero area: repeated and collinear vertices).
    pub fn degenerate(&mut self, at: Vec3) -> &mut Self {
        self.triangle(at, at, at);
        self.triangle(at, at + Vec3::X, at + 2.0 * Vec3::X);
        self
    }

    /// The vertices and triangles built so far.
    pub fn finish(self) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        (self.positions, self.triangles)
    }
}

/// Tiny deterministic generator (SplitMix64) for reproducible meshes.
#[derive(Clone, Debug)]
pub struct SplitMix(pub u64);

impl SplitMix {
    /// The next 64-bit value of the sequence.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// The benchmark scene: a 200 m × 200 m ground grid (40×40 cells, 3,200
/// triangles) with 150 boxes (1,800 triangles) of 2-12 m: 5,000 triangles,
/// about the paper's 4,772 facets.
pub fn bench_scene() -> MeshBuilder {
    let mut m = MeshBuilder::new();
    m.grid(
        Vec3::new(-100.0, -100.0, 0.0),
        (200.0, 200.0),
        (40, 40),
        |x, y| 0.3 * (x * 0.05).sin() * (y * 0.04).cos(),
    );
    let mut rng = SplitMix(7);
    for _ in 0..150 {
        let c = Vec3::new(rng.unit() * 180.0 - 90.0, rng.unit() * 180.0 - 90.0, -0.5);
        let h = Vec3::new(
            1.0 + rng.unit() * 5.0,
            1.0 + rng.unit() * 5.0,
            2.0 + rng.unit() * 10.0,
        );
        m.cuboid(c - Vec3::new(h.x, h.y, 0.0), c + h);
    }
    m
}

/// A mixed test scene: shared-edge grid, boxes standing on it, slivers,
/// a coplanar overlapping pair and degenerate triangles.
pub fn mixed_scene() -> MeshBuilder {
    let mut m = MeshBuilder::new();
    m.grid(
        Vec3::new(-20.0, -20.0, 0.0),
        (40.0, 40.0),
        (16, 16),
        |_, _| 0.0,
    );
    m.cuboid(Vec3::new(-5.0, -3.0, 0.0), Vec3::new(2.0, 4.0, 6.0));
    m.cuboid(Vec3::new(6.0, 6.0, 0.0), Vec3::new(9.0, 12.0, 3.0));
    m.slivers(Vec3::new(-12.0, 10.0, 1.0), 6.0, 1e-3, 24);
    // Coplanar overlapping facets (z = 2 plane, two overlapping squares).
    let z = 2.0;
    m.triangle(
        Vec3::new(10.0, -15.0, z),
        Vec3::new(16.0, -15.0, z),
        Vec3::new(16.0, -9.0, z),
    );
    m.triangle(
        Vec3::new(12.0, -15.0, z),
        Vec3::new(18.0, -15.0, z),
        Vec3::new(18.0, -9.0, z),
    );
    m.degenerate(Vec3::new(0.0, 15.0, 1.0));
    m
}

/// `size_m` × `size_m` of gently undulating ground centred on the origin at
/// height `base_z`, `n × n` cells.
pub fn terrain(size_m: f32, n: usize, base_z: f32) -> MeshBuilder {
    let mut m = MeshBuilder::new();
    let h = size_m / 2.0;
    m.grid(
        Vec3::new(-h, -h, base_z),
        (size_m, size_m),
        (n, n),
        |x, y| 8.0 * (x / 900.0).sin() * (y / 1300.0).cos() + 3.0 * (x / 170.0 + y / 230.0).sin(),
    );
    m
}

impl MeshBuilder {
    /// Wavefront OBJ text of the mesh (one object, 1-based indices).
    pub fn to_obj(&self) -> String {
        let mut s = String::with_capacity(self.positions.len() * 32 + self.triangles.len() * 24);
        for p in &self.positions {
            s += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        for t in &self.triangles {
            s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        s
    }
}
