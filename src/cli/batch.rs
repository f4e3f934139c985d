//! `irsig batch plan|run|slurm|merge|status`: flags → [`crate::batch`]'s
//! calls → lines on stderr and a summary (or JSON) on stdout.

use std::path::PathBuf;

use crate::batch::{self, RunEvent, RunOptions, SlurmOptions};

#[derive(clap::Subcommand, Debug)]
/// The `irsig batch` subcommands.
pub enum BatchCommand {
    /// Expand a batch spec (TOML) into a manifest of frames and shards.
    Plan(PlanArgs),
    /// Render the frames of one shard (all by default) that are not done.
    Run(RunArgs),
    /// Write Slurm job-array scripts (one task per shard + a merge job);
    /// --submit submits them with sbatch.
    Slurm(SlurmArgs),
    /// Gather the finished frames into merged/: NetCDF stack, index.json,
    /// contact sheet.
    Merge(MergeArgs),
    /// Count done, failed and missing frames; print the failed frames'
    /// errors (exit 1 when any frame is failed or missing).
    Status(StatusArgs),
}

#[derive(clap::Args, Debug)]
/// `irsig batch plan`.
pub struct PlanArgs {
    /// The batch spec (see docs/batch.md).
    pub spec: PathBuf,
    /// The batch folder to create.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Print the plan as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(clap::Args, Debug)]
/// `irsig batch run`.
pub struct RunArgs {
    /// The batch folder.
    pub dir: PathBuf,
    /// Shard I/N (0 ≤ I < N): the I-th of N contiguous blocks of frames.
    #[arg(long, value_parser = batch::parse_shard)]
    pub shard: Option<(usize, usize)>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<u32>,
}

#[derive(clap::Args, Debug)]
/// `irsig batch slurm`.
pub struct SlurmArgs {
    /// The batch folder.
    pub dir: PathBuf,
    /// Array tasks (default: the spec's `shards`).
    #[arg(long)]
    pub shards: Option<usize>,
    #[arg(long)]
    /// Slurm partition (`sbatch --partition`; default: the cluster's).
    pub partition: Option<String>,
    /// Time limit per task (Slurm syntax, e.g. 01:00:00).
    #[arg(long)]
    pub time: Option<String>,
    #[arg(long, default_value_t = 1)]
    /// CPUs per array task (`sbatch --cpus-per-task`).
    pub cpus_per_task: u32,
    /// Memory per task (Slurm syntax, e.g. 4G).
    #[arg(long)]
    pub mem: Option<String>,
    #[arg(long)]
    /// Slurm account to charge (`sbatch --account`).
    pub account: Option<String>,
    /// Most tasks running at once.
    #[arg(long)]
    pub max_running: Option<usize>,
    /// Submit the array and the dependent merge job with sbatch.
    #[arg(long)]
    pub submit: bool,
}

#[derive(clap::Args, Debug)]
/// `irsig batch merge`.
pub struct MergeArgs {
    /// The batch folder.
    pub dir: PathBuf,
    /// Only these planes in the stack (comma-separated; default: all).
    #[arg(long, value_delimiter = ',')]
    pub planes: Vec<String>,
}

#[derive(clap::Args, Debug)]
/// `irsig batch status`.
pub struct StatusArgs {
    /// The batch folder.
    pub dir: PathBuf,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `irsig batch`; returns the process exit code.
pub fn run(cmd: BatchCommand) -> anyhow::Result<i32> {
    match cmd {
        BatchCommand::Plan(a) => {
            let p = batch::plan(&a.spec)?;
            let info = batch::write_plan(&a.output, &p)?;
            if a.json {
                println!("{}", serde_json::to_string_pretty(&info)?);
            } else {
                println!(
                    "batch {}: {} frames over {} ({} shards) in {}",
                    info.name,
                    info.frames,
                    info.dimensions.join(" x "),
                    info.shards,
                    a.output.display()
                );
            }
            Ok(0)
        }
        BatchCommand::Run(a) => {
            let o = RunOptions {
                dir: a.dir,
                shard: a.shard,
                threads: a.threads,
            };
            let rep = batch::run(&o, &mut |e| match e {
                RunEvent::Skipped { id } => eprintln!("batch run: {id}: done already"),
                RunEvent::Done { id, seconds } => {
                    eprintln!("batch run: {id}: rendered in {seconds:.2} s")
                }
                RunEvent::Failed { id, error } => eprintln!("batch run: {id}: FAILED: {error}"),
                RunEvent::Busy { id } => {
                    eprintln!("batch run: {id}: being rendered by another runner")
                }
            })?;
            println!(
                "batch run: {} frames: {} rendered, {} done already, {} failed{}",
                rep.frames,
                rep.rendered,
                rep.skipped,
                rep.failed.len(),
                if rep.busy > 0 {
                    format!(", {} taken by other runners", rep.busy)
                } else {
                    String::new()
                }
            );
            Ok(if rep.failed.is_empty() { 0 } else { 1 })
        }
        BatchCommand::Slurm(a) => {
            let o = SlurmOptions {
                shards: a.shards,
                partition: a.partition,
                time: a.time,
                cpus_per_task: Some(a.cpus_per_task),
                mem: a.mem,
                account: a.account,
                max_running: a.max_running,
                irsig: None,
            };
            let s = batch::slurm(&a.dir, &o, a.submit)?;
            println!(
                "batch slurm: {} array tasks: {}; merge: {}; submit with {}",
                s.shards,
                s.array_script.display(),
                s.merge_script.display(),
                s.submit_script.display()
            );
            if let Some((array, merge)) = &s.jobs {
                println!("submitted: array job {array}, merge job {merge} (afterok)");
            }
            Ok(0)
        }
        BatchCommand::Merge(a) => {
            let r = batch::merge(
                &a.dir,
                (!a.planes.is_empty()).then_some(a.planes.as_slice()),
            )?;
            println!(
                "batch merge: {} frames of {}x{} px, {} planes: {}, {}, {}",
                r.frames,
                r.width,
                r.height,
                r.planes.len(),
                r.stack.display(),
                r.index.display(),
                r.contact_sheet.display()
            );
            Ok(0)
        }
        BatchCommand::Status(a) => {
            let b = batch::Batch::open(&a.dir)?;
            let s = b.status();
            if a.json {
                println!("{}", serde_json::to_string_pretty(&s)?);
            } else {
                println!(
                    "batch {}: {} frames: {} done, {} failed, {} missing",
                    b.info.name,
                    s.total,
                    s.done,
                    s.failed.len(),
                    s.missing.len()
                );
                for (id, e) in &s.failed {
                    println!("failed {id}: {e}");
                }
            }
            Ok(if s.done == s.total { 0 } else { 1 })
        }
    }
}
