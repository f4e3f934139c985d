//! `irsig report <x.json>`: a self-contained HTML page of a render's
//! output set (see [`crate::output::report`]).

use std::path::PathBuf;

use crate::output::quicklook::Colormap;
use crate::output::report::{ReportOptions, write_report};

#[derive(clap::Args, Debug)]
/// `irsig report`: an HTML page of a render.
pub struct Args {
    /// The render's JSON summary (`x.json`, written beside its EXR or
    /// GeoTIFF by `irsig render`).
    pub json: PathBuf,
    /// The HTML page to write (default: `x.html` beside the JSON).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Show only these planes (comma-separated; default: all of the set).
    #[arg(long, value_delimiter = ',', value_name = "PLANE,...")]
    pub planes: Vec<String>,
    /// The images' colour map.
    #[arg(long, value_enum, default_value_t = Colormap::Inferno, value_name = "grey|inferno")]
    pub colormap: Colormap,
}

/// Runs `irsig report`; returns the process exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    let out = a
        .output
        .clone()
        .unwrap_or_else(|| a.json.with_extension("html"));
    let info = write_report(
        &a.json,
        &out,
        &ReportOptions {
            planes: a.planes,
            colormap: a.colormap,
        },
    )?;
    println!(
        "wrote {} ({} planes of {}x{}, {} bytes)",
        info.html.display(),
        info.planes.len(),
        info.width,
        info.height,
        info.bytes
    );
    Ok(0)
}
