//! Turbulent exchange between a surface and the air: moist-air properties,
//! the wind at a facet's height, the aerodynamic resistance with a
//! stability correction, free convection, and the latent-heat flux of the
//! surface types (vegetation, wet surfaces, water).
//!
//! Every function is pure and in SI units unless its name says otherwise.
//! Sign convention as in [`super::balance`]: fluxes positive **into** the
//! surface.
//!
//! **Convection is convective only.** The coefficient `h = ρ·c_p/r_a` that
//! these functions give carries no radiative part: longwave exchange is
//! computed explicitly by the surface balance (the legacy McAdams
//! `h = 5.7 + 3.8·v` folds in about 4-5 W m⁻² K⁻¹ of radiation and so
//! counted it twice; it survives only as [`super::balance::Convection::Linear`]
//! for the numerical reference tests).
//!
//! Sources:
//! * Allen, Pereira, Raes & Smith (1998), *Crop evapotranspiration*, FAO
//!   Irrigation and Drainage Paper 56 (FAO-56): eqs. 4 (aerodynamic
//!   resistance), 7-8 (pressure, psychrometric constant), 11-13 (saturation
//!   vapour pressure and its slope), 47 (log-law wind), Annex 3 (λ, ρ_a).
//! * Monteith & Unsworth (2013), *Principles of Environmental Physics*, 4th
//!   ed., ch. 16: bulk Richardson number and the Businger-Dyer / Webb
//!   stability functions for the transfer coefficient.
//! * Incropera, DeWitt, Bergman & Lavine (2007), *Fundamentals of Heat and
//!   Mass Transfer*, 6th ed., eqs. 9.26/9.31 and Table A.4: turbulent free
//!   convection from vertical and upward-facing heated plates,
//!   `Nu = C·Ra^(1/3)` (C = 0.10 vertical, 0.15 horizontal), which makes `h`
//!   independent of the plate size: `h = C·k·(gβ/(να))^(1/3)·ΔT^(1/3)`.
//! * Jarvis (1976), Phil. Trans. R. Soc. B 273, 593; in the form of Noilhan
//!   & Planton (1989), Mon. Wea. Rev. 117, 536, and Chen et al. (1996), J.
//!   Geophys. Res. 101, 7251 (the Noah land model): the canopy resistance.

use serde::{Deserialize, Serialize};

/// von Kármán constant (FAO-56 uses 0.41).
pub const VON_KARMAN: f64 = 0.41;
/// Standard gravity, m/s².
pub const GRAVITY_M_S2: f64 = 9.806_65;
/// Specific heat of moist air at constant pressure, J kg⁻¹ K⁻¹ (FAO-56
/// eq. 8: 1.013e-3 MJ kg⁻¹ °C⁻¹).
pub const CP_AIR_J_KGK: f64 = 1013.0;
/// Specific gas constant of dry air, J kg⁻¹ K⁻¹.
pub const R_DRY_AIR_J_KGK: f64 = 287.058;
/// Ratio of the molecular weights of water vapour and dry air.
pub const EPSILON_WATER: f64 = 0.622;
/// Specific heat of liquid water, J kg⁻¹ K⁻¹ (Incropera Table A.6, 300 K: 4179).
pub const CP_WATER_J_KGK: f64 = 4179.0;
/// Density of liquid water, kg/m³ (used for mm of water ↔ kg/m²).
pub const RHO_WATER_KG_M3: f64 = 1000.0;
use crate::units::ZERO_C_K;

/// Saturation vapour pressure over liquid water, Pa (FAO-56 eq. 11, the
/// Tetens form): `e°(T) = 610.8·exp(17.27·T/(T + 237.3))`, T in °C.
pub fn saturation_vapour_pressure_pa(temp_k: f64) -> f64 {
    let t = temp_k - ZERO_C_K;
    610.8 * (17.27 * t / (t + 237.3)).exp()
}

/// Slope of [`saturation_vapour_pressure_pa`], Pa/K (FAO-56 eq. 13:
/// `Δ = 4098·e°(T)/(T + 237.3)²`).
pub fn saturation_slope_pa_k(temp_k: f64) -> f64 {
    let t = temp_k - ZERO_C_K;
    4098.0 * saturation_vapour_pressure_pa(temp_k) / ((t + 237.3) * (t + 237.3))
}

/// Latent heat of vaporisation, J/kg (FAO-56 Annex 3 eq. 3-1:
/// `λ = 2.501 − 0.002361·T` MJ/kg, T in °C).
pub fn latent_heat_j_kg(temp_k: f64) -> f64 {
    2.501e6 - 2361.0 * (temp_k - ZERO_C_K)
}

/// Density of moist air, kg/m³, with the virtual temperature of FAO-56
/// Annex 3 eq. 3-5 (`T_v = 1.01·T`): `ρ_a = P/(R·1.01·T)`.
pub fn air_density_kg_m3(pressure_pa: f64, air_temp_k: f64) -> f64 {
    pressure_pa / (R_DRY_AIR_J_KGK * 1.01 * air_temp_k)
}

/// Psychrometric constant, Pa/K (FAO-56 eq. 8): `γ = c_p·P/(ε·λ)`.
pub fn psychrometric_pa_k(pressure_pa: f64, air_temp_k: f64) -> f64 {
    CP_AIR_J_KGK * pressure_pa / (EPSILON_WATER * latent_heat_j_kg(air_temp_k))
}

/// Wet-bulb temperature, K, from air temperature and relative humidity by
/// the empirical fit of Stull (2011), J. Appl. Meteor. Climatol. 50, 2267
/// (±0.3 K for RH 5-99 %, −20 to 50 °C at sea-level pressure); used as the
/// temperature of rain.
pub fn wet_bulb_k(air_temp_k: f64, dew_point_k: f64) -> f64 {
    let t = air_temp_k - ZERO_C_K;
    let rh = (100.0 * saturation_vapour_pressure_pa(dew_point_k)
        / saturation_vapour_pressure_pa(air_temp_k))
    .clamp(1.0, 100.0);
    let tw = t * (0.151_977 * (rh + 8.313_659).sqrt()).atan() + (t + rh).atan()
        - (rh - 1.676_331).atan()
        + 0.003_918_38 * rh.powf(1.5) * (0.023_101 * rh).atan()
        - 4.686_035;
    (tw + ZERO_C_K).min(air_temp_k)
}

/// The neutral logarithmic wind profile (FAO-56 eq. 47 is its special case
/// for a 0.12 m grass): `u(z) = u_ref·ln(z/z₀)/ln(z_ref/z₀)`.
/// Heights below `10·z₀` are raised to it (the log law holds only well
/// above the roughness elements).
pub fn log_law_wind_m_s(u_ref_m_s: f64, z_ref_m: f64, z_m: f64, z0_m: f64) -> f64 {
    let z = z_m.max(10.0 * z0_m);
    let zr = z_ref_m.max(10.0 * z0_m);
    u_ref_m_s.max(0.0) * (z / z0_m).ln() / (zr / z0_m).ln()
}

/// Neutral aerodynamic resistance to heat and vapour transfer, s/m
/// (FAO-56 eq. 4):
/// `r_a = ln((z_m − d)/z_om)·ln((z_h − d)/z_oh)/(k²·u_z)`
/// with wind and air temperature both taken at height `z_m` above the
/// surface (`z_m = z_h`), zero-plane displacement `d`, roughness lengths for
/// momentum `z_om` and heat `z_oh`. The wind is floored at
/// [`MIN_WIND_M_S`].
pub fn neutral_resistance_s_m(u_m_s: f64, z_m: f64, d_m: f64, z0m_m: f64, z0h_m: f64) -> f64 {
    let u = u_m_s.max(MIN_WIND_M_S);
    ((z_m - d_m) / z0m_m).ln() * ((z_m - d_m) / z0h_m).ln() / (VON_KARMAN * VON_KARMAN * u)
}

/// Smallest wind speed used in the aerodynamic resistance, m/s: an
/// anemometer's calm (0 m/s) still leaves gusts and meanders near the
/// surface; free convection takes over below it.
pub const MIN_WIND_M_S: f64 = 0.2;

/// Most unstable bulk Richardson number used: the Businger-Dyer form is
/// fitted for `−1 < z/L < 0`; beyond it (calm, hot surfaces) the flux is
/// that of free convection, which the blend with [`free_convection_coeff`]
/// supplies. At the cap the forced coefficient is 17^0.75 = 8.4 times its
/// neutral value.
pub const MIN_RICHARDSON: f64 = -1.0;

/// Most stable bulk Richardson number used: beyond it the exchange is held
/// at its value there, `F(0.2) = 1/(1 + 3·√2) = 0.191` of neutral — a
/// minimum exchange for calm clear nights. Without it the Louis function
/// falls to 0.01 of neutral at Ri = 2 (1 m/s and 1.5 K of inversion at
/// screen height), the modelled surface decouples from the air and runs
/// 2.5-3.5 K below measured skins, which stay within about 1 K of the air
/// (intermittent turbulence, meandering and gravity-wave mixing that the
/// bulk formula does not represent). The operational scheme SURFEX caps the
/// Richardson number the same way, `Ri = min(Ri, XRIMAX)` in its
/// SURFACE_RI (Masson et al. 2013, Geosci. Model Dev. 6, 929); 0.2 is the
/// critical Richardson number of the log-linear (Webb) profile, where
/// classical similarity has no turbulence left.
pub const MAX_RICHARDSON: f64 = 0.2;

/// Windless exchange coefficient `C_sk`, W m⁻² K⁻¹: the convective
/// exchange that remains when the forced turbulence stops, as SNTHERM
/// carries it (Jordan 1991, CRREL Special Report 91-16; its QTURB of
/// 2001/2002 floors a stable layer's coefficient, `qsen = max(qsen0,
/// max(Csk, 0.1))`, with `C_sk` a site input that its public ports set to 2).
/// Applied to snow surfaces only (the `snow` kind, as SNTHERM is a snow
/// model; on soils and canopies the station nights disagree on its sign:
/// docs/validation-stations.md), where it joins the cube blend of forced
/// and free convection, `h³ = h_f³ + C³·|ΔT| + C_sk³`
/// ([`Exchange::coefficient_and_slope`]), so `h` stays
/// smooth in `T_s` (a hard `max` made the surface Newton iteration cycle at
/// the kink) and is ≥ `C_sk` everywhere; where `h_f` ≥ 5 W m⁻² K⁻¹ (any
/// breeze by day) it adds under 0.3 %. Why: at 0.1-0.6 m/s over snow (z₀
/// 1 mm) the neutral coefficient itself is under 1.5 W m⁻² K⁻¹ and the
/// [`MAX_RICHARDSON`] cap leaves 0.19 of it, 0.1-0.3 W m⁻² K⁻¹: a calm clear
/// night then decoupled the snow from the air, 3.5 K colder than measured
/// (Col de Porte, docs/validation-stations.md). The value 1.0 is the
/// laminar free convection over a cooled, upward-facing surface: Incropera
/// et al. (2007) eq. 9.32, `Nu = 0.27·Ra^(1/4)`, gives `h =
/// 0.27·k·(gβΔT/(να))^(1/4)·L^(−1/4)` = 1.0-1.2 W m⁻² K⁻¹ for ΔT = 4-8 K in
/// air at 265 K over L = 1 m (0.6-0.7 at L = 10 m); held constant here (the
/// scene gives no length). SNTHERM's ported 2 W m⁻² K⁻¹ runs that snow day 2
/// K too warm; the day is within tolerance for 0.75-1.4.
pub const WINDLESS_EXCHANGE_W_M2K: f64 = 1.0;

/// Smallest stability factor `F = h/h_neutral` on snow, the stable-side
/// floor of Martin & Lejeune (1998, *Ann. Glaciol.* 26, 179), fitted at Col
/// de Porte to the turbulent fluxes over snow and kept by Crocus as its
/// `M98` option (SURFEX SURFACE_AERO_COND, Cluzet et al. 2016, *Geosci.
/// Model Dev.* 9, 3963; Lafaysse et al. 2017, *The Cryosphere* 11, 1173):
/// `C_H = max(0.75, (1 − 5·Ri)²)·C_HN` for `Ri ≥ 0`, i.e. never under 0.75
/// of neutral (Louis's function falls under it at Ri ≈ 0.03). Over snow the
/// measured exchange stays near neutral in stable air that the bulk
/// Richardson number calls strongly stable (Martin & Lejeune's finding:
/// intermittent turbulence and the shallow, sloping layers over a snow
/// field); without it the clear, stable Col de Porte night of 2001-12-31
/// (1.6-2.3 m/s) ran 3-5 K too cold (docs/validation-stations.md). Snow
/// only (the `snow` kind, [`Exchange::stable_floor`]), joined to
/// [`stability_factor`] by a smooth maximum
/// `F = (F_L⁸ + 0.75⁸)^(1/8)` ([`floored_stability_factor_and_slope`]),
/// at most 2^(1/8) − 1 = 9 % above the larger of the two (where they are
/// equal, Ri ≈ 0.03) and 1.2 % at neutral, so `h` stays smooth in `T_s`
/// for the surface Newton iteration. Unlike M98, the neutral coefficient
/// keeps the surface's own `z_oh` ([`HEAT_ROUGHNESS_RATIO`]).
pub const SNOW_STABLE_FLOOR: f64 = 0.75;

/// [`stability_factor_and_slope`] joined to a floor `floor` (0: none) by
/// the smooth maximum `F = (F_L⁸ + floor⁸)^(1/8)`, with `dF/dRi =
/// (F_L/F)⁷·dF_L/dRi` ([`SNOW_STABLE_FLOOR`]).
pub fn floored_stability_factor_and_slope(richardson: f64, floor: f64) -> (f64, f64) {
    let (f, df) = stability_factor_and_slope(richardson);
    if floor <= 0.0 {
        return (f, df);
    }
    let s = (f.powi(8) + floor.powi(8)).powf(0.125);
    (s, df * (f / s).powi(7))
}

/// Stability factor `F(Ri) = h/h_neutral` of the bulk transfer coefficient
/// for heat. Unstable `Ri < 0`: `(1 − 16·Ri)^0.75` (Monteith & Unsworth
/// 2013, §16.2, after Businger-Dyer), Ri capped at [`MIN_RICHARDSON`].
/// Stable `Ri > 0`: Louis (1979), Boundary-Layer Meteorol. 17, 187, eq. 21
/// with b = d = 5: `1/(1 + 3b·Ri·√(1 + d·Ri))` — smooth and long-tailed —
/// with Ri capped at [`MAX_RICHARDSON`] (a minimum exchange).
pub fn stability_factor(richardson: f64) -> f64 {
    stability_factor_and_slope(richardson).0
}

/// [`stability_factor`] `F(Ri)` and its derivative `dF/dRi`:
/// unstable `−12·F/(1 − 16·Ri)` (0 below the cap [`MIN_RICHARDSON`]);
/// stable `−F²·15·(w + 2.5·Ri/w)`, `w = √(1 + 5·Ri)` (0 above the cap
/// [`MAX_RICHARDSON`]).
pub fn stability_factor_and_slope(richardson: f64) -> (f64, f64) {
    if richardson < 0.0 {
        let base = 1.0 - 16.0 * richardson.max(MIN_RICHARDSON);
        let f = base.powf(0.75);
        let slope = if richardson < MIN_RICHARDSON {
            0.0
        } else {
            -12.0 * f / base
        };
        (f, slope)
    } else {
        let ri = richardson.min(MAX_RICHARDSON);
        let w = (1.0 + 5.0 * ri).sqrt();
        let f = 1.0 / (1.0 + 15.0 * ri * w);
        let slope = if richardson > MAX_RICHARDSON {
            0.0
        } else {
            -f * f * 15.0 * (w + 2.5 * ri / w)
        };
        (f, slope)
    }
}

/// Bulk Richardson number per kelvin of `T_air − T_surface`:
/// `Ri = g·(z − d)·(T_a − T_s)/(T_a·u²)` (Monteith & Unsworth 2013, eq.
/// 16.23), so `Ri = richardson_per_k · (T_a − T_s)`; negative (unstable)
/// when the surface is warmer than the air.
pub fn richardson_per_k(u_m_s: f64, z_m: f64, d_m: f64, air_temp_k: f64) -> f64 {
    let u = u_m_s.max(MIN_WIND_M_S);
    GRAVITY_M_S2 * (z_m - d_m) / (air_temp_k * u * u)
}

/// Free-convection coefficient `C` of `h_free = C·|ΔT|^(1/3)`, W m⁻² K⁻⁴ᐟ³,
/// for turbulent free convection (Incropera et al. 2007, eq. 9.26 vertical
/// `Nu = 0.10·Ra^(1/3)`, eq. 9.31 heated plate facing up `Nu =
/// 0.15·Ra^(1/3)`), with air properties at 300 K (Table A.4: k = 0.0263 W
/// m⁻¹ K⁻¹, ν = 15.89e-6 m²/s, α = 22.5e-6 m²/s, β = 1/300 K⁻¹):
/// `k·(gβ/(να))^(1/3)` = 11.85 W m⁻² K⁻⁴ᐟ³, so 1.19 (vertical) and 1.78
/// (horizontal, unstable side).
pub const FREE_CONVECTION_AIR_300K: f64 = 11.85;

/// `C` for a facet of slope β (degrees from horizontal, > 90 faces down)
/// when the surface is warmer (`surface_warmer`) or colder than the air:
/// the unstable horizontal value 1.78 on the side where the buoyant
/// boundary layer rises freely (warm facing up, cold facing down), the
/// vertical 1.19 for walls, blended linearly in |cos β|, and nothing on the
/// stable side of a horizontal plate (the laminar `Ra^(1/4)` regime there
/// is weak and size-dependent; it is left out).
pub fn free_convection_coeff(slope_deg: f64, surface_warmer: bool) -> f64 {
    let vertical = 0.10 * FREE_CONVECTION_AIR_300K;
    let horizontal = 0.15 * FREE_CONVECTION_AIR_300K;
    let c = slope_deg.to_radians().cos();
    let facing = if surface_warmer { c } else { -c };
    if facing >= 0.0 {
        vertical + (horizontal - vertical) * facing
    } else {
        vertical * (1.0 + facing)
    }
}

/// Mixed forced + free convection: `h = (h_forced³ + h_free³)^(1/3)`
/// (Churchill 1977, AIChE J. 23, 10: the n = 3 blending of assisting
/// forced and natural convection).
pub fn blend_convection(h_forced: f64, h_free: f64) -> f64 {
    (h_forced.powi(3) + h_free.powi(3)).cbrt()
}

/// Where the weather's wind and air temperature were measured and the
/// terrain around the scene: what carries the station wind to each facet.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SurfaceLayer {
    /// Anemometer height of the weather record, m above ground (10 m for
    /// WMO/ASOS stations, TMY3 and EPW).
    pub wind_height_m: f64,
    /// Height above each surface at which the air temperature and humidity
    /// are taken to hold, m (screen height 2 m; FAO-56's reference).
    pub air_height_m: f64,
    /// Roughness length of the site's terrain, m, for moving the wind from
    /// the anemometer to a facet's height (0.03 m: WMO "open" terrain,
    /// short grass and airfields, Wieringa 1992 / WMO-No. 8 Annex 1.B).
    pub site_roughness_m: f64,
}

impl Default for SurfaceLayer {
    fn default() -> Self {
        SurfaceLayer {
            wind_height_m: 10.0,
            air_height_m: 2.0,
            site_roughness_m: 0.03,
        }
    }
}

impl SurfaceLayer {
    /// Checks the heights and roughness (finite; 0.5 ≤ heights ≤ 200 m;
    /// 1e-5 ≤ z₀ ≤ 2 m).
    pub fn validate(&self) -> Result<(), String> {
        for (k, v, lo, hi) in [
            ("wind_height_m", self.wind_height_m, 0.5, 200.0),
            ("air_height_m", self.air_height_m, 0.5, 200.0),
            ("site_roughness_m", self.site_roughness_m, 1e-5, 2.0),
        ] {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(format!("{k} = {v}: expected {lo} to {hi} m"));
            }
        }
        Ok(())
    }
}

/// Ratio of the roughness length for heat and vapour to that for momentum,
/// `z_oh/z_om`, of every surface (solids, water, canopies): 0.1, FAO-56 eq.
/// 4 box (Allen et al. 1998; kB⁻¹ = ln 10 ≈ 2.3).
pub const HEAT_ROUGHNESS_RATIO: f64 = 0.1;

/// Aerodynamic roughness of one surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Roughness {
    /// Zero-plane displacement d, m.
    pub displacement_m: f64,
    /// Roughness length for momentum z_om, m.
    pub momentum_m: f64,
    /// Roughness length for heat and vapour z_oh, m.
    pub heat_m: f64,
}

impl Roughness {
    /// A canopy of height `h` (FAO-56 eq. 4 box): `d = 2/3·h`,
    /// `z_om = 0.123·h`, `z_oh = 0.1·z_om`.
    pub fn canopy(height_m: f64) -> Roughness {
        Roughness::canopy_with_heat_ratio(height_m, HEAT_ROUGHNESS_RATIO)
    }

    /// A canopy of height `h` with `z_oh = ratio·z_om` (the material key
    /// `heat_roughness_ratio`): `d = 2/3·h`, `z_om = 0.123·h` (FAO-56 eq. 4
    /// box). FAO-56's ratio is 0.1 (kB⁻¹ = ln 10 ≈ 2.3, crops and grass);
    /// the ECMWF land surface scheme takes `z_oh = z_om` (ratio 1, kB⁻¹ =
    /// 0) for every tree type (ecLand/IFS `SUSVEG`: `RVZ0H = RVZ0M` for
    /// needleleaf, broadleaf and mixed forest; `RVZ0M/10` for low
    /// vegetation): over tall, rough canopies the exchange of heat is about
    /// as efficient as that of momentum (Garratt 1992, *The Atmospheric
    /// Boundary Layer*, §4.2: kB⁻¹ ≈ 0-2 over forests against ≈ 2 over
    /// crops). Written as `0.0123·h·(ratio/0.1)` so the default ratio gives
    /// FAO-56's `0.0123·h` bit for bit.
    pub fn canopy_with_heat_ratio(height_m: f64, ratio: f64) -> Roughness {
        Roughness {
            displacement_m: 2.0 / 3.0 * height_m,
            momentum_m: 0.123 * height_m,
            heat_m: 0.0123 * height_m * (ratio / HEAT_ROUGHNESS_RATIO),
        }
    }

    /// A bare surface of momentum roughness `z0m` with
    /// `z_oh = HEAT_ROUGHNESS_RATIO·z_om` = z_om/10 (kB⁻¹ = ln 10 ≈ 2.3, the
    /// ratio FAO-56 uses).
    pub fn bare(z0m_m: f64) -> Roughness {
        Roughness {
            displacement_m: 0.0,
            momentum_m: z0m_m,
            heat_m: HEAT_ROUGHNESS_RATIO * z0m_m,
        }
    }
}

/// Temperature-independent exchange quantities of one facet at one
/// instant; with the surface temperature they give the convective
/// coefficient ([`Exchange::coefficient_and_slope`]) and so the sensible flux
/// ([`super::balance::Convection::flux_w_m2`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Exchange {
    /// Wind at the facet's reference height, m/s.
    pub wind_m_s: f64,
    /// Neutral forced-convection coefficient ρ·c_p/r_a, W m⁻² K⁻¹.
    pub h_neutral_w_m2k: f64,
    /// Bulk Richardson number per K of (T_air − T_surface).
    pub richardson_per_k: f64,
    /// Free-convection coefficients when the surface is warmer / colder
    /// than the air, W m⁻² K⁻⁴ᐟ³.
    pub free_warm: f64,
    /// Free-convection coefficient when the surface is colder than the air, W m⁻² K⁻⁴ᐟ³.
    pub free_cold: f64,
    /// ρ_a·c_p, J m⁻³ K⁻¹.
    pub rho_cp_j_m3k: f64,
    /// Windless exchange `C_sk` in the blend, W m⁻² K⁻¹: 0 from
    /// [`Exchange::new`]; [`WINDLESS_EXCHANGE_W_M2K`] on snow (set by the
    /// slab model for the `snow` kind).
    #[serde(default)]
    pub windless_w_m2k: f64,
    /// Smallest stability factor (smooth floor), 0 from [`Exchange::new`];
    /// [`SNOW_STABLE_FLOOR`] on snow (set by the slab model for the `snow`
    /// kind).
    #[serde(default)]
    pub stable_floor: f64,
}

impl Exchange {
    /// The exchange of a facet with roughness `rough`, slope `slope_deg`
    /// and base height `facet_height_m` above the ground, under station wind
    /// `station_wind_m_s`: the wind is moved by the log law over the site's
    /// roughness to `facet_height + d + air_height` (the reference height of
    /// this facet's surface layer), and `r_a` follows FAO-56 eq. 4 between
    /// the surface and `air_height` above the displacement height.
    pub fn new(
        layer: &SurfaceLayer,
        rough: &Roughness,
        slope_deg: f64,
        facet_height_m: f64,
        station_wind_m_s: f64,
        air_temp_k: f64,
        pressure_pa: f64,
    ) -> Exchange {
        let z_ref = rough.displacement_m + layer.air_height_m.max(2.0 * rough.momentum_m);
        let u = log_law_wind_m_s(
            station_wind_m_s,
            layer.wind_height_m,
            facet_height_m.max(0.0) + z_ref,
            layer.site_roughness_m,
        );
        let r_a = neutral_resistance_s_m(
            u,
            z_ref,
            rough.displacement_m,
            rough.momentum_m,
            rough.heat_m,
        );
        let rho_cp = air_density_kg_m3(pressure_pa, air_temp_k) * CP_AIR_J_KGK;
        // The Richardson correction is a property of a horizontal surface
        // layer; walls get the neutral value (their free convection is in
        // the blend).
        let horiz = slope_deg.to_radians().cos().abs();
        Exchange {
            wind_m_s: u,
            h_neutral_w_m2k: rho_cp / r_a,
            richardson_per_k: horiz * richardson_per_k(u, z_ref, rough.displacement_m, air_temp_k),
            free_warm: free_convection_coeff(slope_deg, true),
            free_cold: free_convection_coeff(slope_deg, false),
            rho_cp_j_m3k: rho_cp,
            windless_w_m2k: 0.0,
            stable_floor: 0.0,
        }
    }

    /// Convective coefficient `h` at surface temperature `surf_temp_k`,
    /// `(h_n·F(Ri))³ + (C·|ΔT|^(1/3))³ + C_sk³` blended (W m⁻² K⁻¹; `C_sk` =
    /// [`Exchange::windless_w_m2k`], a constant, so it leaves the slope's
    /// form unchanged), and its
    /// analytic derivative `dh/dT_s`, W m⁻² K⁻². With `ΔT = T_a − T_s`, `h_f =
    /// h_n·F(Ri)`, `Ri = Ri_K·ΔT` and `h³ = h_f³ + C³·|ΔT|` (the free term
    /// cubed analytically, so one cube root, not two):
    /// `dh/dΔT = (h_f²·h_n·F'(Ri)·Ri_K + C³·sgn(ΔT)/3)/h²` and `dh/dT_s =
    /// −dh/dΔT`. On the kink at ΔT = 0 (C switches between its warm and
    /// cold values) the one-sided derivative of the side `ΔT` is on.
    pub fn coefficient_and_slope(&self, air_temp_k: f64, surf_temp_k: f64) -> (f64, f64) {
        let dt = air_temp_k - surf_temp_k;
        let (f, df) =
            floored_stability_factor_and_slope(self.richardson_per_k * dt, self.stable_floor);
        let forced = self.h_neutral_w_m2k * f;
        let c = if dt < 0.0 {
            self.free_warm
        } else {
            self.free_cold
        };
        let c3 = c * c * c;
        let w = self.windless_w_m2k;
        let h = (forced * forced * forced + c3 * dt.abs() + w * w * w).cbrt();
        if h <= 0.0 {
            return (h, 0.0);
        }
        let dh_ddt = (forced * forced * self.h_neutral_w_m2k * df * self.richardson_per_k
            + c3 * dt.signum() / 3.0)
            / (h * h);
        (h, -dh_ddt)
    }
}

/// The canopy (stomatal) resistance of a vegetated surface, s/m, in the
/// Jarvis form of the Noah land model (Chen et al. 1996, eqs. 11-14;
/// Noilhan & Planton 1989):
/// `r_s = r_s,min/(LAI·F₁·F₂·F₃·F₄)`, with
/// * radiation `F₁ = (r_s,min/r_s,max + f)/(1 + f)`, `f = 0.55·(S/R_gl)·(2/LAI)`,
///   S the incident shortwave, W/m²;
/// * vapour deficit `F₂ = 1/(1 + h_s·(q_sat(T_a) − q_a))`, q in kg/kg;
/// * temperature `F₃ = 1 − 0.0016·(298 − T_a)²` (floored at 0.05);
/// * soil moisture `F₄` = relative available water in the root zone,
///   0 (wilting point) … 1 (field capacity and wetter) (floored at 0.01).
///
/// The result is capped at `r_s,max`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Canopy {
    /// Canopy height, m (sets d, z_om, z_oh by
    /// [`Roughness::canopy_with_heat_ratio`]).
    pub height_m: f64,
    /// Leaf area index, m²/m².
    pub lai: f64,
    /// Minimum (unstressed, per unit LAI) stomatal resistance r_s,min, s/m.
    pub min_resistance_s_m: f64,
    /// Largest (cuticular) resistance r_s,max, s/m.
    pub max_resistance_s_m: f64,
    /// Radiation at which F₁ is about half its range, R_gl, W/m².
    pub radiation_limit_w_m2: f64,
    /// Vapour-deficit parameter h_s, (kg/kg)⁻¹.
    pub vpd_coeff: f64,
    /// Relative available soil water, 0 … 1 (F₄).
    pub soil_moisture: f64,
    /// Conductance between the canopy skin and the soil surface under it,
    /// W m⁻² K⁻¹: the skin-layer conductivity Λ_sk of the ECMWF land
    /// surface scheme (Viterbo & Beljaars 1995, J. Climate 8, 2716; IFS
    /// documentation Part IV ch. 8, and ecLand's SUSVEG: 10 for crops and
    /// grass, 15 for bare ground). It lumps conduction through the litter
    /// and the air under the canopy, longwave between leaves and soil and
    /// the under-canopy turbulent exchange.
    pub skin_conductance_w_m2k: f64,
    /// Heat capacity of the canopy skin per unit ground area, J m⁻² K⁻¹
    /// (leaves and stems; [`CANOPY_HEAT_CAPACITY_PER_LAI_J_M2K`] × LAI by
    /// default).
    pub heat_capacity_j_m2k: f64,
    /// Fraction of the absorbed shortwave that reaches the soil surface
    /// through the canopy (ecLand SUSVEG `RVTRSR`: 0.05 for crops and
    /// grass, 0.03 for forests).
    pub soil_shortwave_fraction: f64,
    /// Ratio of the roughness length for heat and vapour to that for
    /// momentum, `z_oh/z_om` ([`Roughness::canopy_with_heat_ratio`]):
    /// [`HEAT_ROUGHNESS_RATIO`] (0.1, FAO-56) by default, 1 for trees in the
    /// ECMWF scheme.
    #[serde(default = "default_heat_roughness_ratio")]
    pub heat_roughness_ratio: f64,
}

fn default_heat_roughness_ratio() -> f64 {
    HEAT_ROUGHNESS_RATIO
}

/// Heat capacity of a canopy per unit leaf area index, J m⁻² K⁻¹: fresh
/// leaf mass 0.1-0.3 kg per m² of leaf (specific leaf mass and a leaf water
/// content of ~80 %) times c ≈ 3.5 kJ kg⁻¹ K⁻¹ gives 0.35-1 kJ m⁻² K⁻¹; with
/// stems, 1 kJ m⁻² K⁻¹ (an estimate; the ECMWF skin has none, Noah-MP a
/// few hundred J m⁻² K⁻¹ per unit LAI). The skin's time constant
/// `C/(Λ_sk + h + 4εσT³)` is minutes, so the value matters little.
pub const CANOPY_HEAT_CAPACITY_PER_LAI_J_M2K: f64 = 1000.0;

impl Canopy {
    /// Canopy resistance, s/m, for incident shortwave `shortwave_w_m2`, air
    /// temperature, vapour pressure and air pressure.
    pub fn resistance_s_m(
        &self,
        shortwave_w_m2: f64,
        air_temp_k: f64,
        vapour_pressure_pa: f64,
        pressure_pa: f64,
    ) -> f64 {
        let lai = self.lai.max(1e-3);
        let f = 0.55 * (shortwave_w_m2.max(0.0) / self.radiation_limit_w_m2) * (2.0 / lai);
        let f1 = (self.min_resistance_s_m / self.max_resistance_s_m + f) / (1.0 + f);
        let deficit = (specific_humidity(saturation_vapour_pressure_pa(air_temp_k), pressure_pa)
            - specific_humidity(vapour_pressure_pa, pressure_pa))
        .max(0.0);
        let f2 = 1.0 / (1.0 + self.vpd_coeff * deficit);
        let f3 = (1.0 - 0.0016 * (298.0 - air_temp_k).powi(2)).max(0.05);
        let f4 = self.soil_moisture.clamp(0.01, 1.0);
        (self.min_resistance_s_m / (lai * f1 * f2 * f3 * f4)).min(self.max_resistance_s_m)
    }
}

/// Specific humidity, kg/kg, of vapour pressure `e` at pressure `P`:
/// `q = ε·e/(P − (1 − ε)·e)`.
pub fn specific_humidity(vapour_pressure_pa: f64, pressure_pa: f64) -> f64 {
    EPSILON_WATER * vapour_pressure_pa / (pressure_pa - (1.0 - EPSILON_WATER) * vapour_pressure_pa)
}

/// Latent heat flux *into* the surface (negative while evaporating), W/m²,
/// and its derivative with respect to the surface temperature:
/// `λE = (ρ_a·c_p/γ)·(e°(T_s) − e_a)/(r_a + r_s)` (the resistance form
/// that FAO-56 eq. 3, Penman-Monteith, linearises; here `T_s` is solved
/// for, so no linearisation is needed), with `r_a = ρ_a·c_p/h`.
/// `conductance_m_s = 1/r_s` (0: a dry surface, no flux). Condensation
/// (`e°(T_s) < e_a`) meets no surface resistance (dew forms on the
/// surface) when `dew` is true, else no flux. Evaporation is limited to
/// `evaporation_cap_w_m2` (a drying store).
///
/// Returns the flux, its derivative with respect to `T_s` at fixed `h`
/// (`−(ρ_a·c_p/γ)·g·Δ(T_s)`, Δ the slope of e°) and its derivative with
/// respect to `h` (`−(ρ_a·c_p/γ)·(e°(T_s) − e_a)·dg/dh`, `g = 1/(r_a +
/// r_s)`, `dg/dh = g²·ρ_a·c_p/h²`; 0 on the cap), so that a caller whose
/// `h` depends on `T_s` has the total derivative.
#[allow(clippy::too_many_arguments)]
pub fn latent_w_m2(
    h_w_m2k: f64,
    rho_cp_j_m3k: f64,
    conductance_m_s: f64,
    dew: bool,
    evaporation_cap_w_m2: f64,
    vapour_pressure_pa: f64,
    pressure_pa: f64,
    air_temp_k: f64,
    surf_temp_k: f64,
) -> (f64, f64, f64) {
    let es = saturation_vapour_pressure_pa(surf_temp_k);
    let deficit = es - vapour_pressure_pa;
    let r_a = rho_cp_j_m3k / h_w_m2k.max(1e-6);
    let g = if deficit >= 0.0 {
        if conductance_m_s <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        1.0 / (r_a + 1.0 / conductance_m_s)
    } else if dew {
        1.0 / r_a
    } else {
        return (0.0, 0.0, 0.0);
    };
    let per_g = rho_cp_j_m3k / psychrometric_pa_k(pressure_pa, air_temp_k);
    let coeff = per_g * g;
    let out = coeff * deficit;
    if out > evaporation_cap_w_m2 {
        return (-evaporation_cap_w_m2, 0.0, 0.0);
    }
    let dg_dh = if h_w_m2k > 1e-6 {
        g * g * rho_cp_j_m3k / (h_w_m2k * h_w_m2k)
    } else {
        0.0
    };
    (
        -out,
        -coeff * saturation_slope_pa_k(surf_temp_k),
        -per_g * deficit * dg_dh,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FAO-56 Table 2.3 / Annex 2 and example 3: e°(20 °C) = 2.338 kPa,
    /// e°(30 °C) = 4.243 kPa, Δ(20 °C) = 0.145 kPa/°C; λ(20 °C) = 2.454
    /// MJ/kg (Annex 3); γ at 101.3 kPa = 0.0674 kPa/°C (Table 2.2, which
    /// uses λ = 2.45). Published values are rounded to the digits shown.
    #[test]
    fn moist_air_against_fao56_tables() {
        let k = |c: f64| c + ZERO_C_K;
        assert!((saturation_vapour_pressure_pa(k(20.0)) - 2338.0).abs() < 1.0);
        assert!((saturation_vapour_pressure_pa(k(30.0)) - 4243.0).abs() < 1.0);
        assert!((saturation_slope_pa_k(k(20.0)) - 144.7).abs() < 0.5);
        assert!((latent_heat_j_kg(k(20.0)) - 2.454e6).abs() < 1e3);
        let gamma = CP_AIR_J_KGK * 101_300.0 / (EPSILON_WATER * 2.45e6);
        assert!((gamma - 67.4).abs() < 0.1, "{gamma}");
        // Slope against a central difference of e°.
        let t = k(25.0);
        let num = (saturation_vapour_pressure_pa(t + 0.01)
            - saturation_vapour_pressure_pa(t - 0.01))
            / 0.02;
        assert!((num - saturation_slope_pa_k(t)).abs() < 1e-3 * num);
    }

    /// Stull (2011) fig./text check value: T = 20 °C, RH = 50 % →
    /// T_w = 13.7 °C.
    #[test]
    fn wet_bulb_stull_check_value() {
        let ta = 293.15;
        // dew point for RH 50 % at 20 °C from the inverse Tetens form
        let e = 0.5 * saturation_vapour_pressure_pa(ta);
        let x = (e / 610.8).ln();
        let td = 237.3 * x / (17.27 - x) + ZERO_C_K;
        let tw = wet_bulb_k(ta, td) - ZERO_C_K;
        assert!((tw - 13.7).abs() < 0.05, "{tw}");
    }

    /// Published values of the chosen exchange formulas (a table):
    /// FAO-56 eq. 4 box: r_a = 208/u₂ s/m for the 0.12 m reference grass
    /// with z_m = z_h = 2 m; FAO-56 eq. 47: u₂ = 0.748·u₁₀ for the grass
    /// profile (4.87/ln(67.8·10 − 5.42) = 0.748); Incropera turbulent free
    /// convection h = 0.15·k·(gβ/να)^(1/3)·ΔT^(1/3): 1.78 W m⁻² K⁻¹ at
    /// ΔT = 1 K (heated plate facing up), 1.19 vertical.
    #[test]
    fn exchange_coefficients_against_published_values() {
        // (u2, r_a published = 208/u2) — FAO-56 box 4 rounds to 3 digits.
        for u2 in [0.5, 1.0, 2.0, 4.0, 8.0] {
            let ra = neutral_resistance_s_m(
                u2,
                2.0,
                Roughness::canopy(0.12).displacement_m,
                Roughness::canopy(0.12).momentum_m,
                Roughness::canopy(0.12).heat_m,
            );
            assert!(
                (ra * u2 - 208.0).abs() < 1.0,
                "u2 {u2}: r_a·u2 = {}",
                ra * u2
            );
        }
        // FAO-56 eq. 47, u2 = u_z·4.87/ln(67.8·z − 5.42), is the log law with
        // d = 0.08 m and z0 = 1/67.8 m: ln(67.8 z − 5.42) = ln((z − 0.08)/0.014749).
        let fao = 4.87 / (67.8f64 * 10.0 - 5.42).ln();
        assert!((fao - 0.748).abs() < 5e-4);
        let ours = log_law_wind_m_s(1.0, 10.0 - 0.08, 2.0 - 0.08, 1.0 / 67.8);
        assert!((ours - fao).abs() < 1e-3, "{ours} vs {fao}");
        assert!((free_convection_coeff(0.0, true) - 1.78).abs() < 0.01);
        assert!((free_convection_coeff(90.0, true) - 1.19).abs() < 0.01);
        assert!((free_convection_coeff(90.0, false) - 1.19).abs() < 0.01);
        assert_eq!(free_convection_coeff(0.0, false), 0.0);
        assert!((free_convection_coeff(180.0, false) - 1.78).abs() < 0.01);
    }

    /// The analytic `dh/dT_s` (and so the sensible flux's derivative, as
    /// the surface balance takes it) against a central difference of the coefficient (1e-5 K step,
    /// agreement to 1e-6 relative) on walls and horizontal facets, in calm
    /// and wind, stable and unstable, and past the Richardson cap; the
    /// stability slope against a central difference of `F(Ri)`.
    #[test]
    fn coefficient_slope_against_central_difference() {
        for ri in [-0.9, -0.3, -1e-3, 1e-3, 0.05, 0.15] {
            let (_, df) = stability_factor_and_slope(ri);
            let num = (stability_factor(ri + 1e-7) - stability_factor(ri - 1e-7)) / 2e-7;
            assert!(
                (num - df).abs() < 1e-6 * num.abs(),
                "Ri {ri}: {num} vs {df}"
            );
        }
        assert_eq!(stability_factor_and_slope(-2.0).1, 0.0);
        assert_eq!(stability_factor_and_slope(0.5).1, 0.0);
        let layer = SurfaceLayer::default();
        for (slope_deg, wind) in [
            (0.0, 0.3),
            (0.0, 4.0),
            (90.0, 1.0),
            (30.0, 0.0),
            (150.0, 2.0),
        ] {
            let ex = Exchange::new(
                &layer,
                &Roughness::bare(0.01),
                slope_deg,
                0.0,
                wind,
                295.0,
                1e5,
            );
            let conv = crate::therm::balance::Convection::SurfaceLayer(layer);
            let h_at = |t: f64| ex.coefficient_and_slope(295.0, t).0;
            let q_at = |t: f64| conv.flux_w_m2(&ex, wind, 295.0, t);
            // ΔT from −40 K (surface much warmer: capped) to +15 K (stable).
            for surf in [335.0, 310.0, 300.0, 296.0, 294.5, 290.0, 280.0] {
                let (h, dh) = ex.coefficient_and_slope(295.0, surf);
                let d = 1e-5;
                let num = (h_at(surf + d) - h_at(surf - d)) / (2.0 * d);
                assert!(
                    (num - dh).abs() < 1e-6 * num.abs().max(1e-3 * h),
                    "slope {slope_deg} wind {wind} T_s {surf}: {num} vs {dh}"
                );
                let (q, dq, h2) = q_at(surf);
                assert_eq!((q, h2), (h * (295.0 - surf), h));
                let num_q = (q_at(surf + d).0 - q_at(surf - d).0) / (2.0 * d);
                assert!((num_q - dq).abs() < 1e-6 * num_q.abs(), "{num_q} vs {dq}");
            }
        }
    }

    /// The windless exchange (on snow): a calm clear night over snow (0.3 m/s at 2
    /// m, z₀ 1 mm, surface 8 K under the air) has a surface-layer
    /// coefficient under 0.3 W m⁻² K⁻¹ and gets `C_sk` (cube-blended: within
    /// 1 %); in a 5 m/s wind the same inversion keeps its own coefficient
    /// (within 0.5 %); and h is continuous across ΔT = 0.
    #[test]
    fn windless_exchange_keeps_calm_layers_coupled() {
        let layer = SurfaceLayer {
            wind_height_m: 2.0,
            air_height_m: 2.0,
            site_roughness_m: 0.001,
        };
        let rough = Roughness::bare(0.001);
        let snow = |u: f64| Exchange {
            windless_w_m2k: WINDLESS_EXCHANGE_W_M2K,
            ..Exchange::new(&layer, &rough, 0.0, 0.0, u, 270.0, 86_000.0)
        };
        let calm = snow(0.3);
        let bare = Exchange::new(&layer, &rough, 0.0, 0.0, 0.3, 270.0, 86_000.0);
        assert!(
            bare.coefficient_and_slope(270.0, 262.0).0 < 0.3,
            "no C_sk off snow"
        );
        let raw = calm.h_neutral_w_m2k * stability_factor(calm.richardson_per_k * 8.0);
        assert!(raw < 0.3, "surface-layer h {raw}");
        let (h, _) = calm.coefficient_and_slope(270.0, 262.0);
        assert!(
            (h - WINDLESS_EXCHANGE_W_M2K).abs() < 0.01 * WINDLESS_EXCHANGE_W_M2K,
            "{h}"
        );
        let windy = snow(5.0);
        let (h, _) = windy.coefficient_and_slope(270.0, 262.0);
        let own = windy.h_neutral_w_m2k * stability_factor(windy.richardson_per_k * 8.0);
        assert!(own > 5.0 && (h - own).abs() < 0.005 * own, "{h} vs {own}");
        let below = calm.coefficient_and_slope(270.0, 270.0 + 1e-9).0;
        let above = calm.coefficient_and_slope(270.0, 270.0 - 1e-9).0;
        assert!((below - above).abs() < 1e-6 && below >= WINDLESS_EXCHANGE_W_M2K);
    }

    /// The stable floor of snow (Martin & Lejeune 1998): F stays within
    /// 2^(1/8) (9 %) of max(F_Louis, 0.75) for −1 ≤ Ri ≤ 10, is 0.75 (to 1e-4) in
    /// strongly stable air where Louis gives 0.19, leaves neutral within
    /// 1.2 %, and its slope matches a central difference; an exchange
    /// without the floor (every surface but snow) is unchanged bit for bit.
    #[test]
    fn snow_stable_floor_keeps_stable_snow_near_neutral() {
        for i in -100..=1000 {
            let ri = i as f64 * 0.01;
            let (f, df) = floored_stability_factor_and_slope(ri, SNOW_STABLE_FLOOR);
            let plain = stability_factor(ri).max(SNOW_STABLE_FLOOR);
            assert!(f >= plain && f <= 1.0906 * plain, "{ri}: {f} vs {plain}");
            let d = 1e-6;
            if (ri - MAX_RICHARDSON).abs() > 2.0 * d
                && (ri - MIN_RICHARDSON).abs() > 2.0 * d
                && ri != 0.0
            {
                let num = (floored_stability_factor_and_slope(ri + d, SNOW_STABLE_FLOOR).0
                    - floored_stability_factor_and_slope(ri - d, SNOW_STABLE_FLOOR).0)
                    / (2.0 * d);
                assert!(
                    (num - df).abs() < 1e-5 + 1e-5 * df.abs(),
                    "{ri}: {num} vs {df}"
                );
            }
            assert_eq!(
                floored_stability_factor_and_slope(ri, 0.0),
                stability_factor_and_slope(ri)
            );
        }
        let neutral = floored_stability_factor_and_slope(0.0, SNOW_STABLE_FLOOR).0;
        assert!(neutral > 1.0 && neutral < 1.012, "{neutral}");
        let deep = floored_stability_factor_and_slope(1.0, SNOW_STABLE_FLOOR).0;
        assert!((deep - SNOW_STABLE_FLOOR).abs() < 1e-4, "{deep}");
        assert!((stability_factor(1.0) - 0.1907).abs() < 1e-4);
    }

    /// Stability: neutral 1; Businger-Dyer at Ri = −0.1: 2.6^0.75; Louis
    /// (1979) eq. 21 (b = d = 5) stable at Ri = 0.1 and at the cap 0.2:
    /// 1/(1 + 1.5·√1.5) = 0.3524, 1/(1 + 3·√2) = 0.1907; beyond the cap
    /// (Ri = 1, 10) the cap's value (the minimum exchange), not Louis's
    /// 1/(1 + 15·√6) = 0.0266.
    #[test]
    fn stability_factor_values() {
        assert_eq!(stability_factor(0.0), 1.0);
        assert!((stability_factor(-0.1) - 2.6f64.powf(0.75)).abs() < 1e-12);
        assert!((stability_factor(0.1) - 0.3524).abs() < 1e-4);
        assert!((stability_factor(0.2) - 0.1907).abs() < 1e-4);
        assert_eq!(stability_factor(1.0), stability_factor(0.2));
        assert_eq!(stability_factor(10.0), stability_factor(0.2));
        assert!((stability_factor(-5.0) - 17f64.powf(0.75)).abs() < 1e-12);
    }

    /// The Penman-Monteith resistance form: flux sign, derivative against a
    /// central difference, the cap, dew.
    #[test]
    fn latent_flux_form() {
        let (h, rho_cp) = (10.0, 1.2 * 1013.0);
        let ea = 1500.0;
        let f = |t: f64, h: f64| {
            latent_w_m2(
                h,
                rho_cp,
                1.0 / 70.0,
                true,
                f64::INFINITY,
                ea,
                101_325.0,
                300.0,
                t,
            )
        };
        let (q, dq, dq_dh) = f(300.0, h);
        assert!(q < 0.0, "evaporation takes heat from the surface");
        let num = (f(300.001, h).0 - f(299.999, h).0) / 0.002;
        assert!((num - dq).abs() < 1e-4 * num.abs());
        let num_h = (f(300.0, h + 1e-3).0 - f(300.0, h - 1e-3).0) / 2e-3;
        assert!(
            (num_h - dq_dh).abs() < 1e-6 * num_h.abs(),
            "{num_h} {dq_dh}"
        );
        // Dew (no surface resistance, g = h/ρc_p): the h-derivative too.
        let fd = |h: f64| latent_w_m2(h, rho_cp, 0.0, true, 0.0, ea, 101_325.0, 300.0, 284.0);
        let num_h = (fd(10.001).0 - fd(9.999).0) / 2e-3;
        assert!((num_h - fd(10.0).2).abs() < 1e-6 * num_h.abs());
        // By hand: r_a = ρc_p/h = 121.56 s/m; λE = ρc_p/γ·(e°−e_a)/(r_a + 70).
        let gamma = psychrometric_pa_k(101_325.0, 300.0);
        let by_hand =
            rho_cp / gamma * (saturation_vapour_pressure_pa(300.0) - ea) / (rho_cp / h + 70.0);
        assert!((q + by_hand).abs() < 1e-9);
        // Cap.
        let (qc, dqc, dqc_dh) = latent_w_m2(
            h,
            rho_cp,
            1.0 / 70.0,
            true,
            50.0,
            ea,
            101_325.0,
            300.0,
            300.0,
        );
        assert_eq!((qc, dqc, dqc_dh), (-50.0, 0.0, 0.0));
        // Dew on a surface below the dew point: heat released into it.
        let td = 286.0; // e°(286) ≈ 1497 Pa < e_a
        assert!(latent_w_m2(h, rho_cp, 0.0, true, 0.0, ea, 101_325.0, 300.0, td - 2.0).0 > 0.0);
        assert_eq!(
            latent_w_m2(h, rho_cp, 0.0, false, 0.0, ea, 101_325.0, 300.0, td - 2.0).0,
            0.0
        );
    }

    /// docs/energy-balance.md's table of exchange constants lists the
    /// values the code uses (each row `| \`NAME\` | value | ... |` between
    /// the table's markers is compared with the constant).
    #[test]
    fn doc_table_matches_the_constants() {
        let doc = include_str!("../../docs/energy-balance.md");
        let start = doc.find("<!-- constants:begin -->").expect("begin marker");
        let end = doc.find("<!-- constants:end -->").expect("end marker");
        let code: &[(&str, f64)] = &[
            ("VON_KARMAN", VON_KARMAN),
            ("GRAVITY_M_S2", GRAVITY_M_S2),
            ("CP_AIR_J_KGK", CP_AIR_J_KGK),
            ("R_DRY_AIR_J_KGK", R_DRY_AIR_J_KGK),
            ("MIN_WIND_M_S", MIN_WIND_M_S),
            ("MIN_RICHARDSON", MIN_RICHARDSON),
            ("MAX_RICHARDSON", MAX_RICHARDSON),
            ("WINDLESS_EXCHANGE_W_M2K", WINDLESS_EXCHANGE_W_M2K),
            ("SNOW_STABLE_FLOOR", SNOW_STABLE_FLOOR),
            ("FREE_CONVECTION_AIR_300K", FREE_CONVECTION_AIR_300K),
            ("HEAT_ROUGHNESS_RATIO", HEAT_ROUGHNESS_RATIO),
            (
                "DEFAULT_SOLID_ROUGHNESS_M",
                crate::therm::surface::DEFAULT_SOLID_ROUGHNESS_M,
            ),
        ];
        let mut seen = 0;
        for line in doc[start..end].lines() {
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            if cells.len() < 4 || !cells[1].starts_with('`') {
                continue;
            }
            let name = cells[1].trim_matches('`');
            let value: f64 = cells[2]
                .parse()
                .unwrap_or_else(|_| panic!("{name}: {}", cells[2]));
            let (_, c) = code
                .iter()
                .find(|(n, _)| *n == name)
                .unwrap_or_else(|| panic!("{name} is not a constant the test knows"));
            assert_eq!(value, *c, "{name}");
            seen += 1;
        }
        assert_eq!(seen, code.len(), "every constant has a row");
    }

    /// `z_oh = ratio·z_om` for a canopy: the default ratio gives FAO-56's
    /// `0.0123·h` bit for bit (existing materials unchanged); ratio 1 (the
    /// ECMWF trees) gives `z_oh = z_om` and the neutral resistance of
    /// FAO-56 eq. 4 with both logarithms equal, `ln((z − d)/z_om)²/(k²u)`,
    /// evaluated by hand for a 27 m canopy, 24 m above d, 3 m/s: d = 18 m,
    /// z_om = 3.321 m, ln(24/3.321) = 1.97779, r_a = 3.91164/(0.1681·3) =
    /// 7.7566 s/m (to 1e-4 relative); with the default ratio the heat
    /// logarithm is ln(240/3.321) = 4.28038 and r_a = 16.787 s/m.
    #[test]
    fn canopy_heat_roughness_ratio() {
        for h in [0.12, 1.0, 27.0] {
            let a = Roughness::canopy(h);
            let b = Roughness::canopy_with_heat_ratio(h, HEAT_ROUGHNESS_RATIO);
            assert_eq!(a.heat_m.to_bits(), (0.0123 * h).to_bits());
            assert_eq!(a, b);
        }
        let r = Roughness::canopy_with_heat_ratio(27.0, 1.0);
        assert!((r.heat_m - r.momentum_m).abs() < 1e-12 * r.momentum_m);
        assert_eq!(r.displacement_m, 18.0);
        let ra = |r: Roughness| {
            neutral_resistance_s_m(3.0, 42.0, r.displacement_m, r.momentum_m, r.heat_m)
        };
        assert!((ra(r) - 7.7566).abs() < 1e-4 * 7.7566, "{}", ra(r));
        let fao = ra(Roughness::canopy(27.0));
        assert!((fao - 16.787).abs() < 1e-4 * 16.787, "{fao}");
    }

    /// Jarvis canopy resistance: unstressed midday grass near FAO-56's
    /// 70 s/m; rises with vapour deficit, darkness and drought.
    #[test]
    fn canopy_resistance_responds() {
        let c = Canopy {
            height_m: 0.12,
            lai: 2.88,
            min_resistance_s_m: 100.0,
            max_resistance_s_m: 5000.0,
            radiation_limit_w_m2: 100.0,
            vpd_coeff: 36.35,
            soil_moisture: 1.0,
            skin_conductance_w_m2k: 10.0,
            heat_capacity_j_m2k: 2880.0,
            soil_shortwave_fraction: 0.05,
            heat_roughness_ratio: HEAT_ROUGHNESS_RATIO,
        };
        let ea = 0.6 * saturation_vapour_pressure_pa(300.0);
        let day = c.resistance_s_m(800.0, 300.0, ea, 101_325.0);
        assert!((40.0..120.0).contains(&day), "{day}");
        assert!(c.resistance_s_m(0.0, 300.0, ea, 101_325.0) > 10.0 * day);
        assert!(c.resistance_s_m(800.0, 300.0, 0.2 * ea, 101_325.0) > day);
        let dry = Canopy {
            soil_moisture: 0.1,
            ..c
        };
        assert!((dry.resistance_s_m(800.0, 300.0, ea, 101_325.0) - 10.0 * day).abs() < 1e-9 * day);
    }
}
