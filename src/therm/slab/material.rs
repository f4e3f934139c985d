//! What a slab is made of: its material and what its back face sees.

use serde::{Deserialize, Serialize};

use crate::therm::surface::SurfaceKind;

use super::*;

/// What the back face (z = L) of the slab sees: the one description of the
/// back boundary, read from a material library as written there
/// (docs/scene-format.md, "Materials"): `back = "insulated"`,
/// `back = { air = { exposed_area = 1.0 } }`, `back = { deep_ground = {} }`
/// or `back = { deep_ground = { temp_c = 12.0 } }`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum BackBoundary {
    /// No heat flow through the back face (`back = "insulated"`).
    #[default]
    Insulated,
    /// Back face exchanges with ambient air (convection and longwave to
    /// surroundings at air temperature); `area_factor` (`exposed_area`, DIRSIG
    /// EXPOSED_AREA) is the exposed back area per unit front area (1.0 for a
    /// plate whose both faces are exposed; default 1).
    #[serde(rename = "air")]
    ExposedToAir {
        #[serde(rename = "exposed_area", default = "one")]
        area_factor: f64,
    },
    /// Back face held at a deep-ground temperature: `temp_k` (written in
    /// °C as `temp_c`, range [`crate::bounds::material::DEEP_GROUND_TEMP`],
    /// checked where it is read), or when absent the site's deep-ground
    /// temperature (a render) or the mean air temperature of the forcing.
    DeepGround {
        #[serde(
            rename = "temp_c",
            default,
            skip_serializing_if = "Option::is_none",
            with = "celsius"
        )]
        temp_k: Option<f64>,
    },
}

fn one() -> f64 {
    1.0
}

/// `temp_c` as written ⇄ `temp_k` as modelled (T/K = t/°C + 273.15); the
/// written value is range-checked here, so the message quotes it as written.
mod celsius {
    use serde::{Deserialize, Deserializer, Serializer};

    use crate::bounds::material::DEEP_GROUND_TEMP;
    use crate::units::ZERO_C_K as ZERO_CELSIUS_K;

    pub fn serialize<S: Serializer>(temp_k: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match temp_k {
            Some(k) => s.serialize_some(&(k - ZERO_CELSIUS_K)),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        match Option::<f64>::deserialize(d)? {
            Some(c) => DEEP_GROUND_TEMP
                .check(c)
                .map(|c| Some(c + ZERO_CELSIUS_K))
                .map_err(serde::de::Error::custom),
            None => Ok(None),
        }
    }
}

/// One material's slab: thermal and surface properties (DIRSIG's
/// MASS_DENSITY, SPECIFIC_HEAT, THERMAL_CONDUCTIVITY, thickness,
/// VISIBLE_EMISSIVITY → `solar_absorptivity`, THERMAL_EMISSIVITY,
/// EXPOSED_AREA → [`BackBoundary::ExposedToAir`], internal power).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlabMaterial {
    pub density_kg_m3: f64,
    pub specific_heat_j_kgk: f64,
    pub conductivity_w_mk: f64,
    pub thickness_m: f64,
    pub solar_absorptivity: f64,
    pub thermal_emissivity: f64,
    pub back: BackBoundary,
    /// Internal heat delivered at the surface node, W/m² (docs/models.md, "Thermal model").
    #[serde(default)]
    pub internal_power_w_m2: f64,
    /// Solar albedo of the ground seen by a tilted facet (default 0.2).
    #[serde(default)]
    pub ground_albedo: Option<f64>,
    /// What the surface is: solid (with a water store), vegetation, water.
    #[serde(default)]
    pub surface: SurfaceKind,
}

impl SlabMaterial {
    /// Thermal diffusivity κ = k/(ρc), m²/s.
    pub fn diffusivity_m2_s(&self) -> f64 {
        self.conductivity_w_mk / (self.density_kg_m3 * self.specific_heat_j_kgk)
    }

    /// Heat capacity per unit area ρ·c·L, J m⁻² K⁻¹.
    pub fn areal_heat_capacity_j_m2k(&self) -> f64 {
        self.density_kg_m3 * self.specific_heat_j_kgk * self.thickness_m
    }

    /// Checks every field is finite and in its physical range.
    pub fn validate(&self) -> Result<(), ThermError> {
        let pos = [
            ("density_kg_m3", self.density_kg_m3),
            ("specific_heat_j_kgk", self.specific_heat_j_kgk),
            ("conductivity_w_mk", self.conductivity_w_mk),
            ("thickness_m", self.thickness_m),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(ThermError::BadMaterial(format!(
                    "{name} must be finite and > 0, got {v}"
                )));
            }
        }
        let unit = [
            ("solar_absorptivity", self.solar_absorptivity),
            ("thermal_emissivity", self.thermal_emissivity),
            ("ground_albedo", self.ground_albedo.unwrap_or(0.2)),
        ];
        for (name, v) in unit {
            if !(0.0..=1.0).contains(&v) {
                return Err(ThermError::BadMaterial(format!(
                    "{name} must be in [0, 1], got {v}"
                )));
            }
        }
        self.surface.validate().map_err(|e| {
            ThermError::BadMaterial(format!("{} surface: {e}", self.surface.name()))
        })?;
        if !self.internal_power_w_m2.is_finite() {
            return Err(ThermError::BadMaterial(
                "internal_power_w_m2 must be finite".into(),
            ));
        }
        match self.back {
            BackBoundary::ExposedToAir { area_factor }
                if !(area_factor.is_finite() && area_factor >= 0.0) =>
            {
                Err(ThermError::BadMaterial(format!(
                    "back area_factor must be >= 0, got {area_factor}"
                )))
            }
            BackBoundary::DeepGround { temp_k: Some(t) } if !(t.is_finite() && t > 0.0) => Err(
                ThermError::BadMaterial(format!("deep-ground temp_k must be > 0 K, got {t}")),
            ),
            _ => Ok(()),
        }
    }
}
