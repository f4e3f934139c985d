//! Everything about one output pixel — its primary hit, the angles, the
//! sun/shadow history, the temperature and its flux terms over the history,
//! the specular bounce and background, every radiometric term
//! (band-integrated, optionally per bin) and the band result — as plain,
//! serialisable data ([`PixelProbe`]); `irsig probe` prints it as text or
//! JSON.
//!
//! The pixel is computed by the render's own functions
//! ([`super::trace_samples`], [`super::thermal_solution`],
//! [`super::pixel::RadiometryContext::evaluate_with`]), so its
//! `band_radiance` and `apparent_temperature` are those the render writes
//! for that pixel (before the sensor's PSF, noise and quantisation).

use anyhow::{Context, bail};
use chrono::{DateTime, Duration, FixedOffset, Utc};
use glam::Vec3;
use serde::Serialize;

use super::frame::Stats;
use super::pixel::{ApparentTempLut, RadiometryContext, SampleResult, representatives};
use super::prepare::{Conditions, Static, prepare_conditions, prepare_static};
use super::run::{output_pixel_samples, trace_samples};
use super::sample::{Sample, Surface, angle_deg, azimuth_deg, zenith_deg};
use super::thermal::thermal_solution;
use crate::radiometry::RadianceTerms;
use crate::scene::LoadedScene;
use crate::scene::spec::Sampling;
use crate::therm::balance::Orientation;
use crate::therm::cache::ThermCache;
use crate::therm::slab::StepRecord;
use crate::trace::Backend;

/// Everything about one output pixel.
#[derive(Clone, Debug, Serialize)]
pub struct PixelProbe {
    /// The scene file.
    pub scene: String,
    /// The output pixel, (column, row) from the top left.
    pub pixel: [u32; 2],
    /// The image time, UTC (RFC 3339).
    pub image_time_utc: String,
    /// The image time on the scene's local clock.
    pub image_time_local: String,
    /// The sensor band's label.
    pub band: String,
    /// Spectral bins of the band integral.
    pub spectral_bins: usize,
    /// Samples per pixel edge (n of the n×n samples).
    pub supersample: u32,
    /// The sun at the image time.
    pub sun: SunReport,
    /// The frame's atmosphere table, why, and how it follows the weather.
    pub atmosphere: super::atmosphere::AtmosphereReport,
    /// The pixel's n×n samples, row by row (`supersample` = n: with
    /// adaptive sampling 1 for a pixel that kept its coarse sample, and a
    /// refined pixel's unrefined cells repeat their one sample).
    pub samples: Vec<SampleReport>,
    /// What `irsig render` writes for this pixel.
    pub pixel_result: PixelResult,
}

#[derive(Clone, Debug, Serialize)]
/// The sun at the image time.
pub struct SunReport {
    /// Solar zenith, degrees.
    pub zenith_deg: f64,
    /// Solar azimuth, degrees clockwise from north.
    pub azimuth_deg: f64,
    /// Unit vector towards the sun (ENU).
    pub dir_enu: [f64; 3],
}

#[derive(Clone, Debug, Serialize)]
/// The pixel's value as `irsig render` writes it.
pub struct PixelResult {
    /// Mean of the samples' band radiance, W m⁻² sr⁻¹ µm⁻¹ (f64).
    pub band_radiance_w_m2_sr_um: f64,
    /// The same as the EXR stores it (f32).
    pub band_radiance_f32: f32,
    /// Band apparent temperature of the f32 radiance (as the render), K.
    pub apparent_temperature_k: Option<f64>,
    /// Mean surface temperature of the samples that hit, K.
    pub surface_temperature_k: Option<f64>,
    /// Mean of the samples' band-integrated terms.
    pub terms: RadianceTerms,
    /// Case of the centre sample.
    pub case: u8,
}

#[derive(Clone, Debug, Serialize)]
/// One sample of the pixel: its ray, hit, angles, bounce and radiometry.
pub struct SampleReport {
    /// Pixel of the supersampled image.
    pub sample_px: [u32; 2],
    /// Unit direction of the primary ray (ENU).
    pub ray_dir: [f32; 3],
    /// What the primary ray hit (`None`: the sky or outside the scene).
    pub hit: Option<SurfaceReport>,
    /// The viewing and sun angles at the hit.
    pub angles: Option<Angles>,
    /// Specular bounce (specular materials only).
    pub bounce: Option<BounceReport>,
    /// The sample's radiometry.
    pub radiometry: RadiometryReport,
}

#[derive(Clone, Debug, Serialize)]
/// A surface point a ray hit: where, what, its history and its temperature.
pub struct SurfaceReport {
    /// Triangle index in the scene.
    pub triangle: u32,
    /// OBJ face index within its object.
    pub facet: u32,
    /// The object's name.
    pub object: String,
    /// The material's name.
    pub material: String,
    /// The material's index (the `material` plane's value).
    pub material_index: u32,
    /// Specular fraction of its reflectance, 0-1.
    pub specularity: f64,
    /// The hit point in world coordinates.
    pub point_m: [f64; 3],
    /// Unit geometric normal facing the incoming ray.
    pub normal: [f32; 3],
    /// Slope of the facet, degrees from horizontal.
    pub slope_deg: f64,
    /// Aspect of the facet, degrees clockwise from north.
    pub aspect_deg: f64,
    /// Distance along the incoming ray, m.
    pub range_m: f32,
    /// The point's sun/shadow history.
    pub history: HistoryReport,
    /// The point's thermal solve.
    pub thermal: ThermalReport,
}

#[derive(Clone, Debug, Serialize)]
/// A surface point's sun/shadow history.
pub struct HistoryReport {
    /// Local clock time of the first sample.
    pub start_local: String,
    /// Interval between samples, minutes.
    pub interval_min: f64,
    /// One character per sample, oldest first (the last is the image time):
    /// 1 sunlit, 0 not.
    pub sunlit: String,
    /// Why, per sample: `1` sunlit, `s` shadowed (a ray was blocked), `a`
    /// facet facing away from the sun, `-` sun below the horizon.
    pub reason: String,
    /// Local clock time of each sample.
    pub times_local: Vec<String>,
    /// Hours the point was sunlit over the history.
    pub hours_sunlit: f64,
    /// Whether the point sees the sun at the image time.
    pub sun_now: bool,
}

#[derive(Clone, Debug, Serialize)]
/// A surface point's thermal solve: its surface, the ground, the series.
pub struct ThermalReport {
    /// Surface kind and its parameters (solid, vegetation, water, snow).
    pub surface: crate::therm::surface::SurfaceKind,
    /// The slab under the surface: its layers (top first; one for a
    /// homogeneous slab), optical constants and back boundary, as the solve
    /// used them (the deep-ground temperature resolved).
    pub slab: SlabReport,
    /// The ground tilted facets see (material name) and its temperature at
    /// the image time, K.
    pub ground_material: Option<String>,
    /// The ground's temperature at the image time, K.
    pub ground_temp_k: f64,
    /// Local clock time of the start of the series (`t_s` = 0).
    pub start_local: String,
    /// Surface temperature at the image time, K.
    pub surface_temp_k: f64,
    /// Accepted march steps.
    pub steps_accepted: usize,
    /// Rejected march steps.
    pub steps_rejected: usize,
    /// Sky view factor of this surface point (per point, not per
    /// triangle: the value the thermal balance used), at the image time.
    pub sky_view: Option<f64>,
    /// Bulk Richardson number and stability function `F(Ri) =
    /// h_forced/h_neutral` of the surface layer at the image time
    /// ([`crate::therm::balance::SurfaceFluxes::stability_factor`]; 1 =
    /// neutral).
    pub richardson: Option<f64>,
    /// The stability function `F(Ri)` at the image time.
    pub stability_factor: Option<f64>,
    /// One record per thermal step, seconds since the history start, with
    /// every surface flux term (W m⁻²).
    pub series: Vec<StepRecord>,
}

#[derive(Clone, Debug, Serialize)]
/// The construction a point's thermal solve used.
pub struct SlabReport {
    /// Layers, top first: thickness, k, ρ, c (a homogeneous slab is one).
    pub layers: Vec<crate::therm::slab::Layer>,
    /// Absorptivity for sunlight.
    pub solar_absorptivity: f64,
    /// Thermal emissivity.
    pub thermal_emissivity: f64,
    /// What the back face sees.
    pub back: crate::therm::slab::BackBoundary,
}

impl SlabReport {
    fn of(m: &crate::therm::slab::SlabMaterial) -> SlabReport {
        SlabReport {
            layers: m.layer_list(),
            solar_absorptivity: m.solar_absorptivity,
            thermal_emissivity: m.thermal_emissivity,
            back: m.back,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
/// The angles at a hit.
pub struct Angles {
    /// Angle between the line of sight (towards the sensor) and the normal.
    pub view_angle_deg: f64,
    /// Zenith angle of the line of sight towards the sensor, at the target
    /// (on the Earth's sphere, as the atmosphere lookup takes it).
    pub view_zenith_deg: f64,
    /// Azimuth of the direction target → sensor, clockwise from north.
    pub view_azimuth_deg: f64,
    /// Angle between the sun direction and the normal (> 90: facing away).
    pub sun_incidence_deg: f64,
}

#[derive(Clone, Debug, Serialize)]
/// The specular bounce of a sample.
pub struct BounceReport {
    /// Unit reflected direction (ENU).
    pub dir: [f32; 3],
    /// Zenith angle of the reflected direction, degrees.
    pub zenith_deg: f64,
    /// Azimuth of the reflected direction, degrees clockwise from north.
    pub azimuth_deg: f64,
    /// `sky`, `ground plane` (leaves the scene downwards) or `surface`.
    pub target: &'static str,
    /// What the bounce hit, for `surface`.
    pub background: Option<SurfaceReport>,
}

#[derive(Clone, Debug, Serialize)]
/// A sample's radiometry: the case, its terms, and per bin with `--spectral`.
pub struct RadiometryReport {
    /// 1 diffuse, 2 specular→sky, 3 specular→background, 4 sky, 0 outside.
    pub case: u8,
    /// The case's name.
    pub case_name: &'static str,
    /// Band-integrated terms, W m⁻² sr⁻¹ µm⁻¹.
    pub terms: RadianceTerms,
    /// Band-integrated radiance at the sensor, W m⁻² sr⁻¹ µm⁻¹.
    pub band_radiance_w_m2_sr_um: f64,
    /// Band-averaged emissivity of the surface (0 for the sky).
    pub emissivity: f64,
    /// The terms per spectral bin (`irsig probe --spectral`).
    pub spectral: Option<Vec<SpectralBin>>,
}

#[derive(Clone, Debug, Serialize)]
/// One spectral bin of a sample's radiometry.
pub struct SpectralBin {
    /// The bin's wavenumber, cm⁻¹.
    pub wavenumber_cm1: f64,
    /// The bin's wavelength, µm.
    pub wavelength_um: f64,
    /// Band weight of the bin (the weights sum to 1).
    pub weight: f64,
    /// Spectral terms, W m⁻² sr⁻¹ µm⁻¹.
    pub terms: RadianceTerms,
}

/// The name of a radiometric case (the paper's eqs. 1-4).
pub fn case_name(case: u8) -> &'static str {
    match case {
        1 => "1: diffuse (eq. 1)",
        2 => "2: specular, sky (eq. 2)",
        3 => "3: specular, background (eq. 3)",
        4 => "4: sky (eq. 4)",
        _ => "0: leaves the scene downwards (ground at air temperature)",
    }
}

struct Ctx<'a> {
    st: &'a Static,
    cond: &'a Conditions,
    offset: FixedOffset,
}

impl Ctx<'_> {
    fn local(&self, t: DateTime<Utc>) -> String {
        t.with_timezone(&self.offset)
            .format("%Y-%m-%dT%H:%M")
            .to_string()
    }

    fn surface(&self, s: &Surface) -> anyhow::Result<SurfaceReport> {
        let (st, cond) = (self.st, self.cond);
        let sc = &st.scene;
        let o = Orientation::from_normal_enu(s.normal.as_dvec3().to_array());
        let mut reason = String::new();
        for (sun, lit) in cond.suns.iter().zip(s.history.iter()) {
            reason.push(if lit {
                '1'
            } else if !sun.up {
                '-'
            } else if s.normal.dot(sun.dir) <= 0.0 {
                'a'
            } else {
                's'
            });
        }
        let interval = Duration::seconds(cond.interval_s);
        let sol = thermal_solution(st, cond, s)?;
        let tri = s.prim as usize;
        Ok(SurfaceReport {
            triangle: s.prim,
            facet: sc.tri_facet[tri],
            object: sc.objects[sc.tri_object[tri] as usize].name.clone(),
            material: sc.materials[s.material as usize].name.clone(),
            material_index: s.material,
            specularity: st.specularity[s.material as usize],
            point_m: sc.frame.to_world(s.point.as_dvec3().to_array()),
            normal: s.normal.to_array(),
            slope_deg: o.slope_deg,
            aspect_deg: o.aspect_deg,
            range_m: s.range_m,
            history: HistoryReport {
                start_local: self.local(cond.start),
                interval_min: cond.interval_s as f64 / 60.0,
                sunlit: s
                    .history
                    .iter()
                    .map(|b| if b { '1' } else { '0' })
                    .collect(),
                reason,
                times_local: (0..s.history.len())
                    .map(|k| self.local(cond.start + interval * k as i32))
                    .collect(),
                hours_sunlit: s.history.count_sunlit() as f64 * cond.interval_s as f64 / 3600.0,
                sun_now: s.sun_now(),
            },
            thermal: ThermalReport {
                surface: cond.slabs[s.material as usize].surface,
                slab: SlabReport::of(&cond.slabs[s.material as usize]),
                ground_material: cond
                    .ground_material
                    .map(|g| self.st.scene.materials[g as usize].name.clone()),
                ground_temp_k: cond.ground_temp_k,
                start_local: self.local(cond.start),
                surface_temp_k: s.temp_k,
                steps_accepted: sol.steps_accepted,
                steps_rejected: sol.steps_rejected,
                sky_view: sol.series.last().map(|r| r.sky_view),
                richardson: sol.series.last().map(|r| r.surface.richardson),
                stability_factor: sol.series.last().map(|r| r.surface.stability_factor()),
                series: sol.series.clone(),
            },
        })
    }

    fn sample(
        &self,
        px: (u32, u32),
        s: &Sample,
        r: SampleResult,
        spectral: Option<Vec<SpectralBin>>,
    ) -> anyhow::Result<SampleReport> {
        let sun_dir = Vec3::from(self.cond.sun_now.sun_dir_enu.map(|v| v as f32));
        let angles = s.surface.as_ref().map(|surf| Angles {
            view_angle_deg: s.view_angle_deg(),
            view_zenith_deg: crate::scene::frame::path_geometry(
                self.st.scene.local_camera.position_m,
                surf.point.as_dvec3().into(),
            )
            .1,
            view_azimuth_deg: azimuth_deg(-s.dir.as_dvec3()),
            sun_incidence_deg: angle_deg(sun_dir.normalize(), surf.normal),
        });
        let bounce = match s.bounce.as_deref() {
            None => None,
            Some((d, bg)) => Some(BounceReport {
                dir: d.to_array(),
                zenith_deg: zenith_deg(*d),
                azimuth_deg: azimuth_deg(d.as_dvec3()),
                target: match bg {
                    Some(_) => "surface",
                    None if d.z > 0.0 => "sky",
                    None => "ground plane",
                },
                background: bg.as_ref().map(|b| self.surface(b)).transpose()?,
            }),
        };
        Ok(SampleReport {
            sample_px: [px.0, px.1],
            ray_dir: s.dir.to_array(),
            hit: s.surface.as_ref().map(|h| self.surface(h)).transpose()?,
            angles,
            bounce,
            radiometry: RadiometryReport {
                case: r.case,
                case_name: case_name(r.case),
                terms: r.terms,
                band_radiance_w_m2_sr_um: r.radiance_w_m2_sr_um,
                emissivity: r.emissivity,
                spectral,
            },
        })
    }
}

/// Mean of the finite values (as the render averages a pixel's samples).
fn finite_mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let (mut s, mut c) = (0.0, 0u32);
    for x in v.filter(|x| x.is_finite()) {
        s += x;
        c += 1;
    }
    (c > 0).then(|| s / c as f64)
}

/// Probes output pixel (`x`, `y`) of a prepared scene. `cond.cache` should
/// keep series (see [`ThermCache::new`]) for the thermal series to be
/// reported; the temperatures are the same either way.
pub fn probe(
    st: &Static,
    cond: &Conditions,
    (x, y): (u32, u32),
    spectral: bool,
) -> anyhow::Result<PixelProbe> {
    let cam = &st.scene.camera;
    if x >= cam.width_px || y >= cam.height_px {
        bail!(
            "--pixel {x},{y}: outside the {}x{} image (columns 0..{}, rows 0..{})",
            cam.width_px,
            cam.height_px,
            cam.width_px - 1,
            cam.height_px - 1
        );
    }
    let mut stats = Stats::default();
    let ss = st.scene.scene.render.supersample().max(1);
    // As the render samples the pixel: adaptive sampling's coarse sample
    // alone (n = 1) or its two levels; uniform sampling's n×n grid.
    // (a shared sample of an unrefined cell is reported at each grid
    // position it stands for)
    let px = output_pixel_samples(st, x, y);
    let (samples, n, px, owners) = if ss > 1 && st.scene.scene.render.sampling == Sampling::Adaptive
    {
        let (samples, n, owners) = super::adaptive::pixel_samples(st, cond, (x, y), &mut stats)?;
        let px = if n == 1 {
            vec![px[((ss / 2) * ss + ss / 2) as usize]]
        } else {
            px
        };
        (samples, n, px, owners)
    } else {
        (trace_samples(st, cond, &px, &mut stats)?, ss, px, None)
    };
    let rctx = RadiometryContext::new(st, cond)?;
    // As the render: a uniform pixel evaluates its centre sample only and
    // reports that result for each of its samples; a refined pixel of
    // adaptive sampling evaluates each position's owner (a shared sample
    // or a donor).
    let rep = representatives(&samples.iter().collect::<Vec<_>>(), n);
    let uniform = rep.iter().enumerate().any(|(k, &r)| r != k);
    let rep = match owners {
        Some(o) if !uniform => o,
        _ => rep,
    };
    let mut results: Vec<SampleResult> = Vec::new();
    let mut bins = Vec::new();
    for (k, s) in samples.iter().enumerate() {
        if rep[k] != k {
            results.push(SampleResult::default());
            bins.push(None);
            continue;
        }
        let mut spec: Vec<SpectralBin> = Vec::new();
        let r = rctx.evaluate_with(s, |i, t: &RadianceTerms| {
            if spectral {
                spec.push(SpectralBin {
                    wavenumber_cm1: st.band.wavenumber_cm1[i],
                    wavelength_um: st.wavelength_um[i],
                    weight: st.band.weights[i],
                    terms: *t,
                });
            }
        })?;
        results.push(r);
        bins.push(spectral.then_some(spec));
    }
    for k in 0..results.len() {
        if rep[k] != k {
            results[k] = results[rep[k]].clone();
            bins[k] = bins[rep[k]].clone();
        }
    }
    let radiance = finite_mean(results.iter().map(|r| r.radiance_w_m2_sr_um)).unwrap_or(f64::NAN);
    let radiance_f32 = radiance as f32;
    let lut = ApparentTempLut::new(&st.band);
    let mut terms = RadianceTerms::default();
    let k = results.len() as f64;
    for r in &results {
        terms.accumulate(&r.terms, 1.0 / k);
    }
    let centre_case = results[((n / 2) * n + n / 2) as usize].case;
    let pixel_result = PixelResult {
        band_radiance_w_m2_sr_um: radiance,
        band_radiance_f32: radiance_f32,
        apparent_temperature_k: lut.apparent_temp_k(&st.band, radiance_f32 as f64),
        surface_temperature_k: finite_mean(
            samples
                .iter()
                .map(|s| s.surface.as_ref().map_or(f64::NAN, |s| s.temp_k)),
        ),
        terms,
        case: centre_case,
    };
    let sc = &st.scene.scene;
    let offset = FixedOffset::east_opt((sc.site.utc_offset_h * 3600.0).round() as i32)
        .context("site utc_offset_h out of range")?;
    let ctx = Ctx { st, cond, offset };
    let reports = px
        .iter()
        .zip(&samples)
        .zip(results)
        .zip(bins)
        .map(|(((&p, s), r), b)| ctx.sample(p, s, r, b))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let sun = &cond.sun_now;
    Ok(PixelProbe {
        scene: st.scene.path.display().to_string(),
        pixel: [x, y],
        image_time_utc: cond
            .image_time
            .to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
        image_time_local: ctx.local(cond.image_time),
        band: st.band.label.clone(),
        spectral_bins: st.band.len(),
        supersample: n,
        sun: SunReport {
            zenith_deg: sun.zenith_deg,
            azimuth_deg: sun.azimuth_deg,
            dir_enu: sun.sun_dir_enu,
        },
        atmosphere: cond.atmosphere_report.clone(),
        samples: reports,
        pixel_result,
    })
}

/// Probes output pixel `pixel` (column, row from the top left) of a loaded
/// scene at its image time, as `irsig probe` does: prepares the static part
/// and the conditions (with a thermal cache that keeps the series), then
/// calls [`probe`]. Runs in the current rayon pool (see
/// [`super::thread_pool`]).
pub fn probe_scene(
    scene: LoadedScene,
    tracer: Option<Backend>,
    pixel: (u32, u32),
    spectral: bool,
) -> anyhow::Result<PixelProbe> {
    let st = prepare_static(scene, tracer)?;
    let t = st.scene.scene.time.utc(&st.scene.scene.site);
    let mut cond = prepare_conditions(&st, t)?;
    // Keep the thermal series (the temperatures do not change).
    cond.cache = ThermCache::new(
        *cond.cache.settings(),
        cond.cache.orientation_quantum_deg(),
        true,
    );
    probe(&st, &cond, pixel, spectral)
}
