//! Weather history: readers (plain CSV, TMY3, EPW), time interpolation,
//! constant-weather source. Owner: the sun/weather work (issue 4).

use chrono::{DateTime, Utc};
use serde::{Deserialize, Serialize};

/// One instant of weather. SI units; optional fields are `None` when the
/// record does not carry them (estimators fill them in later).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WeatherSample {
    pub air_temp_k: f64,
    pub dew_point_k: f64,
    pub wind_speed_m_s: f64,
    pub pressure_pa: f64,
    /// Total cloud cover, 0 (clear) to 1 (overcast).
    pub cloud_fraction: f64,
    /// Measured global horizontal irradiance, W/m².
    pub ghi_w_m2: Option<f64>,
    /// Measured direct normal irradiance, W/m².
    pub dni_w_m2: Option<f64>,
    /// Measured diffuse horizontal irradiance, W/m².
    pub dhi_w_m2: Option<f64>,
    /// Measured effective sky (downwelling longwave) temperature, K.
    pub sky_temp_k: Option<f64>,
    /// Precipitation rate, mm/h.
    pub precip_mm_h: f64,
}

/// A time-ordered weather record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WeatherHistory {
    /// Strictly increasing sample times (UTC).
    pub times: Vec<DateTime<Utc>>,
    pub samples: Vec<WeatherSample>,
    /// Where the record came from (file name, or "constant").
    pub source: String,
}
