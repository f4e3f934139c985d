//! glTF 2.0 (Khronos, <https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html>):
//! `.gltf` JSON with its buffers in external files or embedded `data:` URIs,
//! and binary `.glb`, parsed and validated by the `gltf` crate.
//!
//! The default scene (else scene 0; else, with no scenes, every root node)
//! is walked down its node tree; each node's local transform (matrix, or
//! translation · rotation · scale, §3.5.2) is composed with its parents' in
//! double precision and baked into the positions, so a mesh used by several
//! nodes is one instance per node, each with its own [`Mesh::parts`]
//! entries (`node n (mesh m, primitive k)`). Triangle lists, strips and fans
//! (§3.7.2.1) are read, with or without indices, sparse accessors included;
//! points and lines are skipped with a warning; cameras and lights are not
//! geometry. A node whose transform mirrors (negative determinant) has its
//! triangles' winding reversed, as the specification requires (§3.7.2.1),
//! so that faces keep their outward side.
//!
//! Material names are the glTF materials' `name` (`material<index>` when it
//! has none; a primitive without a material has none, like OBJ faces before
//! any `usemtl`), mapped by the scene like OBJ names. Textures, skins
//! (meshes are placed in their bind pose), morph targets and animations are
//! ignored, with a warning for the last three. Required extensions that
//! change how geometry is stored (Draco, meshopt, mesh quantization, GPU
//! instancing) are refused; any other required extension only changes
//! appearance and is ignored with a warning.
//!
//! Nothing is read from the network: `http(s)` and other URI schemes are
//! refused. Every error names the file and the node, mesh and primitive, the
//! buffer, or the JSON line and column.

use std::path::Path;

use ::gltf as gl;
use gl::accessor::{DataType, Dimensions};
use gl::mesh::Mode;
use glam::{DAffine3, DMat4, DQuat, DVec3};

use super::soup::{Face, Mesh};
use crate::scene::error::{Location, SceneError};
use crate::scene::spec::UpAxis;

/// Required extensions that change how geometry is stored: a file needing
/// one cannot be read correctly without it.
const GEOMETRY_EXTENSIONS: &[(&str, &str)] = &[
    ("KHR_draco_mesh_compression", "Draco-compressed meshes"),
    ("EXT_meshopt_compression", "meshopt-compressed buffers"),
    (
        "KHR_mesh_quantization",
        "quantized (integer) vertex positions",
    ),
    ("EXT_mesh_gpu_instancing", "GPU instancing of meshes"),
];

/// The most elements an accessor without a buffer view (zeros, §3.6.2.4,
/// perhaps with sparse substitutions) may have: nothing in the file bounds
/// them otherwise.
const MAX_ZERO_FILLED: usize = 1 << 24;

/// Reads a `.gltf` or `.glb` file and its buffers.
pub fn load_gltf(path: &Path) -> Result<Mesh, SceneError> {
    let bytes = SceneError::read_bytes(path, crate::bounds::sizes::MAX_MESH_FILE_BYTES)?;
    parse_gltf(path, &bytes)
}

/// Parses glTF JSON or GLB bytes (told apart by the GLB magic `glTF`);
/// external buffers are read relative to `path`'s folder.
pub fn parse_gltf(path: &Path, bytes: &[u8]) -> Result<Mesh, SceneError> {
    let fail = |msg: String| SceneError::Obj {
        loc: Location::file(path),
        msg,
    };
    let glb = bytes.starts_with(b"glTF");
    if glb {
        check_glb_header(bytes).map_err(fail)?;
    } else if let Some(what) = not_gltf(bytes) {
        return Err(fail(format!(
            "not a glTF file: it {what}; expected a binary glTF (GLB, starting with `glTF`) or \
             glTF JSON (starting with `{{`)"
        )));
    }
    let gltf =
        gl::Gltf::from_slice_without_validation(bytes).map_err(|e| crate_error(path, glb, e))?;
    let blob = gltf.blob;
    let mut root = gltf.document.into_json();
    let mut warnings = Vec::new();
    // Extensions the crate does not implement fail its validation; those
    // that only change appearance are dropped here (with a warning) and
    // those that store geometry differently are refused.
    for ext in std::mem::take(&mut root.extensions_required) {
        if let Some((_, what)) = GEOMETRY_EXTENSIONS.iter().find(|(e, _)| *e == ext) {
            return Err(fail(format!(
                "the file requires the extension `{ext}` ({what}), which irsig does not read; \
                 expected plain glTF 2.0 geometry: re-export without it (e.g. `gltf-transform \
                 cp` or Blender's exporter with compression off)"
            )));
        }
        warnings.push(format!(
            "{}: the required glTF extension `{ext}` is ignored: it does not change geometry, \
             and irsig takes materials from its libraries",
            path.display()
        ));
    }
    check_position_indices(&root).map_err(fail)?;
    let doc = gl::Document::from_json(root).map_err(|e| crate_error(path, glb, e))?;
    // The crate keeps node transforms in single precision; they are read
    // again here in double (georeferenced models put large offsets there).
    let json = if glb {
        gl::binary::Glb::from_slice(bytes)
            .map_err(|e| crate_error(path, glb, e))?
            .json
    } else {
        std::borrow::Cow::Borrowed(bytes)
    };
    let nodes = serde_json::from_slice::<RawRoot>(&json)
        .map_err(|e| crate_error(path, glb, gl::Error::Deserialize(e)))?
        .nodes;
    let mut reader = Reader {
        path,
        nodes,
        dir: path.parent().unwrap_or(Path::new("")),
        doc: &doc,
        blob,
        buffers: vec![None; doc.buffers().count()],
        mesh: Mesh {
            path: path.to_path_buf(),
            default_up: UpAxis::Y,
            ..Mesh::default()
        },
        skipped: Vec::new(),
        skinned: false,
        morphed: false,
    };
    reader.read_scene()?;
    let mut m = reader.mesh;
    let file = path.display();
    if reader.skinned {
        warnings.push(format!(
            "{file}: skins are ignored: skinned meshes are placed in their bind pose"
        ));
    }
    if reader.morphed {
        warnings.push(format!(
            "{file}: morph targets are ignored: meshes are placed in their base shape"
        ));
    }
    if doc.animations().next().is_some() {
        warnings.push(format!(
            "{file}: animations are ignored: nodes are placed by their own (static) transforms"
        ));
    }
    if !reader.skipped.is_empty() {
        warnings.push(format!(
            "{file}: point and line primitives skipped (not surfaces): {}",
            reader.skipped.join(", ")
        ));
    }
    m.warnings = warnings;
    let has_area = m.faces.iter().any(|f| {
        let [a, b, c] = [0, 1, 2].map(|k| DVec3::from(m.positions[f.verts[k] as usize]));
        (b - a).cross(c - a).length() > 0.0
    });
    if !has_area {
        return Err(fail(format!(
            "no triangle with an area in the scene's meshes ({} triangles{}; {} point or line \
             primitives skipped): expected at least one surface",
            m.faces.len(),
            if m.faces.is_empty() {
                ""
            } else {
                ", all degenerate"
            },
            reader.skipped.len()
        )));
    }
    Ok(m)
}

/// What a file that is neither GLB nor JSON looks like, from its first
/// bytes (a TIFF or PNG renamed `.glb`, an OBJ, a gzip or zip archive…);
/// `None` when it may be glTF JSON (its first character, after a
/// byte-order mark and white space, is `{`) and the JSON parser is to say
/// what is wrong with it.
fn not_gltf(b: &[u8]) -> Option<String> {
    let t = b.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(b);
    let first = t.iter().find(|c| !c.is_ascii_whitespace());
    if first == Some(&b'{') {
        return None;
    }
    let kinds: [(&[u8], &str); 10] = [
        (b"II*\0", "is a TIFF image (little-endian)"),
        (b"MM\0*", "is a TIFF image (big-endian)"),
        (b"II+\0", "is a BigTIFF image"),
        (b"\x89PNG", "is a PNG image"),
        (b"\xff\xd8\xff", "is a JPEG image"),
        (b"\x1f\x8b", "is gzip-compressed"),
        (b"PK\x03\x04", "is a zip archive"),
        (b"%PDF", "is a PDF document"),
        (b"\x76\x2f\x31\x01", "is an OpenEXR image"),
        (b"ply", "is a PLY mesh"),
    ];
    if let Some((_, what)) = kinds.iter().find(|(m, _)| t.starts_with(m)) {
        return Some(what.to_string());
    }
    if t.is_empty() {
        return Some("is empty".into());
    }
    let text = std::str::from_utf8(&t[..t.len().min(4096)]).is_ok_and(|s| {
        s.chars()
            .all(|c| !c.is_control() || c.is_ascii_whitespace())
    });
    if text {
        let obj = t
            .split(|&c| c == b'\n')
            .any(|l| l.starts_with(b"v ") || l.starts_with(b"f "));
        return Some(if obj {
            "is text with OBJ vertex or face lines (an OBJ mesh: name it `.obj`)".into()
        } else {
            "is text that is not JSON".into()
        });
    }
    Some(format!(
        "is binary data starting with the bytes {}",
        t.iter()
            .take(4)
            .map(|c| format!("{c:02x}"))
            .collect::<Vec<_>>()
            .join(" ")
    ))
}

/// The GLB header (magic, version, length: 12 bytes) and the first chunk
/// header, checked before the crate splits the file (it subtracts the
/// header size from the declared length unchecked).
fn check_glb_header(b: &[u8]) -> Result<(), String> {
    let word = |k: usize| {
        b.get(4 * k..4 * k + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let (Some(version), Some(length)) = (word(1), word(2)) else {
        return Err(format!(
            "truncated GLB: {} bytes, shorter than its 12-byte header",
            b.len()
        ));
    };
    if version != 2 {
        return Err(format!(
            "GLB version {version}: expected 2 (glTF 2.0; version 1 is the obsolete glTF 1.0)"
        ));
    }
    if (length as usize) < 20 {
        return Err(format!(
            "GLB header declares {length} bytes, less than a header and a JSON chunk header (20)"
        ));
    }
    if length as usize > b.len() {
        return Err(format!(
            "truncated GLB: the header declares {length} bytes, the file has {}",
            b.len()
        ));
    }
    Ok(())
}

/// POSITION accessor indices in range: gltf-json 1.4.1's validation looks
/// the POSITION accessor up before it checks the index (a panic otherwise,
/// found by the fuzz campaign).
fn check_position_indices(root: &gl::json::Root) -> Result<(), String> {
    let position = gl::json::validation::Checked::Valid(gl::json::mesh::Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(i) = prim.attributes.get(&position)
                && i.value() >= root.accessors.len()
            {
                return Err(format!(
                    "invalid glTF: `meshes[{m}].primitives[{p}].attributes[\"POSITION\"]`: \
                     accessor {} does not exist (the file has {})",
                    i.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// A `gltf` crate error as a scene error: JSON syntax or type errors at
/// their line and column (of the file, or of the GLB's JSON chunk),
/// validation errors with their JSON path.
fn crate_error(path: &Path, glb: bool, e: gl::Error) -> SceneError {
    let (loc, msg) = match e {
        gl::Error::Deserialize(j) if !glb => (
            Location {
                file: path.to_path_buf(),
                line: j.line(),
                col: j.column(),
                via: None,
            },
            format!("invalid glTF JSON: {j}"),
        ),
        gl::Error::Deserialize(j) => (
            Location::file(path),
            format!("invalid glTF JSON in the GLB's JSON chunk: {j}"),
        ),
        gl::Error::Validation(errors) => {
            let listed: Vec<String> = errors
                .iter()
                .take(8)
                .map(|(p, e)| format!("`{p}`: {e}"))
                .collect();
            (
                Location::file(path),
                format!(
                    "invalid glTF: {}{}",
                    listed.join("; "),
                    if errors.len() > 8 {
                        format!(" (and {} more)", errors.len() - 8)
                    } else {
                        String::new()
                    }
                ),
            )
        }
        gl::Error::Binary(b) => (Location::file(path), format!("invalid GLB: {b}")),
        e => (Location::file(path), format!("invalid glTF: {e}")),
    };
    SceneError::Obj { loc, msg }
}

/// The JSON's nodes (only their transforms), in double precision.
#[derive(serde::Deserialize)]
struct RawRoot {
    #[serde(default)]
    nodes: Vec<RawNode>,
}

/// A node's transform as written: a column-major matrix, or translation,
/// rotation (unit quaternion x, y, z, w) and scale.
#[derive(serde::Deserialize)]
struct RawNode {
    matrix: Option<[f64; 16]>,
    translation: Option<[f64; 3]>,
    rotation: Option<[f64; 4]>,
    scale: Option<[f64; 3]>,
}

/// The walk over one document.
struct Reader<'a> {
    path: &'a Path,
    nodes: Vec<RawNode>,
    dir: &'a Path,
    doc: &'a gl::Document,
    /// The GLB's BIN chunk.
    blob: Option<Vec<u8>>,
    /// Buffer bytes, read when first needed.
    buffers: Vec<Option<Vec<u8>>>,
    mesh: Mesh,
    /// Point and line primitives skipped: their parts and modes.
    skipped: Vec<String>,
    skinned: bool,
    morphed: bool,
}

impl Reader<'_> {
    fn fail(&self, msg: String) -> SceneError {
        SceneError::Obj {
            loc: Location::file(self.path),
            msg,
        }
    }

    /// The nodes of the default scene (else scene 0, else the root nodes),
    /// walked depth-first with their world transforms.
    fn read_scene(&mut self) -> Result<(), SceneError> {
        let doc = self.doc;
        let roots: Vec<gl::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s.nodes().collect(),
            None => {
                let mut child = vec![false; doc.nodes().count()];
                for n in doc.nodes() {
                    for c in n.children() {
                        child[c.index()] = true;
                    }
                }
                let roots: Vec<gl::Node> = doc.nodes().filter(|n| !child[n.index()]).collect();
                if roots.is_empty() {
                    return Err(self.fail(
                        "no scene and no root node: expected a `scenes` entry or nodes to place"
                            .into(),
                    ));
                }
                roots
            }
        };
        let mut seen = vec![false; doc.nodes().count()];
        let mut stack: Vec<(gl::Node, DMat4)> = roots
            .into_iter()
            .rev()
            .map(|n| (n, DMat4::IDENTITY))
            .collect();
        while let Some((node, parent)) = stack.pop() {
            let n = node.index();
            if std::mem::replace(&mut seen[n], true) {
                return Err(self.fail(format!(
                    "node {n} is reached twice from the scene: glTF nodes must form trees \
                     (each node at most one parent, no cycles; glTF 2.0 §3.5.3)"
                )));
            }
            let world = parent * self.local_transform(&node)?;
            if let Some(mesh) = node.mesh() {
                self.skinned |= node.skin().is_some();
                self.place_mesh(&node, &mesh, &world)?;
            }
            for c in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((c, world));
            }
        }
        Ok(())
    }

    /// A node's local transform: its matrix (column-major), or T · R · S
    /// with the rotation quaternion normalised (glTF 2.0 §3.5.2), in double
    /// precision as written in the JSON.
    fn local_transform(&self, node: &gl::Node) -> Result<DMat4, SceneError> {
        let n = node.index();
        let bad = |what: String| self.fail(format!("node {n}: {what}"));
        let raw = self
            .nodes
            .get(n)
            .ok_or_else(|| bad("missing from the JSON".into()))?;
        let m = match raw.matrix {
            Some(matrix) => {
                let m = DMat4::from_cols_array(&matrix);
                if m.row(3) != glam::DVec4::W {
                    return Err(bad(format!(
                        "`matrix` has the last row {:?}: expected (0, 0, 0, 1), an affine transform",
                        m.row(3).to_array()
                    )));
                }
                m
            }
            None => {
                let rotation = raw.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0]);
                let q = DQuat::from_array(rotation);
                let len = q.length();
                if !(len.is_finite() && len > 1e-6) {
                    return Err(bad(format!(
                        "`rotation` {rotation:?} is not a unit quaternion (x, y, z, w)"
                    )));
                }
                DMat4::from_scale_rotation_translation(
                    DVec3::from_array(raw.scale.unwrap_or([1.0; 3])),
                    q / len,
                    DVec3::from_array(raw.translation.unwrap_or([0.0; 3])),
                )
            }
        };
        if !m.is_finite() {
            return Err(bad("its transform has a non-finite value".into()));
        }
        Ok(m)
    }

    /// Appends every primitive of `mesh` as placed by `node`'s world
    /// transform.
    fn place_mesh(
        &mut self,
        node: &gl::Node,
        mesh: &gl::Mesh,
        world: &DMat4,
    ) -> Result<(), SceneError> {
        let xf = DAffine3::from_mat4(*world);
        let mirrored = xf.matrix3.determinant() < 0.0;
        let named = |kind: &str, i: usize, name: Option<&str>| match name {
            Some(s) => format!("{kind} {i} `{s}`"),
            None => format!("{kind} {i}"),
        };
        for prim in mesh.primitives() {
            let part = format!(
                "{} ({}, primitive {})",
                named("node", node.index(), node.name()),
                named("mesh", mesh.index(), mesh.name()),
                prim.index()
            );
            let src = self.mesh.parts.len();
            self.mesh.parts.push(part);
            self.morphed |= prim.morph_targets().next().is_some();
            let mode = prim.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                let part = &self.mesh.parts[src];
                self.skipped.push(format!("{part}: {mode:?}"));
                continue;
            }
            let err = |r: &Self, msg: String| r.mesh.error(src, msg);
            let Some(pos) = prim.get(&gl::Semantic::Positions) else {
                return Err(err(self, "the primitive has no POSITION attribute".into()));
            };
            self.check_accessor(&pos, Dimensions::Vec3, &[DataType::F32])
                .map_err(|e| err(self, format!("POSITION accessor {}: {e}", pos.index())))?;
            let indices = prim.indices();
            if let Some(acc) = &indices {
                self.check_accessor(
                    acc,
                    Dimensions::Scalar,
                    &[DataType::U8, DataType::U16, DataType::U32],
                )
                .map_err(|e| err(self, format!("indices accessor {}: {e}", acc.index())))?;
            }
            let buffers = &self.buffers;
            let read = prim.reader(|b| buffers.get(b.index()).and_then(|d| d.as_deref()));
            // No buffer view and no sparse values: all zeros (§3.6.2.4).
            let positions: Vec<[f32; 3]> = match read.read_positions() {
                Some(it) => it.collect(),
                None => vec![[0.0; 3]; pos.count()],
            };
            let n_vert = positions.len();
            if n_vert != pos.count() {
                return Err(err(
                    self,
                    format!(
                        "POSITION accessor {} has {n_vert} of its {} vertices in its buffer",
                        pos.index(),
                        pos.count()
                    ),
                ));
            }
            if let Some(k) = positions
                .iter()
                .position(|p| !p.iter().all(|v| v.is_finite()))
            {
                return Err(err(
                    self,
                    format!(
                        "vertex {k} (POSITION accessor {}) is {:?}: expected finite numbers",
                        pos.index(),
                        positions[k]
                    ),
                ));
            }
            let idx: Vec<u32> = match (&indices, read.read_indices()) {
                (None, _) => (0..n_vert as u32).collect(),
                (Some(_), Some(r)) => r.into_u32().collect(),
                (Some(acc), None) => vec![0; acc.count()],
            };
            if let Some(k) = idx.iter().position(|&v| v as usize >= n_vert) {
                return Err(err(
                    self,
                    format!(
                        "index {k} is {}, out of range: POSITION has {n_vert} vertices",
                        idx[k]
                    ),
                ));
            }
            let tris = triangles(mode, &idx).map_err(|e| err(self, e))?;
            let material = prim.material().index().map(|i| {
                let name = prim
                    .material()
                    .name()
                    .map_or_else(|| format!("material{i}"), str::to_string);
                let names = &mut self.mesh.material_names;
                match names.iter().position(|(n, _)| *n == name) {
                    Some(k) => k as u32,
                    None => {
                        names.push((name, src));
                        (names.len() - 1) as u32
                    }
                }
            });
            let base = self.mesh.positions.len() as u32;
            self.mesh.positions.extend(positions.iter().map(|p| {
                xf.transform_point3(DVec3::from_array(p.map(f64::from)))
                    .to_array()
            }));
            for t in tris {
                let [a, b, c] = t.map(|v| base + v);
                self.mesh.faces.push(Face {
                    verts: if mirrored {
                        vec![a, c, b]
                    } else {
                        vec![a, b, c]
                    },
                    material,
                    src,
                });
            }
        }
        Ok(())
    }

    /// Checks that the crate's reader stays inside the buffers when it reads
    /// `acc` (it slices without bound checks and asserts on the element
    /// type): the element type, a count of at least 1, a stride no smaller
    /// than an element, and every byte range of the dense and the sparse
    /// part inside its buffer view and buffer (in checked arithmetic).
    /// Reads the buffers it needs.
    fn check_accessor(
        &mut self,
        acc: &gl::Accessor,
        dims: Dimensions,
        types: &[DataType],
    ) -> Result<(), String> {
        if acc.dimensions() != dims || !types.contains(&acc.data_type()) {
            let quantized = acc.dimensions() == dims && dims == Dimensions::Vec3;
            return Err(format!(
                "{:?} of {:?}: expected {dims:?} of {}{}",
                acc.dimensions(),
                acc.data_type(),
                types
                    .iter()
                    .map(|t| format!("{t:?}"))
                    .collect::<Vec<_>>()
                    .join(" or "),
                if quantized {
                    " (integer positions need KHR_mesh_quantization, which irsig does not read)"
                } else {
                    ""
                }
            ));
        }
        if acc.count() == 0 {
            return Err("`count` is 0: expected at least 1".into());
        }
        let elem = acc.size();
        if acc.view().is_none() && acc.count() > MAX_ZERO_FILLED {
            return Err(format!(
                "{} elements without a `bufferView` (all zeros): expected at most {MAX_ZERO_FILLED}",
                acc.count()
            ));
        }
        if let Some(view) = acc.view() {
            self.check_range(&view, acc.offset(), acc.count(), elem)
                .map_err(|e| format!("buffer view {}: {e}", view.index()))?;
        }
        if let Some(sparse) = acc.sparse() {
            let n = sparse.count();
            if n == 0 || n > acc.count() {
                return Err(format!(
                    "sparse `count` {n}: expected 1 to the accessor's count {}",
                    acc.count()
                ));
            }
            let ind = sparse.indices();
            let size = match ind.index_type() {
                gl::accessor::sparse::IndexType::U8 => 1,
                gl::accessor::sparse::IndexType::U16 => 2,
                gl::accessor::sparse::IndexType::U32 => 4,
            };
            self.check_range(&ind.view(), ind.offset(), n, size)
                .map_err(|e| format!("sparse indices, buffer view {}: {e}", ind.view().index()))?;
            let val = sparse.values();
            self.check_range(&val.view(), val.offset(), n, elem)
                .map_err(|e| format!("sparse values, buffer view {}: {e}", val.view().index()))?;
        }
        Ok(())
    }

    /// `count` elements of `elem` bytes from `offset` in `view` (at the
    /// view's stride) lie inside the view, and the view inside its buffer.
    fn check_range(
        &mut self,
        view: &gl::buffer::View,
        offset: usize,
        count: usize,
        elem: usize,
    ) -> Result<(), String> {
        let stride = view.stride().unwrap_or(elem);
        if stride < elem {
            return Err(format!(
                "`byteStride` {stride} is smaller than an element ({elem} bytes)"
            ));
        }
        let end = (count - 1)
            .checked_mul(stride)
            .and_then(|s| s.checked_add(offset))
            .and_then(|s| s.checked_add(elem));
        if end.is_none_or(|e| e > view.length()) {
            return Err(format!(
                "{count} elements of {elem} bytes every {stride} from byte {offset} overrun its \
                 `byteLength` {}",
                view.length()
            ));
        }
        let buffer = view.buffer();
        let data_len = self.buffer(&buffer)?.len();
        let view_end = view.offset().checked_add(view.length());
        if view_end.is_none_or(|e| e > data_len) {
            return Err(format!(
                "bytes {} + {} overrun buffer {} ({data_len} bytes)",
                view.offset(),
                view.length(),
                buffer.index()
            ));
        }
        Ok(())
    }

    /// The bytes of a buffer: the GLB's BIN chunk, a base64 `data:` URI, or
    /// a file relative to the glTF file (its URI percent-decoded); at least
    /// its declared `byteLength`.
    fn buffer(&mut self, buffer: &gl::Buffer) -> Result<&[u8], String> {
        let k = buffer.index();
        if self.buffers[k].is_none() {
            let data = match buffer.source() {
                gl::buffer::Source::Bin if k > 0 => {
                    return Err(format!(
                        "buffer {k} has no `uri`: expected one (only buffer 0 may be the GLB's \
                         BIN chunk)"
                    ));
                }
                gl::buffer::Source::Bin => self.blob.take().ok_or_else(|| {
                    format!("buffer {k} is the GLB's BIN chunk, which the file does not have")
                })?,
                gl::buffer::Source::Uri(uri) => {
                    read_uri(self.dir, uri).map_err(|e| format!("buffer {k}: {e}"))?
                }
            };
            if data.len() < buffer.length() {
                return Err(format!(
                    "buffer {k} holds {} bytes, less than its `byteLength` {}",
                    data.len(),
                    buffer.length()
                ));
            }
            self.buffers[k] = Some(data);
        }
        Ok(self.buffers[k].as_deref().unwrap_or_default())
    }
}

/// A buffer URI's bytes: `data:…;base64,…`, or a relative (or `file:`)
/// path inside the glTF file's folder tree (the project's one path policy,
/// [`crate::files::within`] with no further allowed folder: no path outside
/// it, no `..` above it, no symbolic link out of it); no
/// network scheme. Nothing of a refused file is read, so no error can show
/// its bytes.
fn read_uri(dir: &Path, uri: &str) -> Result<Vec<u8>, String> {
    use base64::Engine;
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((header, data)) = rest.split_once(',') else {
            return Err("`data:` URI without a `,` before its data".into());
        };
        if !header.ends_with(";base64") {
            return Err(format!(
                "`data:{header},…` URI is not base64: expected `data:application/octet-stream;base64,…`"
            ));
        }
        let engine = base64::engine::GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            base64::engine::GeneralPurposeConfig::new()
                .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
        );
        return engine
            .decode(data.trim())
            .map_err(|e| format!("`data:` URI is not valid base64: {e}"));
    }
    let scheme = uri.split_once(':').map(|(s, _)| s).filter(|s| {
        s.len() > 1
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    let rel = match scheme {
        Some(s) if s.eq_ignore_ascii_case("file") => {
            uri[5..].strip_prefix("//").unwrap_or(&uri[5..])
        }
        Some(s) => {
            return Err(format!(
                "`{uri}` is a `{s}:` URI: irsig reads no network or other remote resources; \
                 expected a path relative to the glTF file or a `data:` URI (download the \
                 file next to the glTF and point `uri` at it)"
            ));
        }
        None => uri,
    };
    let rel = percent_encoding::percent_decode_str(rel)
        .decode_utf8()
        .map_err(|e| format!("URI `{uri}` decodes to invalid UTF-8: {e}"))?;
    let file = crate::files::within(dir, Path::new(&*rel), &[]).map_err(|why| {
        format!(
            "URI `{uri}` {why}: a model may only refer to files in its own folder or below \
             (docs/reliability.md, path policy)"
        )
    })?;
    crate::files::read(&file, crate::bounds::sizes::MAX_MESH_FILE_BYTES)
        .map_err(|e| format!("cannot read `{}`: {e}", file.display()))
}

/// Triangles (values of `idx`) of a triangle list, strip or fan (glTF 2.0
/// §3.7.2.1: strip triangle i = (v[i], v[i + 1 + i % 2], v[i + 2 − i % 2]),
/// fan triangle i = (v[i + 1], v[i + 2], v[0])).
fn triangles(mode: Mode, idx: &[u32]) -> Result<Vec<[u32; 3]>, String> {
    let n = idx.len();
    Ok(match mode {
        Mode::Triangles => {
            if !n.is_multiple_of(3) {
                return Err(format!(
                    "{n} indices (or vertices) for a triangle list: expected a multiple of 3"
                ));
            }
            idx.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| {
                let odd = i % 2;
                [idx[i], idx[i + 1 + odd], idx[i + 2 - odd]]
            })
            .collect(),
        Mode::TriangleFan => (0..n.saturating_sub(2))
            .map(|i| [idx[i + 1], idx[i + 2], idx[0]])
            .collect(),
        _ => Vec::new(),
    })
}

#[cfg(test)]
mod tests;
