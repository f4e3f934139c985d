"""glTF/GLB and OBJ meshes exported by trimesh, and trimesh's own triangle
counts, bounds, areas and volumes of every glTF/GLB file of the mesh corpus
(issue 14 item 3): the independent reference of tests/mesh_gltf.rs.

Writes, under tests/data/wild/meshes/:
  trimesh/scene.glb   a box (material `brick`) whose child node is an annulus
                      (material `ring_paint`, non-uniform scale), and the
                      same annulus mesh again under a mirroring node (no
                      material): node hierarchy, instancing, a mirror
  trimesh/scene.obj   the same scene as one OBJ (transforms applied)
  trimesh/box.glb, trimesh/box.obj  the box alone, at its node transform
  trimesh/ring.glb    a flat 64-gon ring (radii 10 and 30 m, material
                      `tarmac`) lying in glTF's horizontal x-z plane, its
                      node translated by (15, 0, -15) m: irsig's rendered
                      area test (area N/2 sin(2 pi/N) (R^2 - r^2))
  gltf_ref.csv        per file: triangles, bounding box, total area and signed
                      volume (sum of a·(b×c)/6; NaN for open surfaces) of the
                      scene with its node transforms applied, in the file's
                      own (glTF: +Y up) coordinates

trimesh reads every file back (process=False: no merging or cleaning), so the
reference values are those of the stored float32 data. trimesh ignores
sparse accessors, so SimpleSparseAccessor.gltf is decoded with pygltflib and
numpy instead (base values, then the sparse indices/values substituted).

Run: python3 -m venv tools/.venv && tools/.venv/bin/pip install trimesh numpy pygltflib
     tools/.venv/bin/python tools/gen_trimesh_exports.py
(run with trimesh 5.2.0, numpy, pygltflib 1.16.5.)
"""

import base64
import csv
import math
import pathlib

import numpy as np
import pygltflib
import trimesh
from trimesh.transformations import compose_matrix

ROOT = pathlib.Path(__file__).resolve().parent.parent / "tests/data/wild/meshes"
OUT = ROOT / "trimesh"

# Files whose reference comes from trimesh; (file, closed surface?)
FILES = [
    ("khronos/Box.gltf", True),
    ("khronos/Box.glb", True),
    ("khronos/SimpleMeshes.gltf", False),
    ("khronos/TriangleWithoutIndices.gltf", False),
    ("khronos/Cameras.gltf", False),
    ("gltf-rs/box_sparse.glb", True),
    ("trimesh/scene.glb", True),
    ("trimesh/scene.obj", True),
    ("trimesh/box.glb", True),
    ("trimesh/box.obj", True),
    ("trimesh/ring.glb", False),
]


def export():
    OUT.mkdir(parents=True, exist_ok=True)
    box = trimesh.creation.box(extents=[2.0, 3.0, 4.0])
    box.visual = trimesh.visual.TextureVisuals(
        material=trimesh.visual.material.PBRMaterial(name="brick")
    )
    ring = trimesh.creation.annulus(r_min=1.0, r_max=2.0, height=0.5, sections=24)
    painted = ring.copy()
    painted.visual = trimesh.visual.TextureVisuals(
        material=trimesh.visual.material.PBRMaterial(name="ring_paint")
    )
    t_box = compose_matrix(angles=[0, 0, math.radians(30)], translate=[5, 1, -2])
    # child of the box: rotated about x and z, stretched 1.5x along z
    t_child = compose_matrix(
        scale=[1, 1, 1.5],
        angles=[math.radians(90), 0, math.radians(10)],
        translate=[-3, 2, 0.5],
    )
    # mirrored (x -> -x) and turned about y
    t_mirror = compose_matrix(
        scale=[-1, 1, 1], angles=[0, math.radians(-45), 0], translate=[0, 0, 7]
    )
    s = trimesh.Scene()
    s.add_geometry(box, node_name="box", geom_name="box", transform=t_box)
    s.add_geometry(
        painted,
        node_name="ring_a",
        geom_name="ring_painted",
        parent_node_name="box",
        transform=t_child,
    )
    s.add_geometry(ring, node_name="ring_b", geom_name="ring", transform=t_mirror)
    s.export(OUT / "scene.glb")
    (OUT / "scene.obj").write_text(
        trimesh.exchange.obj.export_obj(
            s.to_mesh(), include_normals=False, include_texture=False, digits=17
        )
    )
    n, r, big = 64, 10.0, 30.0
    a = np.arange(n) * 2 * math.pi / n
    verts = np.vstack(
        [np.c_[r * np.cos(a), np.zeros(n), r * np.sin(a)]]
        + [np.c_[big * np.cos(a), np.zeros(n), big * np.sin(a)]]
    )
    i, j = np.arange(n), (np.arange(n) + 1) % n
    # inner i, outer j, outer i: counter-clockwise seen from +y (up)
    faces = np.vstack([np.c_[i, j + n, i + n], np.c_[i, j, j + n]])
    flat = trimesh.Trimesh(verts, faces, process=False)
    assert flat.face_normals[:, 1].min() > 0.999
    flat.visual = trimesh.visual.TextureVisuals(
        material=trimesh.visual.material.PBRMaterial(name="tarmac")
    )
    g = trimesh.Scene()
    g.add_geometry(flat, node_name="ring", geom_name="ring",
                   transform=compose_matrix(translate=[15, 0, -15]))
    g.export(OUT / "ring.glb")
    b = trimesh.Scene()
    b.add_geometry(box, node_name="box", geom_name="box", transform=t_box)
    b.export(OUT / "box.glb")
    (OUT / "box.obj").write_text(
        trimesh.exchange.obj.export_obj(
            b.to_mesh(), include_normals=False, include_texture=False, digits=17
        )
    )


def stats(vertices, faces, closed):
    tri = vertices[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1).sum()
    volume = (
        np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0
        if closed
        else math.nan
    )
    return len(faces), vertices[faces].reshape(-1, 3), area, volume


def trimesh_row(rel, closed):
    scene = trimesh.load(ROOT / rel, force="scene", process=False)
    verts, faces, base = [], [], 0
    for node in scene.graph.nodes_geometry:
        transform, name = scene.graph[node]
        m = scene.geometry[name].copy()
        # apply_transform reverses the winding of mirroring transforms
        m.apply_transform(transform)
        verts.append(np.asarray(m.vertices, dtype=np.float64))
        faces.append(np.asarray(m.faces) + base)
        base += len(m.vertices)
    return stats(np.vstack(verts), np.vstack(faces), closed)


def sparse_row(rel):
    """One node, one triangle-list primitive, identity transform."""
    g = pygltflib.GLTF2().load(str(ROOT / rel))
    uri = g.buffers[0].uri
    data = base64.b64decode(uri.split(",", 1)[1])

    def view(i, offset, dtype, count, width):
        v = g.bufferViews[i]
        start = v.byteOffset + offset
        a = np.frombuffer(data, dtype=dtype, count=count * width, offset=start)
        return a.reshape(count, width) if width > 1 else a

    prim = g.meshes[0].primitives[0]
    idx_acc = g.accessors[prim.indices]
    idx = view(idx_acc.bufferView, idx_acc.byteOffset, "<u2", idx_acc.count, 1)
    pos_acc = g.accessors[prim.attributes.POSITION]
    pos = view(pos_acc.bufferView, pos_acc.byteOffset, "<f4", pos_acc.count, 3).copy()
    sp = pos_acc.sparse
    si = view(sp.indices.bufferView, sp.indices.byteOffset, "<u2", sp.count, 1)
    sv = view(sp.values.bufferView, sp.values.byteOffset, "<f4", sp.count, 3)
    pos[si] = sv
    return stats(pos.astype(np.float64), idx.reshape(-1, 3).astype(np.int64), False)


def main():
    export()
    rows = [(rel,) + trimesh_row(rel, closed) + ("trimesh",) for rel, closed in FILES]
    rows.append(
        ("khronos/SimpleSparseAccessor.gltf",)
        + sparse_row("khronos/SimpleSparseAccessor.gltf")
        + ("pygltflib+numpy",)
    )
    with open(ROOT / "gltf_ref.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(
            [
                "file",
                "triangles",
                "xmin",
                "ymin",
                "zmin",
                "xmax",
                "ymax",
                "zmax",
                "area",
                "volume",
                "reference",
            ]
        )
        for rel, n, pts, area, volume, src in rows:
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            w.writerow(
                [rel, n]
                + [repr(float(v)) for v in (*lo, *hi, area, volume)]
                + [src]
            )
    print((ROOT / "gltf_ref.csv").read_text())


if __name__ == "__main__":
    main()
