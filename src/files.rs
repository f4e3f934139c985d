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

use std::io::{self, Read};
use std::path::Path;

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

/// The path policy for files a model refers to (docs/reliability.md):
/// `rel`, relative to `folder`, must stay inside `folder`'s tree. Refused:
/// an absolute path (or a Windows drive/UNC prefix), a `..` that climbs
/// above `folder`, and a path whose symbolic links lead out of `folder`
/// (checked on the canonical paths when the file exists). Returns the
/// joined path, or why it is refused.
pub fn inside_folder(folder: &Path, rel: &Path) -> Result<std::path::PathBuf, String> {
    use std::path::Component;
    let mut depth = 0usize;
    for c in rel.components() {
        match c {
            Component::Prefix(_) | Component::RootDir => {
                return Err("is an absolute path".into());
            }
            Component::ParentDir => {
                if depth == 0 {
                    return Err("climbs out of the model's folder with `..`".into());
                }
                depth -= 1;
            }
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
        }
    }
    let s = rel.to_string_lossy();
    if s.starts_with('\\') || s.as_bytes().get(1) == Some(&b':') {
        return Err("is an absolute path".into());
    }
    let file = folder.join(rel);
    if let (Ok(f), Ok(d)) = (file.canonicalize(), folder_or_cwd(folder).canonicalize())
        && !f.starts_with(&d)
    {
        return Err("leads out of the model's folder through a symbolic link".into());
    }
    Ok(file)
}

/// The path policy for files a scene refers to (docs/reliability.md, "Path
/// policy"): `p`, relative to `folder` (the referring file's folder) or
/// absolute, must lie in `folder`'s tree or in one of the `allow`ed folders
/// (each relative to `folder` or absolute), judged on the lexically
/// normalised path and, when the file exists, again on the canonical one
/// (a symbolic link may not lead out). A `file:` URI is refused (write a
/// path). Returns `folder.join(p)`, or why it is refused (nothing is read).
pub fn within(
    folder: &Path,
    p: &Path,
    allow: &[std::path::PathBuf],
) -> Result<std::path::PathBuf, String> {
    if p.to_string_lossy().starts_with("file:") {
        return Err("is a `file:` URI: expected a path".into());
    }
    let base = std::path::absolute(folder_or_cwd(folder)).map_err(|e| e.to_string())?;
    let roots: Vec<std::path::PathBuf> = std::iter::once(normalise(&base))
        .chain(allow.iter().map(|a| normalise(&base.join(a))))
        .collect();
    let file = folder.join(p);
    let lexical = normalise(&base.join(p));
    if !roots.iter().any(|r| lexical.starts_with(r)) {
        return Err(if p.is_absolute() {
            "is an absolute path outside the allowed folders".into()
        } else {
            "climbs out of the allowed folders with `..`".into()
        });
    }
    if let Ok(canonical) = file.canonicalize() {
        let inside = roots
            .iter()
            .filter_map(|r| r.canonicalize().ok())
            .any(|r| canonical.starts_with(r));
        if !inside {
            return Err("leads out of the allowed folders through a symbolic link".into());
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
    fn inside_folder_refuses_escapes() {
        let d = tempfile::tempdir().unwrap();
        let sub = d.path().join("m");
        std::fs::create_dir(&sub).unwrap();
        std::fs::write(sub.join("a.bin"), b"x").unwrap();
        assert!(inside_folder(&sub, Path::new("a.bin")).is_ok());
        assert!(inside_folder(&sub, Path::new("x/../a.bin")).is_ok());
        for bad in [
            "/etc/passwd",
            "../a.bin",
            "x/../../a.bin",
            "../../../../etc/passwd",
        ] {
            assert!(inside_folder(&sub, Path::new(bad)).is_err(), "{bad}");
        }
        std::os::unix::fs::symlink("/etc/passwd", sub.join("l")).unwrap();
        let e = inside_folder(&sub, Path::new("l")).unwrap_err();
        assert!(e.contains("symbolic link"), "{e}");
    }
}
