//! OBJ geometry: a line-by-line pre-scan that validates every statement
//! and records line numbers (tobj reports none), then tobj for the parse.
//!
//! Supported: `v x y z [w]` (or `v x y z r g b` on every vertex), `vt`,
//! `vn`, `f` with `v`, `v/vt`, `v//vn`, `v/vt/vn` (1-based or negative
//! relative indices, vertices defined before use), `o`, `g`, `usemtl`,
//! `mtllib` (ignored: materials come from the TOML libraries), `s`, `l`
//! and `p` (ignored: not facets), and the free-form-geometry keywords
//! (ignored). Anything else is an error with its line.

use std::path::{Path, PathBuf};

use super::error::{Location, SceneError};

/// One polygon face of an OBJ file.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjFace {
    /// Vertex indices into [`ObjMesh::positions`] (>= 3, in file order).
    pub verts: Vec<u32>,
    /// Index into [`ObjMesh::material_names`] of the `usemtl` in effect,
    /// or `None` before any `usemtl`.
    pub material: Option<u32>,
    /// 1-based line of the `f` statement.
    pub line: usize,
}

/// A parsed OBJ file in its own (model) coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjMesh {
    pub path: PathBuf,
    /// Vertex positions as written (parsed in double precision, so that
    /// projected coordinates such as UTM keep their millimetres).
    pub positions: Vec<[f64; 3]>,
    /// Faces in file order (face `i` is facet `i` of the object).
    pub faces: Vec<ObjFace>,
    /// Distinct `usemtl` names with the line of their first use.
    pub material_names: Vec<(String, usize)>,
}

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

struct Scan {
    n_v: usize,
    n_vt: usize,
    n_vn: usize,
    n_colored: usize,
    first_uncolored: Option<usize>,
    first_colored: Option<usize>,
    faces: Vec<ObjFace>,
    names: Vec<(String, usize)>,
}

/// Reads and parses an OBJ file.
pub fn load_obj(path: &Path) -> Result<ObjMesh, SceneError> {
    let bytes = std::fs::read(path).map_err(|e| SceneError::Io {
        path: path.to_path_buf(),
        error: e,
    })?;
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let off = e.utf8_error().valid_up_to();
            let line = e.as_bytes()[..off].iter().filter(|&&b| b == b'\n').count() + 1;
            return Err(SceneError::Obj {
                loc: Location::line(path, line),
                msg: "invalid UTF-8: expected an OBJ text file".to_string(),
            });
        }
    };
    parse_obj(path, &text)
}

/// Parses OBJ text (`path` only names the file in errors).
pub fn parse_obj(path: &Path, text: &str) -> Result<ObjMesh, SceneError> {
    let scan = prescan(path, text)?;
    // tobj parses `l` polylines of 3+ points as faces: blank them out
    // (keeping the line count) so only `f` statements become faces.
    let sanitized: String = text
        .lines()
        .map(|l| {
            let kw = l.split_whitespace().next();
            if kw == Some("l") || kw == Some("p") {
                ""
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let opts = tobj::LoadOptions {
        single_index: true,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let internal = |what: String| SceneError::Obj {
        loc: Location::file(path),
        msg: format!(
            "internal error: the OBJ pre-scan accepted this file but {what}; please report it"
        ),
    };
    let (models, _) =
        tobj::load_obj_buf(&mut sanitized.as_bytes(), &opts, |_| Ok(Default::default()))
            .map_err(|e| internal(format!("tobj failed: {e}")))?;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces_out: Vec<ObjFace> = Vec::with_capacity(scan.faces.len());
    let mut scanned = scan.faces.into_iter();
    for m in &models {
        let mesh = &m.mesh;
        let base = positions.len() as u32;
        for p in mesh.positions.chunks_exact(3) {
            positions.push([p[0], p[1], p[2]]);
        }
        let n_pos = mesh.positions.len() / 3;
        let arities: Vec<u32> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.clone()
        };
        let mut k = 0usize;
        for a in arities {
            let a = a as usize;
            let Some(idx) = mesh.indices.get(k..k + a) else {
                return Err(internal("tobj returned fewer indices than faces".into()));
            };
            k += a;
            if a < 3 {
                continue;
            }
            let Some(mut f) = scanned.next() else {
                return Err(internal("tobj found more faces".into()));
            };
            if idx.iter().any(|&i| i as usize >= n_pos) {
                return Err(internal("tobj returned an index out of range".into()));
            }
            f.verts = idx.iter().map(|&i| base + i).collect();
            faces_out.push(f);
        }
    }
    if scanned.next().is_some() {
        return Err(internal("tobj found fewer faces".into()));
    }
    if positions.iter().flatten().any(|c| !c.is_finite()) {
        return Err(internal("a vertex is not finite after tobj".into()));
    }
    Ok(ObjMesh {
        path: path.to_path_buf(),
        positions,
        faces: faces_out,
        material_names: scan.names,
    })
}

fn prescan(path: &Path, text: &str) -> Result<Scan, SceneError> {
    let mut s = Scan {
        n_v: 0,
        n_vt: 0,
        n_vn: 0,
        n_colored: 0,
        first_uncolored: None,
        first_colored: None,
        faces: Vec::new(),
        names: Vec::new(),
    };
    let mut current: Option<u32> = None;
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
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
            "v" => {
                if !matches!(args.len(), 3 | 4 | 6) {
                    return Err(err(format!(
                        "vertex: expected `v x y z` (optionally a weight w, or a colour r g b), found {} numbers",
                        args.len()
                    )));
                }
                let mut vals = [0f64; 6];
                for (j, a) in args.iter().enumerate() {
                    let v = num(a).ok_or_else(|| err(format!("vertex: `{a}` is not a number")))?;
                    if !v.is_finite() || v.abs() > f32::MAX as f64 {
                        return Err(err(format!(
                            "vertex: coordinate `{a}` is NaN or infinite (or overflows 32-bit floating point): \
                             expected a finite number"
                        )));
                    }
                    vals[j] = v;
                }
                if args.len() == 4 {
                    let w = vals[3];
                    if w == 0.0 || (0..3).any(|j| !(vals[j] / w).is_finite()) {
                        return Err(err(format!(
                            "vertex: weight w = `{}` gives a non-finite position: expected a non-zero w",
                            args[3]
                        )));
                    }
                }
                if args.len() == 6 {
                    s.n_colored += 1;
                    s.first_colored.get_or_insert(ln);
                } else {
                    s.first_uncolored.get_or_insert(ln);
                }
                s.n_v += 1;
            }
            "vt" => {
                if args.len() < 2
                    || args.len() > 3
                    || args.iter().any(|a| num(a).is_none_or(|v| !v.is_finite()))
                {
                    return Err(err(
                        "texture coordinate: expected `vt u v [w]` with finite numbers".into(),
                    ));
                }
                s.n_vt += 1;
            }
            "vn" => {
                if args.len() != 3 || args.iter().any(|a| num(a).is_none_or(|v| !v.is_finite())) {
                    return Err(err("normal: expected `vn x y z` with finite numbers".into()));
                }
                s.n_vn += 1;
            }
            "f" => {
                if args.len() < 3 {
                    return Err(err(format!(
                        "face: expected at least 3 vertices, found {}",
                        args.len()
                    )));
                }
                for a in &args {
                    face_vertex(a, &s).map_err(|m| err(format!("face vertex `{a}`: {m}")))?;
                }
                s.faces.push(ObjFace {
                    verts: Vec::new(),
                    material: current,
                    line: ln,
                });
            }
            "o" | "g" => {}
            "usemtl" => {
                let name = line
                    .trim_start()
                    .strip_prefix("usemtl")
                    .unwrap_or("")
                    .trim();
                if name.is_empty() {
                    return Err(err("usemtl: expected a material name".into()));
                }
                let id = match s.names.iter().position(|(n, _)| n == name) {
                    Some(id) => id,
                    None => {
                        s.names.push((name.to_string(), ln));
                        s.names.len() - 1
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
    if s.n_colored > 0 && s.n_colored < s.n_v {
        let ln = s.first_uncolored.max(s.first_colored).unwrap_or(0);
        return Err(SceneError::Obj {
            loc: Location::line(path, ln),
            msg: "vertex colours (`v x y z r g b`) must be given on every vertex or on none".into(),
        });
    }
    Ok(s)
}

/// Parses a number the way tobj does (as f64: its `use_f64` feature).
fn num(s: &str) -> Option<f64> {
    s.parse::<f64>().ok()
}

/// Validates one `v[/vt][/vn]` face token against the counts so far.
fn face_vertex(tok: &str, s: &Scan) -> Result<(), String> {
    let parts: Vec<&str> = tok.split('/').collect();
    if parts.len() > 3 {
        return Err("expected v, v/vt, v//vn or v/vt/vn".into());
    }
    let kinds = [
        ("vertex", "vertices", s.n_v),
        ("texture coordinate", "texture coordinates", s.n_vt),
        ("normal", "normals", s.n_vn),
    ];
    for (j, p) in parts.iter().enumerate() {
        if p.is_empty() {
            if j == 0 {
                return Err("missing vertex index".into());
            }
            continue;
        }
        let (kind, plural, n) = kinds[j];
        let idx: i64 = p
            .parse()
            .map_err(|_| format!("`{p}` is not an integer {kind} index"))?;
        let ok = if idx > 0 {
            idx as u64 <= n as u64
        } else {
            idx < 0 && idx.unsigned_abs() <= n as u64
        };
        if !ok {
            return Err(format!(
                "{kind} index {idx} is out of range: {n} {plural} defined so far (indices are 1..={n} or -1..=-{n})"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(t: &str) -> Result<ObjMesh, String> {
        parse_obj(Path::new("m.obj"), t).map_err(|e| e.to_string())
    }

    #[test]
    fn parses_polygons_materials_and_relative_indices() {
        let m = parse(
            "# quad and triangle\nmtllib x.mtl\no part\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n\
             usemtl asphalt\nf 1//1 2//1 3//1 4//1\ns off\nusemtl grass\nf -4 -3 -2\nl 1 2 3\nusemtl asphalt\nf 1 3 4\n",
        )
        .unwrap();
        assert!(m.positions.len() >= 4);
        assert_eq!(m.faces.len(), 3);
        assert_eq!(m.faces[0].verts.len(), 4);
        assert_eq!(m.faces[0].line, 10);
        assert_eq!(m.faces[1].line, 13);
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
            parse("usemtl   \n").unwrap_err(),
            "m.obj:1: usemtl: expected a material name"
        );
        assert_eq!(
            parse("v 0 0 0\nf 1 1\n").unwrap_err(),
            "m.obj:2: face: expected at least 3 vertices, found 2"
        );
        assert_eq!(
            parse("v 0 0 0 1 1 1\nv 0 0 0\n").unwrap_err(),
            "m.obj:2: vertex colours (`v x y z r g b`) must be given on every vertex or on none"
        );
    }
}
