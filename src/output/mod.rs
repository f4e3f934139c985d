//! The output submodel: OpenEXR with named layers, ENVI BSQ cubes with
//! `.hdr` headers, PNG quicklooks. Every file is written as part of an
//! [`OutputSet`](set::OutputSet): into a temporary file in the destination
//! folder, flushed, then renamed over the destination together with the
//! other files of its result, the set's marker (e.g. the JSON summary)
//! last, so an interrupted run never leaves a half-written file or a mixed
//! set that looks complete.

pub mod envi;
pub mod exr;
pub mod exr_zip;
pub mod frame;
pub mod geotiff;
pub mod glyphs;
pub mod quicklook;
pub mod report;
pub mod sequence;
pub mod set;

pub use set::{OutputSet, write_atomic, write_text};

use std::path::PathBuf;

pub use crate::render::planes::{Plane, PlaneStats, Planes, plane_stats};

/// Errors while writing outputs.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The OS refused a write (full disk, permissions, file size limit).
    #[error("cannot write {}: {reason}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS's reason.
        reason: std::io::Error,
    },
    /// The encoder refused the data.
    #[error("cannot encode {}: {msg}", path.display())]
    Encode {
        /// The file.
        path: PathBuf,
        /// The encoder's message.
        msg: String,
    },
    /// The destination cannot take the output (not a folder, not writable).
    #[error("{}: {msg}", path.display())]
    Unusable {
        /// The destination.
        path: PathBuf,
        /// Why, and what was expected.
        msg: String,
    },
}

/// Checks, before any work is done, that files can be written in `dir`:
/// it is created if missing (with its parents), must be a folder, and must
/// accept a new file (a probe file is created there and removed).
pub fn check_output_dir(dir: &std::path::Path) -> Result<(), OutputError> {
    let dir = if dir.as_os_str().is_empty() {
        std::path::Path::new(".")
    } else {
        dir
    };
    let unusable = |msg: String| OutputError::Unusable {
        path: dir.to_path_buf(),
        msg,
    };
    // The folder, or the first of its parents that exists, must be a folder.
    if let Some(existing) = dir.ancestors().find(|a| a.exists())
        && !existing.is_dir()
    {
        return Err(OutputError::Unusable {
            path: existing.to_path_buf(),
            msg: "is not a folder (an output folder was expected)".into(),
        });
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| unusable(format!("cannot create the output folder: {e}")))?;
    tempfile::Builder::new()
        .prefix(".irsig-probe-")
        .tempfile_in(dir)
        .map_err(|e| unusable(format!("cannot write in the output folder: {e}")))?;
    Ok(())
}

/// Checks, before any work is done, that an output file can be written at
/// `path`: it is not a folder, and its folder exists or can be created and
/// is writable (see [`check_output_dir`]).
pub fn check_output_file(path: &std::path::Path) -> Result<(), OutputError> {
    if path.is_dir() {
        return Err(OutputError::Unusable {
            path: path.to_path_buf(),
            msg: "is a folder (an output file path was expected, e.g. out/x.exr)".into(),
        });
    }
    check_output_dir(path.parent().unwrap_or(std::path::Path::new(".")))
}
