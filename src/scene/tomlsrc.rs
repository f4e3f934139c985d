//! A TOML input file kept with its text, so that every error (syntax, type,
//! unknown key, out-of-range value) points at a line and column.

use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use super::error::{Location, SceneError, closest};

/// One step of a key path: a table key or an array index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// A TOML file's path and text.
pub struct TomlSource {
    pub path: PathBuf,
    pub text: String,
}

impl TomlSource {
    /// Reads a file (UTF-8).
    pub fn read(path: &Path) -> Result<Self, SceneError> {
        let bytes = std::fs::read(path).map_err(|e| SceneError::Io {
            path: path.to_path_buf(),
            error: e,
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let off = e.utf8_error().valid_up_to();
            let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
            SceneError::Toml {
                loc: Location::at_offset(path, &text, off),
                msg: "invalid UTF-8: a TOML file must be UTF-8 text".to_string(),
            }
        })?;
        Ok(Self::from_text(path, text))
    }

    pub fn from_text(path: &Path, text: String) -> Self {
        Self {
            path: path.to_path_buf(),
            text,
        }
    }

    /// Deserialises the whole file, mapping errors to `file:line:col: ...`
    /// with a "did you mean" for unknown keys and variants.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, SceneError> {
        toml::from_str(&self.text).map_err(|e| self.toml_error(&e))
    }

    fn toml_error(&self, e: &toml::de::Error) -> SceneError {
        let loc = match e.span() {
            Some(s) => Location::at_offset(&self.path, &self.text, s.start),
            None => Location::file(&self.path),
        };
        let mut msg = e.message().trim().replace('\n', " ");
        if let Some(s) = suggestion(&msg) {
            msg.push_str(&format!("; did you mean `{s}`?"));
        }
        SceneError::Toml { loc, msg }
    }

    /// The location of the value at `path` (or of its key, or of the
    /// nearest enclosing table that exists).
    pub fn loc_of(&self, path: &[Seg]) -> Location {
        match find_span(&self.text, path) {
            Some(s) => Location::at_offset(&self.path, &self.text, s.start),
            None => Location::file(&self.path),
        }
    }

    /// An out-of-range error at `path`.
    pub fn invalid(&self, path: &[Seg], msg: String) -> SceneError {
        SceneError::Invalid {
            loc: self.loc_of(path),
            msg,
        }
    }
}

/// For serde's "unknown field `x`, expected one of `a`, `b`" (and the
/// variant form), the closest expected name.
fn suggestion(msg: &str) -> Option<String> {
    let rest = msg
        .strip_prefix("unknown field `")
        .or_else(|| msg.strip_prefix("unknown variant `"))?;
    let end = rest.find('`')?;
    let word = &rest[..end];
    let expected = &rest[end + 1..];
    let names: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    closest(word, names.iter().copied())
}

/// Span of the item at `path`: the value's span, else its key's, else the
/// deepest existing ancestor's.
fn find_span(text: &str, path: &[Seg]) -> Option<Range<usize>> {
    let doc = toml_edit::ImDocument::parse(text).ok()?;
    let mut best: Option<Range<usize>> = None;
    let mut node = Node::Item(doc.as_item());
    for seg in path {
        let next = match (seg, node) {
            (Seg::Key(k), Node::Item(it)) => {
                let Some(tbl) = it.as_table_like() else { break };
                let Some((key, item)) = tbl.get_key_value(k) else {
                    break;
                };
                if let Some(s) = key.span() {
                    best = Some(s);
                }
                Node::Item(item)
            }
            (Seg::Key(k), Node::Table(t)) => {
                let Some((key, item)) = t.get_key_value(k) else {
                    break;
                };
                if let Some(s) = key.span() {
                    best = Some(s);
                }
                Node::Item(item)
            }
            (Seg::Key(k), Node::Value(v)) => {
                let Some(t) = v.as_inline_table() else { break };
                let Some((key, item)) = toml_edit::TableLike::get_key_value(t, k) else {
                    break;
                };
                if let Some(s) = key.span() {
                    best = Some(s);
                }
                Node::Item(item)
            }
            (Seg::Index(i), Node::Item(it)) => match it {
                toml_edit::Item::ArrayOfTables(a) => match a.get(*i) {
                    Some(t) => {
                        if let Some(s) = t.span() {
                            best = Some(s);
                        }
                        Node::Table(t)
                    }
                    None => break,
                },
                toml_edit::Item::Value(toml_edit::Value::Array(a)) => match a.get(*i) {
                    Some(v) => Node::Value(v),
                    None => break,
                },
                _ => break,
            },
            (Seg::Index(i), Node::Value(toml_edit::Value::Array(a))) => match a.get(*i) {
                Some(v) => Node::Value(v),
                None => break,
            },
            _ => break,
        };
        if let Some(s) = next.span() {
            best = Some(s);
        }
        node = next;
    }
    best
}

#[derive(Clone, Copy)]
enum Node<'a> {
    Item(&'a toml_edit::Item),
    Table(&'a toml_edit::Table),
    Value(&'a toml_edit::Value),
}

impl Node<'_> {
    fn span(&self) -> Option<Range<usize>> {
        match self {
            // A table's own span is its header; keep the key's span instead
            // for implicit tables.
            Node::Item(toml_edit::Item::Value(v)) => v.span(),
            Node::Item(toml_edit::Item::Table(t)) => t.span(),
            Node::Item(_) => None,
            Node::Table(t) => t.span(),
            Node::Value(v) => v.span(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn loc(text: &str, path: &[Seg]) -> String {
        TomlSource::from_text(Path::new("t.toml"), text.to_string())
            .loc_of(path)
            .to_string()
    }
    fn k(s: &str) -> Seg {
        Seg::Key(s.to_string())
    }

    #[test]
    fn spans_of_values_tables_arrays_and_inline_tables() {
        let t = "a = 1\n[site]\nlat = 43.1\n\n[[object]]\nfile = \"x\"\n[[object]]\nfile = \"y\"\nv = [1, 2, { q = 3 }]\n";
        assert_eq!(loc(t, &[k("a")]), "t.toml:1:5");
        assert_eq!(loc(t, &[k("site"), k("lat")]), "t.toml:3:7");
        assert_eq!(
            loc(t, &[k("object"), Seg::Index(1), k("file")]),
            "t.toml:8:8"
        );
        assert_eq!(
            loc(t, &[k("object"), Seg::Index(1), k("v"), Seg::Index(1)]),
            "t.toml:9:9"
        );
        assert_eq!(
            loc(
                t,
                &[k("object"), Seg::Index(1), k("v"), Seg::Index(2), k("q")]
            ),
            "t.toml:9:18"
        );
        // a missing key falls back to its table
        assert_eq!(loc(t, &[k("site"), k("nothing")]), "t.toml:2:1");
        assert_eq!(loc(t, &[k("nothing")]), "t.toml");
    }

    #[test]
    fn unknown_key_messages_get_a_suggestion() {
        assert_eq!(
            suggestion("unknown field `latitude`, expected one of `latitude_deg`, `longitude_deg`")
                .as_deref(),
            Some("latitude_deg")
        );
        assert_eq!(
            suggestion("unknown variant `lwirr`, expected `lwir` or `mwir`").as_deref(),
            Some("lwir")
        );
        assert_eq!(suggestion("missing field `x`"), None);
    }
}
