//! Surface energy balance of a THERM-style slab (DESIGN.md §4): the flux
//! terms at the exposed surface and at the back face, each a pure function
//! of plain data, with the derivative the implicit solver needs.
//!
//! Sign convention: every flux is in W/m² and positive **into** the slab.
//!
//! Surface balance (DESIGN.md §4, after Schott et al. 1992, THERM):
//!
//! ```text
//! q_s = α·[I·E_dir·max(0, n·s) + E_dif·F_sky + ρ_g·E_glob·F_gnd]
//!     + ε·[F_sky·σT_sky⁴ + F_gnd·σT_gnd⁴] − ε·σT_s⁴ + h_c(v, ΔT)·(T_air − T_s) + q_int
//! F_sky = (1 + cos β)/2,  F_gnd = (1 − cos β)/2     (β = slope; isotropic sky and ground)
//! ```
//!
//! The ground seen by a tilted facet is taken as a black body at the air
//! temperature (`T_gnd = T_air`), with solar albedo `ρ_g` (material field
//! `ground_albedo`, default [`DEFAULT_GROUND_ALBEDO`]).

use serde::{Deserialize, Serialize};

/// Stefan–Boltzmann constant, W m⁻² K⁻⁴ (CODATA 2018, exact in SI 2019).
pub const STEFAN_BOLTZMANN_W_M2K4: f64 = 5.670_374_419e-8;

/// Solar albedo of the ground seen by tilted facets when a material gives none.
pub const DEFAULT_GROUND_ALBEDO: f64 = 0.2;

/// Facet orientation: slope from horizontal and aspect (azimuth of the
/// downslope direction = horizontal projection of the outward normal,
/// clockwise from north), degrees.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Orientation {
    pub slope_deg: f64,
    pub aspect_deg: f64,
}

impl Orientation {
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

/// Convective heat-transfer coefficient model:
/// `h_c = max(a + b·v, c·|T_air − T_s|^(1/3))`, W m⁻² K⁻¹.
///
/// Defaults: `a = 5.7`, `b = 3.8` — McAdams (1954), as quoted by Duffie &
/// Beckman, *Solar Engineering of Thermal Processes*, eq. 3.15.1 (wind speed
/// `v` in m/s); the free-convection floor `c = 1.31` W m⁻² K⁻⁴ᐟ³ is the
/// simplified turbulent natural-convection correlation for air
/// (`h = 1.31 ΔT^(1/3)`, ASHRAE Fundamentals), which only takes over from the
/// still-air term for |ΔT| > 80 K. Set all three to build a constant `h`
/// (`b = c = 0`) or no convection at all.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Convection {
    pub still_air_w_m2k: f64,
    pub wind_coeff_j_m3k: f64,
    pub free_coeff_w_m2k4_3: f64,
}

impl Default for Convection {
    fn default() -> Self {
        Convection {
            still_air_w_m2k: 5.7,
            wind_coeff_j_m3k: 3.8,
            free_coeff_w_m2k4_3: 1.31,
        }
    }
}

impl Convection {
    /// A constant coefficient `h` (no wind or free-convection dependence).
    pub fn constant(h_w_m2k: f64) -> Convection {
        Convection {
            still_air_w_m2k: h_w_m2k,
            wind_coeff_j_m3k: 0.0,
            free_coeff_w_m2k4_3: 0.0,
        }
    }

    /// Convective flux into the surface `h_c·(T_air − T_s)` and its
    /// derivative with respect to `T_s`, W/m² and W m⁻² K⁻¹.
    pub fn flux_w_m2(&self, wind_speed_m_s: f64, air_temp_k: f64, surf_temp_k: f64) -> (f64, f64) {
        let dt = air_temp_k - surf_temp_k;
        let forced = self.still_air_w_m2k + self.wind_coeff_j_m3k * wind_speed_m_s.max(0.0);
        let free = self.free_coeff_w_m2k4_3 * dt.abs().cbrt();
        if forced >= free {
            (forced * dt, -forced)
        } else {
            // d/dTs [c |dt|^(1/3) dt] = -(4/3) c |dt|^(1/3)
            (free * dt, -4.0 / 3.0 * free)
        }
    }

    /// The coefficient itself, `h_c(v, ΔT)`.
    pub fn coefficient_w_m2k(&self, wind_speed_m_s: f64, delta_t_k: f64) -> f64 {
        let forced = self.still_air_w_m2k + self.wind_coeff_j_m3k * wind_speed_m_s.max(0.0);
        forced.max(self.free_coeff_w_m2k4_3 * delta_t_k.abs().cbrt())
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
    /// `ε·F_gnd·σT_gnd⁴` with `T_gnd = T_air`, W/m².
    pub ground_longwave_in_w_m2: f64,
    /// Internal power delivered at the surface node, W/m².
    pub internal_w_m2: f64,
    pub air_temp_k: f64,
    pub wind_speed_m_s: f64,
}

impl SurfaceDrive {
    /// `self += w·d`, field by field (for time averages of the drive).
    pub fn add_scaled(&mut self, w: f64, d: &SurfaceDrive) {
        self.absorbed_direct_w_m2 += w * d.absorbed_direct_w_m2;
        self.absorbed_diffuse_w_m2 += w * d.absorbed_diffuse_w_m2;
        self.absorbed_ground_reflected_w_m2 += w * d.absorbed_ground_reflected_w_m2;
        self.sky_longwave_in_w_m2 += w * d.sky_longwave_in_w_m2;
        self.ground_longwave_in_w_m2 += w * d.ground_longwave_in_w_m2;
        self.internal_w_m2 += w * d.internal_w_m2;
        self.air_temp_k += w * d.air_temp_k;
        self.wind_speed_m_s += w * d.wind_speed_m_s;
    }
}

/// Inputs of [`surface_drive`]: the weather/sun forcing at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveInputs {
    pub air_temp_k: f64,
    pub sky_temp_k: f64,
    pub wind_speed_m_s: f64,
    pub dni_w_m2: f64,
    pub dhi_w_m2: f64,
    pub ghi_w_m2: f64,
    /// Unit vector to the sun, ENU.
    pub sun_dir_enu: [f64; 3],
    /// Sun/shadow flag `I(t)`: true when the pixel sees the sun.
    pub sunlit: bool,
}

/// Surface optical properties used by [`surface_drive`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceOptics {
    pub solar_absorptivity: f64,
    pub thermal_emissivity: f64,
    pub ground_albedo: f64,
    pub internal_power_w_m2: f64,
}

/// Evaluates the temperature-independent surface source terms of DESIGN.md
/// §4 for a facet with outward normal `normal_enu` (unit) and sky view
/// factor `f_sky` (normally `(1 + cos β)/2`).
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
    let flag = if inp.sunlit { 1.0 } else { 0.0 };
    SurfaceDrive {
        absorbed_direct_w_m2: a * flag * inp.dni_w_m2.max(0.0) * cos_i.max(0.0),
        absorbed_diffuse_w_m2: a * inp.dhi_w_m2.max(0.0) * f_sky,
        absorbed_ground_reflected_w_m2: a * optics.ground_albedo * inp.ghi_w_m2.max(0.0) * f_gnd,
        sky_longwave_in_w_m2: e * f_sky * sig * inp.sky_temp_k.powi(4),
        ground_longwave_in_w_m2: e * f_gnd * sig * inp.air_temp_k.powi(4),
        internal_w_m2: optics.internal_power_w_m2,
        air_temp_k: inp.air_temp_k,
        wind_speed_m_s: inp.wind_speed_m_s,
    }
}

/// All surface flux terms at one surface temperature, W/m², positive into
/// the slab (`emitted_longwave_w_m2` is the loss `ε·σT_s⁴`, reported as a
/// positive number and subtracted in `net_w_m2`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SurfaceFluxes {
    pub absorbed_direct_w_m2: f64,
    pub absorbed_diffuse_w_m2: f64,
    pub absorbed_ground_reflected_w_m2: f64,
    pub sky_longwave_in_w_m2: f64,
    pub ground_longwave_in_w_m2: f64,
    pub emitted_longwave_w_m2: f64,
    pub convection_w_m2: f64,
    pub internal_w_m2: f64,
    /// Sum of all the terms above (emission counted negative).
    pub net_w_m2: f64,
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
    let (convection, d_conv) = conv.flux_w_m2(drive.wind_speed_m_s, drive.air_temp_k, surf_temp_k);
    let net = drive.absorbed_direct_w_m2
        + drive.absorbed_diffuse_w_m2
        + drive.absorbed_ground_reflected_w_m2
        + drive.sky_longwave_in_w_m2
        + drive.ground_longwave_in_w_m2
        - emitted
        + convection
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
            internal_w_m2: drive.internal_w_m2,
            net_w_m2: net,
        },
        d_conv - d_emitted,
    )
}

/// Flux into the back face of a slab whose back is exposed to ambient air
/// (DIRSIG's EXPOSED_AREA): the exposed back area per unit front area
/// `area_factor` exchanges by convection with the air and by longwave
/// radiation with surroundings at the air temperature,
/// `q_b = A_f·[h_c(v, ΔT)·(T_air − T_b) + ε·σ·(T_air⁴ − T_b⁴)]`.
/// Returns the flux and its derivative with respect to `T_b`.
pub fn exposed_back_flux_w_m2(
    area_factor: f64,
    emissivity: f64,
    conv: &Convection,
    wind_speed_m_s: f64,
    air_temp_k: f64,
    back_temp_k: f64,
) -> (f64, f64) {
    let sig = STEFAN_BOLTZMANN_W_M2K4;
    let (c, dc) = conv.flux_w_m2(wind_speed_m_s, air_temp_k, back_temp_k);
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
        let c = Convection::default();
        // 5.7 + 3.8·2 = 13.3 W/m²K, ΔT = 10 K → 133 W/m² into the surface.
        let (q, dq) = c.flux_w_m2(2.0, 300.0, 290.0);
        assert!((q - 133.0).abs() < 1e-9 && (dq + 13.3).abs() < 1e-12);
        // Free convection dominates at still air and ΔT = 200 K: 1.31·200^(1/3).
        let (q, dq) = c.flux_w_m2(0.0, 300.0, 500.0);
        let h = 1.31 * 200f64.cbrt();
        assert!((q + h * 200.0).abs() < 1e-9);
        // Numerical derivative check (central difference, 1e-4 relative).
        let f = |t: f64| c.flux_w_m2(0.0, 300.0, t).0;
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
            sunlit: true,
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
        let (f, _) = surface_fluxes(&d, 0.9, &Convection::default(), 300.0);
        let expect =
            0.5 * 800.0 * 0.75f64.sqrt() + 50.0 + 0.9 * sig * (270f64.powi(4) - 300f64.powi(4));
        assert!((f.net_w_m2 - expect).abs() < 1e-9);
        // Shadowed: the direct term vanishes, nothing else changes.
        let d2 = surface_drive(
            &DriveInputs {
                sunlit: false,
                ..inp
            },
            &optics,
            [0.0, 0.0, 1.0],
            1.0,
        );
        assert_eq!(d2.absorbed_direct_w_m2, 0.0);
        assert_eq!(d2.absorbed_diffuse_w_m2, d.absorbed_diffuse_w_m2);
    }
}
