//! Which atmosphere table a render uses and why, and the table adjusted to
//! the weather of each frame (`atmos::standard`, `atmos::adjust`).

use std::sync::Arc;

use anyhow::{Context, bail};
use chrono::{DateTime, Utc};
use serde::Serialize;

use crate::atmos::PathSpectra;
use crate::atmos::adjust::{SkyFit, WeatherAdjustment, fit_sky};
use crate::atmos::standard::{self, Choice, StandardAtmosphere};
use crate::atmos::{Atmosphere, SpectralAtmosphere};
use crate::radiometry::Band;
use crate::scene::LoadedScene;
use crate::scene::spec::AtmosphereModel;
use crate::therm::conditions::window_means;
use crate::therm::forcing::Forcing;
use crate::units::ZERO_C_K;
use crate::weather::WeatherHistory;

/// Hours of weather before the scene's time that `model = "auto"` averages.
pub const AUTO_WINDOW_H: i64 = 24;

/// The table a scene uses.
#[derive(Clone, Debug, Serialize)]
pub struct AtmosphereSource {
    /// Shipped table name, or the table file's path.
    pub name: String,
    /// Why this table (the scene's choice, or the auto rule's reasoning).
    pub why: String,
    /// The standard profile's surface values (None for a table file).
    pub profile: Option<StandardAtmosphere>,
    /// The auto rule's scores (for `model = "auto"`).
    pub choice: Option<Choice>,
}

/// Name of the built-in table of a standard atmosphere.
fn builtin_name(m: &AtmosphereModel) -> Option<&'static str> {
    Some(match m {
        AtmosphereModel::Tropical => "tropical",
        AtmosphereModel::MidLatitudeSummer => "mls",
        AtmosphereModel::MidLatitudeWinter => "mlw",
        AtmosphereModel::SubarcticSummer => "sas",
        AtmosphereModel::SubarcticWinter => "saw",
        AtmosphereModel::UsStandard1976 => "us1976",
        AtmosphereModel::TableFile(_) | AtmosphereModel::Auto => return None,
    })
}

/// Which table the scene uses: its `model`, or for `"auto"` the standard
/// atmosphere the weather of the [`AUTO_WINDOW_H`] hours before the
/// scene's time fits best.
pub fn atmosphere_source(
    scene: &LoadedScene,
    weather: impl FnOnce(DateTime<Utc>, DateTime<Utc>) -> anyhow::Result<WeatherHistory>,
) -> anyhow::Result<AtmosphereSource> {
    let sc = &scene.scene;
    Ok(match &sc.atmosphere.model {
        AtmosphereModel::TableFile(p) => AtmosphereSource {
            name: scene.resolve(p).display().to_string(),
            why: "table_file in the scene; used as computed (no surface values to adjust it by)"
                .into(),
            profile: None,
            choice: None,
        },
        AtmosphereModel::Auto => {
            let site = sc.site.location;
            let t = sc.time.utc(&sc.site);
            let history = weather(
                t - chrono::Duration::hours(AUTO_WINDOW_H + 2),
                t + chrono::Duration::hours(1),
            )?;
            let [t_k, e_pa] = window_means(
                &history,
                &site,
                t - chrono::Duration::hours(AUTO_WINDOW_H),
                t,
                [|f| f.air_temp_k, |f| f.vapour_pressure_pa()],
            )
            .context("atmosphere model = \"auto\": the weather before the scene's time")?;
            let choice = standard::choose(t_k, e_pa, site.latitude_deg);
            AtmosphereSource {
                name: choice.name.to_string(),
                why: choice.reason(),
                profile: standard::standard(choice.name).copied(),
                choice: Some(choice),
            }
        }
        m => {
            let name = builtin_name(m).expect("standard models have names");
            let profile = standard::standard(name).copied();
            AtmosphereSource {
                name: name.into(),
                why: format!(
                    "model = \"{}\" in the scene",
                    profile.map(|p| p.model).unwrap_or(name)
                ),
                profile,
                choice: None,
            }
        }
    })
}

/// The source's table resampled over the band's bins, and (when the scene
/// follows the weather and the table is a standard profile) on its own full
/// grid for the per-frame sky fit.
pub fn load_atmosphere(
    scene: &LoadedScene,
    source: &AtmosphereSource,
    band: &Band,
) -> anyhow::Result<(SpectralAtmosphere, Option<Arc<SpectralAtmosphere>>)> {
    let spec = &scene.scene.atmosphere;
    let atm = match &spec.model {
        AtmosphereModel::TableFile(p) => Atmosphere::load(&scene.resolve(p))?,
        _ => {
            if (spec.visibility_km - 23.0).abs() > 1e-9 {
                bail!(
                    "{}: [atmosphere] visibility_km = {}: the shipped tables are for 23 km (rural aerosol); \
                     generate a table for another visibility with tools/lowtran and name it with table_file",
                    scene.path.display(),
                    spec.visibility_km
                );
            }
            Atmosphere::builtin(&source.name)?
        }
    };
    let full = (spec.follow_weather && source.profile.is_some()).then(|| Arc::new(atm.full()));
    let sa = atm
        .resample(&band.wavenumber_cm1)
        .context("atmosphere table over the sensor band")?;
    Ok((sa, full))
}

/// What one frame's atmosphere is and how it was made to fit the weather.
#[derive(Clone, Debug, Serialize)]
pub struct AtmosphereReport {
    /// Which table, and why.
    pub source: AtmosphereSource,
    /// The table was adjusted to this frame's weather.
    pub follow_weather: bool,
    /// Air temperature at the image time, K.
    pub air_temp_k: f64,
    /// Vapour pressure at the image time, Pa.
    pub vapour_pressure_pa: f64,
    /// The thermal model's sky temperature at the image time, K.
    pub thermal_sky_temp_k: f64,
    /// The adjustment and the sky irradiances before and after it (None:
    /// the table as computed).
    pub fit: Option<SkyFit>,
}

impl AtmosphereReport {
    /// Human-readable lines (probe, logs).
    pub fn lines(&self) -> Vec<String> {
        let mut v = vec![format!("table {} — {}", self.source.name, self.source.why)];
        match &self.fit {
            Some(f) => {
                let a = &f.adjustment;
                v.push(format!(
                    "followed the weather: ΔT {:+.2} K (air {:.2} °C), path optical depth × {:.3} \
                     (vapour pressure {:.0} Pa), sky optical depth × {:.3}{}",
                    a.delta_t_k,
                    self.air_temp_k - ZERO_C_K,
                    a.vapour_scale,
                    self.vapour_pressure_pa,
                    a.sky_scale,
                    if f.clamped { " (clamped)" } else { "" }
                ));
                v.push(format!(
                    "sky irradiance: thermal model {:.1} W/m² (T_sky {:.2} °C); table as computed {:.1}, \
                     temperature-shifted {:.1}, used {:.1} W/m²",
                    f.thermal_w_m2,
                    self.thermal_sky_temp_k - ZERO_C_K,
                    f.table_w_m2,
                    f.shifted_w_m2,
                    f.fitted_w_m2
                ));
            }
            None => v.push(format!(
                "table as computed ({}); thermal-model sky {:.2} °C",
                if self.follow_weather {
                    "no standard profile to adjust it by"
                } else {
                    "follow_weather = false"
                },
                self.thermal_sky_temp_k - ZERO_C_K
            )),
        }
        v
    }
}

/// The frame's atmosphere: `band_atm` adjusted to the forcing at the image
/// time (`now`) when `full` is given, with the report.
pub fn frame_atmosphere(
    source: &AtmosphereSource,
    band_atm: &SpectralAtmosphere,
    full: Option<&SpectralAtmosphere>,
    follow_weather: bool,
    now: &Forcing,
) -> anyhow::Result<(SpectralAtmosphere, AtmosphereReport)> {
    let e_now = now.vapour_pressure_pa();
    let fit = match (full, &source.profile) {
        (Some(full), Some(p)) if follow_weather => Some(
            fit_sky(
                full,
                now.air_temp_k - p.surface_temp_k,
                e_now / p.surface_vapour_pressure_pa(),
                now.air_temp_k,
                now.sky_temp_k,
            )
            .context("fitting the atmosphere's sky to the thermal model's")?,
        ),
        _ => None,
    };
    let adj = fit.map(|f| f.adjustment).unwrap_or(WeatherAdjustment::NONE);
    let sa = band_atm
        .adjusted(&adj)
        .context("adjusting the atmosphere to the weather")?;
    Ok((
        sa,
        AtmosphereReport {
            source: source.clone(),
            follow_weather,
            air_temp_k: now.air_temp_k,
            vapour_pressure_pa: e_now,
            thermal_sky_temp_k: now.sky_temp_k,
            fit,
        },
    ))
}

/// The lowest altitude of the atmosphere tables, km: a sensor lower is
/// scaled as a uniform layer ([`path_at`]).
const LOWEST_ALT_KM: f64 = 0.3;
/// The largest view zenith the path lookups use, degrees.
const MAX_VIEW_ZENITH_DEG: f64 = 85.0;

/// τ₂, L_UE, L_US of the path to a sensor `h_km` above the point, seen
/// at view zenith `vz_deg` there (the render's rules: the view zenith
/// clamped to the tables' last angle, a sensor below the tables' lowest
/// altitude scaled as a uniform layer; see [`super::pixel`]'s module docs). The render's
/// lookups and [`super::prepare::validate`] both go through it.
pub fn path_at(
    sa: &crate::atmos::SpectralAtmosphere,
    h: f64,
    vz: f64,
    sun_zenith_deg: f64,
    rel: f64,
) -> Result<PathSpectra, crate::atmos::AtmosError> {
    let vz = vz.min(MAX_VIEW_ZENITH_DEG);
    let p = if h >= LOWEST_ALT_KM {
        sa.path(h, vz, sun_zenith_deg.min(90.0), rel)?
    } else {
        let base = sa.path(LOWEST_ALT_KM, vz, sun_zenith_deg.min(90.0), rel)?;
        let f = h.max(0.0) / LOWEST_ALT_KM;
        let tau2: Vec<f64> = base.tau2.iter().map(|t| t.max(1e-300).powf(f)).collect();
        let l_ue = base
            .l_ue_w_m2_sr_um
            .iter()
            .zip(base.tau2.iter().zip(&tau2))
            .map(|(l, (t0, t))| {
                if *t0 < 1.0 {
                    l * (1.0 - t) / (1.0 - t0)
                } else {
                    0.0
                }
            })
            .collect();
        let l_us = base.l_us_w_m2_sr_um.iter().map(|l| l * f).collect();
        PathSpectra {
            tau2,
            l_ue_w_m2_sr_um: l_ue,
            l_us_w_m2_sr_um: l_us,
        }
    };
    Ok(p)
}
