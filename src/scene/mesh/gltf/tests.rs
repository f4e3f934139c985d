//! Tests of the glTF/GLB reader (moved out of `gltf.rs`).

use super::*;
use base64::Engine;

/// A glTF document whose one buffer (a base64 data URI) holds `pos`
/// (accessor 0: VEC3 float) and, if any, `idx` (accessor 1: SCALAR
/// u16); `rest` is the other top-level members (meshes, nodes, ...).
fn doc(pos: &[[f32; 3]], idx: &[u16], rest: &str) -> Vec<u8> {
    let mut data: Vec<u8> = pos.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let n_pos = data.len();
    data.extend(idx.iter().flat_map(|v| v.to_le_bytes()));
    let uri = base64::engine::general_purpose::STANDARD.encode(&data);
    let mut views = format!(r#"{{"buffer":0,"byteOffset":0,"byteLength":{n_pos}}}"#);
    let (lo, hi) = pos
        .iter()
        .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            (
                std::array::from_fn(|i| lo[i].min(p[i])),
                std::array::from_fn(|i| hi[i].max(p[i])),
            )
        });
    let mut accessors = format!(
        r#"{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":{lo:?},"max":{hi:?}}}"#,
        pos.len()
    );
    if !idx.is_empty() {
        views += &format!(
            r#",{{"buffer":0,"byteOffset":{n_pos},"byteLength":{}}}"#,
            2 * idx.len()
        );
        accessors += &format!(
            r#",{{"bufferView":1,"componentType":5123,"count":{},"type":"SCALAR"}}"#,
            idx.len()
        );
    }
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{uri}"}}],"bufferViews":[{views}],"accessors":[{accessors}],{rest}}}"#,
        data.len()
    )
    .into_bytes()
}

/// One mesh of one primitive (`mode`, indexed when `indexed`) on one
/// node.
fn one(mode: u32, indexed: bool) -> String {
    let indices = if indexed { r#","indices":1"# } else { "" };
    format!(
        r#""meshes":[{{"name":"m","primitives":[{{"attributes":{{"POSITION":0}}{indices},"mode":{mode}}}]}}],"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}]"#
    )
}

const SQUARE: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [1.0, 1.0, 0.0],
];

fn parse(b: &[u8]) -> Result<Mesh, SceneError> {
    parse_gltf(Path::new("m.gltf"), b)
}

fn err(b: &[u8]) -> String {
    parse(b).unwrap_err().to_string()
}

fn tris(m: &Mesh) -> Vec<Vec<u32>> {
    m.faces.iter().map(|f| f.verts.clone()).collect()
}

#[test]
fn lists_strips_and_fans_follow_the_specification() {
    // §3.7.2.1: strip i = (i, i+1+i%2, i+2-i%2); fan i = (i+1, i+2, 0)
    let m = parse(&doc(&SQUARE, &[0, 1, 2, 3], &one(5, true))).unwrap();
    assert_eq!(tris(&m), vec![vec![0, 1, 2], vec![1, 3, 2]]);
    let m = parse(&doc(&SQUARE, &[0, 1, 3, 2], &one(6, true))).unwrap();
    assert_eq!(tris(&m), vec![vec![1, 3, 0], vec![3, 2, 0]]);
    let m = parse(&doc(&SQUARE, &[0, 1, 2, 2, 1, 3], &one(4, true))).unwrap();
    assert_eq!(tris(&m), vec![vec![0, 1, 2], vec![2, 1, 3]]);
    // not indexed: the vertices in order
    let m = parse(&doc(&SQUARE[..3], &[], &one(4, false))).unwrap();
    assert_eq!(tris(&m), vec![vec![0, 1, 2]]);
    let m = parse(&doc(&SQUARE, &[], &one(5, false))).unwrap();
    assert_eq!(tris(&m), vec![vec![0, 1, 2], vec![1, 3, 2]]);
    assert_eq!(m.default_up, UpAxis::Y);
    assert_eq!(m.parts, vec!["node 0 (mesh 0 `m`, primitive 0)"]);
    let e = err(&doc(&SQUARE, &[0, 1, 2, 3], &one(4, true)));
    assert!(
        e.starts_with(
            "m.gltf: node 0 (mesh 0 `m`, primitive 0): 4 indices (or vertices) for a \
             triangle list: expected a multiple of 3"
        ),
        "{e}"
    );
}

#[test]
fn points_and_lines_are_skipped_with_a_warning() {
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":0},{"attributes":{"POSITION":0},"indices":1,"mode":1},{"attributes":{"POSITION":0},"mode":4}]}],"nodes":[{"mesh":0,"name":"n"}],"scenes":[{"nodes":[0]}]"#;
    let m = parse(&doc(&SQUARE[..3], &[0, 1], rest)).unwrap();
    assert_eq!(m.faces.len(), 1);
    assert_eq!(m.faces[0].src, 2);
    assert_eq!(
        m.warnings,
        vec![
            "m.gltf: point and line primitives skipped (not surfaces): node 0 `n` (mesh 0, \
             primitive 0): Points, node 0 `n` (mesh 0, primitive 1): Lines"
        ]
    );
    // nothing but points: refused
    let e = err(&doc(&SQUARE[..3], &[], &one(0, false)));
    assert!(
        e.contains(
            "m.gltf: no triangle with an area in the scene's meshes (0 triangles; 1 point or \
             line primitives skipped)"
        ),
        "{e}"
    );
}

/// A child under a parent: world = parent · child, each T · R · S or a
/// column-major matrix (§3.5.2); a mesh on two nodes is two instances.
#[test]
fn node_transforms_compose_and_instance() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    // parent: translate (10, 0, 0); child: rotate +90° about z, scale 2
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let rest = format!(
        r#""meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{{"children":[1],"translation":[10,0,0]}},{{"mesh":0,"rotation":[0,0,{h},{h}],"scale":[2,2,2]}},{{"mesh":0,"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}}],"scenes":[{{"nodes":[0,2]}}]"#
    );
    let m = parse(&doc(&tri, &[], &rest)).unwrap();
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12);
    let want = [
        [10.0, 0.0, 0.0],
        [10.0, 2.0, 0.0],
        [8.0, 0.0, 0.0],
        [0.0, 0.0, 5.0],
        [1.0, 0.0, 5.0],
        [0.0, 1.0, 5.0],
    ];
    assert_eq!(m.positions.len(), 6);
    for (p, w) in m.positions.iter().zip(want) {
        assert!(close(*p, w), "{p:?} != {w:?}");
    }
    assert_eq!(
        m.parts,
        vec![
            "node 1 (mesh 0, primitive 0)",
            "node 2 (mesh 0, primitive 0)"
        ]
    );
    assert_eq!((m.faces[0].src, m.faces[1].src), (0, 1));
    // a mirroring node (scale -1 in x) reverses the winding, so the
    // face keeps its side: (x, y) → (−x, y) turns (0,1,2) clockwise
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0,"scale":[-1,1,1]}],"scenes":[{"nodes":[0]}]"#;
    let m = parse(&doc(&tri, &[], rest)).unwrap();
    assert_eq!(tris(&m), vec![vec![0, 2, 1]]);
    let p = |k: usize| DVec3::from(m.positions[m.faces[0].verts[k] as usize]);
    assert!((p(1) - p(0)).cross(p(2) - p(0)).z > 0.0);
}

/// Positions interleaved with normals in one buffer view (`byteStride`
/// 24, POSITION at byte 12), as BoxInterleaved stores them.
#[test]
fn interleaved_attributes_are_read_at_their_stride() {
    let mut data = Vec::new();
    for p in &SQUARE[..3] {
        for v in [0.0f32, 0.0, 1.0].iter().chain(p) {
            data.extend(v.to_le_bytes());
        }
    }
    let uri = base64::engine::general_purpose::STANDARD.encode(&data);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":72,"uri":"data:application/octet-stream;base64,{uri}"}}],"bufferViews":[{{"buffer":0,"byteLength":72,"byteStride":24}}],"accessors":[{{"bufferView":0,"byteOffset":12,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],{}}}"#,
        one(4, false)
    );
    let m = parse(json.as_bytes()).unwrap();
    assert_eq!(
        m.positions,
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    );
    // one byte less in the view: the last position overruns it
    let e = err(json
        .replace(
            r#""byteLength":72,"byteStride""#,
            r#""byteLength":71,"byteStride""#,
        )
        .as_bytes());
    assert!(
        e.contains("3 elements of 12 bytes every 24 from byte 12 overrun its `byteLength` 71"),
        "{e}"
    );
    let e = err(json
        .replace(r#""byteStride":24"#, r#""byteStride":8"#)
        .as_bytes());
    assert!(
        e.contains("buffer view 0: `byteStride` 8 is smaller than an element (12 bytes)"),
        "{e}"
    );
}

#[test]
fn the_default_scene_else_scene_0_else_the_root_nodes() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let meshes = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]"#;
    let nodes = r#""nodes":[{"mesh":0},{"mesh":0,"translation":[0,0,3]},{"children":[1]}]"#;
    let z = |m: &Mesh| m.positions.iter().map(|p| p[2]).fold(f64::NAN, f64::max);
    let s = format!(r#"{meshes},{nodes},"scene":1,"scenes":[{{"nodes":[0]}},{{"nodes":[2]}}]"#);
    let m = parse(&doc(&tri, &[], &s)).unwrap();
    assert_eq!((m.faces.len(), z(&m)), (1, 3.0));
    let s = format!(r#"{meshes},{nodes},"scenes":[{{"nodes":[0]}},{{"nodes":[2]}}]"#);
    assert_eq!(z(&parse(&doc(&tri, &[], &s)).unwrap()), 0.0);
    // no scenes: nodes 0 and 2 are the roots
    let m = parse(&doc(&tri, &[], &format!("{meshes},{nodes}"))).unwrap();
    assert_eq!(m.faces.len(), 2);
    let e = err(&doc(&tri, &[], meshes));
    assert!(e.contains("m.gltf: no scene and no root node"), "{e}");
    // a node reached twice (two parents) is refused, not walked twice
    let s = format!(
        r#"{meshes},"nodes":[{{"children":[1]}},{{"mesh":0}},{{"children":[1]}}],"scenes":[{{"nodes":[0,2]}}]"#
    );
    let e = err(&doc(&tri, &[], &s));
    assert!(e.contains("m.gltf: node 1 is reached twice"), "{e}");
    // a cycle
    let s = format!(
        r#"{meshes},"nodes":[{{"children":[1]}},{{"mesh":0,"children":[0]}}],"scenes":[{{"nodes":[0]}}]"#
    );
    assert!(err(&doc(&tri, &[], &s)).contains("node 0 is reached twice"));
}

#[test]
fn material_names() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let rest = r#""materials":[{"name":"Béton"},{}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":1},{"attributes":{"POSITION":0},"material":0},{"attributes":{"POSITION":0}},{"attributes":{"POSITION":0},"material":1}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]"#;
    let m = parse(&doc(&tri, &[], rest)).unwrap();
    assert_eq!(
        m.material_names,
        vec![("material1".to_string(), 0), ("Béton".to_string(), 1)]
    );
    let mats: Vec<Option<u32>> = m.faces.iter().map(|f| f.material).collect();
    assert_eq!(mats, vec![Some(0), Some(1), None, Some(0)]);
}

#[test]
fn extensions_required() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let rest = |ext: &str| {
        format!(
            r#"{},"extensionsUsed":["{ext}"],"extensionsRequired":["{ext}"]"#,
            one(4, false)
        )
    };
    let e = err(&doc(&tri, &[], &rest("KHR_draco_mesh_compression")));
    assert!(
        e.contains(
            "m.gltf: the file requires the extension `KHR_draco_mesh_compression` \
             (Draco-compressed meshes), which irsig does not read"
        ),
        "{e}"
    );
    let m = parse(&doc(&tri, &[], &rest("KHR_materials_clearcoat"))).unwrap();
    assert_eq!(
        m.warnings,
        vec![
            "m.gltf: the required glTF extension `KHR_materials_clearcoat` is ignored: it \
              does not change geometry, and irsig takes materials from its libraries"
        ]
    );
}

#[test]
fn bad_input_is_refused_naming_where() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let at = "m.gltf: node 0 (mesh 0 `m`, primitive 0): ";
    // index out of range
    let e = err(&doc(&tri, &[0, 1, 3], &one(4, true)));
    assert!(
        e.starts_with(&format!(
            "{at}index 2 is 3, out of range: POSITION has 3 vertices"
        )),
        "{e}"
    );
    // non-finite position
    let e = err(&doc(
        &[[0.0; 3], [1.0, f32::NAN, 0.0], [0.0, 1.0, 0.0]],
        &[],
        &one(4, false),
    ));
    assert!(
        e.starts_with(&format!(
            "{at}vertex 1 (POSITION accessor 0) is [1.0, NaN, 0.0]"
        )),
        "{e}"
    );
    // degenerate only
    let e = err(&doc(&[[1.0; 3]; 3], &[], &one(4, false)));
    assert!(
        e.contains("no triangle with an area in the scene's meshes (1 triangles, all degenerate"),
        "{e}"
    );
    // accessor past its buffer view
    let b = String::from_utf8(doc(&tri, &[], &one(4, false))).unwrap();
    let e = err(b.replace(r#""count":3"#, r#""count":4"#).as_bytes());
    assert!(
        e.starts_with(&format!("{at}POSITION accessor 0: buffer view 0: 4 elements of 12 bytes every 12 from byte 0 overrun its `byteLength` 36")),
        "{e}"
    );
    let e = err(b.replace(r#""count":3"#, r#""count":0"#).as_bytes());
    assert!(e.contains("`count` is 0"), "{e}");
    // view past its buffer; huge numbers do not overflow
    let e = err(b
        .replace(
            r#""byteOffset":0,"byteLength":36"#,
            r#""byteOffset":4,"byteLength":36"#,
        )
        .as_bytes());
    assert!(
        e.contains("buffer view 0: bytes 4 + 36 overrun buffer 0 (36 bytes)"),
        "{e}"
    );
    let e = err(b
        .replace(
            r#""byteOffset":0,"byteLength":36"#,
            r#""byteOffset":18446744073709551615,"byteLength":36"#,
        )
        .as_bytes());
    assert!(e.contains("overrun buffer 0"), "{e}");
    let e = err(b
        .replace(r#""count":3"#, r#""count":4294967295000"#)
        .as_bytes());
    assert!(e.contains("overrun its `byteLength`"), "{e}");
    // a wrong type
    let e = err(b.replace(r#""type":"VEC3""#, r#""type":"VEC2""#).as_bytes());
    assert!(
        e.contains("POSITION accessor 0: Vec2 of F32: expected Vec3 of F32"),
        "{e}"
    );
    // bad JSON: line and column
    let e = err(b"{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [\n}\n");
    assert!(e.starts_with("m.gltf:4:1: invalid glTF JSON"), "{e}");
    // an index that points nowhere: the crate's validation, with its path
    let e = err(b
        .replace(r#""nodes":[{"mesh":0}]"#, r#""nodes":[{"mesh":7}]"#)
        .as_bytes());
    assert!(
        e.contains("m.gltf: invalid glTF: `nodes[0].mesh`: Index out of bounds"),
        "{e}"
    );
    // a POSITION accessor that does not exist (a panic in gltf-json)
    let e = err(b
        .replace(r#""POSITION":0"#, r#""POSITION":65536"#)
        .as_bytes());
    assert!(
        e.contains(
            "`meshes[0].primitives[0].attributes[\"POSITION\"]`: accessor 65536 does not exist"
        ),
        "{e}"
    );
    // the network is not read
    let e = err(b
        .replace(
            "data:application/octet-stream;base64,",
            "https://example.com/b.bin?",
        )
        .as_bytes());
    assert!(
        e.contains("buffer 0: `https://example.com/b.bin?")
            && e.contains("is a `https:` URI: irsig reads no network"),
        "{e}"
    );
    let e = err(b.replace(";base64,", ",").as_bytes());
    assert!(e.contains("URI is not base64"), "{e}");
    // a missing external file
    let e = err(b
        .replace(
            r#""uri":"data:application/octet-stream;base64,"#,
            r#""uri":"no%20such.bin","x":""#,
        )
        .as_bytes());
    assert!(e.contains("buffer 0: cannot read `no such.bin`"), "{e}");
    // matrices must be affine; quaternions not zero
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0,"matrix":[1,0,0,1, 0,1,0,0, 0,0,1,0, 0,0,0,1]}],"scenes":[{"nodes":[0]}]"#;
    assert!(
        err(&doc(&tri, &[], rest))
            .contains("m.gltf: node 0: `matrix` has the last row [1.0, 0.0, 0.0, 1.0]")
    );
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0,"rotation":[0,0,0,0]}],"scenes":[{"nodes":[0]}]"#;
    assert!(
        err(&doc(&tri, &[], rest))
            .contains("node 0: `rotation` [0.0, 0.0, 0.0, 0.0] is not a unit quaternion")
    );
    let rest = r#""meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0,"translation":[0,0,1e300],"scale":[1e300,1,1]}],"scenes":[{"nodes":[0]}]"#;
    assert!(parse(&doc(&tri, &[], rest)).is_ok(), "large but finite");
}

/// A GLB of `json` and `bin` (chunks padded to 4 bytes).
fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |b: &[u8], with: u8| {
        let mut v = b.to_vec();
        while !v.len().is_multiple_of(4) {
            v.push(with);
        }
        v
    };
    let (j, b) = (pad(json, b' '), pad(bin, 0));
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&j);
    if !b.is_empty() {
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&b);
    }
    out
}

#[test]
fn glb_containers() {
    let tri: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":36}}],"bufferViews":[{{"buffer":0,"byteLength":36}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],{}}}"#,
        one(4, false)
    );
    let g = glb(json.as_bytes(), &tri);
    let m = parse_gltf(Path::new("m.glb"), &g).unwrap();
    assert_eq!(m.faces.len(), 1);
    // truncated anywhere: an error naming the file, never a panic
    for n in [0, 3, 4, 8, 11, 12, 19, 20, 40, g.len() - 37, g.len() - 1] {
        let e = parse_gltf(Path::new("m.glb"), &g[..n])
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.glb"), "{n}: {e}");
    }
    let e = parse_gltf(Path::new("m.glb"), &g[..g.len() - 1])
        .unwrap_err()
        .to_string();
    assert!(e.contains("truncated GLB: the header declares"), "{e}");
    // no BIN chunk
    let e = parse_gltf(Path::new("m.glb"), &glb(json.as_bytes(), &[]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("buffer 0 is the GLB's BIN chunk, which the file does not have"),
        "{e}"
    );
    // header lengths that would underflow
    let mut h = g.clone();
    h[8..12].copy_from_slice(&5u32.to_le_bytes());
    let e = parse_gltf(Path::new("m.glb"), &h).unwrap_err().to_string();
    assert!(e.contains("GLB header declares 5 bytes"), "{e}");
    h[4..8].copy_from_slice(&1u32.to_le_bytes());
    let e = parse_gltf(Path::new("m.glb"), &h).unwrap_err().to_string();
    assert!(e.contains("GLB version 1: expected 2"), "{e}");
    // a chunk length past the end
    let mut h = g.clone();
    h[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = parse_gltf(Path::new("m.glb"), &h).unwrap_err().to_string();
    assert!(e.starts_with("m.glb: invalid GLB"), "{e}");
}
