//! A constant-weather source: fixed wind, dew point, cloud and pressure,
//! a smooth diurnal air-temperature cycle.

use super::parse::*;
use super::*;

/// Constant weather: the same diurnal cycle every day (air temperature a
/// smooth cycle between the daily minimum near sunrise and the maximum in
/// mid-afternoon; everything else constant). The scene's
/// `[weather.constant]` table (these keys; `t_max_after_noon_h` is not one)
/// and the library's constant-weather source (sweeps such as the seed's
/// wind-speed figure, Fig. 13: fixed wind for the previous 24 h).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantWeather {
    /// Wind speed, m/s (>= 0).
    pub wind_m_s: f64,
    /// Daily minimum air temperature (at sunrise), °C.
    pub air_min_c: f64,
    /// Daily maximum air temperature (at solar noon + [`Self::t_max_after_noon_h`]), °C
    /// (>= `air_min_c`).
    pub air_max_c: f64,
    /// Fixed dew point, °C; must not exceed `air_min_c`.
    pub dew_point_c: f64,
    /// Total cloud cover, 0 (clear) to 1 (overcast).
    #[serde(default)]
    pub cloud_fraction: f64,
    /// Surface air pressure, Pa.
    #[serde(default = "default_pressure_pa")]
    pub pressure_pa: f64,
    /// Hours after solar noon of the daily maximum (default 2.5:
    /// mid-afternoon; not a scene key).
    #[serde(skip, default = "default_t_max_after_noon_h")]
    pub t_max_after_noon_h: f64,
}

fn default_pressure_pa() -> f64 {
    101_325.0
}

fn default_t_max_after_noon_h() -> f64 {
    2.5
}

impl Default for ConstantWeather {
    fn default() -> Self {
        Self {
            wind_m_s: 2.0,
            air_min_c: 15.0,
            air_max_c: 25.0,
            dew_point_c: 10.0,
            cloud_fraction: 0.0,
            pressure_pa: default_pressure_pa(),
            t_max_after_noon_h: default_t_max_after_noon_h(),
        }
    }
}

/// Air temperature of the constant-weather diurnal cycle at `t`, °C.
///
/// Two half-cosines between the daily extremes: the minimum `T_min` at
/// sunrise t_r and the maximum `T_max` at t_x = solar transit +
/// `t_max_after_noon_h`; rising from t_r to t_x,
/// T = T_min + (T_max − T_min)·(1 − cos(π·(t − t_r)/(t_x − t_r)))/2,
/// and falling from t_x to the next sunrise t_r',
/// T = T_max − (T_max − T_min)·(1 − cos(π·(t − t_x)/(t_r' − t_x)))/2.
/// The curve is smooth (zero slope at both extremes). Without a sunrise
/// (polar day or night) t_r = transit − 6 h. Sunrise and transit come from
/// [`crate::sun::sun_events_near`] (SPA).
pub fn diurnal_air_temp_c(
    p: &ConstantWeather,
    lat_deg: f64,
    lon_deg: f64,
    t: DateTime<Utc>,
) -> f64 {
    let keys = |day_offset: i64| -> (DateTime<Utc>, DateTime<Utc>) {
        let ev = crate::sun::sun_events_near(t + Duration::days(day_offset), lat_deg, lon_deg);
        let rise = ev.sunrise.unwrap_or(ev.transit - Duration::hours(6));
        let tmax = ev.transit + Duration::milliseconds((p.t_max_after_noon_h * 3.6e6) as i64);
        (rise, tmax)
    };
    let (r0, x0) = keys(0);
    let (tmin, tmax) = (p.air_min_c, p.air_max_c);
    let half_cos = |a: DateTime<Utc>, b: DateTime<Utc>| {
        let f = (secs_between(a, t) / secs_between(a, b)).clamp(0.0, 1.0);
        (1.0 - (std::f64::consts::PI * f).cos()) / 2.0
    };
    if t < r0 {
        let (_, xm) = keys(-1);
        tmax - (tmax - tmin) * half_cos(xm, r0)
    } else if t < x0 {
        tmin + (tmax - tmin) * half_cos(r0, x0)
    } else {
        let (r1, _) = keys(1);
        tmax - (tmax - tmin) * half_cos(x0, r1)
    }
}

/// A constant-weather history from `start` to `end` (inclusive, sampled every
/// `step_s` seconds): fixed wind, dew point, cloud cover and pressure, air
/// temperature from [`diurnal_air_temp_c`]; no measured irradiance or sky
/// temperature (the forcing builder estimates them).
pub fn constant_weather(
    p: &ConstantWeather,
    lat_deg: f64,
    lon_deg: f64,
    start: DateTime<Utc>,
    end: DateTime<Utc>,
    step_s: f64,
) -> Result<WeatherHistory, WeatherError> {
    let bad = |m: String| Err(WeatherError::Invalid(format!("constant weather: {m}")));
    crate::sun::validate_site(lat_deg, lon_deg, 0.0)
        .map_err(|m| WeatherError::Invalid(format!("constant weather: {m}")))?;
    if !(step_s >= 1.0 && step_s.is_finite()) {
        return bad(format!("step {step_s} s: expected at least 1 s"));
    }
    if end <= start {
        return bad(format!(
            "end {} is not after start {}",
            fmt_time(end),
            fmt_time(start)
        ));
    }
    let params = [
        p.wind_m_s,
        p.air_min_c,
        p.air_max_c,
        p.dew_point_c,
        p.cloud_fraction,
        p.pressure_pa,
        p.t_max_after_noon_h,
    ];
    if params.iter().any(|x| !x.is_finite()) {
        return bad(format!("parameters must be finite numbers: {p:?}"));
    }
    if p.air_min_c > p.air_max_c {
        return bad(format!(
            "minimum air temperature {} °C is above the maximum {} °C",
            p.air_min_c, p.air_max_c
        ));
    }
    if p.dew_point_c > p.air_min_c {
        return bad(format!(
            "dew point {} °C is above the minimum air temperature {} °C (expected dew point <= air temperature)",
            p.dew_point_c, p.air_min_c
        ));
    }
    if !(0.0..=8.0).contains(&p.t_max_after_noon_h) {
        return bad(format!(
            "t_max_after_noon_h {}: expected 0 to 8 h",
            p.t_max_after_noon_h
        ));
    }
    let c = Ctx {
        file: "constant weather",
        line: 0,
    };
    let total = secs_between(start, end);
    let n = (total / step_s).ceil() as usize;
    let mut times = Vec::with_capacity(n + 1);
    let mut samples = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let t = if k == n {
            end
        } else {
            start + Duration::milliseconds((k as f64 * step_s * 1000.0).round() as i64)
        };
        let met = Met {
            air_temp_c: diurnal_air_temp_c(p, lat_deg, lon_deg, t),
            dew_point_c: Some(p.dew_point_c),
            rh_percent: None,
            wind_m_s: p.wind_m_s,
            pressure_hpa: p.pressure_pa / 100.0,
            cloud_fraction: Some(p.cloud_fraction),
            ghi: None,
            dni: None,
            dhi: None,
            sky_temp_c: None,
            precip_mm_h: 0.0,
        };
        times.push(t);
        samples.push(build_sample(&c, met).map_err(|e| WeatherError::Invalid(format!("{e}")))?);
    }
    WeatherHistory::new(times, samples, "constant")
}
