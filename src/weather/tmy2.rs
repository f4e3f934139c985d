//! NREL TMY2 weather files (fixed-width text, 1961-1990 typical years).

use super::parse::*;
use super::*;

/// Columns read from a TMY2 data line: name, first byte (0-based), end byte,
/// scale to the unit used (TMY2 User's Manual, Marion & Urban 1995,
/// NREL/TP-463-7668, table 3-1; the same layout as pvlib's `read_tmy2`).
const FIELDS: [(&str, usize, usize, f64); 13] = [
    ("year", 1, 3, 1.0),
    ("month", 3, 5, 1.0),
    ("day", 5, 7, 1.0),
    ("hour", 7, 9, 1.0),
    ("global horizontal radiation (Wh/m2)", 17, 21, 1.0),
    ("direct normal radiation (Wh/m2)", 23, 27, 1.0),
    ("diffuse horizontal radiation (Wh/m2)", 29, 33, 1.0),
    ("total sky cover (tenths)", 59, 61, 1.0),
    ("dry bulb temperature (0.1 C)", 67, 71, 0.1),
    ("dew point temperature (0.1 C)", 73, 77, 0.1),
    ("relative humidity (%)", 79, 82, 1.0),
    ("atmospheric pressure (mbar)", 84, 88, 1.0),
    ("wind speed (0.1 m/s)", 95, 98, 0.1),
];

/// The station line of a TMY2 file: WBAN, city (may hold spaces), state,
/// UTC offset (h), `N|S deg min`, `E|W deg min`, elevation (m). `None` if
/// the line does not have that shape.
pub(super) fn tmy2_station(line: &str) -> Option<(String, [f64; 4])> {
    let t: Vec<&str> = line.split_whitespace().collect();
    let n = t.len();
    if n < 10
        || line.contains(',')
        || !matches!(t[n - 7], "N" | "S")
        || !matches!(t[n - 4], "E" | "W")
    {
        return None;
    }
    let num = |s: &str| s.parse::<f64>().ok();
    let lat = (num(t[n - 6])? + num(t[n - 5])? / 60.0) * if t[n - 7] == "S" { -1.0 } else { 1.0 };
    let lon = (num(t[n - 3])? + num(t[n - 2])? / 60.0) * if t[n - 4] == "W" { -1.0 } else { 1.0 };
    let name = t[1..n - 9].join(" ");
    Some((name, [num(t[n - 8])?, lat, lon, num(t[n - 1])?]))
}

/// Reads an NREL TMY2 file from text: a station line (see [`tmy2_station`])
/// then 8760 fixed-width hourly records `YYMMDDHH…` in local standard time,
/// hour-ending (hour 1-24, years 19YY). Irradiances are energies over the
/// hour before the stamp (Wh/m² = mean W/m²), the meteorological fields
/// instantaneous. A field of all 9s is missing: an error for the dry-bulb
/// temperature and wind, "not measured" for the others (dew point: the
/// relative humidity is used; pressure: the standard atmosphere at the
/// station's elevation; cloud: derived from GHI). TMY2 has no precipitation
/// amount (0 is used).
pub fn parse_tmy2(text: &str, file: &str, opts: &ReadOptions) -> Result<WeatherFile, WeatherError> {
    let mut lines = text.lines();
    let c1 = Ctx { file, line: 1 };
    let (name, [tz_h, lat, lon, elev]) = tmy2_station(lines.next().unwrap_or("")).ok_or_else(|| {
        c1.malformed(
            "expected the TMY2 station line: WBAN, city, state, UTC offset, N|S deg min, E|W deg min, elevation",
        )
    })?;
    let station = WeatherStation {
        name,
        utc_offset_h: tz_h,
        lat_deg: c1.bound(lat, &bounds::weather::LATITUDE)?,
        lon_deg: c1.bound(lon, &bounds::weather::LONGITUDE)?,
        elevation_m: c1.bound(elev, &bounds::weather::ELEVATION)?,
    };
    let tz = utc_offset_from_hours(&c1, station.utc_offset_h)?;
    let mut raws = Vec::new();
    for (k, line) in lines.enumerate() {
        let c = Ctx { file, line: k + 2 };
        if line.trim().is_empty() {
            continue;
        }
        let end = FIELDS[FIELDS.len() - 1].2;
        let Some(l) = line.get(..end).filter(|l| l.is_ascii()) else {
            return Err(c.malformed(format!(
                "{} characters, expected a TMY2 record of at least {end} (fixed-width columns)",
                line.chars().count()
            )));
        };
        let mut v = [None::<f64>; 13];
        for (j, &(what, a, b, scale)) in FIELDS.iter().enumerate() {
            let s = &l[a..b];
            if !s.trim().is_empty() && s.trim().bytes().all(|x| x == b'9') && j >= 4 {
                continue;
            }
            v[j] = Some(c.num(s, what)? * scale);
        }
        let req = |j: usize| v[j].ok_or_else(|| c.malformed(format!("{} is missing", FIELDS[j].0)));
        let (yy, month, day, hour) = (req(0)?, req(1)?, req(2)?, req(3)?);
        let date = c.date(1900 + yy as i64, month as i64, day as i64)?;
        if !(1.0..=24.0).contains(&hour) || hour.fract() != 0.0 {
            return Err(c.malformed(format!("hour {hour}: expected 1 to 24 (hour-ending)")));
        }
        let met = Met {
            air_temp_c: req(8)?,
            dew_point_c: v[9],
            rh_percent: v[10],
            wind_m_s: req(12)?,
            pressure_hpa: v[11].unwrap_or_else(|| standard_pressure_hpa(station.elevation_m)),
            cloud_fraction: v[7]
                .map(|x| c.range(x, FIELDS[7].0, 0.0, 10.0, "tenths"))
                .transpose()?
                .map(|x| x / 10.0),
            ghi: v[4],
            dni: v[5],
            dhi: v[6],
            sky_temp_c: None,
            precip_mm_h: 0.0,
        };
        raws.push(Stamped {
            line: k + 2,
            date,
            minutes: hour as i64 * 60,
            sample: build_sample(&c, met)?,
        });
    }
    Ok(WeatherFile {
        history: place(raws, tz, file, opts, true)?,
        format: WeatherFormat::Tmy2,
        station: Some(station),
    })
}
