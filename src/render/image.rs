//! One rendered image with what describes it (time, sun, band, forcing
//! estimators): what `irsig render` writes and what each frame of a
//! sequence holds.

use chrono::{DateTime, Utc};

use super::frame::{Frame, ProgressFn};
use super::prepare::{Conditions, Static, prepare_conditions, prepare_static};
use super::run::render_with;
use crate::scene::LoadedScene;
use crate::trace::Backend;

/// A rendered image: its planes and statistics, and what describes it.
pub struct Rendered {
    /// The scene file.
    pub scene: String,
    /// The image time (UTC).
    pub image_time_utc: DateTime<Utc>,
    /// Solar zenith at the image time, degrees.
    pub sun_zenith_deg: f64,
    /// Solar azimuth at the image time, degrees clockwise from north.
    pub sun_azimuth_deg: f64,
    /// Band label.
    pub band: String,
    /// The forcing estimators used (weather files), as text.
    pub estimators: String,
    /// The band's spectral support, µm (lowest, highest wavelength of
    /// non-zero response).
    pub band_um: (f64, f64),
    /// The response-weighted band centre and the response's full width at
    /// half maximum, µm ([`crate::radiometry::SpectralResponse::centroid_um`],
    /// [`crate::radiometry::SpectralResponse::fwhm_um`]): the ENVI
    /// headers' `wavelength` and `fwhm`.
    pub band_centre_fwhm_um: (f64, f64),
    /// The atmosphere table, why, and how it followed the weather.
    pub atmosphere: super::atmosphere::AtmosphereReport,
    /// Material names, by index (the `material` plane's values).
    pub materials: Vec<String>,
    /// The `--set` overrides applied to the scene file.
    pub overrides: Vec<(String, String)>,
    /// The sensor's pose as the scene states it, and its camera.
    pub pose: crate::scene::spec::SensorPose,
    /// The camera built from the pose.
    pub camera: crate::scene::Camera,
    /// Where the image is on the Earth and in the output CRS.
    pub georef: crate::scene::georef::Georef,
    /// The planes (every output plane, at output resolution) and statistics.
    pub frame: Frame,
    /// The tracer's local frame (`scene::frame`): the samples' points are
    /// in it; `local_frame.to_world` gives world coordinates.
    pub local_frame: crate::scene::LocalFrame,
    /// The scene's output options (`[output]`).
    pub output: crate::scene::spec::OutputOptions,
}

/// Renders the prepared scene `st` at `image_time` (UTC): the conditions
/// (weather forcing, sun samples, thermal cache) are prepared here. Runs in
/// the current rayon pool (see [`super::thread_pool`]); `progress` is
/// called from worker threads.
pub fn render_at(
    st: &Static,
    image_time: DateTime<Utc>,
    progress: ProgressFn,
) -> anyhow::Result<Rendered> {
    let cond = prepare_conditions(st, image_time)?;
    let image = render_conditions(st, &cond, progress);
    super::prepare::drop_in_background(cond);
    image
}

/// Renders the prepared scene `st` under prepared conditions `cond` (see
/// [`prepare_conditions`]).
pub fn render_conditions(
    st: &Static,
    cond: &Conditions,
    progress: ProgressFn,
) -> anyhow::Result<Rendered> {
    let frame = render_with(st, cond, progress)?;
    let sc = &st.scene.scene;
    let geo = crate::scene::georef::Geo::new(&sc.site.location, &sc.site.crs)?;
    let georef = crate::scene::georef::georeference(
        &geo,
        &sc.site.location,
        &st.scene.camera,
        sc.sensor.pose.target_m()[2],
        st.scene.frame.origin_m,
    )?;
    Ok(Rendered {
        scene: st.scene.path.display().to_string(),
        image_time_utc: cond.image_time,
        sun_zenith_deg: cond.sun_now.zenith_deg,
        sun_azimuth_deg: cond.sun_now.azimuth_deg,
        band: st.band.label.clone(),
        estimators: cond.estimators.to_string(),
        band_um: st.scene.response.support_um(),
        band_centre_fwhm_um: (st.scene.response.centroid_um(), st.scene.response.fwhm_um()),
        atmosphere: cond.atmosphere_report.clone(),
        materials: st.scene.materials.iter().map(|m| m.name.clone()).collect(),
        overrides: st.scene.overrides.clone(),
        pose: sc.sensor.pose.clone(),
        camera: st.scene.camera,
        georef,
        frame,
        local_frame: st.scene.frame,
        output: sc.output.clone(),
    })
}

/// Renders a loaded scene at its image time, as `irsig render` does
/// (`tracer`: default the scene's `render.tracer`). For several images of
/// one scene, prepare it once with [`prepare_static`] and call
/// [`render_at`], or see [`super::sequence`].
pub fn render_scene(
    scene: LoadedScene,
    tracer: Option<Backend>,
    progress: ProgressFn,
) -> anyhow::Result<Rendered> {
    let st = prepare_static(scene, tracer)?;
    let t = st.scene.scene.time.utc(&st.scene.scene.site);
    render_at(&st, t, progress)
}
