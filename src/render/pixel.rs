//! Step 5: the radiance of each sample by the paper's four cases (eqs.
//! 1-4), evaluated bin by bin over the sensor band and band-integrated term
//! by term; then the output planes (supersampling, PSF, noise,
//! quantisation).
//!
//! Atmospheric geometry: τ₂, L_UE, L_US for the target→sensor path at the
//! sensor's height above the target and the view zenith at the target,
//! both on the Earth's sphere ([`crate::scene::frame::path_geometry`]:
//! the vertical tilts by d/R at a distance d from the frame's origin); a
//! sensor above the tables' top (100 km) sees the top's path, the whole
//! atmosphere ([`crate::atmos::TOP_OF_ATMOSPHERE_KM`]);
//! L_DE, L_DS in the specular direction θ_SK; τ₁ at the sun's zenith.
//! Table lookups are memoised on a fine grid of their arguments (0.05° in
//! angles, 10 m in height, 5° in relative azimuth) — deterministic, since a
//! value depends on its key only.
//!
//! [`RadiometryContext::evaluate`] does not loop over the bins for a
//! diffuse surface: eq. 1's band sums are memoised per (material, path
//! key) and the emitted sum is a Hermite table in temperature
//! ([`crate::radiometry::band_coeffs`]; within 2e-8 relative of the loop,
//! 1e-8 K); the sky and the ground beyond the scene are memoised per key.
//! [`RadiometryContext::evaluate_with`] is the bin-by-bin loop (the
//! reference, and what probes use); specular samples always take it.
//! Documented choices:
//! * a sensor lower than the tables' lowest altitude (0.3 km) uses the
//!   0.3 km path scaled as a uniform layer: τ = τ₀.₃^(h/0.3),
//!   L_UE = L_UE,0.3·(1 − τ)/(1 − τ₀.₃), L_US scaled by h/0.3;
//! * view zeniths beyond the tables' last angle (85°) use 85° (counted);
//! * a primary or specular ray that leaves the scene downwards sees an
//!   infinite ground at air temperature, ε = 1 (counted);
//! * a diffuse facet reflects the sky dome over F_sky = (1 + cos β)/2 of
//!   its hemisphere and the ground (black, at the ground material's solved
//!   temperature; reported as `reflected_background_emitted`) over the
//!   rest, the same split as the thermal balance; ground-reflected
//!   sunlight is not in the radiometry (it is in the thermal balance);
//! * a material with 0 < specularity < 1 is the blend
//!   (1 − s)·eq. 1 + s·eq. 2/3.

use std::sync::Arc;

use glam::{DVec3, Vec3};
use serde::Serialize;

use super::atmosphere::path_at;
use super::planes::Planes;
use super::prepare::{Conditions, Static};
use super::sample::{LastKey, Sample, Surface, angle_deg, azimuth_deg, zenith_deg};
use crate::atmos::PathSpectra;
use crate::radiometry::band_coeffs::{DiffuseCoeffs, DiffuseSpectra, Memo, PlanckTable};
use crate::radiometry::planck::planck_radiance_w_m2_sr_um;
use crate::radiometry::{
    Background, PathRadiance, RadianceTerms, SkyRadiance, SunIllumination, case1_diffuse,
    case2_specular_sky, case3_specular_background, case4_sky, integrate_terms,
};
use crate::scene::frame::path_geometry;

/// The band-integrated result of one sample.
#[derive(Clone, Debug, Default, Serialize)]
pub struct SampleResult {
    /// Which of the paper's cases: 1 diffuse, 2 specular→sky, 3 specular→
    /// background, 4 sky; 0 a ray leaving the scene downwards.
    pub case: u8,
    /// The radiance terms of the paper's equations for this sample.
    pub terms: RadianceTerms,
    /// Band-integrated radiance at the sensor, W m⁻² sr⁻¹ µm⁻¹.
    pub radiance_w_m2_sr_um: f64,
    /// View angle from the surface normal, degrees (NaN for the sky).
    pub view_angle_deg: f64,
    /// Band-averaged emissivity at the view angle.
    pub emissivity: f64,
}

type SkyPair = (Vec<f64>, Vec<f64>);
/// Memo key of a target→sensor path: height (10 m), view zenith (0.05°),
/// relative azimuth (5°).
type PathKey = (i64, i64, i64);
/// Memo key of a sky direction: zenith (0.05°), relative azimuth (5°).
type SkyKey = (i64, i64);

/// Per-frame radiometric state: sun spectra, sky dome, memoised lookups.
pub struct RadiometryContext<'a> {
    st: &'a Static,
    cond: &'a Conditions,
    camera: DVec3,
    sun_dir: Vec3,
    sun_zenith_deg: f64,
    sun_azimuth_deg: f64,
    /// E_S at the actual earth-sun distance, W m⁻² µm⁻¹.
    e_exo: Vec<f64>,
    tau1: Vec<f64>,
    dome: SkyPair,
    /// L(λᵢ, T_gnd) of the ground a diffuse facet sees.
    ground_blackbody: Vec<f64>,
    /// ε(0°, λᵢ) of each material (the diffuse part's emissivity).
    eps_normal: Vec<Vec<f64>>,
    paths: Memo<PathKey, PathSpectra>,
    skies: Memo<SkyKey, SkyPair>,
    /// The fast path of [`Self::evaluate`]: band sums per (material, path)
    /// for diffuse surfaces, per path for the ground beyond the scene, per
    /// direction for the sky; the Planck table in temperature.
    planck: PlanckTable,
    diffuse: Memo<(u32, PathKey), DiffuseCoeffs>,
    outside: Memo<PathKey, RadianceTerms>,
    sky_band: Memo<SkyKey, RadianceTerms>,
}

/// Two surfaces the radiometry cannot tell apart (up to the view
/// direction): same material, facet plane normal, temperature and sun flag.
fn same_surface(a: &Surface, b: &Surface) -> bool {
    a.material == b.material
        && a.normal == b.normal
        && a.temp_k.to_bits() == b.temp_k.to_bits()
        && a.sun_now() == b.sun_now()
}

/// Two samples whose radiometry differs only through the small change of
/// view direction and range inside one pixel.
fn same_radiometry(a: &Sample, b: &Sample) -> bool {
    let surf = |x: &Option<Surface>, y: &Option<Surface>| match (x, y) {
        (None, None) => true,
        (Some(x), Some(y)) => same_surface(x, y),
        _ => false,
    };
    surf(&a.surface, &b.surface)
        && match (a.bounce.as_deref(), b.bounce.as_deref()) {
            (None, None) => true,
            (Some((_, x)), Some((_, y))) => surf(x, y),
            _ => false,
        }
}

/// The sample whose radiometry stands for each of one output pixel's n×n
/// samples (row-major, as [`super::output_pixel_samples`] lists them).
///
/// **Uniform-pixel collapse.** When every sample of the pixel sees the same
/// material on the same plane at the same temperature and sun flag (and the
/// same kind of specular background), the band integral is evaluated once,
/// for the sample nearest the pixel centre, and used for all of them: the
/// samples then differ only by the view direction and range inside the
/// pixel (one instantaneous field of view, a few µrad to mrad). Measured
/// against evaluating every sample on the airfield, 512², 4×4: 2e-4 K RMS
/// and 0.013 K max in apparent temperature (BENCHMARKS.md). Pixels across
/// an edge (object, material, shadow, temperature) evaluate every sample.
pub fn representatives(px: &[&Sample], n: u32) -> Vec<usize> {
    let c = ((n / 2) * n + n / 2) as usize;
    if px.len() == (n * n) as usize && px.iter().all(|s| same_radiometry(s, px[c])) {
        vec![c; px.len()]
    } else {
        (0..px.len()).collect()
    }
}

/// [`representatives`] over a whole `sw`×`sh` sample image of `n`×`n`
/// pixels: the index of the sample whose result each sample uses.
pub fn representatives_frame(samples: &[Sample], sw: u32, sh: u32, n: u32) -> Vec<usize> {
    let (w, h) = (sw / n, sh / n);
    let mut rep: Vec<usize> = (0..samples.len()).collect();
    let idx = |x: u32, y: u32, i: u32, j: u32| ((y * n + j) * sw + x * n + i) as usize;
    let (mut ks, mut px) = (Vec::new(), Vec::new());
    for y in 0..h {
        for x in 0..w {
            ks.clear();
            ks.extend((0..n).flat_map(|j| (0..n).map(move |i| idx(x, y, i, j))));
            px.clear();
            px.extend(ks.iter().map(|&k| &samples[k]));
            for (k, r) in ks.iter().zip(representatives(&px, n)) {
                rep[*k] = ks[r];
            }
        }
    }
    rep
}

fn key(x: f64, quantum: f64) -> i64 {
    (x / quantum).round() as i64
}

/// Folds an azimuth difference into [0, 180] degrees.
fn fold_deg(d: f64) -> f64 {
    let r = d.rem_euclid(360.0);
    if r > 180.0 { 360.0 - r } else { r }
}

impl<'a> RadiometryContext<'a> {
    /// The radiometric state of a frame: sun spectra, sky dome and memos.
    pub fn new(st: &'a Static, cond: &'a Conditions) -> anyhow::Result<Self> {
        let n = st.band.len();
        let sa = &cond.atmosphere;
        let sun = &cond.sun_now;
        let r2 = sun.earth_sun_distance_au * sun.earth_sun_distance_au;
        let e_exo = sa.e_sun_exo().iter().map(|e| e / r2).collect();
        let mut tau1 = vec![0.0; n];
        sa.tau_sun(sun.zenith_deg, &mut tau1)?;
        let dome_de = sa.sky_dome_l_de().to_vec();
        let dome_ds = if sun.zenith_deg < 90.0 {
            sa.sky_dome_l_ds(sun.zenith_deg)?
        } else {
            vec![0.0; n]
        };
        Ok(RadiometryContext {
            st,
            cond,
            camera: DVec3::from(st.scene.local_camera.position_m),
            sun_dir: DVec3::from(sun.sun_dir_enu).as_vec3(),
            sun_zenith_deg: sun.zenith_deg,
            sun_azimuth_deg: sun.azimuth_deg,
            e_exo,
            tau1,
            dome: (dome_de, dome_ds),
            ground_blackbody: st
                .wavelength_um
                .iter()
                .map(|&wl| planck_radiance_w_m2_sr_um(wl, cond.ground_temp_k))
                .collect(),
            eps_normal: st
                .emissivity
                .iter()
                .map(|eps| {
                    let mut e = vec![0.0; n];
                    eps.spectrum_at(0.0, &st.wavelength_um, &mut e);
                    e
                })
                .collect(),
            paths: Memo::default(),
            skies: Memo::default(),
            planck: PlanckTable::new(&st.wavelength_um),
            diffuse: Memo::default(),
            outside: Memo::default(),
            sky_band: Memo::default(),
        })
    }

    /// The memo key of the path from `point` to the sensor.
    fn path_key(&self, point: DVec3) -> PathKey {
        let to_sensor = self.camera - point;
        let (h_km, vz) = path_geometry(self.camera.into(), point.into());
        let h_km = h_km.max(1e-4);
        let los_az = azimuth_deg(-to_sensor);
        let rel = fold_deg(self.sun_azimuth_deg - los_az);
        (key(h_km, 0.01), key(vz, 0.05), key(rel, 5.0))
    }

    /// τ₂, L_UE, L_US from `point` to the sensor.
    fn path(&self, point: DVec3) -> anyhow::Result<Arc<PathSpectra>> {
        self.path_of(self.path_key(point))
    }

    /// τ₂, L_UE, L_US of a path key, memoised.
    fn path_of(&self, k: PathKey) -> anyhow::Result<Arc<PathSpectra>> {
        self.paths.get_or_try_insert(k, |k| self.path_spectra(k))
    }

    /// τ₂, L_UE, L_US of a path key (its grid values).
    fn path_spectra(&self, k: &PathKey) -> anyhow::Result<PathSpectra> {
        let (h, vz, rel) = (k.0 as f64 * 0.01, k.1 as f64 * 0.05, k.2 as f64 * 5.0);
        Ok(path_at(
            &self.cond.atmosphere,
            h,
            vz,
            self.sun_zenith_deg,
            rel,
        )?)
    }

    /// The memo key of a direction towards the sky.
    fn sky_key(&self, dir: Vec3) -> SkyKey {
        let z = zenith_deg(dir).min(90.0);
        let rel = fold_deg(self.sun_azimuth_deg - azimuth_deg(dir.as_dvec3()));
        (key(z, 0.05), key(rel, 5.0))
    }

    /// L_DE(θ_SK), L_DS(θ_SK) for a direction towards the sky.
    fn sky(&self, dir: Vec3) -> anyhow::Result<Arc<SkyPair>> {
        self.skies
            .get_or_try_insert(self.sky_key(dir), |k| self.sky_spectra(k))
    }

    /// L_DE, L_DS of a sky key (its grid values).
    fn sky_spectra(&self, k: &SkyKey) -> anyhow::Result<SkyPair> {
        let n = self.st.band.len();
        let (mut de, mut ds) = (vec![0.0; n], vec![0.0; n]);
        let sa = &self.cond.atmosphere;
        let z = k.0 as f64 * 0.05;
        sa.l_de(z, &mut de)?;
        if self.sun_zenith_deg < 90.0 {
            sa.l_ds(self.sun_zenith_deg, k.1 as f64 * 5.0, z, &mut ds)?;
        }
        Ok((de, ds))
    }

    fn sun_on(&self, s: &Surface, i: usize) -> SunIllumination {
        SunIllumination {
            e_sun_exo_w_m2_um: self.e_exo[i],
            tau1: self.tau1[i],
            cos_incidence: s.normal.dot(self.sun_dir) as f64,
            sun_flag: if s.sun_now() { 1.0 } else { 0.0 },
        }
    }

    fn path_at(p: &PathSpectra, i: usize) -> PathRadiance {
        PathRadiance {
            tau2: p.tau2[i],
            l_ue_w_m2_sr_um: p.l_ue_w_m2_sr_um[i],
            l_us_w_m2_sr_um: p.l_us_w_m2_sr_um[i],
        }
    }

    /// Case 4: the band terms of the sky in a direction (tapped bin by bin).
    fn sky_terms<T>(&self, sky: &SkyPair, mut tap: T) -> RadianceTerms
    where
        T: FnMut(usize, RadianceTerms) -> RadianceTerms,
    {
        integrate_terms(&self.st.band, |i| {
            tap(
                i,
                case4_sky(&SkyRadiance {
                    l_de_w_m2_sr_um: sky.0[i],
                    l_ds_w_m2_sr_um: sky.1[i],
                }),
            )
        })
    }

    /// Where a ray that leaves the scene downwards meets the plane z = 0.
    fn outside_point(&self, dir: Vec3) -> DVec3 {
        let t = (-self.camera.z / dir.z as f64).max(0.0);
        self.camera + dir.as_dvec3() * t
    }

    /// Case 0: the band terms of the ground beyond the scene (air
    /// temperature, ε = 1) seen along `path` (tapped bin by bin).
    fn outside_terms<T>(&self, path: &PathSpectra, mut tap: T) -> RadianceTerms
    where
        T: FnMut(usize, RadianceTerms) -> RadianceTerms,
    {
        let (wl, ta) = (&self.st.wavelength_um, self.cond.air_temp_k);
        integrate_terms(&self.st.band, |i| {
            tap(
                i,
                case1_diffuse(
                    1.0,
                    planck_radiance_w_m2_sr_um(wl[i], ta),
                    &SunIllumination::DARK,
                    &SkyRadiance {
                        l_de_w_m2_sr_um: 0.0,
                        l_ds_w_m2_sr_um: 0.0,
                    },
                    &Self::path_at(path, i),
                ),
            )
        })
    }

    /// F_sky of a surface sample: the sky dome's share of its hemisphere.
    fn sky_view(&self, surf: &Surface) -> f64 {
        crate::trace::sky_view::sky_view_factor(
            surf.normal.z as f64,
            self.st.blocked_sky(surf.prim, surf.normal, surf.point),
        )
    }

    /// The band sums of eq. 1 for material `k.0` seen along path `k.1`.
    fn diffuse_coeffs(&self, k: &(u32, PathKey)) -> anyhow::Result<DiffuseCoeffs> {
        let path = self.path_of(k.1)?;
        Ok(DiffuseCoeffs::new(
            &self.st.band,
            &DiffuseSpectra {
                emissivity: &self.eps_normal[k.0 as usize],
                e_sun_exo_w_m2_um: &self.e_exo,
                tau1: &self.tau1,
                sky_dome_l_de: &self.dome.0,
                sky_dome_l_ds: &self.dome.1,
                tau2: &path.tau2,
                l_ue_w_m2_sr_um: &path.l_ue_w_m2_sr_um,
                l_us_w_m2_sr_um: &path.l_us_w_m2_sr_um,
                ground_blackbody: &self.ground_blackbody,
            },
        ))
    }

    /// The band-integrated radiance of one sample, every term separately.
    ///
    /// Diffuse surfaces, the sky and the ground beyond the scene use band
    /// sums memoised per (material, path key) or direction key
    /// ([`crate::radiometry::band_coeffs`]): a diffuse sample is a few
    /// multiply-adds and a Hermite table lookup in temperature, within
    /// 2e-8 relative of the spectral loop of [`Self::evaluate_with`]
    /// (the sky and the ground beyond are the loop's own sums, memoised).
    /// Specular and partly specular materials run the spectral loop.
    pub fn evaluate(&self, s: &Sample) -> anyhow::Result<SampleResult> {
        self.evaluate_memo(s, &mut EvalMemo::default())
    }

    /// [`Self::evaluate`] with a worker's [`EvalMemo`]: neighbouring
    /// samples mostly share a diffuse key, and a memo hit skips the shared
    /// map's hash, lock and reference count (cache lines the workers would
    /// otherwise pass between cores). The values are the map's, so the
    /// result is the same.
    pub fn evaluate_memo(&self, s: &Sample, memo: &mut EvalMemo) -> anyhow::Result<SampleResult> {
        let Some(surf) = &s.surface else {
            if s.dir.z > 0.0 {
                let t = self.sky_band.get_or_try_insert(self.sky_key(s.dir), |k| {
                    Ok::<_, anyhow::Error>(self.sky_terms(&self.sky_spectra(k)?, |_, t| t))
                })?;
                return Ok(result(4, *t, f64::NAN, f64::NAN));
            }
            let k = self.path_key(self.outside_point(s.dir));
            let t = self.outside.get_or_try_insert(k, |k| {
                let path = self.path_of(*k)?;
                Ok::<_, anyhow::Error>(self.outside_terms(&path, |_, t| t))
            })?;
            return Ok(result(0, *t, f64::NAN, 1.0));
        };
        let spec = self.st.specularity[surf.material as usize].clamp(0.0, 1.0);
        let diffuse = spec <= 0.0;
        if !diffuse {
            return self.evaluate_with(s, |_, _| {});
        }
        let k = (surf.material, self.path_key(surf.point.as_dvec3()));
        let c = match &memo.diffuse {
            Some((last, c)) if *last == k => c,
            _ => {
                let c = self
                    .diffuse
                    .get_or_try_insert(k, |k| self.diffuse_coeffs(k))?;
                &memo.diffuse.insert((k, c)).1
            }
        };
        let sun = if surf.sun_now() { 1.0 } else { 0.0 }
            * (surf.normal.dot(self.sun_dir) as f64).max(0.0);
        // F_sky varies over a side where its sky is partly hidden.
        let f_sky = self.sky_view(surf);
        let terms = c.terms(&self.planck, surf.temp_k, sun, f_sky);
        let view_angle = s.view_angle_deg();
        Ok(result(1, terms, view_angle, c.emissivity))
    }

    /// [`Self::evaluate`], also handing the spectral terms of every band
    /// bin (bin index, terms in W m⁻² sr⁻¹ µm⁻¹ before the band weight) to
    /// `per_bin`, in bin order.
    pub fn evaluate_with<F>(&self, s: &Sample, mut per_bin: F) -> anyhow::Result<SampleResult>
    where
        F: FnMut(usize, &RadianceTerms),
    {
        let mut tap = |i: usize, t: RadianceTerms| {
            per_bin(i, &t);
            t
        };
        let st = self.st;
        let band = &st.band;
        let wl = &st.wavelength_um;
        let Some(surf) = &s.surface else {
            if s.dir.z > 0.0 {
                // Case 4: the sensor sees the sky.
                let terms = self.sky_terms(&*self.sky(s.dir)?, &mut tap);
                return Ok(result(4, terms, f64::NAN, f64::NAN));
            }
            // Leaves the scene downwards: ground at air temperature, ε = 1,
            // seen at the ray's point on the plane z = 0.
            let path = self.path(self.outside_point(s.dir))?;
            let terms = self.outside_terms(&path, &mut tap);
            return Ok(result(0, terms, f64::NAN, 1.0));
        };
        let m = surf.material as usize;
        let eps0 = &self.eps_normal[m];
        let spec = st.specularity[m].clamp(0.0, 1.0);
        let path_arc = self.path(surf.point.as_dvec3())?;
        let path: &PathSpectra = &path_arc;
        let view_angle = s.view_angle_deg();
        let lt = |i: usize, t: f64| planck_radiance_w_m2_sr_um(wl[i], t);
        // The hemisphere a diffuse facet reflects: sky F_sky = (1 + cos β)/2
        // (the sky dome), ground F_gnd = 1 − F_sky (a black body at the
        // ground material's temperature, as in the thermal balance).
        let f_sky = self.sky_view(surf);
        // (the target's L(λᵢ, T) is passed in: the diffuse and specular
        // parts of a partly specular pixel share it)
        let diffuse = |i: usize, target: f64| {
            let e = eps0[i];
            let p = Self::path_at(path, i);
            let mut t = case1_diffuse(
                e,
                target,
                &self.sun_on(surf, i),
                &SkyRadiance {
                    l_de_w_m2_sr_um: f_sky * self.dome.0[i],
                    l_ds_w_m2_sr_um: f_sky * self.dome.1[i],
                },
                &p,
            );
            if f_sky < 1.0 {
                t.reflected_background_emitted =
                    (1.0 - f_sky) * self.ground_blackbody[i] * (1.0 - e) * p.tau2;
            }
            t
        };
        let band_mean = |e: &[f64]| band.weights.iter().zip(e).map(|(w, e)| w * e).sum::<f64>();
        if spec <= 0.0 {
            return Ok(result(
                1,
                integrate_terms(band, |i| tap(i, diffuse(i, lt(i, surf.temp_k)))),
                view_angle,
                band_mean(eps0),
            ));
        }
        // ε(θ_view, λᵢ) of the target, and of a facet the mirror ray meets
        // at its own angle.
        let mut eps_view = vec![0.0; wl.len()];
        st.emissivity[m].spectrum_at(view_angle, wl, &mut eps_view);
        let eps_band = band_mean(&eps_view);
        let (rdir, bg) = s.bounce.as_deref().expect("specular samples have a bounce");
        // What the mirror ray sees: the sky (eq. 2), or a background (eq. 3)
        // that is either a facet or the ground beyond the scene.
        enum Mirror<'m> {
            Sky(Arc<SkyPair>),
            Ground { temp_k: f64 },
            Facet { b: &'m Surface, eps_b: Vec<f64> },
        }
        let mirror = match bg {
            None if rdir.z > 0.0 => Mirror::Sky(self.sky(*rdir)?),
            None => Mirror::Ground {
                temp_k: self.cond.air_temp_k,
            },
            Some(b) => {
                let mut eps_b = vec![0.0; wl.len()];
                st.emissivity[b.material as usize].spectrum_at(
                    angle_deg(-*rdir, b.normal),
                    wl,
                    &mut eps_b,
                );
                Mirror::Facet { b, eps_b }
            }
        };
        let case = if matches!(mirror, Mirror::Sky(_)) {
            2
        } else {
            3
        };
        let specular = |i: usize, target: f64| {
            let eps_theta = eps_view[i];
            let sun = self.sun_on(surf, i);
            let path = Self::path_at(path, i);
            let background = match &mirror {
                Mirror::Sky(sky) => {
                    let sky = SkyRadiance {
                        l_de_w_m2_sr_um: sky.0[i],
                        l_ds_w_m2_sr_um: sky.1[i],
                    };
                    return case2_specular_sky(eps_theta, target, &sun, &sky, &path);
                }
                Mirror::Ground { temp_k } => Background {
                    emissivity: 1.0,
                    blackbody_w_m2_sr_um: lt(i, *temp_k),
                    sun: SunIllumination::DARK,
                },
                Mirror::Facet { b, eps_b } => Background {
                    emissivity: eps_b[i],
                    blackbody_w_m2_sr_um: lt(i, b.temp_k),
                    sun: self.sun_on(b, i),
                },
            };
            case3_specular_background(eps_theta, target, &sun, &background, &path)
        };
        let terms = integrate_terms(band, |i| {
            let target = lt(i, surf.temp_k);
            let mut t = RadianceTerms::default();
            if spec < 1.0 {
                t.accumulate(&diffuse(i, target), 1.0 - spec);
            }
            t.accumulate(&specular(i, target), spec);
            tap(i, t)
        });
        Ok(result(case, terms, view_angle, eps_band))
    }
}

fn result(case: u8, terms: RadianceTerms, view_angle_deg: f64, emissivity: f64) -> SampleResult {
    SampleResult {
        case,
        radiance_w_m2_sr_um: terms.total(),
        terms,
        view_angle_deg,
        emissivity,
    }
}

/// Band apparent temperature by table: L(T) and dL/dT tabulated every
/// 0.25 K over 100-1000 K; a radiance is inverted on the cubic Hermite
/// interpolant of its cell (Fritsch & Carlson 1980, "Monotone piecewise
/// cubic interpolation", SIAM J. Numer. Anal. 17: the Hermite form with
/// exact end slopes) by two Newton steps from the linear estimate — no
/// band integral per pixel. The interpolant's error, h⁴/384·max|L⁗|, is
/// below 1e-6 K over 120-900 K in MWIR and LWIR (checked against
/// [`crate::radiometry::Band::apparent_temp_k`] in the tests). Outside the
/// table, the band's own Newton solver is used.
pub struct ApparentTempLut {
    t0_k: f64,
    dt_k: f64,
    radiance: Vec<f64>,
    /// dL/dT at the nodes times the step: the Hermite tangents per cell.
    tangent: Vec<f64>,
    /// Where to look for a radiance's cell: buckets of the radiance's f64
    /// bit pattern (monotone in a positive radiance, and close to uniform
    /// in log L: the exponent with a linear mantissa) above the first
    /// node's, `1 << bucket_shift` patterns each; each entry the index of
    /// the first node at or above the bucket's lower edge (a search of a
    /// node or two instead of a bisection of the whole table, without a
    /// logarithm per pixel; the cell found is the same).
    bucket_start: Vec<u32>,
    lo_bits: u64,
    bucket_shift: u32,
}

/// At most this many buckets in [`ApparentTempLut::bucket_start`].
const LUT_BUCKETS: u64 = 1 << 13;

impl ApparentTempLut {
    /// The table of `band`: 100-1000 K every 0.25 K.
    pub fn new(band: &crate::radiometry::Band) -> Self {
        let (t0_k, dt_k, n) = (100.0, 0.25, 3601);
        let temps: Vec<f64> = (0..n).map(|i| t0_k + dt_k * i as f64).collect();
        let radiance: Vec<f64> = temps.iter().map(|&t| band.planck_w_m2_sr_um(t)).collect();
        let tangent = temps.iter().map(|&t| band.planck_dt(t) * dt_k).collect();
        // (no buckets for a degenerate table: every search bisects)
        let usable =
            radiance[0] > 0.0 && radiance[n - 1] > radiance[0] && radiance[n - 1].is_finite();
        let lo_bits = radiance[0].to_bits();
        let span = radiance[n - 1].to_bits().wrapping_sub(lo_bits);
        let bucket_shift = (u64::BITS - (span / LUT_BUCKETS).leading_zeros()).min(63);
        let buckets = if usable {
            (span >> bucket_shift) as usize + 1
        } else {
            0
        };
        let bucket_start = (0..buckets + usize::from(usable))
            .map(|b| {
                let edge = lo_bits + ((b as u64) << bucket_shift);
                radiance.partition_point(|&x| x.to_bits() < edge) as u32
            })
            .collect();
        ApparentTempLut {
            t0_k,
            dt_k,
            radiance,
            tangent,
            bucket_start,
            lo_bits,
            bucket_shift,
        }
    }

    /// The index of the first node above `l` (`partition_point(x <= l)` of
    /// the whole table), searched in `l`'s bucket (`l` is inside the
    /// table, so positive and finite; a node of margin on each side).
    fn upper_node(&self, l: f64) -> usize {
        let r = &self.radiance;
        let b = (l.to_bits().wrapping_sub(self.lo_bits) >> self.bucket_shift) as usize;
        if b + 1 >= self.bucket_start.len() {
            return r.partition_point(|&x| x <= l);
        }
        let lo = (self.bucket_start[b] as usize).saturating_sub(1);
        let hi = (self.bucket_start[b + 1] as usize + 1).min(r.len());
        lo + r[lo..hi].partition_point(|&x| x <= l)
    }

    /// The temperature of a blackbody whose band radiance is `l`, K (`None` where the band's own solver finds none).
    pub fn apparent_temp_k(&self, band: &crate::radiometry::Band, l: f64) -> Option<f64> {
        let r = &self.radiance;
        if !(l > r[0] && l < r[r.len() - 1]) {
            return band.apparent_temp_k(l);
        }
        let i = self.upper_node(l).clamp(1, r.len() - 1);
        let (y0, y1) = (r[i - 1], r[i]);
        let (m0, m1) = (self.tangent[i - 1], self.tangent[i]);
        // p(u) = h00 y0 + h10 m0 + h01 y1 + h11 m1, u in [0, 1]; monotone
        // here (L rises with T), so Newton from the chord converges. Over a
        // 0.25-K cell the chord is off by ~1e-3 in u; Newton squares that
        // (times the small curvature) twice: ~1e-19, below f64's rounding,
        // so two iterations are exact (a third changed no output bit).
        let mut u = (l - y0) / (y1 - y0);
        for _ in 0..2 {
            let (u2, u3) = (u * u, u * u * u);
            let p = (2.0 * u3 - 3.0 * u2 + 1.0) * y0
                + (u3 - 2.0 * u2 + u) * m0
                + (3.0 * u2 - 2.0 * u3) * y1
                + (u3 - u2) * m1;
            let dp = (6.0 * u2 - 6.0 * u) * (y0 - y1)
                + (3.0 * u2 - 4.0 * u + 1.0) * m0
                + (3.0 * u2 - 2.0 * u) * m1;
            u = (u - (p - l) / dp).clamp(0.0, 1.0);
        }
        Some(self.t0_k + self.dt_k * (i as f64 - 1.0 + u))
    }
}

/// A worker's last diffuse key and its coefficients (see
/// [`RadiometryContext::evaluate_memo`]).
#[derive(Default)]
pub struct EvalMemo {
    diffuse: Option<((u32, PathKey), Arc<DiffuseCoeffs>)>,
    /// The last pixel radiance (f32 bits) and its apparent temperature:
    /// neighbouring pixels of one facet, temperature and path key have the
    /// same radiance.
    pub(crate) apparent: LastKey<u32, f32>,
}

/// Planes that are NaN by design where no sample of a pixel hit a surface.
pub const SURFACE_PLANES: [&str; 8] = [
    "surface_temperature",
    "sun_now",
    "hours_sunlit",
    "range",
    "ground_x",
    "ground_y",
    "ground_z",
    "view_angle",
];

/// Checks that every output plane is finite wherever the input was accepted:
/// all of them everywhere, except the [`SURFACE_PLANES`] where the pixel's
/// centre sample saw no surface (`material` = −1). A non-finite value is an
/// error naming the plane and the pixel (issue 17: accepted input must not
/// yield NaN or ∞ silently).
pub fn check_finite(p: &Planes) -> anyhow::Result<()> {
    use rayon::prelude::*;
    let material = p.get("material").map(|m| &m.data);
    for plane in &p.planes {
        let may_be_nan = SURFACE_PLANES.contains(&plane.name.as_str());
        // The first offending pixel (in parallel; the same one whatever
        // the thread count).
        const CHUNK: usize = 1 << 16;
        let ok =
            |i: usize, v: f32| v.is_finite() || (may_be_nan && material.is_none_or(|m| m[i] < 0.0));
        let bad = plane
            .data
            .par_chunks(CHUNK)
            .enumerate()
            .find_map_first(|(c, chunk)| {
                let at = c * CHUNK;
                // (all finite, the common case: a loop without early exit)
                if chunk.iter().fold(true, |a, v| a & v.is_finite()) {
                    return None;
                }
                chunk
                    .iter()
                    .enumerate()
                    .position(|(j, &v)| !ok(at + j, v))
                    .map(|j| at + j)
            });
        if let Some(i) = bad {
            let v = plane.data[i];
            let (x, y) = (i as u32 % p.width, i as u32 / p.width);
            anyhow::bail!(
                "the render produced {v} in the {} plane at pixel ({x}, {y}) from accepted \
                 input: every output plane must be finite (a bug: please report it with the scene)",
                plane.name
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::ApparentTempLut;
    use crate::radiometry::{Band, SpectralGrid, SpectralResponse};

    /// check_finite names the first non-finite value (plane order, then
    /// pixel order), across the parallel search's chunks, and lets a
    /// surface plane be NaN only where the pixel saw no surface.
    #[test]
    fn check_finite_reports_the_first_bad_pixel() {
        use super::check_finite;
        use crate::output::Planes;
        let (w, h) = (400u32, 300u32); // more than one chunk of 65536
        let npx = (w * h) as usize;
        let planes = |bad: &[(usize, usize)], sky: usize| {
            let mut p = Planes::new(w, h);
            let mut material = vec![0.0f32; npx];
            material[sky] = -1.0;
            let mut data = [vec![300.0f32; npx], vec![1.0f32; npx]];
            for &(k, i) in bad {
                data[k][i] = if k == 0 { f32::NAN } else { f32::INFINITY };
            }
            let [temp, radiance] = data;
            p.push("material", "", material);
            p.push("surface_temperature", "K", temp);
            p.push("band_radiance", "W", radiance);
            p
        };
        let sky = 70_123;
        assert!(check_finite(&planes(&[], sky)).is_ok());
        // NaN temperature where the pixel saw no surface: allowed.
        assert!(check_finite(&planes(&[(0, sky)], sky)).is_ok());
        // The first bad pixel of the first bad plane, in the second chunk.
        let e = check_finite(&planes(&[(1, 5), (0, 100_401), (0, 119_999)], sky))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("NaN in the surface_temperature plane at pixel (1, 251)"),
            "{e}"
        );
        let e = check_finite(&planes(&[(1, 99_999), (1, 100_000)], sky))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("inf in the band_radiance plane at pixel (399, 249)"),
            "{e}"
        );
    }

    /// The table inversion agrees with the band's own Newton solver (itself
    /// checked against scipy-referenced Planck integrals) to 1e-6 K over
    /// 120-900 K in MWIR and LWIR, and falls back outside its range.
    #[test]
    fn lut_matches_band_newton_solver() {
        for resp in [SpectralResponse::mwir(), SpectralResponse::lwir()] {
            let grid = SpectralGrid::uniform(600.0, 10.0, 300);
            let band = Band::new(&grid, &resp).unwrap();
            let lut = ApparentTempLut::new(&band);
            let mut worst = 0.0f64;
            let mut t = 120.0;
            while t < 900.0 {
                let l = band.planck_w_m2_sr_um(t);
                let a = lut.apparent_temp_k(&band, l).unwrap();
                let b = band.apparent_temp_k(l).unwrap();
                worst = worst.max((a - b).abs());
                t += 0.37;
            }
            assert!(worst < 1e-6, "{}: worst |ΔT| = {worst} K", resp.label);
            // The bucketed search finds the cell a bisection of the whole
            // table finds, at and between every node (buckets in use:
            // about two per node).
            assert!(lut.bucket_start.len() > 4000, "{}", lut.bucket_start.len());
            let r = &lut.radiance;
            for i in 1..r.len() {
                for l in [r[i - 1], 0.5 * (r[i - 1] + r[i]), r[i].next_down()] {
                    assert_eq!(lut.upper_node(l), r.partition_point(|&x| x <= l), "{l}");
                }
            }
            // Outside the table: the band's solver answers.
            let l = band.planck_w_m2_sr_um(2000.0);
            assert!((lut.apparent_temp_k(&band, l).unwrap() - 2000.0).abs() < 1e-6);
            assert!(lut.apparent_temp_k(&band, -1.0).is_none());
        }
    }
}
