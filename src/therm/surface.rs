//! What a surface *is*, for the energy balance: a solid with a surface
//! water store, a vegetated surface that transpires, or open water that
//! absorbs sunlight through its depth and mixes.
//!
//! * **Solid** (pavement, concrete, metal, bare soil): rain and dew fill a
//!   surface store of `water_capacity_mm` (1 mm for pavement: Rim et al.
//!   1999 / Ramier et al. 2011 measured 0.5-1.5 mm depression storage on
//!   urban pavements); while it holds water the surface evaporates at the
//!   potential rate (no surface resistance), limited to what the store
//!   holds; beyond the capacity the water runs off. Starts dry at the
//!   beginning of the thermal history. A bare soil with `soil_wetness`
//!   also evaporates from its pores through the soil surface resistance of
//!   Sellers et al. (1992) ([`soil_resistance_s_m`]), with the wetness a
//!   fixed parameter (no soil-moisture dynamics).
//! * **Vegetation**: a big-leaf canopy skin over the soil slab, with its own
//!   temperature and heat capacity, coupled to the soil surface through the
//!   skin conductance Λ_sk of the ECMWF land surface scheme (the slab's node
//!   0 is the skin, node 1 the soil surface; [`super::slab::Mesh::with_skin`]);
//!   5 % of the absorbed shortwave reaches the soil. Transpiration by the
//!   resistance form of Penman-Monteith with the Jarvis canopy resistance
//!   ([`super::aero::Canopy`]); the canopy's roughness sets the aerodynamic
//!   resistance. Interception by the canopy, soil evaporation under it and
//!   soil-moisture dynamics are not modelled (soil moisture is a fixed
//!   parameter); the sensor sees the skin only (no view-angle dependent mix
//!   of canopy and soil).
//! * **Water**: the slab is the water column (thickness = depth), its bottom
//!   node the sediment. A fraction of the absorbed shortwave (the
//!   near-infrared) is absorbed in the skin, the rest by Beer-Lambert
//!   extinction with depth; whatever reaches the bottom heats the bottom
//!   node. Heat moves between nodes by molecular conduction plus an eddy
//!   diffusivity, much larger where the column is convectively unstable
//!   (denser water above lighter, with the density of Heggen 1983);
//!   evaporation by the bulk-aerodynamic formula (no surface resistance).
//!   Not modelled: currents and inflows, ice, the cool skin (≈0.2-0.3 K).
//! * **Snow**: a solid slab of snow whose surface is capped at 0 °C: when
//!   the balance would take it above, it stays at 0 °C and the surplus
//!   (W/m²) melts snow ([`super::slab::StepRecord::melt_w_m2`]); the melt
//!   water is not kept (no refreezing, no change of depth or albedo).
//!   Sublimation and frost go through the latent path with no surface
//!   resistance, with the saturation vapour pressure and latent heat of
//!   liquid water (over ice at −10 °C e° is 9 % lower and λ 13 % higher;
//!   the two partly cancel in λE).

use serde::{Deserialize, Serialize};

use super::aero::{CANOPY_HEAT_CAPACITY_PER_LAI_J_M2K, Canopy, HEAT_ROUGHNESS_RATIO, Roughness};
use crate::bounds::{Bound, KeyError};

/// Surface type and its parameters (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceKind {
    /// A solid: pavement, metal, bare soil.
    Solid {
        /// Depth of water the surface holds before runoff, mm (0: never wet).
        water_capacity_mm: f64,
        /// Roughness length for momentum, m.
        roughness_m: f64,
        /// Bare soil: the top layer's water content over its saturated
        /// value, θ/θ_sat (Sellers et al. 1992's W); the soil evaporates
        /// through [`soil_resistance_s_m`]. `None`: no evaporation but from
        /// the surface store (pavement, metal, a dry soil).
        #[serde(default)]
        soil_wetness: Option<f64>,
    },
    /// A vegetation canopy over soil.
    Vegetation(Canopy),
    /// Open water, mixed by eddy diffusion.
    Water(WaterBody),
    /// Seasonal snow: a solid whose surface cannot rise above 0 °C (the
    /// surplus melts it) and that sublimates or takes frost through the
    /// latent path with no surface resistance (a saturated ice surface).
    Snow {
        /// Roughness length for momentum, m.
        roughness_m: f64,
    },
}

impl Default for SurfaceKind {
    /// A dry solid of roughness 5 mm (no water store).
    fn default() -> Self {
        SurfaceKind::Solid {
            water_capacity_mm: 0.0,
            roughness_m: DEFAULT_SOLID_ROUGHNESS_M,
            soil_wetness: None,
        }
    }
}

/// Coefficients of the bare-soil surface resistance of Sellers, Heiser &
/// Hall (1992, *J. Geophys. Res.* 97(D17), 19033, eq. 19; fitted to the
/// FIFE 1987 prairie soil; the form SiB2 uses, Sellers et al. 1996, *J.
/// Climate* 9, 676): `r_soil = exp(A − B·W)` s/m.
pub const SOIL_RESISTANCE_A: f64 = 8.206;
/// See [`SOIL_RESISTANCE_A`].
pub const SOIL_RESISTANCE_B: f64 = 4.255;

/// Surface resistance of a bare soil to evaporation, s/m, from the wetness
/// `W = θ/θ_sat` of its top layer (Sellers et al. 1992):
/// `r_soil = exp(8.206 − 4.255·W)` — 3663 s/m dry (W = 0), 436 s/m at W =
/// 0.5, 52 s/m saturated (W = 1). W is clamped to [0, 1]. The soil
/// evaporates as `λE = (ρ_a c_p/γ)·(e°(T_s) − e_a)/(r_a + r_soil)` (the
/// latent path of every surface, [`super::aero::latent_w_m2`]); the
/// humidity of the soil pores is taken as saturated (SiB2's soil-water
/// potential factor `exp(ψg/(R_v T))` is above 0.99 for a moist loam, W ≥
/// 0.5).
pub fn soil_resistance_s_m(wetness: f64) -> f64 {
    (SOIL_RESISTANCE_A - SOIL_RESISTANCE_B * wetness.clamp(0.0, 1.0)).exp()
}

/// Momentum roughness of smooth built surfaces (pavement, concrete, sheet
/// metal), m: 1-5 mm (Stull 1988, fig. 9.6; Wieringa 1993 "smooth
/// surfaces"); 5 mm keeps the log law valid at screen height.
pub const DEFAULT_SOLID_ROUGHNESS_M: f64 = 0.005;

/// Effective thermal conductivity of seasonal snow, W/(m·K), from its
/// density (Sturm, Holmgren, König & Morris 1997, J. Glaciol. 43(143),
/// 26-41, eq. 4; ρ in g/cm³): `k = 0.023 + 0.234·ρ` for ρ < 0.156,
/// `k = 0.138 − 1.01·ρ + 3.233·ρ²` for 0.156 ≤ ρ ≤ 0.6 (fitted to 488
/// needle-probe measurements of seasonal snow). Densities outside 0.1-0.6
/// g/cm³ are clamped to it. The `snow` material of scenes/materials.toml
/// takes its conductivity from this fit at its density (a test checks it).
pub fn snow_conductivity_w_mk(density_kg_m3: f64) -> f64 {
    let rho = (density_kg_m3 / 1000.0).clamp(0.1, 0.6);
    if rho < 0.156 {
        0.023 + 0.234 * rho
    } else {
        0.138 - 1.01 * rho + 3.233 * rho * rho
    }
}

/// A water body's optical and mixing parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WaterBody {
    /// Fraction β of the absorbed shortwave absorbed at the surface (the
    /// near-infrared part of sunlight; 0.4-0.45 in lake models:
    /// Henderson-Sellers 1986, Hostetler & Bartlein 1990).
    pub surface_fraction: f64,
    /// Extinction coefficient η of the rest, 1/m (0.2 clear lakes … 5
    /// turbid ponds).
    pub extinction_per_m: f64,
    /// Eddy diffusivity of a stably stratified column, m²/s.
    pub eddy_diffusivity_m2_s: f64,
    /// Diffusivity where the column is convectively unstable, m²/s.
    pub convective_diffusivity_m2_s: f64,
    /// Roughness length of the water surface, m.
    pub roughness_m: f64,
}

impl SurfaceKind {
    /// The aerodynamic roughness of this surface.
    pub fn roughness(&self) -> Roughness {
        match self {
            SurfaceKind::Solid { roughness_m, .. } => Roughness::bare(*roughness_m),
            SurfaceKind::Vegetation(c) => {
                Roughness::canopy_with_heat_ratio(c.height_m, c.heat_roughness_ratio)
            }
            SurfaceKind::Water(w) => Roughness::bare(w.roughness_m),
            SurfaceKind::Snow { roughness_m } => Roughness::bare(*roughness_m),
        }
    }

    /// Short lower-case name (`solid`, `vegetation`, `water`, `snow`).
    pub fn name(&self) -> &'static str {
        match self {
            SurfaceKind::Solid { .. } => "solid",
            SurfaceKind::Vegetation(_) => "vegetation",
            SurfaceKind::Water(_) => "water",
            SurfaceKind::Snow { .. } => "snow",
        }
    }

    /// Checks every parameter is finite and in its physical range; the
    /// message names the parameter, its value and the range.
    pub fn validate(&self) -> Result<(), String> {
        let check = |k: &str, v: f64, lo: f64, hi: f64| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(format!("{k} = {v}: expected {lo} to {hi}"))
            }
        };
        match *self {
            SurfaceKind::Solid {
                water_capacity_mm,
                roughness_m,
                soil_wetness,
            } => {
                check("water_capacity_mm", water_capacity_mm, 0.0, 50.0)?;
                if let Some(w) = soil_wetness {
                    check("soil_wetness", w, 0.0, 1.0)?;
                }
                check("roughness_m", roughness_m, 1e-5, 0.5)
            }
            SurfaceKind::Vegetation(c) => {
                check("canopy_height_m", c.height_m, 0.01, 30.0)?;
                check("lai", c.lai, 0.1, 10.0)?;
                check(
                    "min_stomatal_resistance_s_m",
                    c.min_resistance_s_m,
                    10.0,
                    1000.0,
                )?;
                check(
                    "max_stomatal_resistance_s_m",
                    c.max_resistance_s_m,
                    c.min_resistance_s_m,
                    1e5,
                )?;
                check("radiation_limit_w_m2", c.radiation_limit_w_m2, 1.0, 1000.0)?;
                check("vpd_coeff", c.vpd_coeff, 0.0, 200.0)?;
                check("soil_moisture", c.soil_moisture, 0.0, 1.0)?;
                check(
                    "skin_conductance_w_m2k",
                    c.skin_conductance_w_m2k,
                    0.5,
                    1.0e4,
                )?;
                check(
                    "canopy_heat_capacity_j_m2k",
                    c.heat_capacity_j_m2k,
                    10.0,
                    1.0e6,
                )?;
                check(
                    "soil_shortwave_fraction",
                    c.soil_shortwave_fraction,
                    0.0,
                    0.9,
                )?;
                check("heat_roughness_ratio", c.heat_roughness_ratio, 1e-4, 1.0)
            }
            SurfaceKind::Water(w) => {
                check("surface_fraction", w.surface_fraction, 0.0, 1.0)?;
                check("extinction_per_m", w.extinction_per_m, 0.01, 100.0)?;
                check("eddy_diffusivity_m2_s", w.eddy_diffusivity_m2_s, 0.0, 1.0)?;
                check(
                    "convective_diffusivity_m2_s",
                    w.convective_diffusivity_m2_s,
                    w.eddy_diffusivity_m2_s,
                    10.0,
                )?;
                check("roughness_m", w.roughness_m, 1e-6, 0.1)
            }
            SurfaceKind::Snow { roughness_m } => check("roughness_m", roughness_m, 1e-5, 0.5),
        }
    }
}

/// Density of fresh water, kg/m³ (Heggen 1983, as in the lake model of
/// Hostetler & Bartlein 1990): `ρ = 1000·(1 − 1.9549e-5·|T − 277|^1.68)`,
/// T in K; maximum at 4 °C.
pub fn water_density_kg_m3(temp_k: f64) -> f64 {
    1000.0 * (1.0 - 1.9549e-5 * (temp_k - 277.0).abs().powf(1.68))
}

/// Fraction of the absorbed shortwave deposited in each node's control
/// volume of a water column with node depths `z_m` (z₀ = 0 the surface,
/// last = the bottom): `β` in the surface node, then
/// `(1 − β)·(e^(−η·z_top) − e^(−η·z_bot))` for the volume `[z_top, z_bot]`
/// of each node (cell faces half-way between nodes), and everything that
/// reaches the bottom node's upper face in the bottom node (the sediment
/// absorbs it). The fractions sum to 1.
pub fn shortwave_fractions(z_m: &[f64], surface_fraction: f64, extinction_per_m: f64) -> Vec<f64> {
    let n = z_m.len();
    let beta = surface_fraction.clamp(0.0, 1.0);
    let t = |z: f64| (-extinction_per_m * z).exp();
    (0..n)
        .map(|i| {
            let top = if i == 0 {
                0.0
            } else {
                0.5 * (z_m[i - 1] + z_m[i])
            };
            let bot = if i + 1 == n {
                f64::INFINITY
            } else {
                0.5 * (z_m[i] + z_m[i + 1])
            };
            let below = if bot.is_finite() { t(bot) } else { 0.0 };
            (1.0 - beta) * (t(top) - below) + if i == 0 { beta } else { 0.0 }
        })
        .collect()
}

/// Conductances between the nodes of a water column for one step, W m⁻²
/// K⁻¹: `(k + ρc·K)/Δz` with `K` the convective diffusivity where the upper
/// node is denser than the lower one, else the stable eddy diffusivity.
/// `base_w_m2k` are the molecular conductances `k/Δz`, `rho_c` the
/// volumetric heat capacity, `k` the molecular conductivity.
pub fn mixing_conductances(
    base_w_m2k: &[f64],
    temps_k: &[f64],
    conductivity_w_mk: f64,
    rho_c_j_m3k: f64,
    water: &WaterBody,
    out: &mut [f64],
) {
    for i in 0..base_w_m2k.len() {
        let dz = conductivity_w_mk / base_w_m2k[i];
        let unstable = water_density_kg_m3(temps_k[i]) > water_density_kg_m3(temps_k[i + 1]);
        let k_eddy = if unstable {
            water.convective_diffusivity_m2_s
        } else {
            water.eddy_diffusivity_m2_s
        };
        out[i] = (conductivity_w_mk + rho_c_j_m3k * k_eddy) / dz;
    }
}

/// `kind = "solid" | "vegetation" | "water" | "snow"` in a material library.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum KindSpec {
    #[default]
    /// A solid: pavement, metal, bare soil.
    Solid,
    /// A vegetation canopy.
    Vegetation,
    /// Open water.
    Water,
    /// Seasonal snow.
    Snow,
}

impl KindSpec {
    fn name(self) -> &'static str {
        match self {
            KindSpec::Solid => "solid",
            KindSpec::Vegetation => "vegetation",
            KindSpec::Water => "water",
            KindSpec::Snow => "snow",
        }
    }
}

/// Defaults of the optional surface parameters, with their sources.
pub mod surface_defaults {
    /// Jarvis/Noah R_gl for grass and crops, W/m² (Noilhan & Planton 1989;
    /// Noah VEGPARM "grassland" 100).
    pub const RADIATION_LIMIT_W_M2: f64 = 100.0;
    /// Noah's cuticular resistance r_s,max, s/m (Chen et al. 1996).
    pub const MAX_STOMATAL_RESISTANCE_S_M: f64 = 5000.0;
    /// Noah's h_s for grass and crops, (kg/kg)⁻¹ (Noah VEGPARM 36.35).
    pub const VPD_COEFF: f64 = 36.35;
    /// FAO-56's bulk stomatal resistance of a well-illuminated leaf, s/m
    /// (FAO-56 eq. 5: r_l = 100 s/m).
    pub const MIN_STOMATAL_RESISTANCE_S_M: f64 = 100.0;
    /// Skin-layer conductivity Λ_sk between a canopy and its soil, W m⁻²
    /// K⁻¹ (ECMWF: Viterbo & Beljaars 1995; ecLand SUSVEG `RVLAMSK` 10 for
    /// crops, grass, shrubs and forests).
    pub const SKIN_CONDUCTANCE_W_M2K: f64 = 10.0;
    /// Fraction of the absorbed shortwave transmitted to the soil (ecLand
    /// SUSVEG `RVTRSR` 0.05 for crops and grass).
    pub const SOIL_SHORTWAVE_FRACTION: f64 = 0.05;
    /// Near-infrared share of absorbed sunlight taken by a water skin
    /// (Henderson-Sellers 1986; Hostetler & Bartlein 1990: 0.4).
    pub const SHORTWAVE_SURFACE_FRACTION: f64 = 0.4;
    /// Eddy diffusivity of a stably stratified small pond, m²/s (1e-6-1e-4
    /// in small lakes, Hondzo & Stefan 1993): 2e-5.
    pub const EDDY_DIFFUSIVITY_M2_S: f64 = 1.0e-4;
    /// Convective overturning, m²/s: fast enough to mix a 1 m column in
    /// minutes.
    pub const CONVECTIVE_DIFFUSIVITY_M2_S: f64 = 1.0e-2;
    /// Roughness length of a water surface at light winds, m (Charnock
    /// z₀ = 0.011·u*²/g ≈ 1e-4 m at u* = 0.3 m/s; Garratt 1992, Table A6).
    pub const WATER_ROUGHNESS_M: f64 = 2.0e-4;
    /// Roughness length of snow-covered flat ground, m (0.1-1 mm: Stull
    /// 1988 fig. 9.6 order of magnitude; ecLand 1.3 mm over ice caps).
    pub const SNOW_ROUGHNESS_M: f64 = 1.0e-3;
}

/// The surface keys of a `[material.NAME]` table, one row each, beside
/// [`SurfaceSpec`]'s fields (docs/scene-format.md's table is generated from
/// them). Their ranges are checked where [`SurfaceSpec::build`] builds the
/// surface: after the defaults, per kind, and for two of them with the
/// lower end another key of the same material.
pub mod keys {
    use crate::bounds::{Bound, Key};

    /// `water_capacity_mm`: depth of water a solid holds before runoff.
    pub const WATER_CAPACITY: Bound = Bound::new("water_capacity_mm", 0.0, 50.0, "mm");
    /// `roughness_m` of a solid: roughness length for momentum.
    pub const SOLID_ROUGHNESS: Bound = Bound::new("roughness_m", 1e-5, 0.5, "m");
    /// `soil_wetness`: θ/θ_sat of a bare soil's top layer.
    pub const SOIL_WETNESS: Bound = Bound::new("soil_wetness", 0.0, 1.0, "");
    /// `canopy_height_m`: height of a vegetation canopy.
    pub const CANOPY_HEIGHT: Bound = Bound::new("canopy_height_m", 0.01, 30.0, "m");
    /// `lai`: leaf area index of a canopy.
    pub const LAI: Bound = Bound::new("lai", 0.1, 10.0, "m²/m²");
    /// `soil_moisture`: relative available soil water of a canopy, 0-1 (Jarvis F₄).
    pub const SOIL_MOISTURE: Bound = Bound::new("soil_moisture", 0.0, 1.0, "");
    /// `min_stomatal_resistance_s_m`: a well-lit, well-watered leaf's resistance.
    pub const MIN_STOMATAL_RESISTANCE: Bound =
        Bound::new("min_stomatal_resistance_s_m", 10.0, 1000.0, "s/m");
    /// Lower end: the minimum resistance of the same material.
    pub const MAX_STOMATAL_RESISTANCE: Bound =
        Bound::new("max_stomatal_resistance_s_m", 10.0, 1e5, "s/m");
    /// `radiation_limit_w_m2`: Jarvis R_gl, the light the stomata open to.
    pub const RADIATION_LIMIT: Bound = Bound::new("radiation_limit_w_m2", 1.0, 1000.0, "W/m²");
    /// `vpd_coeff`: Jarvis h_s, the stomata's closing with the vapour-pressure deficit.
    pub const VPD_COEFF: Bound = Bound::new("vpd_coeff", 0.0, 200.0, "(kg/kg)⁻¹");
    /// `skin_conductance_w_m2k`: Λ_sk between a canopy's skin and its soil.
    pub const SKIN_CONDUCTANCE: Bound =
        Bound::new("skin_conductance_w_m2k", 0.5, 1.0e4, "W/(m²·K)");
    /// `canopy_heat_capacity_j_m2k`: the canopy's own heat capacity.
    pub const CANOPY_HEAT_CAPACITY: Bound =
        Bound::new("canopy_heat_capacity_j_m2k", 10.0, 1.0e6, "J/(m²·K)");
    /// `soil_shortwave_fraction`: share of the absorbed sunlight that reaches the soil.
    pub const SOIL_SHORTWAVE_FRACTION: Bound = Bound::new("soil_shortwave_fraction", 0.0, 0.9, "");
    /// `heat_roughness_ratio`: a canopy's `z_oh/z_om` (kB⁻¹ = −ln ratio ≥ 0).
    pub const HEAT_ROUGHNESS_RATIO: Bound = Bound::new("heat_roughness_ratio", 1e-4, 1.0, "");
    /// `extinction_per_m`: shortwave extinction of water.
    pub const EXTINCTION: Bound = Bound::new("extinction_per_m", 0.01, 100.0, "1/m");
    /// `shortwave_surface_fraction`: share of absorbed sunlight taken by the water's skin.
    pub const SHORTWAVE_SURFACE_FRACTION: Bound =
        Bound::new("shortwave_surface_fraction", 0.0, 1.0, "");
    /// `eddy_diffusivity_m2_s`: mixing of stably stratified water.
    pub const EDDY_DIFFUSIVITY: Bound = Bound::new("eddy_diffusivity_m2_s", 0.0, 1.0, "m²/s");
    /// Lower end: the eddy diffusivity of the same material.
    pub const CONVECTIVE_DIFFUSIVITY: Bound =
        Bound::new("convective_diffusivity_m2_s", 0.0, 10.0, "m²/s");
    /// `roughness_m` of water: roughness length for momentum.
    pub const WATER_ROUGHNESS: Bound = Bound::new("roughness_m", 1e-6, 0.1, "m");

    const fn row(
        p: &'static [&'static str],
        default: &'static str,
        b: Bound,
        m: &'static str,
    ) -> Key {
        Key::number(p, default, b, m).checked_where_built()
    }

    /// Every surface key, in the order the docs list them.
    pub const SURFACE: &[Key] = &[
        Key::text(
            &["kind"],
            "",
            "`\"solid\"`",
            "`\"solid\"`, `\"vegetation\"`, `\"water\"`, `\"snow\"`: the keys below ([energy-balance.md](energy-balance.md))",
        ),
        row(
            &["water_capacity_mm"],
            "0",
            WATER_CAPACITY,
            "solid: water held before runoff",
        ),
        row(
            &["roughness_m"],
            "0.005",
            SOLID_ROUGHNESS,
            "solid: roughness length for momentum",
        ),
        row(
            &["soil_wetness"],
            "none (no soil evaporation)",
            SOIL_WETNESS,
            "solid, bare soil: top-layer water content over saturation θ/θ_sat; evaporation through the Sellers (1992) soil resistance",
        ),
        row(
            &["roughness_m"],
            "2e-4",
            WATER_ROUGHNESS,
            "water: roughness length for momentum",
        ),
        row(
            &["roughness_m"],
            "0.001",
            SOLID_ROUGHNESS,
            "snow: roughness length for momentum",
        ),
        row(
            &["canopy_height_m"],
            "required (vegetation)",
            CANOPY_HEIGHT,
            "",
        ),
        row(&["lai"], "required (vegetation)", LAI, "leaf area index"),
        row(
            &["soil_moisture"],
            "required (vegetation)",
            SOIL_MOISTURE,
            "0 wilting … 1 field capacity",
        ),
        row(
            &["min_stomatal_resistance_s_m"],
            "100",
            MIN_STOMATAL_RESISTANCE,
            "",
        ),
        row(
            &["max_stomatal_resistance_s_m"],
            "5000",
            MAX_STOMATAL_RESISTANCE,
            "and >= `min_stomatal_resistance_s_m`",
        ),
        row(
            &["radiation_limit_w_m2"],
            "100",
            RADIATION_LIMIT,
            "Jarvis R_gl",
        ),
        row(&["vpd_coeff"], "36.35", VPD_COEFF, "Jarvis h_s"),
        row(
            &["skin_conductance_w_m2k"],
            "10",
            SKIN_CONDUCTANCE,
            "vegetation: canopy skin to soil (ECMWF Λ_sk)",
        ),
        row(
            &["canopy_heat_capacity_j_m2k"],
            "1000 × lai",
            CANOPY_HEAT_CAPACITY,
            "vegetation: heat capacity of the canopy skin",
        ),
        row(
            &["soil_shortwave_fraction"],
            "0.05",
            SOIL_SHORTWAVE_FRACTION,
            "vegetation: share of absorbed sunlight reaching the soil",
        ),
        row(
            &["heat_roughness_ratio"],
            "0.1",
            HEAT_ROUGHNESS_RATIO,
            "vegetation: z_oh/z_om (FAO-56 0.1; ECMWF 1 for trees)",
        ),
        row(
            &["extinction_per_m"],
            "required (water)",
            EXTINCTION,
            "Beer-Lambert",
        ),
        row(
            &["shortwave_surface_fraction"],
            "0.4",
            SHORTWAVE_SURFACE_FRACTION,
            "water",
        ),
        row(
            &["eddy_diffusivity_m2_s"],
            "1e-4",
            EDDY_DIFFUSIVITY,
            "water, stable column",
        ),
        row(
            &["convective_diffusivity_m2_s"],
            "1e-2",
            CONVECTIVE_DIFFUSIVITY,
            "water, unstable column; and >= `eddy_diffusivity_m2_s`",
        ),
    ];
}

/// The surface keys of a `[material.NAME]` table as written: `kind` and
/// the parameters of each kind, all optional here; [`SurfaceSpec::build`]
/// fills the defaults and checks what the kind needs.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    /// What the surface is for the energy balance (default `solid`).
    #[serde(default)]
    pub kind: KindSpec,
    /// Solid: water held before runoff, mm (default 0: never wet).
    pub water_capacity_mm: Option<f64>,
    /// Solid and water: roughness length for momentum, m.
    pub roughness_m: Option<f64>,
    /// Solid (bare soil): top-layer water content over saturation, θ/θ_sat.
    pub soil_wetness: Option<f64>,
    /// Vegetation: canopy height, m (required).
    pub canopy_height_m: Option<f64>,
    /// Vegetation: leaf area index (required).
    pub lai: Option<f64>,
    /// Vegetation: relative available soil water 0 (wilting) … 1 (field
    /// capacity) (required).
    pub soil_moisture: Option<f64>,
    /// Vegetation: minimum stomatal resistance per unit LAI, s/m.
    pub min_stomatal_resistance_s_m: Option<f64>,
    /// Vegetation: cuticular (largest) resistance, s/m.
    pub max_stomatal_resistance_s_m: Option<f64>,
    /// Vegetation: the radiation parameter R_gl of the Jarvis F₁, W/m².
    pub radiation_limit_w_m2: Option<f64>,
    /// Vegetation: the vapour-deficit parameter h_s of F₂, (kg/kg)⁻¹.
    pub vpd_coeff: Option<f64>,
    /// Vegetation: conductance between the canopy skin and the soil, W m⁻² K⁻¹.
    pub skin_conductance_w_m2k: Option<f64>,
    /// Vegetation: heat capacity of the canopy skin, J m⁻² K⁻¹.
    pub canopy_heat_capacity_j_m2k: Option<f64>,
    /// Vegetation: fraction of the absorbed shortwave reaching the soil.
    pub soil_shortwave_fraction: Option<f64>,
    /// Vegetation: roughness length for heat over that for momentum, z_oh/z_om.
    pub heat_roughness_ratio: Option<f64>,
    /// Water: Beer-Lambert extinction coefficient, 1/m (required).
    pub extinction_per_m: Option<f64>,
    /// Water: fraction of absorbed shortwave absorbed at the surface.
    pub shortwave_surface_fraction: Option<f64>,
    /// Water: eddy diffusivity of a stable column, m²/s.
    pub eddy_diffusivity_m2_s: Option<f64>,
    /// Water: diffusivity of a convectively unstable column, m²/s.
    pub convective_diffusivity_m2_s: Option<f64>,
}

impl SurfaceSpec {
    /// The surface kind: checks that the keys its kind needs are there and
    /// in range, and that no key of another kind is given; an error names
    /// the key (or, for a missing one, the table).
    pub fn build(&self) -> Result<SurfaceKind, KeyError> {
        use KindSpec::{Snow, Solid, Vegetation, Water};
        use keys as K;
        use surface_defaults as d;
        let m = self;
        let kind_name = m.kind.name();
        let all: [(&'static str, Option<f64>, &[KindSpec]); 18] = [
            ("water_capacity_mm", m.water_capacity_mm, &[Solid]),
            ("soil_wetness", m.soil_wetness, &[Solid]),
            ("roughness_m", m.roughness_m, &[Solid, Water, Snow]),
            ("canopy_height_m", m.canopy_height_m, &[Vegetation]),
            ("lai", m.lai, &[Vegetation]),
            ("soil_moisture", m.soil_moisture, &[Vegetation]),
            (
                "min_stomatal_resistance_s_m",
                m.min_stomatal_resistance_s_m,
                &[Vegetation],
            ),
            (
                "max_stomatal_resistance_s_m",
                m.max_stomatal_resistance_s_m,
                &[Vegetation],
            ),
            (
                "radiation_limit_w_m2",
                m.radiation_limit_w_m2,
                &[Vegetation],
            ),
            ("vpd_coeff", m.vpd_coeff, &[Vegetation]),
            (
                "skin_conductance_w_m2k",
                m.skin_conductance_w_m2k,
                &[Vegetation],
            ),
            (
                "canopy_heat_capacity_j_m2k",
                m.canopy_heat_capacity_j_m2k,
                &[Vegetation],
            ),
            (
                "soil_shortwave_fraction",
                m.soil_shortwave_fraction,
                &[Vegetation],
            ),
            (
                "heat_roughness_ratio",
                m.heat_roughness_ratio,
                &[Vegetation],
            ),
            ("extinction_per_m", m.extinction_per_m, &[Water]),
            (
                "shortwave_surface_fraction",
                m.shortwave_surface_fraction,
                &[Water],
            ),
            ("eddy_diffusivity_m2_s", m.eddy_diffusivity_m2_s, &[Water]),
            (
                "convective_diffusivity_m2_s",
                m.convective_diffusivity_m2_s,
                &[Water],
            ),
        ];
        for (key, v, kinds) in all {
            if v.is_some() && !kinds.contains(&m.kind) {
                return Err(KeyError {
                    path: vec![key],
                    msg: format!(
                        "`{key}` does not apply to kind = \"{kind_name}\" (it is a parameter of {})",
                        kinds
                            .iter()
                            .map(|k| k.name())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                });
            }
        }
        let need = |key: &str, v: Option<f64>| {
            v.ok_or_else(|| KeyError {
                path: vec![],
                msg: format!(
                    "kind = \"{kind_name}\" needs `{key}` (see docs/scene-format.md, \"Surface kinds\")"
                ),
            })
        };
        let range = |b: Bound, v: f64| {
            b.check(v).map_err(|msg| KeyError {
                path: vec![b.key],
                msg,
            })
        };
        // a range whose lower end is another key of the same material
        let above = |b: Bound, v: f64, lo: f64| range(Bound { lo, ..b }, v);
        Ok(match m.kind {
            Solid => {
                let cap = m.water_capacity_mm.unwrap_or(0.0);
                range(K::WATER_CAPACITY, cap)?;
                let z0 = m.roughness_m.unwrap_or(DEFAULT_SOLID_ROUGHNESS_M);
                range(K::SOLID_ROUGHNESS, z0)?;
                if let Some(w) = m.soil_wetness {
                    range(K::SOIL_WETNESS, w)?;
                }
                SurfaceKind::Solid {
                    water_capacity_mm: cap,
                    roughness_m: z0,
                    soil_wetness: m.soil_wetness,
                }
            }
            Vegetation => {
                let height_m = need("canopy_height_m", m.canopy_height_m)?;
                range(K::CANOPY_HEIGHT, height_m)?;
                let lai = need("lai", m.lai)?;
                range(K::LAI, lai)?;
                let soil_moisture = need("soil_moisture", m.soil_moisture)?;
                range(K::SOIL_MOISTURE, soil_moisture)?;
                let rmin = m
                    .min_stomatal_resistance_s_m
                    .unwrap_or(d::MIN_STOMATAL_RESISTANCE_S_M);
                range(K::MIN_STOMATAL_RESISTANCE, rmin)?;
                let rmax = m
                    .max_stomatal_resistance_s_m
                    .unwrap_or(d::MAX_STOMATAL_RESISTANCE_S_M);
                above(K::MAX_STOMATAL_RESISTANCE, rmax, rmin)?;
                let rgl = m.radiation_limit_w_m2.unwrap_or(d::RADIATION_LIMIT_W_M2);
                range(K::RADIATION_LIMIT, rgl)?;
                let hs = m.vpd_coeff.unwrap_or(d::VPD_COEFF);
                range(K::VPD_COEFF, hs)?;
                let skin = m
                    .skin_conductance_w_m2k
                    .unwrap_or(d::SKIN_CONDUCTANCE_W_M2K);
                range(K::SKIN_CONDUCTANCE, skin)?;
                let cap = m
                    .canopy_heat_capacity_j_m2k
                    .unwrap_or(CANOPY_HEAT_CAPACITY_PER_LAI_J_M2K * lai);
                range(K::CANOPY_HEAT_CAPACITY, cap)?;
                let tau = m
                    .soil_shortwave_fraction
                    .unwrap_or(d::SOIL_SHORTWAVE_FRACTION);
                range(K::SOIL_SHORTWAVE_FRACTION, tau)?;
                let ratio = m.heat_roughness_ratio.unwrap_or(HEAT_ROUGHNESS_RATIO);
                range(K::HEAT_ROUGHNESS_RATIO, ratio)?;
                SurfaceKind::Vegetation(Canopy {
                    height_m,
                    lai,
                    min_resistance_s_m: rmin,
                    max_resistance_s_m: rmax,
                    radiation_limit_w_m2: rgl,
                    vpd_coeff: hs,
                    soil_moisture,
                    skin_conductance_w_m2k: skin,
                    heat_capacity_j_m2k: cap,
                    soil_shortwave_fraction: tau,
                    heat_roughness_ratio: ratio,
                })
            }
            Snow => {
                let z0 = m.roughness_m.unwrap_or(d::SNOW_ROUGHNESS_M);
                range(K::SOLID_ROUGHNESS, z0)?;
                SurfaceKind::Snow { roughness_m: z0 }
            }
            Water => {
                let eta = need("extinction_per_m", m.extinction_per_m)?;
                range(K::EXTINCTION, eta)?;
                let beta = m
                    .shortwave_surface_fraction
                    .unwrap_or(d::SHORTWAVE_SURFACE_FRACTION);
                range(K::SHORTWAVE_SURFACE_FRACTION, beta)?;
                let ke = m.eddy_diffusivity_m2_s.unwrap_or(d::EDDY_DIFFUSIVITY_M2_S);
                range(K::EDDY_DIFFUSIVITY, ke)?;
                let kc = m
                    .convective_diffusivity_m2_s
                    .unwrap_or(d::CONVECTIVE_DIFFUSIVITY_M2_S);
                above(K::CONVECTIVE_DIFFUSIVITY, kc, ke)?;
                let z0 = m.roughness_m.unwrap_or(d::WATER_ROUGHNESS_M);
                range(K::WATER_ROUGHNESS, z0)?;
                SurfaceKind::Water(WaterBody {
                    surface_fraction: beta,
                    extinction_per_m: eta,
                    eddy_diffusivity_m2_s: ke,
                    convective_diffusivity_m2_s: kc,
                    roughness_m: z0,
                })
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Heggen's fit against the tabulated density of water (Kell 1975 /
    /// CRC: 998.21 kg/m³ at 20 °C, 995.65 at 30 °C) within 0.5 kg/m³ (the
    /// fit's own accuracy; only the sign of density differences is used);
    /// maximum near 4 °C.
    #[test]
    fn water_density_against_tables() {
        assert!((water_density_kg_m3(293.15) - 998.21).abs() < 0.5);
        assert!((water_density_kg_m3(303.15) - 995.65).abs() < 0.5);
        assert!(water_density_kg_m3(277.0) > water_density_kg_m3(280.0));
        assert!(water_density_kg_m3(277.0) > water_density_kg_m3(274.0));
    }

    /// Sellers et al. (1992) eq. 19, r_soil = exp(8.206 − 4.255·W),
    /// evaluated by hand: 3662.9 s/m at W = 0, 436.4 at 0.5, 52.0 at 1;
    /// W is clamped to [0, 1]. The key builds for a solid only and is
    /// range-checked by name.
    #[test]
    fn soil_resistance_follows_sellers_1992() {
        for (w, r) in [(0.0, 3662.86), (0.5, 436.374), (1.0, 51.9873)] {
            assert!((soil_resistance_s_m(w) - r).abs() < 1e-4 * r, "{w}");
        }
        assert_eq!(soil_resistance_s_m(1.5), soil_resistance_s_m(1.0));
        let spec = SurfaceSpec {
            soil_wetness: Some(0.8),
            ..Default::default()
        };
        assert_eq!(
            spec.build().unwrap(),
            SurfaceKind::Solid {
                water_capacity_mm: 0.0,
                roughness_m: DEFAULT_SOLID_ROUGHNESS_M,
                soil_wetness: Some(0.8),
            }
        );
        let bad = SurfaceSpec {
            soil_wetness: Some(1.2),
            ..Default::default()
        };
        let e = bad.build().unwrap_err();
        assert_eq!(e.path, vec!["soil_wetness"]);
        let veg = SurfaceSpec {
            kind: KindSpec::Vegetation,
            soil_wetness: Some(0.5),
            ..Default::default()
        };
        assert!(veg.build().unwrap_err().msg.contains("soil_wetness"));
    }

    /// Beer-Lambert fractions: they sum to 1, the skin takes β, and the
    /// water above depth z absorbs β + (1 − β)(1 − e^(−ηz)) (checked at
    /// the face half-way between two nodes).
    #[test]
    fn shortwave_fractions_follow_beer_lambert() {
        let z: Vec<f64> = (0..=20).map(|i| 0.05 * i as f64).collect();
        let f = shortwave_fractions(&z, 0.45, 2.0);
        assert!((f.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let upper: f64 = f[..5].iter().sum(); // nodes 0..4, face at 0.225 m
        let expect = 0.45 + 0.55 * (1.0 - (-2.0f64 * 0.225).exp());
        assert!((upper - expect).abs() < 1e-12, "{upper} vs {expect}");
    }
}
