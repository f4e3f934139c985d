//! Weather history: readers (plain CSV, TMY3, EPW), time interpolation,
//! coverage checks and a constant-weather source. Owner: the sun/weather
//! work (issue 4).
//!
//! # Time conventions
//!
//! All times are stored in UTC. Instantaneous quantities (air temperature,
//! dew point, wind, pressure, cloud cover) belong to the record's time
//! stamp. TMY3 and EPW records are *hour-ending*: their irradiances,
//! infrared sky radiation and precipitation are averages over the interval
//! that ends at the stamp, so the readers attach those to the interval's
//! midpoint. To keep one time axis, a history read from such a file is laid
//! on the merged grid stamp₀, mid₁, stamp₁, mid₂, stamp₂, …: at the
//! midpoints the instantaneous fields are the linear interpolation of the
//! neighbouring stamps, and at the stamps the period fields are the linear
//! interpolation of the neighbouring midpoints (the last stamp holds the last
//! period value). Linear interpolation on the merged grid is then *exactly*
//! linear interpolation of each field on its own grid. The plain CSV format
//! takes every value as instantaneous at its stamp.
//!
//! # Interpolation
//!
//! [`WeatherHistory::at`] interpolates linearly in time between the two
//! samples around `t`; an optional field is `Some` only where both samples
//! have it. Outside the record it holds the end values; call
//! [`WeatherHistory::check_covers`] first (the forcing builder does).

use std::path::Path;

use chrono::{DateTime, Datelike, Duration, FixedOffset, NaiveDate, NaiveDateTime, TimeZone, Utc};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// 0 °C in kelvin.
pub const ZERO_C_K: f64 = 273.15;
/// Largest allowed spacing between consecutive records by default, seconds.
pub const DEFAULT_MAX_GAP_S: f64 = 3.0 * 3600.0;

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

/// Errors of the weather readers and of coverage checks. Every file error
/// names the file and, where there is one, the 1-based line.
#[derive(Debug, Error)]
pub enum WeatherError {
    #[error("{file}: cannot read the weather file: {err}")]
    Io { file: String, err: std::io::Error },
    #[error("{file}:{line}: {msg}")]
    Malformed {
        file: String,
        line: usize,
        msg: String,
    },
    #[error("{file}:{line}: {field} = {value} is out of range: expected {expected}")]
    OutOfRange {
        file: String,
        line: usize,
        field: String,
        value: f64,
        expected: String,
    },
    #[error(
        "{file}:{line}: time {} is earlier than {} on line {prev_line}: records must be sorted by time{hint}",
        fmt_time(*.time),
        fmt_time(*.prev)
    )]
    Unsorted {
        file: String,
        line: usize,
        prev_line: usize,
        time: DateTime<Utc>,
        prev: DateTime<Utc>,
        hint: &'static str,
    },
    #[error("{file}:{line}: time {} repeats line {prev_line}: duplicate record", fmt_time(*.time))]
    Duplicate {
        file: String,
        line: usize,
        prev_line: usize,
        time: DateTime<Utc>,
    },
    #[error(
        "{file}:{line}: gap of {:.2} h since line {prev_line} ({} to {}); the largest allowed gap is {:.2} h{hint}",
        secs_between(*.prev, *.time) / 3600.0,
        fmt_time(*.prev),
        fmt_time(*.time),
        .max_gap_s / 3600.0
    )]
    Gap {
        file: String,
        line: usize,
        prev_line: usize,
        prev: DateTime<Utc>,
        time: DateTime<Utc>,
        max_gap_s: f64,
        hint: &'static str,
    },
    #[error("{file}: no weather records (expected {expected})")]
    Empty { file: String, expected: String },
    #[error(
        "weather '{source_name}' (records {} to {}) does not cover the window {} to {}: missing {missing_desc}",
        fmt_time(*.have_start),
        fmt_time(*.have_end),
        fmt_time(*.start),
        fmt_time(*.end)
    )]
    NotCovered {
        source_name: String,
        have_start: DateTime<Utc>,
        have_end: DateTime<Utc>,
        start: DateTime<Utc>,
        end: DateTime<Utc>,
        missing_desc: String,
        /// The missing intervals, UTC.
        missing: Vec<(DateTime<Utc>, DateTime<Utc>)>,
    },
    #[error("{0}")]
    Invalid(String),
}

/// Reader options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadOptions {
    /// UTC offset of plain-CSV times written without one (local standard
    /// time). Ignored for TMY3/EPW, which carry their own offset.
    pub utc_offset: Option<FixedOffset>,
    /// Replace the year of every TMY3/EPW record (typical-year files mix
    /// source years month by month). Records then wrap: see [`read_weather_file_with`].
    pub coerce_year: Option<i32>,
    /// Largest allowed spacing between consecutive records, seconds.
    pub max_gap_s: f64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            utc_offset: None,
            coerce_year: None,
            max_gap_s: DEFAULT_MAX_GAP_S,
        }
    }
}

/// Which reader read a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum WeatherFormat {
    PlainCsv,
    Tmy3,
    Epw,
}

/// Station metadata carried by TMY3 and EPW headers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WeatherStation {
    pub name: String,
    pub lat_deg: f64,
    pub lon_deg: f64,
    pub elevation_m: f64,
    /// Offset of the file's local standard time from UTC, hours.
    pub utc_offset_h: f64,
}

/// A weather file as read: the history, the format and any station metadata.
#[derive(Clone, Debug, PartialEq)]
pub struct WeatherFile {
    pub history: WeatherHistory,
    pub format: WeatherFormat,
    pub station: Option<WeatherStation>,
}

fn fmt_time(t: DateTime<Utc>) -> String {
    if t.timestamp_subsec_nanos() == 0 && t.timestamp() % 60 == 0 {
        t.format("%Y-%m-%dT%H:%MZ").to_string()
    } else {
        t.to_rfc3339_opts(chrono::SecondsFormat::AutoSi, true)
    }
}

fn secs_between(a: DateTime<Utc>, b: DateTime<Utc>) -> f64 {
    (b - a)
        .num_nanoseconds()
        .map(|n| n as f64 * 1e-9)
        .unwrap_or_else(|| (b - a).num_seconds() as f64)
}

fn lerp(a: f64, b: f64, w: f64) -> f64 {
    a + (b - a) * w
}

fn lerp_opt(a: Option<f64>, b: Option<f64>, w: f64) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(lerp(x, y, w)),
        (Some(x), None) if w == 0.0 => Some(x),
        (None, Some(y)) if w == 1.0 => Some(y),
        _ => None,
    }
}

impl WeatherSample {
    /// Linear interpolation between two samples, weight `w` in [0, 1] on `b`.
    pub fn lerp(a: &WeatherSample, b: &WeatherSample, w: f64) -> WeatherSample {
        WeatherSample {
            air_temp_k: lerp(a.air_temp_k, b.air_temp_k, w),
            dew_point_k: lerp(a.dew_point_k, b.dew_point_k, w),
            wind_speed_m_s: lerp(a.wind_speed_m_s, b.wind_speed_m_s, w),
            pressure_pa: lerp(a.pressure_pa, b.pressure_pa, w),
            cloud_fraction: lerp(a.cloud_fraction, b.cloud_fraction, w),
            ghi_w_m2: lerp_opt(a.ghi_w_m2, b.ghi_w_m2, w),
            dni_w_m2: lerp_opt(a.dni_w_m2, b.dni_w_m2, w),
            dhi_w_m2: lerp_opt(a.dhi_w_m2, b.dhi_w_m2, w),
            sky_temp_k: lerp_opt(a.sky_temp_k, b.sky_temp_k, w),
            precip_mm_h: lerp(a.precip_mm_h, b.precip_mm_h, w),
        }
    }

    /// This sample's instantaneous fields (temperatures, wind, pressure,
    /// cloud) with `period`'s period-averaged fields (irradiances, sky
    /// temperature, precipitation).
    fn with_period_fields(&self, period: &WeatherSample) -> WeatherSample {
        WeatherSample {
            ghi_w_m2: period.ghi_w_m2,
            dni_w_m2: period.dni_w_m2,
            dhi_w_m2: period.dhi_w_m2,
            sky_temp_k: period.sky_temp_k,
            precip_mm_h: period.precip_mm_h,
            ..*self
        }
    }
}

impl WeatherHistory {
    /// A history from parallel vectors; times must be strictly increasing.
    pub fn new(
        times: Vec<DateTime<Utc>>,
        samples: Vec<WeatherSample>,
        source: impl Into<String>,
    ) -> Result<Self, WeatherError> {
        let source = source.into();
        if times.len() != samples.len() {
            return Err(WeatherError::Invalid(format!(
                "weather '{source}': {} times but {} samples",
                times.len(),
                samples.len()
            )));
        }
        if times.is_empty() {
            return Err(WeatherError::Empty {
                file: source,
                expected: "at least one sample".into(),
            });
        }
        if let Some(i) = times.windows(2).position(|w| w[1] <= w[0]) {
            return Err(WeatherError::Invalid(format!(
                "weather '{source}': sample {} at {} is not after sample {} at {}",
                i + 1,
                fmt_time(times[i + 1]),
                i,
                fmt_time(times[i])
            )));
        }
        Ok(Self {
            times,
            samples,
            source,
        })
    }

    /// First sample time.
    pub fn start(&self) -> DateTime<Utc> {
        self.times[0]
    }

    /// Last sample time.
    pub fn end(&self) -> DateTime<Utc> {
        *self.times.last().unwrap()
    }

    /// Weather at `t`, linearly interpolated between the neighbouring samples
    /// (see the module docs). Outside the record the end sample is held;
    /// use [`Self::check_covers`] to refuse that instead.
    pub fn at(&self, t: DateTime<Utc>) -> WeatherSample {
        let n = self.times.len();
        let i = self.times.partition_point(|&x| x <= t);
        if i == 0 {
            return self.samples[0];
        }
        if i == n {
            return self.samples[n - 1];
        }
        let (t0, t1) = (self.times[i - 1], self.times[i]);
        let w = secs_between(t0, t) / secs_between(t0, t1);
        WeatherSample::lerp(&self.samples[i - 1], &self.samples[i], w)
    }

    /// Checks that the history covers `[start, end]` with no spacing between
    /// samples above [`DEFAULT_MAX_GAP_S`]; the error lists the missing
    /// intervals (whole hours, UTC).
    pub fn check_covers(
        &self,
        start: DateTime<Utc>,
        end: DateTime<Utc>,
    ) -> Result<(), WeatherError> {
        self.check_covers_with(start, end, DEFAULT_MAX_GAP_S)
    }

    /// [`Self::check_covers`] with an explicit largest allowed gap.
    pub fn check_covers_with(
        &self,
        start: DateTime<Utc>,
        end: DateTime<Utc>,
        max_gap_s: f64,
    ) -> Result<(), WeatherError> {
        let mut missing = Vec::new();
        if self.start() > start {
            missing.push((start, self.start().min(end)));
        }
        for w in self.times.windows(2) {
            if secs_between(w[0], w[1]) > max_gap_s && w[1] > start && w[0] < end {
                missing.push((w[0].max(start), w[1].min(end)));
            }
        }
        if self.end() < end {
            missing.push((self.end().max(start), end));
        }
        if missing.is_empty() {
            return Ok(());
        }
        let floor_h = |t: DateTime<Utc>| {
            let s = t.timestamp();
            Utc.timestamp_opt(s - s.rem_euclid(3600), 0).unwrap()
        };
        let ceil_h = |t: DateTime<Utc>| {
            let f = floor_h(t);
            if f == t { f } else { f + Duration::hours(1) }
        };
        let parts: Vec<String> = missing
            .iter()
            .map(|&(a, b)| {
                let (ha, hb) = (floor_h(a), ceil_h(b));
                let hours = (hb - ha).num_hours();
                format!(
                    "{} h from {} to {}",
                    hours.max(1),
                    ha.format("%Y-%m-%dT%H:00Z"),
                    hb.format("%Y-%m-%dT%H:00Z")
                )
            })
            .collect();
        Err(WeatherError::NotCovered {
            source_name: self.source.clone(),
            have_start: self.start(),
            have_end: self.end(),
            start,
            end,
            missing_desc: parts.join("; "),
            missing,
        })
    }
}

// ---------------------------------------------------------------------------
// Physical helpers
// ---------------------------------------------------------------------------

/// Dew point (°C) from air temperature (°C) and relative humidity (%), by
/// inverting the Magnus formula e_s(T) = 6.1094·exp(17.625·T/(T + 243.04))
/// hPa (Alduchov & Eskridge 1996, J. Appl. Meteor. 35, 601-609):
/// γ = ln(RH/100) + 17.625·T/(243.04 + T), T_d = 243.04·γ/(17.625 − γ).
/// RH below 0.1 % is taken as 0.1 % (the logarithm diverges at 0).
pub fn dew_point_c_from_rh(air_temp_c: f64, rh_percent: f64) -> f64 {
    let (a, b) = (17.625, 243.04);
    let g = (rh_percent.max(0.1) / 100.0).ln() + a * air_temp_c / (b + air_temp_c);
    b * g / (a - g)
}

/// Relative humidity (%) from air temperature and dew point (°C), with the
/// same Magnus formula as [`dew_point_c_from_rh`].
pub fn rh_percent_from_dew_point(air_temp_c: f64, dew_point_c: f64) -> f64 {
    let es = |t: f64| (17.625 * t / (243.04 + t)).exp();
    100.0 * es(dew_point_c) / es(air_temp_c)
}

/// Effective sky temperature (K) of a downwelling longwave irradiance
/// (W/m²): T = (L/σ)^¼ (Stefan–Boltzmann), as EnergyPlus derives it from the
/// EPW "horizontal infrared radiation intensity" field.
pub fn sky_temp_k_from_irradiance(lw_down_w_m2: f64) -> f64 {
    (lw_down_w_m2 / STEFAN_BOLTZMANN).powf(0.25)
}

/// Stefan–Boltzmann constant, W m⁻² K⁻⁴ (CODATA 2018, exact in SI).
pub const STEFAN_BOLTZMANN: f64 = 5.670374419e-8;

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

/// Reads a weather file with default [`ReadOptions`] (max gap 3 h) and the
/// given UTC offset for plain-CSV times written without one. The format is
/// detected: `.epw` → EnergyPlus EPW; a first line of 7 fields followed by a
/// `Date (MM/DD/YYYY),Time (HH:MM),…` header → TMY3; otherwise the plain CSV
/// of docs/weather-format.md.
pub fn read_weather_file(
    path: &Path,
    utc_offset: Option<FixedOffset>,
) -> Result<WeatherHistory, WeatherError> {
    read_weather_file_with(
        path,
        &ReadOptions {
            utc_offset,
            ..ReadOptions::default()
        },
    )
    .map(|f| f.history)
}

/// Reads a weather file (see [`read_weather_file`]) with explicit options,
/// returning the station metadata too.
pub fn read_weather_file_with(
    path: &Path,
    opts: &ReadOptions,
) -> Result<WeatherFile, WeatherError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|err| WeatherError::Io {
        file: file.clone(),
        err,
    })?;
    // TMY3/EPW files are sometimes Latin-1: keep the bytes we can.
    let text = String::from_utf8_lossy(&bytes);
    let is_epw = path
        .extension()
        .map(|e| e.eq_ignore_ascii_case("epw"))
        .unwrap_or(false)
        || text.starts_with("LOCATION,");
    if is_epw {
        return parse_epw(&text, &file, opts);
    }
    let mut lines = text.lines();
    let l1 = lines.next().unwrap_or("");
    let l2 = lines.next().unwrap_or("");
    if split_csv(l1).len() == 7 && l2.trim_start().starts_with("Date (MM/DD/YYYY)") {
        return parse_tmy3(&text, &file, opts);
    }
    parse_plain_csv(&text, &file, opts)
}

/// Splits one CSV line; double-quoted fields may contain commas.
fn split_csv(line: &str) -> Vec<String> {
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
struct Raw {
    line: usize,
    time: DateTime<Utc>,
    sample: WeatherSample,
}

struct Ctx<'a> {
    file: &'a str,
    line: usize,
}

impl Ctx<'_> {
    fn malformed(&self, msg: impl Into<String>) -> WeatherError {
        WeatherError::Malformed {
            file: self.file.to_string(),
            line: self.line,
            msg: msg.into(),
        }
    }

    fn num(&self, s: &str, field: &str) -> Result<f64, WeatherError> {
        let v: f64 = s
            .trim()
            .parse()
            .map_err(|_| self.malformed(format!("{field}: '{}' is not a number", s.trim())))?;
        if !v.is_finite() {
            return Err(self.malformed(format!("{field}: '{}' is not a finite number", s.trim())));
        }
        Ok(v)
    }

    fn range(
        &self,
        v: f64,
        field: &str,
        lo: f64,
        hi: f64,
        unit: &str,
    ) -> Result<f64, WeatherError> {
        if v < lo || v > hi {
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

    /// An irradiance: values in [−10, 0) (sensor offsets at night) become 0.
    fn irradiance(&self, v: f64, field: &str) -> Result<f64, WeatherError> {
        Ok(self.range(v, field, -10.0, 1500.0, "W/m²")?.max(0.0))
    }
}

/// The range checks shared by every reader, in the file's own units.
struct Met {
    air_temp_c: f64,
    dew_point_c: Option<f64>,
    rh_percent: Option<f64>,
    wind_m_s: f64,
    pressure_hpa: f64,
    cloud_fraction: f64,
    ghi: Option<f64>,
    dni: Option<f64>,
    dhi: Option<f64>,
    sky_temp_c: Option<f64>,
    precip_mm_h: f64,
}

fn build_sample(c: &Ctx, m: Met) -> Result<WeatherSample, WeatherError> {
    let t = c.range(m.air_temp_c, "air temperature", -90.0, 60.0, "°C")?;
    let td = match (m.dew_point_c, m.rh_percent) {
        (Some(td), _) => {
            let td = c.range(td, "dew point", -100.0, 60.0, "°C")?;
            if td > t + 1.0 {
                return Err(c.malformed(format!(
                    "dew point {td} °C is above the air temperature {t} °C (expected dew point <= air temperature)"
                )));
            }
            td.min(t)
        }
        (None, Some(rh)) => {
            dew_point_c_from_rh(t, c.range(rh, "relative humidity", 0.0, 100.0, "%")?)
        }
        (None, None) => return Err(c.malformed("neither a dew point nor a relative humidity")),
    };
    let wind = c.range(m.wind_m_s, "wind speed", 0.0, 100.0, "m/s")?;
    let p = c.range(m.pressure_hpa, "pressure", 300.0, 1100.0, "hPa")?;
    let cf = c.range(
        m.cloud_fraction,
        "cloud fraction",
        0.0,
        1.0,
        "(0 clear to 1 overcast)",
    )?;
    let irr = |v: Option<f64>, f: &str| v.map(|x| c.irradiance(x, f)).transpose();
    let sky = m
        .sky_temp_c
        .map(|x| c.range(x, "sky temperature", -150.0, 60.0, "°C"))
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
        precip_mm_h: c.range(m.precip_mm_h, "precipitation", 0.0, 500.0, "mm/h")?,
    })
}

/// Checks order, duplicates and gaps, then builds the history. With
/// `period_fields` the irradiance/sky/precipitation fields are averages over
/// the interval ending at each stamp (see the module docs).
fn assemble(
    raws: Vec<Raw>,
    file: &str,
    opts: &ReadOptions,
    period_fields: bool,
    hint: &'static str,
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
                hint,
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
                hint,
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

fn utc_offset_from_hours(c: &Ctx, h: f64) -> Result<FixedOffset, WeatherError> {
    let h = c.range(h, "time zone", -12.0, 14.0, "hours from UTC")?;
    FixedOffset::east_opt((h * 3600.0).round() as i32)
        .ok_or_else(|| c.malformed(format!("time zone {h} h is not a valid UTC offset")))
}

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

fn parse_offset(s: &str) -> Option<FixedOffset> {
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
            need(6, Some(7), "cloud_fraction or cloud_tenths")?;
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
        let cloud_fraction = match (opt(6)?, opt(7)?) {
            (Some(f), _) => f,
            (None, Some(tenths)) => c.range(tenths, "cloud_tenths", 0.0, 10.0, "tenths")? / 10.0,
            (None, None) => {
                return Err(c.malformed("cloud_fraction and cloud_tenths are both empty"));
            }
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
        history: assemble(raws, file, opts, false, "")?,
        format: WeatherFormat::PlainCsv,
        station: None,
    })
}

const TYPICAL_YEAR_HINT: &str =
    " (typical-year files mix source years month by month: read them with a coerce_year)";

/// Reads an NREL TMY3 CSV from text. Line 1: station id, name, state, UTC
/// offset (h), latitude, longitude, elevation (m); line 2: column names;
/// then hourly records `MM/DD/YYYY,HH:MM,…` in local standard time with
/// hour-ending stamps 01:00..24:00 (Wilcox & Marion 2008, NREL/TP-581-43156).
/// Missing values are −9900 (an error for the meteorological fields; absent
/// for irradiances; 0 for precipitation).
pub fn parse_tmy3(text: &str, file: &str, opts: &ReadOptions) -> Result<WeatherFile, WeatherError> {
    let mut lines = text.lines();
    let c1 = Ctx { file, line: 1 };
    let meta = split_csv(lines.next().unwrap_or(""));
    if meta.len() != 7 {
        return Err(c1.malformed(format!(
            "{} fields in the TMY3 station line, expected 7 (USAF id, name, state, UTC offset, latitude, longitude, elevation)",
            meta.len()
        )));
    }
    let station = WeatherStation {
        name: meta[1].trim().to_string(),
        utc_offset_h: c1.num(&meta[3], "time zone")?,
        lat_deg: c1.range(
            c1.num(&meta[4], "latitude")?,
            "latitude",
            -90.0,
            90.0,
            "degrees",
        )?,
        lon_deg: c1.range(
            c1.num(&meta[5], "longitude")?,
            "longitude",
            -180.0,
            180.0,
            "degrees",
        )?,
        elevation_m: c1.num(&meta[6], "elevation")?,
    };
    let tz = utc_offset_from_hours(&c1, station.utc_offset_h)?;
    let c2 = Ctx { file, line: 2 };
    let names: Vec<String> = split_csv(lines.next().unwrap_or(""))
        .iter()
        .map(|s| s.trim().to_string())
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
        let date = match opts.coerce_year {
            Some(y) => date.with_year(y).ok_or_else(|| {
                c.malformed(format!(
                    "date {date} does not exist in the coerced year {y}"
                ))
            })?,
            None => date,
        };
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
        let local =
            date.and_hms_opt(0, 0, 0).unwrap() + Duration::hours(hh) + Duration::minutes(mm);
        let time = tz
            .from_local_datetime(&local)
            .single()
            .unwrap()
            .with_timezone(&Utc);
        let req = |i: usize, what: &str| -> Result<f64, WeatherError> {
            let v = c.num(&f[i], what)?;
            if v == -9900.0 {
                return Err(c.malformed(format!("{what} is missing (-9900)")));
            }
            Ok(v)
        };
        let opt = |i: usize, what: &str| -> Result<Option<f64>, WeatherError> {
            let v = c.num(&f[i], what)?;
            Ok((v != -9900.0).then_some(v))
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
            pressure_hpa: req(i_p, "Pressure (mbar)")?,
            cloud_fraction: c.range(
                req(i_cld, "TotCld (tenths)")?,
                "TotCld (tenths)",
                0.0,
                10.0,
                "tenths",
            )? / 10.0,
            ghi: opt(i_ghi, "GHI")?,
            dni: opt(i_dni, "DNI")?,
            dhi: opt(i_dhi, "DHI")?,
            sky_temp_c: None,
            precip_mm_h: precip,
        };
        raws.push(Raw {
            line: k + 3,
            time,
            sample: build_sample(&c, met)?,
        });
    }
    Ok(WeatherFile {
        history: assemble(raws, file, opts, true, TYPICAL_YEAR_HINT)?,
        format: WeatherFormat::Tmy3,
        station: Some(station),
    })
}

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
        lat_deg: c1.range(
            c1.num(&loc[6], "latitude")?,
            "latitude",
            -90.0,
            90.0,
            "degrees",
        )?,
        lon_deg: c1.range(
            c1.num(&loc[7], "longitude")?,
            "longitude",
            -180.0,
            180.0,
            "degrees",
        )?,
        utc_offset_h: c1.num(&loc[8], "time zone")?,
        elevation_m: c1.num(&loc[9], "elevation")?,
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
        let year = opts
            .coerce_year
            .map(i64::from)
            .map_or_else(|| int(0, "year"), Ok)?;
        let (month, day, hour, minute) = (
            int(1, "month")?,
            int(2, "day")?,
            int(3, "hour")?,
            int(4, "minute")?,
        );
        let date = NaiveDate::from_ymd_opt(year as i32, month as u32, day as u32)
            .ok_or_else(|| c.malformed(format!("date {year}-{month}-{day} does not exist")))?;
        if !(1..=24).contains(&hour) || !(0..=60).contains(&minute) {
            return Err(c.malformed(format!(
                "hour {hour} minute {minute}: expected hour 1..24 (hour-ending) and minute 0..60"
            )));
        }
        // Hour h, minute m covers ((h−1):00 + m − interval, (h−1):00 + m];
        // hourly files write minute 60 (or 0, meaning the full hour).
        let end_min = if minute == 0 { 60 } else { minute };
        let local = date.and_hms_opt(0, 0, 0).unwrap()
            + Duration::hours(hour - 1)
            + Duration::minutes(end_min);
        let time = tz
            .from_local_datetime(&local)
            .single()
            .unwrap()
            .with_timezone(&Utc);
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
            pressure_hpa: req(9, "atmospheric pressure", 999999.0)? / 100.0,
            cloud_fraction: c.range(
                req(22, "total sky cover", 99.0)?,
                "total sky cover",
                0.0,
                10.0,
                "tenths",
            )? / 10.0,
            ghi: val(13, "GHI", 9999.0)?,
            dni: val(14, "DNI", 9999.0)?,
            dhi: val(15, "DHI", 9999.0)?,
            sky_temp_c,
            precip_mm_h: precip,
        };
        raws.push(Raw {
            line: lineno,
            time,
            sample: build_sample(&c, met)?,
        });
    }
    Ok(WeatherFile {
        history: assemble(raws, file, opts, true, TYPICAL_YEAR_HINT)?,
        format: WeatherFormat::Epw,
        station: Some(station),
    })
}

// ---------------------------------------------------------------------------
// Constant weather
// ---------------------------------------------------------------------------

/// Parameters of the constant-weather source (sweeps such as the seed's
/// wind-speed figure, Fig. 13: fixed wind for the previous 24 h).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConstantWeather {
    pub wind_speed_m_s: f64,
    /// Daily minimum air temperature (at sunrise), °C.
    pub air_temp_min_c: f64,
    /// Daily maximum air temperature (at solar noon + [`Self::t_max_after_noon_h`]), °C.
    pub air_temp_max_c: f64,
    /// Fixed dew point, °C; must not exceed `air_temp_min_c`.
    pub dew_point_c: f64,
    pub cloud_fraction: f64,
    pub pressure_hpa: f64,
    /// Hours after solar noon of the daily maximum (default 2.5: mid-afternoon).
    pub t_max_after_noon_h: f64,
}

impl Default for ConstantWeather {
    fn default() -> Self {
        Self {
            wind_speed_m_s: 2.0,
            air_temp_min_c: 15.0,
            air_temp_max_c: 25.0,
            dew_point_c: 10.0,
            cloud_fraction: 0.0,
            pressure_hpa: 1013.25,
            t_max_after_noon_h: 2.5,
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
    let (tmin, tmax) = (p.air_temp_min_c, p.air_temp_max_c);
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
        p.wind_speed_m_s,
        p.air_temp_min_c,
        p.air_temp_max_c,
        p.dew_point_c,
        p.cloud_fraction,
        p.pressure_hpa,
        p.t_max_after_noon_h,
    ];
    if params.iter().any(|x| !x.is_finite()) {
        return bad(format!("parameters must be finite numbers: {p:?}"));
    }
    if p.air_temp_min_c > p.air_temp_max_c {
        return bad(format!(
            "minimum air temperature {} °C is above the maximum {} °C",
            p.air_temp_min_c, p.air_temp_max_c
        ));
    }
    if p.dew_point_c > p.air_temp_min_c {
        return bad(format!(
            "dew point {} °C is above the minimum air temperature {} °C (expected dew point <= air temperature)",
            p.dew_point_c, p.air_temp_min_c
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
            wind_m_s: p.wind_speed_m_s,
            pressure_hpa: p.pressure_hpa,
            cloud_fraction: p.cloud_fraction,
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

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str =
        "time,air_temp_c,dew_point_c,wind_m_s,pressure_hpa,cloud_fraction,ghi_w_m2\n";

    fn plain(body: &str) -> Result<WeatherFile, WeatherError> {
        parse_plain_csv(&format!("{HEAD}{body}"), "wx.csv", &ReadOptions::default())
    }

    fn utc(s: &str) -> DateTime<Utc> {
        DateTime::parse_from_rfc3339(s).unwrap().with_timezone(&Utc)
    }

    fn err(body: &str) -> String {
        plain(body).unwrap_err().to_string()
    }

    #[test]
    fn plain_csv_reads_and_interpolates_linearly() {
        let f = plain(
            "2024-06-21T00:00:00Z,10,5,2,1000,0.5,\n\
             2024-06-21T01:00:00Z,14,7,4,1010,0.7,100\n\
             2024-06-21T02:00:00Z,12,6,3,1005,0.6,200\n",
        )
        .unwrap();
        let h = f.history;
        assert_eq!(h.times.len(), 3);
        // 15 min after 00:00: weight 0.25 (analytic linear interpolation).
        let s = h.at(utc("2024-06-21T00:15:00Z"));
        assert!((s.air_temp_k - (283.15 + 0.25 * 4.0)).abs() < 1e-12);
        assert!((s.pressure_pa - 100_250.0).abs() < 1e-9);
        assert!((s.cloud_fraction - 0.55).abs() < 1e-12);
        assert_eq!(
            s.ghi_w_m2, None,
            "GHI is missing at 00:00, so unknown between"
        );
        let s = h.at(utc("2024-06-21T01:30:00Z"));
        assert!((s.ghi_w_m2.unwrap() - 150.0).abs() < 1e-12);
        assert!((s.wind_speed_m_s - 3.5).abs() < 1e-12);
        // Exactly on a sample with a missing neighbour, the value is kept.
        assert_eq!(h.at(utc("2024-06-21T01:00:00Z")).ghi_w_m2, Some(100.0));
        // Outside the record the end values are held.
        assert_eq!(h.at(utc("2024-06-22T00:00:00Z")), h.samples[2]);
    }

    #[test]
    fn plain_csv_local_time_with_caller_or_file_offset() {
        let body = "2024-06-21T07:00,10,5,2,1000,0\n2024-06-21 08:00:00,11,5,2,1000,0\n";
        let head = "time,air_temp_c,dew_point_c,wind_m_s,pressure_hpa,cloud_fraction\n";
        let e = parse_plain_csv(&format!("{head}{body}"), "wx.csv", &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("wx.csv:2:") && e.contains("no UTC offset"),
            "{e}"
        );
        let opts = ReadOptions {
            utc_offset: FixedOffset::west_opt(5 * 3600),
            ..ReadOptions::default()
        };
        let h = parse_plain_csv(&format!("{head}{body}"), "wx.csv", &opts)
            .unwrap()
            .history;
        assert_eq!(h.times[0], utc("2024-06-21T12:00:00Z"));
        let h = parse_plain_csv(
            &format!("# utc_offset: -05:00\n{head}{body}"),
            "wx.csv",
            &ReadOptions::default(),
        )
        .unwrap()
        .history;
        assert_eq!(h.times[1], utc("2024-06-21T13:00:00Z"));
    }

    #[test]
    fn plain_csv_rh_tenths_and_optional_columns() {
        let text = "time,air_temp_c,rh_percent,wind_m_s,cloud_tenths,sky_temp_c,precip_mm_h,x_note\n\
                    2024-01-01T00:00:00Z,20,50,1,3,-10,0.5,hello\n";
        let h = parse_plain_csv(text, "wx.csv", &ReadOptions::default())
            .unwrap()
            .history;
        let s = h.samples[0];
        // Magnus dew point at 20 °C, 50 % (hand-computed: 9.2607 °C).
        assert!(
            (s.dew_point_k - ZERO_C_K - 9.2607).abs() < 1e-3,
            "{}",
            s.dew_point_k
        );
        assert!((s.cloud_fraction - 0.3).abs() < 1e-12);
        assert_eq!(s.pressure_pa, 101_325.0);
        assert!((s.sky_temp_k.unwrap() - 263.15).abs() < 1e-12);
        assert_eq!(s.precip_mm_h, 0.5);
    }

    /// Dew point from RH against tabulated saturation vapour pressure over
    /// water (Smithsonian Meteorological Tables / WMO): e_s(20) = 23.39 hPa,
    /// e_s(9.3) = 11.70 → 20 °C 50 % gives 9.3 °C; e_s(30) = 42.47,
    /// e_s(26.2) = 34.0 → 30 °C 80 % gives 26.2 °C; e_s(−10) = 2.865,
    /// e_s(−16) = 1.766, e_s(−17) = 1.630 → −10 °C 60 % gives −16.35 °C (linear
    /// in the table). Tolerance 0.1 K (table rounding and interpolation).
    #[test]
    fn dew_point_from_rh_vs_tables() {
        for (t, rh, td) in [
            (20.0, 50.0, 9.3),
            (30.0, 80.0, 26.2),
            (0.0, 100.0, 0.0),
            (-10.0, 60.0, -16.35),
        ] {
            let got = dew_point_c_from_rh(t, rh);
            assert!((got - td).abs() < 0.1, "T {t} RH {rh}: {got}");
            assert!((rh_percent_from_dew_point(t, got) - rh).abs() < 1e-9);
        }
    }

    #[test]
    fn errors_name_file_line_and_expectation() {
        let ok = "2024-06-21T00:00:00Z,10,5,2,1000,0.5,\n";
        let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,2,1000\n"));
        assert!(e.starts_with("wx.csv:3: 5 fields, expected 7"), "{e}");
        let e = err(&format!("{ok}2024-06-21T01:00:00Z,warm,5,2,1000,0.5,\n"));
        assert!(
            e.starts_with("wx.csv:3: air_temp_c: 'warm' is not a number"),
            "{e}"
        );
        let e = err(&format!("{ok}21/06/2024 01:00,10,5,2,1000,0.5,\n"));
        assert!(
            e.starts_with("wx.csv:3: cannot read time") && e.contains("RFC 3339"),
            "{e}"
        );
        let e = err(&format!("{ok}2024-06-21T01:00:00Z,61,5,2,1000,0.5,\n"));
        assert_eq!(
            e,
            "wx.csv:3: air temperature = 61 is out of range: expected -90 to 60 °C"
        );
        let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,-1,1000,0.5,\n"));
        assert!(
            e.starts_with("wx.csv:3: wind speed = -1 is out of range: expected 0 to 100 m/s"),
            "{e}"
        );
        let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,1,1000,1.5,\n"));
        assert!(e.contains("cloud fraction = 1.5 is out of range"), "{e}");
        let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,15,1,1000,0.5,\n"));
        assert!(
            e.starts_with("wx.csv:3: dew point 15 °C is above the air temperature 10 °C"),
            "{e}"
        );
        let e = err(&format!("{ok}2024-06-21T01:00:00Z,10,5,1,1000,0.5,-50\n"));
        assert!(e.contains("GHI = -50 is out of range"), "{e}");
        let e = parse_plain_csv(
            "time,air_temp_c,rh_percent,wind_m_s,cloud_fraction\n2024-01-01T00:00:00Z,10,101,1,0\n",
            "wx.csv",
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "wx.csv:2: relative humidity = 101 is out of range: expected 0 to 100 %"
        );
    }

    #[test]
    fn errors_for_order_duplicates_and_gaps() {
        let a = "2024-06-21T03:00:00Z,10,5,2,1000,0.5,\n";
        let e = err(&format!("{a}2024-06-21T02:00:00Z,10,5,2,1000,0.5,\n"));
        assert!(
            e.starts_with(
                "wx.csv:3: time 2024-06-21T02:00Z is earlier than 2024-06-21T03:00Z on line 2"
            ),
            "{e}"
        );
        let e = err(&format!("{a}{a}"));
        assert_eq!(
            e,
            "wx.csv:3: time 2024-06-21T03:00Z repeats line 2: duplicate record"
        );
        let e = err(&format!("{a}2024-06-21T07:00:00Z,10,5,2,1000,0.5,\n"));
        assert!(
            e.starts_with("wx.csv:3: gap of 4.00 h since line 2 (2024-06-21T03:00Z to 2024-06-21T07:00Z); the largest allowed gap is 3.00 h"),
            "{e}"
        );
        let opts = ReadOptions {
            max_gap_s: 6.0 * 3600.0,
            ..ReadOptions::default()
        };
        assert!(
            parse_plain_csv(
                &format!("{HEAD}{a}2024-06-21T07:00:00Z,10,5,2,1000,0.5,\n"),
                "wx.csv",
                &opts
            )
            .is_ok()
        );
    }

    #[test]
    fn header_errors() {
        let e = parse_plain_csv(
            "time,air_temp_c,ghi,wind_m_s\n",
            "wx.csv",
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("wx.csv:1: unknown column 'ghi'") && e.contains("ghi_w_m2"),
            "{e}"
        );
        let e = parse_plain_csv(
            "time,air_temp_c,wind_m_s,cloud_fraction\n",
            "wx.csv",
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "wx.csv:1: the header has no dew_point_c or rh_percent column"
        );
        let e = parse_plain_csv("# only comments\n", "wx.csv", &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("wx.csv: no weather records (expected a header row"),
            "{e}"
        );
    }

    #[test]
    fn tmy3_and_epw_errors() {
        let tmy = "723170,\"GREENSBORO\",NC,-5.0,36.1,-79.95,273\n\
            Date (MM/DD/YYYY),Time (HH:MM),GHI (W/m^2),DNI (W/m^2),DHI (W/m^2),TotCld (tenths),Dry-bulb (C),Dew-point (C),RHum (%),Pressure (mbar),Wspd (m/s)\n\
            06/18/1989,01:00,0,0,0,0,18.3,16.7,90,990,2.6\n\
            06/18/1989,02:00,0,0,0,0,-9900,16.7,90,990,2.6\n";
        let e = parse_tmy3(tmy, "t.csv", &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert_eq!(e, "t.csv:4: Dry-bulb (C) is missing (-9900)");
        let tmy2 = tmy.replace(
            "06/18/1989,02:00,0,0,0,0,-9900",
            "06/18/1989,25:00,0,0,0,0,18",
        );
        let e = parse_tmy3(&tmy2, "t.csv", &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.csv:4: time '25:00': expected HH:MM from 01:00 to 24:00"),
            "{e}"
        );
        // Month boundary of a typical year: July of another year → hint.
        let tmy3 = tmy.replace(
            "06/18/1989,02:00,0,0,0,0,-9900",
            "07/01/1981,01:00,0,0,0,0,18",
        );
        let e = parse_tmy3(&tmy3, "t.csv", &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("coerce_year"), "{e}");
        let opts = ReadOptions {
            coerce_year: Some(1989),
            max_gap_s: 400.0 * 3600.0,
            ..ReadOptions::default()
        };
        assert!(parse_tmy3(&tmy3, "t.csv", &opts).is_ok());
        let e = parse_epw("NOT EPW\n", "a.epw", &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("a.epw:1: expected the EPW LOCATION line"),
            "{e}"
        );
    }

    #[test]
    fn check_covers_lists_missing_hours() {
        let mk = |h: &[i64]| {
            let t0 = utc("2024-06-21T00:00:00Z");
            let s = WeatherSample {
                air_temp_k: 290.0,
                dew_point_k: 280.0,
                wind_speed_m_s: 1.0,
                pressure_pa: 101_325.0,
                cloud_fraction: 0.0,
                ghi_w_m2: None,
                dni_w_m2: None,
                dhi_w_m2: None,
                sky_temp_k: None,
                precip_mm_h: 0.0,
            };
            WeatherHistory::new(
                h.iter().map(|&x| t0 + Duration::hours(x)).collect(),
                vec![s; h.len()],
                "w",
            )
            .unwrap()
        };
        let h = mk(&[2, 3, 4, 10, 11]);
        assert!(
            h.check_covers(utc("2024-06-21T02:00:00Z"), utc("2024-06-21T04:00:00Z"))
                .is_ok()
        );
        let e = h
            .check_covers(utc("2024-06-21T00:00:00Z"), utc("2024-06-21T12:30:00Z"))
            .unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains(
                "missing 2 h from 2024-06-21T00:00Z to 2024-06-21T02:00Z; 6 h from 2024-06-21T04:00Z to 2024-06-21T10:00Z; \
                 2 h from 2024-06-21T11:00Z to 2024-06-21T13:00Z"
            ),
            "{msg}"
        );
        let WeatherError::NotCovered { missing, .. } = e else {
            panic!()
        };
        assert_eq!(missing.len(), 3);
        assert!(WeatherHistory::new(vec![utc("2024-06-21T00:00:00Z"); 2], vec![], "w").is_err());
    }

    /// The constant-weather cycle: T_min at sunrise, T_max at transit + 2.5 h,
    /// the mean half-way (cos π/2 = 0), bounded, and fixed other fields.
    /// Sunrise/transit are from the SPA (tested against pvlib elsewhere).
    #[test]
    fn constant_weather_diurnal_cycle() {
        let p = ConstantWeather {
            wind_speed_m_s: 4.47,
            air_temp_min_c: 12.0,
            air_temp_max_c: 26.0,
            dew_point_c: 8.0,
            cloud_fraction: 0.25,
            pressure_hpa: 1000.0,
            t_max_after_noon_h: 2.5,
        };
        let (lat, lon) = (43.1, -77.6);
        let start = utc("1992-07-14T00:00:00Z");
        let end = utc("1992-07-16T00:00:00Z");
        let h = constant_weather(&p, lat, lon, start, end, 900.0).unwrap();
        assert_eq!(h.times.len(), 2 * 96 + 1);
        assert!(h.check_covers(start, end).is_ok());
        let ev = crate::sun::sun_events_near(utc("1992-07-15T17:00:00Z"), lat, lon);
        let rise = ev.sunrise.unwrap();
        let tx = ev.transit + Duration::minutes(150);
        let at = |t| diurnal_air_temp_c(&p, lat, lon, t);
        assert!((at(rise) - 12.0).abs() < 1e-9);
        assert!((at(tx) - 26.0).abs() < 1e-9);
        assert!((at(rise + (tx - rise) / 2) - 19.0).abs() < 1e-6);
        for s in &h.samples {
            let t = s.air_temp_k - ZERO_C_K;
            assert!((12.0 - 1e-9..=26.0 + 1e-9).contains(&t));
            assert_eq!(s.wind_speed_m_s, 4.47);
            assert!((s.dew_point_k - ZERO_C_K - 8.0).abs() < 1e-12);
            assert_eq!(s.cloud_fraction, 0.25);
            assert_eq!(s.ghi_w_m2, None);
        }
        // Rising before the max, falling after (sampled).
        assert!(at(tx - Duration::hours(2)) < at(tx - Duration::hours(1)));
        assert!(at(tx + Duration::hours(2)) < at(tx + Duration::hours(1)));
        // Dew point above the minimum temperature is refused.
        let bad = ConstantWeather {
            dew_point_c: 13.0,
            ..p
        };
        let e = constant_weather(&bad, lat, lon, start, end, 900.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("dew point 13 °C is above the minimum air temperature 12 °C"),
            "{e}"
        );
        // Polar night still gives a finite bounded cycle.
        let h = constant_weather(
            &p,
            85.0,
            0.0,
            utc("2021-12-20T00:00:00Z"),
            utc("2021-12-21T00:00:00Z"),
            3600.0,
        )
        .unwrap();
        assert!(h.samples.iter().all(|s| s.air_temp_k.is_finite()));
    }

    #[test]
    fn utc_offset_parsing() {
        assert_eq!(
            parse_utc_offset("-05:00").unwrap(),
            FixedOffset::west_opt(18000).unwrap()
        );
        assert_eq!(parse_utc_offset("+0530").ok(), None);
        assert_eq!(
            parse_utc_offset("+5").unwrap(),
            FixedOffset::east_opt(18000).unwrap()
        );
        assert!(
            parse_utc_offset("EST")
                .unwrap_err()
                .contains("expected e.g. -05:00")
        );
    }
}
