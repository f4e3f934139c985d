//! `irsig render <scene> -o <path>.exr`: renders the scene and writes the
//! EXR (every plane), a PNG quicklook and a JSON summary beside it, and an
//! ENVI cube with `--envi`.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::bail;

use crate::output::frame::write_rendered;
use crate::render::{Progress, Stage, prepare_conditions, prepare_static, render_conditions};
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

use crate::render::thread_pool;

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
    let image = pool.install(|| -> anyhow::Result<_> {
        let st = prepare_static(scene, a.tracer)?;
        let t = st.scene.scene.time.utc(&st.scene.scene.site);
        note("weather, sun and thermal forcing");
        let cond = prepare_conditions(&st, t)?;
        note("rendering");
        let bar = tty.then(ProgressBar::new);
        let report = bar.as_ref().map(|b| move |p: Progress| b.report(p));
        let image = render_conditions(
            &st,
            &cond,
            report.as_ref().map(|f| f as &(dyn Fn(Progress) + Sync)),
        )?;
        if let Some(b) = &bar {
            b.finish();
        }
        Ok(image)
    })?;
    write_rendered(&a.output, &image, a.envi, None)?;
    let s = &image.frame.stats;
    println!(
        "wrote {} ({}x{}), {:.2} s",
        a.output.display(),
        image.frame.planes.width,
        image.frame.planes.height,
        s.seconds.trace + s.seconds.thermal + s.seconds.radiometry + s.seconds.sensor
    );
    if a.stats {
        println!("{}", serde_json::to_string_pretty(s)?);
    }
    Ok(0)
}
