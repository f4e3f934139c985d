//! The slab solver against analytic solutions of the heat equation, at the
//! default settings (`ThermSettings::default()`: default mesh and adaptive
//! step). Every comparison: max |error| < 0.05 K over the stated window.

use irsig::therm::balance::{Convection, Orientation};
use irsig::therm::forcing::Forcing;
use irsig::therm::slab::{BackBoundary, Layer, SlabMaterial, SlabModel, ThermSettings};
use irsig::units::STEFAN_BOLTZMANN_W_M2K4;

const TOL_K: f64 = 0.05;

fn constant_forcing(t_end_s: f64, dt_s: f64, f: Forcing) -> Vec<Forcing> {
    let n = (t_end_s / dt_s).round() as usize;
    (0..=n)
        .map(|i| Forcing {
            t_s: i as f64 * dt_s,
            ..f
        })
        .collect()
}

fn night(air_k: f64) -> Forcing {
    Forcing {
        t_s: 0.0,
        air_temp_k: air_k,
        sky_temp_k: air_k,
        wind_speed_m_s: 0.0,
        dni_w_m2: 0.0,
        dhi_w_m2: 0.0,
        ghi_w_m2: 0.0,
        sun_dir_enu: [0.0, 0.0, -1.0],
        dew_point_k: irsig::therm::forcing::DRY_AIR_DEW_POINT_K,
        pressure_pa: 101_325.0,
        precip_mm_h: 0.0,
        ground_temp_k: None,
    }
}

fn concrete(thickness_m: f64, back: BackBoundary) -> SlabMaterial {
    SlabMaterial {
        back,
        ..SlabMaterial::with_defaults(2300.0, 880.0, 1.4, thickness_m, 0.0, 0.0)
    }
}

/// exp(x²)·erfc(x) for x ≥ 0: Numerical Recipes `erfcc` (Chebyshev fit,
/// fractional error < 1.2e-7 everywhere), without the exp(−x²) factor.
fn erfcx(x: f64) -> f64 {
    assert!(x >= 0.0);
    let t = 1.0 / (1.0 + 0.5 * x);
    t * (-1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398
                                + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
        .exp()
}

fn max_err(series: impl Iterator<Item = (f64, f64)>) -> f64 {
    let mut worst = (0.0, 0usize, 0.0, 0.0);
    for (i, (a, b)) in series.enumerate() {
        if (a - b).abs() > worst.0 {
            worst = ((a - b).abs(), i, a, b);
        }
    }
    eprintln!(
        "worst at sample {}: {} vs exact {}",
        worst.1, worst.2, worst.3
    );
    worst.0
}

/// Lumped thin plate (Biot = hL/k = 5e-5): 1 mm aluminium, insulated back,
/// no radiation, constant h = 10 W/m²K, from 280 K in 300 K air:
/// `T(t) = T_air + (T0 − T_air)·exp(−h t / (ρ c L))` (Incropera §5.2).
#[test]
fn lumped_thin_plate_exponential_approach() {
    let mat = SlabMaterial {
        ..SlabMaterial::with_defaults(2700.0, 900.0, 200.0, 0.001, 0.0, 0.0)
    };
    let h = 10.0;
    let settings = ThermSettings {
        convection: Convection::constant(h),
        ..ThermSettings::default()
    };
    let model = SlabModel::new(&mat, Orientation::HORIZONTAL, &settings).unwrap();
    let forcing = constant_forcing(7200.0, 60.0, night(300.0));
    let sol = model
        .march(vec![280.0; model.nodes()], &forcing, None, true)
        .unwrap();
    let tau = mat.areal_heat_capacity_j_m2k() / h;
    let err = max_err(
        sol.series
            .iter()
            .map(|r| (r.surface_temp_k, 300.0 - 20.0 * (-r.t_s / tau).exp())),
    );
    eprintln!(
        "lumped plate: max err {err:.2e} K, {} steps",
        sol.steps_accepted
    );
    assert!(err < TOL_K, "max error {err} K");
}

/// Semi-infinite solid (2 m of concrete, diurnal penetration 0.24 m), step
/// in air temperature with a convective surface (h = 15 W/m²K, no
/// radiation): Carslaw & Jaeger §2.7,
/// `T_s = T0 + (T_air − T0)·[1 − exp(H²κt)·erfc(H√(κt))]`, H = h/k.
/// Compared every 15 min over 24 h.
#[test]
fn semi_infinite_convective_step_erfc() {
    let mat = concrete(2.0, BackBoundary::Insulated);
    let h = 15.0;
    let settings = ThermSettings {
        convection: Convection::constant(h),
        ..ThermSettings::default()
    };
    let model = SlabModel::new(&mat, Orientation::HORIZONTAL, &settings).unwrap();
    let forcing = constant_forcing(86400.0, 900.0, night(300.0));
    let sol = model
        .march(vec![280.0; model.nodes()], &forcing, None, true)
        .unwrap();
    let kappa = mat.diffusivity_m2_s();
    let hh = h / mat.conductivity_w_mk;
    let err = max_err(sol.series.iter().skip(1).map(|r| {
        let x = hh * (kappa * r.t_s).sqrt();
        (r.surface_temp_k, 280.0 + 20.0 * (1.0 - erfcx(x)))
    }));
    eprintln!(
        "convective step: max err {err:.2e} K, {} nodes, {} steps",
        model.nodes(),
        sol.steps_accepted
    );
    assert!(err < TOL_K, "max error {err} K");
}

/// Semi-infinite solid under a constant absorbed surface flux q (sun at the
/// zenith, α = 1, no convection or emission): `T_s = T0 + 2q/k·√(κt/π)`
/// (Carslaw & Jaeger §2.9). q = 200 W/m², compared every 15 min from
/// 15 min to 24 h (rise ≈ 39 K).
#[test]
fn semi_infinite_flux_step_sqrt_t() {
    let mut mat = concrete(2.0, BackBoundary::Insulated);
    mat.solar_absorptivity = 1.0;
    let settings = ThermSettings {
        convection: Convection::constant(0.0),
        ..ThermSettings::default()
    };
    let model = SlabModel::new(&mat, Orientation::HORIZONTAL, &settings).unwrap();
    let q = 200.0;
    let sun = Forcing {
        dni_w_m2: q,
        sun_dir_enu: [0.0, 0.0, 1.0],
        dew_point_k: irsig::therm::forcing::DRY_AIR_DEW_POINT_K,
        pressure_pa: 101_325.0,
        precip_mm_h: 0.0,
        ground_temp_k: None,
        ..night(280.0)
    };
    let forcing = constant_forcing(86400.0, 900.0, sun);
    let sol = model
        .march(vec![280.0; model.nodes()], &forcing, None, true)
        .unwrap();
    let kappa = mat.diffusivity_m2_s();
    let k = mat.conductivity_w_mk;
    let err = max_err(sol.series.iter().skip(1).map(|r| {
        (
            r.surface_temp_k,
            280.0 + 2.0 * q / k * (kappa * r.t_s / std::f64::consts::PI).sqrt(),
        )
    }));
    eprintln!(
        "flux step: max err {err:.2e} K, {} steps",
        sol.steps_accepted
    );
    assert!(err < TOL_K, "max error {err} K");
}

/// Damped temperature wave: air temperature `T_m + A sin ωt` (24 h period)
/// over a semi-infinite solid with a convective surface (h = 15 W/m²K). The
/// periodic solution (Carslaw & Jaeger §2.6) is
/// `T = T_m + Im[Θ0 e^{−(1+i)z/δ} e^{iωt}]`, δ = √(2κ/ω),
/// `Θ0 = hA / (h + k(1+i)/δ)`. The run starts from that exact profile
/// (so no start-up transient) and is compared every 5 min for 48 h.
#[test]
fn semi_infinite_sinusoidal_damped_wave() {
    let mat = concrete(1.0, BackBoundary::Insulated);
    let h = 15.0;
    let settings = ThermSettings {
        convection: Convection::constant(h),
        ..ThermSettings::default()
    };
    let model = SlabModel::new(&mat, Orientation::HORIZONTAL, &settings).unwrap();
    let (tm, amp) = (290.0, 10.0);
    let omega = 2.0 * std::f64::consts::PI / 86400.0;
    let kappa = mat.diffusivity_m2_s();
    let delta = (2.0 * kappa / omega).sqrt();
    let k = mat.conductivity_w_mk;
    // Θ0 = hA / ((h + k/δ) + i k/δ)
    let (re_d, im_d) = (h + k / delta, k / delta);
    let den = re_d * re_d + im_d * im_d;
    let (th_re, th_im) = (h * amp * re_d / den, -h * amp * im_d / den);
    // T(z,t) − Tm = Im[Θ0 e^{−z/δ} e^{i(ωt − z/δ)}]
    let exact = |z: f64, t: f64| {
        let ph = omega * t - z / delta;
        tm + (-z / delta).exp() * (th_re * ph.sin() + th_im * ph.cos())
    };
    let forcing = sine_air_two_days(tm, amp, omega);
    let init: Vec<f64> = model.mesh.z_m.iter().map(|&z| exact(z, 0.0)).collect();
    let sol = model.march(init, &forcing, None, true).unwrap();
    let err = max_err(
        sol.series
            .iter()
            .map(|r| (r.surface_temp_k, exact(0.0, r.t_s))),
    );
    eprintln!(
        "damped wave: surface amplitude {:.3} K, max err {err:.2e} K",
        (th_re * th_re + th_im * th_im).sqrt()
    );
    assert!(err < TOL_K, "max error {err} K");
}

/// Two days of night-time forcing every 5 min with the air temperature
/// `tm + amp·sin(ωt)` (the periodic tests' drive).
fn sine_air_two_days(tm: f64, amp: f64, omega: f64) -> Vec<Forcing> {
    let dt = 300.0;
    (0..=(2 * 86400 / 300))
        .map(|i| {
            let t = i as f64 * dt;
            Forcing {
                t_s: t,
                ..night(tm + amp * (omega * t).sin())
            }
        })
        .collect()
}

/// Bisection for a monotone decreasing function on [lo, hi].
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    assert!(f(lo) > 0.0 && f(hi) < 0.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if f(m) > 0.0 { lo = m } else { hi = m }
    }
    0.5 * (lo + hi)
}

/// Steady state of a slab between a full radiative/convective/solar surface
/// balance and a deep-ground node: the profile is linear and the surface
/// temperature solves
/// `αS + ε(F_sky σT_sky⁴ + F_gnd σT_air⁴) − εσT_s⁴ + h(T_air − T_s) = k/L·(T_s − T_deep)`,
/// found here by bisection. The solver marches 60 days of constant forcing
/// from a uniform 250 K.
#[test]
fn slab_steady_state_deep_ground() {
    let mat = SlabMaterial {
        back: BackBoundary::DeepGround {
            temp_k: Some(285.0),
        },
        internal_power_w_m2: 10.0,
        ground_albedo: Some(0.3),
        ..SlabMaterial::with_defaults(1800.0, 1000.0, 1.2, 0.3, 0.7, 0.9)
    };
    let o = Orientation {
        slope_deg: 20.0,
        aspect_deg: 180.0,
    };
    // The analytic balance below uses the linear (McAdams) coefficient.
    let settings = ThermSettings {
        convection: Convection::mcadams(),
        ..ThermSettings::default()
    };
    let model = SlabModel::new(&mat, o, &settings).unwrap();
    let sd = [0.0, -0.6f64, 0.8];
    let f = Forcing {
        air_temp_k: 300.0,
        sky_temp_k: 275.0,
        wind_speed_m_s: 3.0,
        dni_w_m2: 700.0,
        dhi_w_m2: 100.0,
        ghi_w_m2: 660.0,
        sun_dir_enu: sd,
        dew_point_k: irsig::therm::forcing::DRY_AIR_DEW_POINT_K,
        pressure_pa: 101_325.0,
        precip_mm_h: 0.0,
        ground_temp_k: None,
        ..night(300.0)
    };
    let forcing = constant_forcing(60.0 * 86400.0, 86400.0, f);
    let sol = model
        .march(vec![250.0; model.nodes()], &forcing, None, false)
        .unwrap();
    let n = o.normal_enu();
    let cosi = n[0] * sd[0] + n[1] * sd[1] + n[2] * sd[2];
    let (fs, fg) = (o.sky_view_factor(), o.ground_view_factor());
    let sig = STEFAN_BOLTZMANN_W_M2K4;
    let h = 5.7 + 3.8 * 3.0;
    let src = 0.7 * (700.0 * cosi + 100.0 * fs + 0.3 * 660.0 * fg)
        + 0.9 * sig * (fs * 275f64.powi(4) + fg * 300f64.powi(4))
        + 10.0;
    let ts = bisect(
        |t| src - 0.9 * sig * t.powi(4) + h * (300.0 - t) - 1.2 / 0.3 * (t - 285.0),
        200.0,
        400.0,
    );
    let err = (sol.surface_temp_k - ts).abs();
    eprintln!("steady deep ground: T_s {ts:.4} K, err {err:.2e} K");
    assert!(err < TOL_K, "error {err} K");
    // The equilibrium used for spin-up is the same steady state.
    let eq = model.equilibrium(&forcing[0], 1.0, Some(285.0)).unwrap();
    assert!((eq[0] - ts).abs() < TOL_K);
    // Linear profile between the faces.
    let (z, p) = (&model.mesh.z_m, &sol.profile_k);
    for (zi, ti) in z.iter().zip(p) {
        let lin = ts + (285.0 - ts) * zi / 0.3;
        assert!(
            (ti - lin).abs() < TOL_K,
            "profile at z = {zi}: {ti} vs {lin}"
        );
    }
}

/// Steady state of a plate exposed to air on both faces (back: convection
/// and longwave to air-temperature surroundings): the through-slab flux
/// `k/L·(T_s − T_b)` equals the back loss, which fixes T_b given T_s; T_s
/// then solves the surface balance (nested bisection).
#[test]
fn slab_steady_state_exposed_back() {
    let mat = SlabMaterial {
        back: BackBoundary::ExposedToAir { area_factor: 1.0 },
        ..SlabMaterial::with_defaults(1200.0, 1500.0, 0.2, 0.02, 0.8, 0.9)
    };
    // The analytic balance below uses the linear (McAdams) coefficient.
    let settings = ThermSettings {
        convection: Convection::mcadams(),
        ..ThermSettings::default()
    };
    let model = SlabModel::new(&mat, Orientation::HORIZONTAL, &settings).unwrap();
    let f = Forcing {
        air_temp_k: 295.0,
        sky_temp_k: 270.0,
        wind_speed_m_s: 1.0,
        dni_w_m2: 800.0,
        dhi_w_m2: 0.0,
        ghi_w_m2: 800.0,
        sun_dir_enu: [0.0, 0.0, 1.0],
        dew_point_k: irsig::therm::forcing::DRY_AIR_DEW_POINT_K,
        pressure_pa: 101_325.0,
        precip_mm_h: 0.0,
        ground_temp_k: None,
        ..night(295.0)
    };
    let forcing = constant_forcing(10.0 * 86400.0, 86400.0, f);
    let sol = model
        .march(vec![295.0; model.nodes()], &forcing, None, false)
        .unwrap();
    let sig = STEFAN_BOLTZMANN_W_M2K4;
    let h = 5.7 + 3.8;
    let g = 0.2 / 0.02;
    let back_temp = |ts: f64| {
        bisect(
            |tb| g * (ts - tb) - (h * (tb - 295.0) + 0.9 * sig * (tb.powi(4) - 295f64.powi(4))),
            250.0,
            ts + 1e-9,
        )
    };
    let ts = bisect(
        |t| {
            0.8 * 800.0 + 0.9 * sig * 270f64.powi(4) - 0.9 * sig * t.powi(4) + h * (295.0 - t)
                - g * (t - back_temp(t))
        },
        296.0,
        400.0,
    );
    let err = (sol.surface_temp_k - ts).abs();
    let err_b = (sol.profile_k.last().unwrap() - back_temp(ts)).abs();
    eprintln!("steady exposed back: T_s {ts:.4} K err {err:.2e} K, back err {err_b:.2e} K");
    assert!(err < TOL_K && err_b < TOL_K, "errors {err} K, {err_b} K");
}

// --- Layered slabs ------------------------------------------------------------

fn layer(thickness_m: f64, k: f64, rho: f64, c: f64) -> Layer {
    Layer {
        thickness_m,
        conductivity_w_mk: k,
        density_kg_m3: rho,
        specific_heat_j_kgk: c,
    }
}

/// Dry sand over moist sand (the desert sand of scenes/materials.toml's
/// kind) and a conductive skin over insulation: the two contrasts of k.
fn layer_pairs() -> [[Layer; 2]; 2] {
    [
        [
            layer(0.015, 0.24, 1600.0, 800.0),
            layer(0.485, 0.90, 1645.0, 892.0),
        ],
        [
            layer(0.05, 1.4, 2300.0, 880.0),
            layer(0.10, 0.04, 30.0, 1400.0),
        ],
    ]
}

/// Steady state of a two-layer slab between the surface balance of
/// [`slab_steady_state_deep_ground`] and a deep-ground node: the heat flows
/// through the layers' resistances in series, `q = (T_s − T_deep) /
/// (d₁/k₁ + d₂/k₂)`, and the profile is linear in each layer, kinked at the
/// interface (`T_i = T_s − q·d₁/k₁`). Max |error| < 0.05 K at every node.
#[test]
fn layered_slab_steady_state_series_resistance() {
    for [l1, l2] in layer_pairs() {
        let mat = SlabMaterial {
            back: BackBoundary::DeepGround {
                temp_k: Some(285.0),
            },
            ..SlabMaterial::with_layers(&[l1, l2], 0.7, 0.9).unwrap()
        };
        let settings = ThermSettings {
            convection: Convection::mcadams(),
            ..ThermSettings::default()
        };
        let model = SlabModel::new(&mat, Orientation::HORIZONTAL, &settings).unwrap();
        let f = Forcing {
            sky_temp_k: 275.0,
            wind_speed_m_s: 3.0,
            ..night(300.0)
        };
        let forcing = constant_forcing(120.0 * 86400.0, 86400.0, f);
        let sol = model
            .march(vec![250.0; model.nodes()], &forcing, None, false)
            .unwrap();
        let resistance =
            l1.thickness_m / l1.conductivity_w_mk + l2.thickness_m / l2.conductivity_w_mk;
        assert!((mat.conductance_w_m2k() - 1.0 / resistance).abs() < 1e-12);
        let sig = STEFAN_BOLTZMANN_W_M2K4;
        let h = 5.7 + 3.8 * 3.0;
        let ts = bisect(
            |t| {
                0.9 * sig * (275f64.powi(4) - t.powi(4)) + h * (300.0 - t)
                    - (t - 285.0) / resistance
            },
            200.0,
            400.0,
        );
        let q = (ts - 285.0) / resistance;
        let exact = |z: f64| {
            if z <= l1.thickness_m {
                ts - q * z / l1.conductivity_w_mk
            } else {
                ts - q
                    * (l1.thickness_m / l1.conductivity_w_mk
                        + (z - l1.thickness_m) / l2.conductivity_w_mk)
            }
        };
        let (z, p) = (&model.mesh.z_m, &sol.profile_k);
        assert!(
            z.contains(&l1.thickness_m),
            "no node on the interface: {z:?}"
        );
        let err = max_err(z.iter().zip(p).map(|(zi, ti)| (*ti, exact(*zi))));
        eprintln!(
            "layered steady: T_s {ts:.3} K, q {q:.2} W/m2, {} nodes, max err {err:.2e} K",
            z.len()
        );
        assert!(err < TOL_K, "max error {err} K");
    }
}

/// A complex number, for the periodic solution below.
#[derive(Clone, Copy)]
struct C(f64, f64);

impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C(
            (self.0 * o.0 + self.1 * o.1) / d,
            (self.1 * o.0 - self.0 * o.1) / d,
        )
    }
    fn scale(self, s: f64) -> C {
        C(self.0 * s, self.1 * s)
    }
    fn cosh(self) -> C {
        C(self.0.cosh() * self.1.cos(), self.0.sinh() * self.1.sin())
    }
    fn sinh(self) -> C {
        C(self.0.sinh() * self.1.cos(), self.0.cosh() * self.1.sin())
    }
}

/// The periodic (diurnal) state of a two-layer slab with an insulated back
/// under a sinusoidal air temperature and a constant convective coefficient
/// (no radiation): Carslaw & Jaeger §3.7 / the thermal-quadrupole method
/// (Maillet et al. 2000). Each layer j carries `θ(z) e^{iωt}` with wave
/// number `q_j = (1 + i)/δ_j`, δ_j = sqrt(2κ_j/ω); a layer's transfer matrix
/// takes (θ, F = −k θ') from its top to its bottom,
/// `θ_b = θ_t cosh(q d) − F_t sinh(q d)/(k q)`,
/// `F_b = −θ_t k q sinh(q d) + F_t cosh(q d)`; the insulated back (F = 0)
/// gives the surface admittance `Y = F_s/θ_s` and `h(A − θ_s) = Y θ_s`
/// the surface amplitude. The model marches two days from the exact
/// profile; max |error| < 0.05 K at the surface and at the interface,
/// every 5 minutes.
#[test]
fn layered_slab_periodic_state_quadrupoles() {
    for [l1, l2] in layer_pairs() {
        let mat = SlabMaterial::with_layers(&[l1, l2], 0.0, 0.0).unwrap();
        let h = 15.0;
        let settings = ThermSettings {
            convection: Convection::constant(h),
            ..ThermSettings::default()
        };
        let model = SlabModel::new(&mat, Orientation::HORIZONTAL, &settings).unwrap();
        let (tm, amp) = (290.0, 10.0);
        let omega = 2.0 * std::f64::consts::PI / 86400.0;
        let q = |l: &Layer| C(1.0, 1.0).scale((omega / (2.0 * l.diffusivity_m2_s())).sqrt());
        // (θ, F) at depth z below the top of layer l, from (θ_t, F_t).
        let carry = |l: &Layer, th: C, f: C, z: f64| {
            let (qz, kq) = (q(l).scale(z), q(l).scale(l.conductivity_w_mk));
            let th_b = th.mul(qz.cosh()).add(f.mul(qz.sinh()).div(kq).scale(-1.0));
            let f_b = th.mul(kq).mul(qz.sinh()).scale(-1.0).add(f.mul(qz.cosh()));
            (th_b, f_b)
        };
        // Y: the back flux is linear in (θ_s, F_s); F_back(1, Y) = 0.
        let back = |th: C, f: C| {
            let (a, b) = carry(&l1, th, f, l1.thickness_m);
            carry(&l2, a, b, l2.thickness_m).1
        };
        let (f10, f01) = (
            back(C(1.0, 0.0), C(0.0, 0.0)),
            back(C(0.0, 0.0), C(1.0, 0.0)),
        );
        let y = f10.div(f01).scale(-1.0);
        let th_s = C(h * amp, 0.0).div(C(h, 0.0).add(y));
        let f_s = y.mul(th_s);
        let at = |z: f64| {
            if z <= l1.thickness_m {
                carry(&l1, th_s, f_s, z).0
            } else {
                let (a, b) = carry(&l1, th_s, f_s, l1.thickness_m);
                carry(&l2, a, b, z - l1.thickness_m).0
            }
        };
        // T(z, t) = tm + Im[θ(z) e^{iωt}]
        let exact = |z: f64, t: f64| {
            let th = at(z);
            tm + th.0 * (omega * t).sin() + th.1 * (omega * t).cos()
        };
        let forcing = sine_air_two_days(tm, amp, omega);
        let init: Vec<f64> = model.mesh.z_m.iter().map(|&z| exact(z, 0.0)).collect();
        let sol = model.march(init, &forcing, None, true).unwrap();
        let err = max_err(
            sol.series
                .iter()
                .map(|r| (r.surface_temp_k, exact(0.0, r.t_s))),
        );
        let amp_s = (th_s.0 * th_s.0 + th_s.1 * th_s.1).sqrt();
        eprintln!("layered periodic: surface amplitude {amp_s:.3} K, max err {err:.2e} K");
        assert!(err < TOL_K, "surface: max error {err} K");
        // The end profile against the exact one (the interface included).
        let t_end = sol.series.last().unwrap().t_s;
        let err = max_err(
            (model.mesh.z_m.iter().zip(&sol.profile_k)).map(|(z, t)| (*t, exact(*z, t_end))),
        );
        assert!(err < TOL_K, "profile: max error {err} K");
    }
}
