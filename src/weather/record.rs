//! A weather file read once and parsed on demand: [`WeatherText`] (the
//! file's text) and [`WeatherRecord`] (what a loaded scene carries: the
//! text and its parsed records, shared by the load, the warnings, the
//! atmosphere's choice and every frame of a render); the one entry to the
//! readers ([`read_weather`]).

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use chrono::FixedOffset;

use super::csv::parse_plain_csv;
use super::detect::detect_format;
use super::epw::parse_epw;
use super::psm3::parse_psm3;
use super::pvgis::parse_pvgis_csv;
use super::tmy2::parse_tmy2;
use super::tmy3::parse_tmy3;
use super::{
    ReadOptions, SUPPORTED_FORMATS, WeatherError, WeatherFile, WeatherFormat, WeatherHistory,
    WeatherStation, YearSpan,
};

/// A weather file's text as read (the file opened once): parsed with
/// [`WeatherText::parse`] as often as a caller needs other options (a
/// typical year is laid on the years of each window it is read for).
#[derive(Debug)]
pub struct WeatherText {
    path: PathBuf,
    text: String,
}

impl WeatherText {
    /// Reads the file at `path` (a regular file of at most
    /// [`crate::bounds::sizes::MAX_WEATHER_FILE_BYTES`]); a UTF-8
    /// byte-order mark is dropped; bytes that are not UTF-8 are replaced.
    pub fn read(path: &Path) -> Result<Self, WeatherError> {
        let bytes = crate::files::read(path, crate::bounds::sizes::MAX_WEATHER_FILE_BYTES)
            .map_err(|err| WeatherError::Io {
                file: path.display().to_string(),
                err,
            })?;
        let text = String::from_utf8_lossy(&bytes);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text).to_string();
        Ok(Self {
            path: path.to_path_buf(),
            text,
        })
    }

    /// The path the text was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The history and station of the text with `opts`, its format detected
    /// from its first lines ([`detect_format`]).
    pub fn parse(&self, opts: &ReadOptions) -> Result<WeatherFile, WeatherError> {
        let file = self.path.display().to_string();
        let text = self.text.as_str();
        let is_epw = self
            .path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("epw"));
        match detect_format(text, is_epw) {
            Ok(WeatherFormat::Epw) => parse_epw(text, &file, opts),
            Ok(WeatherFormat::Tmy3) => parse_tmy3(text, &file, opts),
            Ok(WeatherFormat::Tmy2) => parse_tmy2(text, &file, opts),
            Ok(WeatherFormat::Psm3) => parse_psm3(text, &file, opts),
            Ok(WeatherFormat::Pvgis) => parse_pvgis_csv(text, &file, opts),
            Ok(WeatherFormat::Csv) => parse_plain_csv(text, &file, opts),
            Err((line, what)) => Err(WeatherError::Malformed {
                file,
                line,
                msg: format!("{what}; irsig reads {SUPPORTED_FORMATS}"),
            }),
        }
    }

    /// The station metadata, read as [`read_station`] does.
    pub fn station(&self, typical_year: bool) -> Result<Option<WeatherStation>, WeatherError> {
        Ok(self.parse(&station_options(typical_year))?.station)
    }
}

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

/// The scene's weather file, read on first use and kept with its parsed
/// records (one per set of [`ReadOptions`]): a loaded scene carries one, so
/// that its load, warnings, atmosphere choice and every frame read the file
/// once. A clone shares the record; asking for another path reads that
/// file instead. Not part of a scene's identity (every two compare equal).
#[derive(Clone, Default)]
pub struct WeatherRecord(Arc<Mutex<Option<Kept>>>);

/// What a [`WeatherRecord`] keeps.
struct Kept {
    text: Arc<WeatherText>,
    parsed: Vec<(ReadOptions, Arc<WeatherFile>)>,
}

impl WeatherRecord {
    fn kept<'a>(g: &'a mut Option<Kept>, path: &Path) -> Result<&'a mut Kept, WeatherError> {
        if g.as_ref().is_none_or(|k| k.text.path != path) {
            *g = Some(Kept {
                text: Arc::new(WeatherText::read(path)?),
                parsed: Vec::new(),
            });
        }
        Ok(g.as_mut().expect("just set"))
    }

    /// The text of the file at `path` (read now, or kept from before).
    pub fn text(&self, path: &Path) -> Result<Arc<WeatherText>, WeatherError> {
        let mut g = self.0.lock().unwrap_or_else(|e| e.into_inner());
        Ok(Self::kept(&mut g, path)?.text.clone())
    }

    /// The file at `path` parsed with `opts` (parsed now, or kept from an
    /// earlier call with equal options).
    pub fn parsed(
        &self,
        path: &Path,
        opts: &ReadOptions,
    ) -> Result<Arc<WeatherFile>, WeatherError> {
        let mut g = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let k = Self::kept(&mut g, path)?;
        if let Some((_, f)) = k.parsed.iter().find(|(o, _)| o == opts) {
            return Ok(f.clone());
        }
        let f = Arc::new(k.text.parse(opts)?);
        k.parsed.push((*opts, f.clone()));
        Ok(f)
    }
}

impl PartialEq for WeatherRecord {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for WeatherRecord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("WeatherRecord")
    }
}
