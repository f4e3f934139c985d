//! Surface energy balance of a THERM-style slab (docs/models.md, docs/energy-balance.md): the flux
//! terms at the exposed surface and at the back face, each a pure function
//! of plain data, with the derivative the implicit solver needs.
//!
//! Sign convention: every flux is in W/m² and positive **into** the slab.
//!
//! Surface balance (after Schott et al. 1992, THERM, with the turbulent
//! terms of [`super::aero`]):
//!
//! ```text
//! q_s = α·[I·E_dir·max(0, n·s) + E_dif·F_sky + ρ_g·E_glob·F_gnd]
//!     + ε·[F_sky·σT_sky⁴ + F_gnd·σT_gnd⁴] − ε·σT_s⁴
//!     + h_c·(T_air − T_s) + λE(T_s) + ρ_w c_w P·(T_wb − T_s) + q_int
//! F_sky = (1 + cos β)/2,  F_gnd = 1 − F_sky      (β = slope; isotropic sky and ground)
//! ```
//!
//! `h_c` is convective only ([`Convection::SurfaceLayer`]); `λE` is the
//! latent heat of transpiration, evaporation from a wet store or open
//! water, or dew ([`super::aero::latent_w_m2`]); the rain term carries the
//! heat of precipitation at the wet-bulb temperature. The ground seen by a
//! tilted facet is a black body at `T_gnd` (the render solves the scene's
//! ground material for it; the forcing builder's default is the air
//! temperature) with solar albedo `ρ_g`.

use serde::{Deserialize, Serialize};

use super::aero::{Exchange, SurfaceLayer};
use crate::units::STEFAN_BOLTZMANN_W_M2K4;

/// Solar albedo of the ground seen by tilted facets when a material gives none.
pub const DEFAULT_GROUND_ALBEDO: f64 = 0.2;

/// Facet orientation: slope from horizontal and aspect (azimuth of the
/// downslope direction = horizontal projection of the outward normal,
/// clockwise from north), degrees.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Orientation {
    /// Tilt of the facet's normal from the zenith, degrees (0 horizontal, 90 a wall).
    pub slope_deg: f64,
    /// Azimuth the facet faces, degrees clockwise from north.
    pub aspect_deg: f64,
}

impl Orientation {
    /// A horizontal facet facing up.
    pub const HORIZONTAL: Orientation = Orientation {
        slope_deg: 0.0,
        aspect_deg: 0.0,
    };

    /// Outward unit normal in local ENU:
    /// `n = (sin β sin A, sin β cos A, cos β)` for slope β, aspect A.
    pub fn normal_enu(&self) -> [f64; 3] {
        let b = self.slope_deg.to_radians();
        let a = self.aspect_deg.to_radians();
        [b.sin() * a.sin(), b.sin() * a.cos(), b.cos()]
    }

    /// Inverse of [`Orientation::normal_enu`] for any non-zero vector
    /// (aspect 0 for a horizontal or downward-vertical normal).
    pub fn from_normal_enu(n: [f64; 3]) -> Orientation {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let (e, nn, u) = (n[0] / len, n[1] / len, n[2] / len);
        let slope_deg = u.clamp(-1.0, 1.0).acos().to_degrees();
        let horiz = (e * e + nn * nn).sqrt();
        let aspect_deg = if horiz < 1e-12 {
            0.0
        } else {
            e.atan2(nn).to_degrees().rem_euclid(360.0)
        };
        Orientation {
            slope_deg,
            aspect_deg,
        }
    }

    /// Sky view factor of an unobstructed facet, `F_sky = (1 + cos β)/2`.
    pub fn sky_view_factor(&self) -> f64 {
        (1.0 + self.slope_deg.to_radians().cos()) / 2.0
    }

    /// Ground view factor, `F_gnd = (1 − cos β)/2 = 1 − F_sky`.
    pub fn ground_view_factor(&self) -> f64 {
        (1.0 - self.slope_deg.to_radians().cos()) / 2.0
    }
}

/// The convective heat-transfer model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Convection {
    /// `h_c = max(a + b·v, c·|T_air − T_s|^(1/3))`, W m⁻² K⁻¹, with the
    /// station wind `v`. McAdams (1954) as quoted by Duffie & Beckman, *Solar
    /// Engineering of Thermal Processes*, eq. 3.15.1 (`a = 5.7`, `b = 3.8`,
    /// [`Convection::mcadams`]) **includes radiative exchange**, which the
    /// surface balance also computes explicitly: kept only for the numerical
    /// reference tests (whose independent solvers use it) and for constant
    /// coefficients ([`Convection::constant`]). Not for scenes.
    Linear {
        /// The still-air term `a`, W m⁻² K⁻¹.
        still_air_w_m2k: f64,
        /// The wind term `b`, W m⁻² K⁻¹ per m/s (= J m⁻³ K⁻¹).
        wind_coeff_j_m3k: f64,
        /// The free-convection term `c`, W m⁻² K⁻⁴ᐟ³.
        free_coeff_w_m2k4_3: f64,
    },
    /// Convection only, from surface-layer similarity
    /// ([`super::aero::Exchange`]): the station wind moved to the facet's
    /// height by the log law, FAO-56's aerodynamic resistance with the
    /// surface's own roughness, a bulk-Richardson stability correction,
    /// blended with turbulent free convection. The default.
    SurfaceLayer(SurfaceLayer),
}

impl Default for Convection {
    fn default() -> Self {
        Convection::SurfaceLayer(SurfaceLayer::default())
    }
}

impl Convection {
    /// A constant coefficient `h` (no wind or free-convection dependence).
    pub fn constant(h_w_m2k: f64) -> Convection {
        Convection::Linear {
            still_air_w_m2k: h_w_m2k,
            wind_coeff_j_m3k: 0.0,
            free_coeff_w_m2k4_3: 0.0,
        }
    }

    /// The legacy McAdams form `max(5.7 + 3.8·v, 1.31·|ΔT|^(1/3))` (see
    /// [`Convection::Linear`]; the free-convection floor is the simplified
    /// turbulent correlation for air of ASHRAE Fundamentals).
    pub fn mcadams() -> Convection {
        Convection::Linear {
            still_air_w_m2k: 5.7,
            wind_coeff_j_m3k: 3.8,
            free_coeff_w_m2k4_3: 1.31,
        }
    }

    /// The site's surface layer, if this is the similarity model.
    pub fn surface_layer(&self) -> Option<&SurfaceLayer> {
        match self {
            Convection::SurfaceLayer(l) => Some(l),
            Convection::Linear { .. } => None,
        }
    }

    /// The convective coefficient `h_c` at surface temperature
    /// `surf_temp_k`, W m⁻² K⁻¹ (see [`Convection::flux_w_m2`]), and its
    /// derivative `dh_c/dT_s`, W m⁻² K⁻². Linear: `max(a +
    /// b·v, c·|ΔT|^(1/3))`, whose free branch has `dh/dT_s = −h/(3·ΔT)`
    /// (ΔT = T_air − T_s); the surface layer:
    /// [`Exchange::coefficient_and_slope`].
    pub fn coefficient_and_slope(
        &self,
        ex: &Exchange,
        wind_speed_m_s: f64,
        air_temp_k: f64,
        surf_temp_k: f64,
    ) -> (f64, f64) {
        match *self {
            Convection::Linear {
                still_air_w_m2k,
                wind_coeff_j_m3k,
                free_coeff_w_m2k4_3,
            } => {
                let dt = air_temp_k - surf_temp_k;
                let forced = still_air_w_m2k + wind_coeff_j_m3k * wind_speed_m_s.max(0.0);
                let free = free_coeff_w_m2k4_3 * dt.abs().cbrt();
                if forced >= free {
                    (forced, 0.0)
                } else {
                    (free, -free / (3.0 * dt))
                }
            }
            Convection::SurfaceLayer(_) => ex.coefficient_and_slope(air_temp_k, surf_temp_k),
        }
    }

    /// Convective flux into a surface `h_c·(T_air − T_s)`, its derivative
    /// with respect to `T_s` (`dh_c/dT_s·(T_air − T_s) − h_c`, analytic) and
    /// the coefficient `h_c` itself (W/m², W m⁻² K⁻¹, W m⁻² K⁻¹), under the
    /// exchange `ex` (used by [`Convection::SurfaceLayer`]) or the station
    /// wind (used by [`Convection::Linear`]).
    pub fn flux_w_m2(
        &self,
        ex: &Exchange,
        wind_speed_m_s: f64,
        air_temp_k: f64,
        surf_temp_k: f64,
    ) -> (f64, f64, f64) {
        let (h, dh) = self.coefficient_and_slope(ex, wind_speed_m_s, air_temp_k, surf_temp_k);
        let dt = air_temp_k - surf_temp_k;
        (h * dt, dh * dt - h, h)
    }
}

/// The temperature-independent part of the surface forcing of one facet at
/// one instant (orientation and sun/shadow flag already applied).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SurfaceDrive {
    /// `α·I·E_dir·max(0, n·s)`, W/m².
    pub absorbed_direct_w_m2: f64,
    /// `α·E_dif·F_sky`, W/m².
    pub absorbed_diffuse_w_m2: f64,
    /// `α·ρ_g·E_glob·F_gnd`, W/m².
    pub absorbed_ground_reflected_w_m2: f64,
    /// `ε·F_sky·σT_sky⁴`, W/m².
    pub sky_longwave_in_w_m2: f64,
    /// `ε·F_gnd·σT_gnd⁴` (the ground's own temperature), W/m².
    pub ground_longwave_in_w_m2: f64,
    /// Internal power delivered at the surface node, W/m².
    pub internal_w_m2: f64,
    /// Air temperature, K.
    pub air_temp_k: f64,
    /// Station wind, m/s.
    pub wind_speed_m_s: f64,
    /// Shortwave incident on the facet (before absorption), W/m².
    pub incident_shortwave_w_m2: f64,
    /// Turbulent exchange of the exposed face and of the back face.
    pub exchange: Exchange,
    /// Turbulent exchange of the back face (for a back exposed to air).
    pub back_exchange: Exchange,
    /// Surface conductance to vapour `1/r_s`, m/s: 0 dry, ∞ free water.
    pub conductance_m_s: f64,
    /// Condensation (dew) allowed on this surface.
    pub dew: bool,
    /// Largest evaporation the surface can supply, W/m² (a drying store).
    pub evaporation_cap_w_m2: f64,
    /// Vapour pressure of the air, Pa.
    pub vapour_pressure_pa: f64,
    /// Station pressure, Pa.
    pub pressure_pa: f64,
    /// Heat carried by rain, `ρ_w·c_w·P`, W m⁻² K⁻¹, and the rain's
    /// temperature (wet bulb), K.
    pub rain_coeff_w_m2k: f64,
    /// Temperature of the rain (its wet bulb), K.
    pub rain_temp_k: f64,
}

impl SurfaceDrive {
    /// `self += w·d`, field by field (for time averages of the drive). The
    /// dew flag is taken from `d`.
    pub fn add_scaled(&mut self, w: f64, d: &SurfaceDrive) {
        self.absorbed_direct_w_m2 += w * d.absorbed_direct_w_m2;
        self.absorbed_diffuse_w_m2 += w * d.absorbed_diffuse_w_m2;
        self.absorbed_ground_reflected_w_m2 += w * d.absorbed_ground_reflected_w_m2;
        self.sky_longwave_in_w_m2 += w * d.sky_longwave_in_w_m2;
        self.ground_longwave_in_w_m2 += w * d.ground_longwave_in_w_m2;
        self.internal_w_m2 += w * d.internal_w_m2;
        self.air_temp_k += w * d.air_temp_k;
        self.wind_speed_m_s += w * d.wind_speed_m_s;
        self.incident_shortwave_w_m2 += w * d.incident_shortwave_w_m2;
        for (a, b) in [
            (&mut self.exchange, &d.exchange),
            (&mut self.back_exchange, &d.back_exchange),
        ] {
            a.wind_m_s += w * b.wind_m_s;
            a.h_neutral_w_m2k += w * b.h_neutral_w_m2k;
            a.richardson_per_k += w * b.richardson_per_k;
            a.free_warm += w * b.free_warm;
            a.free_cold += w * b.free_cold;
            a.rho_cp_j_m3k += w * b.rho_cp_j_m3k;
        }
        self.conductance_m_s += w * d.conductance_m_s;
        self.dew = d.dew;
        self.evaporation_cap_w_m2 += w * d.evaporation_cap_w_m2;
        self.vapour_pressure_pa += w * d.vapour_pressure_pa;
        self.pressure_pa += w * d.pressure_pa;
        self.rain_coeff_w_m2k += w * d.rain_coeff_w_m2k;
        self.rain_temp_k += w * d.rain_temp_k;
    }

    /// Total absorbed shortwave, W/m².
    pub fn absorbed_shortwave_w_m2(&self) -> f64 {
        self.absorbed_direct_w_m2 + self.absorbed_diffuse_w_m2 + self.absorbed_ground_reflected_w_m2
    }
}

/// Inputs of [`surface_drive`]: the weather/sun forcing at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveInputs {
    /// Air temperature, K.
    pub air_temp_k: f64,
    /// Effective sky temperature for longwave exchange, K.
    pub sky_temp_k: f64,
    /// Temperature of the ground seen by a tilted facet, K.
    pub ground_temp_k: f64,
    /// Station wind, m/s.
    pub wind_speed_m_s: f64,
    /// Direct normal irradiance, W/m².
    pub dni_w_m2: f64,
    /// Diffuse horizontal irradiance, W/m².
    pub dhi_w_m2: f64,
    /// Global horizontal irradiance, W/m².
    pub ghi_w_m2: f64,
    /// Unit vector to the sun, ENU.
    pub sun_dir_enu: [f64; 3],
    /// Sunlit fraction `I(t)` in [0, 1]: 1 when the pixel sees the sun.
    pub sunlit: f64,
}

/// Surface optical properties used by [`surface_drive`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceOptics {
    /// Absorptivity α for sunlight, 0-1.
    pub solar_absorptivity: f64,
    /// Thermal (longwave) emissivity ε, 0-1.
    pub thermal_emissivity: f64,
    /// Solar albedo ρ_g of the ground a tilted facet sees, 0-1.
    pub ground_albedo: f64,
    /// Internal heat delivered at the surface node, W/m².
    pub internal_power_w_m2: f64,
}

/// Evaluates the temperature-independent radiative source terms of the
/// surface balance for a facet with outward normal `normal_enu` (unit)
/// and sky view factor `f_sky` (`(1 + cos β)/2` for an unobstructed facet;
/// the ground fills the rest, `F_gnd = 1 − F_sky`). The exchange and
/// moisture fields are left at their defaults (the slab model fills them).
pub fn surface_drive(
    inp: &DriveInputs,
    optics: &SurfaceOptics,
    normal_enu: [f64; 3],
    f_sky: f64,
) -> SurfaceDrive {
    let s = inp.sun_dir_enu;
    let cos_i = normal_enu[0] * s[0] + normal_enu[1] * s[1] + normal_enu[2] * s[2];
    let f_gnd = 1.0 - f_sky;
    let a = optics.solar_absorptivity;
    let e = optics.thermal_emissivity;
    let sig = STEFAN_BOLTZMANN_W_M2K4;
    let flag = inp.sunlit.clamp(0.0, 1.0);
    let direct = flag * inp.dni_w_m2.max(0.0) * cos_i.max(0.0);
    let diffuse = inp.dhi_w_m2.max(0.0) * f_sky;
    let ground = optics.ground_albedo * inp.ghi_w_m2.max(0.0) * f_gnd;
    SurfaceDrive {
        absorbed_direct_w_m2: a * direct,
        absorbed_diffuse_w_m2: a * diffuse,
        absorbed_ground_reflected_w_m2: a * ground,
        sky_longwave_in_w_m2: e * f_sky * sig * inp.sky_temp_k.powi(4),
        ground_longwave_in_w_m2: e * f_gnd * sig * inp.ground_temp_k.powi(4),
        internal_w_m2: optics.internal_power_w_m2,
        air_temp_k: inp.air_temp_k,
        wind_speed_m_s: inp.wind_speed_m_s,
        incident_shortwave_w_m2: direct + diffuse + ground,
        evaporation_cap_w_m2: f64::INFINITY,
        ..SurfaceDrive::default()
    }
}

/// All surface flux terms at one surface temperature, W/m², positive into
/// the slab (`emitted_longwave_w_m2` is the loss `ε·σT_s⁴`, reported as a
/// positive number and subtracted in `net_w_m2`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFluxes {
    /// `α·I·E_dir·max(0, n·s)`, W/m².
    pub absorbed_direct_w_m2: f64,
    /// `α·E_dif·F_sky`, W/m².
    pub absorbed_diffuse_w_m2: f64,
    /// `α·ρ_g·E_glob·F_gnd`, W/m².
    pub absorbed_ground_reflected_w_m2: f64,
    /// `ε·F_sky·σT_sky⁴`, W/m².
    pub sky_longwave_in_w_m2: f64,
    /// `ε·F_gnd·σT_gnd⁴`, W/m².
    pub ground_longwave_in_w_m2: f64,
    /// `ε·σT_s⁴` (counted negative in the net), W/m².
    pub emitted_longwave_w_m2: f64,
    /// Sensible heat from the air, `h_c·(T_air − T_s)`, W/m².
    pub convection_w_m2: f64,
    /// Latent heat: negative while evaporating or transpiring, positive
    /// while dew forms.
    pub latent_w_m2: f64,
    /// Heat brought by rain at its wet-bulb temperature.
    pub rain_w_m2: f64,
    /// Internal heat delivered at the surface node, W/m².
    pub internal_w_m2: f64,
    /// Sum of all the terms above (emission counted negative).
    pub net_w_m2: f64,
    /// Convective coefficient in force, W m⁻² K⁻¹.
    pub convection_coeff_w_m2k: f64,
    /// Bulk Richardson number of the surface layer at this surface
    /// temperature, `Ri = Ri_K·(T_a − T_s)` (Monteith & Unsworth 2013, eq.
    /// 16.23; [`super::aero::richardson_per_k`]), uncapped: the stability
    /// function caps it ([`SurfaceFluxes::stability_factor`]). 0 under
    /// McAdams or a constant coefficient, and on walls (their exchange is
    /// neutral).
    pub richardson: f64,
    /// Floor of the stability factor in force
    /// ([`super::aero::Exchange::stable_floor`]: 0, or
    /// [`super::aero::SNOW_STABLE_FLOOR`] on snow). Written only where
    /// set, so the JSON of every other surface is unchanged.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stability_floor: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl SurfaceFluxes {
    /// The stability function `F(Ri) = h_forced/h_neutral` in force
    /// ([`super::aero::stability_factor`]: Businger-Dyer unstable, Louis
    /// 1979 stable, Ri capped to `[MIN_RICHARDSON, MAX_RICHARDSON]`; on
    /// snow with the floor [`super::aero::SNOW_STABLE_FLOOR`]); 1 is
    /// neutral. Computed from [`SurfaceFluxes::richardson`] on demand (not
    /// in the solver's hot loop).
    pub fn stability_factor(&self) -> f64 {
        super::aero::floored_stability_factor_and_slope(self.richardson, self.stability_floor).0
    }
}

/// Net surface flux into the slab at surface temperature `surf_temp_k`,
/// with every term and `d(net)/dT_s` (W m⁻² K⁻¹).
pub fn surface_fluxes(
    drive: &SurfaceDrive,
    emissivity: f64,
    conv: &Convection,
    surf_temp_k: f64,
) -> (SurfaceFluxes, f64) {
    let sig = STEFAN_BOLTZMANN_W_M2K4;
    let emitted = emissivity * sig * surf_temp_k.powi(4);
    let d_emitted = 4.0 * emissivity * sig * surf_temp_k.powi(3);
    let (h, dh) = conv.coefficient_and_slope(
        &drive.exchange,
        drive.wind_speed_m_s,
        drive.air_temp_k,
        surf_temp_k,
    );
    let dt = drive.air_temp_k - surf_temp_k;
    let (convection, d_conv) = (h * dt, dh * dt - h);
    let (latent, d_latent) = if drive.conductance_m_s > 0.0 || drive.dew {
        let rho_cp = if drive.exchange.rho_cp_j_m3k > 0.0 {
            drive.exchange.rho_cp_j_m3k
        } else {
            super::aero::air_density_kg_m3(drive.pressure_pa, drive.air_temp_k)
                * super::aero::CP_AIR_J_KGK
        };
        let (latent, d_fixed_h, d_per_h) = super::aero::latent_w_m2(
            h,
            rho_cp,
            drive.conductance_m_s,
            drive.dew,
            drive.evaporation_cap_w_m2,
            drive.vapour_pressure_pa,
            drive.pressure_pa,
            drive.air_temp_k,
            surf_temp_k,
        );
        // The total derivative includes the coefficient's own dependence
        // on T_s (stability): without it Newton's Jacobian is wrong
        // wherever the exchange is strongly stable, and the iteration
        // crawls.
        (latent, d_fixed_h + d_per_h * dh)
    } else {
        (0.0, 0.0)
    };
    let rain = drive.rain_coeff_w_m2k * (drive.rain_temp_k - surf_temp_k);
    let net = drive.absorbed_direct_w_m2
        + drive.absorbed_diffuse_w_m2
        + drive.absorbed_ground_reflected_w_m2
        + drive.sky_longwave_in_w_m2
        + drive.ground_longwave_in_w_m2
        - emitted
        + convection
        + latent
        + rain
        + drive.internal_w_m2;
    (
        SurfaceFluxes {
            absorbed_direct_w_m2: drive.absorbed_direct_w_m2,
            absorbed_diffuse_w_m2: drive.absorbed_diffuse_w_m2,
            absorbed_ground_reflected_w_m2: drive.absorbed_ground_reflected_w_m2,
            sky_longwave_in_w_m2: drive.sky_longwave_in_w_m2,
            ground_longwave_in_w_m2: drive.ground_longwave_in_w_m2,
            emitted_longwave_w_m2: emitted,
            convection_w_m2: convection,
            latent_w_m2: latent,
            rain_w_m2: rain,
            internal_w_m2: drive.internal_w_m2,
            net_w_m2: net,
            convection_coeff_w_m2k: h,
            richardson: match conv {
                Convection::SurfaceLayer(_) => drive.exchange.richardson_per_k * dt,
                Convection::Linear { .. } => 0.0,
            },
            stability_floor: match conv {
                Convection::SurfaceLayer(_) => drive.exchange.stable_floor,
                Convection::Linear { .. } => 0.0,
            },
        },
        d_conv - d_emitted + d_latent - drive.rain_coeff_w_m2k,
    )
}

/// Flux into the back face of a slab whose back is exposed to ambient air
/// (DIRSIG's EXPOSED_AREA): the exposed back area per unit front area
/// `area_factor` exchanges by convection with the air and by longwave
/// radiation with surroundings at the air temperature,
/// `q_b = A_f·[h_c·(T_air − T_b) + ε·σ·(T_air⁴ − T_b⁴)]`, with the back
/// face's exchange `ex`. Returns the flux and its derivative with respect
/// to `T_b`.
pub fn exposed_back_flux_w_m2(
    area_factor: f64,
    emissivity: f64,
    conv: &Convection,
    ex: &Exchange,
    wind_speed_m_s: f64,
    air_temp_k: f64,
    back_temp_k: f64,
) -> (f64, f64) {
    let sig = STEFAN_BOLTZMANN_W_M2K4;
    let (c, dc, _) = conv.flux_w_m2(ex, wind_speed_m_s, air_temp_k, back_temp_k);
    let r = emissivity * sig * (air_temp_k.powi(4) - back_temp_k.powi(4));
    let dr = -4.0 * emissivity * sig * back_temp_k.powi(3);
    (area_factor * (c + r), area_factor * (dc + dr))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_normal_round_trip_and_view_factors() {
        // South-facing 30° roof: normal tilts south (−y), F_sky = (1+cos30)/2.
        let o = Orientation {
            slope_deg: 30.0,
            aspect_deg: 180.0,
        };
        let n = o.normal_enu();
        assert!((n[0]).abs() < 1e-12 && (n[1] + 0.5).abs() < 1e-12);
        assert!((n[2] - 3f64.sqrt() / 2.0).abs() < 1e-12);
        let back = Orientation::from_normal_enu(n);
        assert!((back.slope_deg - 30.0).abs() < 1e-9 && (back.aspect_deg - 180.0).abs() < 1e-9);
        assert!((o.sky_view_factor() - (1.0 + 0.75f64.sqrt()) / 2.0).abs() < 1e-12);
        assert!((o.sky_view_factor() + o.ground_view_factor() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn convection_mcadams_and_derivative() {
        let c = Convection::mcadams();
        let ex = Exchange::default();
        // 5.7 + 3.8·2 = 13.3 W/m²K, ΔT = 10 K → 133 W/m² into the surface.
        let (q, dq, h) = c.flux_w_m2(&ex, 2.0, 300.0, 290.0);
        assert!((h - 13.3).abs() < 1e-12);
        assert!((q - 133.0).abs() < 1e-9 && (dq + 13.3).abs() < 1e-12);
        // Free convection dominates at still air and ΔT = 200 K: 1.31·200^(1/3).
        let (q, dq, _) = c.flux_w_m2(&ex, 0.0, 300.0, 500.0);
        let h = 1.31 * 200f64.cbrt();
        assert!((q + h * 200.0).abs() < 1e-9);
        // Numerical derivative check (central difference, 1e-4 relative).
        let f = |t: f64| c.flux_w_m2(&ex, 0.0, 300.0, t).0;
        let num = (f(500.001) - f(499.999)) / 0.002;
        assert!((num - dq).abs() < 1e-4 * dq.abs());
    }

    #[test]
    fn surface_flux_terms_by_hand() {
        // Horizontal facet, sun at 60° elevation, numbers checked by hand.
        let inp = DriveInputs {
            air_temp_k: 300.0,
            sky_temp_k: 270.0,
            wind_speed_m_s: 0.0,
            dni_w_m2: 800.0,
            dhi_w_m2: 100.0,
            ghi_w_m2: 800.0 * 0.5 * 3f64.sqrt() + 100.0,
            sun_dir_enu: [0.0, -0.5, 0.75f64.sqrt()],
            sunlit: 1.0,
            ground_temp_k: 300.0,
        };
        let optics = SurfaceOptics {
            solar_absorptivity: 0.5,
            thermal_emissivity: 0.9,
            ground_albedo: 0.2,
            internal_power_w_m2: 0.0,
        };
        let d = surface_drive(&inp, &optics, [0.0, 0.0, 1.0], 1.0);
        assert!((d.absorbed_direct_w_m2 - 0.5 * 800.0 * 0.75f64.sqrt()).abs() < 1e-9);
        assert!((d.absorbed_diffuse_w_m2 - 50.0).abs() < 1e-12);
        assert_eq!(d.absorbed_ground_reflected_w_m2, 0.0);
        let sig = STEFAN_BOLTZMANN_W_M2K4;
        assert!((d.sky_longwave_in_w_m2 - 0.9 * sig * 270f64.powi(4)).abs() < 1e-9);
        let (f, _) = surface_fluxes(&d, 0.9, &Convection::mcadams(), 300.0);
        let expect =
            0.5 * 800.0 * 0.75f64.sqrt() + 50.0 + 0.9 * sig * (270f64.powi(4) - 300f64.powi(4));
        assert!((f.net_w_m2 - expect).abs() < 1e-9);
        // Shadowed: the direct term vanishes, nothing else changes.
        let d2 = surface_drive(
            &DriveInputs { sunlit: 0.0, ..inp },
            &optics,
            [0.0, 0.0, 1.0],
            1.0,
        );
        assert_eq!(d2.absorbed_direct_w_m2, 0.0);
        assert_eq!(d2.absorbed_diffuse_w_m2, d.absorbed_diffuse_w_m2);
    }
}
