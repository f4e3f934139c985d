//! The output submodel: OpenEXR with named layers, ENVI BSQ cubes with
//! `.hdr` headers, PNG quicklooks. Every file is written atomically: into a
//! temporary file in the destination folder, flushed, then renamed over the
//! destination, so an interrupted run never leaves a half-written file that
//! looks complete.

pub mod bench;
pub mod envi;
pub mod exr;
pub mod frame;
pub mod quicklook;
pub mod sequence;

use std::io::Write;
use std::path::{Path, PathBuf};

pub use crate::render::planes::{Plane, PlaneStats, Planes, plane_stats};

/// Errors while writing outputs.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: cannot encode: {msg}")]
    Encode { path: PathBuf, msg: String },
}

/// Writes `path` atomically: `fill` writes into a temporary file in the same
/// folder, which is synced and renamed over `path` only if `fill` succeeds.
pub fn write_atomic<F>(path: &Path, fill: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut std::io::BufWriter<&mut std::fs::File>) -> Result<(), String>,
{
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".irsig-partial-")
        .tempfile_in(&dir)
        .map_err(io)?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut w).map_err(|msg| OutputError::Encode {
            path: path.to_path_buf(),
            msg,
        })?;
        w.flush().map_err(io)?;
    }
    // tempfile creates 0600 files; outputs are ordinary files (0644).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))
            .map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}
