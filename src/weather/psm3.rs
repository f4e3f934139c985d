//! NSRDB PSM3 / PSM4 CSV files (NREL's "SAM CSV" layout).

use super::parse::*;
use super::*;

/// Reads an NSRDB PSM3 (or PSM4) CSV from text (the SAM CSV layout of
/// NREL's National Solar Radiation Database downloads, read as pvlib's
/// `read_nsrdb_psm4` reads it): line 1 metadata names and line 2 their
/// values (`Latitude`, `Longitude`, `Time Zone` in hours, `Elevation` m,
/// `Location ID`, `City`), line 3 column names, then records
/// `Year,Month,Day,Hour,Minute,…` in the file's time zone. Columns used:
/// `Temperature` (°C), `Dew Point` (°C) or `Relative Humidity` (%),
/// `Pressure` (mbar), `Wind Speed` (m/s), `GHI`, `DNI`, `DHI` (W/m²). The
/// NSRDB gives no cloud cover (its `Cloud Type` is a class, not a
/// fraction): the forcing derives it from GHI. Every value belongs to its
/// time stamp (the NSRDB's satellite values are instantaneous; its TMY
/// files stamp each hour at its middle, HH:30).
pub fn parse_psm3(text: &str, file: &str, opts: &ReadOptions) -> Result<WeatherFile, WeatherError> {
    let mut lines = text.lines();
    let (c1, c2, c3) = (
        Ctx { file, line: 1 },
        Ctx { file, line: 2 },
        Ctx { file, line: 3 },
    );
    let names = split_csv(lines.next().unwrap_or(""));
    let values = split_csv(lines.next().unwrap_or(""));
    let meta = |k: &str| -> Result<&str, WeatherError> {
        names
            .iter()
            .position(|n| n.trim() == k)
            .and_then(|i| values.get(i))
            .map(|v| v.trim())
            .ok_or_else(|| c1.malformed(format!("PSM3 metadata has no '{k}' (lines 1-2)")))
    };
    let station = WeatherStation {
        name: [
            meta("Location ID").unwrap_or(""),
            meta("City").unwrap_or(""),
        ]
        .iter()
        .filter(|s| !s.is_empty() && **s != "-")
        .copied()
        .collect::<Vec<_>>()
        .join(" "),
        lat_deg: c2.bound(
            c2.num(meta("Latitude")?, "Latitude")?,
            &bounds::weather::LATITUDE,
        )?,
        lon_deg: c2.bound(
            c2.num(meta("Longitude")?, "Longitude")?,
            &bounds::weather::LONGITUDE,
        )?,
        utc_offset_h: c2.num(meta("Time Zone")?, "Time Zone")?,
        elevation_m: c2.bound(
            c2.num(meta("Elevation")?, "Elevation")?,
            &bounds::weather::ELEVATION,
        )?,
    };
    let tz = utc_offset_from_hours(&c2, station.utc_offset_h)?;
    let cols: Vec<String> = split_csv(lines.next().unwrap_or(""))
        .iter()
        .map(|s| s.trim().to_string())
        .collect();
    let find = |n: &str| cols.iter().position(|x| x == n);
    let need =
        |n: &str| find(n).ok_or_else(|| c3.malformed(format!("PSM3 header has no '{n}' column")));
    let (i_y, i_mo, i_d, i_h, i_mi) = (
        need("Year")?,
        need("Month")?,
        need("Day")?,
        need("Hour")?,
        need("Minute")?,
    );
    let (i_t, i_w) = (need("Temperature")?, need("Wind Speed")?);
    let (i_td, i_rh, i_p) = (
        find("Dew Point"),
        find("Relative Humidity"),
        find("Pressure"),
    );
    let (i_ghi, i_dni, i_dhi) = (find("GHI"), find("DNI"), find("DHI"));
    let width = [i_y, i_mo, i_d, i_h, i_mi, i_t, i_w]
        .into_iter()
        .chain([i_td, i_rh, i_p, i_ghi, i_dni, i_dhi].into_iter().flatten())
        .max()
        .unwrap_or(0)
        + 1;
    let mut raws = Vec::new();
    for (k, line) in lines.enumerate() {
        let c = Ctx { file, line: k + 4 };
        if line.trim().is_empty() {
            continue;
        }
        let f = split_csv(line);
        if f.len() < width {
            return Err(c.malformed(format!(
                "{} fields, expected at least {width} as in the PSM3 header",
                f.len()
            )));
        }
        let opt = |i: Option<usize>| -> Result<Option<f64>, WeatherError> {
            match i {
                Some(i) if !f[i].trim().is_empty() => c.num(&f[i], &cols[i]).map(Some),
                _ => Ok(None),
            }
        };
        let req =
            |i: usize| opt(Some(i))?.ok_or_else(|| c.malformed(format!("{} is empty", cols[i])));
        let int = |i: usize| -> Result<i64, WeatherError> {
            let v = req(i)?;
            if v.fract() != 0.0 || v.abs() > 1e6 {
                return Err(c.malformed(format!(
                    "{} '{}' is not an integer",
                    cols[i],
                    f[i].trim()
                )));
            }
            Ok(v as i64)
        };
        let date = c.date(int(i_y)?, int(i_mo)?, int(i_d)?)?;
        let (h, mi) = (int(i_h)?, int(i_mi)?);
        if !(0..24).contains(&h) || !(0..60).contains(&mi) {
            return Err(c.malformed(format!(
                "Hour {h} Minute {mi}: expected hour 0-23 and minute 0-59"
            )));
        }
        let met = Met {
            air_temp_c: req(i_t)?,
            dew_point_c: opt(i_td)?,
            rh_percent: opt(i_rh)?,
            wind_m_s: req(i_w)?,
            pressure_hpa: opt(i_p)?.unwrap_or_else(|| standard_pressure_hpa(station.elevation_m)),
            cloud_fraction: None,
            ghi: opt(i_ghi)?,
            dni: opt(i_dni)?,
            dhi: opt(i_dhi)?,
            sky_temp_c: None,
            precip_mm_h: 0.0,
        };
        raws.push(Stamped {
            line: k + 4,
            date,
            minutes: h * 60 + mi,
            sample: build_sample(&c, met)?,
        });
    }
    Ok(WeatherFile {
        history: place(raws, tz, file, opts, false)?,
        format: WeatherFormat::Psm3,
        station: Some(station),
    })
}
