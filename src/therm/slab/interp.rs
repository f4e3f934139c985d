//! The forcing series between its samples: linear interpolation, checks.

use crate::therm::forcing::Forcing;

use super::*;

/// Forcing interpolated at one instant (see module docs).
pub fn forcing_at(forcing: &[Forcing], t_s: f64) -> Forcing {
    let n = forcing.len();
    if t_s <= forcing[0].t_s {
        return forcing[0];
    }
    if t_s >= forcing[n - 1].t_s {
        return forcing[n - 1];
    }
    // index of the segment [j, j+1] containing t
    let j = forcing
        .partition_point(|f| f.t_s <= t_s)
        .saturating_sub(1)
        .min(n - 2);
    let (a, b) = (&forcing[j], &forcing[j + 1]);
    let w = (t_s - a.t_s) / (b.t_s - a.t_s);
    let lerp = |x: f64, y: f64| x + w * (y - x);
    let mut s = [
        lerp(a.sun_dir_enu[0], b.sun_dir_enu[0]),
        lerp(a.sun_dir_enu[1], b.sun_dir_enu[1]),
        lerp(a.sun_dir_enu[2], b.sun_dir_enu[2]),
    ];
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    if len > 1e-12 {
        for c in &mut s {
            *c /= len;
        }
    }
    Forcing {
        t_s,
        air_temp_k: lerp(a.air_temp_k, b.air_temp_k),
        sky_temp_k: lerp(a.sky_temp_k, b.sky_temp_k),
        wind_speed_m_s: lerp(a.wind_speed_m_s, b.wind_speed_m_s),
        dni_w_m2: lerp(a.dni_w_m2, b.dni_w_m2),
        dhi_w_m2: lerp(a.dhi_w_m2, b.dhi_w_m2),
        ghi_w_m2: lerp(a.ghi_w_m2, b.ghi_w_m2),
        sun_dir_enu: s,
        dew_point_k: lerp(a.dew_point_k, b.dew_point_k),
        pressure_pa: lerp(a.pressure_pa, b.pressure_pa),
        precip_mm_h: lerp(a.precip_mm_h, b.precip_mm_h),
        ground_temp_k: match (a.ground_temp_k, b.ground_temp_k) {
            (Some(x), Some(y)) => Some(lerp(x, y)),
            _ => None,
        },
    }
}

/// Checks a forcing series: non-empty, strictly increasing times, finite
/// values, positive temperatures, non-negative wind and irradiances.
pub fn validate_forcing(forcing: &[Forcing]) -> Result<(), ThermError> {
    if forcing.is_empty() {
        return Err(ThermError::BadInput("empty forcing series".into()));
    }
    for (i, f) in forcing.iter().enumerate() {
        let vals = [
            ("t_s", f.t_s),
            ("air_temp_k", f.air_temp_k),
            ("sky_temp_k", f.sky_temp_k),
            ("wind_speed_m_s", f.wind_speed_m_s),
            ("dni_w_m2", f.dni_w_m2),
            ("dhi_w_m2", f.dhi_w_m2),
            ("ghi_w_m2", f.ghi_w_m2),
            ("sun_dir_enu[0]", f.sun_dir_enu[0]),
            ("sun_dir_enu[1]", f.sun_dir_enu[1]),
            ("sun_dir_enu[2]", f.sun_dir_enu[2]),
        ];
        for (name, v) in vals {
            if !v.is_finite() {
                return Err(ThermError::BadInput(format!(
                    "forcing sample {i}: {name} is not finite"
                )));
            }
        }
        if f.air_temp_k <= 0.0 || f.sky_temp_k < 0.0 {
            return Err(ThermError::BadInput(format!(
                "forcing sample {i}: temperatures must be > 0 K"
            )));
        }
        if f.wind_speed_m_s < 0.0 || f.dni_w_m2 < 0.0 || f.dhi_w_m2 < 0.0 || f.ghi_w_m2 < 0.0 {
            return Err(ThermError::BadInput(format!(
                "forcing sample {i}: wind speed and irradiances must be >= 0"
            )));
        }
        if i > 0 && f.t_s <= forcing[i - 1].t_s {
            return Err(ThermError::BadInput(format!(
                "forcing sample {i}: time {} s is not after the previous sample ({} s)",
                f.t_s,
                forcing[i - 1].t_s
            )));
        }
    }
    Ok(())
}
