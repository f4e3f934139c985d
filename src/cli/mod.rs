//! Command-line interface: argument parsing and the subcommands. `main.rs`
//! only calls [`run`] and maps its error to an exit code.

use clap::{Parser, Subcommand};

pub mod atmos;
pub mod crosscheck;

/// irsig — physics-based thermal-infrared synthetic image generator.
#[derive(Parser, Debug)]
#[command(name = "irsig", version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Trace primary, specular-bounce and solar-history rays with both
    /// backends (Embree and obvhs) and compare their hits.
    Crosscheck(crosscheck::Args),
    /// Atmosphere tables: list them, show what a geometry uses.
    Atmos(atmos::Args),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<i32> {
    match cli.command {
        Command::Crosscheck(a) => crosscheck::run(a),
        Command::Atmos(a) => atmos::run(a),
    }
}
