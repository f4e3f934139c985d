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
    let bounds = irsig::bounds::documented();
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
