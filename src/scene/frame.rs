//! The local frame the tracer works in, and how precise it is.
//!
//! User coordinates (OBJ vertices, object and instance translations, the
//! sensor pose) are world coordinates: local ENU metres of the scene's site
//! (x east, y north, z up), read and transformed in f64, so that projected
//! coordinates such as UTM (eastings ~500 km, northings up to 10,000 km)
//! keep their millimetres. The tracer (Embree's and obvhs' f32 geometry),
//! the rays, hit points and secondary-ray offsets work in a *local frame*:
//! the world frame shifted horizontally so that its origin is the camera
//! target rounded to whole metres, `(round(x_t), round(y_t), 0)`. Heights
//! are not shifted (z = 0 stays the site elevation). The shift is applied in
//! f64 before anything is rounded to f32, to the object translations and
//! the pose, so a scene moved as a whole by a whole number of metres gives
//! the same local coordinates bit for bit.
//!
//! Precision: an f32 coordinate of magnitude r in [2^k, 2^(k+1)) is stored
//! to half its spacing, 2^(k−24) m ([`f32_error_m`]). Geometry within
//! [`PRECISE_EXTENT_M`] (16,384 m) of the local origin is exact to 0.5 mm;
//! farther out the scene loads with a warning ([`LocalFrame::warning`]),
//! and beyond [`MAX_EXTENT_M`] (1,048,576 m, where the error reaches 6 cm)
//! it is refused. Results that are positions (bounds, footprints) are
//! reported in world coordinates; ranges and angles do not depend on the
//! frame.

use serde::Serialize;

/// Geometry within this distance (m) of the local origin is stored to
/// 0.5 mm or better (f32 spacing 2^-10 m below 2^14 m).
pub const PRECISE_EXTENT_M: f64 = 16_384.0;

/// Geometry farther than this (m) from the local origin is refused: f32
/// stores it to no better than 6.25 cm (spacing 2^-3 m above 2^20 m).
pub const MAX_EXTENT_M: f64 = 1_048_576.0;

/// The largest rounding error (m) of an f32 coordinate of magnitude `r_m`:
/// half the spacing of f32 values there, 2^(⌊log2 r⌋ − 24) (IEEE 754
/// binary32: 24-bit significand).
pub fn f32_error_m(r_m: f64) -> f64 {
    let r = r_m.abs().max(f32::MIN_POSITIVE as f64);
    2f64.powi(r.log2().floor() as i32 - 24)
}

/// The largest distance (m) from the local origin within which f32
/// coordinates are stored to `error_m` or better.
pub fn extent_for_error_m(error_m: f64) -> f64 {
    2f64.powi((error_m.log2() + 24.0).floor() as i32 + 1)
}

/// The local frame of a loaded scene.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LocalFrame {
    /// The local origin in world coordinates, m: the camera target rounded
    /// to whole metres, at z = 0.
    pub origin_m: [f64; 3],
    /// The largest absolute local coordinate of any vertex, m.
    pub extent_m: f64,
    /// The largest rounding error of a vertex coordinate at that extent, m
    /// ([`f32_error_m`]).
    pub error_m: f64,
    /// [`PRECISE_EXTENT_M`], for the report.
    pub precise_extent_m: f64,
    /// [`MAX_EXTENT_M`], for the report.
    pub max_extent_m: f64,
}

impl LocalFrame {
    /// The frame with origin `origin_m` holding geometry out to `extent_m`.
    pub fn new(origin_m: [f64; 3], extent_m: f64) -> LocalFrame {
        LocalFrame {
            origin_m,
            extent_m,
            error_m: f32_error_m(extent_m),
            precise_extent_m: PRECISE_EXTENT_M,
            max_extent_m: MAX_EXTENT_M,
        }
    }

    /// The origin of the frame whose camera target is `target_m`.
    pub fn origin_for_target(target_m: [f64; 3]) -> [f64; 3] {
        [target_m[0].round(), target_m[1].round(), 0.0]
    }

    /// A world point in the frame (f64).
    pub fn to_local(&self, world_m: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| world_m[i] - self.origin_m[i])
    }

    /// A local point in world coordinates.
    pub fn to_world(&self, local_m: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| local_m[i] + self.origin_m[i])
    }

    /// A warning when the geometry reaches beyond [`PRECISE_EXTENT_M`].
    pub fn warning(&self) -> Option<String> {
        (self.extent_m > PRECISE_EXTENT_M).then(|| {
            format!(
                "the geometry reaches {:.0} m from the tracer's local origin (the camera target, \
                 world ({:.0}, {:.0}) m): single-precision coordinates there are exact to {:.1} mm \
                 only (0.5 mm within {PRECISE_EXTENT_M:.0} m); split the scene or aim the camera \
                 nearer its centre",
                self.extent_m,
                self.origin_m[0],
                self.origin_m[1],
                self.error_m * 1e3
            )
        })
    }
}

/// Mean radius of the Earth (IUGG R₁ of WGS 84), m: the sphere the
/// atmospheric path geometry ([`path_geometry`]) and the altitude pose
/// ([`slant_range_on_sphere_m`]) take the Earth for.
pub const EARTH_RADIUS_M: f64 = 6_371_008.8;

/// The geometry of the atmospheric path from `point_m` to `sensor_m` (both
/// in the scene's or the tracer's frame: z up at the frame's origin, which
/// lies at height 0 on a sphere of radius [`EARTH_RADIUS_M`] centred at
/// C = (0, 0, −R) below it) as the atmosphere tables take it: (the
/// sensor's height above the point, km; the zenith angle of the line of
/// sight at the point, degrees). The height is |S − C| − |P − C|, the
/// zenith angle the angle between S − P and the sphere's vertical
/// (P − C)/|P − C| at the point.
///
/// A flat frame (z up everywhere) would take the height as S_z − P_z and
/// the zenith from +z. Its error grows with the horizontal distance d of
/// the point from the origin: the vertical tilts by d/R (0.9° at 100 km)
/// and the ground falls d²/2R below the plane (0.8 km at 100 km). For a
/// 705 km satellite looking 7.5° off nadir (the edge of a 185 km swath)
/// the zenith angle at the ground is 8.34° (spherical law of sines:
/// sin θ = (R + H)/R · sin η), where a flat frame says 7.5°; at 15° off
/// nadir, 16.7° against 15°. Near the origin (a scene's few km) both
/// agree to d/R: 0.009° at 1 km.
pub fn path_geometry(sensor_m: [f64; 3], point_m: [f64; 3]) -> (f64, f64) {
    let c = [0.0, 0.0, -EARTH_RADIUS_M];
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let len = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let (rs, rp) = (sub(sensor_m, c), sub(point_m, c));
    let h_km = (len(rs) - len(rp)) / 1000.0;
    let los = sub(sensor_m, point_m);
    let cos_z = (los[0] * rp[0] + los[1] * rp[1] + los[2] * rp[2]) / (len(los) * len(rp));
    (h_km, cos_z.clamp(-1.0, 1.0).acos().to_degrees())
}

/// Distance (m) from a target at height `target_z_m` to a sensor at
/// height `altitude_m` (both above the frame's origin, on the sphere of
/// [`EARTH_RADIUS_M`]) whose line of sight has zenith angle
/// `view_zenith_deg` at the target: the root r > 0 of
/// (R + H)² = (R + z)² + r² + 2 (R + z) r cos θ, written
/// r = h (2R + H + z) / ((R + z) cos θ + √((R + z)² cos² θ + h (2R + H + z)))
/// with h = H − z (no cancellation). As R → ∞ this is the flat frame's
/// h / cos θ; at 705 km and θ = 30° it is 801.0 km where the flat frame
/// gives 814.1 km (the sensor 12 km too high, its GSD 1.6 % too coarse).
pub fn slant_range_on_sphere_m(altitude_m: f64, target_z_m: f64, view_zenith_deg: f64) -> f64 {
    let r = EARTH_RADIUS_M;
    let h = altitude_m - target_z_m;
    let rz = r + target_z_m;
    let c = view_zenith_deg.to_radians().cos();
    let q = h * (2.0 * r + altitude_m + target_z_m);
    q / (rz * c + (rz * rz * c * c + q).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_is_half_the_f32_spacing() {
        // The spacing of f32 at r is the distance to the next float.
        for r in [
            0.7f32, 1.0, 3.0, 1000.0, 16_383.0, 16_384.0, 500_000.0, 4.8e6,
        ] {
            let spacing = (f32::from_bits(r.to_bits() + 1) - r) as f64;
            assert_eq!(f32_error_m(r as f64), spacing / 2.0, "{r}");
        }
        assert_eq!(f32_error_m(16_000.0), 2f64.powi(-11)); // ~0.49 mm
        assert_eq!(f32_error_m(MAX_EXTENT_M), 2f64.powi(-4)); // 6.25 cm
        assert_eq!(extent_for_error_m(2f64.powi(-11)), PRECISE_EXTENT_M);
        assert_eq!(extent_for_error_m(2f64.powi(-4)), 2.0 * MAX_EXTENT_M);
        assert!(f32_error_m(extent_for_error_m(1e-3) * 0.999) <= 1e-3);
        assert!(f32_error_m(extent_for_error_m(1e-3)) > 1e-3);
    }

    #[test]
    fn origin_and_round_trip() {
        let o = LocalFrame::origin_for_target([500_020.4, 4_800_019.6, 12.0]);
        assert_eq!(o, [500_020.0, 4_800_020.0, 0.0]);
        let f = LocalFrame::new(o, 100.0);
        assert_eq!(f.to_local([500_021.5, 4_800_000.0, 3.0]), [1.5, -20.0, 3.0]);
        assert_eq!(f.to_world([1.5, -20.0, 3.0]), [500_021.5, 4_800_000.0, 3.0]);
        assert!(f.warning().is_none());
        assert!(
            LocalFrame::new(o, 20_000.0)
                .warning()
                .unwrap()
                .contains("20000 m")
        );
    }
}
