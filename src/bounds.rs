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
    pub lo: f64,
    pub hi: f64,
    /// Unit, as printed after the range (empty for dimensionless).
    pub unit: &'static str,
}

impl Bound {
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

/// Material library keys (`[material.NAME]`, docs/scene-format.md). The
/// ranges span real materials: density from aerogels (~1 kg/m³) to osmium
/// (22 590 kg/m³); specific heat from lead/gold (~129 J/(kg·K)) to water
/// and wet organics (4 180) with margin; conductivity from aerogel/still
/// air (0.013-0.026 W/(m·K)) to diamond (2 200); thickness from a 10 µm
/// foil to a 10 m ground column. Values outside (mutated libraries with
/// conductivities of 1e30 or thicknesses of 1e-12 m) produced surface
/// temperatures in the thousands of kelvin and are refused.
pub mod material {
    use super::Bound;
    pub const DENSITY: Bound = Bound::new("density_kg_m3", 1.0, 25_000.0, "kg/m³");
    pub const SPECIFIC_HEAT: Bound = Bound::new("specific_heat_j_kgk", 100.0, 15_000.0, "J/(kg·K)");
    pub const CONDUCTIVITY: Bound = Bound::new("conductivity_w_mk", 0.005, 2_500.0, "W/(m·K)");
    pub const THICKNESS: Bound = Bound::new("thickness_m", 1e-5, 10.0, "m");
    pub const SOLAR_ABSORPTIVITY: Bound = Bound::new("solar_absorptivity", 0.0, 1.0, "");
    pub const THERMAL_EMISSIVITY: Bound = Bound::new("thermal_emissivity", 0.0, 1.0, "");
    /// Internal heat source: up to about a solar constant either way
    /// (engines, heated buildings, cooled skins).
    pub const INTERNAL_POWER: Bound = Bound::new("internal_power_w_m2", -1_000.0, 1_000.0, "W/m²");
    pub const SPECULARITY: Bound = Bound::new("specularity", 0.0, 1.0, "");
    pub const EXPOSED_AREA: Bound = Bound::new("exposed_area", 1e-6, 10.0, "");
    pub const DEEP_GROUND_TEMP: Bound = Bound::new("temp_c", -90.0, 100.0, "°C");
    pub const FRESNEL_N: Bound = Bound::new("n", 1e-6, 1e4, "");
    pub const FRESNEL_K: Bound = Bound::new("k", 0.0, 1e4, "");
    pub const WATER_CAPACITY: Bound = Bound::new("water_capacity_mm", 0.0, 50.0, "mm");
    pub const SOLID_ROUGHNESS: Bound = Bound::new("roughness_m", 1e-5, 0.5, "m");
    pub const CANOPY_HEIGHT: Bound = Bound::new("canopy_height_m", 0.01, 30.0, "m");
    pub const LAI: Bound = Bound::new("lai", 0.1, 10.0, "m²/m²");
    pub const SOIL_MOISTURE: Bound = Bound::new("soil_moisture", 0.0, 1.0, "");
    pub const MIN_STOMATAL_RESISTANCE: Bound =
        Bound::new("min_stomatal_resistance_s_m", 10.0, 1000.0, "s/m");
    /// Lower end: the minimum resistance of the same material.
    pub const MAX_STOMATAL_RESISTANCE: Bound =
        Bound::new("max_stomatal_resistance_s_m", 10.0, 1e5, "s/m");
    pub const RADIATION_LIMIT: Bound = Bound::new("radiation_limit_w_m2", 1.0, 1000.0, "W/m²");
    pub const VPD_COEFF: Bound = Bound::new("vpd_coeff", 0.0, 200.0, "(kg/kg)⁻¹");
    pub const EXTINCTION: Bound = Bound::new("extinction_per_m", 0.01, 100.0, "1/m");
    pub const SHORTWAVE_SURFACE_FRACTION: Bound =
        Bound::new("shortwave_surface_fraction", 0.0, 1.0, "");
    pub const EDDY_DIFFUSIVITY: Bound = Bound::new("eddy_diffusivity_m2_s", 0.0, 1.0, "m²/s");
    /// Lower end: the eddy diffusivity of the same material.
    pub const CONVECTIVE_DIFFUSIVITY: Bound =
        Bound::new("convective_diffusivity_m2_s", 0.0, 10.0, "m²/s");
    pub const WATER_ROUGHNESS: Bound = Bound::new("roughness_m", 1e-6, 0.1, "m");

    /// Every material bound, in the order docs/scene-format.md lists them.
    pub const ALL: &[Bound] = &[
        DENSITY,
        SPECIFIC_HEAT,
        CONDUCTIVITY,
        THICKNESS,
        SOLAR_ABSORPTIVITY,
        THERMAL_EMISSIVITY,
        INTERNAL_POWER,
        SPECULARITY,
        EXPOSED_AREA,
        DEEP_GROUND_TEMP,
        FRESNEL_N,
        FRESNEL_K,
        WATER_CAPACITY,
        SOLID_ROUGHNESS,
        WATER_ROUGHNESS,
        CANOPY_HEIGHT,
        LAI,
        SOIL_MOISTURE,
        MIN_STOMATAL_RESISTANCE,
        MAX_STOMATAL_RESISTANCE,
        RADIATION_LIMIT,
        VPD_COEFF,
        EXTINCTION,
        SHORTWAVE_SURFACE_FRACTION,
        EDDY_DIFFUSIVITY,
        CONVECTIVE_DIFFUSIVITY,
    ];
}

/// Weather record fields (docs/weather-format.md), after unit conversion.
pub mod weather {
    use super::Bound;
    pub const AIR_TEMP: Bound = Bound::new("air temperature", -90.0, 60.0, "°C");
    pub const DEW_POINT: Bound = Bound::new("dew point", -100.0, 60.0, "°C");
    pub const RELATIVE_HUMIDITY: Bound = Bound::new("relative humidity", 0.0, 100.0, "%");
    pub const WIND: Bound = Bound::new("wind speed", 0.0, 100.0, "m/s");
    pub const PRESSURE: Bound = Bound::new("pressure", 300.0, 1100.0, "hPa");
    pub const CLOUD: Bound = Bound::new("cloud fraction", 0.0, 1.0, "");
    pub const IRRADIANCE: Bound = Bound::new("irradiance", 0.0, 1500.0, "W/m²");
    pub const SKY_TEMP: Bound = Bound::new("sky temperature", -150.0, 60.0, "°C");
    pub const PRECIPITATION: Bound = Bound::new("precipitation", 0.0, 500.0, "mm/h");
    /// A station's UTC offset (TMY3/EPW header); the CSV `utc_offset:`
    /// comment is bounded the same way.
    pub const TIME_ZONE: Bound = Bound::new("time zone", -12.0, 14.0, "hours from UTC");
    /// Station latitude and longitude (EPW header).
    pub const LATITUDE: Bound = Bound::new("latitude", -90.0, 90.0, "degrees");
    pub const LONGITUDE: Bound = Bound::new("longitude", -180.0, 180.0, "degrees");
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
    pub const EMISSIVITY: Bound = Bound::new("emissivity", 0.0, 1.0, "");

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

    pub const ALL: &[Bound] = &[RESOLUTION, EXTENT, EXTENT_SIDE];
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
}

/// Every bound the docs must list, with the doc file that lists it.
pub fn documented() -> Vec<(&'static str, Bound)> {
    let mut v: Vec<(&str, Bound)> = Vec::new();
    v.extend(material::ALL.iter().map(|b| ("docs/scene-format.md", *b)));
    v.extend(data::ALL.iter().map(|b| ("docs/scene-format.md", *b)));
    v.push(("docs/scene-format.md", time::YEAR));
    v.push(("docs/scene-format.md", render::MAX_MEMORY));
    v.extend(terrain::ALL.iter().map(|b| ("docs/scene-format.md", *b)));
    v.extend(weather::ALL.iter().map(|b| ("docs/weather-format.md", *b)));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_names_key_value_and_range() {
        let e = material::CONDUCTIVITY.check(1e30).unwrap_err();
        assert_eq!(
            e,
            "`conductivity_w_mk` = 1e30 is out of range: \
             expected 0.005 <= conductivity_w_mk <= 2500 W/(m·K)"
        );
        assert!(material::CONDUCTIVITY.check(f64::NAN).is_err());
        assert_eq!(material::CONDUCTIVITY.check(0.005), Ok(0.005));
        assert_eq!(material::CONDUCTIVITY.check(2500.0), Ok(2500.0));
    }
}
