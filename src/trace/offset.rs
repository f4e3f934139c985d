//! Robust origins for secondary rays (shadow/solar-history and specular
//! bounces). A fixed epsilon fails at km-scale coordinates where f32 spacing
//! is millimetres; instead the origin is moved off the surface along the
//! geometric normal by a few ULPs of each coordinate, following Wächter &
//! Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
//! Ray Tracing Gems (2019), ch. 6.

use glam::Vec3;

/// Below this magnitude a fixed float offset is used (the ULP method
/// would give denormal steps near the origin).
const ORIGIN: f32 = 1.0 / 32.0;
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
const INT_SCALE: f32 = 256.0;

/// Moves `p` (a point on a surface) off the surface to the side of `n`
/// (the unit geometric normal pointing where the new ray goes). Each
/// coordinate moves by `INT_SCALE·n_i` ULPs of itself: for a unit normal
/// component that is ~1.6 cm at 1 km and ~25 cm at 10 km from the scene
/// origin (coordinates near zero move by `FLOAT_SCALE·n_i` ≈ 15 µm).
pub fn offset_origin(p: Vec3, n: Vec3) -> Vec3 {
    let step = |x: f32, nx: f32| -> f32 {
        let of_i = (INT_SCALE * nx) as i32;
        // Moving the bit pattern by `of_i` moves the value away from zero for
        // positive values; flip the direction for negative values.
        let bits = x.to_bits() as i32;
        let moved = f32::from_bits((if x < 0.0 { bits - of_i } else { bits + of_i }) as u32);
        if x.abs() < ORIGIN {
            x + FLOAT_SCALE * nx
        } else {
            moved
        }
    };
    Vec3::new(step(p.x, n.x), step(p.y, n.y), step(p.z, n.z))
}
