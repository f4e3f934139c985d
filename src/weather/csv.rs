//! The plain CSV weather format (docs/weather-format.md): one record per
//! line, every value instantaneous at its time stamp.

use super::parse::*;
use super::*;

/// Parses a plain-CSV time: RFC 3339 with an offset, or an ISO local time
/// (`YYYY-MM-DDTHH:MM[:SS]`, `T` or space) in `tz`.
fn parse_plain_time(
    c: &Ctx,
    s: &str,
    tz: Option<FixedOffset>,
) -> Result<DateTime<Utc>, WeatherError> {
    let s = s.trim();
    if let Ok(t) = DateTime::parse_from_rfc3339(s) {
        return Ok(t.with_timezone(&Utc));
    }
    for f in [
        "%Y-%m-%dT%H:%M:%S%.f",
        "%Y-%m-%dT%H:%M",
        "%Y-%m-%d %H:%M:%S%.f",
        "%Y-%m-%d %H:%M",
    ] {
        if let Ok(n) = NaiveDateTime::parse_from_str(s, f) {
            let Some(tz) = tz else {
                return Err(c.malformed(format!(
                    "time '{s}' has no UTC offset and no time zone was given: write e.g. {}Z or {}-05:00, \
                     add a '# utc_offset: -05:00' line before the header, or pass the file's time zone",
                    n.format("%Y-%m-%dT%H:%M:%S"),
                    n.format("%Y-%m-%dT%H:%M:%S")
                )));
            };
            return tz
                .from_local_datetime(&n)
                .single()
                .map(|t| t.with_timezone(&Utc))
                .ok_or_else(|| {
                    c.malformed(format!("time '{s}' does not exist in UTC offset {tz}"))
                });
        }
    }
    Err(c.malformed(format!(
        "cannot read time '{s}': expected RFC 3339 (2024-06-21T12:00:00Z, 2024-06-21T07:00:00-05:00) \
         or ISO local time (2024-06-21T07:00 or 2024-06-21 07:00:00) with a time zone"
    )))
}

/// Columns of the plain CSV format (docs/weather-format.md).
pub const PLAIN_CSV_COLUMNS: [&str; 13] = [
    "time",
    "air_temp_c",
    "dew_point_c",
    "rh_percent",
    "wind_m_s",
    "pressure_hpa",
    "cloud_fraction",
    "cloud_tenths",
    "ghi_w_m2",
    "dni_w_m2",
    "dhi_w_m2",
    "sky_temp_c",
    "precip_mm_h",
];

/// Reads the plain CSV weather format from text (`file` names it in errors).
pub fn parse_plain_csv(
    text: &str,
    file: &str,
    opts: &ReadOptions,
) -> Result<WeatherFile, WeatherError> {
    let mut tz = opts.utc_offset;
    let mut header: Option<(usize, Vec<String>)> = None;
    let mut raws = Vec::new();
    let mut col = [None::<usize>; 13];
    for (i, line) in text.lines().enumerate() {
        let c = Ctx { file, line: i + 1 };
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        if let Some(comment) = t.strip_prefix('#') {
            if let Some(v) = comment.trim().strip_prefix("utc_offset:") {
                let off = parse_offset(v).ok_or_else(|| {
                    c.malformed(format!("utc_offset '{}': expected e.g. -05:00", v.trim()))
                })?;
                tz = tz.or(Some(off));
            }
            continue;
        }
        let fields = split_csv(t);
        let Some((_, names)) = &header else {
            let names: Vec<String> = fields
                .iter()
                .map(|f| f.trim().to_ascii_lowercase())
                .collect();
            for (k, n) in names.iter().enumerate() {
                match PLAIN_CSV_COLUMNS.iter().position(|x| x == n) {
                    Some(j) if col[j].is_some() => {
                        return Err(c.malformed(format!("column '{n}' appears twice")));
                    }
                    Some(j) => col[j] = Some(k),
                    None if n.starts_with("x_") => {}
                    None => {
                        return Err(c.malformed(format!(
                            "unknown column '{n}': expected the header to name columns from {} \
                             (prefix extra columns with x_ to keep them)",
                            PLAIN_CSV_COLUMNS.join(", ")
                        )));
                    }
                }
            }
            let need = |j: usize, alt: Option<usize>, what: &str| -> Result<(), WeatherError> {
                if col[j].is_none() && alt.is_none_or(|a| col[a].is_none()) {
                    return Err(c.malformed(format!("the header has no {what} column")));
                }
                Ok(())
            };
            need(0, None, "time")?;
            need(1, None, "air_temp_c")?;
            need(2, Some(3), "dew_point_c or rh_percent")?;
            need(4, None, "wind_m_s")?;
            header = Some((i + 1, names));
            continue;
        };
        if fields.len() != names.len() {
            return Err(c.malformed(format!(
                "{} fields, expected {} as in the header ({})",
                fields.len(),
                names.len(),
                names.join(",")
            )));
        }
        let get = |j: usize| col[j].map(|k| fields[k].trim()).filter(|s| !s.is_empty());
        let req = |j: usize| {
            get(j).ok_or_else(|| c.malformed(format!("{} is empty", PLAIN_CSV_COLUMNS[j])))
        };
        let opt = |j: usize| get(j).map(|s| c.num(s, PLAIN_CSV_COLUMNS[j])).transpose();
        let time = parse_plain_time(&c, req(0)?, tz)?;
        c.bound(time.year().into(), &bounds::time::YEAR)?;
        let cloud_fraction = match (opt(6)?, opt(7)?) {
            (Some(f), _) => Some(f),
            (None, Some(tenths)) => {
                Some(c.range(tenths, "cloud_tenths", 0.0, 10.0, "tenths")? / 10.0)
            }
            (None, None) => None,
        };
        let met = Met {
            air_temp_c: c.num(req(1)?, "air_temp_c")?,
            dew_point_c: opt(2)?,
            rh_percent: opt(3)?,
            wind_m_s: c.num(req(4)?, "wind_m_s")?,
            pressure_hpa: opt(5)?.unwrap_or(1013.25),
            cloud_fraction,
            ghi: opt(8)?,
            dni: opt(9)?,
            dhi: opt(10)?,
            sky_temp_c: opt(11)?,
            precip_mm_h: opt(12)?.unwrap_or(0.0),
        };
        raws.push(Raw {
            line: i + 1,
            time,
            sample: build_sample(&c, met)?,
        });
    }
    if header.is_none() {
        return Err(WeatherError::Empty {
            file: file.into(),
            expected: format!(
                "a header row naming columns from {}",
                PLAIN_CSV_COLUMNS.join(", ")
            ),
        });
    }
    Ok(WeatherFile {
        history: assemble(raws, file, opts, false)?,
        format: WeatherFormat::Csv,
        station: None,
    })
}
