//! Slurm job scripts for a batch (`irsig batch slurm`): a job array with
//! one task per shard (`SLURM_ARRAY_TASK_ID` → shard, threads from
//! `SLURM_CPUS_PER_TASK`), and a merge job that runs after the whole array
//! has succeeded (`--dependency=afterok:<array job>`). Optionally submitted
//! with `sbatch`.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};

use super::Batch;

/// What the scripts ask Slurm for.
#[derive(Debug, Clone, Default)]
pub struct SlurmOptions {
    /// Number of array tasks (shards); None: the plan's.
    pub shards: Option<usize>,
    /// `--partition`.
    pub partition: Option<String>,
    /// `--time` per task (Slurm syntax, e.g. `01:00:00`).
    pub time: Option<String>,
    /// `--cpus-per-task` (default 1).
    pub cpus_per_task: Option<u32>,
    /// `--mem` per task (Slurm syntax, e.g. `4G`).
    pub mem: Option<String>,
    /// `--account`.
    pub account: Option<String>,
    /// Most array tasks running at once (`--array=0-N%max`).
    pub max_running: Option<usize>,
    /// The irsig binary the tasks run (default: this one).
    pub irsig: Option<PathBuf>,
}

/// The scripts written, and the job ids when submitted.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SlurmScripts {
    /// The array job's script (one task per shard).
    pub array_script: PathBuf,
    /// The merge job's script.
    pub merge_script: PathBuf,
    /// The script that submits both (the merge after the array).
    pub submit_script: PathBuf,
    /// Number of shards (array tasks).
    pub shards: usize,
    /// (array job id, merge job id) when submitted.
    pub jobs: Option<(String, String)>,
}

/// A value for an `#SBATCH` line: no spaces, quotes or newlines.
fn check_value(flag: &str, v: &str) -> anyhow::Result<()> {
    if v.is_empty()
        || v.chars()
            .any(|c| c.is_whitespace() || matches!(c, '"' | '\'' | '\\' | '$' | '`'))
    {
        bail!("--{flag} {v:?}: expected a Slurm value without spaces or quotes");
    }
    Ok(())
}

/// A path that goes into a generated script: no control characters (a
/// newline would end a line of the script and start a command; a folder
/// named `r7\ntouch /tmp/x #` did). `what` names it in the error.
fn check_path(what: &str, p: &Path) -> anyhow::Result<()> {
    let s = p.as_os_str().to_string_lossy();
    if s.chars().any(char::is_control) {
        bail!(
            "{what} {:?} holds a control character (newline, tab, escape…): the Slurm scripts \
             cannot name it safely; rename it",
            p.as_os_str()
        );
    }
    if std::str::from_utf8(p.as_os_str().as_encoded_bytes()).is_err() {
        bail!(
            "{what} {:?} is not valid UTF-8: the Slurm scripts cannot name it safely; rename it",
            p.as_os_str()
        );
    }
    Ok(())
}

/// A path for an `#SBATCH` line, which Slurm splits at white space and
/// does not unquote: white space and quotes are refused (with what to do),
/// `%` (Slurm's filename patterns) doubled.
fn sbatch_path(what: &str, p: &Path) -> anyhow::Result<String> {
    let s = p.display().to_string();
    if s.chars()
        .any(|c| c.is_whitespace() || matches!(c, '"' | '\'' | '\\' | '#'))
    {
        bail!(
            "{what} {s:?} holds white space, a quote, `\\` or `#`, which an `#SBATCH --output` \
             line cannot hold; give the batch a folder whose path has none"
        );
    }
    Ok(s.replace('%', "%%"))
}

/// Quotes a path for a POSIX shell.
fn sh_quote(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', r"'\''"))
}

/// Writes `slurm/array.sh`, `slurm/merge.sh` and `slurm/submit.sh` into
/// the batch folder; with `submit`, runs `sbatch` for the array and the
/// dependent merge job and returns their ids.
pub fn slurm(dir: &Path, o: &SlurmOptions, submit: bool) -> anyhow::Result<SlurmScripts> {
    let batch = Batch::open(dir)?;
    let dir =
        std::path::absolute(dir).with_context(|| format!("cannot resolve {}", dir.display()))?;
    let n = o.shards.unwrap_or(batch.info.shards).max(1);
    if n > batch.frames.len().max(1) {
        bail!(
            "--shards {n}: the batch has only {} frames",
            batch.frames.len()
        );
    }
    for (flag, v) in [
        ("partition", &o.partition),
        ("time", &o.time),
        ("mem", &o.mem),
        ("account", &o.account),
    ] {
        if let Some(v) = v {
            check_value(flag, v)?;
        }
    }
    let cpus = o.cpus_per_task.unwrap_or(1).max(1);
    let irsig = match &o.irsig {
        Some(p) => std::path::absolute(p)?,
        None => std::env::current_exe().context("cannot find the irsig binary")?,
    };
    check_path("the batch folder", &dir)?;
    check_path("the irsig binary", &irsig)?;
    let sdir = dir.join("slurm");
    let logs = sbatch_path("the batch folder", &sdir.join("logs"))?;
    std::fs::create_dir_all(sdir.join("logs"))
        .with_context(|| format!("cannot create {}", sdir.display()))?;
    let name: String = batch
        .info
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .take(40)
        .collect();
    let mut common = String::new();
    for (flag, v) in [
        ("partition", &o.partition),
        ("account", &o.account),
        ("mem", &o.mem),
    ] {
        if let Some(v) = v {
            common += &format!("#SBATCH --{flag}={v}\n");
        }
    }
    let array = format!(
        "#!/bin/bash\n\
         # irsig batch {name}: one Slurm array task per shard ({n} shards, {frames} frames).\n\
         # Written by `irsig batch slurm`; submit with submit.sh (array + merge).\n\
         #SBATCH --job-name=irsig-{name}\n\
         #SBATCH --array=0-{last}{max}\n\
         #SBATCH --cpus-per-task={cpus}\n\
         {time}{common}\
         #SBATCH --output={logs}/shard-%a.out\n\
         set -euo pipefail\n\
         exec {irsig} batch run {dir} --shard \"${{SLURM_ARRAY_TASK_ID}}/{n}\" --threads \"${{SLURM_CPUS_PER_TASK:-{cpus}}}\"\n",
        frames = batch.frames.len(),
        last = n - 1,
        max = o.max_running.map_or(String::new(), |m| format!("%{m}")),
        time = o
            .time
            .as_ref()
            .map_or(String::new(), |t| format!("#SBATCH --time={t}\n")),
        irsig = sh_quote(&irsig),
        dir = sh_quote(&dir),
    );
    let merge = format!(
        "#!/bin/bash\n\
         # irsig batch {name}: merges the frames once every array task has succeeded.\n\
         #SBATCH --job-name=irsig-{name}-merge\n\
         #SBATCH --cpus-per-task=1\n\
         {common}\
         #SBATCH --output={logs}/merge.out\n\
         set -euo pipefail\n\
         exec {irsig} batch merge {dir}\n",
        irsig = sh_quote(&irsig),
        dir = sh_quote(&dir),
    );
    let submit_sh = format!(
        "#!/bin/bash\n\
         # Submits the array, then the merge job to run after it (afterok).\n\
         set -euo pipefail\n\
         cd {sdir}\n\
         array=$(sbatch --parsable array.sh)\n\
         array=${{array%%;*}}\n\
         merge=$(sbatch --parsable --dependency=afterok:\"$array\" merge.sh)\n\
         echo \"array job $array, merge job ${{merge%%;*}}\"\n",
        sdir = sh_quote(&sdir),
    );
    let paths = (
        sdir.join("array.sh"),
        sdir.join("merge.sh"),
        sdir.join("submit.sh"),
    );
    crate::output::write_text(&paths.0, &array)?;
    crate::output::write_text(&paths.1, &merge)?;
    crate::output::write_text(&paths.2, &submit_sh)?;
    let mut jobs = None;
    if submit {
        let sbatch = |args: &[&str]| -> anyhow::Result<String> {
            let out = Command::new("sbatch")
                .args(args)
                .current_dir(&sdir)
                .output()
                .context("cannot run sbatch (is Slurm installed and on PATH?)")?;
            if !out.status.success() {
                bail!(
                    "sbatch {}: {}",
                    args.join(" "),
                    String::from_utf8_lossy(&out.stderr).trim()
                );
            }
            let id = String::from_utf8_lossy(&out.stdout).trim().to_string();
            Ok(id.split(';').next().unwrap_or("").to_string())
        };
        let a = sbatch(&["--parsable", "array.sh"])?;
        let m = sbatch(&[
            "--parsable",
            &format!("--dependency=afterok:{a}"),
            "merge.sh",
        ])?;
        jobs = Some((a, m));
    }
    Ok(SlurmScripts {
        array_script: paths.0,
        merge_script: paths.1,
        submit_script: paths.2,
        shards: n,
        jobs,
    })
}
