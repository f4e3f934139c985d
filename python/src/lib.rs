//! `irsig._irsig`: the Rust side of the Python package `irsig`. It holds
//! no logic of its own beyond argument conversion: scenes are loaded,
//! checked and rendered by the irsig library, and the results go back as
//! numpy arrays (moved, not copied) and JSON text that `irsig/__init__.py`
//! turns into xarray and pandas objects.
//!
//! Renders run in a scoped thread with the GIL released; the calling thread
//! wakes every few milliseconds to check for signals (Ctrl-C sets the
//! render's cancellation flag, see `irsig::render::cancel`) and to pass the
//! progress on to the Python callback.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

use chrono::{DateTime, NaiveDate, NaiveDateTime, Utc};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use irsig::render::cancel::{self, Cancelled};
use irsig::render::sequence::{FramePlan, Frames, plan_sequence, plan_sweep};
use irsig::render::{Progress, Rendered, Stage, prepare_static, render_at};
use irsig::scene::{LoadedScene, SceneError as LibSceneError, TimeSpec};
use irsig::trace::Backend;

create_exception!(
    irsig,
    IrsigError,
    PyException,
    "An error of irsig; the message is the one the CLI prints."
);
create_exception!(
    irsig,
    SceneError,
    IrsigError,
    "A scene, material, mesh or data file is wrong; `file`, `line` and `column` say where (line and column 0: unknown)."
);
create_exception!(
    irsig,
    WeatherError,
    IrsigError,
    "A weather file is wrong or does not cover the history; `file` and `line` say where."
);

/// The Python exception of an irsig error: the message is the CLI's
/// (`{e:#}`, the whole context chain), the class and attributes follow the
/// first located error of the chain.
fn to_py(e: anyhow::Error) -> PyErr {
    if e.chain().any(|c| c.is::<Cancelled>()) {
        return PyKeyboardInterrupt::new_err("render cancelled");
    }
    let msg = format!("{e:#}");
    Python::with_gil(|py| {
        let located = e.chain().find_map(|c| {
            if let Some(s) = c.downcast_ref::<LibSceneError>() {
                let (file, line, col, via) = match s {
                    LibSceneError::Io { path, .. } => (path.display().to_string(), 0, 0, None),
                    _ => s.location().map_or((String::new(), 0, 0, None), |l| {
                        let via = l.via.as_deref().map(str::to_string);
                        (l.file.display().to_string(), l.line, l.col, via)
                    }),
                };
                Some((SceneError::new_err(msg.clone()), file, line, col, via))
            } else if let Some(w) = c.downcast_ref::<irsig::weather::WeatherError>() {
                let (file, line) = weather_location(w);
                Some((WeatherError::new_err(msg.clone()), file, line, 0, None))
            } else {
                None
            }
        });
        match located {
            Some((err, file, line, col, via)) => {
                let v = err.value(py);
                let _ = v.setattr("file", (!file.is_empty()).then_some(file));
                let _ = v.setattr("line", line);
                let _ = v.setattr("column", col);
                let _ = v.setattr("override", via);
                err
            }
            None => IrsigError::new_err(msg),
        }
    })
}

/// File and line of a weather error (line 0: none; file empty: the error
/// names no file, e.g. weather that does not cover the history).
fn weather_location(w: &irsig::weather::WeatherError) -> (String, usize) {
    use irsig::weather::WeatherError as W;
    match w {
        W::Malformed { file, line, .. }
        | W::OutOfRange { file, line, .. }
        | W::Unsorted { file, line, .. }
        | W::Duplicate { file, line, .. }
        | W::Gap { file, line, .. } => (file.clone(), *line),
        W::Io { file, .. } | W::Empty { file, .. } => (file.clone(), 0),
        _ => (String::new(), 0),
    }
}

fn anyhow_py<T, E: Into<anyhow::Error>>(r: Result<T, E>) -> PyResult<T> {
    r.map_err(|e| to_py(e.into()))
}

/// A loaded scene (with its overrides applied).
#[pyclass(module = "irsig._irsig", frozen)]
struct Scene {
    scene: LoadedScene,
    /// The scene file's text with the overrides applied (sweeps override
    /// it further).
    text: String,
    overrides: Vec<(String, String)>,
    unset: Vec<String>,
}

#[pymethods]
impl Scene {
    /// Loads `path`, applying `overrides` ((key, value) pairs, the CLI's
    /// `--set key=value`).
    #[staticmethod]
    #[pyo3(signature = (path, overrides = Vec::new(), unset = Vec::new()))]
    fn load(
        path: PathBuf,
        overrides: Vec<(String, String)>,
        unset: Vec<String>,
    ) -> PyResult<Scene> {
        let read = || -> anyhow::Result<(LoadedScene, String)> {
            let text = std::fs::read_to_string(&path).map_err(|error| LibSceneError::Io {
                path: path.clone(),
                error,
            })?;
            if overrides.is_empty() && unset.is_empty() {
                // Exactly the CLI's load without --set.
                return Ok((irsig::scene::load(&path)?, text));
            }
            let text = if unset.is_empty() {
                text
            } else {
                irsig::scene::remove_keys(&path, &text, &unset)?
            };
            let text = irsig::scene::apply_overrides(&path, &text, &overrides)?;
            Ok((
                irsig::scene::load_edited(&path, text.clone(), &overrides)?,
                text,
            ))
        };
        let (scene, text) = read().map_err(to_py)?;
        Ok(Scene {
            scene,
            text,
            overrides,
            unset,
        })
    }

    #[getter]
    fn path(&self) -> PathBuf {
        self.scene.path.clone()
    }

    #[getter]
    fn overrides(&self) -> Vec<(String, String)> {
        self.overrides.clone()
    }

    #[getter]
    fn unset(&self) -> Vec<String> {
        self.unset.clone()
    }

    /// The scene file's text with the overrides applied.
    #[getter]
    fn text(&self) -> &str {
        &self.text
    }

    /// The image size (width, height) in output pixels.
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.scene.camera.width_px, self.scene.camera.height_px)
    }

    /// `irsig check --json` as JSON text.
    fn check_json(&self) -> PyResult<String> {
        anyhow_py(serde_json::to_string(&irsig::render::memory::check_report(
            &self.scene,
        )))
    }

    fn __repr__(&self) -> String {
        format!(
            "Scene({:?}, {} triangles, {}x{} px)",
            self.scene.path.display().to_string(),
            self.scene.triangles.len(),
            self.scene.camera.width_px,
            self.scene.camera.height_px
        )
    }
}

/// Progress of a whole call (one or more frames) in units of 1/1000 of a
/// render stage: frame i, stage s at fraction f is i·3000 + s·1000 + 1000·f.
struct Reporter {
    frame: AtomicU64,
    done: AtomicU64,
}

const STAGE_UNITS: u64 = 1000;
const FRAME_UNITS: u64 = 3 * STAGE_UNITS;

impl Reporter {
    fn report(&self, p: Progress) {
        let stage = match p.stage {
            Stage::Trace => 0,
            Stage::Thermal => 1,
            Stage::Radiometry => 2,
        };
        let frac = (STAGE_UNITS * p.done.min(p.total))
            .checked_div(p.total)
            .unwrap_or(STAGE_UNITS);
        let d = self.frame.load(Ordering::Relaxed) * FRAME_UNITS + stage * STAGE_UNITS + frac;
        self.done.fetch_max(d, Ordering::Relaxed);
    }

    /// Frame `i` starts (the previous ones are complete).
    fn start_frame(&self, i: u64) {
        self.frame.store(i, Ordering::Relaxed);
        self.done.fetch_max(i * FRAME_UNITS, Ordering::Relaxed);
    }
}

/// Runs `work` in a rayon pool of `threads` workers (FTZ/DAZ set, the
/// cancellation flag watched) on a scoped thread, with the GIL released.
/// The calling thread polls for signals (Ctrl-C cancels the render and
/// raises `KeyboardInterrupt`) and calls `progress(done, total)` when the
/// progress moved; an exception from the callback cancels the render too.
fn run_blocking<T: Send>(
    py: Python<'_>,
    threads: Option<u32>,
    progress: Option<&Bound<'_, PyAny>>,
    frames: u64,
    work: impl FnOnce(&Reporter) -> anyhow::Result<T> + Send,
) -> PyResult<T> {
    let flag = Arc::new(AtomicBool::new(false));
    let f2 = flag.clone();
    let mut b = rayon::ThreadPoolBuilder::new().start_handler(move |_| {
        irsig::trace::embree::set_thread_ftz_daz();
        cancel::set_thread_flag(f2.clone());
    });
    if let Some(n) = threads {
        irsig::bounds::args::THREADS
            .check(n.into())
            .map_err(IrsigError::new_err)?;
        b = b.num_threads(n as usize);
    }
    let pool = b
        .build()
        .map_err(|e| IrsigError::new_err(format!("cannot start the thread pool: {e}")))?;
    let rep = Reporter {
        frame: AtomicU64::new(0),
        done: AtomicU64::new(0),
    };
    let total = frames * FRAME_UNITS;
    let caller = std::thread::current();
    let mut pending: Option<PyErr> = None;
    // Set by the worker just before it wakes the caller: `is_finished` may
    // still be false right after the unpark (the thread has not exited yet),
    // which cost every call up to one more 20-ms wait.
    let done = AtomicBool::new(false);
    let result = std::thread::scope(|s| {
        let rep = &rep;
        let pool = &pool;
        let done = &done;
        let h = s.spawn(move || {
            let r = pool.install(|| work(rep));
            done.store(true, Ordering::Release);
            caller.unpark();
            r
        });
        let mut shown = u64::MAX;
        loop {
            py.allow_threads(|| {
                if !done.load(Ordering::Acquire) {
                    std::thread::park_timeout(Duration::from_millis(20));
                }
            });
            let finished = done.load(Ordering::Acquire);
            if let Some(cb) = progress {
                let d = if finished {
                    total
                } else {
                    rep.done.load(Ordering::Relaxed)
                };
                if d != shown {
                    shown = d;
                    if let Err(e) = cb.call1((d, total)) {
                        pending = Some(e);
                    }
                }
            }
            if pending.is_none()
                && let Err(e) = py.check_signals()
            {
                pending = Some(e);
            }
            if pending.is_some() {
                flag.store(true, Ordering::Relaxed);
            }
            if finished || pending.is_some() {
                break;
            }
        }
        py.allow_threads(|| h.join())
    });
    if let Some(e) = pending {
        return Err(e);
    }
    match result {
        Ok(r) => r.map_err(to_py),
        Err(_) => Err(IrsigError::new_err("the render panicked")),
    }
}

/// The backend named `tracer` (None: the scene's).
fn backend(tracer: Option<&str>) -> PyResult<Option<Backend>> {
    match tracer {
        None => Ok(None),
        Some("embree") => Ok(Some(Backend::Embree)),
        Some("bvh") => Ok(Some(Backend::Bvh)),
        Some(t) => Err(IrsigError::new_err(format!(
            "tracer={t:?}: expected \"embree\" or \"bvh\""
        ))),
    }
}

/// A frame's image time: `None` the scene's `[time]`; RFC 3339 with an
/// offset (`2001-08-08T16:00:00Z`); a local date-time of the site's clock
/// (`2001-08-08T12:00[:00]`); or a local clock time on the scene's date
/// (`12:00[:00]`).
fn image_time(
    s: Option<&str>,
    scene: &LoadedScene,
) -> anyhow::Result<(NaiveDateTime, DateTime<Utc>)> {
    let sc = &scene.scene;
    let local = match s {
        None => sc.time.local,
        Some(s) => {
            if let Ok(t) = DateTime::parse_from_rfc3339(s) {
                let utc = t.with_timezone(&Utc);
                irsig::bounds::time::YEAR
                    .check(chrono::Datelike::year(&utc).into())
                    .map_err(|m| anyhow::anyhow!("time={s:?}: {m}"))?;
                let off = chrono::Duration::seconds((sc.site.utc_offset_h * 3600.0).round() as i64);
                return Ok((utc.naive_utc() + off, utc));
            }
            local_time(s, sc.time.local.date())?
        }
    };
    Ok((local, TimeSpec { local }.utc(&sc.site)))
}

fn local_time(s: &str, date: NaiveDate) -> anyhow::Result<NaiveDateTime> {
    irsig::render::sequence::parse_local_time("time", s, date).map_err(|_| {
        anyhow::anyhow!(
            "time={s:?}: expected RFC 3339 with an offset (2001-08-08T16:00:00Z), a local date-time of the site's clock (2001-08-08T12:00) or a local clock time on the scene's date (12:00)"
        )
    })
}

/// The local times from `start` to `stop` every `step` (`1h`, `30min`,
/// ...), as `irsig sequence --from --to --step`, as ISO text.
#[pyfunction]
fn sequence_times(scene: &Scene, start: &str, stop: &str, step: &str) -> PyResult<Vec<String>> {
    use irsig::render::sequence::{
        TimeNames, parse_local_time, parse_step_s_named, time_steps_named,
    };
    let date = scene.scene.scene.time.local.date();
    let r = || -> anyhow::Result<Vec<String>> {
        let step_s = parse_step_s_named("step", step)?;
        let from = parse_local_time("start", start, date)?;
        let to = parse_local_time("stop", stop, date)?;
        Ok(time_steps_named(TimeNames::PYTHON, from, to, step_s)?
            .iter()
            .map(|t| t.format("%Y-%m-%dT%H:%M:%S").to_string())
            .collect())
    };
    r().map_err(to_py)
}

/// One rendered image as Python objects: `planes` is a list of (name,
/// unit, float32 array of shape (height, width)) whose data are the
/// render's own buffers; `meta` is JSON text.
fn image_to_py<'py>(
    py: Python<'py>,
    image: Rendered,
    mut meta: serde_json::Value,
) -> PyResult<Bound<'py, PyDict>> {
    let frame = image.frame;
    let (w, h) = (frame.planes.width as usize, frame.planes.height as usize);
    let planes = PyList::empty(py);
    for p in frame.planes.planes {
        let a = PyArray1::from_vec(py, p.data).reshape([h, w])?;
        planes.append((p.name, p.unit, a))?;
    }
    let points = PyList::empty(py);
    for (i, axis) in hit_points(
        &frame.samples,
        frame.sample_width as usize,
        w,
        h,
        &image.local_frame,
    )
    .into_iter()
    .enumerate()
    {
        let name = ["east", "north", "up"][i];
        points.append((name, PyArray1::from_vec(py, axis).reshape([h, w])?))?;
    }
    meta["scene"] = image.scene.into();
    meta["image_time_utc"] = image
        .image_time_utc
        .to_rfc3339_opts(chrono::SecondsFormat::Secs, true)
        .into();
    meta["sun_zenith_deg"] = image.sun_zenith_deg.into();
    meta["sun_azimuth_deg"] = image.sun_azimuth_deg.into();
    meta["band"] = image.band.into();
    meta["estimators"] = image.estimators.into();
    meta["atmosphere"] = serde_json::to_value(&image.atmosphere).unwrap_or_default();
    meta["stats"] = serde_json::to_value(&frame.stats).unwrap_or_default();
    meta["georef"] = serde_json::to_value(&image.georef).unwrap_or_default();
    let d = PyDict::new(py);
    d.set_item("planes", planes)?;
    d.set_item("points", points)?;
    d.set_item("meta", meta.to_string())?;
    Ok(d)
}

/// The world point (east, north, up, m: the scene's coordinates) each
/// output pixel's centre sample hits (NaN where it sees no surface), three
/// `w`×`h` float64 planes (the tracer's local-frame points plus the frame's
/// origin, so that projected coordinates keep their millimetres).
fn hit_points(
    samples: &[irsig::render::Sample],
    sample_width: usize,
    w: usize,
    h: usize,
    frame: &irsig::scene::LocalFrame,
) -> [Vec<f64>; 3] {
    let n = (sample_width / w.max(1)).max(1);
    let mut out = [
        vec![f64::NAN; w * h],
        vec![f64::NAN; w * h],
        vec![f64::NAN; w * h],
    ];
    for y in 0..h {
        for x in 0..w {
            let k = (y * n + n / 2) * sample_width + x * n + n / 2;
            if let Some(p) = samples.get(k).and_then(|s| s.surface.as_ref()) {
                let world = frame.to_world(p.point.as_dvec3().to_array());
                for (axis, v) in out.iter_mut().zip(world) {
                    axis[y * w + x] = v;
                }
            }
        }
    }
    out
}

/// What a frame's Dataset carries beside the image's own description: the
/// local time, site, band limits, camera and materials of its scene.
fn scene_meta(sc: &LoadedScene, local: NaiveDateTime) -> serde_json::Value {
    let (lo, hi) = sc.response.support_um();
    let site = &sc.scene.site;
    serde_json::json!({
        "image_time_local": local.format("%Y-%m-%dT%H:%M:%S").to_string(),
        "utc_offset_h": site.utc_offset_h,
        "latitude_deg": site.location.latitude_deg,
        "longitude_deg": site.location.longitude_deg,
        "band_min_um": lo,
        "band_max_um": hi,
        "camera": sc.camera,
        "materials": sc.materials.iter().map(|m| m.name.as_str()).collect::<Vec<_>>(),
    })
}

/// Renders `scene` at `time` (see `image_time`).
#[pyfunction]
#[pyo3(signature = (scene, time = None, threads = None, tracer = None, progress = None))]
fn render<'py>(
    py: Python<'py>,
    scene: &Scene,
    time: Option<String>,
    threads: Option<u32>,
    tracer: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let be = backend(tracer.as_deref())?;
    let (local, utc) = image_time(time.as_deref(), &scene.scene).map_err(to_py)?;
    let meta = scene_meta(&scene.scene, local);
    let loaded = scene.scene.clone();
    let image = run_blocking(py, threads, progress.as_ref(), 1, |rep| {
        let mut st = prepare_static(loaded, be)?;
        st.keep_samples = true; // hit_points reads the samples' points
        let report = |p: Progress| rep.report(p);
        render_at(&st, utc, Some(&report))
    })?;
    image_to_py(py, image, meta)
}

/// Renders planned frames (`irsig::render::sequence::Frames`, the static
/// part shared as the CLI shares it) with the GIL released.
fn render_frames<'py>(
    py: Python<'py>,
    plans: Vec<FramePlan>,
    threads: Option<u32>,
    tracer: Option<Backend>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    // Each frame's scene description: a plan without a scene keeps the
    // scene of the plan before.
    let mut metas = Vec::with_capacity(plans.len());
    let mut last: Option<&LoadedScene> = None;
    for p in &plans {
        last = p.scene.as_ref().or(last);
        let Some(sc) = last else {
            return Err(IrsigError::new_err("the first frame has no scene"));
        };
        metas.push(scene_meta(sc, p.local.unwrap_or(sc.scene.time.local)));
    }
    let n = plans.len() as u64;
    let frames = run_blocking(py, threads, progress.as_ref(), n, |rep| {
        let mut out = Vec::with_capacity(plans.len());
        let mut frames = Frames::new(plans, tracer);
        frames.keep_samples = true; // hit_points reads the samples' points
        let report = |p: Progress| rep.report(p);
        while let Some(f) = frames.next_with(Some(&report)) {
            let f = f?;
            rep.start_frame(f.index as u64 + 1);
            out.push(f);
        }
        Ok(out)
    })?;
    let list = PyList::empty(py);
    for (f, mut m) in frames.into_iter().zip(metas) {
        m["value"] = f.value.into();
        m["image_time_local"] = f.local.format("%Y-%m-%dT%H:%M:%S").to_string().into();
        m["reused"] = serde_json::json!({
            "geometry": f.reused.geometry,
            "atmosphere": f.reused.atmosphere,
        });
        list.append(image_to_py(py, f.image, m)?)?;
    }
    Ok(list)
}

/// Renders `scene` at each of `times` (each as `render`'s `time`), as
/// `irsig sequence`: the static part (geometry, BVH, tables) is prepared
/// once.
#[pyfunction]
#[pyo3(signature = (scene, times, threads = None, tracer = None, progress = None))]
fn sequence<'py>(
    py: Python<'py>,
    scene: &Scene,
    times: Vec<String>,
    threads: Option<u32>,
    tracer: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let be = backend(tracer.as_deref())?;
    let locals = times
        .iter()
        .map(|t| image_time(Some(t), &scene.scene).map(|(local, _)| local))
        .collect::<anyhow::Result<Vec<_>>>()
        .map_err(to_py)?;
    let plans = plan_sequence(scene.scene.clone(), &locals);
    render_frames(py, plans, threads, be, progress)
}

/// Renders `scene` with `key` set to each of `values` (TOML values), as
/// `irsig sweep --key --values`: every value's scene is loaded (and so
/// checked) before any is rendered; geometry and atmosphere are reused
/// between frames where the key leaves them unchanged. `time`: every
/// frame's image time (default: each scene's `[time]`).
#[pyfunction]
#[pyo3(signature = (scene, key, values, time = None, threads = None, tracer = None, progress = None))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    scene: &Scene,
    key: String,
    values: Vec<String>,
    time: Option<String>,
    threads: Option<u32>,
    tracer: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let be = backend(tracer.as_deref())?;
    let local = match time.as_deref() {
        None => None,
        Some(t) => Some(image_time(Some(t), &scene.scene).map_err(to_py)?.0),
    };
    let values: Vec<&str> = values.iter().map(String::as_str).collect();
    let mut plans = plan_sweep(
        &scene.scene.path,
        &scene.text,
        &scene.overrides,
        &key,
        &values,
    )
    .map_err(to_py)?;
    for p in &mut plans {
        p.local = local.or(p.local);
    }
    render_frames(py, plans, threads, be, progress)
}

/// Everything about output pixel (`x`, `y`) (column, row from the top
/// left) at `time`, as `irsig probe --json` (JSON text).
#[pyfunction]
#[pyo3(signature = (scene, x, y, time = None, spectral = false, threads = None, tracer = None))]
#[allow(clippy::too_many_arguments)]
fn probe(
    py: Python<'_>,
    scene: &Scene,
    x: u32,
    y: u32,
    time: Option<String>,
    spectral: bool,
    threads: Option<u32>,
    tracer: Option<String>,
) -> PyResult<String> {
    let be = backend(tracer.as_deref())?;
    let cam = &scene.scene.scene.sensor;
    let (w, h) = (cam.width_px, cam.height_px);
    if x >= w || y >= h {
        return Err(IrsigError::new_err(format!(
            "x={x}, y={y}: outside the {w}x{h} image (x 0..{}, y 0..{})",
            w.saturating_sub(1),
            h.saturating_sub(1)
        )));
    }
    let mut loaded = scene.scene.clone();
    if let Some(t) = time.as_deref() {
        // The image time is the scene's `[time] local`.
        loaded.scene.time.local = image_time(Some(t), &scene.scene).map_err(to_py)?.0;
    }
    let report = run_blocking(py, threads, None, 1, |_| {
        irsig::render::probe::probe_scene(loaded, be, (x, y), spectral)
    })?;
    anyhow_py(serde_json::to_string(&report))
}

/// Solar position (NREL SPA) at `time` (RFC 3339 with an offset), as
/// `irsig sun --json` (JSON text).
#[pyfunction]
#[pyo3(signature = (lat, lon, time, elevation = 0.0, pressure_hpa = None, temp_c = None, delta_t_s = None))]
fn sun(
    lat: f64,
    lon: f64,
    time: &str,
    elevation: f64,
    pressure_hpa: Option<f64>,
    temp_c: Option<f64>,
    delta_t_s: Option<f64>,
) -> PyResult<String> {
    let t = irsig::sun::report::parse_time(time).map_err(IrsigError::new_err)?;
    let d = irsig::sun::SpaOptions::default();
    let opts = irsig::sun::SpaOptions {
        pressure_hpa: pressure_hpa.unwrap_or(d.pressure_hpa),
        temp_c: temp_c.unwrap_or(d.temp_c),
        delta_t_s,
        ..d
    };
    let r = irsig::sun::report::sun_report(t, lat, lon, elevation, &opts).map_err(to_py)?;
    anyhow_py(serde_json::to_string(&r))
}

/// The shipped atmosphere tables: (name, source, description); the source
/// is a file path or "embedded in the irsig binary".
#[pyfunction]
fn atmos_list() -> PyResult<Vec<(String, String, String)>> {
    anyhow_py(irsig::atmos::list_builtin().map(|l| {
        l.into_iter()
            .map(|(n, s, d)| (n, s.to_string(), d))
            .collect()
    }))
}

/// What atmosphere `name` contributes for one geometry over `band`, as
/// `irsig atmos show` (JSON text).
#[pyfunction]
#[pyo3(signature = (name, altitude_km, zenith_deg, sky_zenith_deg = None, sun_zenith_deg = 45.0, rel_azimuth_deg = 90.0, band = "8-14"))]
fn atmos_show(
    name: &str,
    altitude_km: f64,
    zenith_deg: f64,
    sky_zenith_deg: Option<f64>,
    sun_zenith_deg: f64,
    rel_azimuth_deg: f64,
    band: &str,
) -> PyResult<String> {
    use irsig::atmos::view::{AtmosGeometry, atmos_view};
    let g = AtmosGeometry {
        altitude_km,
        view_zenith_deg: zenith_deg,
        sky_zenith_deg: sky_zenith_deg.unwrap_or(zenith_deg),
        sun_zenith_deg,
        rel_azimuth_deg,
    };
    let v = atmos_view(name, band, g).map_err(to_py)?;
    anyhow_py(serde_json::to_string(&v))
}

/// Surface temperature and every flux term of one material and facet over
/// time, as `irsig therm --json` (JSON text); the arguments are its flags
/// (`irsig::therm::series::FacetRun`).
#[pyfunction]
#[pyo3(signature = (
    materials, material, lat, lon, start, stop, weather = None, forcing = None,
    typical_year = false, elevation = 0.0, slope = 0.0, aspect = 180.0, step_min = 15.0,
    spin_up_h = 24.0, spin_up_start = "mean-forcing", convection = "surface-layer",
    wind_height_m = 10.0, air_height_m = 2.0, site_roughness_m = 0.03, facet_height_m = 0.0,
    shadow = None, sky_view = None,
))]
#[allow(clippy::too_many_arguments)]
fn therm(
    py: Python<'_>,
    materials: PathBuf,
    material: String,
    lat: f64,
    lon: f64,
    start: &str,
    stop: &str,
    weather: Option<PathBuf>,
    forcing: Option<PathBuf>,
    typical_year: bool,
    elevation: f64,
    slope: f64,
    aspect: f64,
    step_min: f64,
    spin_up_h: f64,
    spin_up_start: &str,
    convection: &str,
    wind_height_m: f64,
    air_height_m: f64,
    site_roughness_m: f64,
    facet_height_m: f64,
    shadow: Option<&str>,
    sky_view: Option<f64>,
) -> PyResult<String> {
    use irsig::scene::lookup::load_material;
    use irsig::therm::balance::{Convection, Orientation};
    use irsig::therm::series::{
        FacetRun, ForcingSource, facet_series, parse_shadow_ranges, parse_time,
    };
    use irsig::therm::slab::SpinUpStart;
    let build = || -> anyhow::Result<FacetRun> {
        Ok(FacetRun {
            material_name: material.clone(),
            material: load_material(&materials, &material)?,
            forcing: match (forcing, weather) {
                (Some(p), None) => ForcingSource::ForcingCsv(p),
                (None, Some(path)) => ForcingSource::Weather {
                    path,
                    typical_year,
                    stand_in: false,
                },
                _ => anyhow::bail!("give weather= or forcing= (one of them)"),
            },
            site: irsig::sun::Site {
                latitude_deg: lat,
                longitude_deg: lon,
                elevation_m: elevation,
            },
            orientation: Orientation {
                slope_deg: slope,
                aspect_deg: aspect,
            },
            from: parse_time(start).map_err(|e| e.context("start"))?,
            to: parse_time(stop).map_err(|e| e.context("stop"))?,
            step_min,
            spin_up_h,
            spin_up_start: match spin_up_start {
                "mean-forcing" => SpinUpStart::MeanForcing,
                "first-sample" => SpinUpStart::FirstSample,
                s => anyhow::bail!(
                    "spin_up_start={s:?}: expected \"mean-forcing\" or \"first-sample\""
                ),
            },
            convection: match convection {
                "surface-layer" => Convection::SurfaceLayer(irsig::therm::aero::SurfaceLayer {
                    wind_height_m,
                    air_height_m,
                    site_roughness_m,
                }),
                "mcadams" => Convection::mcadams(),
                c => anyhow::bail!("convection={c:?}: expected \"surface-layer\" or \"mcadams\""),
            },
            facet_height_m,
            shadow: shadow
                .map(parse_shadow_ranges)
                .transpose()?
                .unwrap_or_default(),
            sky_view,
        })
    };
    let run = build().map_err(to_py)?;
    let series = run_blocking(py, Some(1), None, 1, |_| facet_series(&run))?;
    let mut v = serde_json::to_value(&series).map_err(|e| to_py(e.into()))?;
    v["estimators"] = series.estimator_lines.into();
    Ok(v.to_string())
}

/// The version of the extension (and of the irsig library it was built with).
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _irsig(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(sequence, m)?)?;
    m.add_function(wrap_pyfunction!(sequence_times, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sun, m)?)?;
    m.add_function(wrap_pyfunction!(probe, m)?)?;
    m.add_function(wrap_pyfunction!(atmos_list, m)?)?;
    m.add_function(wrap_pyfunction!(atmos_show, m)?)?;
    m.add_function(wrap_pyfunction!(therm, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add("IrsigError", py.get_type::<IrsigError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("WeatherError", py.get_type::<WeatherError>())?;
    Ok(())
}
