//! `irsig crosscheck <scene.toml | mesh.obj>`: traces primary, specular and
//! solar-history rays with Embree and obvhs and reports the differences
//! ([`crate::bench::crosscheck_file`]).

use std::path::PathBuf;

use crate::bench::crosscheck_file::{MeshView, crosscheck_file};

#[derive(clap::Args, Debug)]
/// `irsig crosscheck`: both ray-tracing backends on the same rays.
pub struct Args {
    /// A scene file (.toml: its sensor camera and the sun directions of its
    /// shadow history are used) or an OBJ mesh (a camera is generated
    /// looking at it obliquely, with a summer day's sun arc).
    pub input: PathBuf,
    /// Image width of the generated camera (OBJ input), pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub width: u32,
    /// Image height of the generated camera (OBJ input), pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub height: u32,
    /// Number of solar-history directions (OBJ input: a summer day's arc).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(0..=96))]
    pub sun_samples: u32,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `irsig crosscheck`; returns the process exit code (non-zero when the backends disagree).
pub fn run(a: Args) -> anyhow::Result<i32> {
    let mesh = MeshView {
        width: a.width,
        height: a.height,
        sun_samples: a.sun_samples,
    };
    let report = crosscheck_file(&a.input, mesh)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.to_text());
    }
    Ok(if report.unexplained() == 0 { 0 } else { 2 })
}
