//! Rendering a batch's frames on this machine (`irsig batch run`): all of
//! them, or one shard (a Slurm array task). Finished frames are skipped, so
//! a re-run after a crash or pre-emption resumes where it stopped; a frame
//! that fails is recorded under `failed/` and the others go on.
//!
//! Each frame is claimed with an exclusive advisory lock (`flock`, std's
//! [`std::fs::File::try_lock`]) on `locks/<frame id>.lock` before it is
//! rendered, and held until its files are written; a runner that finds a
//! frame locked goes on to the next. So any number of runners on one
//! folder (several `batch run`s without `--shard`, or overlapping shards)
//! share the frames without rendering one twice: dynamic load balancing.
//! A runner killed mid-frame releases its lock with its process.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use chrono::NaiveDateTime;

use super::plan::LOCAL_FORMAT;
use super::{Batch, FrameJob, shard_range};
use crate::render::{ProgressFn, Static, derive_static, render_at, thread_pool};
use crate::scene::spec::TimeSpec;

/// What [`run`] renders.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// The batch folder.
    pub dir: PathBuf,
    /// Shard `i` of `n`; `None`: every frame.
    pub shard: Option<(usize, usize)>,
    /// Worker threads (None: all cores).
    pub threads: Option<u32>,
}

/// What happened to one frame.
#[derive(Debug, Clone)]
pub enum RunEvent {
    /// Already complete: skipped.
    Skipped {
        /// The frame's id.
        id: String,
    },
    /// Rendered and written in `seconds`.
    Done {
        /// The frame's id.
        id: String,
        /// Wall time of the render and the writes, s.
        seconds: f64,
    },
    /// Failed with this error (recorded under `failed/`).
    Failed {
        /// The frame's id.
        id: String,
        /// The error, as recorded.
        error: String,
    },
    /// Being rendered by another runner (its lock is held): skipped.
    Busy {
        /// The frame's id.
        id: String,
    },
}

/// [`run`]'s counts.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct RunReport {
    /// Frames of the shard.
    pub frames: usize,
    /// Frames rendered now.
    pub rendered: usize,
    /// Frames already complete.
    pub skipped: usize,
    /// Frames another runner held the lock of (rendering them).
    pub busy: usize,
    /// (frame id, error)
    pub failed: Vec<(String, String)>,
}

/// Renders the frames of a shard (or all) that are not complete, one after
/// another, each in parallel inside; consecutive frames with the same
/// scene and overrides share the static part, and [`derive_static`] shares
/// geometry, BVH and tables whenever the overrides leave them unchanged.
/// Errors of single frames are recorded, not returned; the result is an
/// error only when the batch itself cannot be read or written.
pub fn run(o: &RunOptions, event: &mut dyn FnMut(&RunEvent)) -> anyhow::Result<RunReport> {
    let batch = Batch::open(&o.dir)?;
    let range = match o.shard {
        Some((i, n)) => shard_range(i, n, batch.frames.len()),
        None => 0..batch.frames.len(),
    };
    let pool = thread_pool(o.threads)?;
    let mut rep = RunReport {
        frames: range.len(),
        ..Default::default()
    };
    let mut st: Option<Static> = None;
    let mut st_key: Option<(PathBuf, Vec<(String, String)>)> = None;
    for f in &batch.frames[range] {
        if batch.is_done(f) {
            rep.skipped += 1;
            event(&RunEvent::Skipped { id: f.id.clone() });
            continue;
        }
        let Some(_claim) = claim(&batch.dir, f)? else {
            rep.busy += 1;
            event(&RunEvent::Busy { id: f.id.clone() });
            continue;
        };
        // Another runner may have finished it between the check and the lock.
        if batch.is_done(f) {
            rep.skipped += 1;
            event(&RunEvent::Skipped { id: f.id.clone() });
            continue;
        }
        let t0 = Instant::now();
        let r = pool.install(|| {
            render_frame(
                &batch.dir,
                f,
                batch.info.quicklook(),
                &mut st,
                &mut st_key,
                None,
            )
        });
        let fail = batch.failure_path(f);
        match r {
            Ok(()) => {
                if fail.exists() {
                    std::fs::remove_file(&fail)
                        .with_context(|| format!("cannot remove {}", fail.display()))?;
                }
                rep.rendered += 1;
                event(&RunEvent::Done {
                    id: f.id.clone(),
                    seconds: t0.elapsed().as_secs_f64(),
                });
            }
            Err(e) => {
                let error = format!("{e:#}");
                std::fs::create_dir_all(batch.dir.join("failed"))
                    .with_context(|| format!("cannot create {}/failed", batch.dir.display()))?;
                crate::output::write_text(&fail, &(error.clone() + "\n"))?;
                // A failed scene load leaves no usable static part.
                st = None;
                st_key = None;
                event(&RunEvent::Failed {
                    id: f.id.clone(),
                    error: error.clone(),
                });
                rep.failed.push((f.id.clone(), error));
            }
        }
    }
    Ok(rep)
}

/// Claims frame `f`: its lock file `locks/<id>.lock`, locked exclusively
/// without waiting. `None` when another runner holds it. The lock goes
/// with the returned file (dropped after the frame is written). The lock
/// files stay (empty); removing one could let two runners lock two
/// different files of the same name.
fn claim(dir: &Path, f: &FrameJob) -> anyhow::Result<Option<std::fs::File>> {
    let locks = dir.join("locks");
    std::fs::create_dir_all(&locks)
        .with_context(|| format!("cannot create {}", locks.display()))?;
    let p = locks.join(format!("{}.lock", f.id));
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&p)
        .with_context(|| format!("cannot open the frame lock {}", p.display()))?;
    match file.try_lock() {
        Ok(()) => Ok(Some(file)),
        Err(std::fs::TryLockError::WouldBlock) => Ok(None),
        Err(std::fs::TryLockError::Error(e)) => {
            Err(e).with_context(|| format!("cannot lock {}", p.display()))
        }
    }
}

/// Renders one frame and writes its files (EXR, PNG, then the JSON that
/// marks it complete), its quicklook drawn as `batch_quicklook` says,
/// reusing `st` when the scene and overrides are those
/// of `st_key`.
fn render_frame(
    dir: &Path,
    f: &FrameJob,
    batch_quicklook: crate::output::frame::QuicklookOptions,
    st: &mut Option<Static>,
    st_key: &mut Option<(PathBuf, Vec<(String, String)>)>,
    progress: ProgressFn,
) -> anyhow::Result<()> {
    let key = (f.scene.clone(), f.overrides.clone());
    if st_key.as_ref() != Some(&key) {
        let scene = crate::scene::load_with_overrides(&f.scene, &f.overrides)?;
        let (s, _) = derive_static(st.as_ref(), scene, None)?;
        *st = Some(s);
        *st_key = Some(key);
    }
    let s = st.as_ref().expect("set above");
    let sc = &s.scene.scene;
    let local = match &f.local_time {
        Some(t) => NaiveDateTime::parse_from_str(t, LOCAL_FORMAT)
            .with_context(|| format!("frame {}: local time {t:?}", f.id))?,
        None => sc.time.local,
    };
    let utc = TimeSpec { local }.utc(&sc.site);
    let img = render_at(s, utc, progress)?;
    let info = serde_json::json!({
        "id": f.id,
        "index": f.index,
        "local_time": local.format(LOCAL_FORMAT).to_string(),
        "labels": f.labels,
        "overrides": f.overrides,
    });
    crate::output::frame::write_rendered(
        &dir.join(&f.outputs.exr),
        &img,
        crate::output::frame::Formats {
            exr: true,
            quicklook: batch_quicklook,
            ..Default::default()
        },
        Some(info),
    )
}
