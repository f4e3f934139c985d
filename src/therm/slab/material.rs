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
        /// Exposed back area per unit front area (`exposed_area`).
        area_factor: f64,
    },
    /// Back face held at a deep-ground temperature: `temp_k` (written in
    /// °C as `temp_c`, range [`keys::DEEP_GROUND_TEMP`],
    /// checked where it is read), or when absent the site's deep-ground
    /// temperature (a render) or the mean air temperature of the forcing.
    DeepGround {
        #[serde(
            rename = "temp_c",
            default,
            skip_serializing_if = "Option::is_none",
            with = "celsius"
        )]
        /// The deep-ground temperature, K (`None`: the site's or the forcing's).
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

    use super::keys::DEEP_GROUND_TEMP;
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

/// The keys of a `[material.NAME]` table that fill [`SlabMaterial`], one
/// row each, beside the fields: the material library reader
/// (`scene::material`) checks every value as written against its range,
/// and docs/scene-format.md's table of material keys is generated from
/// these rows. Adding a key to the construction is its field on
/// [`SlabMaterial`] and its row here, then the physics that reads it
/// (ARCHITECTURE.md, "a material key"). The ranges span real materials:
/// density from aerogels (~1 kg/m³) to osmium (22 590 kg/m³); specific
/// heat from lead/gold (~129 J/(kg·K)) to water and wet organics (4 180)
/// with margin; conductivity from aerogel/still air (0.013-0.026 W/(m·K))
/// to diamond (2 200); thickness from a 10 µm foil to a 10 m ground
/// column. Values outside (mutated libraries with conductivities of 1e30
/// or thicknesses of 1e-12 m) produced surface temperatures in the
/// thousands of kelvin and are refused.
pub mod keys {
    use crate::bounds::{Bound, Key};

    /// `density_kg_m3`: ρ.
    pub const DENSITY: Bound = Bound::new("density_kg_m3", 1.0, 25_000.0, "kg/m³");
    /// `specific_heat_j_kgk`: c.
    pub const SPECIFIC_HEAT: Bound = Bound::new("specific_heat_j_kgk", 100.0, 15_000.0, "J/(kg·K)");
    /// `conductivity_w_mk`: k.
    pub const CONDUCTIVITY: Bound = Bound::new("conductivity_w_mk", 0.005, 2_500.0, "W/(m·K)");
    /// `thickness_m`: L.
    pub const THICKNESS: Bound = Bound::new("thickness_m", 1e-5, 10.0, "m");
    /// `solar_absorptivity`: α for sunlight.
    pub const SOLAR_ABSORPTIVITY: Bound = Bound::new("solar_absorptivity", 0.0, 1.0, "");
    /// `thermal_emissivity`: ε.
    pub const THERMAL_EMISSIVITY: Bound = Bound::new("thermal_emissivity", 0.0, 1.0, "");
    /// Internal heat source: up to about a solar constant either way
    /// (engines, heated buildings, cooled skins).
    pub const INTERNAL_POWER: Bound = Bound::new("internal_power_w_m2", -1_000.0, 1_000.0, "W/m²");
    /// `exposed_area` of a back exposed to air (its area per unit front area).
    pub const EXPOSED_AREA: Bound = Bound::new("exposed_area", 1e-6, 10.0, "");
    /// `temp_c` of a deep-ground back.
    pub const DEEP_GROUND_TEMP: Bound = Bound::new("temp_c", -90.0, 100.0, "°C");
    /// The keys of one `layers` entry, top first (each with the range of
    /// the slab key of the same name; checked as written by the library
    /// reader, at the entry).
    pub const LAYER: [Bound; 4] = [THICKNESS, CONDUCTIVITY, DENSITY, SPECIFIC_HEAT];

    /// Every key of the construction, in the order the docs list them.
    pub const CONSTRUCTION: &[Key] = &[
        Key::number(
            &["density_kg_m3"],
            "required or `layers`",
            DENSITY,
            "ρ (aerogels ~1 to osmium 22 590)",
        ),
        Key::number(
            &["specific_heat_j_kgk"],
            "required or `layers`",
            SPECIFIC_HEAT,
            "c (lead/gold ~129 to water 4 180, with margin)",
        ),
        Key::number(
            &["conductivity_w_mk"],
            "required or `layers`",
            CONDUCTIVITY,
            "k (aerogel/still air ~0.013-0.026 to diamond 2 200)",
        ),
        Key::number(
            &["thickness_m"],
            "required or `layers`",
            THICKNESS,
            "slab thickness L (a 10 µm foil to a 10 m ground column)",
        ),
        Key::text(
            &["layers"],
            "",
            "none",
            "a layered slab instead of the four keys above: `layers = [{ thickness_m, \
             conductivity_w_mk, density_kg_m3, specific_heat_j_kgk }, ...]`, top first, each \
             key in the range of the slab key of its name, at most 4 layers; a node on every \
             interface (not for `kind = \"water\"`)",
        ),
        Key::number(
            &["solar_absorptivity"],
            "required",
            SOLAR_ABSORPTIVITY,
            "α_s, 0.3-3 µm (DIRSIG VISIBLE_EMISSIVITY)",
        ),
        Key::number(
            &["thermal_emissivity"],
            "required",
            THERMAL_EMISSIVITY,
            "hemispherical ε used by the thermal model",
        ),
        Key::text(
            &["back"],
            "",
            "`\"insulated\"`",
            "`\"insulated\"`, `{ air = { exposed_area = 1.0 } }` (back face exchanges heat with \
             air; exposed_area = back area per front area, DIRSIG EXPOSED_AREA), \
             `{ deep_ground = {} }` or `{ deep_ground = { temp_c = 12.0 } }` (back node at a \
             fixed deep temperature, °C; default: the mean air temperature of the 72 h before \
             the image time, or of the history if longer, clipped to the weather record; \
             `irsig therm` follows the same rule with `--to` as the image time)",
        ),
        Key::number(
            &["back", "air", "exposed_area"],
            "1",
            EXPOSED_AREA,
            "in `back = { air = { exposed_area } }`",
        ),
        // checked as it is read, in °C (`celsius`), so the message quotes it as written
        Key::number(
            &["back", "deep_ground", "temp_c"],
            "mean air",
            DEEP_GROUND_TEMP,
            "in `back = { deep_ground = { temp_c } }`",
        ),
        Key::number(
            &["internal_power_w_m2"],
            "0",
            INTERNAL_POWER,
            "internal heat source per facet area (up to about a solar constant either way)",
        ),
    ];
}

/// One layer of a layered slab (`layers = [{ ... }, ...]`, top first).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Layer {
    /// Thickness, m.
    pub thickness_m: f64,
    /// Thermal conductivity k, W m⁻¹ K⁻¹.
    pub conductivity_w_mk: f64,
    /// Density ρ, kg/m³.
    pub density_kg_m3: f64,
    /// Specific heat c, J kg⁻¹ K⁻¹.
    pub specific_heat_j_kgk: f64,
}

impl Layer {
    /// Volumetric heat capacity ρc, J m⁻³ K⁻¹.
    pub fn heat_capacity_j_m3k(&self) -> f64 {
        self.density_kg_m3 * self.specific_heat_j_kgk
    }

    /// Thermal diffusivity κ = k/(ρc), m²/s.
    pub fn diffusivity_m2_s(&self) -> f64 {
        self.conductivity_w_mk / self.heat_capacity_j_m3k()
    }
}

/// The most layers a slab may have.
pub const MAX_LAYERS: usize = 4;

/// The layers of a layered slab, top first (empty: one homogeneous slab).
/// A fixed array, so that a material stays `Copy`; written and read as the
/// list `layers = [{ ... }, ...]`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Layers {
    len: usize,
    items: [Option<Layer>; MAX_LAYERS],
}

impl Layers {
    /// The layers `v` (top first); `None` when there are more than [`MAX_LAYERS`].
    pub fn new(v: &[Layer]) -> Option<Layers> {
        if v.len() > MAX_LAYERS {
            return None;
        }
        let mut items = [None; MAX_LAYERS];
        for (slot, l) in items.iter_mut().zip(v) {
            *slot = Some(*l);
        }
        Some(Layers {
            len: v.len(),
            items,
        })
    }

    /// Whether the slab is homogeneous (no layers given).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The layers, top first.
    pub fn iter(&self) -> impl Iterator<Item = Layer> + '_ {
        self.items[..self.len]
            .iter()
            .map(|l| l.expect("set below len"))
    }
}

impl Serialize for Layers {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

impl<'de> Deserialize<'de> for Layers {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<Layer>::deserialize(d)?;
        Layers::new(&v).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "`layers` has {} layers: at most {MAX_LAYERS}",
                v.len()
            ))
        })
    }
}

/// One material's slab: thermal and surface properties (DIRSIG's
/// MASS_DENSITY, SPECIFIC_HEAT, THERMAL_CONDUCTIVITY, thickness,
/// VISIBLE_EMISSIVITY → `solar_absorptivity`, THERMAL_EMISSIVITY,
/// EXPOSED_AREA → [`BackBoundary::ExposedToAir`], internal power). It reads
/// itself from a `[material.NAME]` table (serde, the keys its fields name;
/// their rows in [`keys`]); [`SlabMaterial::NOT_LIBRARY_KEYS`] are set by
/// the model, and `surface` is built from the table's surface keys
/// (`therm::surface::SurfaceSpec`).
///
/// A layered slab (`layers`) keeps its layers in [`SlabMaterial::layers`];
/// its ρ, c and k fields are then its top layer's and `thickness_m` the
/// whole slab's (the sum of the layers): the library reader checks that a
/// table gives the four keys or `layers`, not both, and fills them
/// ([`SlabMaterial::filled_from_layers`]); read alone, an absent key is 0 and
/// [`SlabMaterial::validate`] refuses it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlabMaterial {
    /// Density ρ, kg/m³ (a layered slab: its top layer's).
    #[serde(default)]
    pub density_kg_m3: f64,
    /// Specific heat c, J kg⁻¹ K⁻¹ (a layered slab: its top layer's).
    #[serde(default)]
    pub specific_heat_j_kgk: f64,
    /// Thermal conductivity k, W m⁻¹ K⁻¹ (a layered slab: its top layer's).
    #[serde(default)]
    pub conductivity_w_mk: f64,
    /// Thickness L, m (a layered slab: the sum of its layers).
    #[serde(default)]
    pub thickness_m: f64,
    /// The layers of a layered slab, top first; empty for one homogeneous
    /// slab of the four fields above.
    #[serde(default, skip_serializing_if = "Layers::is_empty")]
    pub layers: Layers,
    /// Absorptivity α for sunlight (DIRSIG's VISIBLE_EMISSIVITY), 0-1.
    pub solar_absorptivity: f64,
    /// Thermal emissivity ε, 0-1.
    pub thermal_emissivity: f64,
    #[serde(default)]
    /// What the back face sees.
    pub back: BackBoundary,
    /// Internal heat delivered at the surface node, W/m² (docs/models.md, "Thermal model").
    #[serde(default)]
    pub internal_power_w_m2: f64,
    /// Solar albedo of the ground seen by a tilted facet (default 0.2).
    #[serde(default)]
    pub ground_albedo: Option<f64>,
    /// What the surface is: solid (with a water store), vegetation, water, snow.
    #[serde(default)]
    pub surface: SurfaceKind,
}

impl SlabMaterial {
    /// The construction a library table of only the six required keys
    /// reads as: every other field at its own serde default (insulated back,
    /// no internal power, the scene's ground albedo, a solid surface). The
    /// base value of code that builds a material by hand (test fixtures
    /// complete it with `..`), so a new key with a default touches no such
    /// code.
    pub fn with_defaults(
        density_kg_m3: f64,
        specific_heat_j_kgk: f64,
        conductivity_w_mk: f64,
        thickness_m: f64,
        solar_absorptivity: f64,
        thermal_emissivity: f64,
    ) -> SlabMaterial {
        use serde::de::value::{Error, MapDeserializer};
        let required = [
            ("density_kg_m3", density_kg_m3),
            ("specific_heat_j_kgk", specific_heat_j_kgk),
            ("conductivity_w_mk", conductivity_w_mk),
            ("thickness_m", thickness_m),
            ("solar_absorptivity", solar_absorptivity),
            ("thermal_emissivity", thermal_emissivity),
        ];
        SlabMaterial::deserialize(MapDeserializer::<_, Error>::new(required.into_iter()))
            .expect("the six required keys are every field without a default")
    }

    /// As [`SlabMaterial::with_defaults`], a layered slab: `layers` top
    /// first (as the library key `layers` gives them); an error for no
    /// layers or more than [`MAX_LAYERS`].
    pub fn with_layers(
        layers: &[Layer],
        solar_absorptivity: f64,
        thermal_emissivity: f64,
    ) -> Result<SlabMaterial, String> {
        let top = layers
            .first()
            .ok_or("`layers` is empty: give at least one layer")?;
        let base = SlabMaterial::with_defaults(
            top.density_kg_m3,
            top.specific_heat_j_kgk,
            top.conductivity_w_mk,
            top.thickness_m,
            solar_absorptivity,
            thermal_emissivity,
        );
        let layers = Layers::new(layers)
            .ok_or_else(|| format!("{} layers: at most {MAX_LAYERS}", layers.len()))?;
        Ok(SlabMaterial { layers, ..base }.filled_from_layers())
    }

    /// This material with its ρ, c and k its top layer's and its thickness
    /// the sum of its layers (unchanged when it has none).
    pub fn filled_from_layers(self) -> SlabMaterial {
        let Some(top) = self.layers.iter().next() else {
            return self;
        };
        SlabMaterial {
            density_kg_m3: top.density_kg_m3,
            specific_heat_j_kgk: top.specific_heat_j_kgk,
            conductivity_w_mk: top.conductivity_w_mk,
            thickness_m: self.layers.iter().map(|l| l.thickness_m).sum(),
            ..self
        }
    }

    /// Fields that are not keys of a material library: the ground albedo
    /// (the scene's, set at render time) and the surface kind (built from
    /// the table's `kind` and surface keys).
    pub const NOT_LIBRARY_KEYS: &[&str] = &["ground_albedo", "surface"];

    /// Thermal diffusivity κ = k/(ρc), m²/s (a layered slab: its top layer's).
    pub fn diffusivity_m2_s(&self) -> f64 {
        self.conductivity_w_mk / (self.density_kg_m3 * self.specific_heat_j_kgk)
    }

    /// The slab's layers, top first: the layers given, or the one layer of
    /// a homogeneous slab.
    pub fn layer_list(&self) -> Vec<Layer> {
        if self.layers.is_empty() {
            return vec![Layer {
                thickness_m: self.thickness_m,
                conductivity_w_mk: self.conductivity_w_mk,
                density_kg_m3: self.density_kg_m3,
                specific_heat_j_kgk: self.specific_heat_j_kgk,
            }];
        }
        self.layers.iter().collect()
    }

    /// Heat capacity per unit area Σ ρ·c·L over the layers, J m⁻² K⁻¹.
    pub fn areal_heat_capacity_j_m2k(&self) -> f64 {
        if self.layers.is_empty() {
            return self.density_kg_m3 * self.specific_heat_j_kgk * self.thickness_m;
        }
        self.layers
            .iter()
            .map(|l| l.heat_capacity_j_m3k() * l.thickness_m)
            .sum()
    }

    /// Steady conductance of the whole slab, front face to back face,
    /// `1 / Σ L_j/k_j` (the layers' thermal resistances in series), W m⁻² K⁻¹.
    pub fn conductance_w_m2k(&self) -> f64 {
        1.0 / self
            .layer_list()
            .iter()
            .map(|l| l.thickness_m / l.conductivity_w_mk)
            .sum::<f64>()
    }

    /// Checks every field is finite and in its physical range.
    pub fn validate(&self) -> Result<(), ThermError> {
        let positive = |name: &dyn std::fmt::Display, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(ThermError::BadMaterial(format!(
                    "{name} must be finite and > 0, got {v}"
                )))
            }
        };
        positive(&"density_kg_m3", self.density_kg_m3)?;
        positive(&"specific_heat_j_kgk", self.specific_heat_j_kgk)?;
        positive(&"conductivity_w_mk", self.conductivity_w_mk)?;
        positive(&"thickness_m", self.thickness_m)?;
        for (i, l) in self.layers.iter().enumerate() {
            let at = |key: &str| format!("layers[{i}].{key}");
            positive(&at("thickness_m"), l.thickness_m)?;
            positive(&at("conductivity_w_mk"), l.conductivity_w_mk)?;
            positive(&at("density_kg_m3"), l.density_kg_m3)?;
            positive(&at("specific_heat_j_kgk"), l.specific_heat_j_kgk)?;
        }
        if !self.layers.is_empty() && matches!(self.surface, SurfaceKind::Water(_)) {
            return Err(ThermError::BadMaterial(
                "a water body is one mixed column: `layers` are not for kind = \"water\"".into(),
            ));
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
        if matches!(self.surface, SurfaceKind::Snow { .. })
            && matches!(self.back, BackBoundary::ExposedToAir { .. })
        {
            return Err(ThermError::BadMaterial(
                "snow lies on the ground: its back is \"insulated\" or { deep_ground }, not { air }"
                    .into(),
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
