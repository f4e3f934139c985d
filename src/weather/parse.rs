//! What every reader shares: file/line context for errors (`Ctx`), the
//! range checks of a record's fields (`Met`, `build_sample`), and laying
//! records on one UTC time axis (`place`, `assemble`).

use super::*;

/// Splits one CSV line; double-quoted fields may contain commas.
pub(super) fn split_csv(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    for c in line.trim_end_matches(['\r', '\n']).chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// One parsed record before the history is assembled.
pub(super) struct Raw {
    pub(super) line: usize,
    pub(super) time: DateTime<Utc>,
    pub(super) sample: WeatherSample,
}

pub(super) struct Ctx<'a> {
    pub(super) file: &'a str,
    pub(super) line: usize,
}

impl Ctx<'_> {
    pub(super) fn malformed(&self, msg: impl Into<String>) -> WeatherError {
        WeatherError::Malformed {
            file: self.file.to_string(),
            line: self.line,
            msg: msg.into(),
        }
    }

    pub(super) fn num(&self, s: &str, field: &str) -> Result<f64, WeatherError> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| self.malformed(format!("{field}: '{}' is not a number", s.trim())))?;
        if !v.is_finite() {
            return Err(self.malformed(format!("{field}: '{}' is not a finite number", s.trim())));
        }
        Ok(v)
    }

    pub(super) fn range(
        &self,
        v: f64,
        field: &str,
        lo: f64,
        hi: f64,
        unit: &str,
    ) -> Result<f64, WeatherError> {
        if !(v >= lo && v <= hi) {
            return Err(WeatherError::OutOfRange {
                file: self.file.to_string(),
                line: self.line,
                field: field.to_string(),
                value: v,
                expected: format!("{lo} to {hi} {unit}"),
            });
        }
        Ok(v)
    }

    /// Checks `v` against its [`Bound`] (crate::bounds::weather).
    pub(super) fn bound(&self, v: f64, b: &Bound) -> Result<f64, WeatherError> {
        self.range(v, b.key, b.lo, b.hi, b.unit)
    }

    /// A calendar date of a record, with its year inside
    /// [`crate::bounds::time::YEAR`] (chrono's arithmetic on years near its
    /// limit of ±262 143 overflowed).
    pub(super) fn date(&self, year: i64, month: i64, day: i64) -> Result<NaiveDate, WeatherError> {
        self.bound(year as f64, &bounds::time::YEAR)?;
        let (Ok(month), Ok(day)) = (u32::try_from(month), u32::try_from(day)) else {
            return Err(self.malformed(format!("date {year}-{month}-{day} does not exist")));
        };
        NaiveDate::from_ymd_opt(year as i32, month, day)
            .ok_or_else(|| self.malformed(format!("date {year}-{month}-{day} does not exist")))
    }

    /// A record's local time in `tz`, as UTC (the year is already bounded,
    /// so this cannot overflow).
    pub(super) fn local_to_utc(
        &self,
        tz: FixedOffset,
        local: NaiveDateTime,
    ) -> Result<DateTime<Utc>, WeatherError> {
        tz.from_local_datetime(&local)
            .single()
            .map(|t| t.with_timezone(&Utc))
            .ok_or_else(|| {
                self.malformed(format!("time {local} does not exist in UTC offset {tz}"))
            })
    }

    /// An irradiance: values in [−10, 0) (sensor offsets at night) become 0.
    pub(super) fn irradiance(&self, v: f64, field: &str) -> Result<f64, WeatherError> {
        Ok(self
            .range(v, field, -10.0, bounds::weather::IRRADIANCE.hi, "W/m²")?
            .max(0.0))
    }
}

/// The range checks shared by every reader, in the file's own units.
pub(super) struct Met {
    pub(super) air_temp_c: f64,
    pub(super) dew_point_c: Option<f64>,
    pub(super) rh_percent: Option<f64>,
    pub(super) wind_m_s: f64,
    /// Readers whose files may omit it use [`standard_pressure_hpa`].
    pub(super) pressure_hpa: f64,
    pub(super) cloud_fraction: Option<f64>,
    pub(super) ghi: Option<f64>,
    pub(super) dni: Option<f64>,
    pub(super) dhi: Option<f64>,
    pub(super) sky_temp_c: Option<f64>,
    pub(super) precip_mm_h: f64,
}

pub(super) fn build_sample(c: &Ctx, m: Met) -> Result<WeatherSample, WeatherError> {
    let t = c.bound(m.air_temp_c, &bounds::weather::AIR_TEMP)?;
    let td = match (m.dew_point_c, m.rh_percent) {
        (Some(td), _) => {
            let td = c.bound(td, &bounds::weather::DEW_POINT)?;
            if td > t + 1.0 {
                return Err(c.malformed(format!(
                    "dew point {td} °C is above the air temperature {t} °C (expected dew point <= air temperature)"
                )));
            }
            td.min(t)
        }
        (None, Some(rh)) => {
            dew_point_c_from_rh(t, c.bound(rh, &bounds::weather::RELATIVE_HUMIDITY)?)
        }
        (None, None) => return Err(c.malformed("neither a dew point nor a relative humidity")),
    };
    let wind = c.bound(m.wind_m_s, &bounds::weather::WIND)?;
    let p = c.bound(m.pressure_hpa, &bounds::weather::PRESSURE)?;
    let cf = m
        .cloud_fraction
        .map(|x| c.bound(x, &bounds::weather::CLOUD))
        .transpose()?;
    if cf.is_none() && m.ghi.is_none() && (m.dni.is_none() || m.dhi.is_none()) {
        return Err(c.malformed(
            "total cloud cover is missing, and the record has no measured GHI (or DNI and DHI) to \
             derive it from: cloud cover is needed to estimate the irradiance",
        ));
    }
    let irr = |v: Option<f64>, f: &str| v.map(|x| c.irradiance(x, f)).transpose();
    let sky = m
        .sky_temp_c
        .map(|x| c.bound(x, &bounds::weather::SKY_TEMP))
        .transpose()?;
    Ok(WeatherSample {
        air_temp_k: t + ZERO_C_K,
        dew_point_k: td + ZERO_C_K,
        wind_speed_m_s: wind,
        pressure_pa: p * 100.0,
        cloud_fraction: cf,
        ghi_w_m2: irr(m.ghi, "GHI")?,
        dni_w_m2: irr(m.dni, "DNI")?,
        dhi_w_m2: irr(m.dhi, "DHI")?,
        sky_temp_k: sky.map(|x| x + ZERO_C_K),
        precip_mm_h: c.bound(m.precip_mm_h, &bounds::weather::PRECIPITATION)?,
    })
}

/// Checks order, duplicates and gaps, then builds the history. With
/// `period_fields` the irradiance/sky/precipitation fields are averages over
/// the interval ending at each stamp (see the module docs).
pub(super) fn assemble(
    raws: Vec<Raw>,
    file: &str,
    opts: &ReadOptions,
    period_fields: bool,
) -> Result<WeatherHistory, WeatherError> {
    if raws.is_empty() {
        return Err(WeatherError::Empty {
            file: file.to_string(),
            expected: "data lines after the header".into(),
        });
    }
    for w in raws.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if b.time == a.time {
            return Err(WeatherError::Duplicate {
                file: file.into(),
                line: b.line,
                prev_line: a.line,
                time: b.time,
            });
        }
        if b.time < a.time {
            return Err(WeatherError::Unsorted {
                file: file.into(),
                line: b.line,
                prev_line: a.line,
                time: b.time,
                prev: a.time,
            });
        }
        let gap = secs_between(a.time, b.time);
        if gap > opts.max_gap_s {
            return Err(WeatherError::Gap {
                file: file.into(),
                line: b.line,
                prev_line: a.line,
                prev: a.time,
                time: b.time,
                max_gap_s: opts.max_gap_s,
            });
        }
    }
    let mut times = Vec::with_capacity(2 * raws.len());
    let mut samples = Vec::with_capacity(2 * raws.len());
    if !period_fields || raws.len() == 1 {
        for r in raws {
            times.push(r.time);
            samples.push(r.sample);
        }
    } else {
        let n = raws.len();
        for i in 0..n {
            if i > 0 {
                // Midpoint of the interval ending at stamp i: instantaneous
                // fields interpolated, period fields as recorded at stamp i.
                let (a, b) = (&raws[i - 1], &raws[i]);
                let mid = a.time + (b.time - a.time) / 2;
                times.push(mid);
                samples.push(
                    WeatherSample::lerp(&a.sample, &b.sample, 0.5).with_period_fields(&b.sample),
                );
            }
            // Stamp i: period fields interpolated between midpoints i and i+1.
            let r = &raws[i];
            let period = if i + 1 < n {
                let prev_len = if i > 0 {
                    secs_between(raws[i - 1].time, r.time)
                } else {
                    secs_between(r.time, raws[1].time)
                };
                let next_len = secs_between(r.time, raws[i + 1].time);
                // Midpoints at −prev_len/2 and +next_len/2 around the stamp.
                let w = (prev_len / 2.0) / (prev_len / 2.0 + next_len / 2.0);
                WeatherSample::lerp(&r.sample, &raws[i + 1].sample, w)
            } else {
                r.sample
            };
            times.push(r.time);
            samples.push(r.sample.with_period_fields(&period));
        }
    }
    WeatherHistory::new(times, samples, file)
}

pub(super) fn utc_offset_from_hours(c: &Ctx, h: f64) -> Result<FixedOffset, WeatherError> {
    let h = c.bound(h, &bounds::weather::TIME_ZONE)?;
    FixedOffset::east_opt((h * 3600.0).round() as i32)
        .ok_or_else(|| c.malformed(format!("time zone {h} h is not a valid UTC offset")))
}

pub(super) fn parse_offset(s: &str) -> Option<FixedOffset> {
    let s = s.trim();
    if s.eq_ignore_ascii_case("z") || s.eq_ignore_ascii_case("utc") {
        return FixedOffset::east_opt(0);
    }
    let (sign, rest) = match s.as_bytes().first()? {
        b'+' => (1, &s[1..]),
        b'-' => (-1, &s[1..]),
        _ => return None,
    };
    let (h, m) = match rest.split_once(':') {
        Some((h, m)) => (h.parse::<i32>().ok()?, m.parse::<i32>().ok()?),
        None => (rest.parse::<i32>().ok()?, 0),
    };
    if h > 14 || !(0..60).contains(&m) {
        return None;
    }
    FixedOffset::east_opt(sign * (h * 3600 + m * 60))
}

/// Parses a UTC offset such as `-05:00`, `+0530`, `+2` or `Z` (for CLI flags).
pub fn parse_utc_offset(s: &str) -> Result<FixedOffset, String> {
    parse_offset(s)
        .ok_or_else(|| format!("cannot read UTC offset '{s}': expected e.g. -05:00, +01:00 or Z"))
}

/// One record of a file in local standard time, before it is laid on the
/// UTC time axis by [`place`]: the date written in the file and the stamp's
/// minutes after that date's midnight (1440 for TMY3's `24:00`).
pub(super) struct Stamped {
    pub(super) line: usize,
    pub(super) date: NaiveDate,
    pub(super) minutes: i64,
    pub(super) sample: WeatherSample,
}

/// Lays local-time records on the UTC axis and assembles the history. A
/// typical-year file read without [`ReadOptions::typical_year`] is refused
/// where its source year changes ([`WeatherError::TypicalYear`]); with it,
/// the records are laid on every year of the span (see [`YearSpan`]).
pub(super) fn place(
    recs: Vec<Stamped>,
    tz: FixedOffset,
    file: &str,
    opts: &ReadOptions,
    period_fields: bool,
) -> Result<WeatherHistory, WeatherError> {
    let at = |r: &Stamped, date: NaiveDate| {
        let local = date.and_hms_opt(0, 0, 0).unwrap() + Duration::minutes(r.minutes);
        Ctx { file, line: r.line }.local_to_utc(tz, local)
    };
    let Some(span) = opts.typical_year else {
        let mut raws = Vec::with_capacity(recs.len());
        for r in &recs {
            raws.push(Raw {
                line: r.line,
                time: at(r, r.date)?,
                sample: r.sample,
            });
        }
        for (w, r) in raws.windows(2).zip(recs.windows(2)) {
            let gap = secs_between(w[0].time, w[1].time);
            if r[0].date.year() != r[1].date.year() && (gap <= 0.0 || gap > opts.max_gap_s) {
                let years = recs.iter().map(|r| r.date.year());
                return Err(WeatherError::TypicalYear {
                    file: file.into(),
                    line: r[1].line,
                    prev_line: r[0].line,
                    prev_date: r[0].date,
                    date: r[1].date,
                    first_year: years.clone().min().unwrap_or(0),
                    last_year: years.max().unwrap_or(0),
                });
            }
        }
        return assemble(raws, file, opts, period_fields);
    };
    // Within the typical year the records must run in calendar order.
    let key = |r: &Stamped| (r.date.month(), r.date.day(), r.minutes);
    for w in recs.windows(2) {
        if key(&w[1]) <= key(&w[0]) {
            return Err(Ctx {
                file,
                line: w[1].line,
            }
            .malformed(format!(
                "{:02}-{:02} {:02}:{:02} does not follow {:02}-{:02} {:02}:{:02} (line {}): a typical \
                 year's records must run from January to December",
                w[1].date.month(),
                w[1].date.day(),
                w[1].minutes / 60,
                w[1].minutes % 60,
                w[0].date.month(),
                w[0].date.day(),
                w[0].minutes / 60,
                w[0].minutes % 60,
                w[0].line
            )));
        }
    }
    let has_feb29 = recs
        .iter()
        .any(|r| (r.date.month(), r.date.day()) == (2, 29));
    let mut raws = Vec::with_capacity(recs.len() * (span.last - span.first + 1).max(0) as usize);
    for y in span.first..=span.last {
        let leap = NaiveDate::from_ymd_opt(y, 2, 29).is_some();
        for r in &recs {
            let (m, d) = (r.date.month(), r.date.day());
            let days: &[u32] = match (m, d) {
                (2, 29) if !leap => &[],
                (2, 28) if leap && !has_feb29 => &[28, 29],
                _ => &[d],
            };
            for &d in days {
                let date = Ctx { file, line: r.line }.date(y.into(), m.into(), d.into())?;
                raws.push(Raw {
                    line: r.line,
                    time: at(r, date)?,
                    sample: r.sample,
                });
            }
        }
    }
    // The repeated 28 February interleaves with the original: restore time
    // order (stable, and the file's own order was checked above).
    raws.sort_by_key(|r| r.time);
    assemble(raws, file, opts, period_fields)
}
