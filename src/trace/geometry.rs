//! The tracer's input: a validated world-space triangle soup, and the one
//! test of zero area.

use glam::Vec3;

/// Errors in geometry handed to the tracer.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GeometryError {
    #[error(
        "vertex {index} is not finite: ({x}, {y}, {z}); every coordinate must be a finite number"
    )]
    /// A vertex with a NaN or infinite coordinate.
    NonFiniteVertex {
        /// Index of the vertex.
        index: usize,
        /// Its coordinates, m.
        x: f32,
        /// y coordinate, m.
        y: f32,
        /// z coordinate, m.
        z: f32,
    },
    #[error("triangle {tri} refers to vertex {vertex}, but there are only {count} vertices")]
    /// A triangle naming a vertex past the end of the vertex list.
    IndexOutOfRange {
        /// Index of the triangle.
        tri: usize,
        /// The vertex index it names.
        vertex: u32,
        /// Number of vertices there are.
        count: usize,
    },
    #[error("too many triangles ({0}); at most {max} are supported", max = u32::MAX - 1)]
    /// More triangles than a `u32` primitive id can number.
    TooMany(usize),
    #[error("Embree error: {0}")]
    /// An error reported by Embree while building the scene.
    Embree(String),
}

/// Whether a triangle has area as the tracer sees it: its cross product
/// (v1−v0)×(v2−v0) is finite and non-zero in single precision, and
/// non-zero in double precision from the same vertices (exactly collinear
/// or repeated vertices). The one test of zero area: the scene loader
/// leaves out (and counts) the triangles that fail it, and
/// [`Geometry::new`] skips them in any other input.
pub fn has_area(v: [Vec3; 3]) -> bool {
    let len = (v[1] - v[0]).cross(v[2] - v[0]).length();
    let q = v.map(|p| p.as_dvec3());
    let area2 = (q[1] - q[0]).cross(q[2] - q[0]).length();
    len > 0.0 && len.is_finite() && area2 > 0.0
}

/// A validated world-space triangle soup, the tracer's input.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// Vertex positions, m (the scene's local east-north-up frame).
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Indices (into `triangles`) of the triangles that are traced: all but
    /// the zero-area ones.
    pub traced: Vec<u32>,
    /// Unit geometric normal per input triangle (right-handed winding
    /// `(v1-v0)×(v2-v0)`; zero for skipped triangles).
    pub normals: Vec<Vec3>,
    /// Largest absolute coordinate, the scale for offsets and tolerances.
    pub max_abs_coord: f32,
}

impl Geometry {
    /// Validates and prepares geometry. Zero-area triangles (including
    /// triangles with repeated vertices) are skipped and counted in
    /// [`Geometry::skipped`].
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, GeometryError> {
        if triangles.len() >= u32::MAX as usize {
            return Err(GeometryError::TooMany(triangles.len()));
        }
        for (index, p) in positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(GeometryError::NonFiniteVertex {
                    index,
                    x: p.x,
                    y: p.y,
                    z: p.z,
                });
            }
        }
        let n = positions.len();
        let mut traced = Vec::with_capacity(triangles.len());
        let mut normals = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            for &vertex in t {
                if vertex as usize >= n {
                    return Err(GeometryError::IndexOutOfRange {
                        tri: i,
                        vertex,
                        count: n,
                    });
                }
            }
            let [a, b, c] = t.map(|k| positions[k as usize]);
            let cross = (b - a).cross(c - a);
            if has_area([a, b, c]) {
                traced.push(i as u32);
                normals.push(cross / cross.length());
            } else {
                normals.push(Vec3::ZERO);
            }
        }
        let max_abs_coord = positions
            .iter()
            .fold(0.0f32, |m, p| m.max(p.abs().max_element()));
        Ok(Geometry {
            positions,
            triangles,
            traced,
            normals,
            max_abs_coord,
        })
    }

    /// Number of zero-area triangles that are not traced.
    pub fn skipped(&self) -> usize {
        self.triangles.len() - self.traced.len()
    }

    /// Vertices of input triangle `prim`.
    pub fn vertices(&self, prim: u32) -> [Vec3; 3] {
        self.triangles[prim as usize].map(|k| self.positions[k as usize])
    }

    /// Point on triangle `prim` at barycentrics (u, v) — more precise than
    /// `org + t·dir` far from the origin of the ray.
    pub fn point(&self, prim: u32, u: f32, v: f32) -> Vec3 {
        let [a, b, c] = self.vertices(prim);
        a * (1.0 - u - v) + b * u + c * v
    }

    /// Axis-aligned bounds (min, max) of all vertices; zero for no vertices.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        if self.positions.is_empty() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        self.positions.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }
}
