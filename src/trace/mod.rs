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
mod geometry;
pub mod meshgen;
pub mod offset;
mod ray;
pub mod sky_view;
mod tracer;

pub use geometry::{Geometry, GeometryError, has_area};
pub use ray::{Hit, MAX_RAY_COORD, Ray, in_ray_range};
pub use tracer::{Backend, QueryMode, Tracer};

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
