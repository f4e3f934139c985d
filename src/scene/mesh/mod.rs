//! Mesh files of `[[object]]`: Wavefront OBJ ([`obj`]) and glTF 2.0
//! ([`gltf`]: `.gltf`, `.glb`) read into one polygon soup ([`Mesh`]) in the
//! file's own coordinates, with every face triangulated ([`triangulate`]). The scene loader places a mesh with
//! the object's transform and maps its material names to the libraries'.
//! Other geometry sources (terrain) can build a [`Mesh`] directly and
//! call [`Mesh::triangulate`].

pub mod gltf;
pub mod obj;
pub mod triangulate;

use std::path::{Path, PathBuf};

use super::error::{Location, SceneError};
use super::spec::UpAxis;

/// One polygon face.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Vertex indices into [`Mesh::positions`] (>= 3, in file order).
    pub verts: Vec<u32>,
    /// Index into [`Mesh::material_names`], or `None` when the face has
    /// no material of its own (before any OBJ `usemtl`).
    pub material: Option<u32>,
    /// Where the face is written ([`Mesh::place`]): its 1-based OBJ line,
    /// or for glTF an index into [`Mesh::parts`].
    pub src: usize,
}

/// A mesh file's faces in its own (model) coordinates.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Mesh {
    pub path: PathBuf,
    /// Vertex positions as written (in double precision, so that
    /// projected coordinates such as UTM keep their millimetres).
    pub positions: Vec<[f64; 3]>,
    /// Faces in file order (face `i` is facet `i` of the object).
    pub faces: Vec<Face>,
    /// Distinct material names in order of first use, with where that use
    /// is written (as [`Face::src`]).
    pub material_names: Vec<(String, usize)>,
    /// glTF: what each [`Face::src`] is (node, mesh, primitive); empty for
    /// OBJ, whose `src` are lines.
    pub parts: Vec<String>,
    /// Triangles (indices into `positions`, the face's winding) of every
    /// face, in face order; filled by [`Mesh::triangulate`].
    pub triangles: Vec<[u32; 3]>,
    /// The face of each triangle.
    pub tri_face: Vec<u32>,
    /// Things worth a note that do not stop the load (e.g. objects or
    /// groups with no faces), each naming the file.
    pub warnings: Vec<String>,
    /// The format's up axis, used when the scene gives no `up_axis`: +z
    /// (irsig's own frame) for OBJ, which has no convention; +y for glTF
    /// (glTF 2.0 §3.4: +Y up, metres, right-handed).
    pub default_up: UpAxis,
}

impl Mesh {
    /// Where a face or material use is written, for messages: `file:line`
    /// (OBJ) or `file: node `n` (mesh `m`, primitive k)` (glTF).
    pub fn place(&self, src: usize) -> String {
        match self.parts.get(src) {
            Some(part) => format!("{}: {part}", self.path.display()),
            None => Location::line(&self.path, src).to_string(),
        }
    }

    /// An error about a face or material use at `src`.
    pub fn error(&self, src: usize, msg: String) -> SceneError {
        match self.parts.get(src) {
            Some(part) => SceneError::Obj {
                loc: Location::file(&self.path),
                msg: format!("{part}: {msg}"),
            },
            None => SceneError::Obj {
                loc: Location::line(&self.path, src),
                msg,
            },
        }
    }

    /// The error for mesh material names (indices into
    /// [`Mesh::material_names`]) that neither the object's `materials`
    /// map, nor a library, nor a `*` entry resolves: it points at the
    /// first one's use, lists them all with theirs, the libraries'
    /// materials, and how to map them (at `object`, the `[[object]]`).
    pub fn unmapped_error(
        &self,
        unmapped: &[usize],
        library: &[&str],
        libraries: &[PathBuf],
        object: &Location,
    ) -> SceneError {
        let (first, src) = &self.material_names[unmapped[0]];
        let suggestion = super::error::closest(first, library.iter().copied())
            .map(|s| format!("; did you mean `{s}`?"))
            .unwrap_or_else(|| ".".to_string());
        let names: Vec<String> = unmapped
            .iter()
            .map(|&k| {
                let (name, src) = &self.material_names[k];
                format!("`{name}` ({})", self.place(*src))
            })
            .collect();
        let files: Vec<String> = libraries
            .iter()
            .map(|p| format!("`{}`", p.display()))
            .collect();
        self.error(
            *src,
            format!(
                "material `{first}` is not defined in the material libraries {}{suggestion} \
                 Unmapped material names of this file: {}. The libraries define: {}. Expected \
                 each name in a library, or mapped by the object's `materials` table ({object}), \
                 e.g. `materials = {{ \"{first}\" = \"{}\", \"*\" = \"{}\" }}` (`*`: every other name)",
                if files.is_empty() { "(none given)".to_string() } else { files.join(", ") },
                names.join(", "),
                library.join(", "),
                library.first().unwrap_or(&"concrete"),
                library.last().unwrap_or(&"concrete"),
            ),
        )
    }

    /// Splits every face into triangles ([`triangulate::triangulate`]);
    /// a self-intersecting face is an error naming its line.
    pub fn triangulate(&mut self) -> Result<(), SceneError> {
        self.triangles.clear();
        self.tri_face.clear();
        let mut pts = Vec::new();
        for (fi, f) in self.faces.iter().enumerate() {
            pts.clear();
            pts.extend(
                f.verts
                    .iter()
                    .map(|&v| glam::DVec3::from(self.positions[v as usize])),
            );
            let tris = triangulate::triangulate(&pts)
                .map_err(|e| self.error(f.src, format!("face: {e}")))?;
            for t in tris {
                self.triangles.push(t.map(|k| f.verts[k]));
                self.tri_face.push(fi as u32);
            }
        }
        Ok(())
    }
}

/// Reads a mesh file, chosen by its extension (`.obj`, `.gltf`, `.glb`;
/// any other that starts with the GLB magic `glTF` is read as GLB), and
/// triangulates it.
pub fn load(path: &Path) -> Result<Mesh, SceneError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut mesh = match ext.as_str() {
        "obj" => obj::load_obj(path)?,
        "gltf" | "glb" => self::gltf::load_gltf(path)?,
        _ if is_glb(path) => self::gltf::load_gltf(path)?,
        _ => {
            return Err(SceneError::Obj {
                loc: Location::file(path),
                msg: format!(
                    "unknown mesh file type `{}`: expected a Wavefront OBJ file (.obj) or \
                     glTF 2.0 (.gltf, .glb)",
                    if ext.is_empty() { "(none)" } else { &ext }
                ),
            });
        }
    };
    mesh.triangulate()?;
    Ok(mesh)
}

/// Whether a file starts with the GLB magic (a missing or unreadable file
/// is not: the loader then reports it as of unknown type).
fn is_glb(path: &Path) -> bool {
    use std::io::Read;
    let mut magic = [0u8; 4];
    crate::files::check_regular(path, crate::bounds::sizes::MAX_MESH_FILE_BYTES)
        .and_then(|_| std::fs::File::open(path))
        .and_then(|mut f| f.read_exact(&mut magic))
        .is_ok_and(|()| &magic == b"glTF")
}

/// The text of a file that may be UTF-8 (with or without a byte-order
/// mark), UTF-16 with a byte-order mark, or else Latin-1 (ISO 8859-1, as
/// older exporters write accented names): every byte is then the code
/// point of the same value, so nothing is lost or refused.
pub fn decode_text(bytes: &[u8]) -> String {
    if let Some(rest) = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF])
        && let Ok(t) = std::str::from_utf8(rest)
    {
        return t.to_string();
    }
    let utf16 = |be: bool| {
        let units: Vec<u16> = bytes[2..]
            .chunks_exact(2)
            .map(|c| {
                if be {
                    u16::from_be_bytes([c[0], c[1]])
                } else {
                    u16::from_le_bytes([c[0], c[1]])
                }
            })
            .collect();
        String::from_utf16(&units).ok()
    };
    let decoded = match bytes {
        [0xFE, 0xFF, ..] => utf16(true),
        [0xFF, 0xFE, ..] => utf16(false),
        _ => None,
    };
    if let Some(t) = decoded {
        return t;
    }
    match std::str::from_utf8(bytes) {
        Ok(t) => t.to_string(),
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_encodings() {
        assert_eq!(decode_text(b"usemtl a\n"), "usemtl a\n");
        assert_eq!(decode_text(b"\xEF\xBB\xBFv 1"), "v 1");
        assert_eq!(decode_text(b"Mat\xE9riau"), "Matériau");
        assert_eq!(decode_text("Matériau".as_bytes()), "Matériau");
        assert_eq!(decode_text(b"\xFE\xFF\x00v\x00 \x001"), "v 1");
        assert_eq!(decode_text(b"\xFF\xFEv\x00 \x001\x00"), "v 1");
    }
}
