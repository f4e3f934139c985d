//! `irsig render <scene> -o <path>.exr`: renders the scene and writes the
//! EXR (every plane), a PNG quicklook and a JSON summary beside it, and an
//! ENVI cube with `--envi`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Serialize;

use crate::output::{envi::write_envi, exr::write_exr, quicklook::write_png};
use crate::render::{
    Frame, Progress, Stage, Stats, prepare_conditions, prepare_static, render_with,
};
use crate::trace::Backend;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// Output EXR path; the PNG quicklook (.png), the JSON summary (.json)
    /// and the ENVI cube (.img/.hdr, with --envi) are written beside it.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Override a scene key before loading, e.g. `--set sensor.band=lwir`
    /// or `--set weather.constant.wind_m_s=4.47` (repeatable). An inline
    /// table replaces a whole table, e.g. the pose of Fig. 14:
    /// `--set 'sensor.pose={slant_range={slant_range_m=10000.0,view_zenith_deg=75.0,azimuth_deg=180.0}}'`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Also write an ENVI BSQ float32 cube of every plane.
    #[arg(long)]
    pub envi: bool,
    /// Ray-tracing backend (default: the scene's `render.tracer`).
    #[arg(long, value_enum)]
    pub tracer: Option<Backend>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Print the rays cast and skipped, thermal solves and cache hits, and
    /// the time per stage.
    #[arg(long)]
    pub stats: bool,
}

/// Parses `KEY=VALUE` overrides.
pub fn parse_overrides(set: &[String]) -> anyhow::Result<Vec<(String, String)>> {
    set.iter()
        .map(|s| match s.split_once('=') {
            Some((k, v)) if !k.trim().is_empty() => {
                Ok((k.trim().to_string(), v.trim().to_string()))
            }
            _ => bail!("--set {s}: expected KEY=VALUE, e.g. --set sensor.band=lwir"),
        })
        .collect()
}

pub use crate::render::thread_pool;

/// A terminal progress bar over the render's stages (trace blocks, thermal
/// solves, radiometry); reports may come from any worker thread and out of
/// order, so the position only grows within a stage.
pub struct ProgressBar {
    bar: indicatif::ProgressBar,
    state: std::sync::Mutex<Option<(Stage, u64)>>,
}

impl ProgressBar {
    pub fn new() -> ProgressBar {
        let bar = indicatif::ProgressBar::new(0);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "irsig: {msg:<22} [{bar:32}] {pos}/{len} {elapsed_precise} (eta {eta})",
            )
            .expect("valid template")
            .progress_chars("=> "),
        );
        ProgressBar {
            bar,
            state: std::sync::Mutex::new(None),
        }
    }

    pub fn report(&self, p: Progress) {
        let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match *st {
            Some((stage, done)) if stage == p.stage => {
                if p.done > done {
                    *st = Some((stage, p.done));
                    self.bar.set_position(p.done);
                }
            }
            _ => {
                *st = Some((p.stage, p.done));
                self.bar.reset();
                self.bar.set_message(match p.stage {
                    Stage::Trace => "tracing (blocks)",
                    Stage::Thermal => "temperatures (samples)",
                    Stage::Radiometry => "radiometry (samples)",
                });
                self.bar.set_length(p.total);
                self.bar.set_position(p.done);
            }
        }
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Default for ProgressBar {
    fn default() -> Self {
        Self::new()
    }
}

/// The JSON summary written beside the image.
#[derive(Serialize)]
pub struct Summary<'a> {
    pub scene: String,
    pub image_time_utc: String,
    pub sun_zenith_deg: f64,
    pub sun_azimuth_deg: f64,
    pub band: String,
    pub estimators: String,
    pub quicklook: String,
    pub planes: Vec<(String, String)>,
    pub stats: &'a Stats,
}

/// Writes a frame's outputs next to `exr`; returns the summary text.
pub fn write_frame(
    exr: &Path,
    frame: &Frame,
    summary_of: impl FnOnce(String) -> anyhow::Result<String>,
    envi: bool,
) -> anyhow::Result<()> {
    if exr.extension().and_then(|e| e.to_str()) != Some("exr") {
        bail!("-o {}: the output must be an .exr path", exr.display());
    }
    if let Some(d) = exr.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    write_exr(exr, &frame.planes)?;
    let p = &frame.planes;
    let ql = p
        .get("sensor_radiance")
        .expect("render writes sensor_radiance");
    let s = write_png(
        &exr.with_extension("png"),
        p.width,
        p.height,
        &ql.data,
        "sensor_radiance W m-2 sr-1 um-1",
    )?;
    let quicklook = format!(
        "sensor_radiance, linear 2-98 percentile stretch {} .. {} W m-2 sr-1 um-1",
        s.lo, s.hi
    );
    if envi {
        write_envi(&exr.with_extension("img"), p, None, "irsig render planes")?;
    }
    let json = summary_of(quicklook)?;
    crate::output::write_atomic(&exr.with_extension("json"), |w| {
        std::io::Write::write_all(w, json.as_bytes()).map_err(|e| e.to_string())
    })?;
    Ok(())
}

pub fn run(a: Args) -> anyhow::Result<i32> {
    // Check the output path before spending time on the render.
    if a.output.extension().and_then(|e| e.to_str()) != Some("exr") {
        bail!("-o {}: the output must be an .exr path", a.output.display());
    }
    let overrides = parse_overrides(&a.set)?;
    let pool = thread_pool(a.threads)?;
    let tty = std::io::stderr().is_terminal();
    let note = |m: &str| {
        if tty {
            eprintln!("irsig: {m}");
        }
    };
    note("loading scene");
    let scene = crate::scene::load_with_overrides(&a.scene, &overrides)?;
    let (frame, summary) = pool.install(|| -> anyhow::Result<_> {
        let st = prepare_static(scene, a.tracer)?;
        let t = st.scene.scene.time.utc(&st.scene.scene.site);
        note("weather, sun and thermal forcing");
        let cond = prepare_conditions(&st, t)?;
        note("rendering");
        let bar = tty.then(ProgressBar::new);
        let report = bar.as_ref().map(|b| move |p: Progress| b.report(p));
        let frame = render_with(
            &st,
            &cond,
            report.as_ref().map(|f| f as &(dyn Fn(Progress) + Sync)),
        )?;
        if let Some(b) = &bar {
            b.finish();
        }
        let summary = (
            st.scene.path.display().to_string(),
            t.to_rfc3339(),
            cond.sun_now.zenith_deg,
            cond.sun_now.azimuth_deg,
            st.band.label.clone(),
            cond.estimators.to_string(),
        );
        Ok((frame, summary))
    })?;
    let planes: Vec<(String, String)> = frame
        .planes
        .planes
        .iter()
        .map(|p| (p.name.clone(), p.unit.clone()))
        .collect();
    write_frame(
        &a.output,
        &frame,
        |quicklook| {
            Ok(serde_json::to_string_pretty(&Summary {
                scene: summary.0,
                image_time_utc: summary.1,
                sun_zenith_deg: summary.2,
                sun_azimuth_deg: summary.3,
                band: summary.4,
                estimators: summary.5,
                quicklook,
                planes,
                stats: &frame.stats,
            })?)
        },
        a.envi,
    )?;
    let s = &frame.stats;
    println!(
        "wrote {} ({}x{}), {:.2} s",
        a.output.display(),
        frame.planes.width,
        frame.planes.height,
        s.seconds.trace + s.seconds.thermal + s.seconds.radiometry + s.seconds.sensor
    );
    if a.stats {
        println!("{}", serde_json::to_string_pretty(s)?);
    }
    Ok(0)
}
