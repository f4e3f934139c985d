//! Command-line interface: argument parsing and the subcommands. `main.rs`
//! only calls [`run`] and maps its error to an exit code.

use clap::{Parser, Subcommand};

pub mod atmos;
pub mod batch;
pub mod bench;
pub mod check;
pub mod crosscheck;
pub mod log;
pub mod probe;
pub mod render;
pub mod report;
pub mod sequence;
pub mod sun;
pub mod therm;

pub use log::{warn_about_frame, warn_or_refuse};

/// irsig — physics-based thermal-infrared synthetic image generator.
#[derive(Parser, Debug)]
#[command(name = "irsig", version = crate::version::LONG_VERSION, about)]
pub struct Cli {
    /// No notes or progress on stderr (errors only).
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// More detail on stderr.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    pub verbose: u8,
    #[command(subcommand)]
    /// The subcommand to run.
    pub command: Command,
}

#[derive(Subcommand, Debug)]
#[allow(clippy::large_enum_variant)]
/// The `irsig` subcommands.
pub enum Command {
    /// Trace primary, specular-bounce and solar-history rays with both
    /// backends (Embree and obvhs) and compare their hits.
    Crosscheck(crosscheck::Args),
    /// Benchmarks: ray throughput, stage times against the ray floor, run
    /// time against error.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Batches over scenes, times, sweeps and random draws: plan a
    /// manifest, run shards here or as a Slurm job array, merge.
    #[command(subcommand)]
    Batch(batch::BatchCommand),
    /// Load and validate a scene; print a summary (objects, facets,
    /// materials, bounds, sensor footprint, what the render will need).
    Check(check::Args),
    /// Render a scene: EXR with every plane, PNG quicklook, JSON summary
    /// (and ENVI with --envi).
    Render(render::Args),
    /// Everything about one output pixel: hit, angles, sun/shadow history,
    /// temperature and flux terms, specular bounce, every radiometric term.
    Probe(probe::Args),
    /// Render one frame per local clock time (e.g. --from 08:00 --to 15:00
    /// --step 1h) plus a contact sheet under one stretch and index.json.
    Sequence(sequence::SequenceArgs),
    /// Render one frame per value of a scene key (e.g. --key
    /// weather.constant.wind_m_s --values 0,4.47,8.94,13.41) plus a contact
    /// sheet under one stretch and index.json.
    Sweep(sequence::SweepArgs),
    /// Solar position (NREL SPA) for a site and a UTC instant.
    Sun(sun::Args),
    /// Surface temperature and flux terms of one material and facet over
    /// time (THERM-style slab, docs/models.md).
    Therm(therm::Args),
    /// Atmosphere tables: list them, show what a geometry uses.
    Atmos(atmos::Args),
    /// Write a self-contained HTML page of a render (x.json): each plane
    /// with a colour bar, hover read-out and histogram, the material table,
    /// sun, sensor and atmosphere.
    Report(report::Args),
    /// Print a shell completion script (e.g. `irsig completions bash >
    /// ~/.local/share/bash-completion/completions/irsig`).
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the manual page (roff), e.g. `irsig man > irsig.1; man ./irsig.1`.
    Man,
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<i32> {
    log::set_level(cli.quiet, cli.verbose);
    match cli.command {
        Command::Crosscheck(a) => crosscheck::run(a),
        Command::Bench(c) => bench::run(c),
        Command::Batch(c) => batch::run(c),
        Command::Check(a) => check::run(a),
        Command::Render(a) => render::run(a),
        Command::Probe(a) => probe::run(a),
        Command::Sequence(a) => sequence::run_sequence(a),
        Command::Sweep(a) => sequence::run_sweep(a),
        Command::Sun(a) => sun::run(a),
        Command::Therm(a) => therm::run(a),
        Command::Atmos(a) => atmos::run(a),
        Command::Report(a) => report::run(a),
        Command::Completions { shell } => {
            let mut cmd = <Cli as clap::CommandFactory>::command();
            clap_complete::generate(shell, &mut cmd, "irsig", &mut std::io::stdout());
            Ok(0)
        }
        Command::Man => {
            let cmd = <Cli as clap::CommandFactory>::command();
            clap_mangen::Man::new(cmd).render(&mut std::io::stdout())?;
            Ok(0)
        }
    }
}
