//! Errors of the scene loader. Every error names the file and, where the
//! input has one, the line and column, and says what was expected.

use std::fmt;
use std::path::{Path, PathBuf};

/// A place in an input file: 1-based line and column; 0 means unknown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The file.
    pub file: PathBuf,
    /// 1-based line (0: unknown).
    pub line: usize,
    /// 1-based column (0: unknown).
    pub col: usize,
    /// What put the item there when it is not the file's own text: the
    /// command-line override (`--set key=value`) that set it (then `line`
    /// is 0: the item is on no line of the file).
    pub via: Option<Box<str>>,
}

impl Location {
    /// A whole file (no line known).
    pub fn file(file: &Path) -> Self {
        Self {
            file: file.to_path_buf(),
            line: 0,
            col: 0,
            via: None,
        }
    }
    /// A line of a file (column unknown).
    pub fn line(file: &Path, line: usize) -> Self {
        Self {
            file: file.to_path_buf(),
            line,
            col: 0,
            via: None,
        }
    }
    /// The location of byte offset `offset` in `text` (lines and columns
    /// counted in characters, 1-based).
    pub fn at_offset(file: &Path, text: &str, offset: usize) -> Self {
        let offset = offset.min(text.len());
        // Step back to a char boundary so slicing never panics.
        let mut o = offset;
        while o > 0 && !text.is_char_boundary(o) {
            o -= 1;
        }
        let before = &text[..o];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        Self {
            file: file.to_path_buf(),
            line,
            col,
            via: None,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(via) = &self.via {
            write!(f, " ({via})")?;
        }
        if self.line > 0 {
            write!(f, ":{}", self.line)?;
            if self.col > 0 {
                write!(f, ":{}", self.col)?;
            }
        }
        Ok(())
    }
}

/// Why a scene did not load. `Display` gives `file:line:col: what is wrong`.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read.
    #[error("{}: cannot read file: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (kept out of `source()` so that error chains do
        /// not print it twice).
        error: std::io::Error,
    },
    /// TOML syntax, a wrong type, a missing or unknown key (scene or
    /// material file).
    #[error("{loc}: {msg}")]
    Toml {
        /// Where.
        loc: Location,
        /// What is wrong and what was expected.
        msg: String,
    },
    /// A value outside its physical or allowed range.
    #[error("{loc}: {msg}")]
    Invalid {
        /// Where.
        loc: Location,
        /// The value, and what was expected.
        msg: String,
    },
    /// A malformed OBJ line (bad number, NaN/inf vertex, face index out of
    /// range, ...).
    #[error("{loc}: {msg}")]
    Obj {
        /// Where (file and line, or the glTF part).
        loc: Location,
        /// What is wrong and what was expected.
        msg: String,
    },
    /// An OBJ `usemtl` (or an object's default `material`) names a material
    /// no library defines.
    #[error(
        "{loc}: material `{name}` is not defined in the material libraries {}{}",
        libraries_list(libraries),
        suggestion.as_ref().map(|s| format!("; did you mean `{s}`?")).unwrap_or_default()
    )]
    UndefinedMaterial {
        /// Where the name is used.
        loc: Location,
        /// The name.
        name: String,
        /// The libraries searched.
        libraries: Box<[PathBuf]>,
        /// The closest name they define, if one is close.
        suggestion: Option<String>,
    },
    /// A data file referenced by a scene or material (response curve,
    /// emissivity table, PSF kernel) is malformed.
    #[error("{loc}: {msg}")]
    Data {
        /// Where (file and line).
        loc: Location,
        /// What is wrong and what was expected.
        msg: String,
    },
}

fn libraries_list(libs: &[PathBuf]) -> String {
    if libs.is_empty() {
        return "(none given: add `materials = [\"...\"]` to the scene file)".to_string();
    }
    libs.iter()
        .map(|p| format!("`{}`", p.display()))
        .collect::<Vec<_>>()
        .join(", ")
}

impl SceneError {
    /// Reads a text file a scene refers to (the scene itself, a material
    /// library, a response or kernel CSV) through [`crate::files::read_text`]
    /// with the text-file size limit; a failure is [`SceneError::Io`].
    pub fn read_text(path: &Path) -> Result<String, SceneError> {
        crate::files::read_text(path, crate::bounds::sizes::MAX_TEXT_FILE_BYTES)
            .map_err(|error| Self::io(path, error))
    }

    /// A data file's error from a lower layer's reader (the response and
    /// emissivity-table CSVs of [`crate::radiometry`]): its message at
    /// `file:line` (line 0: the file as a whole).
    pub fn from_data(file: &Path, e: crate::radiometry::RadiometryError) -> SceneError {
        let (line, msg) = match e {
            crate::radiometry::RadiometryError::Csv { line, msg, .. } => (line, msg),
            other => (0, other.to_string()),
        };
        SceneError::Data {
            loc: Location::line(file, line),
            msg,
        }
    }

    /// Reads the bytes of a file a scene refers to (a mesh, a raster, the
    /// scene text) through [`crate::files::read`] with its kind's size
    /// limit; a failure is [`SceneError::Io`].
    pub fn read_bytes(path: &Path, max_bytes: u64) -> Result<Vec<u8>, SceneError> {
        crate::files::read(path, max_bytes).map_err(|error| Self::io(path, error))
    }

    fn io(path: &Path, error: std::io::Error) -> SceneError {
        SceneError::Io {
            path: path.to_path_buf(),
            error,
        }
    }

    /// The location the error points at (file, line, column), if any.
    pub fn location(&self) -> Option<&Location> {
        match self {
            SceneError::Io { .. } => None,
            SceneError::Toml { loc, .. }
            | SceneError::Invalid { loc, .. }
            | SceneError::Obj { loc, .. }
            | SceneError::UndefinedMaterial { loc, .. }
            | SceneError::Data { loc, .. } => Some(loc),
        }
    }
}

/// The candidate closest to `word` (Levenshtein distance), if it is close
/// enough to be a plausible typo: distance at most max(2, n/3), n the
/// longer of the two names (so a missing unit suffix such as `_deg` is
/// still matched).
pub fn closest<'a, I>(word: &str, candidates: I) -> Option<String>
where
    I: IntoIterator<Item = &'a str>,
{
    candidates
        .into_iter()
        .map(|c| (strsim::levenshtein(word, c), c))
        .filter(|(d, c)| *d <= (word.chars().count().max(c.chars().count()) / 3).max(2))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_map_to_lines_and_columns() {
        let t = "a = 1\nbb = 2\n\nccc = 3";
        let p = Path::new("f.toml");
        assert_eq!(Location::at_offset(p, t, 0).to_string(), "f.toml:1:1");
        assert_eq!(Location::at_offset(p, t, 6).to_string(), "f.toml:2:1");
        assert_eq!(Location::at_offset(p, t, 11).to_string(), "f.toml:2:6");
        assert_eq!(Location::at_offset(p, t, 14).to_string(), "f.toml:4:1");
        assert_eq!(Location::at_offset(p, t, 999).to_string(), "f.toml:4:8");
        // multi-byte characters count as one column and never split
        let u = "é = 1\nx";
        assert_eq!(Location::at_offset(p, u, 1).to_string(), "f.toml:1:1");
        assert_eq!(Location::at_offset(p, u, 2).to_string(), "f.toml:1:2");
    }

    #[test]
    fn suggestions_pick_close_names_only() {
        let keys = ["latitude_deg", "longitude_deg", "elevation_m"];
        assert_eq!(
            closest("latitude", keys.iter().copied()).as_deref(),
            Some("latitude_deg")
        );
        assert_eq!(
            closest("elevaton_m", keys.iter().copied()).as_deref(),
            Some("elevation_m")
        );
        assert_eq!(closest("colour", keys.iter().copied()), None);
    }
}
