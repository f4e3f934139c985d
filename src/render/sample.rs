//! What a ray found: the sample of a (sub-)pixel and its surface record,
//! with the angles the radiometry and the probe report.

use glam::{DVec3, Vec3};

use super::sunflags::SunFlags;

/// A surface point seen by a ray: a compact record (no heap allocation for
/// histories up to [`super::sunflags::INLINE_SWITCHES`] transitions).
#[derive(Clone, Debug, Default)]
pub struct Surface {
    /// Index of the triangle hit.
    pub prim: u32,
    /// Index of its material (the scene's material order).
    pub material: u32,
    /// The hit point, m (the tracer's local frame).
    pub point: Vec3,
    /// Unit geometric normal, facing the incoming ray.
    pub normal: Vec3,
    /// Distance along the incoming ray, m.
    pub range_m: f32,
    /// Sun/shadow flag per history sample (sunlit or not).
    pub history: SunFlags,
    /// Surface temperature at the image time, K (filled in step 4).
    pub temp_k: f64,
}

impl Surface {
    /// Sunlit at the image time (the last history sample).
    pub fn sun_now(&self) -> bool {
        self.history.last().unwrap_or(false)
    }

    /// The facet side the record is on: its facet and the bits of its
    /// normal (which faces the incoming ray). What is a function of the
    /// side alone (orientation, blocked sky) may be kept under this key.
    pub fn side(&self) -> (u32, [u32; 3]) {
        (self.prim, self.normal.to_array().map(f32::to_bits))
    }
}

/// A worker's one-entry memo of a pure function: the value for the last
/// key asked for (neighbouring samples mostly repeat a key, so a repeat
/// skips the computation and gives the same value).
#[derive(Debug)]
pub(crate) struct LastKey<K, V>(Option<(K, V)>);

impl<K, V> Default for LastKey<K, V> {
    fn default() -> Self {
        LastKey(None)
    }
}

impl<K: PartialEq, V: Copy> LastKey<K, V> {
    /// The value for `key`: the kept one on a repeat, else `f()` (kept).
    pub(crate) fn get_or(&mut self, key: K, f: impl FnOnce() -> V) -> V {
        match &self.0 {
            Some((last, v)) if *last == key => *v,
            _ => {
                let v = f();
                self.0 = Some((key, v));
                v
            }
        }
    }
}

/// What a (sub-)pixel's ray found.
#[derive(Clone, Debug, Default)]
pub struct Sample {
    /// Unit direction of the primary ray.
    pub dir: Vec3,
    /// What the primary ray hit (`None`: the sky or outside the scene).
    pub surface: Option<Surface>,
    /// For specular materials: the reflected direction and the background
    /// facet it hits (`None`: the sky). Boxed: few samples are specular,
    /// and a sample without it is half the size (less to move and cache).
    pub bounce: Option<Box<(Vec3, Option<Surface>)>>,
}

impl Sample {
    /// The view angle of the surface the primary ray hit: between the ray
    /// (reversed) and the surface normal, degrees (NaN for no surface).
    pub fn view_angle_deg(&self) -> f64 {
        self.surface
            .as_ref()
            .map_or(f64::NAN, |surf| angle_deg(-self.dir, surf.normal))
    }
}

/// Angle between two unit vectors, degrees.
pub fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    (a.as_dvec3().dot(b.as_dvec3()))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// Zenith angle of a direction, degrees.
pub fn zenith_deg(d: Vec3) -> f64 {
    angle_deg(d.normalize(), Vec3::Z)
}

/// Azimuth of a direction, clockwise from north, degrees in [0, 360).
pub fn azimuth_deg(d: DVec3) -> f64 {
    d.x.atan2(d.y).to_degrees().rem_euclid(360.0)
}
