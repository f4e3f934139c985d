//! Whole output sets: the files of one result (a render's EXR, PNG, JSON
//! and ENVI cube; a sequence's contact sheet and `index.json`) appear
//! together or not at all.
//!
//! The protocol ([`OutputSet`]):
//! 1. every file is written in full under a temporary name
//!    `.irsig-partial-XXXXXX` in its destination folder, flushed and synced;
//!    nothing visible changes while this happens, and a failure removes the
//!    temporary files of the set and leaves the previous set as it was;
//! 2. on [`OutputSet::commit`] the previous set's *marker* (the file that
//!    says a set is complete, e.g. the JSON summary) is removed first, then
//!    the other files are renamed over their destinations in the order they
//!    were staged, and the marker is renamed last.
//!
//! So a set whose marker exists is complete, and a set whose marker is
//! missing is an interrupted one, which the next run replaces. A rename is
//! atomic on POSIX file systems, so no file is ever seen half-written.
//!
//! Every temporary file is held under an exclusive advisory lock
//! (`flock`) by the process that writes it; [`remove_stale_partials`],
//! called by every new set, removes the temporary files in its folder that
//! nobody holds, i.e. those of killed runs, and leaves those of live
//! writers (another process writing into the same folder) alone.
//!
//! For tests of the protocol, the environment variable `IRSIG_STALL_AT`
//! stops the process at a named point ([`stall_point`]) so that a test can
//! kill it exactly there: `staged` (every file of the set written under its
//! temporary name, nothing renamed), `marker-removed` (the previous marker
//! removed), `renamed-K` (K files of the set renamed, K ≥ 1) and
//! `staged-K` (K files written under temporary names, the set still being
//! written), optionally qualified with the marker's file name
//! (`renamed-1@x.json`).

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::OutputError;

/// The name prefix of temporary files.
pub const PARTIAL_PREFIX: &str = ".irsig-partial-";

/// What a file writer of a set writes into: a buffered writer that
/// remembers the first I/O error (so that an encoder's failure that was
/// really a write failure is reported as one).
pub type Sink<'a> = std::io::BufWriter<Tap<'a>>;

/// A writer over a temporary file that records its first I/O error.
pub struct Tap<'a> {
    file: &'a mut File,
    error: Option<std::io::Error>,
}

impl Tap<'_> {
    /// `r`, its error recorded first.
    fn checked<T>(&mut self, r: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(e) = &r {
            self.record(e);
        }
        r
    }

    fn record(&mut self, e: &std::io::Error) {
        if self.error.is_none() {
            self.error = Some(match e.raw_os_error() {
                Some(code) => std::io::Error::from_raw_os_error(code),
                None => std::io::Error::new(e.kind(), e.to_string()),
            });
        }
    }
}

impl Write for Tap<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let r = self.file.write(buf);
        self.checked(r)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let r = self.file.flush();
        self.checked(r)
    }
}

/// Seeking (an encoder that writes a table of offsets after the data it
/// points to, e.g. EXR's, seeks back to it; the [`Sink`]'s buffer is
/// flushed first): errors are recorded as a write's are.
impl Seek for Tap<'_> {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        let r = self.file.seek(pos);
        self.checked(r)
    }
}

/// Reading back what was written (to patch a header in place after the
/// data: [`super::exr`]); errors are recorded as a write's are.
impl Read for Tap<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let r = self.file.read(buf);
        self.checked(r)
    }
}

/// One file written under its temporary name.
struct Staged {
    tmp: tempfile::NamedTempFile,
    dest: PathBuf,
}

/// The files of one result, staged under temporary names and committed
/// together (see the module documentation).
pub struct OutputSet {
    marker: PathBuf,
    staged: Vec<Staged>,
}

/// The folder of `path` (`.` for a bare file name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn io_error(path: &Path, reason: std::io::Error) -> OutputError {
    OutputError::Io {
        path: path.to_path_buf(),
        reason,
    }
}

impl OutputSet {
    /// A new set whose completion marker is `marker` (committed last). Its
    /// folder is created if needed, and the stale temporary files of killed
    /// runs in it are removed.
    pub fn new(marker: &Path) -> Result<OutputSet, OutputError> {
        let dir = folder_of(marker);
        std::fs::create_dir_all(&dir).map_err(|e| io_error(&dir, e))?;
        remove_stale_partials(&dir).map_err(|e| io_error(&dir, e))?;
        Ok(OutputSet {
            marker: marker.to_path_buf(),
            staged: Vec::new(),
        })
    }

    /// The marker file.
    pub fn marker(&self) -> &Path {
        &self.marker
    }

    fn marker_name(&self) -> String {
        self.marker
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    }

    /// The destinations staged so far, in order.
    pub fn files(&self) -> impl Iterator<Item = &Path> {
        self.staged.iter().map(|s| s.dest.as_path())
    }

    /// Writes `path`'s contents with `fill` into a locked temporary file in
    /// `path`'s folder, flushed and synced; it becomes `path` on
    /// [`commit`](Self::commit). `fill`'s error is the encoder's message;
    /// an I/O failure is reported as `cannot write <path>: <OS reason>`.
    /// On an error this temporary file is removed (and the set's others
    /// when the set is dropped).
    pub fn stage<F>(&mut self, path: &Path, fill: F) -> Result<(), OutputError>
    where
        F: FnOnce(&mut Sink) -> Result<(), String>,
    {
        let io = |e| io_error(path, e);
        if self.staged.iter().any(|s| s.dest == path) {
            return Err(OutputError::Encode {
                path: path.to_path_buf(),
                msg: "staged twice in one output set".into(),
            });
        }
        let mut tmp = locked_temp(&folder_of(path)).map_err(io)?;
        let (encoded, io_failed) = {
            let mut w = std::io::BufWriter::new(Tap {
                file: tmp.as_file_mut(),
                error: None,
            });
            let encoded = fill(&mut w);
            let flushed = if encoded.is_ok() { w.flush() } else { Ok(()) };
            let (tap, _) = w.into_parts();
            (encoded, tap.error.map(Err).unwrap_or(flushed))
        };
        io_failed.map_err(io)?;
        encoded.map_err(|msg| OutputError::Encode {
            path: path.to_path_buf(),
            msg,
        })?;
        // tempfile creates 0600 files; outputs are ordinary files (0644).
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            tmp.as_file()
                .set_permissions(std::fs::Permissions::from_mode(0o644))
                .map_err(io)?;
        }
        tmp.as_file().sync_all().map_err(io)?;
        self.staged.push(Staged {
            tmp,
            dest: path.to_path_buf(),
        });
        stall_point(
            &format!("staged-{}", self.staged.len()),
            &self.marker_name(),
        );
        Ok(())
    }

    /// Makes the staged files visible: removes the previous marker, renames
    /// the other files in staging order and the marker last. A set without
    /// its marker staged cannot be committed.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let marker = self.marker.clone();
        let Some(m) = self.staged.iter().position(|s| s.dest == marker) else {
            return Err(OutputError::Encode {
                path: marker,
                msg: "the output set's marker file was not written".into(),
            });
        };
        let last = self.staged.remove(m);
        let name = self.marker_name();
        stall_point("staged", &name);
        match std::fs::remove_file(&marker) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io_error(&marker, e)),
        }
        stall_point("marker-removed", &name);
        let staged = std::mem::take(&mut self.staged);
        for (k, s) in staged.into_iter().chain([last]).enumerate() {
            let dest = s.dest;
            // The lock goes with the returned file, closed here.
            s.tmp.persist(&dest).map_err(|e| io_error(&dest, e.error))?;
            stall_point(&format!("renamed-{}", k + 1), &name);
        }
        // The renames reach the disk with the folder's entry list.
        if let Ok(d) = File::open(folder_of(&marker)) {
            let _ = d.sync_all();
        }
        Ok(())
    }
}

/// A temporary file `.irsig-partial-XXXXXX` in `dir` under an exclusive
/// lock. A cleaner may remove the name in the instant between its creation
/// and the lock; the file is then made again.
fn locked_temp(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    loop {
        let tmp = tempfile::Builder::new()
            .prefix(PARTIAL_PREFIX)
            .tempfile_in(dir)?;
        tmp.as_file().lock()?;
        if same_file(tmp.as_file(), tmp.path()) {
            return Ok(tmp);
        }
    }
}

/// Whether `path` still names the open file `f`.
fn same_file(f: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (f.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = f;
        path.exists()
    }
}

/// Removes the temporary files `.irsig-partial-*` in `dir` that no live
/// process holds (those of killed runs); returns how many it removed.
pub fn remove_stale_partials(dir: &Path) -> std::io::Result<usize> {
    let mut removed = 0;
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
        Err(e) => return Err(e),
    };
    for entry in entries {
        let entry = entry?;
        if !entry
            .file_name()
            .to_string_lossy()
            .starts_with(PARTIAL_PREFIX)
        {
            continue;
        }
        let path = entry.path();
        // Another user's file, or one gone since: not ours to judge.
        let Ok(f) = std::fs::OpenOptions::new().write(true).open(&path) else {
            continue;
        };
        if f.try_lock().is_ok() && std::fs::remove_file(&path).is_ok() {
            removed += 1;
        }
    }
    Ok(removed)
}

/// Stops the process for ever at the point `point` of writing the set
/// whose marker is named `marker` when the environment variable
/// `IRSIG_STALL_AT` is `point` or `point@marker` (a fault-injection hook
/// for tests that kill the process there); says so on stderr first.
pub fn stall_point(point: &str, marker: &str) {
    static AT: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    let Some(at) = AT.get_or_init(|| std::env::var("IRSIG_STALL_AT").ok()) else {
        return;
    };
    let hit = match at.split_once('@') {
        Some((p, m)) => p == point && m == marker,
        None => at == point,
    };
    if hit {
        eprintln!("irsig: stalled at {point}@{marker} (IRSIG_STALL_AT)");
        loop {
            std::thread::sleep(std::time::Duration::from_secs(3600));
        }
    }
}

/// Writes `path` atomically as a set of one file.
pub fn write_atomic<F>(path: &Path, fill: F) -> Result<(), OutputError>
where
    F: FnOnce(&mut Sink) -> Result<(), String>,
{
    let mut set = OutputSet::new(path)?;
    set.stage(path, fill)?;
    set.commit()
}

/// Writes the text `text` to `path` atomically ([`write_atomic`]).
pub fn write_text(path: &Path, text: &str) -> Result<(), OutputError> {
    write_atomic(path, |w| {
        w.write_all(text.as_bytes()).map_err(|e| e.to_string())
    })
}
