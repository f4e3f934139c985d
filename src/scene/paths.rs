//! The files a scene refers to: the path policy (docs/reliability.md, "Path
//! policy"), then "a regular file that exists", each refusal reported at
//! the scene-file key that names the file.

use std::path::{Path, PathBuf};

use super::error::SceneError;
use super::tomlsrc::{Seg, TomlSource};

/// The file `p` named at key `at` of the scene `src` (a `what`, e.g.
/// "weather file"), resolved from the scene file's folder: refused when the
/// path policy does not allow it (outside the scene's folder tree and the
/// `files.allow` folders), when it is missing, or when it is not a regular
/// file. Nothing of the file is read.
pub(crate) fn referenced_file(
    src: &TomlSource,
    allow: &[PathBuf],
    p: &Path,
    at: &[Seg],
    what: &str,
) -> Result<PathBuf, SceneError> {
    let folder = src.path.parent().unwrap_or(Path::new(""));
    let r = crate::files::within(folder, p, allow).map_err(|why| {
        src.invalid(
            at,
            format!(
                "{what} `{}` {why}: a scene reads files in its own folder tree unless \
                 `files.allow` lists the folder (docs/scene-format.md, \"Files\")",
                p.display()
            ),
        )
    })?;
    if r.is_file() {
        Ok(r)
    } else if let Some(kind) = crate::files::not_regular(&r) {
        Err(src.invalid(
            at,
            format!(
                "{what} `{}` is {kind} ({}): expected a regular file",
                p.display(),
                r.display()
            ),
        ))
    } else {
        Err(src.invalid(
            at,
            format!(
                "{what} `{}` not found (looked for {})",
                p.display(),
                r.display()
            ),
        ))
    }
}

/// A path named in the scene file `scene_file`, resolved from its folder.
pub(crate) fn resolve(scene_file: &Path, p: &Path) -> PathBuf {
    scene_file.parent().unwrap_or(Path::new("")).join(p)
}
