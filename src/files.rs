//! Reading input files: regular files only, each with a size limit checked
//! before a byte is read (docs/reliability.md).
//!
//! Every loader (scene and material TOML, OBJ/glTF meshes and their
//! buffers, DEM and land-cover GeoTIFFs, weather files, forcing, response,
//! kernel and emissivity CSVs, atmosphere tables) reads its file through
//! [`read`] or [`read_text`]. A device (`/dev/zero`, `/dev/urandom`), a
//! FIFO, a socket or a folder is refused at once with what it is, instead
//! of being read until memory runs out or blocking forever; a file larger
//! than its kind's limit ([`crate::bounds::sizes`]) is refused with its
//! size and the limit. The limit is checked again while reading (a file
//! growing under the reader stops at limit + 1 bytes).

use std::collections::BTreeMap;
use std::io::{self, Read};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// How many times [`read`] has opened each path in this process.
static OPENED: Mutex<BTreeMap<PathBuf, usize>> = Mutex::new(BTreeMap::new());

/// How many times [`read`] (and [`read_text`]) opened `path` in this
/// process, as given to them: a diagnostic for tests (a render opens its
/// weather file once, `tests/weather_once.rs`).
pub fn opened_count(path: &Path) -> usize {
    let m = OPENED.lock().unwrap_or_else(|e| e.into_inner());
    m.get(path).copied().unwrap_or(0)
}

/// What a path is when it is not a regular file (for error messages).
fn kind_of(md: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = md.file_type();
    if t.is_dir() {
        "a folder"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// Checks that `path` is a regular file (symbolic links followed) of at
/// most `limit` bytes; returns its size.
pub fn check_regular(path: &Path, limit: u64) -> io::Result<u64> {
    let md = std::fs::metadata(path)?;
    if !md.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("is {}: expected a regular file", kind_of(&md)),
        ));
    }
    if md.len() > limit {
        return Err(too_large(md.len(), limit));
    }
    Ok(md.len())
}

fn too_large(len: u64, limit: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!(
            "is {} bytes, more than the {} bytes ({} MiB) this kind of file may have",
            len,
            limit,
            limit >> 20
        ),
    )
}

/// The bytes of regular file `path`, refused without reading if it is not a
/// regular file or is larger than `limit` bytes.
pub fn read(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let len = check_regular(path, limit)?;
    let f = std::fs::File::open(path)?;
    *OPENED
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .entry(path.to_path_buf())
        .or_default() += 1;
    let mut out = Vec::with_capacity(len as usize);
    f.take(limit.saturating_add(1)).read_to_end(&mut out)?;
    if out.len() as u64 > limit {
        return Err(too_large(out.len() as u64, limit));
    }
    Ok(out)
}

/// As [`read`], as UTF-8 text.
pub fn read_text(path: &Path, limit: u64) -> io::Result<String> {
    String::from_utf8(read(path, limit)?).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("stream did not contain valid UTF-8 ({e})"),
        )
    })
}

/// What `path` is when it exists but is not a regular file (a folder, a
/// device, a FIFO, a socket); `None` for a regular file or a missing path.
pub fn not_regular(path: &Path) -> Option<&'static str> {
    std::fs::metadata(path)
        .ok()
        .filter(|m| !m.is_file())
        .map(|m| kind_of(&m))
}

/// The one path policy for the files a file refers to (docs/reliability.md,
/// "Path policy"): the files a scene names, a material library's emissivity
/// tables and a glTF model's external buffers (its caller decodes the URI
/// first). `p`, relative to `folder` (the referring file's folder) or
/// absolute, must lie in `folder`'s tree or in one of the `allow`ed folders
/// (each relative to `folder` or absolute; a model's buffers have none),
/// judged on the lexically normalised path and, when the file exists, again
/// on the canonical one (a symbolic link may not lead out). A `file:` URI
/// and a Windows drive or UNC path (`C:…`, `\\…`) are refused (write a
/// relative path). Returns `folder.join(p)`, or why it is refused (nothing
/// is read).
pub fn within(
    folder: &Path,
    p: &Path,
    allow: &[std::path::PathBuf],
) -> Result<std::path::PathBuf, String> {
    let s = p.to_string_lossy();
    if s.starts_with("file:") {
        return Err("is a `file:` URI: expected a path".into());
    }
    let b = s.as_bytes();
    if s.starts_with('\\') || (b.len() > 1 && b[0].is_ascii_alphabetic() && b[1] == b':') {
        return Err("is an absolute (Windows drive or UNC) path: expected a relative path".into());
    }
    let others = if allow.is_empty() {
        ""
    } else {
        " and the allowed folders"
    };
    let base = std::path::absolute(folder_or_cwd(folder)).map_err(|e| e.to_string())?;
    let roots: Vec<std::path::PathBuf> = std::iter::once(normalise(&base))
        .chain(allow.iter().map(|a| normalise(&base.join(a))))
        .collect();
    let file = folder.join(p);
    let lexical = normalise(&base.join(p));
    if !roots.iter().any(|r| lexical.starts_with(r)) {
        return Err(if p.is_absolute() {
            format!("is an absolute path outside its folder tree{others}")
        } else {
            format!("climbs out of its folder tree{others} with `..`")
        });
    }
    if let Ok(canonical) = file.canonicalize() {
        let inside = roots
            .iter()
            .filter_map(|r| r.canonicalize().ok())
            .any(|r| canonical.starts_with(r));
        if !inside {
            return Err(format!(
                "leads out of its folder tree{others} through a symbolic link"
            ));
        }
    }
    Ok(file)
}

/// `p` with `.` dropped and each `..` taking off the component before it
/// (lexically: symbolic links are not followed; `..` at the root stays at
/// the root).
fn normalise(p: &Path) -> std::path::PathBuf {
    use std::path::Component;
    let mut out = std::path::PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out
}

fn folder_or_cwd(p: &Path) -> &Path {
    if p.as_os_str().is_empty() {
        Path::new(".")
    } else {
        p
    }
}

/// The comma-separated numbers of one CSV line, each finite; else the
/// 1-based column and text of the first that is not (the emissivity-table and
/// PSF-kernel readers).
pub fn csv_numbers(line: &str) -> Result<Vec<f64>, (usize, String)> {
    line.split(',')
        .enumerate()
        .map(|(i, f)| {
            let f = f.trim();
            match f.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err((i + 1, f.to_string())),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_devices_folders_fifos_and_large_files() {
        let e = read(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert!(e.to_string().contains("character device"), "{e}");
        let e = read(Path::new("/"), 1 << 20).unwrap_err();
        assert!(e.to_string().contains("a folder"), "{e}");
        let d = tempfile::tempdir().unwrap();
        let fifo = d.path().join("p");
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if ok {
            let e = read(&fifo, 1 << 20).unwrap_err();
            assert!(e.to_string().contains("FIFO"), "{e}");
        }
        let f = d.path().join("big");
        std::fs::write(&f, vec![b'x'; 1000]).unwrap();
        let e = read(&f, 999).unwrap_err();
        assert!(e.to_string().contains("1000 bytes"), "{e}");
        assert_eq!(read(&f, 1000).unwrap().len(), 1000);
        assert!(read(&d.path().join("none"), 10).unwrap_err().kind() == io::ErrorKind::NotFound);
    }

    #[test]
    fn within_refuses_escapes() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("m");
        std::fs::create_dir(&sub).unwrap();
        std::fs::write(sub.join("a.bin"), b"x").unwrap();
        assert!(within(&sub, Path::new("a.bin"), &[]).is_ok());
        assert!(within(&sub, Path::new("x/../a.bin"), &[]).is_ok());
        for bad in [
            "/etc/passwd",
            "../a.bin",
            "x/../../a.bin",
            "../../../../etc/passwd",
            "C:/Windows/win.ini",
            "\\\\server\\share\\a.bin",
            "file:///etc/passwd",
        ] {
            assert!(within(&sub, Path::new(bad), &[]).is_err(), "{bad}");
        }
        std::os::unix::fs::symlink("/etc/passwd", sub.join("l")).unwrap();
        let e = within(&sub, Path::new("l"), &[]).unwrap_err();
        assert!(e.contains("symbolic link"), "{e}");
    }
}
