//! The one mesh type ([`Mesh`], [`Face`]): what the mesh readers
//! ([`super::obj`], [`super::gltf`]) and the terrain mesher
//! ([`crate::scene::terrain`]) produce, and the scene loader places, and its
//! triangulation. The readers import it from here, below them, so imports
//! run one way.

use std::path::PathBuf;

use super::triangulate;
use crate::scene::error::{Location, SceneError};
use crate::scene::spec::UpAxis;

/// One polygon face.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Vertex indices into [`Mesh::positions`] (>= 3, in file order);
    /// empty for a terrain cell, whose two triangles are made directly.
    pub verts: Vec<u32>,
    /// Index into [`Mesh::material_names`], or `None` when the face has
    /// no material of its own (before any OBJ `usemtl`).
    pub material: Option<u32>,
    /// Where the face is written ([`Mesh::place`]): its 1-based OBJ line,
    /// or for glTF an index into [`Mesh::parts`]; for a terrain its grid
    /// cell (row-major), as is its index.
    pub src: usize,
}

/// A mesh's faces in its own coordinates: a mesh file's (model
/// coordinates), or a terrain's (scene coordinates, m; one face per grid
/// cell, a hole a face with no material and no triangles). The loader
/// places every mesh the same way: the triangles with their face's
/// material and the face's index as facet id, zero-area ones left out.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Mesh {
    /// The file it was read from (a terrain: its DEM).
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
    /// face, in face order; filled by [`Mesh::triangulate`] (a terrain:
    /// by the mesher, counter-clockwise seen from above).
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
        let suggestion = crate::scene::error::closest(first, library.iter().copied())
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
