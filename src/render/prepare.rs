//! Everything a render needs, prepared once: the static part (geometry,
//! tracer, materials, band, atmosphere — shared by every frame of a
//! sequence or sweep) and the conditions of one frame (time, weather
//! forcing, sun samples, thermal cache).

use std::sync::{Arc, OnceLock};

use anyhow::Context;
use chrono::{DateTime, Utc};
use glam::Vec3;

use super::atmosphere::{
    AtmosphereReport, AtmosphereSource, atmosphere_source, frame_atmosphere, load_atmosphere,
};
use super::weather::{FrameWeather, frame_weather, key_recent_samples, scene_weather};
use crate::atmos::SpectralAtmosphere;
use crate::radiometry::{Band, Emissivity, SpectralGrid};
use crate::scene::LoadedScene;
use crate::scene::material::{Emissivity as SceneEmissivity, Material};
use crate::scene::spec::TracerKind;
use crate::sun::{SolarPosition, solar_position};
use crate::therm::cache::ThermCache;
use crate::therm::conditions::frame_ground;
use crate::therm::forcing::{EstimatorReport, Forcing};
use crate::therm::slab::{SlabMaterial, ThermSettings};
use crate::trace::sky_view::{SkyPatch, barycentric};
use crate::trace::{self, Backend, Geometry, Tracer};

/// The parts of a render that do not depend on time or weather.
pub struct Static {
    /// The loaded scene.
    pub scene: LoadedScene,
    /// The traced geometry (the scene's triangles in the tracer's local frame).
    pub geometry: Arc<Geometry>,
    /// The ray tracer over `geometry`.
    pub tracer: Arc<dyn Tracer>,
    /// Per material (scene material index): the slab model, the emissivity
    /// model and the specularity.
    pub slabs: Vec<SlabMaterial>,
    /// Spectral emissivity model of each material.
    pub emissivity: Vec<Emissivity>,
    /// Specular fraction of each material's reflectance, 0-1.
    pub specularity: Vec<f64>,
    /// The sensor band's spectral grid and response.
    pub band: Band,
    /// Wavelength of each band bin, µm.
    pub wavelength_um: Vec<f64>,
    /// The atmosphere table over the band's bins, as computed.
    pub atmosphere: SpectralAtmosphere,
    /// Which table and why.
    pub atmosphere_source: AtmosphereSource,
    /// The table on its own full grid, for the per-frame sky fit (when the
    /// scene follows the weather with a standard profile).
    pub atmosphere_full: Option<Arc<SpectralAtmosphere>>,
    /// Per triangle and side (0: the side its winding's normal points to),
    /// the fraction of its sky the scene hides, one value or a grid over the
    /// side, traced on first use ([`Static::blocked_sky`]).
    pub sky_blocked: Arc<Vec<[OnceLock<SkyPatch>; 2]>>,
    /// Keep every traced sample in [`super::Frame::samples`] (callers that
    /// read the samples' points or histories; a render otherwise streams
    /// them band by band and keeps only the planes). Default false.
    pub keep_samples: bool,
}

impl Static {
    /// The fraction of the sky that the scene hides from the point `point`
    /// of triangle `prim`'s side facing `normal` (`trace::sky_view`): the
    /// side is traced once (centroid and corners; a grid where they
    /// differ, [`SkyPatch`]) and the point takes its interpolated value.
    /// The thermal balance and the radiometry both use it:
    /// F_sky = (1 + cos β)/2 − this.
    pub fn blocked_sky(&self, prim: u32, normal: Vec3, point: Vec3) -> f64 {
        let v = self.geometry.vertices(prim);
        let face = (v[1] - v[0]).cross(v[2] - v[0]);
        let side = usize::from(face.dot(normal) < 0.0);
        let patch = self.sky_blocked[prim as usize][side]
            .get_or_init(|| SkyPatch::trace(self.tracer.as_ref(), v, normal));
        match patch.uniform() {
            Some(b) => b,
            None => {
                let (b1, b2) = barycentric(v, point);
                patch.at(b1, b2)
            }
        }
    }
}

/// One sample of the sun/shadow history.
#[derive(Clone, Copy, Debug)]
pub struct SunSample {
    /// Seconds since the start of the history.
    pub t_s: i64,
    /// Unit vector towards the sun (ENU).
    pub dir: Vec3,
    /// Sun above the horizon.
    pub up: bool,
}

/// The render's thermal tolerance grows with a step's age before the image
/// time on this scale, s: `thermal_tol_k·√(1 + age/15 min)`
/// ([`ThermSettings::tol_at`]; chosen on the accuracy curves: at 48², 0.1 K
/// with 15 min is more accurate than a uniform 0.3 K with a third fewer
/// Newton iterations, BENCHMARKS.md "The default render").
pub const THERMAL_TOL_AGE_S: f64 = 900.0;

/// The conditions of one frame.
pub struct Conditions {
    /// The image time (UTC).
    pub image_time: DateTime<Utc>,
    /// Start of the history (image time − history hours).
    pub start: DateTime<Utc>,
    /// The forcing of the thermal history.
    pub forcing: Vec<Forcing>,
    /// Which weather estimators built it.
    pub estimators: EstimatorReport,
    /// Shadow-history samples on the fine grid (`interval_s` apart); the
    /// last one is at the image time.
    pub suns: Vec<SunSample>,
    /// Interval of the fine shadow-history grid, s.
    pub interval_s: i64,
    /// Fine samples per traced sample (see [`FrameWeather::coarse_every`]).
    pub coarse_every: usize,
    /// Fine samples within which the thermal key keeps a transition at
    /// full resolution (a power of two ≥ 2; 0: all of them), see
    /// `render::key_history`.
    pub key_recent: usize,
    /// The sun at the image time.
    pub sun_now: SolarPosition,
    /// The thermal cache of the frame (its settings: step and tolerance).
    pub cache: ThermCache,
    /// Air temperature at the image time, K.
    pub air_temp_k: f64,
    /// The material tilted facets see as their ground (the one with the
    /// largest area of near-horizontal, upward-facing triangles), if any.
    pub ground_material: Option<u32>,
    /// Surface temperature of that ground at the image time, K (the air
    /// temperature when the scene has no ground).
    pub ground_temp_k: f64,
    /// Height of the scene's ground (its lowest point), m: facet heights
    /// for the wind are taken above it.
    pub ground_z_m: f64,
    /// The scene's slabs with `deep_ground = {}` set to
    /// [`crate::therm::conditions::deep_ground_temp_k`] (indexed like the scene's materials).
    pub slabs: Vec<SlabMaterial>,
    /// The frame's atmosphere: [`Static::atmosphere`] adjusted to the
    /// weather at the image time (`atmos::adjust`).
    pub atmosphere: SpectralAtmosphere,
    /// How the atmosphere followed the weather, for the summary.
    pub atmosphere_report: AtmosphereReport,
}

/// The spectral emissivity model of a scene material.
pub fn emissivity_of(m: &Material) -> anyhow::Result<Emissivity> {
    Ok(match &m.emissivity {
        SceneEmissivity::Constant => Emissivity::Constant(m.construction.thermal_emissivity),
        SceneEmissivity::Fresnel { n, k } => Emissivity::Fresnel { n: *n, k: *k },
        SceneEmissivity::Table(t) => Emissivity::Table(t.clone()),
    })
}

/// The sensor band's bins: uniform in wavenumber at the scene's step over
/// the response's support, only bins with non-zero response kept; refused
/// beyond [`crate::bounds::sizes::MAX_SPECTRAL_BINS`].
pub fn band_of(scene: &LoadedScene) -> anyhow::Result<Band> {
    // Spectral grid: uniform in wavenumber at the scene's step over the
    // response's support; only bins with non-zero response are kept.
    let resp = &scene.response;
    let (lo_um, hi_um) = resp.support_um();
    let (first, step, count) = super::memory::band_grid(scene);
    let max_bins = crate::bounds::sizes::MAX_SPECTRAL_BINS;
    if count.is_nan() || count > max_bins as f64 {
        anyhow::bail!(
            "{}: the band {lo_um}-{hi_um} um at render.spectral_step_cm1 = {step} needs {count} \
             spectral bins (about {:.0} MiB of atmosphere spectra); at most {max_bins}: \
             raise render.spectral_step_cm1 or narrow the band",
            scene.path.display(),
            super::memory::spectral_mib(count)
        );
    }
    let count = (count as usize).max(2);
    let grid = SpectralGrid::uniform(first.max(step), step, count);
    Band::new(&grid, resp).context("sensor band")
}

/// What a render refuses before it traces, checked without tracing: the
/// memory limit, the band's bins, the materials' emissivity tables, the
/// atmosphere table (its source, file and bins) and the sensor's paths
/// through it ([`check_paths`]). `irsig check` calls it, so it refuses
/// what a render of the scene would (the render makes the same calls in
/// [`derive_static`]).
pub fn validate(scene: &LoadedScene) -> anyhow::Result<()> {
    super::memory::check(scene)?;
    for m in &scene.materials {
        emissivity_of(m)?;
    }
    let band = band_of(scene)?;
    let source = atmosphere_source(scene, |from, to| scene_weather(scene, from, to))?;
    let (sa, _) = load_atmosphere(scene, &source, &band)?;
    check_paths(scene, &sa)
}

/// The sensor's paths to the scene's geometry are inside the atmosphere
/// table: the path lookups of the render ([`super::atmosphere::path_at`]) at
/// the lowest and highest sensor height over the geometry's bounding box
/// (on the Earth's sphere, [`crate::scene::frame::path_geometry`]) and
/// at the view zeniths from 0 to the largest of the box's corners. A
/// sensor above the tables' top (100 km) passes (it sees the top's path);
/// a table file ending lower refuses it here, naming the axis and range.
pub fn check_paths(scene: &LoadedScene, sa: &SpectralAtmosphere) -> anyhow::Result<()> {
    let cam = scene.local_camera.position_m;
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &scene.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] as f64);
            hi[k] = hi[k].max(p[k] as f64);
        }
    }
    if scene.positions.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    let (mut h_min, mut h_max, mut vz_max) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for c in 0..8 {
        let pick = |k: usize| if c >> k & 1 == 1 { hi[k] } else { lo[k] };
        let corner = [pick(0), pick(1), pick(2)];
        let (h, vz) = crate::scene::frame::path_geometry(cam, corner);
        let below = crate::scene::frame::path_geometry(cam, [cam[0], cam[1], corner[2]]).0;
        h_min = h_min.min(h).min(below);
        h_max = h_max.max(h).max(below);
        vz_max = vz_max.max(vz);
    }
    for h in [h_min.max(1e-4), h_max.max(1e-4)] {
        for vz in [0.0, vz_max.min(90.0)] {
            super::atmosphere::path_at(sa, h, vz, 0.0, 0.0).with_context(|| {
                format!(
                    "{}: the sensor {:.3} km above the scene's geometry, seen at view zenith {:.2}°",
                    scene.path.display(),
                    h,
                    vz
                )
            })?;
        }
    }
    Ok(())
}

/// Loads the static part of a scene.
pub fn prepare_static(scene: LoadedScene, backend: Option<Backend>) -> anyhow::Result<Static> {
    Ok(derive_static(None, scene, backend)?.0)
}

/// What [`derive_static`] shared with the previous [`Static`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Reused {
    /// Geometry and tracer (BVH) shared: same vertices, triangles, backend.
    pub geometry: bool,
    /// Atmosphere table shared: same `[atmosphere]` and band bins.
    pub atmosphere: bool,
}

/// The static part of `scene`, sharing with `prev` (when given) what the
/// new scene leaves unchanged: the geometry and tracer (BVH) when the
/// vertices, triangles and tracer backend are equal, the resampled
/// atmosphere table when `[atmosphere]` and the band's wavenumbers are
/// equal. Materials and band are cheap and always rebuilt. `backend` must
/// be the one `prev` was prepared with (None: each scene's
/// `render.tracer`). Used by sweeps over keys such as the sensor pose.
pub fn derive_static(
    prev: Option<&Static>,
    scene: LoadedScene,
    backend: Option<Backend>,
) -> anyhow::Result<(Static, Reused)> {
    super::memory::check(&scene)?;
    let mut reused = Reused::default();
    let backend_of = |s: &LoadedScene| {
        backend.unwrap_or(match s.scene.render.tracer {
            TracerKind::Embree => Backend::Embree,
            TracerKind::Bvh => Backend::Bvh,
        })
    };
    let same_geometry = prev.filter(|p| {
        backend_of(&p.scene) == backend_of(&scene)
            && p.scene.positions == scene.positions
            && p.scene.triangles == scene.triangles
    });
    let (geometry, tracer, sky_blocked) = match same_geometry {
        Some(p) => {
            reused.geometry = true;
            (p.geometry.clone(), p.tracer.clone(), p.sky_blocked.clone())
        }
        None => {
            let positions = scene.positions.iter().map(|p| Vec3::from(*p)).collect();
            let geometry = Arc::new(
                Geometry::new(positions, scene.triangles.clone())
                    .with_context(|| format!("{}: bad geometry", scene.path.display()))?,
            );
            let tracer: Arc<dyn Tracer> = Arc::from(trace::build(backend_of(&scene), &geometry)?);
            let n = geometry.triangles.len();
            let sky_blocked = Arc::new((0..n).map(|_| Default::default()).collect());
            (geometry, tracer, sky_blocked)
        }
    };
    let slabs: Vec<SlabMaterial> = scene.materials.iter().map(|m| m.construction).collect();
    let emissivity = scene
        .materials
        .iter()
        .map(emissivity_of)
        .collect::<anyhow::Result<Vec<_>>>()?;
    let specularity = scene.materials.iter().map(|m| m.specularity).collect();

    let band = band_of(&scene)?;
    let wavelength_um = band.wavenumber_cm1.iter().map(|v| 1e4 / v).collect();

    let source = atmosphere_source(&scene, |from, to| scene_weather(&scene, from, to))?;
    let same_atmosphere = prev.filter(|p| {
        p.scene.scene.atmosphere == scene.scene.atmosphere
            && p.atmosphere_source.name == source.name
            && p.band.wavenumber_cm1 == band.wavenumber_cm1
    });
    let (atmosphere, atmosphere_full) = match same_atmosphere {
        Some(p) => {
            reused.atmosphere = true;
            (p.atmosphere.clone(), p.atmosphere_full.clone())
        }
        None => load_atmosphere(&scene, &source, &band)?,
    };
    check_paths(&scene, &atmosphere)?;
    Ok((
        Static {
            scene,
            geometry,
            tracer,
            slabs,
            emissivity,
            specularity,
            band,
            wavelength_um,
            atmosphere,
            atmosphere_source: source,
            atmosphere_full,
            sky_blocked,
            keep_samples: prev.is_some_and(|p| p.keep_samples),
        },
        reused,
    ))
}

/// The scene's ground material: the one with the largest area of
/// triangles facing up within 10° of the zenith.
pub fn ground_material(scene: &LoadedScene) -> Option<u32> {
    let mut area = vec![0.0f64; scene.materials.len()];
    let cos10 = 10f64.to_radians().cos();
    for (t, &m) in scene.triangles.iter().zip(&scene.tri_material) {
        let p = |i: u32| glam::DVec3::from(scene.positions[i as usize].map(f64::from));
        let n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
        let len = n.length();
        if len > 0.0 && n.z / len >= cos10 {
            area[m as usize] += 0.5 * len;
        }
    }
    area.iter()
        .enumerate()
        .filter(|(_, a)| **a > 0.0)
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i as u32)
}

/// Builds the conditions of a frame at `image_time` (UTC) from the scene's
/// weather, history length and sampling.
pub fn prepare_conditions(st: &Static, image_time: DateTime<Utc>) -> anyhow::Result<Conditions> {
    let sc = &st.scene.scene;
    let opts = &sc.render;
    let mut fw = frame_weather(&st.scene, image_time)?;
    let settings = ThermSettings {
        step_s: fw.step_s,
        tol_k: Some(opts.thermal_tol_k),
        tol_age_s: Some(THERMAL_TOL_AGE_S),
        spin_up_h: opts.history_hours,
        ..ThermSettings::default()
    };
    // The ground tilted facets see: the scene's ground material, solved
    // sunlit and horizontal over the history; its temperature series and
    // solar albedo go into every facet's balance (F_gnd = (1 − cos β)/2).
    let ground = ground_material(&st.scene);
    let (slabs, ground_temp_k) = frame_ground(
        &st.slabs,
        fw.deep_ground_k,
        ground.map(|g| g as usize),
        &settings,
        &mut fw.forcing,
    )
    .with_context(|| {
        format!(
            "thermal model of the ground material {}",
            ground.map_or("", |g| st.scene.materials[g as usize].name.as_str())
        )
    })?;
    let FrameWeather {
        site,
        start,
        interval_s,
        n_sun,
        coarse_every,
        forcing,
        estimators,
        ..
    } = fw;
    let suns = (0..=n_sun)
        .map(|k| {
            let t = start + chrono::Duration::seconds(k * interval_s);
            let p = solar_position(t, site.latitude_deg, site.longitude_deg, site.elevation_m);
            SunSample {
                t_s: k * interval_s,
                dir: glam::DVec3::from(p.sun_dir_enu).as_vec3(),
                up: p.elevation_deg > 0.0,
            }
        })
        .collect();
    let sun_now = solar_position(
        image_time,
        site.latitude_deg,
        site.longitude_deg,
        site.elevation_m,
    );
    let air_temp_k = forcing.last().map(|f| f.air_temp_k).unwrap_or(288.15);
    let now = forcing.last().context("no forcing at the image time")?;
    let (atmosphere, atmosphere_report) = frame_atmosphere(
        &st.atmosphere_source,
        &st.atmosphere,
        st.atmosphere_full.as_deref(),
        sc.atmosphere.follow_weather,
        now,
    )?;
    Ok(Conditions {
        image_time,
        start,
        forcing,
        estimators,
        suns,
        interval_s,
        coarse_every: coarse_every as usize,
        key_recent: opts
            .shadow_key_recent_h
            .map_or(0, |h| key_recent_samples(h, interval_s)),
        sun_now,
        cache: ThermCache::new(settings, 0.0, false),
        ground_z_m: st.scene.bounds_m().0[2],
        ground_material: ground,
        ground_temp_k,
        air_temp_k,
        slabs,
        atmosphere,
        atmosphere_report,
    })
}

/// Drops `value` on a thread of its own, so that the caller goes on (a
/// render's thermal cache and sky-view patches are millions of small
/// allocations: tens of ms of frees on one core after a 512² frame). A
/// process that exits meanwhile leaves the rest to the OS. If no thread
/// can be started, `value` is dropped here.
pub fn drop_in_background<T: Send + 'static>(value: T) {
    let _ = std::thread::Builder::new()
        .name("irsig-drop".into())
        .spawn(move || drop(value));
}
