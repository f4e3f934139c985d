//! The physical range of every user-supplied quantity, stated once.
//!
//! Each parser checks a value against its [`Bound`] where the value enters
//! (the scene and material TOML, the weather readers, the response, kernel
//! and emissivity CSVs, the atmosphere tables) and reports the file, line,
//! key, value and this range. docs/scene-format.md and
//! docs/weather-format.md list the same ranges; `tests/bounds_docs.rs`
//! reads those tables back and compares them with [`documented`], so the
//! docs cannot drift from the checks.
//!
//! Sizes derived from the inputs (spectral bins, table dimensions, image
//! size × supersampling × history) are bounded before anything is
//! allocated: see [`sizes`] and `render::memory`.

/// A closed range `lo <= value <= hi` of one input key, in `unit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// The key as written in the input (TOML key, CSV column, header field).
    pub key: &'static str,
    /// Lowest value allowed (inclusive).
    pub lo: f64,
    /// Highest value allowed (inclusive).
    pub hi: f64,
    /// Unit, as printed after the range (empty for dimensionless).
    pub unit: &'static str,
}

impl Bound {
    /// The range `lo <= key <= hi unit`.
    pub const fn new(key: &'static str, lo: f64, hi: f64, unit: &'static str) -> Self {
        Self { key, lo, hi, unit }
    }

    /// Whether `v` is finite and inside the range.
    pub fn contains(&self, v: f64) -> bool {
        v.is_finite() && v >= self.lo && v <= self.hi
    }

    /// The range as text: `lo <= key <= hi unit`.
    pub fn expected(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!("{} <= {} <= {}{unit}", num(self.lo), self.key, num(self.hi))
    }

    /// `Ok(v)` inside the range, else the message "`key` = v is out of
    /// range: expected lo <= key <= hi unit".
    pub fn check(&self, v: f64) -> Result<f64, String> {
        if self.contains(v) {
            Ok(v)
        } else {
            Err(format!(
                "`{}` = {} is out of range: expected {}",
                self.key,
                num(v),
                self.expected()
            ))
        }
    }
}

/// A number as people write it: plain between 1e-4 and 1e6, else in
/// exponent form (`1e30`, not thirty zeros).
pub fn num(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-4..1e6).contains(&a) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Image times and weather records: the years the sun ephemeris (NREL SPA
/// with the Espenak-Meeus ΔT polynomials) and the weather readers are
/// tested for. Outside them chrono's date arithmetic can overflow; they are
/// refused with this range instead.
pub mod time {
    use super::Bound;
    /// Calendar year of the image time and of every weather record.
    pub const YEAR: Bound = Bound::new("year", 1900.0, 2200.0, "");
}

/// Weather record fields (docs/weather-format.md), after unit conversion.
pub mod weather {
    use super::Bound;
    /// Air temperature.
    pub const AIR_TEMP: Bound = Bound::new("air temperature", -90.0, 60.0, "°C");
    /// Dew-point temperature.
    pub const DEW_POINT: Bound = Bound::new("dew point", -100.0, 60.0, "°C");
    /// Relative humidity.
    pub const RELATIVE_HUMIDITY: Bound = Bound::new("relative humidity", 0.0, 100.0, "%");
    /// Wind speed.
    pub const WIND: Bound = Bound::new("wind speed", 0.0, 100.0, "m/s");
    /// Station pressure.
    pub const PRESSURE: Bound = Bound::new("pressure", 300.0, 1100.0, "hPa");
    /// Total cloud cover as a fraction.
    pub const CLOUD: Bound = Bound::new("cloud fraction", 0.0, 1.0, "");
    /// Each irradiance (GHI, DNI, DHI, longwave down).
    pub const IRRADIANCE: Bound = Bound::new("irradiance", 0.0, 1500.0, "W/m²");
    /// Sky (radiative) temperature.
    pub const SKY_TEMP: Bound = Bound::new("sky temperature", -150.0, 60.0, "°C");
    /// Precipitation rate.
    pub const PRECIPITATION: Bound = Bound::new("precipitation", 0.0, 500.0, "mm/h");
    /// A station's UTC offset (TMY3/EPW header); the CSV `utc_offset:`
    /// comment is bounded the same way.
    pub const TIME_ZONE: Bound = Bound::new("time zone", -12.0, 14.0, "hours from UTC");
    /// Station latitude and longitude (EPW header).
    pub const LATITUDE: Bound = Bound::new("latitude", -90.0, 90.0, "degrees");
    /// Station longitude, east positive.
    pub const LONGITUDE: Bound = Bound::new("longitude", -180.0, 180.0, "degrees");
    /// Station elevation above sea level.
    pub const ELEVATION: Bound = Bound::new("elevation", -500.0, 9000.0, "m");

    /// Every record bound, in the order docs/weather-format.md lists them.
    pub const ALL: &[Bound] = &[
        AIR_TEMP,
        DEW_POINT,
        RELATIVE_HUMIDITY,
        WIND,
        PRESSURE,
        CLOUD,
        IRRADIANCE,
        SKY_TEMP,
        PRECIPITATION,
        TIME_ZONE,
        LATITUDE,
        LONGITUDE,
        ELEVATION,
        super::time::YEAR,
    ];
}

/// Data files a scene names: response curves, PSF kernels, emissivity
/// tables (docs/scene-format.md).
pub mod data {
    use super::Bound;
    /// Wavelengths of a response file or an emissivity table, µm: the
    /// range of ideal bands (`range_um`). A wavelength of 1e-10 µm made the
    /// band's spectral grid 5e12 bins and aborted the process.
    pub const WAVELENGTH_UM: Bound = Bound::new("wavelength_um", 0.2, 100.0, "µm");
    /// Relative response (any scale; normalised). Above 1e6 the band
    /// normalisation could overflow to a non-finite radiance.
    pub const RESPONSE: Bound = Bound::new("response", 0.0, 1e6, "");
    /// PSF kernel weights (normalised to sum 1; a PSF is non-negative).
    pub const KERNEL_WEIGHT: Bound = Bound::new("weight", 0.0, 1e6, "");
    /// Rows (= columns) of a PSF kernel, odd.
    pub const KERNEL_SIZE: Bound = Bound::new("kernel size", 1.0, 255.0, "rows");
    /// Emissivity table angles from the normal.
    pub const EMISSIVITY_ANGLE: Bound = Bound::new("angle_deg", 0.0, 90.0, "degrees");
    /// Emissivity table values.
    pub const EMISSIVITY: Bound = Bound::new("emissivity", 0.0, 1.0, "");

    /// Every data-file bound, as docs/scene-format.md lists them.
    pub const ALL: &[Bound] = &[
        WAVELENGTH_UM,
        RESPONSE,
        KERNEL_WEIGHT,
        KERNEL_SIZE,
        EMISSIVITY_ANGLE,
        EMISSIVITY,
    ];
}

/// Atmosphere table files (docs/atmosphere-tables.md).
pub mod atmos_table {
    use super::Bound;
    /// Wavenumber grid, cm⁻¹ (0.1 µm to 10 mm).
    pub const WAVENUMBER: Bound = Bound::new("wavenumber_cm1", 1.0, 1e5, "cm⁻¹");
    /// Samples in the wavenumber grid.
    pub const WAVENUMBER_COUNT: Bound = Bound::new("wavenumber count", 1.0, 1e6, "samples");
    /// Decoded size of a table (header + payload, after gunzip); the shipped
    /// tables are ~30 MiB.
    pub const MAX_BYTES: u64 = 2 << 30;
    /// Transmittances (`tau_path`, `tau_sun`): 0 to 1 (the f32 values of a
    /// table, rounded to its `mantissa_bits`, may exceed 1 by 10⁻⁴).
    pub const TRANSMITTANCE: Bound = Bound::new("transmittance", 0.0, 1.0001, "");
    /// Radiances (`l_ue`, `l_us`, `l_de`, `l_ds`), in W/(m²·sr·µm) as the
    /// tables store them: non-negative and at most 10⁶ — 40 times the
    /// spectral radiance of a 1500 K blackbody at its peak, above any
    /// atmospheric path, sky or scattered-sun radiance (the shipped
    /// tables' largest is ~100).
    pub const RADIANCE: Bound = Bound::new("radiance", 0.0, 1e6, "W/(m²·sr·µm)");
    /// Exo-atmospheric solar irradiance `e_sun_exo`, W/(m²·µm): at most
    /// 10⁵ (the sun's peak is ~2 100).
    pub const SOLAR_IRRADIANCE: Bound = Bound::new("e_sun_exo", 0.0, 1e5, "W/(m²·µm)");

    /// The physical range of quantity `name` (None: a quantity irsig does
    /// not use, not checked).
    pub fn range_of(name: &str) -> Option<Bound> {
        match name {
            "tau_path" | "tau_sun" => Some(TRANSMITTANCE),
            "l_ue" | "l_us" | "l_de" | "l_ds" => Some(RADIANCE),
            "e_sun_exo" => Some(SOLAR_IRRADIANCE),
            _ => None,
        }
    }

    /// Every atmosphere-table bound, as docs/reliability.md lists them.
    pub const ALL: &[Bound] = &[
        WAVENUMBER,
        WAVENUMBER_COUNT,
        TRANSMITTANCE,
        RADIANCE,
        SOLAR_IRRADIANCE,
    ];
}

/// `[render]` keys of the scene (docs/scene-format.md).
pub mod render {
    use super::Bound;
    /// `render.max_memory_mib`: the largest estimated peak a render may
    /// need (`render::memory`).
    pub const MAX_MEMORY: Bound = Bound::new("max_memory_mib", 1.0, 1e9, "MiB");
}

/// `[[terrain]]` keys of the scene (docs/scene-format.md).
pub mod terrain {
    use super::Bound;
    /// Mesh spacing: 1 cm to 10 km.
    pub const RESOLUTION: Bound = Bound::new("resolution_m", 0.01, 10_000.0, "m");
    /// `extent_m` box coordinates, scene frame (the tracer's frame reaches
    /// 1,048,576 m from the camera target).
    pub const EXTENT: Bound = Bound::new("extent_m", -1e6, 1e6, "m");
    /// `extent_m` as the side of a square centred on the site.
    pub const EXTENT_SIDE: Bound = Bound::new("extent_m", 0.01, 2e6, "m");

    /// DEM heights, m (the ocean's deepest point is −10 935 m, the
    /// highest summit 8 849 m). A height outside (an `inf` or `1e300` in
    /// the raster) is refused naming its pixel; NaN and the no-data value
    /// are no data.
    pub const HEIGHT: Bound = Bound::new("height", -12_000.0, 10_000.0, "m");

    /// The `[[terrain]]` key bounds docs/scene-format.md lists.
    pub const ALL: &[Bound] = &[RESOLUTION, EXTENT, EXTENT_SIDE];
}

/// Numeric arguments of the commands and of the Python functions that
/// mirror them (docs/reliability.md lists them; `tests/bounds_docs.rs`
/// compares). One [`Arg`] per quantity: the CLI checks it under its flag,
/// the library and Python under the argument's own name, so that an error
/// names what the caller wrote.
pub mod args {
    use super::Bound;

    /// A numeric argument: its CLI flag, its name in the library's plain
    /// data and the Python API (the same), and its range.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct Arg {
        /// The flag, e.g. `--step`.
        pub flag: &'static str,
        /// The range, keyed by the library/Python name (`step_min`).
        pub bound: Bound,
    }

    impl Arg {
        /// The argument `flag` with the range `bound`.
        pub const fn new(flag: &'static str, bound: Bound) -> Self {
            Self { flag, bound }
        }
        /// Checks `v` under the library/Python name.
        pub fn check(&self, v: f64) -> Result<f64, String> {
            self.bound.check(v)
        }
        /// Checks `v` under the CLI flag: "--step 1e-9: out of range:
        /// expected …".
        pub fn check_flag(&self, v: f64) -> Result<f64, String> {
            if self.bound.contains(v) {
                Ok(v)
            } else {
                Err(format!(
                    "{} {}: out of range: expected {}",
                    self.flag,
                    super::num(v),
                    self.bound.expected()
                ))
            }
        }
    }

    /// `irsig therm --step` / `therm(step_min=)`: 1 s to 1 day.
    pub const THERM_STEP_MIN: Arg =
        Arg::new("--step", Bound::new("step_min", 1.0 / 60.0, 1440.0, "min"));
    /// `--spin-up-h` / `spin_up_h`: up to a year.
    pub const THERM_SPIN_UP_H: Arg =
        Arg::new("--spin-up-h", Bound::new("spin_up_h", 0.0, 8760.0, "h"));
    /// `--facet-height-m` / `facet_height_m`.
    pub const THERM_FACET_HEIGHT: Arg = Arg::new(
        "--facet-height-m",
        Bound::new("facet_height_m", 0.0, 1e4, "m"),
    );
    /// `--lat` / `lat`.
    pub const LAT: Arg = Arg::new("--lat", Bound::new("lat", -90.0, 90.0, "degrees"));
    /// `--lon` / `lon` (0-360 east accepted).
    pub const LON: Arg = Arg::new("--lon", Bound::new("lon", -180.0, 360.0, "degrees"));
    /// `--elevation` / `elevation`.
    pub const ELEVATION: Arg =
        Arg::new("--elevation", Bound::new("elevation", -1000.0, 9000.0, "m"));
    /// `--slope` / `slope`.
    pub const SLOPE: Arg = Arg::new("--slope", Bound::new("slope", 0.0, 180.0, "degrees"));
    /// `--aspect` / `aspect`.
    pub const ASPECT: Arg = Arg::new("--aspect", Bound::new("aspect", -360.0, 360.0, "degrees"));
    /// `irsig therm --sky-view` / `therm(sky_view=)`: the facet's sky view
    /// factor (no more than its open sky, (1 + cos β)/2, checked with the
    /// slope).
    pub const SKY_VIEW: Arg = Arg::new("--sky-view", Bound::new("sky_view", 0.0, 1.0, ""));
    /// `irsig sun --pressure-hpa` / `sun(pressure_hpa=)`: refraction.
    pub const SUN_PRESSURE: Arg = Arg::new(
        "--pressure-hpa",
        Bound::new("pressure_hpa", 1.0, 2000.0, "hPa"),
    );
    /// `irsig sun --temp-c` / `sun(temp_c=)`: refraction.
    pub const SUN_TEMP: Arg = Arg::new("--temp-c", Bound::new("temp_c", -100.0, 100.0, "°C"));
    /// `irsig sun --delta-t` / `sun(delta_t_s=)`: TT − UT (about −3 to
    /// 500 s over 1900-2200; 1e308 gave NaN angles with exit 0).
    pub const SUN_DELTA_T: Arg =
        Arg::new("--delta-t", Bound::new("delta_t_s", -8000.0, 8000.0, "s"));
    /// `--threads` / `threads` (render, sequence, sweep, probe).
    pub const THREADS: Arg = Arg::new("--threads", Bound::new("threads", 1.0, 1024.0, ""));
    /// Time steps a facet march may take (spin-up and output, at the
    /// step): 2·10⁶ (15-min steps for 57 years; 1-min steps for 3.8
    /// years), about 0.5 GB of forcing and records. Checked before the
    /// forcing is allocated.
    pub const THERM_MAX_STEPS: f64 = 2e6;

    /// Every argument, in the order docs/reliability.md lists them.
    pub const ALL: &[Arg] = &[
        THERM_STEP_MIN,
        THERM_SPIN_UP_H,
        THERM_FACET_HEIGHT,
        LAT,
        LON,
        ELEVATION,
        SLOPE,
        ASPECT,
        SKY_VIEW,
        SUN_PRESSURE,
        SUN_TEMP,
        SUN_DELTA_T,
        THREADS,
        QUICKLOOK_MIN_SPAN_K,
    ];

    // Output options (issue 32).

    /// `--quicklook-min-span-k` (render, sequence, sweep) / a batch spec's
    /// `quicklook_min_span_k`: the PNG quicklook's stretch spans at least
    /// this many kelvin of apparent temperature (0: the plain 2-98 %
    /// stretch).
    pub const QUICKLOOK_MIN_SPAN_K: Arg = Arg::new(
        "--quicklook-min-span-k",
        Bound::new("quicklook_min_span_k", 0.0, 1000.0, "K"),
    );
}

/// Sizes derived from the inputs, bounded before allocation.
pub mod sizes {
    /// Bins of a band's spectral grid (0.2-100 µm at the finest step,
    /// 0.1 cm⁻¹, would be 5e5 bins; the shipped tables have 2 000).
    pub const MAX_SPECTRAL_BINS: usize = 200_000;
    /// Pixels of a DEM or land-cover raster (a 1°×1° tile of USGS 3DEP at
    /// 1/3″, 10,812², has 1.17e8; decoded as f32 that is 470 MB).
    pub const MAX_RASTER_PIXELS: usize = 1 << 27;
    /// Vertices of one terrain mesh (4,000 × 4,000).
    pub const MAX_TERRAIN_VERTICES: usize = 16_000_000;
    /// Size of a text input (scene, material library, response, kernel and
    /// emissivity CSVs) on disk, bytes (the shipped ones are under 100 kB).
    pub const MAX_TEXT_FILE_BYTES: u64 = 64 << 20;
    /// Size of a mesh file (OBJ, glTF/GLB) or of one external glTF buffer.
    pub const MAX_MESH_FILE_BYTES: u64 = 4 << 30;
    /// Size of a DEM or land-cover GeoTIFF on disk (a 1°×1° 1/3″ tile is
    /// ~470 MB uncompressed).
    pub const MAX_RASTER_FILE_BYTES: u64 = 2 << 30;
    /// Size of a weather or forcing file (a 30-year hourly record is
    /// ~60 MB as EPW).
    pub const MAX_WEATHER_FILE_BYTES: u64 = 512 << 20;
}

// --- Keys described beside their fields (issue 31) --------------------------

/// One key of an input table, described once, beside the field it fills
/// (the material keys: `therm::slab::keys`, `therm::surface::keys`,
/// `scene::material::keys`): where it is written, its unit, default and
/// range as the docs list them, and what it means. The material-key table
/// of docs/scene-format.md is generated from these rows
/// (`tests/bounds_docs.rs`; `IRSIG_BLESS=1` rewrites it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    /// The path inside the table as written: `["thickness_m"]`,
    /// `["back", "air", "exposed_area"]`.
    pub path: &'static [&'static str],
    /// Unit as the docs print it (empty: dimensionless or not a number).
    pub unit: &'static str,
    /// The default as the docs print it (`required`, `0`, `"insulated"`).
    pub default: &'static str,
    /// The range of a number (its `key` is the path's last segment).
    pub range: Option<Bound>,
    /// `true`: the reader of the whole table checks the value as written
    /// against `range`; `false`: the code that builds the value checks it
    /// (after defaults, with per-kind ranges or a lower end taken from
    /// another key).
    pub as_written: bool,
    /// What it means, one line (the docs' last column).
    pub meaning: &'static str,
}

impl Key {
    /// A key that is not a number (or has no range).
    pub const fn text(
        path: &'static [&'static str],
        unit: &'static str,
        default: &'static str,
        meaning: &'static str,
    ) -> Self {
        Self {
            path,
            unit,
            default,
            range: None,
            as_written: false,
            meaning,
        }
    }

    /// A number in `range`, checked as written.
    pub const fn number(
        path: &'static [&'static str],
        default: &'static str,
        range: Bound,
        meaning: &'static str,
    ) -> Self {
        Self {
            path,
            unit: range.unit,
            default,
            range: Some(range),
            as_written: true,
            meaning,
        }
    }

    /// The same key, its range checked where its value is built.
    pub const fn checked_where_built(self) -> Self {
        Self {
            as_written: false,
            ..self
        }
    }
}

/// A key's value refused: where inside its table (the key path; empty: the
/// table itself) and why. The reader that knows the file turns it into
/// `file:line:col: message`.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyError {
    /// The key path inside the table.
    pub path: Vec<&'static str>,
    /// What is wrong and what was expected.
    pub msg: String,
}

impl KeyError {
    /// The error of a value outside its range, at `path`.
    pub fn range(path: &'static [&'static str], b: &Bound, v: f64) -> Result<f64, Self> {
        b.check(v).map_err(|msg| Self {
            path: path.to_vec(),
            msg,
        })
    }
}

/// Scene keys whose range is checked on the value as written, one row each
/// (key path in the scene TOML, range): `scene::validate` walks this table,
/// and docs/scene-format.md lists every row (`tests/bounds_docs.rs`).
/// Issue 31 moves the scene's literal range checks here table by table; the
/// checks that depend on other keys (poses, terrain extents, quantisation
/// limits) are still written out in `scene/validate.rs`.
pub mod scene_keys {
    use super::Bound;
    /// (path in the scene TOML, range). A path segment `*` is every entry
    /// of an array of tables (`[[object]]`); a number array at the end of
    /// a path (`translate_m = [x, y, z]`) has each element checked. Only
    /// values the file writes (after `--set`) are checked: every default
    /// lies inside its range.
    pub type Row = (&'static [&'static str], Bound);
    /// Coordinates: the farthest a scene point or a pose may lie from the
    /// scene origin, m (projected coordinate systems stay within ±2.1e7 m).
    pub const COORD: f64 = 1e8;
    /// `translate_m` of an object or instance, each coordinate.
    pub const TRANSLATE: Bound = Bound::new("translate_m", -COORD, COORD, "m");
    /// `rotate_deg` of an object or instance, each angle.
    pub const ROTATE: Bound = Bound::new("rotate_deg", -COORD, COORD, "degrees");
    /// `scale`, one factor or each of three.
    pub const SCALE: Bound = Bound::new("scale", 1e-9, 1e9, "");
    /// A pose's `target_m`, each coordinate.
    pub const TARGET: Bound = Bound::new("target_m", -COORD, COORD, "m");
    /// A pose's `azimuth_deg` (target → sensor, clockwise from north).
    pub const AZIMUTH: Bound = Bound::new("azimuth_deg", -360.0, 360.0, "degrees");
    /// `weather.constant`: the air temperatures (and `air_max_c >=
    /// air_min_c`, checked beside the table).
    /// `air_min_c`.
    pub const AIR_MIN: Bound = Bound::new("air_min_c", -90.0, 60.0, "°C");
    /// `air_max_c`.
    pub const AIR_MAX: Bound = Bound::new("air_max_c", -90.0, 60.0, "°C");
    /// `weather.constant.dew_point_c` (and `<= air_min_c`, beside the table).
    pub const DEW_POINT: Bound = Bound::new("dew_point_c", -100.0, 60.0, "°C");
    /// `sensor.band.range_um` (and `range_um[1] > range_um[0]`).
    pub const RANGE_UM: Bound = Bound::new("range_um", 0.2, 100.0, "µm");
    /// Every range of the scene file, checked by `scene::validate` and
    /// listed in docs/scene-format.md.
    pub const ALL: &[Row] = &[
        (
            &["site", "latitude_deg"],
            Bound::new("latitude_deg", -90.0, 90.0, "degrees"),
        ),
        (
            &["site", "longitude_deg"],
            Bound::new("longitude_deg", -180.0, 180.0, "degrees"),
        ),
        (
            &["site", "elevation_m"],
            Bound::new("elevation_m", -500.0, 9000.0, "m"),
        ),
        (
            &["site", "utc_offset_h"],
            Bound::new("utc_offset_h", -14.0, 14.0, "hours"),
        ),
        (
            &["atmosphere", "visibility_km"],
            Bound::new("visibility_km", 0.05, 1000.0, "km"),
        ),
        (&["object", "*", "translate_m"], TRANSLATE),
        (&["object", "*", "rotate_deg"], ROTATE),
        (&["object", "*", "scale"], SCALE),
        (&["object", "*", "instance", "*", "translate_m"], TRANSLATE),
        (&["object", "*", "instance", "*", "rotate_deg"], ROTATE),
        (&["object", "*", "instance", "*", "scale"], SCALE),
        (
            &["weather", "constant", "wind_m_s"],
            Bound::new("wind_m_s", 0.0, 100.0, "m/s"),
        ),
        (&["weather", "constant", "air_min_c"], AIR_MIN),
        (&["weather", "constant", "air_max_c"], AIR_MAX),
        (&["weather", "constant", "dew_point_c"], DEW_POINT),
        (
            &["weather", "constant", "cloud_fraction"],
            Bound::new("cloud_fraction", 0.0, 1.0, ""),
        ),
        (
            &["weather", "constant", "pressure_pa"],
            Bound::new("pressure_pa", 30_000.0, 110_000.0, "Pa"),
        ),
        (
            &["sensor", "width_px"],
            Bound::new("width_px", 1.0, 65536.0, "pixels"),
        ),
        (
            &["sensor", "height_px"],
            Bound::new("height_px", 1.0, 65536.0, "pixels"),
        ),
        (
            &["sensor", "fov_h_deg"],
            Bound::new("fov_h_deg", 1e-6, 170.0, "degrees"),
        ),
        (
            &["sensor", "fov_v_deg"],
            Bound::new("fov_v_deg", 1e-6, 170.0, "degrees"),
        ),
        (
            &["sensor", "pose", "look_at", "position_m"],
            Bound::new("position_m", -COORD, COORD, "m"),
        ),
        (&["sensor", "pose", "look_at", "target_m"], TARGET),
        (
            &["sensor", "pose", "look_at", "up"],
            Bound::new("up", -COORD, COORD, ""),
        ),
        (
            &["sensor", "pose", "altitude", "altitude_m"],
            Bound::new("altitude_m", -1e3, COORD, "m"),
        ),
        (
            &["sensor", "pose", "altitude", "view_zenith_deg"],
            Bound::new("view_zenith_deg", 0.0, 89.0, "degrees"),
        ),
        (&["sensor", "pose", "altitude", "azimuth_deg"], AZIMUTH),
        (&["sensor", "pose", "altitude", "target_m"], TARGET),
        (
            &["sensor", "pose", "slant_range", "slant_range_m"],
            Bound::new("slant_range_m", 0.0, COORD, "m"),
        ),
        (
            &["sensor", "pose", "slant_range", "view_zenith_deg"],
            Bound::new("view_zenith_deg", 0.0, 89.999, "degrees"),
        ),
        (&["sensor", "pose", "slant_range", "azimuth_deg"], AZIMUTH),
        (&["sensor", "pose", "slant_range", "target_m"], TARGET),
        (&["sensor", "band", "range_um"], RANGE_UM),
        (
            &["sensor", "psf", "gaussian", "sigma_px"],
            Bound::new("sigma_px", 1e-6, 100.0, "pixels"),
        ),
        (
            &["sensor", "noise", "random_sigma_w_m2_sr_um"],
            Bound::new("random_sigma_w_m2_sr_um", 0.0, 1e6, "W m⁻² sr⁻¹ µm⁻¹"),
        ),
        (
            &["sensor", "noise", "periodic", "amplitude_w_m2_sr_um"],
            Bound::new("amplitude_w_m2_sr_um", 0.0, 1e6, "W m⁻² sr⁻¹ µm⁻¹"),
        ),
        (
            &["sensor", "noise", "periodic", "period_px"],
            Bound::new("period_px", 2.0, 1e6, "pixels"),
        ),
        (
            &["sensor", "quantisation", "bits"],
            Bound::new("bits", 1.0, 16.0, ""),
        ),
        (
            &["render", "max_memory_mib"],
            crate::bounds::render::MAX_MEMORY,
        ),
        (
            &["render", "supersample"],
            Bound::new("supersample", 1.0, 16.0, ""),
        ),
        (
            &["render", "spectral_step_cm1"],
            Bound::new("spectral_step_cm1", 0.1, 100.0, "cm⁻¹"),
        ),
        (
            &["render", "thermal_step_min"],
            Bound::new("thermal_step_min", 1.0 / 60.0, 60.0, "minutes"),
        ),
        (
            &["render", "refine_threshold_k"],
            Bound::new("refine_threshold_k", 0.001, 100.0, "K"),
        ),
        (
            &["render", "thermal_tol_k"],
            Bound::new("thermal_tol_k", 1e-6, 1.0, "K"),
        ),
        (
            &["render", "shadow_interval_min"],
            Bound::new("shadow_interval_min", 1.0, 120.0, "minutes"),
        ),
        (
            &["render", "shadow_resolution_min"],
            Bound::new("shadow_resolution_min", 0.5, 120.0, "minutes"),
        ),
        (
            &["render", "shadow_key_recent_h"],
            Bound::new("shadow_key_recent_h", 0.1, 240.0, "hours"),
        ),
        (
            &["render", "history_hours"],
            Bound::new("history_hours", 1.0, 240.0, "hours"),
        ),
    ];
}

/// Every bound the docs must list, with the doc file that lists it.
pub fn documented() -> Vec<(&'static str, Bound)> {
    let mut v: Vec<(&str, Bound)> = Vec::new();
    v.extend(data::ALL.iter().map(|b| ("docs/scene-format.md", *b)));
    v.push(("docs/scene-format.md", time::YEAR));
    v.extend(terrain::ALL.iter().map(|b| ("docs/scene-format.md", *b)));
    v.extend(
        scene_keys::ALL
            .iter()
            .map(|(_, b)| ("docs/scene-format.md", *b)),
    );
    v.extend(weather::ALL.iter().map(|b| ("docs/weather-format.md", *b)));
    v.extend(args::ALL.iter().map(|a| ("docs/reliability.md", a.bound)));
    v.extend(atmos_table::ALL.iter().map(|b| ("docs/reliability.md", *b)));
    v.push(("docs/reliability.md", terrain::HEIGHT));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_names_key_value_and_range() {
        const CONDUCTIVITY: Bound = Bound::new("conductivity_w_mk", 0.005, 2_500.0, "W/(m·K)");
        let e = CONDUCTIVITY.check(1e30).unwrap_err();
        assert_eq!(
            e,
            "`conductivity_w_mk` = 1e30 is out of range: \
             expected 0.005 <= conductivity_w_mk <= 2500 W/(m·K)"
        );
        assert!(CONDUCTIVITY.check(f64::NAN).is_err());
        assert_eq!(CONDUCTIVITY.check(0.005), Ok(0.005));
        assert_eq!(CONDUCTIVITY.check(2500.0), Ok(2500.0));
    }
}
