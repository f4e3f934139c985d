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
//! `src/`. Each file's `#[cfg(test)]` module (the tail of the file, by the
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

/// The file of `src/` a path names: its longest prefix that is a module file.
fn resolve<'a>(
    path: &[String],
    by_module: &'a BTreeMap<Vec<String>, String>,
) -> Option<&'a String> {
    (1..=path.len())
        .rev()
        .find_map(|n| by_module.get(&path[..n].to_vec()))
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
        let set = edges.entry(f.rel.clone()).or_default();
        for t in targets {
            if let Some(to) = resolve(&t, &by_module)
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
    // Comments and the trailing test module are not code.
    let c = code_of(
        "use a; // crate::x\n/// [`crate::y`]\n#[cfg(test)]\nmod tests {\n use crate::z;\n}\n",
    );
    assert!(!c.contains("crate::"), "{c}");
}
