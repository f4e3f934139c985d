//! The ranges are stated once (`irsig::bounds`); the reference pages list
//! them for people. This test reads the pages' tables back: for every bound
//! there must be a table row naming the key in backticks with a cell
//! `[lo, hi]` whose numbers equal the bound's, so the docs cannot drift
//! from the checks (issue 17).

use std::path::Path;

/// The `[a, b]` cells of a markdown table row, as numbers.
fn ranges_in(row: &str) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut rest = row;
    while let Some(i) = rest.find('[') {
        rest = &rest[i + 1..];
        let Some(j) = rest.find(']') else { break };
        if let Some((a, b)) = rest[..j].split_once(',')
            && let (Ok(a), Ok(b)) = (a.trim().parse::<f64>(), b.trim().parse::<f64>())
        {
            out.push((a, b));
        }
        rest = &rest[j + 1..];
    }
    out
}

#[test]
fn every_bound_is_listed_in_the_docs_with_its_range() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut missing = Vec::new();
    let mut bounds = irsig::bounds::documented();
    // the material keys, described beside their fields
    bounds.extend(
        irsig::scene::material::library_keys()
            .iter()
            .filter_map(|k| k.range)
            .map(|b| ("docs/scene-format.md", b)),
    );
    assert!(bounds.len() > 40, "{} bounds", bounds.len());
    for (doc, b) in bounds {
        let text = std::fs::read_to_string(root.join(doc)).unwrap();
        let key = format!("`{}`", b.key);
        let found = text
            .lines()
            .filter(|l| l.starts_with('|') && l.contains(&key))
            .any(|l| ranges_in(l).contains(&(b.lo, b.hi)));
        if !found {
            missing.push(format!("{doc}: {key} [{}, {}]", b.lo, b.hi));
        }
    }
    assert!(missing.is_empty(), "not listed:\n{}", missing.join("\n"));
}

#[test]
fn the_range_reader_reads_what_the_docs_write() {
    assert_eq!(
        ranges_in("| `thickness_m` | m | required | [1e-5, 10] | slab |"),
        vec![(1e-5, 10.0)]
    );
    assert_eq!(ranges_in("| `a` | [x, 1] | (0, 1] |"), vec![]);
}

const BEGIN: &str = "<!-- material keys: generated from the rows beside the fields \
(therm/slab/material.rs, therm/surface.rs, scene/material.rs) by tests/bounds_docs.rs; \
IRSIG_BLESS=1 cargo test --test bounds_docs rewrites it -->";
const END: &str = "<!-- end of material keys -->";

/// The material-key table as docs/scene-format.md prints it.
fn material_key_table() -> String {
    use irsig::bounds::num;
    let mut t = String::from("| key | unit | default | range | meaning |\n|---|---|---|---|---|\n");
    for k in irsig::scene::material::library_keys() {
        let range = k
            .range
            .map(|b| format!("[{}, {}]", num(b.lo), num(b.hi)))
            .unwrap_or_default();
        let cells = [
            format!("`{}`", k.path[k.path.len() - 1]),
            k.unit.to_string(),
            k.default.to_string(),
            range,
            k.meaning.to_string(),
        ];
        t.push('|');
        for c in &cells {
            t.push_str(&if c.is_empty() {
                " |".into()
            } else {
                format!(" {c} |")
            });
        }
        t.push('\n');
    }
    t
}

/// Adding a material key is its field and its row beside it (and the
/// physics that reads it): the docs' table is generated from the rows, and
/// this test fails until it is regenerated (`IRSIG_BLESS=1`).
#[test]
fn the_material_key_table_in_the_docs_is_generated_from_the_rows() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scene-format.md");
    let text = std::fs::read_to_string(&path).unwrap();
    let (Some(a), Some(b)) = (text.find(BEGIN), text.find(END)) else {
        panic!("docs/scene-format.md lacks the markers {BEGIN} … {END}");
    };
    let want = format!("{BEGIN}\n\n{}\n{END}", material_key_table());
    let have = &text[a..b + END.len()];
    if have != want {
        if std::env::var_os("IRSIG_BLESS").is_some() {
            let new = format!("{}{want}{}", &text[..a], &text[b + END.len()..]);
            std::fs::write(&path, new).unwrap();
        } else {
            panic!(
                "docs/scene-format.md's material-key table differs from the rows in the code; \
                 rerun with IRSIG_BLESS=1 to regenerate it. Expected:\n{want}"
            );
        }
    }
}
