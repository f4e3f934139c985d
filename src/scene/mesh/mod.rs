//! Mesh files of `[[object]]`: Wavefront OBJ ([`obj`]) and glTF 2.0
//! ([`gltf`]: `.gltf`, `.glb`) read into one polygon soup ([`Mesh`]) in the
//! file's own coordinates, with every face triangulated ([`triangulate`]). The scene loader places a mesh with
//! the object's transform and maps its material names to the libraries'.
//! The terrain mesher ([`crate::scene::terrain`]) builds the same [`Mesh`]
//! directly: one mesh type for every geometry source.

pub mod gltf;
pub mod obj;
mod soup;
mod text;
pub mod triangulate;

use std::path::Path;

pub use soup::{Face, Mesh};
pub use text::decode_text;

use super::error::{Location, SceneError};

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
