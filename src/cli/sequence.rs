//! `irsig sequence` (one frame per local clock time, the paper's Fig. 12)
//! and `irsig sweep` (one frame per value of a scene key, Figs. 13 and 14):
//! flag parsing over [`crate::render::sequence`] (planning and rendering
//! frames) and [`crate::output::sequence`] (frames, contact sheet and
//! `index.json` in an output folder).

use std::path::PathBuf;

use super::render::parse_overrides;
use crate::output::exr::ExrCompression;
use crate::output::frame::QuicklookOptions;
use crate::output::quicklook::Colormap;
use crate::output::sequence::{FrameDone, SequenceOutput, write_sequence};
use crate::render::sequence::{FramePlan, plan_sequence, plan_sweep, scene_text, time_steps};
use crate::render::sequence::{parse_local_time, parse_step_s};
use crate::render::thread_pool;
use crate::trace::Backend;

/// Options shared by `sequence` and `sweep`.
#[derive(clap::Args, Debug)]
pub struct Common {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// Output folder (created if needed): one EXR + PNG + JSON per frame,
    /// `contact_sheet.png` and `index.json`.
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Override a scene key before loading, e.g. `--set sensor.width_px=128`
    /// or a whole table: `--set 'sensor.pose={slant_range={slant_range_m=10000,
    /// view_zenith_deg=0,azimuth_deg=180}}'` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Remove a key or a whole table from the scene before the overrides,
    /// e.g. `--unset sensor.pose.altitude` (repeatable).
    #[arg(long = "unset", value_name = "KEY")]
    pub unset: Vec<String>,
    /// Also write an ENVI BSQ float32 cube of every plane per frame.
    #[arg(long)]
    pub envi: bool,
    /// The EXRs' compression (lossless; see `irsig render --help`).
    /// Default: each frame's scene's `output.exr_compression` (zips).
    #[arg(long, value_name = "none|rle|zips|zip|piz")]
    pub exr_compression: Option<ExrCompression>,
    /// The quicklooks' and the contact sheet's colour map (as `irsig
    /// render --colormap`; a colour bar is drawn below each).
    #[arg(long, value_enum, default_value_t = Colormap::Grey, value_name = "grey|inferno")]
    pub colormap: Colormap,
    /// Each quicklook's stretch, and the contact sheet's common one, spans
    /// at least this many kelvin of apparent temperature (as `irsig render
    /// --quicklook-min-span-k`).
    #[arg(long, default_value_t = 2.0, value_name = "K")]
    pub quicklook_min_span_k: f64,
    /// Render every frame, even those already complete in the output
    /// folder from an earlier run of the same scene (by default such
    /// frames, e.g. of a killed run, are kept and not rendered again).
    #[arg(long)]
    pub no_resume: bool,
    /// Ray-tracing backend (default: the scene's `render.tracer`).
    #[arg(long, value_enum)]
    pub tracer: Option<Backend>,
    /// Worker threads per frame (default: all cores). Results do not
    /// depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

#[derive(clap::Args, Debug)]
/// `irsig sequence`: one frame per local clock time.
pub struct SequenceArgs {
    #[command(flatten)]
    /// The scene, output and render options every frame shares.
    pub common: Common,
    /// First local clock time: `HH:MM[:SS]` on the scene's image date, or a
    /// local date-time `YYYY-MM-DDTHH:MM[:SS]` (the site's `utc_offset_h`
    /// applies).
    #[arg(long)]
    pub from: String,
    /// Last local clock time (included when a step lands on it); same forms.
    #[arg(long)]
    pub to: String,
    /// Time step, e.g. `1h`, `30min`, `1h30m`, `90s`.
    #[arg(long)]
    pub step: String,
}

#[derive(clap::Args, Debug)]
/// `irsig sweep`: one frame per value of a scene key.
pub struct SweepArgs {
    #[command(flatten)]
    /// The scene, output and render options every frame shares.
    pub common: Common,
    /// The dotted scene key to sweep, e.g. `weather.constant.wind_m_s` or
    /// `sensor.pose.slant_range.view_zenith_deg`.
    #[arg(long)]
    pub key: String,
    /// Comma-separated TOML values, one frame each, e.g. `0,4.47,8.94,13.41`.
    #[arg(long, value_name = "V1,V2,...")]
    pub values: String,
}

/// The scene text with `--unset` and `--set` applied, and the `--set`
/// overrides (which errors name).
fn edited_text(c: &Common) -> anyhow::Result<(String, Vec<(String, String)>)> {
    let set = parse_overrides(&c.set)?;
    Ok((scene_text(&c.scene, &c.unset, &set)?, set))
}

/// Runs `irsig sequence`; returns the process exit code.
pub fn run_sequence(a: SequenceArgs) -> anyhow::Result<i32> {
    let c = &a.common;
    quicklook_options(c)?;
    let step_s = parse_step_s(&a.step)?;
    let (text, set) = edited_text(c)?;
    let scene = crate::scene::load_edited(&c.scene, text, &set)?;
    super::log::warn_about_frame(&scene);
    let date = scene.scene.time.local.date();
    let from = parse_local_time("--from", &a.from, date)?;
    let to = parse_local_time("--to", &a.to, date)?;
    let times = time_steps(from, to, step_s)?;
    run_frames(c, "sequence", None, plan_sequence(scene, &times))
}

/// The quicklook flags, checked (before any rendering).
fn quicklook_options(c: &Common) -> anyhow::Result<QuicklookOptions> {
    crate::bounds::args::QUICKLOOK_MIN_SPAN_K
        .check_flag(c.quicklook_min_span_k)
        .map_err(anyhow::Error::msg)?;
    Ok(QuicklookOptions {
        colormap: c.colormap,
        min_span_k: c.quicklook_min_span_k,
    })
}

/// Runs `irsig sweep`; returns the process exit code.
pub fn run_sweep(a: SweepArgs) -> anyhow::Result<i32> {
    let c = &a.common;
    quicklook_options(c)?;
    let (text, set) = edited_text(c)?;
    let values: Vec<&str> = a.values.split(',').collect();
    let plans = plan_sweep(&c.scene, &text, &set, &a.key, &values)?;
    if let Some(s) = plans.iter().find_map(|p| p.scene.as_ref()) {
        super::log::warn_about_frame(s);
    }
    run_frames(c, "sweep", Some(a.key.trim()), plans)
}

/// Renders, writes and reports the planned frames.
fn run_frames(
    c: &Common,
    command: &str,
    key: Option<&str>,
    plans: Vec<FramePlan>,
) -> anyhow::Result<i32> {
    let out = SequenceOutput {
        dir: c.output.clone(),
        command: command.into(),
        key: key.map(str::to_string),
        scene: c.scene.display().to_string(),
        envi: c.envi,
        exr_compression: c.exr_compression,
        quicklook: quicklook_options(c)?,
    };
    let pool = thread_pool(c.threads)?;
    let n = plans.len();
    let index = pool.install(|| {
        write_sequence(
            plans,
            c.tracer,
            out,
            !c.no_resume,
            &mut |done, entry, exr| {
                let what = match done {
                    FrameDone::Rendered(f) => {
                        let p = &f.image.frame.planes;
                        format!(
                            "wrote {} ({}x{}), {:.2} s",
                            exr.display(),
                            p.width,
                            p.height,
                            entry.seconds
                        )
                    }
                    FrameDone::Skipped => format!("{} is complete, kept", exr.display()),
                };
                println!(
                    "frame {}/{n} {}: {what}; apparent temperature std {:.3} K",
                    entry.index + 1,
                    entry.value,
                    entry.apparent_temperature_k.std,
                );
            },
        )
    })?;
    println!(
        "wrote {} frames, {} and {}",
        index.frames.len(),
        c.output.join(&index.contact_sheet.file).display(),
        c.output.join("index.json").display()
    );
    Ok(0)
}
