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
    /// Set when `text` is the file's text edited on the command line
    /// (`--set`, `--unset`): errors are then reported where the item is in
    /// the file, or as the override that put it there.
    pub edits: Option<Edits>,
}

/// The file's own text and the overrides applied to it.
pub struct Edits {
    pub original: String,
    /// (dotted key, value) as given on the command line.
    pub overrides: Vec<(String, String)>,
}

impl TomlSource {
    /// Reads a file (UTF-8).
    pub fn read(path: &Path) -> Result<Self, SceneError> {
        let bytes =
            crate::files::read(path, crate::bounds::sizes::MAX_TEXT_FILE_BYTES).map_err(|e| {
                SceneError::Io {
                    path: path.to_path_buf(),
                    error: e,
                }
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
            edits: None,
        }
    }

    /// `edited`: the text of the file `path` (`original`) after `--unset`
    /// and the `overrides` (`--set key=value`) were applied to it.
    pub fn from_edited(
        path: &Path,
        original: String,
        edited: String,
        overrides: &[(String, String)],
    ) -> Self {
        Self {
            path: path.to_path_buf(),
            text: edited,
            edits: Some(Edits {
                original,
                overrides: overrides.to_vec(),
            }),
        }
    }

    /// The location of byte `offset` of the text: in the file's own text,
    /// or the override that set the item there.
    fn location(&self, offset: usize) -> Location {
        if self.edits.is_none() {
            return Location::at_offset(&self.path, &self.text, offset);
        }
        let Some(path) = path_at(&self.text, offset) else {
            return Location::file(&self.path);
        };
        let loc = self.loc_of(&path);
        // The same column as in the edited text where the error's line is
        // unchanged at the item's place in the file (e.g. a key before
        // its value).
        let (Some(se), Some(ed)) = (find_span(&self.text, &path), &self.edits) else {
            return loc;
        };
        let at = |text: &str, o: usize| Location::at_offset(&self.path, text, o);
        let (err, item) = (at(&self.text, offset), at(&self.text, se.start));
        let line = (loc.line + err.line).checked_sub(item.line);
        match line {
            Some(l)
                if loc.via.is_none()
                    && loc.line > 0
                    && self.text.lines().nth(err.line - 1) == ed.original.lines().nth(l - 1) =>
            {
                Location { line: l, ..err }
            }
            _ => loc,
        }
    }

    /// Deserialises the whole file, mapping errors to `file:line:col: ...`
    /// with a "did you mean" for unknown keys and variants.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, SceneError> {
        toml::from_str(&self.text).map_err(|e| self.toml_error(&e))
    }

    fn toml_error(&self, e: &toml::de::Error) -> SceneError {
        let loc = match e.span() {
            Some(s) => self.location(s.start),
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
        let Some(ed) = &self.edits else {
            return match find_span(&self.text, path) {
                Some(s) => Location::at_offset(&self.path, &self.text, s.start),
                None => Location::file(&self.path),
            };
        };
        let keys = |k: &str| -> Vec<Seg> { k.split('.').map(|p| key(p.trim())).collect() };
        let via = |(k, v): &(String, String)| Location {
            via: Some(format!("--set {k}={v}").into()),
            ..Location::file(&self.path)
        };
        // An item an override set (or one inside it).
        if let Some(o) = ed
            .overrides
            .iter()
            .find(|(k, _)| path.starts_with(&keys(k)))
        {
            return via(o);
        }
        match find_span(&ed.original, path) {
            Some(s) => Location::at_offset(&self.path, &ed.original, s.start),
            // A table only an override created.
            None => match ed.overrides.iter().find(|(k, _)| keys(k).starts_with(path)) {
                Some(o) => via(o),
                None => Location::file(&self.path),
            },
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

fn key(k: &str) -> Seg {
    Seg::Key(k.to_string())
}

/// The key path of the deepest key, value or table header of `text` that
/// holds byte `offset`.
fn path_at(text: &str, offset: usize) -> Option<Vec<Seg>> {
    let doc = toml_edit::ImDocument::parse(text).ok()?;
    let mut path = Vec::new();
    in_table(doc.as_table(), offset, &mut path).then_some(path)
}

fn holds(span: Option<Range<usize>>, offset: usize) -> bool {
    span.is_some_and(|s| s.start <= offset && offset < s.end.max(s.start + 1))
}

/// [`path_at`] inside a table (`path` extended in place when found).
fn in_table(t: &dyn toml_edit::TableLike, offset: usize, path: &mut Vec<Seg>) -> bool {
    for (k, _) in t.iter() {
        let Some((kk, item)) = t.get_key_value(k) else {
            continue;
        };
        path.push(key(k));
        if in_item(item, offset, path) || holds(kk.span(), offset) {
            return true;
        }
        path.pop();
    }
    false
}

fn in_item(item: &toml_edit::Item, offset: usize, path: &mut Vec<Seg>) -> bool {
    match item {
        toml_edit::Item::Value(v) => in_value(v, offset, path),
        // (a table's span may cover its body: its keys first)
        toml_edit::Item::Table(t) => in_table(t, offset, path) || holds(t.span(), offset),
        toml_edit::Item::ArrayOfTables(a) => {
            for (i, t) in a.iter().enumerate() {
                path.push(Seg::Index(i));
                if in_table(t, offset, path) || holds(t.span(), offset) {
                    return true;
                }
                path.pop();
            }
            false
        }
        toml_edit::Item::None => false,
    }
}

fn in_value(v: &toml_edit::Value, offset: usize, path: &mut Vec<Seg>) -> bool {
    if !holds(v.span(), offset) {
        return false;
    }
    match v {
        toml_edit::Value::Array(a) => {
            for (i, e) in a.iter().enumerate() {
                path.push(Seg::Index(i));
                if in_value(e, offset, path) {
                    return true;
                }
                path.pop();
            }
        }
        toml_edit::Value::InlineTable(t) => {
            let mut inner = Vec::new();
            if in_table(t, offset, &mut inner) {
                path.extend(inner);
            }
        }
        _ => {}
    }
    true
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
