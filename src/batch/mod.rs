//! Batches: many frames (time sequences, sweeps, several scenes, random
//! draws for training data) planned once into a manifest and rendered by
//! any number of independent workers — this machine, or the tasks of a
//! Slurm job array — then merged into one result set.
//!
//! A batch folder holds:
//! - `batch.json`: the [`Plan`] without its frames (name, spec, default
//!   shard count, varied dimensions) and the number of frames;
//! - `manifest.jsonl`: one [`FrameJob`] per line (id, scene, overrides,
//!   local time, labels, output paths);
//! - `frames/<id>.{exr,png,json}`: each frame's outputs; the JSON is
//!   written last, so a frame is complete exactly when its JSON exists
//!   ([`is_done`]); every file is written under a temporary name and
//!   renamed, so a killed worker never leaves a half-written frame;
//! - `failed/<id>.txt`: the error of a frame that failed (removed when the
//!   frame later succeeds);
//! - `slurm/`: the job scripts [`slurm`] writes; `merged/`: [`merge`]'s
//!   result set.
//!
//! Shard `i` of `n` is the `i`-th of `n` contiguous blocks of the manifest
//! ([`shard_range`]); the manifest is scene-major, so a shard holds as few
//! scenes as possible, and consecutive frames of one scene and overrides
//! share the static work (geometry, BVH, tables) within a worker.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};

pub mod merge;
pub mod plan;
pub mod run;
pub mod slurm;
pub mod spec;

pub use merge::{MergeReport, merge};
pub use plan::{FrameJob, Outputs, Plan, plan};
pub use run::{RunEvent, RunOptions, RunReport, run};
pub use slurm::{SlurmOptions, SlurmScripts, slurm};

/// `batch.json`: what the batch is, without its frames.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BatchInfo {
    /// Format marker.
    pub format: String,
    /// The batch's name.
    pub name: String,
    /// The spec it was planned from.
    pub spec: PathBuf,
    /// The default shard count.
    pub shards: usize,
    /// The label keys that vary across frames.
    pub dimensions: Vec<String>,
    /// The product's axes (see [`Plan::axes`]); empty in a batch planned
    /// before they were recorded (its stack is then flat over `frame`).
    #[serde(default)]
    pub axes: Vec<String>,
    /// Number of frames.
    pub frames: usize,
    /// irsig's version that planned it.
    pub irsig_version: String,
    /// The spec's `colormap` (absent: grey).
    #[serde(default)]
    pub colormap: crate::output::quicklook::Colormap,
    /// The spec's `quicklook_min_span_k` (absent: 2 K).
    #[serde(default = "two_k")]
    pub quicklook_min_span_k: f64,
}

fn two_k() -> f64 {
    crate::output::frame::QuicklookOptions::default().min_span_k
}

impl BatchInfo {
    /// How the frames' quicklooks and the contact sheet are drawn.
    pub fn quicklook(&self) -> crate::output::frame::QuicklookOptions {
        crate::output::frame::QuicklookOptions {
            colormap: self.colormap,
            min_span_k: self.quicklook_min_span_k,
        }
    }
}

/// The value of [`BatchInfo::format`].
pub const FORMAT: &str = "irsig-batch-1";

/// The manifest's text: one JSON object per line.
fn manifest_text(frames: &[FrameJob]) -> anyhow::Result<String> {
    let mut s = String::new();
    for f in frames {
        s.push_str(&serde_json::to_string(f)?);
        s.push('\n');
    }
    Ok(s)
}

/// Writes a plan into `dir` (created if missing): `batch.json` and
/// `manifest.jsonl`. A folder that already holds the same batch is left as
/// it is (its finished frames stay valid); one that holds another batch is
/// an error.
pub fn write_plan(dir: &Path, p: &Plan) -> anyhow::Result<BatchInfo> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let info = BatchInfo {
        format: FORMAT.into(),
        name: p.name.clone(),
        spec: p.spec.clone(),
        shards: p.shards,
        dimensions: p.dimensions.clone(),
        axes: p.axes.clone(),
        frames: p.frames.len(),
        irsig_version: env!("CARGO_PKG_VERSION").into(),
        colormap: p.quicklook.colormap,
        quicklook_min_span_k: p.quicklook.min_span_k,
    };
    let manifest = manifest_text(&p.frames)?;
    let mpath = dir.join("manifest.jsonl");
    if mpath.exists() {
        let old = std::fs::read_to_string(&mpath)
            .with_context(|| format!("cannot read {}", mpath.display()))?;
        if old != manifest {
            bail!(
                "{} already holds another batch's manifest: choose another output folder, \
                 or remove it to plan anew",
                dir.display()
            );
        }
    }
    crate::output::write_text(&mpath, &manifest)?;
    crate::output::write_text(
        &dir.join("batch.json"),
        &(serde_json::to_string_pretty(&info)? + "\n"),
    )?;
    Ok(info)
}

/// A batch folder read back: its info and frames.
pub struct Batch {
    /// The batch folder.
    pub dir: PathBuf,
    /// Its `batch.json`.
    pub info: BatchInfo,
    /// Its frames (manifest order).
    pub frames: Vec<FrameJob>,
}

impl Batch {
    /// Reads `dir/batch.json` and `dir/manifest.jsonl`; errors name the
    /// file and line.
    pub fn open(dir: &Path) -> anyhow::Result<Batch> {
        let ipath = dir.join("batch.json");
        let text = std::fs::read_to_string(&ipath).with_context(|| {
            format!(
                "cannot read {} (is {} a batch folder made by `irsig batch plan`?)",
                ipath.display(),
                dir.display()
            )
        })?;
        let info: BatchInfo = serde_json::from_str(&text)
            .with_context(|| format!("{}: not an irsig batch.json", ipath.display()))?;
        if info.format != FORMAT {
            bail!(
                "{}: format {:?}, expected {FORMAT:?}",
                ipath.display(),
                info.format
            );
        }
        let mpath = dir.join("manifest.jsonl");
        let text = std::fs::read_to_string(&mpath)
            .with_context(|| format!("cannot read {}", mpath.display()))?;
        let frames = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
            .map(|(i, l)| {
                serde_json::from_str::<FrameJob>(l).with_context(|| {
                    format!("{}:{}: not a frame of the manifest", mpath.display(), i + 1)
                })
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        if frames.len() != info.frames {
            bail!(
                "{}: {} frames, but batch.json says {}",
                mpath.display(),
                frames.len(),
                info.frames
            );
        }
        Ok(Batch {
            dir: dir.to_path_buf(),
            info,
            frames,
        })
    }

    /// Whether frame `f`'s outputs are complete.
    pub fn is_done(&self, f: &FrameJob) -> bool {
        is_done(&self.dir, f)
    }

    /// Where frame `f`'s failure is recorded.
    pub fn failure_path(&self, f: &FrameJob) -> PathBuf {
        self.dir.join("failed").join(format!("{}.txt", f.id))
    }

    /// The frames' completion: done, failed (with the error), missing.
    pub fn status(&self) -> Status {
        let mut s = Status {
            total: self.frames.len(),
            done: 0,
            failed: Vec::new(),
            missing: Vec::new(),
        };
        for f in &self.frames {
            if self.is_done(f) {
                s.done += 1;
            } else if let Ok(e) = std::fs::read_to_string(self.failure_path(f)) {
                s.failed.push((f.id.clone(), e.trim().to_string()));
            } else {
                s.missing.push(f.id.clone());
            }
        }
        s
    }
}

/// Whether frame `f` of the batch in `dir` is complete: its JSON (written
/// last, atomically) and its EXR exist.
pub fn is_done(dir: &Path, f: &FrameJob) -> bool {
    dir.join(&f.outputs.json).is_file() && dir.join(&f.outputs.exr).is_file()
}

/// How far a batch is.
#[derive(Debug, Clone, Serialize)]
pub struct Status {
    /// Frames in the batch.
    pub total: usize,
    /// Frames complete.
    pub done: usize,
    /// (frame id, error)
    pub failed: Vec<(String, String)>,
    /// Frames neither complete nor failed.
    pub missing: Vec<String>,
}

/// Parses `i/n` (0 ≤ i < n): shard `i` of `n`.
pub fn parse_shard(s: &str) -> anyhow::Result<(usize, usize)> {
    let err = || anyhow::anyhow!("shard {s:?}: expected I/N with 0 <= I < N, e.g. 0/4");
    let (i, n) = s.split_once('/').ok_or_else(err)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| err())?,
        n.trim().parse().map_err(|_| err())?,
    );
    if n == 0 || i >= n {
        return Err(err());
    }
    Ok((i, n))
}

/// The frames of shard `i` of `n` among `total`: the `i`-th of `n`
/// contiguous blocks whose sizes differ by at most one.
pub fn shard_range(i: usize, n: usize, total: usize) -> std::ops::Range<usize> {
    (i * total / n)..((i + 1) * total / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_cover_every_frame_once() {
        for total in [0, 1, 5, 6, 7, 100] {
            for n in 1..=8 {
                let mut seen = vec![0; total];
                for i in 0..n {
                    let r = shard_range(i, n, total);
                    assert!(r.len() <= total.div_ceil(n) && r.len() + 1 >= total / n);
                    r.for_each(|k| seen[k] += 1);
                }
                assert!(seen.iter().all(|&c| c == 1), "{total} {n}");
            }
        }
        assert_eq!(parse_shard("2/3").unwrap(), (2, 3));
        for bad in ["3/3", "1", "a/2", "0/0", "-1/2"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
    }
}
