//! Weather history: readers (one file per format: [`csv`], [`tmy3`],
//! [`epw`], behind one entry, [`read_weather`]), time interpolation,
//! coverage checks and a constant-weather source ([`constant`]). Owner: the
//! sun/weather work (issue 4).
//!
//! A reader turns a file's text into [`WeatherFile`]: it parses records
//! with the shared `Ctx` (file/line errors), `Met` and
//! `build_sample`, and lays them on one time axis with `assemble` (all in
//! `parse.rs`). [`detect_format`] (`detect.rs`) tells the format from the
//! first lines; [`record`] holds the entry ([`read_weather`]) and the
//! file read once ([`WeatherRecord`]). This file holds the types the
//! readers fill and the record's interpolation; it imports no child.
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

use chrono::{DateTime, Datelike, Duration, FixedOffset, NaiveDate, NaiveDateTime, TimeZone, Utc};
use serde::{Deserialize, Serialize};

use crate::bounds::{self, Bound};
use crate::units::{STEFAN_BOLTZMANN_W_M2K4, ZERO_C_K};
use thiserror::Error;

pub mod constant;
pub mod csv;
mod detect;
pub mod epw;
mod parse;
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
pub use detect::detect_format;
pub use epw::parse_epw;
pub use parse::parse_utc_offset;
pub use psm3::parse_psm3;
pub use pvgis::parse_pvgis_csv;
pub use record::{
    WeatherRecord, WeatherText, read_station, read_weather, read_weather_file,
    read_weather_file_with, station_options,
};
pub use tmy2::parse_tmy2;
pub use tmy3::parse_tmy3;

/// Largest allowed spacing between consecutive records by default, seconds.
pub const DEFAULT_MAX_GAP_S: f64 = 3.0 * 3600.0;

/// One instant of weather. SI units; optional fields are `None` when the
/// record does not carry them (estimators fill them in later).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WeatherSample {
    /// Air temperature, K.
    pub air_temp_k: f64,
    /// Dew point, K.
    pub dew_point_k: f64,
    /// Wind speed at the station's anemometer, m/s.
    pub wind_speed_m_s: f64,
    /// Station pressure, Pa.
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
    /// One sample per time in `times`.
    pub samples: Vec<WeatherSample>,
    /// Where the record came from (file name, or "constant").
    pub source: String,
}

/// Errors of the weather readers and of coverage checks. Every file error
/// names the file and, where there is one, the 1-based line.
#[derive(Debug, Error)]
pub enum WeatherError {
    #[error("{file}: cannot read the weather file: {err}")]
    /// The file cannot be opened or read.
    Io {
        /// The file.
        file: String,
        /// The system's error.
        err: std::io::Error,
    },
    #[error("{file}:{line}: {msg}")]
    /// A line that does not parse: a field is missing or not a number.
    Malformed {
        /// The file, as named to the reader.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong and what was expected.
        msg: String,
    },
    #[error("{file}:{line}: {field} = {value} is out of range: expected {expected}")]
    /// A value outside its physical range.
    OutOfRange {
        /// The file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// The field's name.
        field: String,
        /// The value read, in the field's unit.
        value: f64,
        /// The range expected, in words.
        expected: String,
    },
    #[error(
        "{file}:{line}: time {} is earlier than {} on line {prev_line}: records must be sorted by time",
        fmt_time(*.time),
        fmt_time(*.prev)
    )]
    /// A record earlier than the one before it.
    Unsorted {
        /// The file.
        file: String,
        /// 1-based line of the record.
        line: usize,
        /// 1-based line of the record before it.
        prev_line: usize,
        /// Its time (UTC).
        time: DateTime<Utc>,
        /// The earlier record's time (UTC).
        prev: DateTime<Utc>,
    },
    #[error("{file}:{line}: time {} repeats line {prev_line}: duplicate record", fmt_time(*.time))]
    /// A record at the same time as an earlier one.
    Duplicate {
        /// The file.
        file: String,
        /// 1-based line of the record.
        line: usize,
        /// 1-based line of the record it repeats.
        prev_line: usize,
        /// Their time (UTC).
        time: DateTime<Utc>,
    },
    #[error(
        "{file}:{line}: gap of {:.2} h since line {prev_line} ({} to {}); the largest allowed gap is {:.2} h",
        secs_between(*.prev, *.time) / 3600.0,
        fmt_time(*.prev),
        fmt_time(*.time),
        .max_gap_s / 3600.0
    )]
    /// A gap between records longer than the reader allows.
    Gap {
        /// The file.
        file: String,
        /// 1-based line of the record after the gap.
        line: usize,
        /// 1-based line of the record before the gap.
        prev_line: usize,
        /// The time before the gap (UTC).
        prev: DateTime<Utc>,
        /// The time after the gap (UTC).
        time: DateTime<Utc>,
        /// The largest gap allowed, s.
        max_gap_s: f64,
    },
    #[error("{file}: no weather records (expected {expected})")]
    /// A file with no records.
    Empty {
        /// The file.
        file: String,
        /// What records the format expects, in words.
        expected: String,
    },
    #[error(
        "weather '{source_name}' (records {} to {}) does not cover the window {} to {}: missing {missing_desc}",
        fmt_time(*.have_start),
        fmt_time(*.have_end),
        fmt_time(*.start),
        fmt_time(*.end)
    )]
    /// A record that does not cover the window a render or run needs.
    NotCovered {
        /// The record's source (file name, or "constant").
        source_name: String,
        /// First record time (UTC).
        have_start: DateTime<Utc>,
        /// Last record time (UTC).
        have_end: DateTime<Utc>,
        /// Start of the window needed (UTC).
        start: DateTime<Utc>,
        /// End of the window needed (UTC).
        end: DateTime<Utc>,
        /// The missing intervals, in words.
        missing_desc: String,
        /// The missing intervals, UTC.
        missing: Vec<(DateTime<Utc>, DateTime<Utc>)>,
    },
    #[error(
        "{file}:{line}: the records jump from {prev_date} (line {prev_line}) to {date}: this is a \
         typical-year file (its months come from different years, {first_year} to {last_year}); \
         set `typical_year = true` in the scene's [weather.file] (irsig therm: --typical-year)"
    )]
    /// A file whose dates jump between years: a typical-year file read as a dated one.
    TypicalYear {
        /// The file.
        file: String,
        /// 1-based line of the record after the jump.
        line: usize,
        /// 1-based line of the record before it.
        prev_line: usize,
        /// The date before the jump.
        prev_date: NaiveDate,
        /// The date after it.
        date: NaiveDate,
        /// Earliest year of the file's records.
        first_year: i32,
        /// Latest year of the file's records.
        last_year: i32,
    },
    #[error("{0}")]
    /// Any other problem, as a whole message.
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
    /// First year, inclusive.
    pub first: i32,
    /// Last year, inclusive.
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
    /// Station name, as the header gives it.
    pub name: String,
    /// Latitude, degrees north.
    pub lat_deg: f64,
    /// Longitude, degrees east.
    pub lon_deg: f64,
    /// Elevation above sea level, m.
    pub elevation_m: f64,
    /// Offset of the file's local standard time from UTC, hours.
    pub utc_offset_h: f64,
}

/// A weather file as read: the history, the format and any station metadata.
#[derive(Clone, Debug, PartialEq)]
pub struct WeatherFile {
    /// The records, in UTC.
    pub history: WeatherHistory,
    /// The format the file was read as.
    pub format: WeatherFormat,
    /// The station of the header (TMY3, TMY2, EPW, PSM3, PVGIS); `None` for plain CSV.
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

impl WeatherHistory {
    /// The same record with every sample time moved by `by`.
    pub fn shifted(mut self, by: Duration) -> WeatherHistory {
        for t in &mut self.times {
            *t += by;
        }
        self
    }
}

#[cfg(test)]
mod tests;
