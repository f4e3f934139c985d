//! What a slab is made of: its material and what its back face sees.

use serde::{Deserialize, Serialize};

use crate::therm::surface::SurfaceKind;

use super::*;

/// What the back face (z = L) of the slab sees.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BackBoundary {
    /// No heat flow through the back face.
    Insulated,
    /// Back face exchanges with ambient air (convection and longwave to
    /// surroundings at air temperature); `area_factor` is the exposed back
    /// area per unit front area (DIRSIG's EXPOSED_AREA − 1 for a plate whose
    /// both faces are exposed: use 1.0).
    ExposedToAir { area_factor: f64 },
    /// Back face held at a deep-ground temperature: `temp_k`, or the mean
    /// air temperature of the forcing when `None`.
    DeepGround { temp_k: Option<f64> },
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
