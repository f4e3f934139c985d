//! NREL TMY3 weather files.

use super::parse::*;
use super::*;

/// A TMY3 column name as written, trimmed, with SolarAnywhere's doubled
/// closing parenthesis (`DNI (W/m^2))`) undone.
fn tmy3_column_name(s: &str) -> String {
    let mut n = s.trim();
    while n.ends_with("))") {
        n = &n[..n.len() - 1];
    }
    n.to_string()
}

/// Reads an NREL TMY3 CSV from text (also SolarAnywhere's "TMY3 format":
/// an eighth station field, `DNI (W/m^2))`, empty cells for missing values). Line 1: station id, name, state, UTC
/// offset (h), latitude, longitude, elevation (m); line 2: column names;
/// then hourly records `MM/DD/YYYY,HH:MM,…` in local standard time with
/// hour-ending stamps 01:00..24:00 (Wilcox & Marion 2008, NREL/TP-581-43156).
/// Missing values are −9900 (an error for the meteorological fields; absent
/// for irradiances; 0 for precipitation).
pub fn parse_tmy3(text: &str, file: &str, opts: &ReadOptions) -> Result<WeatherFile, WeatherError> {
    let mut lines = text.lines();
    let c1 = Ctx { file, line: 1 };
    let meta = split_csv(lines.next().unwrap_or(""));
    // SolarAnywhere's "TMY3 format" adds a quoted eighth field (data
    // version, licence) and empty ones.
    if meta.len() < 7 {
        return Err(c1.malformed(format!(
            "{} fields in the TMY3 station line, expected 7 (USAF id, name, state, UTC offset, latitude, longitude, elevation)",
            meta.len()
        )));
    }
    let station = WeatherStation {
        name: meta[1].trim().to_string(),
        utc_offset_h: c1.num(&meta[3], "time zone")?,
        lat_deg: c1.bound(c1.num(&meta[4], "latitude")?, &bounds::weather::LATITUDE)?,
        lon_deg: c1.bound(c1.num(&meta[5], "longitude")?, &bounds::weather::LONGITUDE)?,
        elevation_m: c1.bound(c1.num(&meta[6], "elevation")?, &bounds::weather::ELEVATION)?,
    };
    let tz = utc_offset_from_hours(&c1, station.utc_offset_h)?;
    let c2 = Ctx { file, line: 2 };
    let names: Vec<String> = split_csv(lines.next().unwrap_or(""))
        .iter()
        .map(|s| tmy3_column_name(s))
        .collect();
    let find = |n: &str| -> Result<usize, WeatherError> {
        names
            .iter()
            .position(|x| x == n)
            .ok_or_else(|| c2.malformed(format!("TMY3 header has no '{n}' column")))
    };
    let (i_t, i_td, i_rh, i_p, i_w, i_cld) = (
        find("Dry-bulb (C)")?,
        find("Dew-point (C)")?,
        find("RHum (%)")?,
        find("Pressure (mbar)")?,
        find("Wspd (m/s)")?,
        find("TotCld (tenths)")?,
    );
    let (i_ghi, i_dni, i_dhi) = (
        find("GHI (W/m^2)")?,
        find("DNI (W/m^2)")?,
        find("DHI (W/m^2)")?,
    );
    let i_pd = names.iter().position(|x| x == "Lprecip depth (mm)");
    let i_pq = names.iter().position(|x| x == "Lprecip quantity (hr)");
    let mut raws = Vec::new();
    for (k, line) in lines.enumerate() {
        let c = Ctx { file, line: k + 3 };
        if line.trim().is_empty() {
            continue;
        }
        let f = split_csv(line);
        if f.len() < names.len() {
            return Err(c.malformed(format!(
                "{} fields, expected {} as in the TMY3 header",
                f.len(),
                names.len()
            )));
        }
        let date = NaiveDate::parse_from_str(f[0].trim(), "%m/%d/%Y")
            .map_err(|_| c.malformed(format!("date '{}': expected MM/DD/YYYY", f[0].trim())))?;
        c.date(date.year().into(), date.month().into(), date.day().into())?;
        let (hh, mm) = f[1]
            .trim()
            .split_once(':')
            .and_then(|(h, m)| Some((h.parse::<i64>().ok()?, m.parse::<i64>().ok()?)))
            .filter(|&(h, m)| (0..=24).contains(&h) && (0..60).contains(&m) && (h < 24 || m == 0))
            .ok_or_else(|| {
                c.malformed(format!(
                    "time '{}': expected HH:MM from 01:00 to 24:00",
                    f[1].trim()
                ))
            })?;
        // Missing: -9900 (NREL) or an empty cell (SolarAnywhere).
        let opt = |i: usize, what: &str| -> Result<Option<f64>, WeatherError> {
            if f[i].trim().is_empty() {
                return Ok(None);
            }
            let v = c.num(&f[i], what)?;
            Ok((v != -9900.0).then_some(v))
        };
        let req = |i: usize, what: &str| -> Result<f64, WeatherError> {
            opt(i, what)?
                .ok_or_else(|| c.malformed(format!("{what} is missing ('{}')", f[i].trim())))
        };
        let td = opt(i_td, "Dew-point (C)")?;
        let rh = opt(i_rh, "RHum (%)")?;
        let precip = match (i_pd, i_pq) {
            (Some(d), Some(q)) => match (
                opt(d, "Lprecip depth (mm)")?,
                opt(q, "Lprecip quantity (hr)")?,
            ) {
                (Some(depth), Some(hours)) if hours > 0.0 => depth / hours,
                (Some(depth), _) => depth,
                _ => 0.0,
            },
            _ => 0.0,
        };
        let met = Met {
            air_temp_c: req(i_t, "Dry-bulb (C)")?,
            dew_point_c: td,
            rh_percent: rh,
            wind_m_s: req(i_w, "Wspd (m/s)")?,
            pressure_hpa: opt(i_p, "Pressure (mbar)")?
                .unwrap_or_else(|| standard_pressure_hpa(station.elevation_m)),
            cloud_fraction: opt(i_cld, "TotCld (tenths)")?
                .map(|v| c.range(v, "TotCld (tenths)", 0.0, 10.0, "tenths"))
                .transpose()?
                .map(|v| v / 10.0),
            ghi: opt(i_ghi, "GHI")?,
            dni: opt(i_dni, "DNI")?,
            dhi: opt(i_dhi, "DHI")?,
            sky_temp_c: None,
            precip_mm_h: precip,
        };
        raws.push(Stamped {
            line: k + 3,
            date,
            minutes: hh * 60 + mm,
            sample: build_sample(&c, met)?,
        });
    }
    Ok(WeatherFile {
        history: place(raws, tz, file, opts, true)?,
        format: WeatherFormat::Tmy3,
        station: Some(station),
    })
}
