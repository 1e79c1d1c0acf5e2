"""Model files into Meshes (glsandbox.meshfile), the normals they get, the models made
without a file (glsandbox.meshgen), and one-line errors for every kind of bad file."""

from __future__ import annotations

import io
import json
import os
import signal
import struct
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from glsandbox import meshgen
from glsandbox.errors import SandboxError
from glsandbox.meshfile import FIT_SIZE, load_mesh

CUBE_V = np.array([(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                   (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)], dtype=float)
# Counter-clockwise seen from outside.
CUBE_F = np.array([(0, 3, 2), (0, 2, 1), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
                   (3, 7, 6), (3, 6, 2), (0, 4, 7), (0, 7, 3), (1, 2, 6), (1, 6, 5)])


def obj_text(v: np.ndarray, f: np.ndarray, extra: str = "") -> str:
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    return "\n".join(lines) + "\n" + extra


def write(tmp_path: Path, name: str, data: str | bytes) -> Path:
    path = tmp_path / name
    path.write_bytes(data.encode() if isinstance(data, str) else data)
    return path


def cube_files(tmp_path: Path) -> Iterator[Path]:
    import trimesh

    mesh = trimesh.Trimesh(CUBE_V, CUBE_F, process=False)
    for ext in ("obj", "ply", "stl", "off", "glb"):
        path = tmp_path / f"cube.{ext}"
        mesh.export(path)
        yield path
    ascii_ply = tmp_path / "cube_ascii.ply"
    mesh.export(ascii_ply, encoding="ascii")
    yield ascii_ply
    ascii_stl = tmp_path / "cube_ascii.stl"
    ascii_stl.write_bytes(trimesh.exchange.stl.export_stl_ascii(mesh).encode())
    yield ascii_stl


def outward(mesh) -> np.ndarray:
    """Whether each triangle's normal (counter-clockwise) points away from the centre."""
    tri = mesh.triangles()
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return np.einsum("ij,ij->i", n, tri.mean(axis=1) - mesh.positions.mean(axis=0)) > 0


# --- every format -----------------------------------------------------------------


def test_every_format_loads_the_cube_with_sharp_edges(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    for path in cube_files(tmp_path):
        loaded = load_mesh(path)
        mesh = loaded.mesh
        assert mesh.mode == "triangles" and loaded.triangle_count == 12, path
        assert mesh.vertex_count == 24, path  # crease normals: each corner once per face
        assert loaded.normals == "crease" and loaded.dropped_degenerate == 0
        # Every normal is an axis, pointing out of the face it belongs to.
        assert np.allclose(np.abs(mesh.normals).max(axis=1), 1.0)
        assert np.all(np.einsum("ij,ij->i", mesh.normals, mesh.positions) > 0)
        assert outward(mesh).all(), path
        assert not mesh.positions.flags.writeable
        assert loaded.describe().startswith(f"{path.name}: 12 triangles, 24 vertices")
    out, err = capfd.readouterr()
    assert out == "" and err == ""


@pytest.mark.parametrize("mode, vertices", [("smooth", 8), ("flat", 24), ("crease", 24)])
def test_normal_modes_on_the_cube(tmp_path: Path, mode: str, vertices: int) -> None:
    loaded = load_mesh(write(tmp_path, "c.obj", obj_text(CUBE_V, CUBE_F)), normals=mode)
    assert loaded.mesh.vertex_count == vertices and loaded.normals == mode
    if mode == "smooth":  # corner normals point along the diagonals
        np.testing.assert_allclose(loaded.mesh.normals, loaded.mesh.positions / np.sqrt(3), atol=1e-12)


def test_crease_angle_decides_what_stays_sharp(tmp_path: Path) -> None:
    path = write(tmp_path, "c.obj", obj_text(CUBE_V, CUBE_F))
    assert load_mesh(path, crease_angle=89.0).mesh.vertex_count == 24
    assert load_mesh(path, crease_angle=91.0).mesh.vertex_count == 8
    sphere = meshgen.icosphere(3)
    text = obj_text(sphere.positions, sphere.indices.reshape(-1, 3))
    smooth = load_mesh(write(tmp_path, "s.obj", text))
    assert smooth.mesh.vertex_count == sphere.vertex_count  # a sphere has no crease
    np.testing.assert_allclose(smooth.mesh.normals, smooth.mesh.positions, atol=0.02)


def test_normals_from_the_file_are_used_and_required_when_asked(tmp_path: Path) -> None:
    v, f = CUBE_V, CUBE_F
    header = (f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n")
    n = -v / np.sqrt(3)  # deliberately inward: the file's word counts
    body = "".join(f"{p[0]} {p[1]} {p[2]} {m[0]} {m[1]} {m[2]}\n" for p, m in zip(v, n))
    body += "".join(f"3 {a} {b} {c}\n" for a, b, c in f)
    loaded = load_mesh(write(tmp_path, "n.ply", header + body))
    assert loaded.normals == "file" and loaded.mesh.vertex_count == 8
    np.testing.assert_allclose(loaded.mesh.normals, -loaded.mesh.positions / np.sqrt(3), atol=1e-6)
    assert load_mesh(tmp_path / "n.ply", normals="flat").mesh.vertex_count == 24
    with pytest.raises(SandboxError, match="no vertex normals"):
        load_mesh(write(tmp_path, "plain.obj", obj_text(CUBE_V, CUBE_F)), normals="file")


def test_obj_uv_and_material_texture_in_the_course_convention(tmp_path: Path) -> None:
    # OBJ's vt has v up (0 at the bottom of the image); the course's v = 0 is the top row.
    Image.fromarray(np.array([[[255, 0, 0, 255], [0, 255, 0, 255]],
                              [[0, 0, 255, 255], [255, 255, 0, 255]]], dtype=np.uint8)).save(tmp_path / "tex.png")
    (tmp_path / "m.mtl").write_text("newmtl paint\nKd 0.5 0.25 1.0\nmap_Kd tex.png\n")
    text = ("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
            "usemtl paint\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")
    loaded = load_mesh(write(tmp_path, "quad.obj", text))
    mesh = loaded.mesh
    assert loaded.texture is not None and loaded.texture.shape == (2, 2, 4)
    assert loaded.texture[0, 0].tolist() == [255, 0, 0, 255]  # row 0 is the image's top row
    for p, uv in zip(mesh.positions, mesh.uvs):
        assert uv.tolist() == [p[0], 1.0 - p[1]]  # the bottom-left corner (vt 0 0) is the course's (0, 1)
    assert loaded.base_color[:3] == pytest.approx((0.5, 0.25, 1.0), abs=1 / 255)
    assert "texture 2x2" in loaded.describe()


def glb_bytes(positions: np.ndarray, indices: np.ndarray, uvs: np.ndarray | None = None,
              image: np.ndarray | None = None, matrix: list[float] | None = None,
              factor: list[float] | None = None, truncate: int = 0) -> bytes:
    """A minimal GLB written by hand (what a file from Blender holds, reduced to one mesh)."""
    blobs: list[bytes] = []
    views: list[dict] = []
    accessors: list[dict] = []

    def add(array: np.ndarray, kind: str, component: int, target: int | None = None) -> int:
        raw = array.tobytes()
        view = {"buffer": 0, "byteOffset": sum(len(b) for b in blobs), "byteLength": len(raw)}
        if target:
            view["target"] = target
        blobs.append(raw + b"\0" * (-len(raw) % 4))
        views.append(view)
        acc = {"bufferView": len(views) - 1, "componentType": component, "count": len(array), "type": kind}
        if kind == "VEC3":
            acc["min"], acc["max"] = array.min(axis=0).tolist(), array.max(axis=0).tolist()
        accessors.append(acc)
        return len(accessors) - 1

    attributes = {"POSITION": add(positions.astype(np.float32), "VEC3", 5126, 34962)}
    if uvs is not None:
        attributes["TEXCOORD_0"] = add(uvs.astype(np.float32), "VEC2", 5126, 34962)
    primitive = {"attributes": attributes, "indices": add(indices.astype(np.uint32), "SCALAR", 5125, 34963)}
    gltf: dict = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                  "nodes": [{"mesh": 0, **({"matrix": matrix} if matrix else {})}],
                  "meshes": [{"primitives": [primitive]}], "accessors": accessors, "bufferViews": views}
    if image is not None:
        png = io.BytesIO()
        Image.fromarray(image).save(png, format="PNG")
        raw = png.getvalue()
        views.append({"buffer": 0, "byteOffset": sum(len(b) for b in blobs), "byteLength": len(raw)})
        blobs.append(raw + b"\0" * (-len(raw) % 4))
        gltf["images"] = [{"bufferView": len(views) - 1, "mimeType": "image/png"}]
        gltf["textures"] = [{"source": 0}]
        primitive["material"] = 0
        gltf["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                       "baseColorFactor": factor or [1, 1, 1, 1]}}]
    binary = b"".join(blobs)
    gltf["buffers"] = [{"byteLength": len(binary)}]
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    data = struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body
    return data[:len(data) - truncate] if truncate else data


def test_gltf_texture_uv_and_colour_come_through_unflipped(tmp_path: Path) -> None:
    # glTF's uv already has v = 0 at the image's top row, like the course.
    image = np.zeros((4, 8, 4), dtype=np.uint8)
    image[..., 3] = 255
    image[0, :, 0] = 255  # the top row red
    pos = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], dtype=float)
    uvs = np.array([(0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (0.0, 0.0)])  # the quad's top edge at v = 0
    idx = np.array([0, 1, 2, 0, 2, 3])
    loaded = load_mesh(write(tmp_path, "q.glb", glb_bytes(pos, idx, uvs, image, factor=[0.5, 1, 1, 1])))
    assert loaded.texture is not None and loaded.texture.shape == (4, 8, 4)
    np.testing.assert_array_equal(loaded.texture, image)
    for p, uv in zip(loaded.mesh.positions, loaded.mesh.uvs):
        np.testing.assert_allclose(uv, [p[0], 1.0 - p[1]], atol=1e-7)
    assert loaded.base_color == pytest.approx((0.5, 1.0, 1.0, 1.0), abs=1 / 255)


def test_a_mirroring_node_transform_keeps_triangles_counter_clockwise(tmp_path: Path) -> None:
    flip = [-2.0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 5, 0, 0, 1]  # column-major: x mirrored, scale 2, moved 5 along x
    data = glb_bytes(CUBE_V, CUBE_F.reshape(-1), matrix=flip)
    mesh = load_mesh(write(tmp_path, "m.glb", data)).mesh
    np.testing.assert_allclose(mesh.positions.min(axis=0), [3, -2, -2], atol=1e-6)
    np.testing.assert_allclose(mesh.positions.max(axis=0), [7, 2, 2], atol=1e-6)
    assert outward(mesh).all()


def test_fit_centres_the_model_and_scales_its_longest_side(tmp_path: Path) -> None:
    v = CUBE_V * [3.0, 1.0, 0.5] + [10.0, -4.0, 2.0]
    loaded = load_mesh(write(tmp_path, "box.obj", obj_text(v, CUBE_F)), fit=True)
    lo, hi = loaded.mesh.positions.min(axis=0), loaded.mesh.positions.max(axis=0)
    np.testing.assert_allclose((lo + hi) / 2, 0.0, atol=1e-12)
    assert (hi - lo).max() == pytest.approx(FIT_SIZE)
    np.testing.assert_allclose(hi - lo, [2.0, 2 / 3, 1 / 3])
    assert loaded.fit_center == pytest.approx((10.0, -4.0, 2.0)) and loaded.fit_scale == pytest.approx(1 / 3)


def test_degenerate_faces_are_dropped_and_counted(tmp_path: Path) -> None:
    v = np.concatenate([CUBE_V, [(5.0, 5, 5), (6.0, 6, 6), (7.0, 7, 7)]])
    f = np.concatenate([CUBE_F, [(0, 0, 1), (2, 3, 3), (8, 9, 10)]])  # repeated corners, collinear corners
    loaded = load_mesh(write(tmp_path, "d.obj", obj_text(v, f)))
    assert loaded.dropped_degenerate == 3
    assert loaded.triangle_count == 12
    assert loaded.mesh.vertex_count == 24  # the collinear points are not kept
    assert "3 degenerate faces dropped" in loaded.describe()


# --- bad files: one line naming the file ------------------------------------------


def truncated_stl(tmp_path: Path) -> Path:
    import trimesh

    path = tmp_path / "t.stl"
    trimesh.Trimesh(CUBE_V, CUBE_F, process=False).export(path)
    path.write_bytes(path.read_bytes()[:-30])
    return path


def truncated_ply(tmp_path: Path) -> Path:
    import trimesh

    path = tmp_path / "t.ply"
    trimesh.Trimesh(CUBE_V, CUBE_F, process=False).export(path)
    path.write_bytes(path.read_bytes()[:-9])
    return path


def garbage(name: str) -> bytes:
    rng = np.random.default_rng(len(name))
    return rng.integers(0, 256, 4000, dtype=np.uint8).tobytes()


BAD_FILES = {
    "missing": (lambda p: p / "nowhere.obj", "not found"),
    "empty": (lambda p: write(p, "empty.obj", b""), "empty"),
    "directory": (lambda p: (p / "folder.obj").mkdir() or p / "folder.obj", "directory"),
    "unsupported": (lambda p: write(p, "model.fbx", b"Kaydara FBX Binary"), "unsupported"),
    "garbage obj": (lambda p: write(p, "g.obj", garbage("g.obj")), "binary data"),
    "garbage off": (lambda p: write(p, "g.off", garbage("g.off")), "binary data"),
    "garbage ply": (lambda p: write(p, "g.ply", garbage("g.ply")), "not a PLY file"),
    "garbage stl": (lambda p: write(p, "g.stl", garbage("g.stl")), "not a valid binary STL"),
    "garbage glb": (lambda p: write(p, "g.glb", garbage("g.glb")), "not a GLB file"),
    "garbage gltf": (lambda p: write(p, "g.gltf", "{ this is not json"), "invalid JSON"),
    "truncated stl": (truncated_stl, "truncated"),
    "truncated ply": (truncated_ply, "cannot read this PLY file"),
    "truncated glb": (lambda p: write(p, "t.glb", glb_bytes(CUBE_V, CUBE_F.reshape(-1), truncate=40)), "truncated"),
    "tiny stl": (lambda p: write(p, "tiny.stl", b"\x01\x02\x03"), "too short"),
    "no faces": (lambda p: write(p, "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), "no faces"),
    "only degenerate": (lambda p: write(p, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), "degenerate"),
    "nan": (lambda p: write(p, "nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "NaN or infinite"),
    "inf": (lambda p: write(p, "inf.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n"), "NaN or infinite"),
    "obj index out of range": (lambda p: write(p, "oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
                               "out of range"),
    "ply index out of range": (lambda p: write(p, "oob.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
                               "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                               "out of range"),
}


@pytest.mark.parametrize("case", BAD_FILES)
def test_bad_files_raise_one_line_naming_the_file(tmp_path: Path, case: str,
                                                  capfd: pytest.CaptureFixture[str]) -> None:
    make, words = BAD_FILES[case]
    path = make(tmp_path)
    with pytest.raises(SandboxError) as info:
        load_mesh(path)
    message = str(info.value)
    assert "\n" not in message
    assert str(path) in message
    assert words in message
    out, err = capfd.readouterr()
    assert out == "" and err == ""


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes on this system")
def test_a_named_pipe_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)

    def hung(*_: object) -> None:
        raise TimeoutError("load_mesh blocked on a named pipe")

    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(10)
    try:
        with pytest.raises(SandboxError, match=r"named pipe \(FIFO\)") as info:
            load_mesh(fifo)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert str(fifo) in str(info.value) and "\n" not in str(info.value)


def test_bad_options_are_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "c.obj", obj_text(CUBE_V, CUBE_F))
    with pytest.raises(SandboxError, match="normals"):
        load_mesh(path, normals="bumpy")
    with pytest.raises(SandboxError, match="crease_angle"):
        load_mesh(path, crease_angle=270)


# --- generated models ------------------------------------------------------------------


def test_generated_models_are_deterministic_closed_and_counter_clockwise() -> None:
    for s in range(4):
        sphere = meshgen.icosphere(s)
        assert sphere.element_count // 3 == 20 * 4**s
        assert outward(sphere).all()
        np.testing.assert_allclose(np.linalg.norm(sphere.positions, axis=1), 1.0)
    a, b = meshgen.rock(3, seed=4), meshgen.rock(3, seed=4)
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.indices, b.indices)
    assert not np.array_equal(meshgen.rock(3, seed=5).positions, a.positions)
    assert outward(a).all() and a.element_count // 3 == 1280
    # Closed: every edge is used once in each direction.
    tri = a.indices.reshape(-1, 3)
    p = np.unique(a.positions, axis=0, return_inverse=True)[1].reshape(-1)[tri]
    edges = np.concatenate([p[:, [0, 1]], p[:, [1, 2]], p[:, [2, 0]]])
    forward = {tuple(e) for e in edges}
    assert len(forward) == len(edges) and all((b_, a_) in forward for a_, b_ in forward)


def test_terrain_has_the_triangles_asked_for_facing_up_with_uv() -> None:
    for target in (1000, 10_000):
        cells = meshgen.terrain_cells_for(target)
        mesh = meshgen.terrain(cells)
        assert mesh.element_count // 3 == 2 * cells * cells
        assert abs(2 * cells * cells - target) / target < 0.05
        tri = mesh.triangles()
        assert np.all(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, 1] > 0)
        assert mesh.uvs.min() == 0.0 and mesh.uvs.max() == 1.0
        assert np.all(mesh.normals[:, 1] > 0.3)
