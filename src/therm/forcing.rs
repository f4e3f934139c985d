//! The per-step boundary forcing of the thermal solver, built from a
//! [`crate::weather::WeatherHistory`] and the sun ephemeris. Owner: the
//! sun/weather work (issue 4); consumed by the slab solver.
//!
//! At every step [`build_forcing`] interpolates the weather
//! ([`WeatherHistory::at`]), computes the sun (NREL SPA, [`crate::sun`]) and
//! fills in what the record lacks:
//!
//! * **Irradiance.** All of GHI, DNI, DHI measured: used as they are. Two of
//!   them: the third from the closure GHI = DHI + DNI·cos z, with
//!   DNI = (GHI − DHI)/cos z only for z ≤ 87° (cos z ≥ 0.052; lower suns give
//!   DNI = 0, DHI = GHI). GHI only: Erbs et al. (1982) diffuse fraction.
//!   None: Ineichen & Perez (2002) clear sky (Linke turbidity
//!   [`ForcingOptions::linke_turbidity`], Kasten & Young 1989 air mass)
//!   reduced by cloud with Kasten & Czeplak (1980),
//!   GHI = GHI_clear·(1 − 0.75·C^3.4), then split by Erbs. With the sun below
//!   the horizon (apparent elevation ≤ 0) DNI = 0.
//! * **Sky temperature.** Measured: used. Otherwise εσT_air⁴ with the
//!   Berdahl & Martin (1984) clear-sky emissivity and the Crawford & Duchon
//!   (1999) cloud correction ε = C + (1 − C)·ε_clear.
//!
//! The [`EstimatorReport`] counts which path each step took, so the render
//! can print which estimators were used.

use chrono::{DateTime, Duration, Timelike, Utc};
use serde::{Deserialize, Serialize};

use crate::sun::{Site, SpaOptions, solar_position_with, validate_site};
use crate::units::{STEFAN_BOLTZMANN_W_M2K4, ZERO_C_K};
use crate::weather::{WeatherError, WeatherHistory, WeatherSample};

/// Everything the surface energy balance needs at one instant, for an
/// unshadowed horizontal reference; the solver applies orientation and the
/// pixel's sun/shadow flag. SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Forcing {
    /// Seconds since the start of the run.
    pub t_s: f64,
    /// Air temperature, K.
    pub air_temp_k: f64,
    /// Effective clear+cloud sky temperature for longwave exchange, K.
    pub sky_temp_k: f64,
    /// Station wind speed, m/s.
    pub wind_speed_m_s: f64,
    /// Direct normal irradiance at the ground (0 with the sun down), W/m².
    pub dni_w_m2: f64,
    /// Diffuse horizontal irradiance, W/m².
    pub dhi_w_m2: f64,
    /// Global horizontal irradiance, W/m² (for ground-reflected light).
    pub ghi_w_m2: f64,
    /// Unit vector towards the sun, local ENU (x east, y north, z up).
    pub sun_dir_enu: [f64; 3],
    /// Dew point of the air, K.
    pub dew_point_k: f64,
    /// Air pressure, Pa.
    pub pressure_pa: f64,
    /// Precipitation rate, mm/h.
    pub precip_mm_h: f64,
    /// Temperature of the ground seen by tilted facets, K; `None`: the air
    /// temperature (the builder's choice; a render fills in its ground
    /// material's own solved temperature).
    pub ground_temp_k: Option<f64>,
}

impl Forcing {
    /// The ground temperature in force, K.
    pub fn ground_k(&self) -> f64 {
        self.ground_temp_k.unwrap_or(self.air_temp_k)
    }

    /// Vapour pressure of the air, Pa (saturation at the dew point).
    pub fn vapour_pressure_pa(&self) -> f64 {
        super::aero::saturation_vapour_pressure_pa(self.dew_point_k)
    }
}

/// Dew point of "dry" forcing in tests and in `irsig therm --forcing`
/// files (which carry no humidity), K (vapour pressure 0.2 Pa).
pub const DRY_AIR_DEW_POINT_K: f64 = 200.0;

/// Solar "constant" at 1 AU used for the extraterrestrial irradiance,
/// W/m² (the value of pvlib and of the ASTM E-490 spectrum).
pub const SOLAR_CONSTANT_W_M2: f64 = 1366.1;

/// Largest zenith angle at which DNI is derived from GHI and DHI, degrees
/// (pvlib's `erbs` uses the same 87° guard).
pub const MAX_ZENITH_FOR_DNI_DEG: f64 = 87.0;

/// Options of [`build_forcing_with`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ForcingOptions {
    /// Linke turbidity for the Ineichen–Perez clear sky (≈2 very clean,
    /// 3 rural mid-latitude, 4-5 humid or urban, 6-7 polluted).
    pub linke_turbidity: f64,
    /// Largest allowed spacing between weather samples inside the window, s.
    pub max_gap_s: f64,
}

impl Default for ForcingOptions {
    fn default() -> Self {
        Self {
            linke_turbidity: 3.0,
            max_gap_s: crate::weather::DEFAULT_MAX_GAP_S,
        }
    }
}

/// Which estimators [`build_forcing`] used, counted in steps.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EstimatorReport {
    /// The weather record's source (file name, or "constant").
    pub weather_source: String,
    /// Forcing samples counted.
    pub n_samples: usize,
    /// GHI, DNI and DHI all measured.
    pub irradiance_measured: usize,
    /// DNI derived as (GHI − DHI)/cos z.
    pub dni_from_ghi_dhi: usize,
    /// DHI derived as GHI − DNI·cos z.
    pub dhi_from_ghi_dni: usize,
    /// GHI derived as DHI + DNI·cos z.
    pub ghi_from_dni_dhi: usize,
    /// Measured GHI split by Erbs.
    pub erbs_from_measured_ghi: usize,
    /// Ineichen–Perez clear sky × Kasten–Czeplak cloud reduction, Erbs split.
    pub clear_sky_cloud: usize,
    /// Sky temperature measured by the record.
    pub sky_temp_measured: usize,
    /// Berdahl–Martin clear sky + Crawford–Duchon cloud correction.
    pub sky_temp_estimated: usize,
    /// Cloud cover not in the record: derived from the clear-sky index of
    /// the measured GHI ([`cloud_from_clear_sky_index`]).
    pub cloud_derived: usize,
    /// Linke turbidity used by the clear-sky model.
    pub linke_turbidity: f64,
}

impl EstimatorReport {
    /// Human-readable lines, one per estimator used.
    pub fn lines(&self) -> Vec<String> {
        let n = self.n_samples;
        let mut v = vec![format!(
            "weather: {} ({n} forcing samples)",
            self.weather_source
        )];
        let mut irr = |k: usize, what: String| {
            if k > 0 {
                v.push(format!("irradiance at {k} of {n} samples: {what}"));
            }
        };
        irr(self.irradiance_measured, "measured GHI, DNI and DHI".into());
        irr(
            self.dni_from_ghi_dhi,
            "measured GHI and DHI, DNI = (GHI - DHI)/cos z (0 beyond z = 87 deg)".into(),
        );
        irr(
            self.dhi_from_ghi_dni,
            "measured GHI and DNI, DHI = GHI - DNI cos z".into(),
        );
        irr(
            self.ghi_from_dni_dhi,
            "measured DNI and DHI, GHI = DHI + DNI cos z".into(),
        );
        irr(
            self.erbs_from_measured_ghi,
            "measured GHI, split by Erbs et al. (1982)".into(),
        );
        irr(
            self.clear_sky_cloud,
            format!(
                "estimated: Ineichen-Perez clear sky (Linke turbidity {}, Kasten-Young air mass) x Kasten-Czeplak \
                 cloud factor (1 - 0.75 C^3.4), split by Erbs et al. (1982)",
                self.linke_turbidity
            ),
        );
        if self.cloud_derived > 0 {
            v.push(format!(
                "cloud cover at {} of {n} samples: not in the record, derived from the clear-sky index of \
                 the measured GHI (Kasten-Czeplak inverted, C = ((1 - GHI/GHI_clear)/0.75)^(1/3.4)); \
                 sun below {} deg: interpolated in time",
                self.cloud_derived, MIN_ELEVATION_FOR_CLOUD_DEG
            ));
        }
        if self.sky_temp_measured > 0 {
            v.push(format!(
                "sky temperature at {} of {n} samples: measured",
                self.sky_temp_measured
            ));
        }
        if self.sky_temp_estimated > 0 {
            v.push(format!(
                "sky temperature at {} of {n} samples: estimated, Berdahl-Martin (1984) clear-sky emissivity \
                 from dew point, with Crawford-Duchon (1999) cloud correction",
                self.sky_temp_estimated
            ));
        }
        v
    }
}

impl std::fmt::Display for EstimatorReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for l in self.lines() {
            writeln!(f, "{l}")?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// Irradiance models (pure functions)
// ---------------------------------------------------------------------------

/// Extraterrestrial normal irradiance, W/m²: E₀ = S/R², S =
/// [`SOLAR_CONSTANT_W_M2`], R the earth–sun distance in AU (from the SPA).
pub fn extraterrestrial_normal_w_m2(earth_sun_distance_au: f64) -> f64 {
    SOLAR_CONSTANT_W_M2 / (earth_sun_distance_au * earth_sun_distance_au)
}

/// Relative optical air mass of Kasten & Young (1989), Appl. Opt. 28,
/// 4735: m = 1/(cos z + 0.50572·(96.07995° − z)^−1.6364), z the apparent
/// zenith in degrees. `None` for z > 90°.
pub fn kasten_young_airmass(apparent_zenith_deg: f64) -> Option<f64> {
    if apparent_zenith_deg.is_nan() || apparent_zenith_deg > 90.0 {
        return None;
    }
    let z = apparent_zenith_deg;
    Some(1.0 / (z.to_radians().cos() + 0.50572 * (6.07995 + (90.0 - z)).powf(-1.6364)))
}

/// Clear-sky global, direct normal and diffuse horizontal irradiance, W/m².
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Irradiance {
    /// Global horizontal irradiance, W/m².
    pub ghi_w_m2: f64,
    /// Direct normal irradiance, W/m².
    pub dni_w_m2: f64,
    /// Diffuse horizontal irradiance, W/m².
    pub dhi_w_m2: f64,
}

/// Ineichen & Perez (2002) clear-sky model (Solar Energy 73, 151-157), as in
/// pvlib's `clearsky.ineichen` (without the Perez enhancement):
/// fh1 = e^(−h/8000), fh2 = e^(−h/1250), cg1 = 5.09e−5·h + 0.868,
/// cg2 = 3.92e−5·h + 0.0387;
/// GHI = cg1·E₀·cos z·exp(−cg2·AM·(fh1 + fh2·(T_L − 1)));
/// DNI = min(b·E₀·exp(−0.09·AM·(T_L − 1)), GHI·(1 − (0.1 − 0.2e^(−T_L))/(0.1 + 0.882/fh1))/cos z)
/// with b = 0.664 + 0.163/fh1; DHI = GHI − DNI·cos z. `AM` is the absolute
/// (pressure-corrected) air mass, h the altitude in m, T_L the Linke
/// turbidity, E₀ the extraterrestrial normal irradiance. Zero with the
/// apparent sun at or below the horizon.
pub fn ineichen_perez(
    apparent_zenith_deg: f64,
    airmass_absolute: f64,
    linke_turbidity: f64,
    altitude_m: f64,
    dni_extra_w_m2: f64,
) -> Irradiance {
    let cos_z = apparent_zenith_deg.to_radians().cos().max(0.0);
    if cos_z <= 0.0 || !airmass_absolute.is_finite() {
        return Irradiance {
            ghi_w_m2: 0.0,
            dni_w_m2: 0.0,
            dhi_w_m2: 0.0,
        };
    }
    let (h, tl, am) = (altitude_m, linke_turbidity, airmass_absolute);
    let fh1 = (-h / 8000.0).exp();
    let fh2 = (-h / 1250.0).exp();
    let cg1 = 5.09e-05 * h + 0.868;
    let cg2 = 3.92e-05 * h + 0.0387;
    let ghi = cg1 * dni_extra_w_m2 * cos_z * (-cg2 * am * (fh1 + fh2 * (tl - 1.0))).exp().max(0.0);
    let b = 0.664 + 0.163 / fh1;
    let bnci = dni_extra_w_m2 * (b * (-0.09 * am * (tl - 1.0)).exp()).max(0.0);
    let bnci2 =
        ghi * ((1.0 - (0.1 - 0.2 * (-tl).exp()) / (0.1 + 0.882 / fh1)) / cos_z).clamp(0.0, 1e20);
    let dni = bnci.min(bnci2);
    Irradiance {
        ghi_w_m2: ghi,
        dni_w_m2: dni,
        dhi_w_m2: ghi - dni * cos_z,
    }
}

/// Cloud reduction of global irradiance by Kasten & Czeplak (1980), Solar
/// Energy 24, 177-189: GHI = GHI_clear·(1 − 0.75·C^3.4), C the total cloud
/// cover fraction (their N/8).
pub fn kasten_czeplak_ghi_w_m2(ghi_clear_w_m2: f64, cloud_fraction: f64) -> f64 {
    ghi_clear_w_m2 * (1.0 - 0.75 * cloud_fraction.clamp(0.0, 1.0).powf(3.4))
}

/// Cloud cover from the clear-sky index k_c = GHI/GHI_clear, by inverting
/// the Kasten & Czeplak (1980) relation the clear-sky path uses
/// ([`kasten_czeplak_ghi_w_m2`], k_c = 1 − 0.75·C^3.4):
/// C = ((1 − k_c)/0.75)^(1/3.4), with k_c clipped to [0.25, 1] (C in [0, 1]).
pub fn cloud_from_clear_sky_index(kc: f64) -> f64 {
    ((1.0 - kc).clamp(0.0, 0.75) / 0.75).powf(1.0 / 3.4)
}

/// Lowest solar elevation at which cloud cover is derived from measured
/// GHI, degrees; lower suns (and nights) take it interpolated in time
/// between the neighbouring derived values.
pub const MIN_ELEVATION_FOR_CLOUD_DEG: f64 = 10.0;

/// Erbs, Klein & Duffie (1982), Solar Energy 28, 293-302, eq. 1: diffuse
/// fraction DHI/GHI from the clearness index k_t:
/// 1 − 0.09·k_t (k_t ≤ 0.22); 0.9511 − 0.1604·k_t + 4.388·k_t² −
/// 16.638·k_t³ + 12.336·k_t⁴ (0.22 < k_t ≤ 0.8); 0.165 (k_t > 0.8).
pub fn erbs_diffuse_fraction(kt: f64) -> f64 {
    if kt <= 0.22 {
        1.0 - 0.09 * kt
    } else if kt <= 0.8 {
        0.9511 - 0.1604 * kt + 4.388 * kt.powi(2) - 16.638 * kt.powi(3) + 12.336 * kt.powi(4)
    } else {
        0.165
    }
}

/// Splits GHI into DNI and DHI with [`erbs_diffuse_fraction`], as pvlib's
/// `irradiance.erbs`: k_t = GHI/(E₀·max(cos z, 0.065)) clipped to [0, 1];
/// DHI = f_d·GHI; DNI = (GHI − DHI)/cos z, set to 0 (and DHI = GHI) for
/// z > 87° or negative values. Returns (irradiance, k_t).
pub fn erbs_split(ghi_w_m2: f64, zenith_deg: f64, dni_extra_w_m2: f64) -> (Irradiance, f64) {
    let cos_z = zenith_deg.to_radians().cos();
    let kt = (ghi_w_m2 / (dni_extra_w_m2 * cos_z.max(0.065))).clamp(0.0, 1.0);
    let dhi = erbs_diffuse_fraction(kt) * ghi_w_m2;
    let dni = (ghi_w_m2 - dhi) / cos_z;
    let bad =
        zenith_deg > MAX_ZENITH_FOR_DNI_DEG || ghi_w_m2 < 0.0 || dni < 0.0 || !dni.is_finite();
    let irr = if bad {
        Irradiance {
            ghi_w_m2,
            dni_w_m2: 0.0,
            dhi_w_m2: ghi_w_m2,
        }
    } else {
        Irradiance {
            ghi_w_m2,
            dni_w_m2: dni,
            dhi_w_m2: dhi,
        }
    };
    (irr, kt)
}

// ---------------------------------------------------------------------------
// Sky temperature
// ---------------------------------------------------------------------------

/// Clear-sky emissivity of Berdahl & Martin (1984), Solar Energy 32,
/// 663-664: ε₀ = 0.711 + 0.56·(T_dp/100) + 0.73·(T_dp/100)², T_dp the dew
/// point in °C, plus their hour-of-day term 0.013·cos(2π·t/24) (t in hours
/// from local midnight) and pressure term 0.00012·(P − 1000) (P in hPa).
pub fn berdahl_martin_clear_sky_emissivity(
    dew_point_c: f64,
    solar_hour: f64,
    pressure_hpa: f64,
) -> f64 {
    let x = dew_point_c / 100.0;
    0.711
        + 0.56 * x
        + 0.73 * x * x
        + 0.013 * (2.0 * std::f64::consts::PI * solar_hour / 24.0).cos()
        + 0.00012 * (pressure_hpa - 1000.0)
}

/// All-sky emissivity with the cloud correction of Crawford & Duchon (1999),
/// J. Appl. Meteor. 38, 474-480: ε = C + (1 − C)·ε_clear (their cloud
/// fraction clf = C, cloud base radiating as a blackbody at air temperature).
pub fn crawford_duchon_emissivity(clear_sky_emissivity: f64, cloud_fraction: f64) -> f64 {
    let c = cloud_fraction.clamp(0.0, 1.0);
    c + (1.0 - c) * clear_sky_emissivity
}

/// Effective sky temperature (K) from the emissivity: σT_sky⁴ = ε·σT_air⁴.
pub fn sky_temp_k_from_emissivity(air_temp_k: f64, emissivity: f64) -> f64 {
    emissivity.clamp(0.0, 1.0).powf(0.25) * air_temp_k
}

/// Sky temperature (K) from air temperature, dew point (K), cloud cover,
/// local solar hour and pressure (Pa): Berdahl–Martin clear sky with the
/// Crawford–Duchon cloud correction.
pub fn estimate_sky_temp_k(
    air_temp_k: f64,
    dew_point_k: f64,
    cloud_fraction: f64,
    solar_hour: f64,
    pressure_pa: f64,
) -> f64 {
    let e0 = berdahl_martin_clear_sky_emissivity(
        dew_point_k - ZERO_C_K,
        solar_hour,
        pressure_pa / 100.0,
    );
    sky_temp_k_from_emissivity(air_temp_k, crawford_duchon_emissivity(e0, cloud_fraction))
}

/// Local mean solar hour (0-24) at a longitude: UTC hour + lon/15.
pub fn local_mean_solar_hour(t: DateTime<Utc>, lon_deg: f64) -> f64 {
    let h = t.hour() as f64 + t.minute() as f64 / 60.0 + t.second() as f64 / 3600.0;
    (h + lon_deg / 15.0).rem_euclid(24.0)
}

// ---------------------------------------------------------------------------
// Building the forcing
// ---------------------------------------------------------------------------

/// Which path one step's irradiance took.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum IrrPath {
    Measured,
    DniFromGhiDhi,
    DhiFromGhiDni,
    GhiFromDniDhi,
    Erbs,
    ClearSky,
}

/// Irradiance of one step from the (interpolated) weather and the sun.
fn step_irradiance(
    w: &WeatherSample,
    cloud_fraction: f64,
    apparent_zenith_deg: f64,
    earth_sun_distance_au: f64,
    elevation_m: f64,
    linke_turbidity: f64,
) -> (Irradiance, IrrPath) {
    let z = apparent_zenith_deg;
    let cos_z = z.to_radians().cos();
    let sun_up = z < 90.0;
    let cos_up = cos_z.max(0.0);
    let e0 = extraterrestrial_normal_w_m2(earth_sun_distance_au);
    let (mut irr, path) = match (w.ghi_w_m2, w.dni_w_m2, w.dhi_w_m2) {
        (Some(g), Some(b), Some(d)) => (
            Irradiance {
                ghi_w_m2: g,
                dni_w_m2: b,
                dhi_w_m2: d,
            },
            IrrPath::Measured,
        ),
        (Some(g), None, Some(d)) => {
            let dni = if z <= MAX_ZENITH_FOR_DNI_DEG {
                ((g - d) / cos_z).clamp(0.0, e0)
            } else {
                0.0
            };
            let dhi = if dni > 0.0 { d } else { g };
            (
                Irradiance {
                    ghi_w_m2: g,
                    dni_w_m2: dni,
                    dhi_w_m2: dhi,
                },
                IrrPath::DniFromGhiDhi,
            )
        }
        (Some(g), Some(b), None) => (
            Irradiance {
                ghi_w_m2: g,
                dni_w_m2: b,
                dhi_w_m2: (g - b * cos_up).max(0.0),
            },
            IrrPath::DhiFromGhiDni,
        ),
        (None, Some(b), Some(d)) => (
            Irradiance {
                ghi_w_m2: d + b * cos_up,
                dni_w_m2: b,
                dhi_w_m2: d,
            },
            IrrPath::GhiFromDniDhi,
        ),
        (Some(g), None, None) => (erbs_split(g, z, e0).0, IrrPath::Erbs),
        _ => {
            let am_abs = kasten_young_airmass(z).map(|m| m * w.pressure_pa / 101_325.0);
            let cs = match am_abs {
                Some(am) => ineichen_perez(z, am, linke_turbidity, elevation_m, e0),
                None => ineichen_perez(90.0, f64::NAN, linke_turbidity, elevation_m, e0),
            };
            let ghi = kasten_czeplak_ghi_w_m2(cs.ghi_w_m2, cloud_fraction);
            (erbs_split(ghi, z, e0).0, IrrPath::ClearSky)
        }
    };
    if !sun_up {
        irr.dni_w_m2 = 0.0;
    }
    (irr, path)
}

/// The forcing at `n_steps + 1` instants t_k = start + k·step_s, k = 0..=n_steps
/// (both ends of every step), with the default [`ForcingOptions`]. See the
/// module docs for the estimators; the weather must cover the whole window
/// (else [`WeatherError::NotCovered`] lists the missing hours).
pub fn build_forcing(
    history: &WeatherHistory,
    site: &Site,
    start: DateTime<Utc>,
    step_s: f64,
    n_steps: usize,
) -> Result<(Vec<Forcing>, EstimatorReport), WeatherError> {
    build_forcing_with(
        history,
        site,
        start,
        step_s,
        n_steps,
        &ForcingOptions::default(),
    )
}

/// [`build_forcing`] with explicit options.
pub fn build_forcing_with(
    history: &WeatherHistory,
    site: &Site,
    start: DateTime<Utc>,
    step_s: f64,
    n_steps: usize,
    opts: &ForcingOptions,
) -> Result<(Vec<Forcing>, EstimatorReport), WeatherError> {
    validate_site(site.latitude_deg, site.longitude_deg, site.elevation_m)
        .map_err(WeatherError::Invalid)?;
    if !(step_s > 0.0 && step_s.is_finite()) {
        return Err(WeatherError::Invalid(format!(
            "forcing step {step_s} s: expected a positive number of seconds"
        )));
    }
    if !(opts.linke_turbidity >= 1.0 && opts.linke_turbidity <= 10.0) {
        return Err(WeatherError::Invalid(format!(
            "Linke turbidity {}: expected 1 to 10",
            opts.linke_turbidity
        )));
    }
    let at = |k: usize| start + Duration::nanoseconds((k as f64 * step_s * 1e9).round() as i64);
    let end = at(n_steps);
    history.check_covers_with(start, end, opts.max_gap_s)?;
    let mut report = EstimatorReport {
        weather_source: history.source.clone(),
        n_samples: n_steps + 1,
        linke_turbidity: opts.linke_turbidity,
        ..EstimatorReport::default()
    };
    let steps: Vec<_> = (0..=n_steps)
        .map(|k| {
            let t = at(k);
            let w = history.at(t);
            let spa = SpaOptions {
                pressure_hpa: w.pressure_pa / 100.0,
                temp_c: w.air_temp_k - ZERO_C_K,
                ..SpaOptions::default()
            };
            let sun = solar_position_with(
                t,
                site.latitude_deg,
                site.longitude_deg,
                site.elevation_m,
                &spa,
            );
            (t, w, sun)
        })
        .collect();
    let cloud = step_cloud(history, &steps, site, opts, &mut report)?;
    let mut out = Vec::with_capacity(n_steps + 1);
    for (k, ((t, w, sun), cloud)) in steps.into_iter().zip(cloud).enumerate() {
        let (irr, path) = step_irradiance(
            &w,
            cloud,
            sun.zenith_deg,
            sun.earth_sun_distance_au,
            site.elevation_m,
            opts.linke_turbidity,
        );
        match path {
            IrrPath::Measured => report.irradiance_measured += 1,
            IrrPath::DniFromGhiDhi => report.dni_from_ghi_dhi += 1,
            IrrPath::DhiFromGhiDni => report.dhi_from_ghi_dni += 1,
            IrrPath::GhiFromDniDhi => report.ghi_from_dni_dhi += 1,
            IrrPath::Erbs => report.erbs_from_measured_ghi += 1,
            IrrPath::ClearSky => report.clear_sky_cloud += 1,
        }
        let sky_temp_k = match w.sky_temp_k {
            Some(s) => {
                report.sky_temp_measured += 1;
                s
            }
            None => {
                report.sky_temp_estimated += 1;
                estimate_sky_temp_k(
                    w.air_temp_k,
                    w.dew_point_k,
                    cloud,
                    local_mean_solar_hour(t, site.longitude_deg),
                    w.pressure_pa,
                )
            }
        };
        out.push(Forcing {
            t_s: k as f64 * step_s,
            air_temp_k: w.air_temp_k,
            sky_temp_k,
            wind_speed_m_s: w.wind_speed_m_s,
            dni_w_m2: irr.dni_w_m2,
            dhi_w_m2: irr.dhi_w_m2,
            ghi_w_m2: irr.ghi_w_m2,
            sun_dir_enu: sun.sun_dir_enu,
            dew_point_k: w.dew_point_k.min(w.air_temp_k),
            pressure_pa: w.pressure_pa,
            precip_mm_h: w.precip_mm_h,
            ground_temp_k: None,
        });
    }
    Ok((out, report))
}

/// The cloud cover of every step: the record's where it has one; else
/// derived from the clear-sky index of the measured GHI (or DHI + DNI·cos z)
/// with the sun at least [`MIN_ELEVATION_FOR_CLOUD_DEG`] up
/// ([`cloud_from_clear_sky_index`], Ineichen–Perez clear sky as in the
/// clear-sky path); at lower suns, interpolated linearly in time between
/// the nearest derived values (held before the first and after the last).
fn step_cloud(
    history: &WeatherHistory,
    steps: &[(DateTime<Utc>, WeatherSample, crate::sun::SolarPosition)],
    site: &Site,
    opts: &ForcingOptions,
    report: &mut EstimatorReport,
) -> Result<Vec<f64>, WeatherError> {
    if steps.iter().all(|(_, w, _)| w.cloud_fraction.is_some()) {
        return Ok(steps
            .iter()
            .map(|(_, w, _)| w.cloud_fraction.unwrap())
            .collect());
    }
    let derived: Vec<Option<f64>> = steps
        .iter()
        .map(|(_, w, sun)| {
            let z = sun.zenith_deg;
            let cos_z = z.to_radians().cos();
            let ghi = w
                .ghi_w_m2
                .or_else(|| Some(w.dhi_w_m2? + w.dni_w_m2? * cos_z.max(0.0)))?;
            if 90.0 - z < MIN_ELEVATION_FOR_CLOUD_DEG {
                return None;
            }
            let am = kasten_young_airmass(z)? * w.pressure_pa / 101_325.0;
            let e0 = extraterrestrial_normal_w_m2(sun.earth_sun_distance_au);
            let cs = ineichen_perez(z, am, opts.linke_turbidity, site.elevation_m, e0);
            Some(cloud_from_clear_sky_index(ghi / cs.ghi_w_m2))
        })
        .collect();
    let known: Vec<usize> = (0..steps.len()).filter(|&k| derived[k].is_some()).collect();
    let mut out = Vec::with_capacity(steps.len());
    for (k, (t, w, _)) in steps.iter().enumerate() {
        if let Some(c) = w.cloud_fraction {
            out.push(c);
            continue;
        }
        report.cloud_derived += 1;
        let i = known.partition_point(|&j| j < k);
        let c = match (i.checked_sub(1).map(|i| known[i]), known.get(i)) {
            (_, Some(&b)) if b == k => derived[k].unwrap(),
            (Some(a), Some(&b)) => {
                let w = (k - a) as f64 / (b - a) as f64;
                derived[a].unwrap() + (derived[b].unwrap() - derived[a].unwrap()) * w
            }
            (Some(a), None) => derived[a].unwrap(),
            (None, Some(&b)) => derived[b].unwrap(),
            (None, None) => {
                return Err(WeatherError::Invalid(format!(
                    "weather '{}' has no cloud cover at {}, and no measured GHI with the sun {} deg \
                     or more above the horizon between {} and {} to derive it from: add total \
                     cloud cover to the file",
                    history.source,
                    t.to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
                    MIN_ELEVATION_FOR_CLOUD_DEG,
                    steps[0]
                        .0
                        .to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
                    steps[steps.len() - 1]
                        .0
                        .to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
                )));
            }
        };
        out.push(c);
    }
    Ok(out)
}

/// σT⁴ of a sky temperature, W/m² (downwelling longwave), for reports.
pub fn sky_longwave_w_m2(sky_temp_k: f64) -> f64 {
    STEFAN_BOLTZMANN_W_M2K4 * sky_temp_k.powi(4)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weather::{ConstantWeather, ReadOptions, constant_weather, parse_plain_csv};

    fn utc(s: &str) -> DateTime<Utc> {
        DateTime::parse_from_rfc3339(s).unwrap().with_timezone(&Utc)
    }

    /// Berdahl–Martin + Crawford–Duchon against values computed by hand from
    /// the published formulas (tolerance 1e-9):
    /// T_dp 10 °C, 06 h, 1000 hPa: ε₀ = 0.711 + 0.056 + 0.0073 = 0.7743,
    /// T_sky(20 °C air) = 293.15·0.7743^¼ = 274.99020 K; with C = 0.5:
    /// ε = 0.5 + 0.5·0.7743 = 0.88715, T_sky = 284.50451 K;
    /// T_dp 20 °C, 00 h, 1013.25 hPa: ε₀ = 0.711 + 0.112 + 0.0292 + 0.013 +
    /// 0.00159 = 0.86679, T_sky(25 °C) = 287.68240 K; overcast: T_sky = T_air.
    #[test]
    fn sky_temperature_vs_hand_computed() {
        let e0 = berdahl_martin_clear_sky_emissivity(10.0, 6.0, 1000.0);
        assert!((e0 - 0.7743).abs() < 1e-9);
        assert!(
            (estimate_sky_temp_k(293.15, 283.15, 0.0, 6.0, 100_000.0) - 274.9901977574314).abs()
                < 1e-9
        );
        assert!(
            (estimate_sky_temp_k(293.15, 283.15, 0.5, 6.0, 100_000.0) - 284.5045148917038).abs()
                < 1e-9
        );
        assert!((berdahl_martin_clear_sky_emissivity(20.0, 0.0, 1013.25) - 0.86679).abs() < 1e-9);
        assert!(
            (estimate_sky_temp_k(298.15, 293.15, 0.0, 0.0, 101_325.0) - 287.6823957421511).abs()
                < 1e-9
        );
        assert!((estimate_sky_temp_k(273.15, 268.15, 1.0, 14.0, 95_000.0) - 273.15).abs() < 1e-12);
        // Downwelling longwave of that clear sky: ε·σ·T⁴ = 0.7743·σ·293.15⁴ ≈ 325.8 W/m².
        let lw = sky_longwave_w_m2(274.9901977574314);
        assert!((lw - 0.7743 * STEFAN_BOLTZMANN_W_M2K4 * 293.15f64.powi(4)).abs() < 1e-9);
    }

    /// The clear-sky-index cloud estimate inverts the published Kasten &
    /// Czeplak (1980) relation k_c = 1 − 0.75·C^3.4 (to 1e-12), and clips
    /// outside it: k_c ≥ 1 → clear, k_c ≤ 0.25 → overcast.
    #[test]
    fn cloud_from_clear_sky_index_inverts_kasten_czeplak() {
        for i in 0..=20 {
            let c = i as f64 / 20.0;
            let kc = kasten_czeplak_ghi_w_m2(1.0, c);
            assert!((kc - (1.0 - 0.75 * c.powf(3.4))).abs() < 1e-15);
            assert!((cloud_from_clear_sky_index(kc) - c).abs() < 1e-12, "{c}");
        }
        assert_eq!(cloud_from_clear_sky_index(1.2), 0.0);
        assert_eq!(cloud_from_clear_sky_index(0.1), 1.0);
        // Half cover: k_c = 1 − 0.75·0.5^3.4 = 0.9289508.
        assert!((cloud_from_clear_sky_index(0.9289508) - 0.5).abs() < 1e-6);
    }

    /// A record without cloud cover but with measured GHI: the forcing
    /// derives the cloud from the clear-sky index. GHI made by the
    /// clear-sky path from cloud 0.6 gives back cloud 0.6 at every step
    /// (daytime derived, night interpolated), hence the same sky
    /// temperature as the record with cloud 0.6 (to 1e-9 K).
    #[test]
    fn cloud_derived_from_measured_ghi() {
        let site = Site {
            latitude_deg: 43.1,
            longitude_deg: -77.6,
            elevation_m: 150.0,
        };
        let start = utc("1992-07-15T00:00:00Z");
        let p = ConstantWeather {
            cloud_fraction: 0.6,
            ..ConstantWeather::default()
        };
        let h =
            constant_weather(&p, 43.1, -77.6, start, start + Duration::hours(48), 900.0).unwrap();
        let n = h.times.len() - 1;
        let (f, rep) = build_forcing(&h, &site, start, 900.0, n).unwrap();
        assert_eq!((rep.clear_sky_cloud, rep.cloud_derived), (n + 1, 0));
        let mut g = h.clone();
        for (s, x) in g.samples.iter_mut().zip(&f) {
            s.cloud_fraction = None;
            s.ghi_w_m2 = Some(x.ghi_w_m2);
        }
        let (f2, rep2) = build_forcing(&g, &site, start, 900.0, n).unwrap();
        assert_eq!(
            (rep2.erbs_from_measured_ghi, rep2.cloud_derived),
            (n + 1, n + 1)
        );
        assert!(rep2.to_string().contains("clear-sky index"));
        for (a, b) in f.iter().zip(&f2) {
            assert!(
                (a.sky_temp_k - b.sky_temp_k).abs() < 1e-9,
                "{} {}",
                a.sky_temp_k,
                b.sky_temp_k
            );
        }
        // No daylight GHI at all (a night-only window): a clear error.
        let night = start + Duration::hours(4);
        let e = build_forcing(&g, &site, night, 900.0, 4)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no cloud cover") && e.contains("add total cloud cover"),
            "{e}"
        );
    }

    /// Erbs diffuse fraction at the published branch points (eq. 1):
    /// k_t = 0.22 → 1 − 0.0198 = 0.9802; k_t = 0.8 → 0.9511 − 0.12832 +
    /// 2.80832 − 8.518656 + 5.0528256 = 0.1652696; k_t > 0.8 → 0.165.
    #[test]
    fn erbs_branch_values() {
        assert!((erbs_diffuse_fraction(0.22) - 0.9802).abs() < 1e-12);
        assert!((erbs_diffuse_fraction(0.8) - 0.1652696).abs() < 1e-12);
        assert_eq!(erbs_diffuse_fraction(0.9), 0.165);
        // Continuity at the branch points within 0.002 (the published fit).
        assert!((erbs_diffuse_fraction(0.2200001) - 0.9802).abs() < 2e-3);
    }

    #[test]
    fn clear_sky_forcing_from_constant_weather() {
        let site = Site {
            latitude_deg: 43.1,
            longitude_deg: -77.6,
            elevation_m: 150.0,
        };
        let start = utc("1992-07-15T00:00:00Z");
        let p = ConstantWeather::default();
        let h = constant_weather(
            &p,
            site.latitude_deg,
            site.longitude_deg,
            start,
            start + Duration::hours(24),
            900.0,
        )
        .unwrap();
        let (f, rep) = build_forcing(&h, &site, start, 1800.0, 48).unwrap();
        assert_eq!(f.len(), 49);
        assert_eq!(rep.clear_sky_cloud, 49);
        assert_eq!(rep.sky_temp_estimated, 49);
        assert!(
            rep.to_string().contains("Ineichen-Perez")
                && rep.to_string().contains("Berdahl-Martin")
        );
        for (k, x) in f.iter().enumerate() {
            assert_eq!(x.t_s, k as f64 * 1800.0);
            let sun = crate::sun::solar_position(
                start + Duration::seconds(k as i64 * 1800),
                43.1,
                -77.6,
                150.0,
            );
            assert!((x.sun_dir_enu[2] - sun.sun_dir_enu[2]).abs() < 1e-3);
            if x.sun_dir_enu[2] <= 0.0 {
                assert_eq!(x.dni_w_m2, 0.0, "sun down at step {k}");
                assert_eq!(x.ghi_w_m2, 0.0);
            }
            // Closure GHI = DHI + DNI cos z.
            assert!(
                (x.ghi_w_m2 - x.dhi_w_m2 - x.dni_w_m2 * x.sun_dir_enu[2].max(0.0)).abs() < 1e-6
            );
            assert!(x.sky_temp_k < x.air_temp_k && x.sky_temp_k > x.air_temp_k - 40.0);
        }
        // Clear July noon at 43° N: GHI ≈ 900-1000 W/m².
        let noon = f.iter().map(|x| x.ghi_w_m2).fold(0.0, f64::max);
        assert!((850.0..1050.0).contains(&noon), "{noon}");
        // Overcast: the Kasten–Czeplak factor 0.25 on GHI.
        let h2 = constant_weather(
            &ConstantWeather {
                cloud_fraction: 1.0,
                ..p
            },
            site.latitude_deg,
            site.longitude_deg,
            start,
            start + Duration::hours(24),
            900.0,
        )
        .unwrap();
        let (f2, _) = build_forcing(&h2, &site, start, 1800.0, 48).unwrap();
        for (a, b) in f.iter().zip(&f2) {
            assert!((b.ghi_w_m2 - 0.25 * a.ghi_w_m2).abs() < 1e-9);
        }
    }

    #[test]
    fn measured_ghi_dhi_gives_dni_with_horizon_guard() {
        let csv = "time,air_temp_c,dew_point_c,wind_m_s,cloud_fraction,ghi_w_m2,dhi_w_m2\n\
                   2024-06-21T00:00:00Z,20,10,2,0.2,0,0\n\
                   2024-06-21T12:00:00Z,30,10,2,0.2,800,150\n\
                   2024-06-22T00:00:00Z,20,10,2,0.2,0,0\n";
        let ropts = ReadOptions {
            max_gap_s: 12.0 * 3600.0,
            ..ReadOptions::default()
        };
        let h = parse_plain_csv(csv, "m.csv", &ropts).unwrap().history;
        let site = Site {
            latitude_deg: 0.0,
            longitude_deg: 0.0,
            elevation_m: 0.0,
        };
        // Max gap 12 h allowed for this sparse test record.
        let opts = ForcingOptions {
            max_gap_s: 12.0 * 3600.0,
            ..ForcingOptions::default()
        };
        let start = utc("2024-06-21T00:00:00Z");
        let (f, rep) = build_forcing_with(&h, &site, start, 600.0, 144, &opts).unwrap();
        assert_eq!(rep.dni_from_ghi_dhi, 145);
        let noon = &f[72];
        let sun = crate::sun::solar_position_with(
            start + Duration::hours(12),
            0.0,
            0.0,
            0.0,
            &SpaOptions {
                pressure_hpa: 1013.25,
                temp_c: 30.0,
                ..SpaOptions::default()
            },
        );
        let want = (800.0 - 150.0) / sun.zenith_deg.to_radians().cos();
        assert!(
            (noon.dni_w_m2 - want).abs() < 1e-9,
            "{} vs {want}",
            noon.dni_w_m2
        );
        for x in &f {
            let z = x.sun_dir_enu[2].clamp(-1.0, 1.0).acos().to_degrees();
            if z > MAX_ZENITH_FOR_DNI_DEG {
                assert_eq!(x.dni_w_m2, 0.0);
                assert_eq!(x.dhi_w_m2, x.ghi_w_m2);
            }
            assert!(x.dni_w_m2.is_finite() && x.dni_w_m2 >= 0.0);
        }
        // The default 3 h max gap refuses this record and says where.
        let e = build_forcing(&h, &site, start, 600.0, 144)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("12 h from 2024-06-21T00:00Z to 2024-06-21T12:00Z"),
            "{e}"
        );
    }

    #[test]
    fn window_not_covered_names_hours() {
        let site = Site {
            latitude_deg: 45.0,
            longitude_deg: 7.0,
            elevation_m: 0.0,
        };
        let s = utc("2024-03-01T00:00:00Z");
        let h = constant_weather(
            &ConstantWeather::default(),
            45.0,
            7.0,
            s,
            s + Duration::hours(6),
            900.0,
        )
        .unwrap();
        let e = build_forcing(&h, &site, s - Duration::hours(2), 900.0, 40)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("2 h from 2024-02-29T22:00Z to 2024-03-01T00:00Z"),
            "{e}"
        );
        assert!(
            e.contains("2 h from 2024-03-01T06:00Z to 2024-03-01T08:00Z"),
            "{e}"
        );
        let bad = Site {
            latitude_deg: 95.0,
            ..site
        };
        assert!(
            build_forcing(&h, &bad, s, 900.0, 4)
                .unwrap_err()
                .to_string()
                .contains("latitude 95")
        );
    }
}
