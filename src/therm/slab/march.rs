//! The march: backward Euler with adaptive steps, the surface-only Newton
//! iteration, spin-up and the step records (module docs of [`super`], "Time").

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::therm::aero::{self, Exchange, Roughness};
use crate::therm::balance::{
    self, DriveInputs, Orientation, SurfaceDrive, SurfaceFluxes, SurfaceOptics,
};
use crate::therm::forcing::Forcing;
use crate::therm::surface::{SurfaceKind, WaterBody, mixing_conductances, shortwave_fractions};

use super::*;

/// Surface state and every flux term at one output time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    /// Time, s from the start of the forcing.
    pub t_s: f64,
    /// Surface temperature, K.
    pub surface_temp_k: f64,
    /// Air temperature, K.
    pub air_temp_k: f64,
    /// Whether the facet saw the sun (a sunlit fraction above one half).
    pub sunlit: bool,
    /// Sunlit fraction in force (0 … 1).
    pub sunlit_fraction: f64,
    /// Water held by the surface store, mm (solids only).
    pub water_store_mm: f64,
    /// Sky view factor of the facet (the rest of the hemisphere is ground).
    pub sky_view: f64,
    /// Every term of the surface energy balance.
    pub surface: SurfaceFluxes,
    /// Conduction from the surface node into the slab, W/m² (under a
    /// canopy: from the canopy skin into the soil).
    pub conduction_into_slab_w_m2: f64,
    /// Temperature of the soil surface under a canopy skin, K (node 1; the
    /// surface temperature for every other surface kind).
    pub soil_surface_temp_k: f64,
    /// Snow: the surplus that melts snow while the surface is held at 0 °C,
    /// W/m² (the surface node's balance at the cap, its storage term left
    /// out); 0 below the cap and for other surfaces.
    pub melt_w_m2: f64,
    /// Flux into the slab through the back face, W/m².
    pub back_w_m2: f64,
    /// Temperature of the back face, K.
    pub back_temp_k: f64,
    /// Heat stored in the slab relative to 0 K, J/m².
    pub stored_energy_j_m2: f64,
    /// ∫(net surface + back) flux dt since the start of the march, J/m²
    /// (exact for the discrete scheme: equals the stored-energy change).
    pub energy_in_j_m2: f64,
}

/// What [`SlabModel::march`] returns.
#[derive(Clone, Debug, PartialEq)]
pub struct ThermSolution {
    /// Surface temperature at the last forcing time (the image time), K.
    pub surface_temp_k: f64,
    /// Water in the surface store at the image time, mm.
    pub water_store_mm: f64,
    /// Node temperatures at the last forcing time, K.
    pub profile_k: Vec<f64>,
    /// One record per forcing sample (empty unless asked for).
    pub series: Vec<StepRecord>,
    /// Accepted and rejected internal steps.
    pub steps_accepted: usize,
    /// Rejected internal steps.
    pub steps_rejected: usize,
    /// Newton iterations over all steps (accepted, rejected and the
    /// spin-up's steady state), i.e. surface-balance evaluations.
    pub newton_iterations: usize,
}

/// The window of forcing (from its first sample) whose mean drive gives the
/// initial profile under [`SpinUpStart::MeanForcing`], s: one day.
pub const SPIN_UP_MEAN_WINDOW_S: f64 = 86_400.0;

/// A march stopped at a forcing sample: everything its next step reads
/// (the node profile, the last accepted increment and step, the step
/// suggestion, the water store) and its counters. Resuming it with
/// [`SlabModel::advance`] gives the bits of the march that did not stop.
#[derive(Clone, Debug, PartialEq)]
pub struct MarchState {
    /// Index of the forcing sample the march stands at.
    pub at: usize,
    temps: Vec<f64>,
    prev_inc: Vec<f64>,
    prev_h: f64,
    h_try: f64,
    store_mm: f64,
    energy_in: f64,
    /// Accepted and rejected steps and Newton iterations so far.
    pub accepted: usize,
    /// Rejected steps so far.
    pub rejected: usize,
    /// Newton iterations so far.
    pub newton: usize,
}

/// A slab of one material at one orientation, ready to march.
#[derive(Clone, Debug)]
pub struct SlabModel {
    /// The slab's material.
    pub material: SlabMaterial,
    /// Orientation of the facet.
    pub orientation: Orientation,
    /// Solver settings (step, tolerance, mesh, convection, spin-up).
    pub settings: ThermSettings,
    /// The graded mesh (shared by the solves of one material in a cache).
    pub mesh: Arc<Mesh>,
    normal: [f64; 3],
    f_sky: f64,
    optics: SurfaceOptics,
    /// Height of the facet above the ground, m (for the wind).
    height_m: f64,
    roughness: Roughness,
    /// Fraction of the absorbed shortwave deposited in each node.
    sw_fraction: Vec<f64>,
    /// Step with the full-system Newton iteration (the algorithm before
    /// issue 12), as the reference of the surface-only Newton's test.
    #[cfg(test)]
    full_newton: bool,
}

/// Scratch of [`SlabModel::implicit_step`]'s elimination of the linear
/// interior. `beta`, `gamma`, `inv_diag` and `g_inv_diag` depend only on
/// the step size, the conductances and the back-face case, so they are kept
/// for the next step when those repeat (every step at the largest step size
/// on a solid's constant conductances); `alpha` depends on the old profile
/// and is redone every step.
struct Work {
    alpha: Vec<f64>,
    beta: Vec<f64>,
    gamma: Vec<f64>,
    /// `1/diag_i` and `g_i/diag_i` of the eliminated rows: the right-hand
    /// side's recurrence is then a multiply-add per row, not a division in
    /// the loop-carried chain.
    inv_diag: Vec<f64>,
    g_inv_diag: Vec<f64>,
    /// What the kept coefficients were built for: 1/h's bits, m, whether
    /// the back node is fixed, and the conductances.
    built: Option<(u64, usize, bool)>,
    built_g: Vec<f64>,
    /// Newton iterations done with this scratch.
    newton: usize,
}

impl MarchState {
    /// Number of nodes of the slab it marches.
    pub fn nodes(&self) -> usize {
        self.temps.len()
    }
}

impl SlabModel {
    /// Builds the mesh and checks the inputs.
    pub fn new(
        material: &SlabMaterial,
        orientation: Orientation,
        settings: &ThermSettings,
    ) -> Result<Self, ThermError> {
        material.validate()?;
        Self::with_mesh(
            material,
            orientation,
            settings,
            Arc::new(Mesh::graded(material, settings)),
        )
    }

    /// [`SlabModel::new`] with a mesh built before; `mesh` must be
    /// `Mesh::graded(material, settings)` (a vegetated material's canopy
    /// skin node is added here, [`Mesh::with_skin`]).
    pub(crate) fn with_mesh(
        material: &SlabMaterial,
        orientation: Orientation,
        settings: &ThermSettings,
        mesh: Arc<Mesh>,
    ) -> Result<Self, ThermError> {
        material.validate()?;
        if !(settings.step_s.is_finite() && settings.step_s > 0.0) {
            return Err(ThermError::BadInput(format!(
                "step_s must be > 0, got {}",
                settings.step_s
            )));
        }
        if let Some(t) = settings.tol_k
            && !(t.is_finite() && t > 0.0)
        {
            return Err(ThermError::BadInput(format!("tol_k must be > 0, got {t}")));
        }
        if !(orientation.slope_deg.is_finite() && orientation.aspect_deg.is_finite()) {
            return Err(ThermError::BadInput("orientation must be finite".into()));
        }
        if let Some(l) = settings.convection.surface_layer() {
            l.validate().map_err(ThermError::BadInput)?;
        }
        // A canopy is a skin node over the soil mesh (surface.rs).
        let mesh = match material.surface {
            SurfaceKind::Vegetation(c) => {
                Arc::new(mesh.with_skin(c.heat_capacity_j_m2k, c.skin_conductance_w_m2k))
            }
            _ => mesh,
        };
        let n = mesh.z_m.len();
        let sw_fraction = match material.surface {
            SurfaceKind::Water(w) => {
                shortwave_fractions(&mesh.z_m, w.surface_fraction, w.extinction_per_m)
            }
            SurfaceKind::Vegetation(c) => (0..n)
                .map(|i| match i {
                    0 => 1.0 - c.soil_shortwave_fraction,
                    1 => c.soil_shortwave_fraction,
                    _ => 0.0,
                })
                .collect(),
            _ => (0..n).map(|i| if i == 0 { 1.0 } else { 0.0 }).collect(),
        };
        Ok(SlabModel {
            material: *material,
            orientation,
            settings: *settings,
            mesh,
            height_m: 0.0,
            roughness: material.surface.roughness(),
            sw_fraction,
            normal: orientation.normal_enu(),
            f_sky: orientation.sky_view_factor(),
            optics: SurfaceOptics {
                solar_absorptivity: material.solar_absorptivity,
                thermal_emissivity: material.thermal_emissivity,
                ground_albedo: material
                    .ground_albedo
                    .unwrap_or(balance::DEFAULT_GROUND_ALBEDO),
                internal_power_w_m2: material.internal_power_w_m2,
            },
            #[cfg(test)]
            full_newton: false,
        })
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.mesh.z_m.len()
    }

    /// The same model with part `blocked` of its sky hidden by the scene
    /// (`trace::sky_view`): sky view factor (1 + cos β)/2 − blocked, rest ground.
    pub fn with_blocked_sky(mut self, blocked: f64) -> Self {
        if blocked.is_finite() {
            self.f_sky = (self.f_sky - blocked).clamp(0.0, 1.0);
        }
        self
    }

    /// The same model for a facet `height_m` above the ground (wind at
    /// the facet; see [`aero::Exchange::new`]).
    pub fn with_height(mut self, height_m: f64) -> Self {
        self.height_m = if height_m.is_finite() {
            height_m.max(0.0)
        } else {
            0.0
        };
        self
    }

    /// The temperature-independent surface drive at an instant, with the
    /// sunlit fraction `sunlit` (0 shadow … 1 sun). A solid's water store
    /// is taken as dry; [`SlabModel::march`] wets it.
    pub fn drive(&self, f: &Forcing, sunlit: f64) -> SurfaceDrive {
        self.drive_with(f, sunlit, true)
    }

    /// [`Self::drive`] for a march step: the rain's wet-bulb temperature
    /// (four arctangents and two exponentials) is worked out only while it
    /// rains — with no rain its coefficient is 0 and the rain term is 0
    /// whatever the temperature (the air temperature stands in).
    fn step_drive(&self, f: &Forcing, sunlit: f64) -> SurfaceDrive {
        self.drive_with(f, sunlit, f.precip_mm_h > 0.0)
    }

    fn drive_with(&self, f: &Forcing, sunlit: f64, rain_temp: bool) -> SurfaceDrive {
        let mut d = balance::surface_drive(
            &DriveInputs {
                air_temp_k: f.air_temp_k,
                sky_temp_k: f.sky_temp_k,
                ground_temp_k: f.ground_k(),
                wind_speed_m_s: f.wind_speed_m_s,
                dni_w_m2: f.dni_w_m2,
                dhi_w_m2: f.dhi_w_m2,
                ghi_w_m2: f.ghi_w_m2,
                sun_dir_enu: f.sun_dir_enu,
                sunlit,
            },
            &self.optics,
            self.normal,
            self.f_sky,
        );
        let slope = self.orientation.slope_deg;
        if let Some(layer) = self.settings.convection.surface_layer() {
            let ex = |s: f64, r: &Roughness| {
                Exchange::new(
                    layer,
                    r,
                    s,
                    self.height_m,
                    f.wind_speed_m_s,
                    f.air_temp_k,
                    f.pressure_pa,
                )
            };
            d.exchange = ex(slope, &self.roughness);
            // Snow keeps SNTHERM's windless exchange (aero::WINDLESS_EXCHANGE_W_M2K)
            // and Crocus's stable floor (aero::SNOW_STABLE_FLOOR).
            if matches!(self.material.surface, SurfaceKind::Snow { .. }) {
                d.exchange.windless_w_m2k = aero::WINDLESS_EXCHANGE_W_M2K;
                d.exchange.stable_floor = aero::SNOW_STABLE_FLOOR;
            }
            // The back of a plate: a smooth face looking the other way
            // (only a back exposed to air exchanges with it).
            if matches!(self.material.back, BackBoundary::ExposedToAir { .. }) {
                d.back_exchange = ex(
                    180.0 - slope,
                    &Roughness::bare(crate::therm::surface::DEFAULT_SOLID_ROUGHNESS_M),
                );
            }
        } else {
            d.exchange.rho_cp_j_m3k =
                aero::air_density_kg_m3(f.pressure_pa, f.air_temp_k) * aero::CP_AIR_J_KGK;
        }
        d.vapour_pressure_pa = f.vapour_pressure_pa();
        d.pressure_pa = f.pressure_pa;
        d.rain_coeff_w_m2k =
            aero::CP_WATER_J_KGK * f.precip_mm_h.max(0.0) / 3600.0 * aero::RHO_WATER_KG_M3 / 1000.0;
        d.rain_temp_k = if rain_temp {
            aero::wet_bulb_k(f.air_temp_k, f.dew_point_k)
        } else {
            f.air_temp_k
        };
        match self.material.surface {
            SurfaceKind::Solid {
                water_capacity_mm,
                soil_wetness,
                ..
            } => {
                // A bare soil evaporates through its surface resistance
                // (Sellers et al. 1992); other solids only from the store.
                d.conductance_m_s = soil_wetness
                    .map_or(0.0, |w| 1.0 / crate::therm::surface::soil_resistance_s_m(w));
                d.dew = water_capacity_mm > 0.0 || soil_wetness.is_some();
            }
            SurfaceKind::Vegetation(c) => {
                let r_s = c.resistance_s_m(
                    d.incident_shortwave_w_m2,
                    f.air_temp_k,
                    d.vapour_pressure_pa,
                    f.pressure_pa,
                );
                d.conductance_m_s = 1.0 / r_s;
                d.dew = true;
            }
            SurfaceKind::Water(_) | SurfaceKind::Snow { .. } => {
                d.conductance_m_s = f64::INFINITY;
                d.dew = true;
            }
        }
        d
    }

    /// The highest surface temperature, K: 0 °C for snow (the surplus
    /// melts it), none for other surfaces.
    pub fn melt_cap_k(&self) -> Option<f64> {
        match self.material.surface {
            SurfaceKind::Snow { .. } => Some(crate::units::ZERO_C_K),
            _ => None,
        }
    }

    /// Melt flux of a step of `h` s from `old` to `new`, W/m²: what the
    /// surface node's balance has left over with the surface held at the
    /// cap (`net − τ·S + g₀·(T₁ − T₀) − C₀·(T₀ − T₀ᵒˡᵈ)/h`); 0 below the cap.
    fn melt_w_m2(
        &self,
        old: &[f64],
        new: &[f64],
        h: f64,
        g: &[f64],
        net_w_m2: f64,
        sw: f64,
    ) -> f64 {
        match self.melt_cap_k() {
            Some(cap) if new[0] >= cap => {
                let inv_h = if h.is_finite() { 1.0 / h } else { 0.0 };
                (net_w_m2 - (1.0 - self.sw_fraction[0]) * sw + g[0] * (new[1] - new[0])
                    - self.mesh.cap_j_m2k[0] * inv_h * (new[0] - old[0]))
                    .max(0.0)
            }
            _ => 0.0,
        }
    }

    /// Whether node 0 is a canopy skin over the soil (vegetation).
    pub fn has_skin(&self) -> bool {
        matches!(self.material.surface, SurfaceKind::Vegetation(_))
    }

    /// Water the surface store can hold, mm (0 for vegetation and water).
    pub fn water_capacity_mm(&self) -> f64 {
        match self.material.surface {
            SurfaceKind::Solid {
                water_capacity_mm, ..
            } => water_capacity_mm,
            _ => 0.0,
        }
    }

    /// Node conductances for a step starting from `temps` (water mixes).
    fn conductances(&self, temps: &[f64], out: &mut [f64]) {
        match self.material.surface {
            SurfaceKind::Water(w) => mixing_conductances(
                &self.mesh.cond_w_m2k,
                temps,
                self.material.conductivity_w_mk,
                self.material.density_kg_m3 * self.material.specific_heat_j_kgk,
                &w,
                out,
            ),
            _ => out.copy_from_slice(&self.mesh.cond_w_m2k),
        }
    }

    /// Deep-ground temperature for this forcing, if the back is tied to one.
    pub fn deep_temp_k(&self, forcing: &[Forcing]) -> Option<f64> {
        match self.material.back {
            BackBoundary::DeepGround { temp_k: Some(t) } => Some(t),
            BackBoundary::DeepGround { temp_k: None } => {
                Some(forcing.iter().map(|f| f.air_temp_k).sum::<f64>() / forcing.len() as f64)
            }
            _ => None,
        }
    }

    /// Back-face flux into the slab and its derivative wrt the back temperature.
    fn back_flux(
        &self,
        drive: &SurfaceDrive,
        back_temp_k: f64,
        deep: Option<f64>,
        g_last: f64,
    ) -> (f64, f64) {
        match self.material.back {
            BackBoundary::Insulated => (0.0, 0.0),
            BackBoundary::ExposedToAir { area_factor } => balance::exposed_back_flux_w_m2(
                area_factor,
                self.material.thermal_emissivity,
                &self.settings.convection,
                &drive.back_exchange,
                drive.wind_speed_m_s,
                drive.air_temp_k,
                back_temp_k,
            ),
            // Not used for the solve (the node is fixed); reported as the
            // conduction from the deep node into the last free node.
            BackBoundary::DeepGround { .. } => (
                g_last * (deep.unwrap_or(back_temp_k) - back_temp_k),
                -g_last,
            ),
        }
    }

    /// One implicit step: solves
    /// `C_i (T_i − T_i^old)/h = Σ conduction + boundary fluxes(T, f)` for T;
    /// `h = ∞` gives the steady state. Returns false if Newton failed.
    ///
    /// Only the boundary nodes are nonlinear: the surface node (the energy
    /// balance) and, for a back exposed to air, the back node. The interior
    /// rows are linear, so they are eliminated once per step (the Thomas
    /// algorithm's sweep, here from the bottom up): node i's row gives
    /// `T_i = α_i + β_i·T_{i−1} + γ_i·T_b` (T_b the back node when it is an
    /// unknown, else γ = 0). Newton's method then iterates on the surface
    /// temperature alone (with the back temperature: a 2×2 system) to
    /// |δT| < 1e-9 K, and the interior follows by back-substitution. In
    /// exact arithmetic every iterate equals the full system's Newton
    /// iterate (its linear rows are solved exactly at every iteration).
    #[allow(clippy::too_many_arguments)]
    fn implicit_step(
        &self,
        old: &[f64],
        new: &mut [f64],
        h: f64,
        g: &[f64],
        drive: &SurfaceDrive,
        deep: Option<f64>,
        w: &mut Work,
    ) -> bool {
        #[cfg(test)]
        if self.full_newton {
            return self.implicit_step_full(old, new, h, g, drive, deep);
        }
        let n = old.len();
        let cap = &self.mesh.cap_j_m2k;
        let sw = drive.absorbed_shortwave_w_m2();
        let inv_h = if h.is_finite() { 1.0 / h } else { 0.0 };
        let back_unknown =
            deep.is_none() && matches!(self.material.back, BackBoundary::ExposedToAir { .. });
        if let Some(d) = deep {
            new[n - 1] = d;
        }
        // Linear rows 1..=m; node m+1 is the fixed deep node, the back
        // unknown, or (insulated back, m = n − 1) absent.
        let m = if deep.is_some() || back_unknown {
            n - 2
        } else {
            n - 1
        };
        // Temperatures relative to the first iterate, u = T − T_ref: the
        // elimination's coefficients then multiply small numbers, and the
        // conduction terms keep the full system's rounding (a thin plate's
        // huge conductances amplify the rounding of T ≈ 300 K otherwise).
        let t_ref = new[0];
        let key = (inv_h.to_bits(), m, deep.is_some());
        if w.built != Some(key) || w.built_g[..] != g[..] {
            // The matrix part of the elimination (a function of the key
            // alone, so reusing it gives the bits a rebuild would).
            let (beta, gamma) = (&mut w.beta, &mut w.gamma);
            let (inv_diag, g_inv_diag) = (&mut w.inv_diag, &mut w.g_inv_diag);
            w.built = None;
            for i in (1..=m).rev() {
                let mut diag = cap[i] * inv_h + g[i - 1];
                let mut gam = 0.0;
                if i + 1 < n {
                    diag += g[i];
                    if i < m {
                        diag -= g[i] * beta[i + 1];
                        gam = g[i] * gamma[i + 1];
                    } else if deep.is_none() {
                        gam = g[i];
                    }
                }
                if diag == 0.0 || !diag.is_finite() {
                    return false;
                }
                let inv = 1.0 / diag;
                inv_diag[i] = inv;
                g_inv_diag[i] = if i < m { g[i] * inv } else { 0.0 };
                beta[i] = g[i - 1] * inv;
                gamma[i] = gam * inv;
            }
            w.built = Some(key);
            w.built_g.copy_from_slice(g);
        }
        let (alpha, beta, gamma) = (&mut w.alpha, &w.beta, &w.gamma);
        if m >= 1 {
            let mut rhs = cap[m] * inv_h * (old[m] - t_ref) + self.sw_fraction[m] * sw;
            // (a fixed deep node is node m + 1)
            if let Some(d) = deep {
                rhs += g[m] * (d - t_ref);
            }
            let mut a = rhs * w.inv_diag[m];
            alpha[m] = a;
            for i in (1..m).rev() {
                let rhs = cap[i] * inv_h * (old[i] - t_ref) + self.sw_fraction[i] * sw;
                a = rhs * w.inv_diag[i] + w.g_inv_diag[i] * a;
                alpha[i] = a;
            }
        }
        // u_1 = a1 + b1·u_0 + c1·u_b, and (back unknown) u_{n−2} = p + q·u_0 + s·u_b.
        let (a1, b1, c1) = match (m, deep) {
            (0, Some(d)) => (d - t_ref, 0.0, 0.0),
            (0, None) => (0.0, 0.0, 1.0),
            _ => (alpha[1], beta[1], gamma[1]),
        };
        let (mut p, mut q, mut s) = (0.0, 1.0, 0.0);
        if back_unknown {
            for i in 1..=m {
                p = alpha[i] + beta[i] * p;
                q *= beta[i];
                s = beta[i] * s + gamma[i];
            }
        }
        let eps = self.material.thermal_emissivity;
        let sw_below = (1.0 - self.sw_fraction[0]) * sw;
        let mut t0 = new[0];
        let mut tb = new[n - 1];
        let mut converged = false;
        for iter in 0..120 {
            w.newton += 1;
            // Residuals R = rhs − lhs; J = −∂R/∂T; solve J·δ = R.
            let (sf, ds) = balance::surface_fluxes(drive, eps, &self.settings.convection, t0);
            let (u0, ub) = (t0 - t_ref, tb - t_ref);
            let u1 = a1 + b1 * u0 + c1 * ub;
            let r0 = -cap[0] * inv_h * (t0 - old[0]) + g[0] * (u1 - u0) + sf.net_w_m2 - sw_below;
            let j00 = cap[0] * inv_h + g[0] * (1.0 - b1) - ds;
            let (d0, db) = if back_unknown {
                let gl = g[n - 2];
                let (qb, dqb) = self.back_flux(drive, tb, deep, 0.0);
                let um = p + q * u0 + s * ub;
                let rb = -cap[n - 1] * inv_h * (tb - old[n - 1])
                    + gl * (um - ub)
                    + self.sw_fraction[n - 1] * sw
                    + qb;
                let (j0b, jb0) = (-g[0] * c1, -gl * q);
                let jbb = cap[n - 1] * inv_h + gl * (1.0 - s) - dqb;
                let det = j00 * jbb - j0b * jb0;
                ((r0 * jbb - j0b * rb) / det, (j00 * rb - jb0 * r0) / det)
            } else {
                (r0 / j00, 0.0)
            };
            if !(d0.is_finite() && db.is_finite()) {
                return false;
            }
            // Damped after 30 iterations: the turbulent exchange has kinks
            // (capped stability factors) where plain Newton can cycle.
            let damp = if iter < 30 { 1.0 } else { 0.5 };
            // Keep the iterate physical; the root is always > 0 K.
            t0 = (t0 + damp * d0).max(1.0);
            if back_unknown {
                tb = (tb + damp * db).max(1.0);
            }
            if d0.abs().max(db.abs()) < 1e-9 {
                converged = true;
                break;
            }
        }
        if !converged {
            return false;
        }
        // Snow: the surface cannot rise above 0 °C; the surface residual
        // falls with T₀, so the capped solution leaves a surplus (the melt).
        if let Some(cap) = self.melt_cap_k()
            && t0 > cap
            && !back_unknown
        {
            t0 = cap;
        }
        new[0] = t0;
        if back_unknown {
            new[n - 1] = tb;
        }
        let (mut u, ub) = (t0 - t_ref, tb - t_ref);
        for i in 1..=m {
            u = alpha[i] + beta[i] * u + gamma[i] * ub;
            new[i] = t_ref + u;
        }
        true
    }

    /// Steady state under forcing `f` with sun flag `sunlit`: the spin-up
    /// initial condition (an implicit step with infinite step size, started
    /// from the air temperature).
    pub fn equilibrium(
        &self,
        f: &Forcing,
        sunlit: f64,
        deep: Option<f64>,
    ) -> Result<Vec<f64>, ThermError> {
        self.steady_state(f, &self.drive(f, sunlit), deep)
            .ok_or_else(|| ThermError::NoConvergence {
                t_s: f.t_s,
                why: "no steady state for the spin-up initial condition".into(),
            })
    }

    /// Steady state under the time-mean surface drive of the first
    /// [`SPIN_UP_MEAN_WINDOW_S`] (24 h) of `forcing` — all of it when it is
    /// shorter — (each sample's drive with its sun/shadow flag, trapezoid
    /// weights in time): every term of [`SurfaceDrive`] is averaged, and
    /// the back face sees the mean air temperature and wind. See the module
    /// docs for why. One whole day is the period of the diurnal forcing,
    /// so its mean is the mean of the periodic solution; and the initial
    /// state then depends only on the first day of the sun/shadow history,
    /// so that marches of histories that differ only later share their
    /// start (the thermal cache's checkpoints, `therm::cache`).
    pub fn mean_equilibrium(
        &self,
        forcing: &[Forcing],
        shadow: Option<&SunHistory>,
        deep: Option<f64>,
    ) -> Result<Vec<f64>, ThermError> {
        let end = forcing
            .partition_point(|f| f.t_s <= forcing[0].t_s + SPIN_UP_MEAN_WINDOW_S)
            .max(1);
        let forcing = &forcing[..end];
        let n = forcing.len();
        let mut sum = SurfaceDrive::default();
        let mut total_w = 0.0;
        for (i, f) in forcing.iter().enumerate() {
            // Trapezoid weights; a single sample has weight 1.
            let w = if n == 1 {
                1.0
            } else {
                let a = forcing[i.saturating_sub(1)].t_s;
                let b = forcing[(i + 1).min(n - 1)].t_s;
                0.5 * (b - a)
            };
            sum.add_scaled(
                w,
                &self.drive(f, sun_fraction(shadow, f.t_s, self.settings.shadow_ramp)),
            );
            total_w += w;
        }
        if total_w <= 0.0 || !total_w.is_finite() {
            return Err(ThermError::BadInput(
                "forcing samples must span a positive time".into(),
            ));
        }
        let mut mean = SurfaceDrive::default();
        mean.add_scaled(1.0 / total_w, &sum);
        let f_mean = Forcing {
            air_temp_k: mean.air_temp_k,
            wind_speed_m_s: mean.wind_speed_m_s,
            ..forcing[0]
        };
        self.steady_state(&f_mean, &mean, deep)
            .ok_or_else(|| ThermError::NoConvergence {
                t_s: forcing[0].t_s,
                why: "no steady state under the mean forcing for the spin-up".into(),
            })
    }

    /// The implicit step of infinite size under `drive` (back face under
    /// `f`), started from the air temperature; `None` if Newton failed.
    fn steady_state(
        &self,
        f: &Forcing,
        drive: &SurfaceDrive,
        deep: Option<f64>,
    ) -> Option<Vec<f64>> {
        let n = self.nodes();
        let old = vec![f.air_temp_k; n];
        let mut new = old.clone();
        let mut w = Work::new(n);
        let mut g = vec![0.0; n - 1];
        let SurfaceKind::Water(water) = self.material.surface else {
            self.conductances(&old, &mut g);
            // A huge (not infinite) step keeps the matrix regular when no
            // heat can leave the slab (e.g. ε = 0 and no convection).
            if self.implicit_step(&old, &mut new, 1e12, &g, drive, deep, &mut w) {
                return Some(new);
            }
            return self.steady_by_stepping(&old, &g, drive, deep, &mut w);
        };
        // Water: the mixing depends on the profile. Start fully mixed and
        // iterate until the stable/unstable pattern repeats.
        let fully_mixed = WaterBody {
            eddy_diffusivity_m2_s: water.convective_diffusivity_m2_s,
            ..water
        };
        mixing_conductances(
            &self.mesh.cond_w_m2k,
            &old,
            self.material.conductivity_w_mk,
            self.material.density_kg_m3 * self.material.specific_heat_j_kgk,
            &fully_mixed,
            &mut g,
        );
        let mut prev = g.clone();
        for _ in 0..20 {
            new.copy_from_slice(&old);
            if !self.implicit_step(&old, &mut new, 1e12, &g, drive, deep, &mut w) {
                return None;
            }
            self.conductances(&new, &mut g);
            if g == prev {
                break;
            }
            prev.copy_from_slice(&g);
        }
        Some(new)
    }

    /// Fallback for [`Self::steady_state`] when Newton on the infinite step
    /// fails (the turbulent and latent terms have kinks where a root can
    /// sit): pseudo-transient continuation, implicit steps from 10 min
    /// growing by 1.5x until the profile changes by < 1e-7 K.
    fn steady_by_stepping(
        &self,
        start: &[f64],
        g: &[f64],
        drive: &SurfaceDrive,
        deep: Option<f64>,
        w: &mut Work,
    ) -> Option<Vec<f64>> {
        let mut cur = start.to_vec();
        let mut new = cur.clone();
        let mut h = 600.0;
        for _ in 0..400 {
            new.copy_from_slice(&cur);
            if !self.implicit_step(&cur, &mut new, h, g, drive, deep, w) {
                h *= 0.25;
                if h < 1.0 {
                    return None;
                }
                continue;
            }
            let change = cur
                .iter()
                .zip(&new)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            cur.copy_from_slice(&new);
            if change < 1e-7 {
                return Some(cur);
            }
            h = (h * 1.5).min(1e9);
        }
        Some(cur)
    }

    /// Marches from the spin-up start ([`ThermSettings::spin_up_start`]) at
    /// the first forcing sample to the last
    /// one; the returned surface temperature is at the last forcing time.
    pub fn solve(
        &self,
        forcing: &[Forcing],
        shadow: Option<&SunHistory>,
        record: bool,
    ) -> Result<ThermSolution, ThermError> {
        let state = self.initial_state(forcing, shadow)?;
        self.march_on(state, forcing, shadow, record)
    }

    /// Marches an explicit initial node profile (length [`Self::nodes`])
    /// through the forcing, from its first to its last sample.
    pub fn march(
        &self,
        init_k: Vec<f64>,
        forcing: &[Forcing],
        shadow: Option<&SunHistory>,
        record: bool,
    ) -> Result<ThermSolution, ThermError> {
        let state = self.start_state(init_k, forcing)?;
        self.march_on(state, forcing, shadow, record)
    }

    /// Marches `state` on to the last forcing sample and returns the
    /// solution there (with the record of every sample reached when
    /// `record`; see [`Self::advance`]).
    pub fn march_on(
        &self,
        mut state: MarchState,
        forcing: &[Forcing],
        shadow: Option<&SunHistory>,
        record: bool,
    ) -> Result<ThermSolution, ThermError> {
        let mut series = Vec::new();
        let rec = if record { Some(&mut series) } else { None };
        self.advance(&mut state, forcing, shadow, forcing.len() - 1, rec)?;
        Ok(Self::finish(state, series))
    }

    /// The state of a march standing at the first forcing sample with the
    /// node profile `init_k` (length [`Self::nodes`]; a fixed deep node is
    /// set to the deep-ground temperature).
    pub fn start_state(
        &self,
        init_k: Vec<f64>,
        forcing: &[Forcing],
    ) -> Result<MarchState, ThermError> {
        validate_forcing(forcing)?;
        let n = self.nodes();
        if init_k.len() != n || init_k.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
            return Err(ThermError::BadInput(format!(
                "initial profile must have {n} finite positive temperatures"
            )));
        }
        let mut temps = init_k;
        if let Some(d) = self.deep_temp_k(forcing) {
            temps[n - 1] = d;
        }
        let s = &self.settings;
        Ok(MarchState {
            at: 0,
            prev_inc: vec![0.0; n],
            temps,
            prev_h: f64::NAN,
            h_try: match s.tol_k {
                Some(_) => s.step_s.min(60.0),
                None => s.step_s,
            },
            store_mm: 0.0,
            energy_in: 0.0,
            accepted: 0,
            rejected: 0,
            newton: 0,
        })
    }

    /// The spin-up state of [`Self::solve`]: the march standing at the
    /// first forcing sample with the initial profile of
    /// [`ThermSettings::spin_up_start`].
    pub fn initial_state(
        &self,
        forcing: &[Forcing],
        shadow: Option<&SunHistory>,
    ) -> Result<MarchState, ThermError> {
        validate_forcing(forcing)?;
        if let Some(h) = shadow {
            h.validate()?;
        }
        let deep = self.deep_temp_k(forcing);
        let init = match self.settings.spin_up_start {
            SpinUpStart::FirstSample => {
                let sunlit0 = sun_fraction(shadow, forcing[0].t_s, self.settings.shadow_ramp);
                self.equilibrium(&forcing[0], sunlit0, deep)?
            }
            SpinUpStart::MeanForcing => self.mean_equilibrium(forcing, shadow, deep)?,
        };
        self.start_state(init, forcing)
    }

    /// Marches `state` on from the forcing sample it stands at to sample
    /// `until` (the march's breakpoints are the forcing samples, so a
    /// march stopped at a sample and resumed is bit for bit the march that
    /// did not stop: everything its next step reads is in the state).
    /// With `series`, the record of each sample reached is pushed (and of
    /// the first sample, when the march stands there).
    pub fn advance(
        &self,
        state: &mut MarchState,
        forcing: &[Forcing],
        shadow: Option<&SunHistory>,
        until: usize,
        mut series: Option<&mut Vec<StepRecord>>,
    ) -> Result<(), ThermError> {
        let n = self.nodes();
        if state.temps.len() != n || until >= forcing.len() {
            return Err(ThermError::BadInput(format!(
                "march state of {} nodes up to sample {until} for a {n}-node slab and {} samples",
                state.temps.len(),
                forcing.len()
            )));
        }
        let deep = self.deep_temp_k(forcing);
        let capacity_mm = self.water_capacity_mm();
        let mut w = Work::new(n);
        let mut g = vec![0.0; n - 1];
        let MarchState {
            at,
            temps,
            prev_inc,
            prev_h,
            h_try,
            store_mm,
            energy_in,
            accepted,
            rejected,
            newton,
        } = state;
        let mut new = temps.clone();
        let s = &self.settings;
        if let Some(out) = series.as_deref_mut()
            && *at == 0
            && out.is_empty()
        {
            let e0 = self.mesh.stored_energy_j_m2(temps);
            out.push(self.record(&forcing[0], shadow, temps, deep, e0, 0.0, *store_mm));
        }
        // Breakpoints: every forcing sample (where the interpolated forcing
        // has a kink). Sun/shadow transitions are not breakpoints: a step
        // takes the history's exact mean sunlit fraction over its span
        // (`mean_sun_fraction`), and the step control resolves the
        // transition like any other change of the drive.
        while *at < until {
            let (a, b) = (forcing[*at].t_s, forcing[*at + 1].t_s);
            let mut t = a;
            while t < b {
                let mut h = h_try.min(s.step_s);
                let last = t + h >= b - 1e-9 * (b - a).max(1e-9);
                if last {
                    h = b - t;
                }
                let t_new = if last { b } else { t + h };
                let f = forcing_at(forcing, t_new);
                let sunlit = mean_sun_fraction(shadow, t, t_new, s.shadow_ramp);
                let mut drive = self.step_drive(&f, sunlit);
                if capacity_mm > 0.0 {
                    wet_drive(&mut drive, *store_mm, f.precip_mm_h, f.air_temp_k, h);
                }
                self.conductances(temps, &mut g);
                new.copy_from_slice(temps);
                if prev_h.is_finite() {
                    // Newton starts from the linear extrapolation of the
                    // last accepted step (the implicit step's root does not
                    // depend on the start; fewer iterations reach it).
                    let r = h / *prev_h;
                    new[0] = (temps[0] + r * prev_inc[0]).max(1.0);
                    new[n - 1] = (temps[n - 1] + r * prev_inc[n - 1]).max(1.0);
                    if let Some(d) = deep {
                        new[n - 1] = d;
                    }
                }
                let ok = self.implicit_step(temps, &mut new, h, &g, &drive, deep, &mut w);
                if !ok {
                    if h <= s.min_step_s {
                        *newton += w.newton;
                        return Err(ThermError::NoConvergence {
                            t_s: t,
                            why: format!("Newton did not converge at the smallest step {h} s"),
                        });
                    }
                    *rejected += 1;
                    *h_try = (h * 0.25).max(s.min_step_s);
                    continue;
                }
                // Local error estimate  h²/2·|T''| ≈ h/(h + h_prev)·|Δ − (h/h_prev)·Δ_prev|.
                if let Some(tol) = s.tol_at(forcing[forcing.len() - 1].t_s - t_new) {
                    let hp = if prev_h.is_finite() { *prev_h } else { h };
                    let mut err = 0.0f64;
                    for i in 0..n {
                        let inc = new[i] - temps[i];
                        err = err.max((inc - h / hp * prev_inc[i]).abs());
                    }
                    err *= h / (h + hp);
                    let fac = if err > 0.0 {
                        0.9 * (tol / err).sqrt()
                    } else {
                        4.0
                    };
                    if err > tol && h > s.min_step_s {
                        *rejected += 1;
                        *h_try = (h * fac.clamp(0.1, 0.9)).max(s.min_step_s);
                        continue;
                    }
                    *h_try = h * fac.clamp(0.2, 4.0);
                    if last {
                        // Keep the pre-truncation step suggestion sensible.
                        *h_try = h_try.max(h);
                    }
                }
                // Accept. The step's fluxes are needed only for the energy
                // record and the water store (a third of a solve's flux
                // evaluations otherwise).
                if series.is_some() || capacity_mm > 0.0 {
                    let (sf, _) = balance::surface_fluxes(
                        &drive,
                        self.material.thermal_emissivity,
                        &s.convection,
                        new[0],
                    );
                    let g_last = g[n - 2];
                    let back = match deep {
                        Some(d) => g_last * (d - new[n - 2]),
                        None => self.back_flux(&drive, new[n - 1], None, g_last).0,
                    };
                    // Shortwave that reaches a fixed deep node leaves the slab.
                    let lost = if deep.is_some() {
                        self.sw_fraction[n - 1] * drive.absorbed_shortwave_w_m2()
                    } else {
                        0.0
                    };
                    let melt = self.melt_w_m2(
                        temps,
                        &new,
                        h,
                        &g,
                        sf.net_w_m2,
                        drive.absorbed_shortwave_w_m2(),
                    );
                    *energy_in += h * (sf.net_w_m2 - lost + back - melt);
                    if capacity_mm > 0.0 {
                        *store_mm = update_store_mm(
                            *store_mm,
                            capacity_mm,
                            f.precip_mm_h,
                            sf.latent_w_m2,
                            f.air_temp_k,
                            h,
                        );
                    }
                }
                for i in 0..n {
                    prev_inc[i] = new[i] - temps[i];
                }
                *prev_h = h;
                temps.copy_from_slice(&new);
                t = t_new;
                *accepted += 1;
            }
            *at += 1;
            if let Some(out) = series.as_deref_mut() {
                let e = self.mesh.stored_energy_j_m2(temps);
                out.push(self.record(&forcing[*at], shadow, temps, deep, e, *energy_in, *store_mm));
            }
        }
        *newton += w.newton;
        Ok(())
    }

    /// The solution a march's final state stands for.
    pub fn finish(state: MarchState, series: Vec<StepRecord>) -> ThermSolution {
        ThermSolution {
            surface_temp_k: state.temps[0],
            water_store_mm: state.store_mm,
            profile_k: state.temps,
            series,
            steps_accepted: state.accepted,
            steps_rejected: state.rejected,
            newton_iterations: state.newton,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        f: &Forcing,
        shadow: Option<&SunHistory>,
        temps: &[f64],
        deep: Option<f64>,
        stored: f64,
        energy_in: f64,
        store_mm: f64,
    ) -> StepRecord {
        let n = temps.len();
        let sunlit = sun_fraction(shadow, f.t_s, self.settings.shadow_ramp);
        let mut drive = self.drive(f, sunlit);
        if self.water_capacity_mm() > 0.0 {
            // The store as it stands, over a nominal 1-s step (the flux the
            // surface supports now).
            wet_drive(&mut drive, store_mm, f.precip_mm_h, f.air_temp_k, 1.0);
        }
        let mut g = vec![0.0; n - 1];
        self.conductances(temps, &mut g);
        let (sf, _) = balance::surface_fluxes(
            &drive,
            self.material.thermal_emissivity,
            &self.settings.convection,
            temps[0],
        );
        let g_last = g[n - 2];
        let back = match deep {
            Some(d) => g_last * (d - temps[n - 2]),
            None => self.back_flux(&drive, temps[n - 1], None, g_last).0,
        };
        StepRecord {
            t_s: f.t_s,
            surface_temp_k: temps[0],
            air_temp_k: f.air_temp_k,
            sunlit: sunlit > 0.5,
            sunlit_fraction: sunlit,
            water_store_mm: store_mm,
            sky_view: self.f_sky,
            surface: sf,
            conduction_into_slab_w_m2: g[0] * (temps[0] - temps[1]),
            melt_w_m2: self.melt_w_m2(
                temps,
                temps,
                f64::INFINITY,
                &g,
                sf.net_w_m2,
                drive.absorbed_shortwave_w_m2(),
            ),
            soil_surface_temp_k: if self.has_skin() { temps[1] } else { temps[0] },
            back_w_m2: back,
            back_temp_k: temps[n - 1],
            stored_energy_j_m2: stored,
            energy_in_j_m2: energy_in,
        }
    }
}

impl Work {
    fn new(n: usize) -> Work {
        Work {
            alpha: vec![0.0; n],
            beta: vec![0.0; n],
            gamma: vec![0.0; n],
            inv_diag: vec![0.0; n],
            g_inv_diag: vec![0.0; n],
            built: None,
            built_g: vec![0.0; n.saturating_sub(1)],
            newton: 0,
        }
    }
}

/// Convenience: surface temperature (and optionally the series) of one
/// material/orientation/shadow history under a forcing series, spun up from
/// equilibrium at the first sample.
pub fn solve_surface(
    material: &SlabMaterial,
    orientation: Orientation,
    shadow: Option<&SunHistory>,
    forcing: &[Forcing],
    settings: &ThermSettings,
    record: bool,
) -> Result<ThermSolution, ThermError> {
    SlabModel::new(material, orientation, settings)?.solve(forcing, shadow, record)
}

#[cfg(test)]
mod reference;
#[cfg(test)]
mod tests;
