//! The output submodel: OpenEXR with named layers, ENVI BSQ cubes with
//! `.hdr` headers, PNG quicklooks. Every file is written atomically: into a
//! temporary file in the destination folder, flushed, then renamed over the
//! destination, so an interrupted run never leaves a half-written file that
//! looks complete.

pub mod envi;
pub mod exr;
pub mod frame;
pub mod quicklook;
pub mod sequence;

use std::io::Write;
use std::path::{Path, PathBuf};

/// One image plane (an "AOV"): name, unit, row-major f32 samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    pub name: String,
    pub unit: String,
    pub data: Vec<f32>,
}

/// A set of planes of the same size.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Planes {
    pub width: u32,
    pub height: u32,
    pub planes: Vec<Plane>,
}

impl Planes {
    pub fn new(width: u32, height: u32) -> Self {
        Planes {
            width,
            height,
            planes: Vec::new(),
        }
    }

    /// Adds a plane; `data.len()` must equal `width·height`.
    pub fn push(&mut self, name: &str, unit: &str, data: Vec<f32>) {
        assert_eq!(
            data.len(),
            self.width as usize * self.height as usize,
            "plane {name} has the wrong size"
        );
        self.planes.push(Plane {
            name: name.into(),
            unit: unit.into(),
            data,
        });
    }

    pub fn get(&self, name: &str) -> Option<&Plane> {
        self.planes.iter().find(|p| p.name == name)
    }
}

impl Plane {
    /// Statistics of the plane's finite values.
    pub fn stats(&self) -> PlaneStats {
        plane_stats(&self.data)
    }
}

/// Summary statistics of the finite values of a plane.
#[derive(Clone, Copy, Debug, serde::Serialize, PartialEq)]
pub struct PlaneStats {
    pub mean: f64,
    pub min: f64,
    pub max: f64,
    /// Population standard deviation.
    pub std: f64,
    /// Number of finite values.
    pub count: usize,
}

/// Statistics of the finite values of `data` (NaN fields when none).
pub fn plane_stats(data: &[f32]) -> PlaneStats {
    let v: Vec<f64> = data
        .iter()
        .filter(|x| x.is_finite())
        .map(|&x| x as f64)
        .collect();
    if v.is_empty() {
        return PlaneStats {
            mean: f64::NAN,
            min: f64::NAN,
            max: f64::NAN,
            std: f64::NAN,
            count: 0,
        };
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    PlaneStats {
        mean,
        min: v.iter().copied().fold(f64::INFINITY, f64::min),
        max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        std: var.sqrt(),
        count: v.len(),
    }
}

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
