//! The six LOWTRAN-7 standard atmospheres and the rule that picks one from
//! the weather (`[atmosphere] model = "auto"`).
//!
//! Surface values are those of the AFGL profiles the tables were made with
//! (Anderson et al. 1986, *AFGL Atmospheric Constituent Profiles (0-120 km)*,
//! AFGL-TR-86-0110, first level of each profile; the same profiles as
//! McClatchey et al. 1972 and LOWTRAN 7's MODEL = 1..6). Column water vapour
//! as quoted for these models by 6S/MODTRAN users (e.g. 4.12 g/cm² tropical,
//! 2.93 mid-latitude summer). `tests` checks the surface temperatures against
//! the shipped tables themselves: near the horizon, in the opaque centre of
//! the 15 µm CO₂ band, the sky's brightness temperature is that of the air
//! within a few hundred metres of the ground.
//!
//! # The rule
//! The weather's mean air temperature T̄ and mean vapour pressure ē over the
//! 24 h before the image time are compared with each model's surface values:
//!
//! d² = ((T̄ − T₀)/8 K)² + (ln(ē/e₀)/ln 1.5)² + p_lat
//!
//! and the model with the smallest d² wins. Humidity weighs most (a factor
//! 1.5 in vapour pressure counts as much as 8 K) because the thermal
//! infrared's path transmission and sky emission follow the water vapour
//! column, while the remaining temperature difference is corrected afterwards
//! ([`super::adjust`]). The season enters through T̄ and ē; latitude as a
//! soft prior: p_lat = 1 when the site's |latitude| is outside the model's
//! band (tropical 0-30°, mid-latitude and US 1976 25-60°, sub-arctic 50-90°),
//! since the models' upper-air profiles (tropopause height, ozone) belong to
//! their latitude.

use crate::units::ZERO_C_K;
use serde::Serialize;

/// Surface values of one standard atmosphere.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StandardAtmosphere {
    /// Shipped table name (`data/atmos/<name>.atm.gz`).
    pub name: &'static str,
    /// The scene's `[atmosphere] model` value.
    pub model: &'static str,
    /// Air temperature at the surface, K.
    pub surface_temp_k: f64,
    /// Water vapour at the surface, ppmv.
    pub surface_h2o_ppmv: f64,
    /// Surface pressure, Pa.
    pub surface_pressure_pa: f64,
    /// Precipitable water of the column, g/cm².
    pub column_h2o_g_cm2: f64,
    /// |latitude| band the model stands for, degrees.
    pub lat_band_deg: (f64, f64),
}

impl StandardAtmosphere {
    /// Surface vapour pressure e₀ = x_H₂O · p, Pa.
    pub fn surface_vapour_pressure_pa(&self) -> f64 {
        self.surface_h2o_ppmv * 1e-6 * self.surface_pressure_pa
    }
}

/// The six standard atmospheres (AFGL-TR-86-0110, level 0 km).
pub const STANDARD_ATMOSPHERES: [StandardAtmosphere; 6] = [
    StandardAtmosphere {
        name: "tropical",
        model: "tropical",
        surface_temp_k: 299.7,
        surface_h2o_ppmv: 25_930.0,
        surface_pressure_pa: 101_300.0,
        column_h2o_g_cm2: 4.12,
        lat_band_deg: (0.0, 30.0),
    },
    StandardAtmosphere {
        name: "mls",
        model: "mid-latitude-summer",
        surface_temp_k: 294.2,
        surface_h2o_ppmv: 18_760.0,
        surface_pressure_pa: 101_300.0,
        column_h2o_g_cm2: 2.93,
        lat_band_deg: (25.0, 60.0),
    },
    StandardAtmosphere {
        name: "mlw",
        model: "mid-latitude-winter",
        surface_temp_k: 272.2,
        surface_h2o_ppmv: 4_316.0,
        surface_pressure_pa: 101_800.0,
        column_h2o_g_cm2: 0.853,
        lat_band_deg: (25.0, 60.0),
    },
    StandardAtmosphere {
        name: "sas",
        model: "subarctic-summer",
        surface_temp_k: 287.2,
        surface_h2o_ppmv: 11_940.0,
        surface_pressure_pa: 101_000.0,
        column_h2o_g_cm2: 2.10,
        lat_band_deg: (50.0, 90.0),
    },
    StandardAtmosphere {
        name: "saw",
        model: "subarctic-winter",
        surface_temp_k: 257.2,
        surface_h2o_ppmv: 1_405.0,
        surface_pressure_pa: 101_300.0,
        column_h2o_g_cm2: 0.419,
        lat_band_deg: (50.0, 90.0),
    },
    StandardAtmosphere {
        name: "us1976",
        model: "us-standard-1976",
        surface_temp_k: 288.2,
        surface_h2o_ppmv: 7_745.0,
        surface_pressure_pa: 101_325.0,
        column_h2o_g_cm2: 1.42,
        lat_band_deg: (25.0, 60.0),
    },
];

/// The standard atmosphere of a shipped table name, if it is one.
pub fn standard(name: &str) -> Option<&'static StandardAtmosphere> {
    STANDARD_ATMOSPHERES.iter().find(|s| s.name == name)
}

/// Temperature scale of the rule, K.
pub const CHOICE_TEMP_SCALE_K: f64 = 8.0;
/// Vapour-pressure ratio of the rule that counts as much as the temperature scale.
pub const CHOICE_VAPOUR_RATIO: f64 = 1.5;
/// Penalty for a model outside its latitude band.
pub const CHOICE_LATITUDE_PENALTY: f64 = 1.0;

/// One candidate's score.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Candidate {
    /// The standard atmosphere's name.
    pub name: &'static str,
    /// d² of the rule (smaller fits better).
    pub distance2: f64,
}

/// The choice and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Choice {
    /// The standard atmosphere chosen.
    pub name: &'static str,
    /// Mean air temperature the rule used, K.
    pub mean_air_temp_k: f64,
    /// Mean vapour pressure the rule used, Pa.
    pub mean_vapour_pressure_pa: f64,
    /// The site's latitude, degrees.
    pub latitude_deg: f64,
    /// Every model, best first.
    pub candidates: Vec<Candidate>,
}

impl Choice {
    /// One line for logs and `irsig probe`.
    pub fn reason(&self) -> String {
        let s = standard(self.name).expect("a standard atmosphere");
        let next = self
            .candidates
            .get(1)
            .map(|c| format!("; next {} (d² {:.2})", c.name, c.distance2))
            .unwrap_or_default();
        format!(
            "auto: 24-h mean air {:.1} °C, vapour pressure {:.0} Pa, latitude {:.1}° → {} \
             (surface {:.1} °C, {:.0} Pa; d² {:.2}{next})",
            self.mean_air_temp_k - ZERO_C_K,
            self.mean_vapour_pressure_pa,
            self.latitude_deg,
            s.name,
            s.surface_temp_k - ZERO_C_K,
            s.surface_vapour_pressure_pa(),
            self.candidates[0].distance2,
        )
    }
}

/// Picks the standard atmosphere by the module's rule from the mean air
/// temperature (K), the mean vapour pressure (Pa) and the site latitude.
pub fn choose(mean_air_temp_k: f64, mean_vapour_pressure_pa: f64, latitude_deg: f64) -> Choice {
    let e = mean_vapour_pressure_pa.max(1.0);
    let lat = latitude_deg.abs();
    let mut candidates: Vec<Candidate> = STANDARD_ATMOSPHERES
        .iter()
        .map(|s| {
            let dt = (mean_air_temp_k - s.surface_temp_k) / CHOICE_TEMP_SCALE_K;
            let de = (e / s.surface_vapour_pressure_pa()).ln() / CHOICE_VAPOUR_RATIO.ln();
            let p = if lat < s.lat_band_deg.0 || lat > s.lat_band_deg.1 {
                CHOICE_LATITUDE_PENALTY
            } else {
                0.0
            };
            Candidate {
                name: s.name,
                distance2: dt * dt + de * de + p,
            }
        })
        .collect();
    // Stable sort: ties keep the table order (deterministic).
    candidates.sort_by(|a, b| a.distance2.total_cmp(&b.distance2));
    Choice {
        name: candidates[0].name,
        mean_air_temp_k,
        mean_vapour_pressure_pa,
        latitude_deg,
        candidates,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::therm::aero::saturation_vapour_pressure_pa;

    fn vp(dew_c: f64) -> f64 {
        saturation_vapour_pressure_pa(dew_c + 273.15)
    }

    /// Each model's own surface conditions at a latitude inside its band
    /// choose that model (the rule is consistent with its own data).
    #[test]
    fn each_model_chooses_itself() {
        for s in &STANDARD_ATMOSPHERES {
            let lat = 0.5 * (s.lat_band_deg.0 + s.lat_band_deg.1);
            let c = choose(s.surface_temp_k, s.surface_vapour_pressure_pa(), lat);
            assert_eq!(c.name, s.name, "{c:?}");
        }
    }

    /// Climatology the models stand for (approximate monthly means of air
    /// temperature and dew point): Rochester NY in July (21.5 °C, 15 °C)
    /// → mid-latitude summer; in January (−4 °C, dew point −9 °C) →
    /// mid-latitude winter; Fairbanks in January (−22 °C, dew point −26 °C)
    /// → sub-arctic winter; Fairbanks in July (17 °C, dew point 9 °C) →
    /// sub-arctic summer; Miami in August (29 °C, dew point 23.5 °C) →
    /// tropical; San Francisco in March (13 °C, dew point 7 °C) → US 1976.
    #[test]
    fn climatology_picks_the_expected_model() {
        let cases = [
            ("Rochester July", 21.5, 15.0, 43.1, "mls"),
            ("Rochester January", -4.0, -9.0, 43.1, "mlw"),
            ("Fairbanks January", -22.0, -26.0, 64.8, "saw"),
            ("Fairbanks July", 17.0, 9.0, 64.8, "sas"),
            ("Miami August", 29.0, 23.5, 25.8, "tropical"),
            ("San Francisco March", 13.0, 7.0, 37.6, "us1976"),
        ];
        for (what, t_c, td_c, lat, expect) in cases {
            let c = choose(t_c + 273.15, vp(td_c), lat);
            assert_eq!(c.name, expect, "{what}: {}", c.reason());
        }
    }

    /// Surface vapour pressures from the AFGL mixing ratios agree with the
    /// models' column water vapour ordering (an independent quantity).
    #[test]
    fn vapour_pressure_follows_column_water() {
        let mut by_e: Vec<_> = STANDARD_ATMOSPHERES.iter().collect();
        by_e.sort_by(|a, b| {
            a.surface_vapour_pressure_pa()
                .total_cmp(&b.surface_vapour_pressure_pa())
        });
        let mut by_w: Vec<_> = STANDARD_ATMOSPHERES.iter().collect();
        by_w.sort_by(|a, b| a.column_h2o_g_cm2.total_cmp(&b.column_h2o_g_cm2));
        let names = |v: &[&StandardAtmosphere]| v.iter().map(|s| s.name).collect::<Vec<_>>();
        assert_eq!(names(&by_e), names(&by_w));
    }

    /// The surface temperatures against the shipped LOWTRAN tables: the
    /// sky's brightness temperature at 89° zenith in the opaque 15 µm CO₂
    /// band centre (660 cm⁻¹) is that of the air within a few hundred
    /// metres of the ground, i.e. T₀ minus a lapse of 6.5 K/km over that
    /// depth (plus for sub-arctic winter's surface inversion): within 3.5 K.
    #[test]
    fn surface_temperatures_match_the_tables() {
        use crate::radiometry::brightness_temp_k;
        for s in &STANDARD_ATMOSPHERES {
            let sa = crate::atmos::Atmosphere::builtin(s.name).unwrap().full();
            let i = sa
                .wavenumber_cm1
                .iter()
                .position(|&v| (v - 660.0).abs() < 1e-6)
                .unwrap();
            let mut l = vec![0.0; sa.len()];
            sa.l_de(89.0, &mut l).unwrap();
            let tb = brightness_temp_k(1e4 / 660.0, l[i]).unwrap();
            assert!(
                (tb - s.surface_temp_k).abs() < 3.5,
                "{}: {tb} vs {}",
                s.name,
                s.surface_temp_k
            );
        }
    }
}
