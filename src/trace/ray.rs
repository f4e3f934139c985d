//! Rays and hits: the tracer's queries and answers.

use glam::Vec3;

/// Largest origin or direction component a ray may have: Embree's
/// `FLT_LARGE` (1.844e18). Embree checks `|org|, |dir| <= FLT_LARGE` per
/// lane and aborts the process (an assertion in the library) on a larger,
/// finite value in an active lane, so such rays are invalid (they never hit).
pub const MAX_RAY_COORD: f32 = 1.844e18;

/// A ray: origin, direction (need not be normalised; `t` is in units of
/// `|dir|`), and the accepted interval `[tnear, tfar]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin, m (scene coordinates).
    pub org: Vec3,
    /// Direction (any non-zero length; sets the unit of `t`).
    pub dir: Vec3,
    /// Start of the accepted interval, in units of `|dir|`.
    pub tnear: f32,
    /// End of the accepted interval (`f32::INFINITY`: unbounded).
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
    /// Distance to the hit, in units of the ray's `|dir|`.
    pub t: f32,
    /// Index of the input triangle hit.
    pub prim: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
}

impl Hit {
    /// Smallest barycentric coordinate: 0 on an edge, 1/3 at the centroid.
    pub fn edge_distance(&self) -> f32 {
        self.u.min(self.v).min(1.0 - self.u - self.v)
    }
}
