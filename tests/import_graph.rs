//! The house rules of `src/` (issue 31), checked on the source text:
//!
//! 1. **Imports only downward.** Every top-level module has a layer
//!    ([`LAYERS`]); a module may import only from its own layer or a lower
//!    one. The layers follow the model's data path: the ground floor
//!    (bounds, version), the sun and the ray tracer, radiometry and the
//!    atmosphere, the thermal model, the scene that builds every type from
//!    its file, the sensor, the render, the outputs, and the runners above
//!    them.
//! 2. **No cycle between the files of one module** (a file importing a file
//!    that imports it back, directly or around a loop).
//! 3. **No source file over [`MAX_LINES`] lines.**
//!
//! What the code does today that breaks a rule is listed below
//! ([`KNOWN_UP_IMPORTS`], [`KNOWN_FILE_CYCLES`], [`KNOWN_LONG_FILES`]) — the
//! debt issue 31 pays off. The test fails on any *new* breach, and also when
//! a listed one is gone, so the lists only ever shrink: delete the line when
//! the refactor removes the import.
//!
//! Imports are read from the text: `crate::a::b…` and `super::…`/`self::…`
//! paths outside comments, and bare paths that start at a child module of the
//! file (`mod obj;` then `obj::load_obj(…)` or `use obj::X`, with no `use` of
//! a `crate::` path), resolved to the longest path that is a file of
//! `src/`. A path that names an item a module re-exports (`pub use
//! sample::Sample;` in `render/mod.rs`, then `super::Sample` or
//! `crate::render::Sample`) is followed to the file that defines it, and a
//! file that uses a name it re-exports itself has an edge to that name's
//! file (`pub use thermal::key_history;` and `key_history(…)` in the same
//! `mod.rs`). Each file's `#[cfg(test)]` module (the tail of the file, by the
//! project's convention, or a `tests.rs` file of its own) is left out: a
//! test may reach anywhere.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Lowest first. A module may import from its own layer or any below it.
const LAYERS: &[&[&str]] = &[
    &["bounds", "files", "units", "version"],
    &["sun", "trace"],
    &["radiometry"],
    &["atmos"],
    &["weather"],
    &["therm"],
    &["scene"],
    &["sensor"],
    &["render"],
    &["output"],
    &["batch", "bench"],
    &["cli"],
];

/// Up-layer imports the code has today (importer → imported top-level
/// module). Issue 31 item 1 removes each.
const KNOWN_UP_IMPORTS: &[(&str, &str)] = &[];

/// File-level import cycles inside a module today, as the sorted set of
/// files in each strongly connected component. Each is a `mod.rs` that
/// calls into a child by a bare path (`validate::validate(…)`,
/// `table::…`) while the child uses an item of the `mod.rs` by `super::`
/// (found when the bare paths were added to the check, issue 31 item 5).
const KNOWN_FILE_CYCLES: &[&[&str]] = &[];

/// The most lines a file of `src/` may have.
const MAX_LINES: usize = 1200;

/// Files over [`MAX_LINES`] today (issue 31 item 4 cuts them).
const KNOWN_LONG_FILES: &[&str] = &[];

/// A source file: its path under `src/` and its module path (`scene::mesh::obj`).
struct SourceFile {
    rel: String,
    module: Vec<String>,
    text: String,
}

fn collect(dir: &Path, root: &Path, out: &mut Vec<SourceFile>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect(&p, root, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            let rel = p
                .strip_prefix(root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            let mut module: Vec<String> = rel
                .trim_end_matches(".rs")
                .split('/')
                .map(String::from)
                .collect();
            if module
                .last()
                .is_some_and(|l| l == "mod" || l == "lib" || l == "main")
            {
                module.pop();
            }
            let text =
                std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            out.push(SourceFile { rel, module, text });
        }
    }
}

/// The file's code without comments and without its trailing test module.
fn code_of(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let t = line.trim_start();
        if t.starts_with("#[cfg(test)]")
            && lines
                .peek()
                .is_some_and(|n| n.trim_start().starts_with("mod "))
        {
            break;
        }
        let code = match t.find("//") {
            Some(i) => &t[..i],
            None => t,
        };
        out.push_str(code);
        out.push('\n');
    }
    out
}

/// The `a::b::c` paths that start at `start` in `code` (after `crate::`,
/// `super::` or `self::`), as segments; `{a, b::c}` groups are expanded
/// one level.
fn paths_after(code: &str, start: &str) -> Vec<Vec<String>> {
    paths_from(code, start, false)
}

/// As [`paths_after`], for a bare path's first segment (`obj::`): only
/// where it starts a path (not after `::`, so `crate::a::obj::x` is not
/// read as the child `obj`).
fn bare_paths_after(code: &str, start: &str) -> Vec<Vec<String>> {
    paths_from(code, start, true)
}

fn paths_from(code: &str, start: &str, bare: bool) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find(start) {
        let before_ok = i == 0
            || !rest[..i]
                .ends_with(|c: char| c.is_alphanumeric() || c == '_' || (bare && c == ':'));
        rest = &rest[i + start.len()..];
        if !before_ok {
            continue;
        }
        let seg_end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .unwrap_or(rest.len());
        let head: Vec<String> = rest[..seg_end]
            .split("::")
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect();
        if (rest[seg_end..].starts_with('{') && rest[..seg_end].ends_with("::"))
            || (head.is_empty() && rest.starts_with('{'))
        {
            let close = rest.find('}').unwrap_or(rest.len());
            let inner = &rest[seg_end + 1..close];
            for item in inner.split(',') {
                let item = item.trim();
                let mut p = head.clone();
                p.extend(
                    item.split("::")
                        .map(|s| {
                            s.trim()
                                .trim_end_matches(|c: char| !(c.is_alphanumeric() || c == '_'))
                        })
                        .filter(|s| !s.is_empty())
                        .map(String::from),
                );
                out.push(p);
            }
        } else {
            out.push(head);
        }
    }
    out
}

/// A module's re-exports: (module path, name) → the full path it stands for.
type Reexports = BTreeMap<(Vec<String>, String), Vec<String>>;

/// The file of `src/` a path names: its longest prefix that is a module
/// file, or, when the rest of the path starts with a name that module
/// re-exports, the file of the re-exported path (followed up to 8 times).
fn resolve<'a>(
    path: &[String],
    by_module: &'a BTreeMap<Vec<String>, String>,
    reexports: &Reexports,
) -> Option<&'a String> {
    let mut path = path.to_vec();
    for _ in 0..8 {
        let n = (1..=path.len())
            .rev()
            .find(|&n| by_module.contains_key(&path[..n]))?;
        match path
            .get(n)
            .and_then(|name| reexports.get(&(path[..n].to_vec(), name.clone())))
        {
            Some(to) if *to != path[..=n] => {
                let mut next = to.clone();
                next.extend_from_slice(&path[n + 1..]);
                path = next;
            }
            _ => return by_module.get(&path[..n]),
        }
    }
    None
}

/// The `pub use` / `pub(crate) use` statements of `code` (the file of
/// `module`, whose parent is `parent`): each re-exported name (its alias,
/// or the path's last segment) and the full path it stands for. A glob
/// (`pub use spec::*;`) re-exports every item its module defines (found by
/// [`defines`] in `files`).
fn reexports_of(
    code: &str,
    module: &[String],
    parent: &[String],
    files: &[SourceFile],
) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    for stmt in reexport_statements(code) {
        let body = stmt.trim().trim_end_matches(';');
        let (head, items): (&str, Vec<&str>) = match body.find('{') {
            Some(i) => (
                &body[..i],
                body[i + 1..body.rfind('}').unwrap_or(body.len())]
                    .split(',')
                    .collect(),
            ),
            None => ("", vec![body]),
        };
        for item in items {
            let item = item.trim();
            if item.is_empty() {
                continue;
            }
            let (path, alias) = match item.split_once(" as ") {
                Some((p, a)) => (p.trim(), Some(a.trim())),
                None => (item, None),
            };
            let segs: Vec<&str> = head
                .split("::")
                .chain(path.split("::"))
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .collect();
            let Some((&first, rest)) = segs.split_first() else {
                continue;
            };
            let mut full: Vec<String> = match first {
                "crate" => Vec::new(),
                "super" => parent.to_vec(),
                "self" => module.to_vec(),
                child => {
                    let mut m = module.to_vec();
                    m.push(child.to_string());
                    m
                }
            };
            full.extend(rest.iter().map(|s| s.to_string()));
            if full.last().is_some_and(|l| l == "*") {
                full.pop();
                if let Some(f) = files.iter().find(|f| f.module == full) {
                    for name in defined_names(&code_of(&f.text)) {
                        let mut to = full.clone();
                        to.push(name.clone());
                        out.push((name, to));
                    }
                }
                continue;
            }
            let name = alias.unwrap_or(full.last().map_or("", String::as_str));
            if name != "self" && name != "_" {
                out.push((name.to_string(), full.clone()));
            }
        }
    }
    out
}

/// The re-export statements of `code` (`pub use …;`, `pub(crate) use
/// …;`), from `use` to the `;`.
fn reexport_statements(code: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(i) = rest.find("pub") {
        let word_start = i == 0 || !rest[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_');
        let after = &rest[i + 3..];
        let after = after
            .strip_prefix("(crate)")
            .or_else(|| after.strip_prefix("(super)"))
            .unwrap_or(after);
        let t = after.trim_start();
        if word_start && let Some(body) = t.strip_prefix("use ") {
            let end = body.find(';').map_or(body.len(), |e| e + 1);
            out.push(&body[..end]);
            rest = &body[end..];
        } else {
            rest = &rest[i + 3..];
        }
    }
    out
}

/// The names of the public items `code` defines (`pub fn x`, `pub struct
/// X`, …, `pub(crate)` too).
fn defined_names(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in code.lines() {
        let t = line.trim_start();
        let Some(t) = t.strip_prefix("pub") else {
            continue;
        };
        let t = t
            .strip_prefix("(crate)")
            .or_else(|| t.strip_prefix("(super)"))
            .unwrap_or(t)
            .trim_start();
        let t = t.strip_prefix("const fn ").unwrap_or(t);
        for kw in [
            "fn ", "struct ", "enum ", "type ", "const ", "static ", "trait ", "mod ",
        ] {
            if let Some(rest) = t.strip_prefix(kw) {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    out.insert(name);
                }
            }
        }
    }
    out
}

/// Whether `code` uses `name` (a name its file re-exports): as a word of
/// its own that starts a path (not after `::` or `.`, not in a `mod name;`
/// declaration); a function's name (lower case) only where it is called
/// or starts a path (`name(`, `name::`: not a variable of the same name);
/// a type's name not where a line declares an enum variant or a field of
/// that name (`Name(String),`, `Name {` with no `=` on the line).
fn uses_name(code: &str, name: &str) -> bool {
    let is_fn = name.starts_with(|c: char| c.is_lowercase() || c == '_');
    code.match_indices(name).any(|(i, _)| {
        let (before, after) = (&code[..i], &code[i + name.len()..]);
        let starts = !before
            .ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == ':' || c == '.')
            && !before.trim_end().ends_with(" mod");
        let ends = !after.starts_with(|c: char| c.is_alphanumeric() || c == '_');
        let line_start = before.rfind('\n').map_or(0, |n| n + 1);
        let line = code[line_start..].lines().next().unwrap_or("");
        let declares = before[line_start..].trim().is_empty()
            && !line.contains('=')
            && (after.starts_with('(') || after.starts_with(" {") || after.starts_with(','));
        let used = if is_fn {
            after.starts_with('(') || after.starts_with("::")
        } else {
            !declares
        };
        starts && ends && used
    })
}

fn layer_of(top: &str) -> usize {
    LAYERS
        .iter()
        .position(|l| l.contains(&top))
        .unwrap_or_else(|| panic!("top-level module `{top}` has no layer: add it to LAYERS"))
}

/// Files of `src/` and the files each imports.
fn graph() -> (Vec<SourceFile>, BTreeMap<String, BTreeSet<String>>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    collect(&root, &root, &mut files);
    let by_module: BTreeMap<Vec<String>, String> = files
        .iter()
        .map(|f| (f.module.clone(), f.rel.clone()))
        .collect();
    let mut reexports = Reexports::new();
    for f in &files {
        let parent = &f.module[..f.module.len().saturating_sub(1)];
        for (name, to) in reexports_of(&code_of(&f.text), &f.module, parent, &files) {
            reexports.insert((f.module.clone(), name), to);
        }
    }
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        // A unit-test module in its own file (`#[cfg(test)] mod tests;`).
        if f.rel.ends_with("/tests.rs") {
            continue;
        }
        let code = code_of(&f.text);
        let mut targets = paths_after(&code, "crate::");
        // `super` of src/a/b.rs is `a`; of src/a/b/mod.rs also `a`.
        let parent: Vec<String> = f.module[..f.module.len().saturating_sub(1)].to_vec();
        for p in paths_after(&code, "super::") {
            let mut full = parent.clone();
            full.extend(p);
            targets.push(full);
        }
        for p in paths_after(&code, "self::") {
            let mut full = f.module.clone();
            full.extend(p);
            targets.push(full);
        }
        // Bare paths from a child module of this file (`obj::load_obj(…)`);
        // a re-export (`pub use obj::X;`) is the module's face, not a use.
        let used = without_reexports(&code);
        for child in children_of(&f.module, &files) {
            for p in bare_paths_after(&used, &format!("{child}::")) {
                let mut full = f.module.clone();
                full.push(child.clone());
                full.extend(p);
                targets.push(full);
            }
        }
        // A name this file re-exports, used in its own code.
        for ((m, name), to) in &reexports {
            if *m == f.module && uses_name(&used, name) {
                targets.push(to.clone());
            }
        }
        let set = edges.entry(f.rel.clone()).or_default();
        for t in targets {
            if let Some(to) = resolve(&t, &by_module, &reexports)
                && *to != f.rel
            {
                set.insert(to.clone());
            }
        }
    }
    (files, edges)
}

/// `code` without its re-export statements (`pub use …;`, `pub(crate) use …;`).
fn without_reexports(code: &str) -> String {
    let mut out = String::with_capacity(code.len());
    let mut rest = code;
    while let Some(i) = rest.find("pub") {
        let stmt = rest[i..].trim_start_matches("pub");
        let stmt = stmt
            .strip_prefix("(crate)")
            .or_else(|| stmt.strip_prefix("(super)"))
            .unwrap_or(stmt);
        let word_start = i == 0 || !rest[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_');
        if word_start && stmt.trim_start().starts_with("use ") {
            out.push_str(&rest[..i]);
            let end = rest[i..].find(';').map_or(rest.len(), |e| i + e + 1);
            rest = &rest[end..];
        } else {
            out.push_str(&rest[..i + 3]);
            rest = &rest[i + 3..];
        }
    }
    out.push_str(rest);
    out
}

/// The names of the modules declared inside `module` (its child files).
fn children_of(module: &[String], files: &[SourceFile]) -> BTreeSet<String> {
    files
        .iter()
        .filter(|g| g.module.len() == module.len() + 1 && g.module.starts_with(module))
        .map(|g| g.module[module.len()].clone())
        .collect()
}

fn top_of(rel: &str) -> &str {
    rel.split('/').next().unwrap().trim_end_matches(".rs")
}

#[test]
fn imports_run_only_downward() {
    let (_, edges) = graph();
    let mut found: BTreeMap<(String, String), Vec<String>> = BTreeMap::new();
    for (from, tos) in &edges {
        let a = top_of(from);
        if matches!(a, "lib" | "main") {
            continue;
        }
        for to in tos {
            let b = top_of(to);
            if a != b && layer_of(b) > layer_of(a) {
                found
                    .entry((a.to_string(), b.to_string()))
                    .or_default()
                    .push(format!("{from} → {to}"));
            }
        }
    }
    let known: BTreeSet<(String, String)> = KNOWN_UP_IMPORTS
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    let new: Vec<String> = found
        .iter()
        .filter(|(k, _)| !known.contains(*k))
        .map(|((a, b), w)| format!("{a} → {b} (up a layer): {}", w.join(", ")))
        .collect();
    let gone: Vec<String> = known
        .iter()
        .filter(|k| !found.contains_key(*k))
        .map(|(a, b)| format!("{a} → {b}"))
        .collect();
    assert!(
        new.is_empty(),
        "imports up a layer (see LAYERS in tests/import_graph.rs):\n{}",
        new.join("\n")
    );
    assert!(
        gone.is_empty(),
        "these listed up-imports are gone: delete them from KNOWN_UP_IMPORTS:\n{}",
        gone.join("\n")
    );
}

/// Strongly connected components of more than one file (Tarjan).
fn cycles(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct St<'a> {
        edges: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut St<'a>, v: &'a str) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        s.on.insert(v);
        if let Some(ws) = s.edges.get(v) {
            for w in ws {
                let w = w.as_str();
                if !s.index.contains_key(w) {
                    visit(s, w);
                    let lw = s.low[w];
                    let lv = s.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if s.on.contains(w) {
                    let iw = s.index[w];
                    let lv = s.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = St {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: vec![],
        on: BTreeSet::new(),
        out: vec![],
    };
    for v in edges.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out.sort();
    s.out
}

#[test]
fn no_import_cycle_between_the_files_of_a_module() {
    let (_, edges) = graph();
    // Only edges inside one top-level module: those between modules are the
    // layer test's.
    let inner: BTreeMap<String, BTreeSet<String>> = edges
        .iter()
        .map(|(a, tos)| {
            (
                a.clone(),
                tos.iter()
                    .filter(|b| top_of(b) == top_of(a))
                    .cloned()
                    .collect(),
            )
        })
        .collect();
    let found = cycles(&inner);
    let known: Vec<Vec<String>> = KNOWN_FILE_CYCLES
        .iter()
        .map(|c| c.iter().map(|s| s.to_string()).collect())
        .collect();
    let new: Vec<String> = found
        .iter()
        .filter(|c| !known.contains(c))
        .map(|c| c.join(" ↔ "))
        .collect();
    let gone: Vec<String> = known
        .iter()
        .filter(|c| !found.contains(c))
        .map(|c| c.join(" ↔ "))
        .collect();
    assert!(new.is_empty(), "file import cycles:\n{}", new.join("\n"));
    assert!(
        gone.is_empty(),
        "these listed cycles changed or are gone: update KNOWN_FILE_CYCLES:\n{}",
        gone.join("\n")
    );
}

#[test]
fn no_source_file_is_over_the_line_limit() {
    let (files, _) = graph();
    let long: BTreeSet<&str> = files
        .iter()
        .filter(|f| f.text.lines().count() > MAX_LINES)
        .map(|f| f.rel.as_str())
        .collect();
    let known: BTreeSet<&str> = KNOWN_LONG_FILES.iter().copied().collect();
    let new: Vec<&&str> = long.difference(&known).collect();
    let gone: Vec<&&str> = known.difference(&long).collect();
    assert!(new.is_empty(), "files over {MAX_LINES} lines: {new:?}");
    assert!(
        gone.is_empty(),
        "now under {MAX_LINES} lines: delete from KNOWN_LONG_FILES: {gone:?}"
    );
}

#[test]
fn the_resolver_sees_a_planted_up_import_and_cycle() {
    // The checks must be able to fail: a synthetic graph with a cycle.
    let mut e: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    e.entry("a.rs".into()).or_default().insert("b.rs".into());
    e.entry("b.rs".into()).or_default().insert("c.rs".into());
    e.entry("c.rs".into()).or_default().insert("a.rs".into());
    e.entry("d.rs".into()).or_default().insert("a.rs".into());
    assert_eq!(
        cycles(&e),
        vec![vec!["a.rs".to_string(), "b.rs".into(), "c.rs".into()]]
    );
    // Grouped and nested paths.
    let p = paths_after(
        "use crate::{scene::mesh::Mesh, therm};\nlet x = crate::render::planes::Plane::A;",
        "crate::",
    );
    assert!(
        p.contains(&vec!["scene".into(), "mesh".into(), "Mesh".into()]),
        "{p:?}"
    );
    assert!(p.contains(&vec!["therm".into()]), "{p:?}");
    assert!(
        p.contains(&vec![
            "render".into(),
            "planes".into(),
            "Plane".into(),
            "A".into()
        ]),
        "{p:?}"
    );
    // A bare path from a child module; not the same name inside a longer path.
    let b = bare_paths_after(
        "let m = obj::load_obj(p)?;\nlet n = crate::scene::mesh::obj::Other;",
        "obj::",
    );
    assert_eq!(b, vec![vec!["load_obj".to_string()]], "{b:?}");
    // A re-exported name is followed to the file that defines it.
    let files = vec![
        SourceFile {
            rel: "r/mod.rs".into(),
            module: vec!["r".into()],
            text: "mod s;\npub use s::{f, G as H};\npub use t::*;\nfn go() { f(); }\n".into(),
        },
        SourceFile {
            rel: "r/s.rs".into(),
            module: vec!["r".into(), "s".into()],
            text: "pub fn f() {}\n".into(),
        },
        SourceFile {
            rel: "r/t.rs".into(),
            module: vec!["r".into(), "t".into()],
            text: "pub(crate) struct K;\n".into(),
        },
    ];
    let r = reexports_of(&files[0].text, &files[0].module, &[], &files);
    let to = |p: &[&str]| p.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    assert_eq!(
        r,
        vec![
            ("f".to_string(), to(&["r", "s", "f"])),
            ("H".to_string(), to(&["r", "s", "G"])),
            ("K".to_string(), to(&["r", "t", "K"])),
        ]
    );
    let by_module: BTreeMap<Vec<String>, String> = files
        .iter()
        .map(|f| (f.module.clone(), f.rel.clone()))
        .collect();
    let rx: Reexports = r
        .into_iter()
        .map(|(n, p)| ((vec!["r".to_string()], n), p))
        .collect();
    assert_eq!(
        resolve(&to(&["r", "K", "new"]), &by_module, &rx).map(String::as_str),
        Some("r/t.rs")
    );
    assert_eq!(
        resolve(&to(&["r", "go"]), &by_module, &rx).map(String::as_str),
        Some("r/mod.rs")
    );
    assert!(uses_name("fn go() { f(); }", "f"));
    assert!(!uses_name("x.f(); a::f(); ff();", "f"));
    // Not a module declaration, a variable or a variant of the same name.
    assert!(!uses_name(
        "pub mod rays;\nfn t(rays: &[Ray]) -> usize { rays.len() }",
        "rays"
    ));
    assert!(!uses_name(
        "enum E {\n    Emissivity(String),\n}",
        "Emissivity"
    ));
    assert!(uses_name("let e = Emissivity::Table(t);", "Emissivity"));
    assert!(uses_name("fn f(b: &Batch) -> Vec<FrameJob> {", "FrameJob"));
    // Comments and the trailing test module are not code.
    let c = code_of(
        "use a; // crate::x\n/// [`crate::y`]\n#[cfg(test)]\nmod tests {\n use crate::z;\n}\n",
    );
    assert!(!c.contains("crate::"), "{c}");
}

/// The `.rs` files below `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let p = e.expect("directory entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The struct literals `Name { … }` in `text` that name every field (no
/// `..base`), as 1-based line numbers; a definition (`struct Name {`), an
/// `impl` block (`impl Name {`, `impl Trait for Name {`) or a return type
/// (`-> Name {`) is not a literal.
fn literals_without_base(text: &str, name: &str) -> Vec<usize> {
    let open = format!("{name} {{");
    let mut out = Vec::new();
    for (i, _) in text.match_indices(&open) {
        let before = text[..i].trim_end();
        if ["struct", "impl", "for", "->"]
            .iter()
            .any(|w| before.ends_with(w))
        {
            continue;
        }
        let mut depth = 0usize;
        let mut end = text.len();
        for (j, c) in text[i + open.len() - 1..].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = i + open.len() - 1 + j;
                        break;
                    }
                }
                _ => {}
            }
        }
        if !text[i..end].contains("..") {
            out.push(text[..i].matches('\n').count() + 1);
        }
    }
    out
}

/// Adding a material key touches at most two files (ARCHITECTURE.md, "where
/// to add a material key"): code that builds a `SlabMaterial` by hand
/// completes it with `..` (`SlabMaterial::with_defaults`, the six required
/// keys), so a new key with a default changes none of it.
#[test]
fn slab_materials_built_by_hand_complete_themselves_with_defaults() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for d in ["src", "tests", "python/src"] {
        if root.join(d).is_dir() {
            rust_files(&root.join(d), &mut files);
        }
    }
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for line in literals_without_base(&text, "SlabMaterial") {
            found.push(format!(
                "{}:{line}",
                f.strip_prefix(root).unwrap().display()
            ));
        }
    }
    assert!(
        found.is_empty(),
        "SlabMaterial literals naming every field (complete them with \
         `..SlabMaterial::with_defaults(…)`):\n{}",
        found.join("\n")
    );
    // The check can fail.
    assert_eq!(
        literals_without_base("pub struct Mat {\n}\nlet m = Mat {\n a: 1,\n};", "Mat"),
        vec![3]
    );
    assert!(literals_without_base("let m = Mat { a: 1, ..b };", "Mat").is_empty());
}
