//! The obvhs backend of [`Tracer`]: a pure-Rust BVH2 (PLOC build) with
//! obvhs's Möller–Trumbore triangle test, one ray at a time. It has no
//! packets and its triangle test is not watertight (shared edges can be
//! missed or resolved to the neighbour at equal `t`); the cross-check
//! ([`crate::bench::crosscheck`]) tells such ties from real disagreements.

use std::sync::Arc;
use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams, bvh2::Bvh2, bvh2::builder::build_bvh2_from_tris, ray::RayHit,
    triangle::Triangle,
};

use super::geometry::Geometry;
use super::ray::{Hit, Ray};
use super::tracer::{Backend, Tracer};

/// obvhs-based tracer.
pub struct BvhTracer {
    geometry: Arc<Geometry>,
    /// Traced triangles, in `geometry.traced` order.
    tris: Vec<Triangle>,
    bvh: Option<Bvh2>,
}

impl BvhTracer {
    /// Builds the BVH over the traced triangles of `geometry`.
    pub fn new(geometry: Arc<Geometry>) -> Self {
        let tris: Vec<Triangle> = geometry
            .traced
            .iter()
            .map(|&t| {
                let [v0, v1, v2] = geometry.vertices(t).map(Vec3A::from);
                Triangle { v0, v1, v2 }
            })
            .collect();
        let bvh = (!tris.is_empty()).then(|| {
            build_bvh2_from_tris(
                &tris,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        });
        BvhTracer {
            geometry,
            tris,
            bvh,
        }
    }

    fn to_obvhs(ray: &Ray) -> obvhs::ray::Ray {
        obvhs::ray::Ray::new(
            Vec3A::from(ray.org),
            Vec3A::from(ray.dir),
            ray.tnear.max(0.0),
            ray.tfar,
        )
    }

    /// Closest hit of one ray (barycentrics always on the triangle).
    pub fn intersect1(&self, ray: &Ray) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        if !ray.is_valid() || ray.tfar < ray.tnear {
            return None;
        }
        let r = Self::to_obvhs(ray);
        let mut hit = RayHit::none();
        let found = bvh.ray_traverse(r, &mut hit, |ray, id| {
            self.tris[bvh.primitive_indices[id] as usize].intersect(ray)
        });
        if !found {
            return None;
        }
        let local = bvh.primitive_indices[hit.primitive_id as usize] as usize;
        let (u, v) = barycentrics(&self.tris[local], ray);
        Some(Hit {
            t: hit.t,
            prim: self.geometry.traced[local],
            u,
            v,
        })
    }

    /// Whether anything blocks one ray.
    pub fn occluded1(&self, ray: &Ray) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        if !ray.is_valid() || ray.tfar < ray.tnear {
            return false;
        }
        !bvh.ray_traverse_miss(Self::to_obvhs(ray), |ray, id| {
            self.tris[bvh.primitive_indices[id] as usize].intersect(ray)
        })
    }
}

/// Embree-convention barycentrics `(u, v)` of the ray's crossing of the
/// triangle's plane (weights of v1 and v2), Möller & Trumbore (1997),
/// evaluated in f64 and clamped onto the triangle: obvhs's own (f32) test
/// accepted the hit as inside, and on slivers at grazing incidence the f32
/// recomputation could land well outside (u + v = 1.03 seen in the stress
/// suite).
fn barycentrics(tri: &Triangle, ray: &Ray) -> (f32, f32) {
    let (o, d) = (ray.org.as_dvec3(), ray.dir.as_dvec3());
    let (v0, v1, v2) = (
        Vec3::from(tri.v0).as_dvec3(),
        Vec3::from(tri.v1).as_dvec3(),
        Vec3::from(tri.v2).as_dvec3(),
    );
    let e1 = v1 - v0;
    let e2 = v2 - v0;
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return (0.0, 0.0);
    }
    let s = o - v0;
    let q = s.cross(e1);
    let (u, v) = ((s.dot(p) / det).max(0.0), (d.dot(q) / det).max(0.0));
    let sum = u + v;
    let (u, v) = if sum > 1.0 {
        (u / sum, v / sum)
    } else {
        (u, v)
    };
    (u as f32, v as f32)
}

impl Tracer for BvhTracer {
    fn backend(&self) -> Backend {
        Backend::Bvh
    }

    fn intersect(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        for (r, h) in rays.iter().zip(hits.iter_mut()) {
            *h = self.intersect1(r);
        }
    }

    fn occluded(&self, rays: &[Ray], blocked: &mut [bool]) {
        assert_eq!(rays.len(), blocked.len(), "one slot per ray");
        for (r, b) in rays.iter().zip(blocked.iter_mut()) {
            *b = self.occluded1(r);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (stress suite): barycentrics of a hit on a 6 m × 6 µm
    /// sliver at grazing incidence stay on the triangle (u, v ≥ 0,
    /// u + v ≤ 1), and for an ordinary triangle they are exact (reference:
    /// the point the ray is aimed at, barycentrics (0.25, 0.5)).
    #[test]
    fn barycentrics_on_the_triangle() {
        let tri = |w: f32| Triangle {
            v0: Vec3A::ZERO,
            v1: Vec3A::new(6.0, 0.0, 0.0),
            v2: Vec3A::new(6.0, w, 0.0),
        };
        let target = Vec3::new(6.0 * 0.75, 6.0 * 0.5, 0.0);
        let ray = Ray::new(
            target + Vec3::new(-3.0, 1.0, 2.0),
            Vec3::new(3.0, -1.0, -2.0),
        );
        let (u, v) = barycentrics(&tri(6.0), &ray);
        assert!((u - 0.25).abs() < 1e-6 && (v - 0.5).abs() < 1e-6, "{u} {v}");
        let mut rng = crate::trace::meshgen::SplitMix(1);
        for _ in 0..1000 {
            let x = rng.unit() * 6.0;
            let org = Vec3::new(x - 20.0, rng.unit() * 1e-5, 0.05);
            let ray = Ray::new(org, Vec3::new(20.0, 0.0, -0.05));
            let (u, v) = barycentrics(&tri(6e-6), &ray);
            assert!(u >= 0.0 && v >= 0.0 && u + v <= 1.0 + 1e-6, "{u} {v}");
        }
    }
}
