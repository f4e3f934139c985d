//! The seed's radiometry equations 1-4 (Schott, Raqueño, Salvaggio, Opt. Eng.
//! 31(7) 1992, p. 1509), evaluated at one wavelength, returning every term.
//!
//! Units: spectral radiances W m⁻² sr⁻¹ µm⁻¹, irradiances W m⁻² µm⁻¹; angles enter
//! only through the cosines and emissivities the caller passes. Reflectance is
//! 1 − ε (opaque surfaces). Band values follow by weighting every term with the
//! same [`super::spectral::Band`] weights ([`RadianceTerms::accumulate`]).

/// Sun illumination of a surface point: I · (E_S/π) τ₁ cos θ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunIllumination {
    /// Exo-atmospheric solar spectral irradiance E_S, W m⁻² µm⁻¹.
    pub e_sun_exo_w_m2_um: f64,
    /// Transmission of the sun→surface path, τ₁.
    pub tau1: f64,
    /// cos of the angle between the surface normal and the sun direction (θ_S or θ_B);
    /// negative values (sun behind the facet) count as 0.
    pub cos_incidence: f64,
    /// Sun/shadow flag I (1 lit, 0 shadowed); fractional values allowed for
    /// partial shadow.
    pub sun_flag: f64,
}

impl SunIllumination {
    /// No sun (night or shadow).
    pub const DARK: Self = Self {
        e_sun_exo_w_m2_um: 0.0,
        tau1: 0.0,
        cos_incidence: 0.0,
        sun_flag: 0.0,
    };

    /// I · E_S/π · τ₁ · max(0, cos θ): the "radiance-equivalent" solar term, W m⁻² sr⁻¹ µm⁻¹,
    /// to be multiplied by the reflectance.
    pub fn reflected_basis_w_m2_sr_um(&self) -> f64 {
        self.sun_flag * self.e_sun_exo_w_m2_um / std::f64::consts::PI
            * self.tau1
            * self.cos_incidence.max(0.0)
    }
}

/// The target→sensor path: τ₂(θ_E), L_UE(θ_E), L_US(θ_E).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathRadiance {
    /// Path transmittance τ₂.
    pub tau2: f64,
    /// Path thermal (self-emitted) radiance L_UE, W m⁻² sr⁻¹ µm⁻¹.
    pub l_ue_w_m2_sr_um: f64,
    /// Path solar-scattered radiance L_US, W m⁻² sr⁻¹ µm⁻¹.
    pub l_us_w_m2_sr_um: f64,
}

impl PathRadiance {
    /// A transparent, non-emitting path (sensor at the surface).
    pub const TRANSPARENT: Self = Self {
        tau2: 1.0,
        l_ue_w_m2_sr_um: 0.0,
        l_us_w_m2_sr_um: 0.0,
    };
}

/// Downwelled sky radiance: thermal L_DE and solar-scattered L_DS, W m⁻² sr⁻¹ µm⁻¹.
/// For case 1 these are the sky-dome averages; for cases 2 and 4 the values in the
/// direction θ_SK.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyRadiance {
    /// Sky thermal radiance L_DE, W m⁻² sr⁻¹ µm⁻¹.
    pub l_de_w_m2_sr_um: f64,
    /// Sky solar-scattered radiance L_DS, W m⁻² sr⁻¹ µm⁻¹.
    pub l_ds_w_m2_sr_um: f64,
}

/// The background object seen in a specular bounce (case 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Background {
    /// ε_B(θ_BT, λ): background emissivity toward the target.
    pub emissivity: f64,
    /// Blackbody radiance at the background temperature, L_TB, W m⁻² sr⁻¹ µm⁻¹.
    pub blackbody_w_m2_sr_um: f64,
    /// Sun on the background (I_B, θ_B, τ₁).
    pub sun: SunIllumination,
}

/// Every term of eqs. 1-4 at the sensor, W m⁻² sr⁻¹ µm⁻¹ (or band-averaged after
/// [`RadianceTerms::accumulate`]). Terms that a case does not have are 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct RadianceTerms {
    /// ε L_T τ₂: target self-emission.
    pub emitted: f64,
    /// I_T (E_S/π) τ₁ cos θ_S (1−ε) τ₂: reflected direct sun.
    pub reflected_solar: f64,
    /// L_DE (1−ε) τ₂: reflected sky thermal radiance (cases 1, 2).
    pub reflected_sky_thermal: f64,
    /// L_DS (1−ε) τ₂: reflected sky scattered radiance (cases 1, 2).
    pub reflected_sky_scattered: f64,
    /// ε_B L_TB (1−ε) τ₂: reflected background emission (case 3).
    pub reflected_background_emitted: f64,
    /// I_B (E_S/π) τ₁ cos θ_B (1−ε_B)(1−ε) τ₂: reflected sun off the background (case 3).
    pub reflected_background_solar: f64,
    /// L_UE: path thermal radiance (cases 1-3); sky thermal L_DE(θ_SK) in case 4.
    pub path_thermal: f64,
    /// L_US: path scattered radiance (cases 1-3); sky scattered L_DS(θ_SK) in case 4.
    pub path_scattered: f64,
}

impl RadianceTerms {
    /// Every term, in the order of the fields.
    pub fn values(&self) -> [f64; 8] {
        [
            self.emitted,
            self.reflected_solar,
            self.reflected_sky_thermal,
            self.reflected_sky_scattered,
            self.reflected_background_emitted,
            self.reflected_background_solar,
            self.path_thermal,
            self.path_scattered,
        ]
    }

    /// Sum of all terms: the radiance reaching the sensor.
    pub fn total(&self) -> f64 {
        self.emitted
            + self.reflected_solar
            + self.reflected_sky_thermal
            + self.reflected_sky_scattered
            + self.reflected_background_emitted
            + self.reflected_background_solar
            + self.path_thermal
            + self.path_scattered
    }

    /// self += weight · other, term by term (for band integration).
    pub fn accumulate(&mut self, other: &RadianceTerms, weight: f64) {
        self.emitted += weight * other.emitted;
        self.reflected_solar += weight * other.reflected_solar;
        self.reflected_sky_thermal += weight * other.reflected_sky_thermal;
        self.reflected_sky_scattered += weight * other.reflected_sky_scattered;
        self.reflected_background_emitted += weight * other.reflected_background_emitted;
        self.reflected_background_solar += weight * other.reflected_background_solar;
        self.path_thermal += weight * other.path_thermal;
        self.path_scattered += weight * other.path_scattered;
    }
}

/// Band-integrates per-bin terms: Σᵢ wᵢ · terms(i) over a band's bins, term by
/// term (`terms(i)` gets the index into `band.weights` / `band.wavenumber_cm1`).
pub fn integrate_terms<F>(band: &super::spectral::Band, mut terms: F) -> RadianceTerms
where
    F: FnMut(usize) -> RadianceTerms,
{
    let mut acc = RadianceTerms::default();
    for (i, w) in band.weights.iter().enumerate() {
        acc.accumulate(&terms(i), *w);
    }
    acc
}

fn surface_sky(
    emissivity: f64,
    target_bb: f64,
    sun: &SunIllumination,
    sky: &SkyRadiance,
    path: &PathRadiance,
) -> RadianceTerms {
    let rho = 1.0 - emissivity;
    RadianceTerms {
        emitted: emissivity * target_bb * path.tau2,
        reflected_solar: sun.reflected_basis_w_m2_sr_um() * rho * path.tau2,
        reflected_sky_thermal: sky.l_de_w_m2_sr_um * rho * path.tau2,
        reflected_sky_scattered: sky.l_ds_w_m2_sr_um * rho * path.tau2,
        reflected_background_emitted: 0.0,
        reflected_background_solar: 0.0,
        path_thermal: path.l_ue_w_m2_sr_um,
        path_scattered: path.l_us_w_m2_sr_um,
    }
}

/// Eq. 1, diffuse surface:
/// L = ε(0,λ) L_T τ₂ + I_T (E_S/π) τ₁ cos θ_S (1−ε(0,λ)) τ₂ + [L_DE + L_DS](1−ε(0,λ)) τ₂ + L_UE + L_US,
/// with `emissivity_normal` = ε(0, λ) and `sky_dome` the sky-dome-integrated
/// downwelled radiances.
pub fn case1_diffuse(
    emissivity_normal: f64,
    target_blackbody_w_m2_sr_um: f64,
    sun: &SunIllumination,
    sky_dome: &SkyRadiance,
    path: &PathRadiance,
) -> RadianceTerms {
    surface_sky(
        emissivity_normal,
        target_blackbody_w_m2_sr_um,
        sun,
        sky_dome,
        path,
    )
}

/// Eq. 2, specular surface whose reflected ray reaches the sky:
/// L = ε(θ,λ) L_T τ₂ + I_T (E_S/π) τ₁ cos θ_S (1−ε(θ,λ)) τ₂ + [L_DE(θ_SK) + L_DS(θ_SK)](1−ε(θ,λ)) τ₂ + L_UE + L_US.
pub fn case2_specular_sky(
    emissivity_theta: f64,
    target_blackbody_w_m2_sr_um: f64,
    sun: &SunIllumination,
    sky_in_reflected_direction: &SkyRadiance,
    path: &PathRadiance,
) -> RadianceTerms {
    surface_sky(
        emissivity_theta,
        target_blackbody_w_m2_sr_um,
        sun,
        sky_in_reflected_direction,
        path,
    )
}

/// Eq. 3, specular surface whose reflected ray hits a background object:
/// L = ε L_T τ₂ + I_T (E_S/π) τ₁ cos θ_S (1−ε) τ₂ + ε_B L_TB (1−ε) τ₂
///   + I_B (E_S/π) τ₁ cos θ_B (1−ε_B)(1−ε) τ₂ + L_UE + L_US.
pub fn case3_specular_background(
    emissivity_theta: f64,
    target_blackbody_w_m2_sr_um: f64,
    sun: &SunIllumination,
    background: &Background,
    path: &PathRadiance,
) -> RadianceTerms {
    let rho = 1.0 - emissivity_theta;
    RadianceTerms {
        emitted: emissivity_theta * target_blackbody_w_m2_sr_um * path.tau2,
        reflected_solar: sun.reflected_basis_w_m2_sr_um() * rho * path.tau2,
        reflected_sky_thermal: 0.0,
        reflected_sky_scattered: 0.0,
        reflected_background_emitted: background.emissivity
            * background.blackbody_w_m2_sr_um
            * rho
            * path.tau2,
        reflected_background_solar: background.sun.reflected_basis_w_m2_sr_um()
            * (1.0 - background.emissivity)
            * rho
            * path.tau2,
        path_thermal: path.l_ue_w_m2_sr_um,
        path_scattered: path.l_us_w_m2_sr_um,
    }
}

/// Eq. 4, the sensor ray goes to the sky: L = L_DE(θ_SK) + L_DS(θ_SK)
/// (reported as `path_thermal` and `path_scattered`).
pub fn case4_sky(sky: &SkyRadiance) -> RadianceTerms {
    RadianceTerms {
        path_thermal: sky.l_de_w_m2_sr_um,
        path_scattered: sky.l_ds_w_m2_sr_um,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sun() -> SunIllumination {
        SunIllumination {
            e_sun_exo_w_m2_um: 31.4159,
            tau1: 0.5,
            cos_incidence: 0.8,
            sun_flag: 1.0,
        }
    }

    #[test]
    fn case1_terms_by_hand() {
        // ε = 0.9, L_T = 10, τ₂ = 0.8, E_S/π = 10.00000..., τ₁ = 0.5, cos = 0.8
        // emitted = 0.9·10·0.8 = 7.2; solar = 10·0.5·0.8·0.1·0.8 = 0.32 (E_S/π = 9.99999...)
        // sky: (3 + 0.5)·0.1·0.8 = 0.24 + 0.04; path 1.5 + 0.2
        let p = PathRadiance {
            tau2: 0.8,
            l_ue_w_m2_sr_um: 1.5,
            l_us_w_m2_sr_um: 0.2,
        };
        let s = SkyRadiance {
            l_de_w_m2_sr_um: 3.0,
            l_ds_w_m2_sr_um: 0.5,
        };
        let t = case1_diffuse(0.9, 10.0, &sun(), &s, &p);
        let es_pi = 31.4159 / std::f64::consts::PI;
        assert!((t.emitted - 7.2).abs() < 1e-12);
        assert!((t.reflected_solar - es_pi * 0.5 * 0.8 * 0.1 * 0.8).abs() < 1e-12);
        assert!((t.reflected_solar - 0.32).abs() < 1e-5);
        assert!((t.reflected_sky_thermal - 0.24).abs() < 1e-12);
        assert!((t.reflected_sky_scattered - 0.04).abs() < 1e-12);
        assert_eq!((t.path_thermal, t.path_scattered), (1.5, 0.2));
        assert!((t.total() - (7.2 + t.reflected_solar + 0.28 + 1.7)).abs() < 1e-12);
        // shadow removes only the solar term; sun behind the facet likewise
        let mut dark = sun();
        dark.sun_flag = 0.0;
        assert_eq!(case1_diffuse(0.9, 10.0, &dark, &s, &p).reflected_solar, 0.0);
        dark = sun();
        dark.cos_incidence = -0.3;
        assert_eq!(case1_diffuse(0.9, 10.0, &dark, &s, &p).reflected_solar, 0.0);
    }

    #[test]
    fn case3_terms_by_hand() {
        // ε = 0.2 (ρ = 0.8), τ₂ = 0.5, ε_B = 0.9, L_TB = 8, background sun basis = 10·0.5·0.8 = 4
        let p = PathRadiance {
            tau2: 0.5,
            l_ue_w_m2_sr_um: 1.0,
            l_us_w_m2_sr_um: 0.1,
        };
        let b = Background {
            emissivity: 0.9,
            blackbody_w_m2_sr_um: 8.0,
            sun: sun(),
        };
        let t = case3_specular_background(0.2, 10.0, &SunIllumination::DARK, &b, &p);
        assert!((t.emitted - 1.0).abs() < 1e-12);
        assert_eq!(t.reflected_solar, 0.0);
        assert!((t.reflected_background_emitted - 0.9 * 8.0 * 0.8 * 0.5).abs() < 1e-12);
        let basis = 31.4159 / std::f64::consts::PI * 0.5 * 0.8;
        assert!((t.reflected_background_solar - basis * 0.1 * 0.8 * 0.5).abs() < 1e-12);
        assert_eq!(t.reflected_sky_thermal + t.reflected_sky_scattered, 0.0);
        assert!((t.total() - (1.0 + 2.88 + basis * 0.04 + 1.1)).abs() < 1e-12);
    }

    #[test]
    fn case2_and_case4_by_hand() {
        let p = PathRadiance {
            tau2: 0.7,
            l_ue_w_m2_sr_um: 2.0,
            l_us_w_m2_sr_um: 0.0,
        };
        let s = SkyRadiance {
            l_de_w_m2_sr_um: 4.0,
            l_ds_w_m2_sr_um: 1.0,
        };
        let t = case2_specular_sky(0.6, 9.0, &SunIllumination::DARK, &s, &p);
        assert!((t.emitted - 0.6 * 9.0 * 0.7).abs() < 1e-12);
        assert!((t.reflected_sky_thermal - 4.0 * 0.4 * 0.7).abs() < 1e-12);
        assert!((t.reflected_sky_scattered - 1.0 * 0.4 * 0.7).abs() < 1e-12);
        let t4 = case4_sky(&s);
        assert_eq!(t4.total(), 5.0);
        assert_eq!(t4.emitted, 0.0);
    }

    #[test]
    fn integrate_terms_weights_each_term() {
        let g = crate::radiometry::SpectralGrid::uniform(500.0, 20.0, 1976);
        let band =
            crate::radiometry::Band::new(&g, &crate::radiometry::SpectralResponse::lwir()).unwrap();
        // constant terms integrate to themselves (weights sum to 1)
        let t = integrate_terms(&band, |_| {
            case4_sky(&SkyRadiance {
                l_de_w_m2_sr_um: 2.0,
                l_ds_w_m2_sr_um: 0.5,
            })
        });
        assert!((t.path_thermal - 2.0).abs() < 1e-12 && (t.path_scattered - 0.5).abs() < 1e-12);
        // a linear-in-index spectrum integrates to Σ wᵢ i
        let expect: f64 = band
            .weights
            .iter()
            .enumerate()
            .map(|(i, w)| w * i as f64)
            .sum();
        let t = integrate_terms(&band, |i| RadianceTerms {
            emitted: i as f64,
            ..Default::default()
        });
        assert!((t.emitted - expect).abs() < 1e-12 && t.total() == t.emitted);
    }

    #[test]
    fn isothermal_enclosure_gives_planck_for_any_emissivity() {
        // Surface, sky and air all at T; path τ arbitrary with L_UE = (1−τ)B:
        // L = εBτ + (1−ε)Bτ + (1−τ)B = B, for every ε (Kirchhoff consistency).
        let b = crate::radiometry::planck::planck_radiance_w_m2_sr_um(10.0, 290.0);
        for eps in [0.0, 0.3, 0.95, 1.0] {
            for tau in [0.0, 0.4, 1.0] {
                let p = PathRadiance {
                    tau2: tau,
                    l_ue_w_m2_sr_um: (1.0 - tau) * b,
                    l_us_w_m2_sr_um: 0.0,
                };
                let s = SkyRadiance {
                    l_de_w_m2_sr_um: b,
                    l_ds_w_m2_sr_um: 0.0,
                };
                let t = case1_diffuse(eps, b, &SunIllumination::DARK, &s, &p);
                assert!((t.total() / b - 1.0).abs() < 1e-14, "{eps} {tau}");
                let bg = Background {
                    emissivity: 0.7,
                    blackbody_w_m2_sr_um: b,
                    sun: SunIllumination::DARK,
                };
                let t3 = case3_specular_background(eps, b, &SunIllumination::DARK, &bg, &p);
                // ε_B B (1−ε) τ < B(1−ε)τ unless ε_B = 1: the background is not an enclosure
                assert!(t3.total() <= b * (1.0 + 1e-14));
            }
        }
    }
}
