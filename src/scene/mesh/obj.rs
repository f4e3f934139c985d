//! Wavefront OBJ: irsig's own line-by-line parser (one pass; every error
//! names the file and line and says what was expected). It replaced a
//! pre-scan followed by `tobj`, which disagreed with it on details such
//! as `usemtl<TAB>name` and reports no line numbers.
//!
//! Supported: `v x y z [w]` (or `v x y z r g b`: the colour is ignored),
//! `vt`, `vn`, `f` with `v`, `v/vt`, `v//vn`, `v/vt/vn` (1-based or
//! negative relative indices, vertices defined before use), `o`, `g`,
//! `usemtl` (without a name: no material, the object's own), `mtllib`
//! (ignored: materials come from the TOML libraries), `s`, `l` and `p` (ignored: not surfaces), the free-form-geometry
//! keywords (ignored) and `\` line continuations. Anything else is an
//! error with its line. The text may be UTF-8, UTF-16 with a byte-order
//! mark, or Latin-1 ([`super::decode_text`]).

use std::path::Path;

use super::soup::{Face, Mesh};
use crate::scene::error::{Location, SceneError};

/// Keywords accepted and ignored (not geometry irsig uses).
const IGNORED: &[&str] = &[
    "s",
    "p",
    "l",
    "mtllib",
    "vp",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "usemap",
    "maplib",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
];

/// Reads and parses an OBJ file (faces not yet triangulated).
pub fn load_obj(path: &Path) -> Result<Mesh, SceneError> {
    let bytes = SceneError::read_bytes(path, crate::bounds::sizes::MAX_MESH_FILE_BYTES)?;
    parse_obj(path, &super::text::decode_text(&bytes))
}

/// A named `o` object or `g` group and the faces written while it is
/// current.
struct Part {
    statement: &'static str,
    name: String,
    line: usize,
    faces: usize,
}

/// Parses OBJ text (`path` only names the file in errors and warnings).
pub fn parse_obj(path: &Path, text: &str) -> Result<Mesh, SceneError> {
    let mut m = Mesh {
        path: path.to_path_buf(),
        ..Mesh::default()
    };
    let (mut n_vt, mut n_vn) = (0usize, 0usize);
    // Face vertices whose texture/normal index is out of range (count,
    // first line and what): read past, as irsig uses neither.
    let mut ignored: (usize, Option<(usize, String)>) = (0, None);
    let mut current: Option<u32> = None;
    let mut parts: Vec<Part> = Vec::new();
    let (mut object, mut groups): (Option<usize>, Vec<usize>) = (None, Vec::new());
    for (ln, line) in logical_lines(text) {
        let err = |msg: String| SceneError::Obj {
            loc: Location::line(path, ln),
            msg,
        };
        let mut words = line.split_whitespace();
        let Some(kw) = words.next() else { continue };
        if kw.starts_with('#') {
            continue;
        }
        let args: Vec<&str> = words.collect();
        match kw {
            "v" => m.positions.push(vertex(&args).map_err(err)?),
            "vt" => {
                if args.is_empty()
                    || args.len() > 3
                    || args.iter().any(|a| num(a).is_none_or(|v| !v.is_finite()))
                {
                    return Err(err(
                        "texture coordinate: expected `vt u [v [w]]` with finite numbers".into(),
                    ));
                }
                n_vt += 1;
            }
            "vn" => {
                if args.len() != 3 || args.iter().any(|a| num(a).is_none_or(|v| !v.is_finite())) {
                    return Err(err("normal: expected `vn x y z` with finite numbers".into()));
                }
                n_vn += 1;
            }
            "f" => {
                if args.len() < 3 {
                    return Err(err(format!(
                        "face: expected at least 3 vertices, found {}",
                        args.len()
                    )));
                }
                let counts = [m.positions.len(), n_vt, n_vn];
                let mut verts = Vec::with_capacity(args.len());
                for a in &args {
                    let (v, unused) = face_vertex(a, counts)
                        .map_err(|e| err(format!("face vertex `{a}`: {e}")))?;
                    verts.push(v);
                    if let Some(e) = unused {
                        ignored.0 += 1;
                        ignored.1.get_or_insert((ln, format!("`{a}`: {e}")));
                    }
                }
                m.faces.push(Face {
                    verts,
                    material: current,
                    src: ln,
                });
                for &k in object.iter().chain(&groups) {
                    parts[k].faces += 1;
                }
            }
            "o" | "g" => {
                let names: Vec<String> = if kw == "o" {
                    let name = rest_of(&line, kw);
                    if name.is_empty() {
                        vec![]
                    } else {
                        vec![name.to_string()]
                    }
                } else {
                    args.iter().map(|s| s.to_string()).collect()
                };
                let statement = if kw == "o" { "o" } else { "g" };
                let ids: Vec<usize> = names
                    .into_iter()
                    .map(|name| {
                        match parts
                            .iter()
                            .position(|p| p.statement == statement && p.name == name)
                        {
                            Some(k) => k,
                            None => {
                                parts.push(Part {
                                    statement,
                                    name,
                                    line: ln,
                                    faces: 0,
                                });
                                parts.len() - 1
                            }
                        }
                    })
                    .collect();
                if kw == "o" {
                    object = ids.first().copied();
                    groups.clear();
                } else {
                    groups = ids;
                }
            }
            "usemtl" => {
                let name = rest_of(&line, kw);
                if name.is_empty() {
                    // No name: back to no material (the object's own).
                    current = None;
                    continue;
                }
                let id = match m.material_names.iter().position(|(n, _)| n == name) {
                    Some(id) => id,
                    None => {
                        m.material_names.push((name.to_string(), ln));
                        m.material_names.len() - 1
                    }
                };
                current = Some(id as u32);
            }
            k if IGNORED.contains(&k) => {}
            k => {
                let shown: String = k.chars().take(20).collect();
                return Err(err(format!(
                    "unknown OBJ statement `{shown}`: expected v, vt, vn, f, o, g, usemtl, mtllib, s, l or a comment"
                )));
            }
        }
    }
    let file = path.display();
    if let (n, Some((ln, what))) = ignored {
        m.warnings.push(format!(
            "{file}: {n} face vertices refer to texture coordinates or normals that are not \
             defined (first at line {ln}, {what}); irsig reads neither, so those indices are \
             ignored (vertex indices are still checked)"
        ));
    }
    if m.faces.is_empty() {
        m.warnings.push(format!(
            "{file}: no faces (`f`): nothing of it is rendered (points and lines are not surfaces)"
        ));
    } else {
        let empty: Vec<String> = parts
            .iter()
            .filter(|p| p.faces == 0)
            .map(|p| format!("`{} {}` (line {})", p.statement, p.name, p.line))
            .collect();
        if !empty.is_empty() {
            m.warnings.push(format!(
                "{file}: objects or groups with no faces: {}",
                empty.join(", ")
            ));
        }
    }
    Ok(m)
}

/// Lines joined across `\` continuations, each with the number of its
/// first physical line (1-based).
fn logical_lines(text: &str) -> impl Iterator<Item = (usize, String)> + '_ {
    let mut lines = text.lines().enumerate();
    std::iter::from_fn(move || {
        let (i, first) = lines.next()?;
        let mut line = first.to_string();
        while line.trim_end().ends_with('\\') {
            let cut = line.trim_end().len() - 1;
            line.truncate(cut);
            match lines.next() {
                Some((_, next)) => {
                    line.push(' ');
                    line.push_str(next);
                }
                None => break,
            }
        }
        Some((i + 1, line))
    })
}

/// The text after the keyword, trimmed (names may hold spaces).
fn rest_of<'a>(line: &'a str, kw: &str) -> &'a str {
    line.trim_start().strip_prefix(kw).unwrap_or("").trim()
}

/// One `v` statement: `x y z`, `x y z w` (divided by w) or `x y z r g b`.
fn vertex(args: &[&str]) -> Result<[f64; 3], String> {
    if !matches!(args.len(), 3 | 4 | 6) {
        return Err(format!(
            "vertex: expected `v x y z` (optionally a weight w, or a colour r g b), found {} numbers",
            args.len()
        ));
    }
    let mut vals = [0f64; 6];
    for (j, a) in args.iter().enumerate() {
        let v = num(a).ok_or_else(|| {
            format!("vertex: `{a}` is not a number: expected a decimal number such as -1.5 or 2e3")
        })?;
        if !v.is_finite() || v.abs() > f32::MAX as f64 {
            return Err(format!(
                "vertex: coordinate `{a}` is NaN or infinite (or overflows 32-bit floating point): \
                 expected a finite number"
            ));
        }
        vals[j] = v;
    }
    let w = if args.len() == 4 { vals[3] } else { 1.0 };
    let p = [vals[0] / w, vals[1] / w, vals[2] / w];
    if w == 0.0
        || p.iter()
            .any(|c| !c.is_finite() || c.abs() > f32::MAX as f64)
    {
        return Err(format!(
            "vertex: weight w = `{}` gives a non-finite position: expected a non-zero w",
            args[3]
        ));
    }
    Ok(p)
}

/// Parses a number (in double precision).
fn num(s: &str) -> Option<f64> {
    s.parse::<f64>().ok()
}

/// One `v[/vt][/vn]` face token, checked against the counts of vertices,
/// texture coordinates and normals so far; the 0-based vertex index, and
/// what was wrong with a texture or normal index that is out of range
/// (irsig uses neither, so such an index is ignored, not refused).
fn face_vertex(tok: &str, counts: [usize; 3]) -> Result<(u32, Option<String>), String> {
    let parts: Vec<&str> = tok.split('/').collect();
    if parts.len() > 3 {
        return Err("expected v, v/vt, v//vn or v/vt/vn".into());
    }
    let kinds = [
        ("vertex", "vertices"),
        ("texture coordinate", "texture coordinates"),
        ("normal", "normals"),
    ];
    let mut vertex = 0;
    let mut unused = None;
    for (j, p) in parts.iter().enumerate() {
        if p.is_empty() {
            if j == 0 {
                return Err("missing vertex index".into());
            }
            continue;
        }
        let ((kind, plural), n) = (kinds[j], counts[j]);
        let idx: i64 = p
            .parse()
            .map_err(|_| format!("`{p}` is not an integer {kind} index"))?;
        let zero_based = if idx > 0 && idx as u64 <= n as u64 {
            idx as u64 - 1
        } else if idx < 0 && idx.unsigned_abs() <= n as u64 {
            n as u64 - idx.unsigned_abs()
        } else {
            let msg = format!(
                "{kind} index {idx} is out of range: {n} {plural} defined so far (indices are 1..={n} or -1..=-{n})"
            );
            if j == 0 {
                return Err(msg);
            }
            unused.get_or_insert(msg);
            continue;
        };
        if j == 0 {
            vertex = u32::try_from(zero_based)
                .map_err(|_| format!("vertex index {idx} exceeds 2^32 vertices"))?;
        }
    }
    Ok((vertex, unused))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(t: &str) -> Result<Mesh, String> {
        parse_obj(Path::new("m.obj"), t).map_err(|e| e.to_string())
    }

    #[test]
    fn parses_polygons_materials_and_relative_indices() {
        let m = parse(
            "# quad and triangle\nmtllib x.mtl\no part\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n\
             usemtl asphalt\nf 1//1 2//1 3//1 4//1\ns off\nusemtl grass\nf -4 -3 -2\nl 1 2 3\nusemtl asphalt\nf 1 3 4\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.faces.len(), 3);
        assert_eq!(m.faces[0].verts.len(), 4);
        assert_eq!(m.faces[0].src, 10);
        assert_eq!(m.faces[1].src, 13);
        assert_eq!(
            m.material_names,
            vec![("asphalt".to_string(), 9), ("grass".to_string(), 12)]
        );
        assert_eq!(
            m.faces.iter().map(|f| f.material).collect::<Vec<_>>(),
            vec![Some(0), Some(1), Some(0)]
        );
        // face 2 (-4 -3 -2) is vertices 1 2 3 -> positions (0,0,0) (1,0,0) (1,1,0)
        let p: Vec<[f64; 3]> = m.faces[1]
            .verts
            .iter()
            .map(|&i| m.positions[i as usize])
            .collect();
        assert_eq!(p, vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    }

    #[test]
    fn homogeneous_weight_divides() {
        let m = parse("v 2 4 6 2\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let p = m.positions[m.faces[0].verts[0] as usize];
        assert_eq!(p, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn errors_name_the_line() {
        assert_eq!(
            parse("v 0 0 0\nv 1 nan 0\n").unwrap_err(),
            "m.obj:2: vertex: coordinate `nan` is NaN or infinite (or overflows 32-bit floating point): expected a finite number"
        );
        assert_eq!(
            parse("v 0 0 0\nv 1 1e39 0\n").unwrap_err(),
            "m.obj:2: vertex: coordinate `1e39` is NaN or infinite (or overflows 32-bit floating point): expected a finite number"
        );
        assert_eq!(
            parse("v 0 0 0\nv 1 0 0\nf 1 2 3\n").unwrap_err(),
            "m.obj:3: face vertex `3`: vertex index 3 is out of range: 2 vertices defined so far (indices are 1..=2 or -1..=-2)"
        );
        assert_eq!(
            parse("v 0 0\n").unwrap_err(),
            "m.obj:1: vertex: expected `v x y z` (optionally a weight w, or a colour r g b), found 2 numbers"
        );
        assert_eq!(
            parse("v 0 0 0\nhello world\n").unwrap_err(),
            "m.obj:2: unknown OBJ statement `hello`: expected v, vt, vn, f, o, g, usemtl, mtllib, s, l or a comment"
        );
        assert_eq!(
            parse("v 0 0 0\nf 1 1\n").unwrap_err(),
            "m.obj:2: face: expected at least 3 vertices, found 2"
        );
        assert_eq!(
            parse("v 0 0 0\nv 1 2 3.1+e2\n").unwrap_err(),
            "m.obj:2: vertex: `3.1+e2` is not a number: expected a decimal number such as -1.5 or 2e3"
        );
        assert_eq!(
            parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n").unwrap_err(),
            "m.obj:4: face vertex `0`: vertex index 0 is out of range: 3 vertices defined so far (indices are 1..=3 or -1..=-3)"
        );
        // Texture and normal indices are not used: out of range, they are
        // read past with a warning (not refused).
        let m = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n").unwrap();
        assert_eq!(m.faces[0].verts, vec![0, 1, 2]);
        assert_eq!(
            m.warnings,
            vec![
                "m.obj: 3 face vertices refer to texture coordinates or normals that are not defined (first at line 4, `1/1`: texture coordinate index 1 is out of range: 0 texture coordinates defined so far (indices are 1..=0 or -1..=-0)); irsig reads neither, so those indices are ignored (vertex indices are still checked)"
            ]
        );
    }

    #[test]
    fn usemtl_names_keep_inner_spaces_and_take_tabs() {
        let m = parse(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl\tconcrete\nf 1 2 3\nusemtl   Material name with  spaces   \nf 1 2 3\n",
        )
        .unwrap();
        assert_eq!(
            m.material_names,
            vec![
                ("concrete".to_string(), 4),
                ("Material name with  spaces".to_string(), 6)
            ]
        );
    }

    #[test]
    fn colours_on_some_vertices_continuations_and_crlf() {
        let m = parse(
            "v 0 0 0\r\nv 1 0 0 1 0.5 0\r\nv 0 1 0\r\nf 1 \\\r\n 2 3\r\n# two lines, one face\r\nf 1 2 3\r\n",
        )
        .unwrap();
        assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
        assert_eq!(m.faces.len(), 2);
        assert_eq!((m.faces[0].src, m.faces[1].src), (4, 7));
        assert_eq!(m.faces[0].verts, vec![0, 1, 2]);
    }

    #[test]
    fn empty_objects_and_groups_are_warned_about() {
        let m = parse("o empty\nv 0 0 0\nv 1 0 0\nv 0 1 0\no full\ng a b\nf 1 2 3\ng c\nl 1 2\n")
            .unwrap();
        assert_eq!(
            m.warnings,
            vec!["m.obj: objects or groups with no faces: `o empty` (line 1), `g c` (line 8)"]
        );
        let m = parse("v 0 0 0\nv 1 0 0\np 1 2\n").unwrap();
        assert_eq!(
            m.warnings,
            vec![
                "m.obj: no faces (`f`): nothing of it is rendered (points and lines are not surfaces)"
            ]
        );
    }
}
