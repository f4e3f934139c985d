//! The primary rays of the camera ([`Camera`], defined with the scene's
//! sensor in [`crate::scene::camera`]): rays are emitted in f32 world
//! coordinates, pixels in 4×4 tile order for 16-wide packets.

use crate::trace::Ray;

pub use crate::scene::camera::Camera;

impl Camera {
    /// The primary ray through image point (x, y).
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        Ray::new(self.position().as_vec3(), self.direction(x, y).as_vec3())
    }

    /// Pixels in 4×4 tile order (row-major tiles, row-major inside a tile),
    /// so that each run of 16 forms one coherent packet. Edge tiles are
    /// partial.
    pub fn tile_order(&self) -> Vec<(u32, u32)> {
        tile_order(self.width_px, self.height_px, 4)
    }
}

/// Pixels of a `width × height` image in `tile × tile` blocks.
pub fn tile_order(width: u32, height: u32, tile: u32) -> Vec<(u32, u32)> {
    let mut out = Vec::with_capacity(width as usize * height as usize);
    for ty in (0..height).step_by(tile as usize) {
        for tx in (0..width).step_by(tile as usize) {
            for y in ty..(ty + tile).min(height) {
                for x in tx..(tx + tile).min(width) {
                    out.push((x, y));
                }
            }
        }
    }
    out
}
