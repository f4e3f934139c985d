//! EnergyPlus EPW weather files.

use super::parse::*;
use super::*;

/// Reads an EnergyPlus EPW file from text (EnergyPlus Auxiliary Programs,
/// "Weather Converter Program"): 8 header lines (LOCATION: city, state,
/// country, source, WMO, latitude, longitude, UTC offset, elevation), then
/// records `year,month,day,hour(1-24),minute,flags,dry bulb °C,dew point °C,
/// RH %,pressure Pa,…` in local standard time, hour-ending. Fields used
/// (0-based): 6 dry bulb, 7 dew point, 8 RH, 9 pressure, 12 horizontal
/// infrared (→ sky temperature), 13 GHI, 14 DNI, 15 DHI, 21 wind speed,
/// 22 total sky cover (tenths), 33/34 liquid precipitation depth/quantity.
/// Missing codes (99.9, 999, 999999, 9999, 99) give an error for required
/// fields and `None`/0 for optional ones.
pub fn parse_epw(text: &str, file: &str, opts: &ReadOptions) -> Result<WeatherFile, WeatherError> {
    let mut lines = text.lines();
    let c1 = Ctx { file, line: 1 };
    let loc = split_csv(lines.next().unwrap_or(""));
    if loc.len() < 10 || loc[0].trim() != "LOCATION" {
        return Err(c1.malformed(
            "expected the EPW LOCATION line: LOCATION,city,state,country,source,WMO,latitude,longitude,time zone,elevation",
        ));
    }
    let station = WeatherStation {
        name: loc[1].trim().to_string(),
        lat_deg: c1.bound(c1.num(&loc[6], "latitude")?, &bounds::weather::LATITUDE)?,
        lon_deg: c1.bound(c1.num(&loc[7], "longitude")?, &bounds::weather::LONGITUDE)?,
        utc_offset_h: c1.num(&loc[8], "time zone")?,
        elevation_m: c1.bound(c1.num(&loc[9], "elevation")?, &bounds::weather::ELEVATION)?,
    };
    let tz = utc_offset_from_hours(&c1, station.utc_offset_h)?;
    for k in 2..=8 {
        if lines.next().is_none() {
            return Err(Ctx { file, line: k }.malformed("file ends inside the 8 EPW header lines"));
        }
    }
    let mut raws = Vec::new();
    for (k, line) in lines.enumerate() {
        let lineno = k + 9;
        let c = Ctx { file, line: lineno };
        if line.trim().is_empty() {
            continue;
        }
        let f = split_csv(line);
        if f.len() < 35 {
            return Err(c.malformed(format!("{} fields, expected 35 EPW data fields", f.len())));
        }
        let int = |i: usize, what: &str| -> Result<i64, WeatherError> {
            f[i].trim()
                .parse::<i64>()
                .map_err(|_| c.malformed(format!("{what} '{}' is not an integer", f[i].trim())))
        };
        let year = int(0, "year")?;
        let (month, day, hour, minute) = (
            int(1, "month")?,
            int(2, "day")?,
            int(3, "hour")?,
            int(4, "minute")?,
        );
        let date = c.date(year, month, day)?;
        if !(1..=24).contains(&hour) || !(0..=60).contains(&minute) {
            return Err(c.malformed(format!(
                "hour {hour} minute {minute}: expected hour 1..24 (hour-ending) and minute 0..60"
            )));
        }
        // Hour h, minute m covers ((h−1):00 + m − interval, (h−1):00 + m];
        // hourly files write minute 60 (or 0, meaning the full hour).
        let end_min = if minute == 0 { 60 } else { minute };
        let val = |i: usize, what: &str, missing: f64| -> Result<Option<f64>, WeatherError> {
            let v = c.num(&f[i], what)?;
            Ok((v < missing).then_some(v))
        };
        let req = |i: usize, what: &str, missing: f64| -> Result<f64, WeatherError> {
            val(i, what, missing)?
                .ok_or_else(|| c.malformed(format!("{what} is missing ({})", f[i].trim())))
        };
        let lw = val(12, "horizontal infrared radiation", 9999.0)?;
        let sky_temp_c = lw
            .filter(|&x| x > 0.0)
            .map(|x| sky_temp_k_from_irradiance(x) - ZERO_C_K);
        let precip = match (
            val(33, "liquid precipitation depth", 999.0)?,
            val(34, "liquid precipitation quantity", 99.0)?,
        ) {
            (Some(d), Some(q)) if q > 0.0 => d / q,
            (Some(d), _) => d,
            _ => 0.0,
        };
        let met = Met {
            air_temp_c: req(6, "dry bulb temperature", 99.9)?,
            dew_point_c: val(7, "dew point temperature", 99.9)?,
            rh_percent: val(8, "relative humidity", 999.0)?,
            wind_m_s: req(21, "wind speed", 999.0)?,
            pressure_hpa: val(9, "atmospheric pressure", 999999.0)?
                .map_or_else(|| standard_pressure_hpa(station.elevation_m), |p| p / 100.0),
            cloud_fraction: val(22, "total sky cover", 99.0)?
                .map(|v| c.range(v, "total sky cover", 0.0, 10.0, "tenths"))
                .transpose()?
                .map(|v| v / 10.0),
            ghi: val(13, "GHI", 9999.0)?,
            dni: val(14, "DNI", 9999.0)?,
            dhi: val(15, "DHI", 9999.0)?,
            sky_temp_c,
            precip_mm_h: precip,
        };
        raws.push(Stamped {
            line: lineno,
            date,
            minutes: (hour - 1) * 60 + end_min,
            sample: build_sample(&c, met)?,
        });
    }
    Ok(WeatherFile {
        history: place(raws, tz, file, opts, true)?,
        format: WeatherFormat::Epw,
        station: Some(station),
    })
}
