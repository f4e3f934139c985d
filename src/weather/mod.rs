//! Weather history: readers (one file per format: [`csv`], [`tmy3`],
//! [`epw`], behind one entry, [`read_weather`]), time interpolation,
//! coverage checks and a constant-weather source ([`constant`]). Owner: the
//! sun/weather work (issue 4).
//!
//! A reader turns a file's text into [`WeatherFile`]: it parses records
//! with the shared `Ctx` (file/line errors), `Met` and
//! `build_sample`, and lays them on one time axis with `assemble`.
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

use crate::bounds::{self, Bound};
use crate::units::{STEFAN_BOLTZMANN_W_M2K4, ZERO_C_K};
use thiserror::Error;

pub mod constant;
pub mod csv;
pub mod epw;
pub mod psm3;
pub mod pvgis;
pub mod record;
mod site_check;
pub mod tmy2;
pub mod tmy3;

pub use site_check::{
    MAX_STATION_OFFSET_DEG, SUN_DOWN_ELEVATION_DEG, SUN_UP_ELEVATION_DEG, SUNLIGHT_WHILE_DOWN_W_M2,
    stand_in_solar_shift, station_mismatch, sunlight_mismatch,
};

pub use constant::{ConstantWeather, constant_weather, diurnal_air_temp_c};
pub use csv::{PLAIN_CSV_COLUMNS, parse_plain_csv};
pub use epw::parse_epw;
pub use psm3::parse_psm3;
pub use pvgis::parse_pvgis_csv;
pub use record::{WeatherRecord, WeatherText};
pub use tmy2::parse_tmy2;
pub use tmy3::parse_tmy3;

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
    /// Total cloud cover, 0 (clear) to 1 (overcast); `None` where the
    /// record does not carry it but has measured irradiance the forcing
    /// derives it from (see [`crate::therm::forcing`]).
    pub cloud_fraction: Option<f64>,
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
        "{file}:{line}: time {} is earlier than {} on line {prev_line}: records must be sorted by time",
        fmt_time(*.time),
        fmt_time(*.prev)
    )]
    Unsorted {
        file: String,
        line: usize,
        prev_line: usize,
        time: DateTime<Utc>,
        prev: DateTime<Utc>,
    },
    #[error("{file}:{line}: time {} repeats line {prev_line}: duplicate record", fmt_time(*.time))]
    Duplicate {
        file: String,
        line: usize,
        prev_line: usize,
        time: DateTime<Utc>,
    },
    #[error(
        "{file}:{line}: gap of {:.2} h since line {prev_line} ({} to {}); the largest allowed gap is {:.2} h",
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
    #[error(
        "{file}:{line}: the records jump from {prev_date} (line {prev_line}) to {date}: this is a \
         typical-year file (its months come from different years, {first_year} to {last_year}); \
         set `typical_year = true` in the scene's [weather.file] (irsig therm: --typical-year)"
    )]
    TypicalYear {
        file: String,
        line: usize,
        prev_line: usize,
        prev_date: NaiveDate,
        date: NaiveDate,
        first_year: i32,
        last_year: i32,
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
    /// Read the file as a typical year (TMY3, most EPW: each month taken
    /// from a different source year) and lay it on every calendar year of
    /// this span, so that a window crossing 31 Dec → 1 Jan wraps to the
    /// file's own January (see [`YearSpan`]). Ignored for the plain CSV.
    pub typical_year: Option<YearSpan>,
    /// Largest allowed spacing between consecutive records, seconds.
    pub max_gap_s: f64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            utc_offset: None,
            typical_year: None,
            max_gap_s: DEFAULT_MAX_GAP_S,
        }
    }
}

/// The calendar years (first to last, inclusive) onto which a typical-year
/// file is laid: every year gets a copy of the file's records with the
/// year replaced (month, day and local time kept). In a leap year a file
/// without 29 February repeats its 28 February for it (as EnergyPlus does,
/// Input Output Reference, "RunPeriod"); in other years a file's 29
/// February records are dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct YearSpan {
    pub first: i32,
    pub last: i32,
}

impl YearSpan {
    /// The years a window `[start, end]` (UTC) needs: one year either side
    /// (a file in local time reaches up to 14 h into the neighbouring UTC
    /// year), clipped to [`crate::bounds::time::YEAR`].
    pub fn around(start: DateTime<Utc>, end: DateTime<Utc>) -> Self {
        let (lo, hi) = (bounds::time::YEAR.lo as i32, bounds::time::YEAR.hi as i32);
        Self {
            first: (start.year() - 1).clamp(lo, hi),
            last: (end.year() + 1).clamp(lo, hi),
        }
    }
}

/// A weather file format: which reader reads a file, and what a scene's
/// `[weather.file] format` names (`"csv"`, `"tmy3"`, …; the one type for
/// both, issue 31).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WeatherFormat {
    /// irsig's plain CSV (docs/weather-format.md).
    Csv,
    /// NREL TMY3, and SolarAnywhere's "TMY3 format".
    Tmy3,
    /// EnergyPlus EPW (also PVGIS's EPW output).
    Epw,
    /// NREL TMY2.
    Tmy2,
    /// NSRDB PSM3/PSM4 CSV.
    Psm3,
    /// PVGIS TMY CSV.
    Pvgis,
}

/// The formats [`read_weather`] recognises, for error messages.
pub const SUPPORTED_FORMATS: &str = "irsig plain CSV (docs/weather-format.md), NREL TMY3 (also \
     SolarAnywhere's TMY3 format), NREL TMY2, EnergyPlus EPW (also PVGIS's EPW), NSRDB PSM3/PSM4 CSV, \
     PVGIS TMY CSV";

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
            cloud_fraction: lerp_opt(a.cloud_fraction, b.cloud_fraction, w),
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
    (lw_down_w_m2 / STEFAN_BOLTZMANN_W_M2K4).powf(0.25)
}

/// Air pressure (Pa) of the standard atmosphere at an altitude (m), as
/// pvlib's `alt2pres`: p = 100·((44331.514 − h)/11880.516)^(1/0.1902632).
pub fn pressure_pa_from_altitude(altitude_m: f64) -> f64 {
    100.0 * ((44331.514 - altitude_m) / 11880.516).powf(1.0 / 0.1902632)
}

/// Pressure of the standard atmosphere at a station's elevation, hPa: what
/// a reader takes for a record without a pressure
/// ([`pressure_pa_from_altitude`]).
pub fn standard_pressure_hpa(elevation_m: f64) -> f64 {
    pressure_pa_from_altitude(elevation_m) / 100.0
}

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

/// Reads a weather file with default [`ReadOptions`] (max gap 3 h) and the
/// given UTC offset for plain-CSV times written without one. The format is
/// detected from the file (see [`read_weather`]).
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

/// Reads a weather file (see [`read_weather`]) with explicit options,
/// returning the station metadata too (the same as [`read_weather`]).
pub fn read_weather_file_with(
    path: &Path,
    opts: &ReadOptions,
) -> Result<WeatherFile, WeatherError> {
    read_weather(path, opts)
}

/// The one entry to the weather readers: reads a weather file with
/// explicit options, detecting its format from its first lines
/// ([`detect_format`]), and returns the history with the station metadata.
/// A UTF-8 byte-order mark is dropped; bytes that are not UTF-8 (Latin-1
/// station names) are replaced.
pub fn read_weather(path: &Path, opts: &ReadOptions) -> Result<WeatherFile, WeatherError> {
    WeatherText::read(path)?.parse(opts)
}

/// The format of a weather file's text, from its first lines: EPW (a
/// `.epw` name or a `LOCATION,` first line); TMY3 (7 or more fields, then a
/// `Date (MM/DD/YYYY)` header); TMY2 (a whitespace station line ending
/// `N|S deg min E|W deg min elevation`); NSRDB PSM3/PSM4 (`Location ID` in
/// line 1, a `Year,Month,Day,Hour` header in line 3); PVGIS TMY CSV (a
/// `Latitude (decimal degrees):` line); the plain CSV (a header naming a
/// `time` column). Otherwise `Err((line, what it looks like))`.
pub fn detect_format(text: &str, epw_name: bool) -> Result<WeatherFormat, (usize, String)> {
    let lines: Vec<&str> = text.lines().take(40).collect();
    let l = |i: usize| lines.get(i).copied().unwrap_or("");
    if epw_name || text.starts_with("LOCATION,") {
        return Ok(WeatherFormat::Epw);
    }
    if l(1).trim_start().starts_with("Date (MM/DD/YYYY)") && split_csv(l(0)).len() >= 7 {
        return Ok(WeatherFormat::Tmy3);
    }
    if tmy2::tmy2_station(l(0)).is_some() {
        return Ok(WeatherFormat::Tmy2);
    }
    let first4 = |s: &str| -> Vec<String> {
        split_csv(s)
            .iter()
            .take(4)
            .map(|x| x.trim().to_string())
            .collect()
    };
    if split_csv(l(0)).iter().any(|x| x.trim() == "Location ID")
        && first4(l(2)) == ["Year", "Month", "Day", "Hour"]
    {
        return Ok(WeatherFormat::Psm3);
    }
    if lines
        .iter()
        .any(|x| x.starts_with("Latitude (decimal degrees):"))
    {
        return Ok(WeatherFormat::Pvgis);
    }
    let t = text.trim_start();
    let looks = |what: &str| {
        Err((
            1,
            format!("this looks like {what}, not a weather format irsig reads"),
        ))
    };
    if t.starts_with('{') || t.starts_with('[') {
        return looks("a JSON file (e.g. PVGIS's JSON output: download its CSV or EPW instead)");
    }
    if t.starts_with("PK\u{3}\u{4}") {
        return looks("a ZIP archive or an Excel workbook (unpack it, or save the sheet as CSV)");
    }
    if t.starts_with("\u{1f}\u{fffd}") || t.starts_with("\u{1f}\u{8b}") {
        return looks("a gzip-compressed file (decompress it first)");
    }
    if l(1).starts_with("ObservationTime(LST)") {
        return looks("SolarAnywhere's own \"SA format\" (download its \"TMY3 format\" instead)");
    }
    // The plain CSV: the first line that is neither blank nor a comment
    // is its header.
    let Some((i, header)) = lines
        .iter()
        .enumerate()
        .find(|(_, x)| !x.trim().is_empty() && !x.trim_start().starts_with('#'))
    else {
        return Ok(WeatherFormat::Csv); // the reader reports "no header"
    };
    if split_csv(header)
        .iter()
        .any(|x| x.trim().eq_ignore_ascii_case("time"))
    {
        return Ok(WeatherFormat::Csv);
    }
    let shown: String = header.chars().take(60).collect();
    Err((
        i + 1,
        format!(
            "'{shown}{}' is not the start of a weather format irsig recognises (a plain CSV's header \
             names a `time` column)",
            if header.chars().count() > 60 {
                "…"
            } else {
                ""
            }
        ),
    ))
}

/// The station of a weather file (`None` for a plain CSV), read with the
/// file's own years (a typical year laid on one year) and no gap limit:
/// only the header matters here.
pub fn read_station(
    path: &Path,
    typical_year: bool,
) -> Result<Option<WeatherStation>, WeatherError> {
    WeatherText::read(path)?.station(typical_year)
}

/// The options [`read_station`] reads a file with: no gap limit, a typical
/// year laid on 2001.
pub fn station_options(typical_year: bool) -> ReadOptions {
    ReadOptions {
        typical_year: typical_year.then_some(YearSpan {
            first: 2001,
            last: 2001,
        }),
        max_gap_s: f64::INFINITY,
        ..ReadOptions::default()
    }
}

impl WeatherHistory {
    /// The same record with every sample time moved by `by`.
    pub fn shifted(mut self, by: Duration) -> WeatherHistory {
        for t in &mut self.times {
            *t += by;
        }
        self
    }
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
    fn bound(&self, v: f64, b: &Bound) -> Result<f64, WeatherError> {
        self.range(v, b.key, b.lo, b.hi, b.unit)
    }

    /// A calendar date of a record, with its year inside
    /// [`crate::bounds::time::YEAR`] (chrono's arithmetic on years near its
    /// limit of ±262 143 overflowed).
    fn date(&self, year: i64, month: i64, day: i64) -> Result<NaiveDate, WeatherError> {
        self.bound(year as f64, &bounds::time::YEAR)?;
        let (Ok(month), Ok(day)) = (u32::try_from(month), u32::try_from(day)) else {
            return Err(self.malformed(format!("date {year}-{month}-{day} does not exist")));
        };
        NaiveDate::from_ymd_opt(year as i32, month, day)
            .ok_or_else(|| self.malformed(format!("date {year}-{month}-{day} does not exist")))
    }

    /// A record's local time in `tz`, as UTC (the year is already bounded,
    /// so this cannot overflow).
    fn local_to_utc(
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
    fn irradiance(&self, v: f64, field: &str) -> Result<f64, WeatherError> {
        Ok(self
            .range(v, field, -10.0, bounds::weather::IRRADIANCE.hi, "W/m²")?
            .max(0.0))
    }
}

/// The range checks shared by every reader, in the file's own units.
struct Met {
    air_temp_c: f64,
    dew_point_c: Option<f64>,
    rh_percent: Option<f64>,
    wind_m_s: f64,
    /// Readers whose files may omit it use [`standard_pressure_hpa`].
    pressure_hpa: f64,
    cloud_fraction: Option<f64>,
    ghi: Option<f64>,
    dni: Option<f64>,
    dhi: Option<f64>,
    sky_temp_c: Option<f64>,
    precip_mm_h: f64,
}

fn build_sample(c: &Ctx, m: Met) -> Result<WeatherSample, WeatherError> {
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
fn assemble(
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

fn utc_offset_from_hours(c: &Ctx, h: f64) -> Result<FixedOffset, WeatherError> {
    let h = c.bound(h, &bounds::weather::TIME_ZONE)?;
    FixedOffset::east_opt((h * 3600.0).round() as i32)
        .ok_or_else(|| c.malformed(format!("time zone {h} h is not a valid UTC offset")))
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

/// One record of a file in local standard time, before it is laid on the
/// UTC time axis by [`place`]: the date written in the file and the stamp's
/// minutes after that date's midnight (1440 for TMY3's `24:00`).
struct Stamped {
    line: usize,
    date: NaiveDate,
    minutes: i64,
    sample: WeatherSample,
}

/// Lays local-time records on the UTC axis and assembles the history. A
/// typical-year file read without [`ReadOptions::typical_year`] is refused
/// where its source year changes ([`WeatherError::TypicalYear`]); with it,
/// the records are laid on every year of the span (see [`YearSpan`]).
fn place(
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

#[cfg(test)]
mod tests;
