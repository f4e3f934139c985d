//! A TOML input file kept with its text, so that every error (syntax, type,
//! unknown key, out-of-range value) points at a line and column.

use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use super::error::{Location, SceneError, closest};

/// One step of a key path: a table key or an array index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Seg {
    /// A table key.
    Key(String),
    /// An array index (0-based).
    Index(usize),
}

/// A TOML file's path and text.
pub struct TomlSource {
    /// The file.
    pub path: PathBuf,
    /// The text parsed (after any edits).
    pub text: String,
    /// Set when `text` is the file's text edited on the command line
    /// (`--set`, `--unset`): errors are then reported where the item is in
    /// the file, or as the override that put it there.
    pub edits: Option<Edits>,
}

/// The file's own text and the overrides applied to it.
pub struct Edits {
    /// The file's own text.
    pub original: String,
    /// (dotted key, value) as given on the command line.
    pub overrides: Vec<(String, String)>,
}

impl TomlSource {
    /// Reads a file (UTF-8).
    pub fn read(path: &Path) -> Result<Self, SceneError> {
        let bytes = SceneError::read_bytes(path, crate::bounds::sizes::MAX_TEXT_FILE_BYTES)?;
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

    /// A source of `text`, reported as the file `path`.
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
        let doc = toml_edit::ImDocument::parse(ed.original.as_str()).ok();
        let keys = |k: &str| -> Vec<Seg> {
            doc.as_ref()
                .and_then(|d| override_path(d.as_item(), k).ok())
                .unwrap_or_else(|| k.split('.').map(|p| key(p.trim())).collect())
        };
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

/// The key path of an override key (`--set`, `--unset`, a sweep's or a
/// batch's key) in the document `root`: dotted parts, each a key with
/// optional `[n]` indices (`object[2].material`,
/// `object[0].instance[1].translate_m[2]`); a part that follows an array of
/// tables (`[[object]]`, `[[terrain]]`, `[[object.instance]]`) or an array
/// of inline tables selects an entry by index (`object.2`) or by its
/// `name` key (`object.truck.translate_m`). Keys not in the document stay
/// keys (an override may add them). Errors name the override and what
/// was expected.
pub fn override_path(root: &toml_edit::Item, k: &str) -> Result<Vec<Seg>, String> {
    let mut raw = Vec::new();
    for part in k.split('.') {
        let part = part.trim();
        let (base, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        let base = base.trim();
        if base.is_empty() {
            return Err(format!(
                "`{k}`: expected a dotted key such as sensor.band or object[0].material"
            ));
        }
        raw.push(Seg::Key(base.to_string()));
        while !rest.is_empty() {
            let close = rest.find(']').filter(|_| rest.starts_with('['));
            let idx = close.and_then(|c| rest[1..c].trim().parse::<usize>().ok());
            match (close, idx) {
                (Some(c), Some(i)) => {
                    raw.push(Seg::Index(i));
                    rest = rest[c + 1..].trim_start();
                }
                _ => {
                    return Err(format!(
                        "`{k}`: `{part}`: expected an index in brackets such as object[0]"
                    ));
                }
            }
        }
    }
    let mut out = Vec::with_capacity(raw.len());
    let mut node = Some(ONode::Item(root));
    let mut shown = String::new();
    for seg in raw {
        let entries = node.and_then(|n| n.entries());
        let seg = match (seg, &entries) {
            (Seg::Key(name), Some(list)) => match name.parse::<usize>() {
                Ok(i) => Seg::Index(i),
                Err(_) => match list
                    .iter()
                    .position(|t| t.0.as_deref() == Some(name.as_str()))
                {
                    Some(i) => Seg::Index(i),
                    None => {
                        let names: Vec<&str> = list.iter().filter_map(|t| t.0.as_deref()).collect();
                        return Err(format!(
                            "`{k}`: no entry of `{shown}` is named `{name}` ({}); select one by \
                             its `name` or by index, e.g. {shown}[0]",
                            if names.is_empty() {
                                "its entries have no `name`".to_string()
                            } else {
                                format!("names: {}", names.join(", "))
                            }
                        ));
                    }
                },
            },
            (s, _) => s,
        };
        node = match (&seg, node) {
            (Seg::Index(i), Some(n)) => match &entries {
                Some(list) if *i < list.len() => list[*i].1,
                Some(list) => {
                    return Err(format!(
                        "`{k}`: `{shown}` has {} entries (indices 0..{}); no index {i} (an \
                         override changes or adds keys of the entries the scene writes, but adds \
                         no entries: write another one in the scene)",
                        list.len(),
                        list.len().saturating_sub(1)
                    ));
                }
                None => match n.array_len() {
                    Some(len) if *i < len => n.at(*i),
                    Some(len) => {
                        return Err(format!("`{k}`: `{shown}` has {len} elements; no index {i}"));
                    }
                    None => return Err(format!("`{k}`: `{shown}` is not an array")),
                },
            },
            (Seg::Key(name), Some(n)) => n.get(name),
            (_, None) => None,
        };
        match &seg {
            Seg::Key(name) if shown.is_empty() => shown = name.clone(),
            Seg::Key(name) => shown = format!("{shown}.{name}"),
            Seg::Index(i) => shown = format!("{shown}[{i}]"),
        }
        out.push(seg);
    }
    Ok(out)
}

/// A node of a parsed document while an override key is resolved.
#[derive(Clone, Copy)]
enum ONode<'a> {
    Item(&'a toml_edit::Item),
    Table(&'a toml_edit::Table),
    Value(&'a toml_edit::Value),
}

/// (its `name`, the node) of each entry of an array of tables or inline tables.
type Entries<'a> = Vec<(Option<String>, Option<ONode<'a>>)>;

impl<'a> ONode<'a> {
    fn entries(self) -> Option<Entries<'a>> {
        let name = |t: &dyn toml_edit::TableLike| {
            t.get("name").and_then(|n| n.as_str()).map(str::to_string)
        };
        match self {
            ONode::Item(toml_edit::Item::ArrayOfTables(a)) => {
                Some(a.iter().map(|t| (name(t), Some(ONode::Table(t)))).collect())
            }
            ONode::Item(toml_edit::Item::Value(v)) | ONode::Value(v) => {
                let a = v.as_array()?;
                if a.is_empty() || !a.iter().all(|e| e.is_inline_table()) {
                    return None;
                }
                Some(
                    a.iter()
                        .map(|e| {
                            (
                                e.as_inline_table().and_then(|t| name(t)),
                                Some(ONode::Value(e)),
                            )
                        })
                        .collect(),
                )
            }
            _ => None,
        }
    }

    fn array_len(self) -> Option<usize> {
        match self {
            ONode::Item(toml_edit::Item::Value(v)) | ONode::Value(v) => {
                v.as_array().map(|a| a.len())
            }
            ONode::Item(toml_edit::Item::ArrayOfTables(a)) => Some(a.len()),
            _ => None,
        }
    }

    fn at(self, i: usize) -> Option<ONode<'a>> {
        match self {
            ONode::Item(toml_edit::Item::Value(v)) | ONode::Value(v) => {
                v.as_array().and_then(|a| a.get(i)).map(ONode::Value)
            }
            _ => None,
        }
    }

    fn get(self, k: &str) -> Option<ONode<'a>> {
        match self {
            ONode::Item(it) => it.as_table_like()?.get(k).map(ONode::Item),
            ONode::Table(t) => t.get(k).map(ONode::Item),
            ONode::Value(v) => v.as_inline_table()?.get(k).map(ONode::Value),
        }
    }
}

/// Sets the item at `path` (from [`override_path`]) to `value`, creating
/// missing tables on the way; `Err` says why it cannot (shown after the
/// override's name).
pub fn set_at(
    root: &mut toml_edit::Item,
    path: &[Seg],
    value: toml_edit::Value,
) -> Result<(), String> {
    edit_item(root, path, &mut Some(value), "")
}

/// Removes the item at `path` (from [`override_path`]): a key, an array
/// element or a whole `[[...]]` entry.
pub fn remove_at(root: &mut toml_edit::Item, path: &[Seg]) -> Result<(), String> {
    edit_item(root, path, &mut None, "")
}

fn seg_text(shown: &str, seg: &Seg) -> String {
    match seg {
        Seg::Key(k) if shown.is_empty() => k.clone(),
        Seg::Key(k) => format!("{shown}.{k}"),
        Seg::Index(i) => format!("{shown}[{i}]"),
    }
}

/// `value`: Some to set, None to remove.
fn edit_item(
    item: &mut toml_edit::Item,
    path: &[Seg],
    value: &mut Option<toml_edit::Value>,
    shown: &str,
) -> Result<(), String> {
    let Some(seg) = path.first() else {
        return Err(format!("`{shown}`: expected a key inside it"));
    };
    match (item, seg) {
        (toml_edit::Item::ArrayOfTables(a), Seg::Index(i)) => {
            let n = a.len();
            if *i >= n {
                return Err(format!(
                    "`{shown}` has {n} entries; no index {i} (an override changes or adds keys of \
                     the entries the scene writes, but adds no entries: write another \
                     `[[{shown}]]` in the scene)"
                ));
            }
            if path.len() == 1 {
                return match value {
                    None => {
                        a.remove(*i);
                        Ok(())
                    }
                    Some(_) => Err(format!(
                        "`{}`: a whole [[{shown}]] entry cannot be set; set its keys",
                        seg_text(shown, seg)
                    )),
                };
            }
            let t = a.get_mut(*i).expect("in range");
            edit_table(t, &path[1..], value, &seg_text(shown, seg), false)
        }
        (toml_edit::Item::Value(v), _) => edit_value(v, path, value, shown),
        (toml_edit::Item::Table(t), Seg::Key(_)) => edit_table(t, path, value, shown, false),
        (toml_edit::Item::None, _) => Err(format!("`{shown}` is not in the scene")),
        _ => Err(format!(
            "`{}`: `{shown}` is not an array",
            seg_text(shown, seg)
        )),
    }
}

fn edit_table(
    t: &mut dyn toml_edit::TableLike,
    path: &[Seg],
    value: &mut Option<toml_edit::Value>,
    shown: &str,
    inline: bool,
) -> Result<(), String> {
    let seg = &path[0];
    let Seg::Key(k) = seg else {
        return Err(format!(
            "`{}`: `{shown}` is a table, not an array",
            seg_text(shown, seg)
        ));
    };
    let here = seg_text(shown, seg);
    if path.len() == 1 {
        return match value.take() {
            Some(v) => {
                t.insert(k, toml_edit::Item::Value(v));
                Ok(())
            }
            None => t
                .remove(k)
                .map(|_| ())
                .ok_or_else(|| format!("the scene has no `{here}`")),
        };
    }
    if t.get(k).is_none() {
        if value.is_none() {
            return Err(format!("the scene has no `{here}`"));
        }
        if let Seg::Index(i) = path[1] {
            // An override changes, or adds, keys of what the scene writes;
            // it cannot make up an array's other elements or a new entry.
            return Err(format!(
                "`{here}[{i}]`: the scene has no `{here}`, so it has no element {i} to set; \
                 an override adds keys to the tables and entries the scene writes, but no new \
                 entries or elements: write them in the scene file, or set the array whole, e.g. \
                 --set '{here}=[...]'"
            ));
        }
        let new = if inline {
            toml_edit::Item::Value(toml_edit::Value::InlineTable(Default::default()))
        } else {
            toml_edit::Item::Table(toml_edit::Table::new())
        };
        t.insert(k, new);
    }
    let item = t.get_mut(k).expect("present");
    edit_item(item, &path[1..], value, &here)
}

fn edit_value(
    v: &mut toml_edit::Value,
    path: &[Seg],
    value: &mut Option<toml_edit::Value>,
    shown: &str,
) -> Result<(), String> {
    let seg = &path[0];
    match (v, seg) {
        (toml_edit::Value::InlineTable(t), Seg::Key(_)) => edit_table(t, path, value, shown, true),
        (toml_edit::Value::Array(a), Seg::Index(i)) => {
            let n = a.len();
            if *i >= n {
                return Err(format!("`{shown}` has {n} elements; no index {i}"));
            }
            if path.len() == 1 {
                match value.take() {
                    Some(new) => {
                        a.replace(*i, new);
                    }
                    None => {
                        a.remove(*i);
                    }
                }
                return Ok(());
            }
            let e = a.get_mut(*i).expect("in range");
            edit_value(e, &path[1..], value, &seg_text(shown, seg))
        }
        (_, Seg::Key(_)) => Err(format!(
            "`{}`: `{shown}` is a value, not a table",
            seg_text(shown, seg)
        )),
        (_, Seg::Index(_)) => Err(format!(
            "`{}`: `{shown}` is not an array",
            seg_text(shown, seg)
        )),
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
