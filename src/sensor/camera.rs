//! Pinhole (perspective) camera: position, orthonormal view basis, angular
//! field of view and pixel counts. Positions are f64 (km-scale scenes);
//! rays are emitted in f32 world coordinates.

use glam::DVec3;

use crate::trace::Ray;

/// A perspective camera. Pixel (0, 0) is the top-left corner; image x grows
/// along `right`, image y along `-up`.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    /// tan(fov_x / 2), tan(fov_y / 2).
    pub tan_half_fov: (f64, f64),
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// Camera at `position` looking at `target`, horizontal field of view
    /// `fov_x_deg`, square pixels. `up_hint` is usually +z; when the view is
    /// (nearly) vertical, +y (north) is used so that north is up in the image.
    pub fn look_at(
        position: DVec3,
        target: DVec3,
        fov_x_deg: f64,
        width: u32,
        height: u32,
    ) -> Self {
        let forward = (target - position).normalize();
        let up_hint = if forward.z.abs() > 0.999 {
            DVec3::Y
        } else {
            DVec3::Z
        };
        let right = forward.cross(up_hint).normalize();
        let up = right.cross(forward);
        let tx = (fov_x_deg.to_radians() / 2.0).tan();
        let ty = tx * height as f64 / width as f64;
        Camera {
            position,
            forward,
            right,
            up,
            tan_half_fov: (tx, ty),
            width,
            height,
        }
    }

    /// The camera of a scene's sensor.
    pub fn from_geometry(g: &crate::scene::camera::CameraGeometry) -> Self {
        let t = |deg: f64| (deg.to_radians() / 2.0).tan();
        Camera {
            position: DVec3::from(g.position_m),
            forward: DVec3::from(g.forward),
            right: DVec3::from(g.right),
            up: DVec3::from(g.up),
            tan_half_fov: (t(g.fov_h_deg), t(g.fov_v_deg)),
            width: g.width_px,
            height: g.height_px,
        }
    }

    /// Unit direction through image point (x, y) in pixel units (pixel
    /// centres at +0.5).
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        let sx = (2.0 * x / self.width as f64 - 1.0) * self.tan_half_fov.0;
        let sy = (1.0 - 2.0 * y / self.height as f64) * self.tan_half_fov.1;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// The primary ray through image point (x, y).
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        Ray::new(self.position.as_vec3(), self.direction(x, y).as_vec3())
    }

    /// Pixels in 4×4 tile order (row-major tiles, row-major inside a tile),
    /// so that each run of 16 forms one coherent packet. Edge tiles are
    /// partial.
    pub fn tile_order(&self) -> Vec<(u32, u32)> {
        tile_order(self.width, self.height, 4)
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
