//! The per-step boundary forcing of the thermal solver, built from a
//! [`super::weather::WeatherHistory`] and the sun ephemeris. Owner: the
//! sun/weather work (issue 4); consumed by the slab solver.

use serde::{Deserialize, Serialize};

/// Everything the surface energy balance needs at one instant, for an
/// unshadowed horizontal reference; the solver applies orientation and the
/// pixel's sun/shadow flag. SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Forcing {
    /// Seconds since the start of the run.
    pub t_s: f64,
    pub air_temp_k: f64,
    /// Effective clear+cloud sky temperature for longwave exchange, K.
    pub sky_temp_k: f64,
    pub wind_speed_m_s: f64,
    /// Direct normal irradiance at the ground (0 with the sun down), W/m².
    pub dni_w_m2: f64,
    /// Diffuse horizontal irradiance, W/m².
    pub dhi_w_m2: f64,
    /// Global horizontal irradiance, W/m² (for ground-reflected light).
    pub ghi_w_m2: f64,
    /// Unit vector towards the sun, local ENU (x east, y north, z up).
    pub sun_dir_enu: [f64; 3],
}
