//! The camera: a pinhole (perspective) camera with position, orthonormal
//! basis, angular field of view and pixel counts, built from a
//! [`SensorSpec`] ([`camera_geometry`]) or aimed at a point
//! ([`Camera::look_at`]). The one camera type of the program: the render,
//! the cross-check and the scene summary use it (the primary rays are made
//! by `crate::sensor::camera`). Plain data, local ENU metres (x east,
//! y north, z up); positions are f64 (km-scale scenes).

use glam::DVec3;
use serde::Serialize;

use super::spec::{SensorPose, SensorSpec};

/// A pinhole camera. Pixel (0, 0) is the top-left corner of the image;
/// pixel centres are at (i + 0.5, j + 0.5); image x grows along `right`,
/// image y along `-up`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Camera {
    /// Projection centre, metres.
    pub position_m: [f64; 3],
    /// Unit optical axis (look direction).
    pub forward: [f64; 3],
    /// Unit vector towards increasing column (image right).
    pub right: [f64; 3],
    /// Unit vector towards decreasing row (image up); right = forward × up.
    pub up: [f64; 3],
    /// Full horizontal field of view, degrees.
    pub fov_h_deg: f64,
    /// Full vertical field of view, degrees.
    pub fov_v_deg: f64,
    /// Image width, pixels.
    pub width_px: u32,
    /// Image height, pixels.
    pub height_px: u32,
    /// tan(fov_h / 2), tan(fov_v / 2) (what the projection uses).
    #[serde(skip)]
    pub tan_half_fov: (f64, f64),
}

/// Unit vector with azimuth `az_deg` (clockwise from north) and zenith
/// angle `zen_deg` (from +z): (sin z·sin a, sin z·cos a, cos z).
pub fn direction_from_angles(zenith_deg: f64, azimuth_deg: f64) -> [f64; 3] {
    let (z, a) = (zenith_deg.to_radians(), azimuth_deg.to_radians());
    [z.sin() * a.sin(), z.sin() * a.cos(), z.cos()]
}

/// The camera of a sensor spec in the frame whose origin is `origin_m`
/// (world coordinates; its z must be 0, see [`super::frame`]): the pose's
/// points are moved into the frame before the camera is computed.
pub fn camera_geometry_at(s: &SensorSpec, origin_m: [f64; 3]) -> Result<Camera, String> {
    debug_assert_eq!(origin_m[2], 0.0, "the local frame keeps heights");
    let mut local = s.clone();
    local.pose = s.pose.shifted(origin_m);
    camera_geometry(&local)
}

/// The camera of a sensor spec. Errors (as text) for a degenerate pose:
/// sensor at its target, an `up` parallel to the view, a sensor below
/// its target with the altitude form.
pub fn camera_geometry(s: &SensorSpec) -> Result<Camera, String> {
    let (pos, target, up_hint) = match &s.pose {
        SensorPose::LookAt {
            position_m,
            target_m,
            up,
        } => (
            DVec3::from(*position_m),
            DVec3::from(*target_m),
            up.map(DVec3::from),
        ),
        SensorPose::Altitude {
            altitude_m,
            view_zenith_deg,
            azimuth_deg,
            target_m,
        } => {
            let t = DVec3::from(*target_m);
            let h = altitude_m - t.z;
            if h <= 0.0 {
                return Err(format!(
                    "altitude {altitude_m} m is not above the target (z = {} m)",
                    t.z
                ));
            }
            // on the Earth's sphere: the sensor `altitude_m` above it
            let range = super::frame::slant_range_on_sphere_m(*altitude_m, t.z, *view_zenith_deg);
            let d = DVec3::from(direction_from_angles(*view_zenith_deg, *azimuth_deg));
            (t + d * range, t, None)
        }
        SensorPose::SlantRange {
            slant_range_m,
            view_zenith_deg,
            azimuth_deg,
            target_m,
        } => {
            let t = DVec3::from(*target_m);
            let d = DVec3::from(direction_from_angles(*view_zenith_deg, *azimuth_deg));
            (t + d * *slant_range_m, t, None)
        }
    };
    let f = target - pos;
    if f.length().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || !f.is_finite() {
        return Err("the sensor position coincides with its target".into());
    }
    let forward = f.normalize();
    let up_hint = match up_hint {
        Some(u) => u,
        None => {
            if forward.z.abs() > 1.0 - 1e-9 {
                // Straight down or up: image top towards the far side of the
                // pose's azimuth (north for look_at).
                match &s.pose {
                    SensorPose::Altitude { azimuth_deg, .. }
                    | SensorPose::SlantRange { azimuth_deg, .. } => {
                        DVec3::from(direction_from_angles(90.0, azimuth_deg + 180.0))
                    }
                    SensorPose::LookAt { .. } => DVec3::Y,
                }
            } else {
                DVec3::Z
            }
        }
    };
    let right = forward.cross(up_hint);
    if right.length().is_nan() || right.length() <= 1e-9 {
        return Err("the `up` direction is parallel to the line of sight".into());
    }
    let right = right.normalize();
    let up = right.cross(forward).normalize();
    let t = |deg: f64| (deg.to_radians() / 2.0).tan();
    Ok(Camera {
        position_m: pos.to_array(),
        forward: forward.to_array(),
        right: right.to_array(),
        up: up.to_array(),
        fov_h_deg: s.fov_h_deg,
        fov_v_deg: s.fov_v_deg(),
        width_px: s.width_px,
        height_px: s.height_px,
        tan_half_fov: (t(s.fov_h_deg), t(s.fov_v_deg())),
    })
}

impl Camera {
    /// Camera at `position` looking at `target`, horizontal field of view
    /// `fov_x_deg`, square pixels. The up hint is +z; when the view is
    /// (nearly) vertical, +y (north) is used so that north is up in the
    /// image.
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
            position_m: position.to_array(),
            forward: forward.to_array(),
            right: right.to_array(),
            up: up.to_array(),
            fov_h_deg: fov_x_deg,
            fov_v_deg: 2.0 * ty.atan().to_degrees(),
            width_px: width,
            height_px: height,
            tan_half_fov: (tx, ty),
        }
    }

    /// The same camera with `n`×`n` pixels per pixel (supersampling).
    pub fn supersampled(&self, n: u32) -> Camera {
        Camera {
            width_px: self.width_px * n,
            height_px: self.height_px * n,
            ..*self
        }
    }

    /// Projection centre.
    pub fn position(&self) -> DVec3 {
        DVec3::from(self.position_m)
    }

    /// Unit direction through image point (x, y) in pixel units (pixel
    /// centres at +0.5).
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        let sx = (2.0 * x / self.width_px as f64 - 1.0) * self.tan_half_fov.0;
        let sy = (1.0 - 2.0 * y / self.height_px as f64) * self.tan_half_fov.1;
        (DVec3::from(self.forward) + DVec3::from(self.right) * sx + DVec3::from(self.up) * sy)
            .normalize()
    }

    /// Unit ray direction through image point (`col`, `row`) in pixel
    /// units (pixel centres at i + 0.5).
    pub fn ray_direction(&self, col: f64, row: f64) -> [f64; 3] {
        self.direction(col, row).to_array()
    }

    /// Where the ray through (`col`, `row`) meets the horizontal plane
    /// z = `ground_z_m`; `None` if it does not (at or above the horizon).
    pub fn ground_point(&self, col: f64, row: f64, ground_z_m: f64) -> Option<[f64; 3]> {
        let d = self.ray_direction(col, row);
        let dz = ground_z_m - self.position_m[2];
        if d[2] >= 0.0 || dz >= 0.0 {
            return None;
        }
        let t = dz / d[2];
        Some([
            self.position_m[0] + t * d[0],
            self.position_m[1] + t * d[1],
            ground_z_m,
        ])
    }

    /// The image corners (top-left, top-right, bottom-right, bottom-left)
    /// projected onto z = `ground_z_m`.
    pub fn footprint(&self, ground_z_m: f64) -> [Option<[f64; 3]>; 4] {
        let (w, h) = (self.width_px as f64, self.height_px as f64);
        [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)].map(|(c, r)| self.ground_point(c, r, ground_z_m))
    }

    /// Ground sample distance at the image centre on z = `ground_z_m`,
    /// metres per pixel (across, along), from the centre pixel's corners.
    pub fn centre_gsd_m(&self, ground_z_m: f64) -> Option<[f64; 2]> {
        let (cx, cy) = (self.width_px as f64 / 2.0, self.height_px as f64 / 2.0);
        let a = DVec3::from(self.ground_point(cx - 0.5, cy, ground_z_m)?);
        let b = DVec3::from(self.ground_point(cx + 0.5, cy, ground_z_m)?);
        let c = DVec3::from(self.ground_point(cx, cy - 0.5, ground_z_m)?);
        let d = DVec3::from(self.ground_point(cx, cy + 0.5, ground_z_m)?);
        Some([(b - a).length(), (d - c).length()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::spec::{Band, NoiseSpec, Psf};

    fn spec(pose: SensorPose, w: u32, h: u32, fov: f64) -> SensorSpec {
        SensorSpec {
            width_px: w,
            height_px: h,
            fov_h_deg: fov,
            fov_v_deg: None,
            band: Band::Lwir,
            psf: Psf::None,
            noise: NoiseSpec::default(),
            quantisation: None,
            pose,
        }
    }

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
    }

    #[test]
    fn nadir_altitude_footprint_is_analytic() {
        // 2 km above the origin, 10° square FOV: half-width 2000·tan 5°.
        let c = camera_geometry(&spec(
            SensorPose::Altitude {
                altitude_m: 2000.0,
                view_zenith_deg: 0.0,
                azimuth_deg: 180.0,
                target_m: [0.0; 3],
            },
            100,
            100,
            10.0,
        ))
        .unwrap();
        assert!(close(c.position_m, [0.0, 0.0, 2000.0], 1e-9));
        assert!(close(c.forward, [0.0, 0.0, -1.0], 1e-12));
        // azimuth 180 (sensor south): image top is north, right is east.
        assert!(close(c.up, [0.0, 1.0, 0.0], 1e-9));
        assert!(close(c.right, [1.0, 0.0, 0.0], 1e-9));
        let half = 2000.0 * 5f64.to_radians().tan();
        let fp = c.footprint(0.0);
        assert!(close(fp[0].unwrap(), [-half, half, 0.0], 1e-6));
        assert!(close(fp[2].unwrap(), [half, -half, 0.0], 1e-6));
        let g = c.centre_gsd_m(0.0).unwrap();
        // one pixel subtends 2·tan(5°)/100 (within the small-angle
        // difference between centre and edge pixels, < 1e-4 relative)
        assert!((g[0] - 2.0 * half / 100.0).abs() / g[0] < 1e-4, "{g:?}");
    }

    #[test]
    fn slant_range_places_sensor_on_the_view_cone() {
        // 10 km at 60° from the vertical, sensor south of the target.
        let c = camera_geometry(&spec(
            SensorPose::SlantRange {
                slant_range_m: 10_000.0,
                view_zenith_deg: 60.0,
                azimuth_deg: 180.0,
                target_m: [100.0, 200.0, 0.0],
            },
            64,
            32,
            5.0,
        ))
        .unwrap();
        assert!(close(
            c.position_m,
            [100.0, 200.0 - 10_000.0 * 3f64.sqrt() / 2.0, 5000.0],
            1e-6
        ));
        // the centre ray hits the target
        let p = c.ground_point(32.0, 16.0, 0.0).unwrap();
        assert!(close(p, [100.0, 200.0, 0.0], 1e-6));
        // square pixels: vertical FOV from aspect
        let expect_v = 2.0 * ((2.5f64.to_radians()).tan() * 0.5).atan().to_degrees();
        assert!((c.fov_v_deg - expect_v).abs() < 1e-12);
        // orthonormal, right-handed (right = forward × up)
        let (f, r, u) = (
            DVec3::from(c.forward),
            DVec3::from(c.right),
            DVec3::from(c.up),
        );
        assert!(f.dot(r).abs() < 1e-12 && f.dot(u).abs() < 1e-12 && r.dot(u).abs() < 1e-12);
        assert!((f.cross(u) - r).length() < 1e-12);
        // looking north and down: image up tilts north and up
        assert!(c.up[1] > 0.0 && c.up[2] > 0.0);
    }

    #[test]
    fn degenerate_poses_are_errors() {
        let e = camera_geometry(&spec(
            SensorPose::LookAt {
                position_m: [1.0, 2.0, 3.0],
                target_m: [1.0, 2.0, 3.0],
                up: None,
            },
            8,
            8,
            10.0,
        ))
        .unwrap_err();
        assert!(e.contains("coincides"));
        let e = camera_geometry(&spec(
            SensorPose::LookAt {
                position_m: [0.0, 0.0, 10.0],
                target_m: [0.0, 0.0, 0.0],
                up: Some([0.0, 0.0, 1.0]),
            },
            8,
            8,
            10.0,
        ))
        .unwrap_err();
        assert!(e.contains("parallel"));
    }
}
