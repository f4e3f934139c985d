//! The output submodel: OpenEXR with named layers, ENVI BSQ cubes with
//! `.hdr` headers, PNG quicklooks. Every file is written as part of an
//! [`OutputSet`](set::OutputSet): into a temporary file in the destination
//! folder, flushed, then renamed over the destination together with the
//! other files of its result, the set's marker (e.g. the JSON summary)
//! last, so an interrupted run never leaves a half-written file or a mixed
//! set that looks complete.

pub mod bench;
pub mod envi;
pub mod exr;
pub mod frame;
pub mod quicklook;
pub mod sequence;
pub mod set;

pub use set::{OutputSet, write_atomic};

use std::path::PathBuf;

pub use crate::render::planes::{Plane, PlaneStats, Planes, plane_stats};

/// Errors while writing outputs.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The OS refused a write (full disk, permissions, file size limit).
    #[error("cannot write {}: {reason}", path.display())]
    Io {
        path: PathBuf,
        reason: std::io::Error,
    },
    #[error("cannot encode {}: {msg}", path.display())]
    Encode { path: PathBuf, msg: String },
}
