//! The ray tracer submodel: a [`Tracer`] trait with two interchangeable
//! backends — Embree through FFI ([`embree`], the default, 16-wide packets)
//! and obvhs ([`bvh`], a pure-Rust fallback) — plus robust secondary-ray
//! origins ([`offset`]) and generated test meshes ([`meshgen`]). The backend
//! cross-check is a harness above the scene and the sensor
//! ([`crate::bench::crosscheck`]).
//!
//! Geometry is one world-space triangle soup ([`Geometry`]), validated once:
//! non-finite vertices and out-of-range indices are errors, zero-area
//! triangles are skipped (never traced) and counted. Hits always report the
//! index of the triangle in the caller's input.

pub mod bvh;
pub mod embree;
pub mod meshgen;
pub mod offset;
pub mod sky_view;

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Largest origin or direction component a ray may have: Embree's
/// `FLT_LARGE` (1.844e18). Embree checks `|org|, |dir| <= FLT_LARGE` per
/// lane and aborts the process (an assertion in the library) on a larger,
/// finite value in an active lane, so such rays are invalid (they never hit).
pub const MAX_RAY_COORD: f32 = 1.844e18;

/// A ray: origin, direction (need not be normalised; `t` is in units of
/// `|dir|`), and the accepted interval `[tnear, tfar]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub org: Vec3,
    pub dir: Vec3,
    pub tnear: f32,
    pub tfar: f32,
}

impl Ray {
    /// A ray over `[0, inf)`.
    pub fn new(org: Vec3, dir: Vec3) -> Self {
        Ray {
            org,
            dir,
            tnear: 0.0,
            tfar: f32::INFINITY,
        }
    }
    /// True when origin and direction are finite, within Embree's range
    /// ([`MAX_RAY_COORD`]) and the direction non-zero.
    pub fn is_valid(&self) -> bool {
        in_ray_range(self.org)
            && in_ray_range(self.dir)
            && self.dir.length_squared() > 0.0
            && !self.tnear.is_nan()
            && !self.tfar.is_nan()
    }
}

/// A ray origin's or direction's part of [`Ray::is_valid`]: finite and
/// within Embree's range ([`MAX_RAY_COORD`]).
pub fn in_ray_range(v: Vec3) -> bool {
    v.is_finite() && v.abs().max_element() <= MAX_RAY_COORD
}

/// The closest hit of a ray: distance along the ray, the input triangle
/// index, and Embree-convention barycentrics (`p = (1-u-v)·v0 + u·v1 + v·v2`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub prim: u32,
    pub u: f32,
    pub v: f32,
}

impl Hit {
    /// Smallest barycentric coordinate: 0 on an edge, 1/3 at the centroid.
    pub fn edge_distance(&self) -> f32 {
        self.u.min(self.v).min(1.0 - self.u - self.v)
    }
}

/// Which backend traces the rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Backend {
    /// Embree (system library through the C shim), 16-wide packets.
    Embree,
    /// obvhs BVH (pure Rust), single rays.
    Bvh,
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Backend::Embree => "embree",
            Backend::Bvh => "bvh",
        })
    }
}

/// How a backend issues queries. Packets are used for groups of rays that
/// callers order by 4x4 pixel tile; `Single` forces one ray per call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum QueryMode {
    #[default]
    Packet16,
    Single,
}

/// Ray queries over a committed, read-only scene. Implementations are
/// shared across rayon threads.
pub trait Tracer: Send + Sync {
    fn backend(&self) -> Backend;
    /// Closest hit of each ray (`hits.len() == rays.len()`). Rays are taken
    /// in groups of 16 in order: for coherent packets, order rays by tile.
    /// Invalid rays (non-finite or zero direction) never hit.
    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]);
    /// Whether anything blocks each ray within `[tnear, tfar]`.
    fn occluded(&self, rays: &[Ray], blocked: &mut [bool]);
    /// Shadow queries from up to 16 origins toward several directions (the
    /// solar history of a group of points: one sun direction at a time).
    /// For each `k`, the origins whose lane bit is set in `active[k]` are
    /// queried toward `dirs[k]`, and `blocked[k]` gets the lanes whose ray
    /// is blocked: lane `i` of `blocked[k]` is [`Self::occluded`] of
    /// `Ray::new(origins[i], dirs[k])` where `active[k]` has it, else 0.
    /// Backends may fill a packet's origins once for all directions (no
    /// [`Ray`] per query).
    fn occluded_fan(&self, origins: &[Vec3], dirs: &[Vec3], active: &[u16], blocked: &mut [u16]) {
        assert!(origins.len() <= 16, "at most 16 origins");
        assert!(dirs.len() == active.len() && dirs.len() == blocked.len());
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::Z); 16];
        let (mut lanes, mut hit) = ([0usize; 16], [false; 16]);
        for ((dir, &act), out) in dirs.iter().zip(active).zip(blocked.iter_mut()) {
            let mut m = 0;
            for (lane, o) in origins.iter().enumerate() {
                if act >> lane & 1 == 1 {
                    rays[m] = Ray::new(*o, *dir);
                    lanes[m] = lane;
                    m += 1;
                }
            }
            self.occluded(&rays[..m], &mut hit[..m]);
            *out = (lanes[..m].iter().zip(&hit[..m]))
                .filter(|(_, b)| **b)
                .fold(0, |acc, (lane, _)| acc | 1 << lane);
        }
    }
}

/// Errors in geometry handed to the tracer.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum GeometryError {
    #[error(
        "vertex {index} is not finite: ({x}, {y}, {z}); every coordinate must be a finite number"
    )]
    NonFiniteVertex {
        index: usize,
        x: f32,
        y: f32,
        z: f32,
    },
    #[error("triangle {tri} refers to vertex {vertex}, but there are only {count} vertices")]
    IndexOutOfRange {
        tri: usize,
        vertex: u32,
        count: usize,
    },
    #[error("too many triangles ({0}); at most {max} are supported", max = u32::MAX - 1)]
    TooMany(usize),
    #[error("Embree error: {0}")]
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
    pub positions: Vec<Vec3>,
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

/// Builds the tracer of the chosen backend over `geometry`.
pub fn build(
    backend: Backend,
    geometry: &std::sync::Arc<Geometry>,
) -> Result<Box<dyn Tracer>, GeometryError> {
    Ok(match backend {
        Backend::Embree => Box::new(embree::EmbreeTracer::new(
            geometry.clone(),
            QueryMode::Packet16,
        )?),
        Backend::Bvh => Box::new(bvh::BvhTracer::new(geometry.clone())),
    })
}
