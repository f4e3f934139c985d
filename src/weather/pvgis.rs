//! PVGIS typical-meteorological-year CSV files (EU JRC).

use super::parse::*;
use super::*;
use chrono::Timelike;

/// Reads a PVGIS TMY CSV from text (the CSV output of the EU JRC's PVGIS
/// `tmy` tool, read as pvlib's `read_pvgis_tmy` reads it): header lines
/// `Latitude (decimal degrees): …`, `Longitude (decimal degrees): …`,
/// `Elevation (m): …`, the months' source years, then the column line
/// `time(UTC),T2m,RH,G(h),Gb(n),Gd(h),IR(h),WS10m,WD10m,SP` and hourly
/// records `YYYYMMDD:HHMM,…` in UTC up to a blank line (a legend follows).
/// Fields: air temperature T2m (°C), relative humidity RH (%), GHI G(h),
/// DNI Gb(n), DHI Gd(h) (W/m²), downwelling infrared IR(h) (W/m², → sky
/// temperature T = (IR/σ)^¼), wind WS10m (m/s), pressure SP (Pa). PVGIS
/// gives no cloud cover (the measured infrared makes it unnecessary). Every
/// value belongs to its time stamp, as pvlib reads them (the header's
/// `Irradiance Time Offset` is not applied).
pub fn parse_pvgis_csv(
    text: &str,
    file: &str,
    opts: &ReadOptions,
) -> Result<WeatherFile, WeatherError> {
    let mut head = [None::<f64>; 3];
    let keys = [
        "Latitude (decimal degrees):",
        "Longitude (decimal degrees):",
        "Elevation (m):",
    ];
    let mut cols: Option<(usize, Vec<String>)> = None;
    let mut raws = Vec::new();
    let mut station: Option<WeatherStation> = None;
    for (i, line) in text.lines().enumerate() {
        let c = Ctx { file, line: i + 1 };
        let t = line.trim();
        let Some((_, names)) = &cols else {
            for (k, key) in keys.iter().enumerate() {
                if let Some(v) = t.strip_prefix(key) {
                    head[k] = Some(c.num(v, key.trim_end_matches(':'))?);
                }
            }
            if t.starts_with("time(UTC),") {
                let [Some(lat), Some(lon), Some(elev)] = head else {
                    return Err(c.malformed(
                        "the PVGIS header before the column line lacks Latitude (decimal degrees), \
                         Longitude (decimal degrees) or Elevation (m)",
                    ));
                };
                station = Some(WeatherStation {
                    name: format!("PVGIS {lat:.3} {lon:.3}"),
                    lat_deg: c.bound(lat, &bounds::weather::LATITUDE)?,
                    lon_deg: c.bound(lon, &bounds::weather::LONGITUDE)?,
                    elevation_m: c.bound(elev, &bounds::weather::ELEVATION)?,
                    utc_offset_h: 0.0,
                });
                let names: Vec<String> =
                    split_csv(t).iter().map(|s| s.trim().to_string()).collect();
                for n in ["T2m", "RH", "WS10m"] {
                    if !names.iter().any(|x| x == n) {
                        return Err(c.malformed(format!("PVGIS column line has no '{n}' column")));
                    }
                }
                cols = Some((i + 1, names));
            }
            continue;
        };
        if t.is_empty() {
            break; // the legend follows the records
        }
        let f = split_csv(t);
        if f.len() != names.len() {
            return Err(c.malformed(format!(
                "{} fields, expected {} as in the PVGIS column line",
                f.len(),
                names.len()
            )));
        }
        let get = |n: &str| -> Result<Option<f64>, WeatherError> {
            match names.iter().position(|x| x == n) {
                Some(k) if !f[k].trim().is_empty() => c.num(&f[k], n).map(Some),
                _ => Ok(None),
            }
        };
        let req = |n: &str| get(n)?.ok_or_else(|| c.malformed(format!("{n} is empty")));
        let stamp = NaiveDateTime::parse_from_str(f[0].trim(), "%Y%m%d:%H%M").map_err(|_| {
            c.malformed(format!(
                "time '{}': expected YYYYMMDD:HHMM (UTC)",
                f[0].trim()
            ))
        })?;
        let date = c.date(
            stamp.year().into(),
            stamp.month().into(),
            stamp.day().into(),
        )?;
        let elev = station.as_ref().map_or(0.0, |s| s.elevation_m);
        let sky_temp_c = get("IR(h)")?
            .map(|x| c.range(x, "IR(h)", 0.0, bounds::weather::IRRADIANCE.hi, "W/m²"))
            .transpose()?
            .filter(|&x| x > 0.0)
            .map(|x| sky_temp_k_from_irradiance(x) - ZERO_C_K);
        let met = Met {
            air_temp_c: req("T2m")?,
            dew_point_c: None,
            rh_percent: Some(req("RH")?),
            wind_m_s: req("WS10m")?,
            pressure_hpa: get("SP")?.map_or_else(|| standard_pressure_hpa(elev), |p| p / 100.0),
            cloud_fraction: None,
            ghi: get("G(h)")?,
            dni: get("Gb(n)")?,
            dhi: get("Gd(h)")?,
            sky_temp_c,
            precip_mm_h: 0.0,
        };
        raws.push(Stamped {
            line: i + 1,
            date,
            minutes: (stamp.hour() * 60 + stamp.minute()).into(),
            sample: build_sample(&c, met)?,
        });
    }
    let Some(station) = station else {
        return Err(WeatherError::Empty {
            file: file.into(),
            expected:
                "the PVGIS column line time(UTC),T2m,RH,G(h),Gb(n),Gd(h),IR(h),WS10m,WD10m,SP"
                    .into(),
        });
    };
    let utc = FixedOffset::east_opt(0).unwrap();
    Ok(WeatherFile {
        history: place(raws, utc, file, opts, false)?,
        format: WeatherFormat::Pvgis,
        station: Some(station),
    })
}
