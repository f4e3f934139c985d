//! `irsig bench rays|speed|accuracy`: flags → [`crate::bench`]'s
//! calls → tables on stdout (or JSON) and, for `accuracy`, files written by
//! [`crate::bench::report`].

use std::path::PathBuf;

use super::render::parse_overrides;
use crate::bench::{self, AccuracyOptions, RaysOptions, SpeedOptions};

#[derive(clap::Subcommand, Debug)]
/// The `irsig bench` subcommands.
pub enum BenchCommand {
    /// Mrays/s for primary and shadow rays, per backend and query mode.
    Rays(RaysArgs),
    /// Run time against error for each knob (thermal step, shadow sampling,
    /// spectral step, supersampling, spin-up) against a converged reference.
    Accuracy(AccuracyArgs),
    /// Render stage times, Mrays/s and the ratio to the pure-Embree ray
    /// floor, peak memory, over image sizes and facet counts.
    Speed(SpeedArgs),
}

#[derive(clap::Args, Debug)]
/// `irsig bench speed`.
pub struct SpeedArgs {
    /// The scene file.
    pub scene: std::path::PathBuf,
    /// Image sizes (square), pixels.
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024,2048")]
    pub sizes: Vec<u32>,
    /// Facet multipliers: each triangle split into n² (1, 9 ≈ 10x, 100).
    #[arg(long, value_delimiter = ',', default_value = "1,3,10")]
    pub subdivide: Vec<u32>,
    /// Image size used for the facet-count rows.
    #[arg(long, default_value_t = 512)]
    pub facet_size: u32,
    /// Override scene keys (as `irsig render --set`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<u32>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(clap::Args, Debug)]
/// `irsig bench rays`.
pub struct RaysArgs {
    /// Image width and height, pixels.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub size: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<u32>,
    /// Timed repetitions per row (the best is reported).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub repeat: u32,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

#[derive(clap::Args, Debug)]
/// `irsig bench accuracy`.
pub struct AccuracyArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Output image size (square), pixels.
    #[arg(long, default_value_t = 128)]
    pub size: u32,
    /// Folder for accuracy.csv, accuracy.json and accuracy.svg.
    #[arg(short, long, default_value = "out/bench-accuracy")]
    pub output: PathBuf,
    /// Override scene keys (as `irsig render --set`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<u32>,
    /// Run only these knobs' ladders (repeatable; e.g. `history_hours`);
    /// default: all of them.
    #[arg(long = "knob", value_name = "NAME")]
    pub knobs: Vec<String>,
    /// Keep the knobs not named by `--knob` at irsig's defaults in the
    /// reference and the ladders (a cheaper reference for one knob, e.g.
    /// supersampling at full image size).
    #[arg(long, requires = "knobs")]
    pub others_at_default: bool,
    /// Only the reference and the default set (checks a default set
    /// against the converged reference without the ladders).
    #[arg(long, conflicts_with_all = ["knobs", "others_at_default"])]
    pub no_ladders: bool,
    /// Replace the ladder of the one knob named by `--knob` with these
    /// values (e.g. `--ladder 60,30,20` for a cheaper run at full size).
    #[arg(long, value_delimiter = ',', value_name = "VALUES")]
    pub ladder: Vec<f64>,
    /// A candidate set: the defaults with these render keys changed (e.g.
    /// `render.shadow_interval_min=60`, repeatable); adds a `candidate` row.
    #[arg(long, value_name = "KEY=VALUE")]
    pub candidate: Vec<String>,
    /// A further candidate set, its render keys separated by commas (e.g.
    /// `render.supersample=8,render.shadow_interval_min=60`); repeatable,
    /// one row (`also1`, `also2`, …) each.
    #[arg(long, value_name = "KEY=VALUE,...")]
    pub also: Vec<String>,
    /// Change the converged reference's render keys (e.g.
    /// `render.supersample=16`, repeatable).
    #[arg(long, value_name = "KEY=VALUE")]
    pub reference: Vec<String>,
}

/// Runs `irsig bench`; returns the process exit code.
pub fn run(cmd: BenchCommand) -> anyhow::Result<i32> {
    match cmd {
        BenchCommand::Rays(a) => rays(a),
        BenchCommand::Speed(a) => speed(a),
        BenchCommand::Accuracy(a) => accuracy(a),
    }
}

fn rays(a: RaysArgs) -> anyhow::Result<i32> {
    let r = bench::rays(&RaysOptions {
        size: a.size,
        threads: a.threads,
        repeat: a.repeat,
    })?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&r.rows)?);
        return Ok(0);
    }
    println!(
        "bench rays: {} triangles, {}x{} px, {} threads, Embree {}, best of {}",
        r.triangles, r.size, r.size, r.threads, r.embree_version, r.repeat
    );
    println!("| workload | backend | mode | rays | best ms | Mrays/s |\n|---|---|---|---|---|---|");
    for r in &r.rows {
        println!(
            "| {} | {} | {} | {} | {:.1} | {:.1} |",
            r.workload,
            r.backend,
            r.mode,
            r.rays,
            r.best_s * 1e3,
            r.mrays_per_s
        );
    }
    Ok(0)
}

fn speed(a: SpeedArgs) -> anyhow::Result<i32> {
    let opts = SpeedOptions {
        scene: a.scene,
        sizes: a.sizes,
        subdivide: a.subdivide,
        facet_size: a.facet_size,
        overrides: parse_overrides(&a.set)?,
        threads: a.threads,
    };
    let rows = bench::speed(&opts, &mut |r| {
        if !a.json {
            eprintln!(
                "bench speed: {}² px, {} triangles: {:.2} s",
                r.size, r.triangles, r.total_s
            );
        }
    })?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(0);
    }
    println!(
        "| px | triangles | load+BVH s | weather+sun s | trace s | thermal s | radiometry s | sensor s | total s | write s | total+write s | Mrays/s (trace) | Embree floor s | render/floor | solves | peak MiB |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {0}² | {1} | {2:.2} | {3:.2} | {4:.2} | {5:.2} | {6:.2} | {7:.2} | {8:.2} | {14:.2} | {15:.2} | {9:.1} | {10:.3} | {11:.0}x | {12} | {13:.0} |",
            r.size,
            r.triangles,
            r.load_bvh_s,
            r.conditions_s,
            r.trace_s,
            r.thermal_s,
            r.radiometry_s,
            r.sensor_s,
            r.total_s,
            r.mrays_per_s,
            r.embree_floor_s,
            r.ratio_to_floor,
            r.thermal_solves,
            r.peak_rss_mib,
            r.output_s,
            r.total_with_output_s
        );
    }
    Ok(0)
}

fn accuracy(a: AccuracyArgs) -> anyhow::Result<i32> {
    if !a.ladder.is_empty() && a.knobs.len() != 1 {
        anyhow::bail!("--ladder needs exactly one --knob");
    }
    let opts = AccuracyOptions {
        scene: a.scene,
        size: a.size,
        overrides: parse_overrides(&a.set)?,
        threads: a.threads,
        knobs: a.knobs,
        others_at_default: a.others_at_default,
        no_ladders: a.no_ladders,
        ladder: a.ladder,
        candidate: parse_overrides(&a.candidate)?,
        also: (a.also.iter())
            .map(|set| {
                let pairs: Vec<String> = set.split(',').map(str::to_string).collect();
                parse_overrides(&pairs)
            })
            .collect::<Result<_, _>>()?,
        reference: parse_overrides(&a.reference)?,
    };
    let rows = bench::accuracy(&opts, &mut |what| eprintln!("bench accuracy: {what}"))?;
    crate::bench::report::write_accuracy(&a.output, &rows)?;
    print!("{}", bench::accuracy::to_csv(&rows));
    Ok(0)
}
