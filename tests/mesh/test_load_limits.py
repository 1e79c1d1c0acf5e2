"""Loading model files in linear time and bounded memory: crease normals as the pairwise rule
says on ordinary meshes, a fan and a repeated triangle that load in time linear in their size, a chain of
nested glTF nodes, and a model too big for the memory limit refused in one line before it is loaded."""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import trimesh

from glsandbox import meshgen
from glsandbox.errors import SandboxError
from glsandbox.mesh.precheck import (BYTES_PER_TRIANGLE, MEMORY_ENV, OBJ_BYTES_PER_FILE_BYTE, OBJ_BYTES_PER_LINE,
                                 needed_bytes)
from glsandbox.mesh.load import load_model
from glsandbox.mesh.normals import corner_normals, face_normals
from support import assert_user_error, run_cli


def pairwise_normals(positions: np.ndarray, tris: np.ndarray, crease: float) -> np.ndarray:
    """The crease rule written out as the module docstring states it, corner by corner: the
    angle-weighted sum of the face normals at the corner's position (same coordinates) that lie within
    ``crease`` degrees of the corner's own face normal. Slow, and the reference."""
    faces = face_normals(positions, tris)
    p = positions[tris]
    corners = []  # (position key, face, angle)
    for f in range(tris.shape[0]):
        for k in range(3):
            a, b = p[f, (k + 1) % 3] - p[f, k], p[f, (k + 2) % 3] - p[f, k]
            angle = math.atan2(np.linalg.norm(np.cross(a, b)), float(a @ b))
            corners.append((tuple(p[f, k] + 0.0), f, angle))
    at: dict[tuple[float, ...], list[int]] = {}
    for c, (key, _, _) in enumerate(corners):
        at.setdefault(key, []).append(c)
    limit = math.cos(math.radians(crease))
    out = np.zeros((len(corners), 3))
    for c, (key, f, _) in enumerate(corners):
        total = np.zeros(3)
        for d in at[key]:
            g, angle = corners[d][1], corners[d][2]
            if faces[f] @ faces[g] >= limit:
                total += faces[g] * angle
        size = np.linalg.norm(total)
        out[c] = total / size if size > 0.0 else faces[f]  # a knife edge (or rounding at 0°): its own
    return out.reshape(-1, 3, 3)


def ordinary_meshes() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    box = trimesh.creation.box()
    cylinder = trimesh.creation.cylinder(1.0, 2.0, sections=24)
    sphere = trimesh.creation.icosphere(2)
    rock = meshgen.rock(1)  # a lumpy closed surface, as a scan is
    return {"box": (np.asarray(box.vertices), np.asarray(box.faces)),
            "cylinder": (np.asarray(cylinder.vertices), np.asarray(cylinder.faces)),
            "sphere": (np.asarray(sphere.vertices), np.asarray(sphere.faces)),
            "rock": (np.asarray(rock.positions), np.asarray(rock.indices, dtype=np.intp).reshape(-1, 3))}


@pytest.mark.parametrize("name", ["box", "cylinder", "sphere", "rock"])
@pytest.mark.parametrize("crease", [0.0, 5.0, 30.0, 60.0, 180.0])
def test_crease_normals_follow_the_pairwise_rule_on_ordinary_meshes(name: str, crease: float) -> None:
    positions, tris = ordinary_meshes()[name]
    got = corner_normals(positions, tris.astype(np.intp), "crease", crease)
    np.testing.assert_allclose(got, pairwise_normals(positions, tris, crease), atol=1e-12)


def test_a_cone_apex_of_many_faces_is_split_where_its_ring_bends() -> None:
    # 200 faces meet at the apex: the ring walk (tier 3). Neighbouring faces differ by 1.8°, so at
    # 30° the apex is one smooth group: every apex corner gets the axis; at 1° every face keeps its own.
    cone = trimesh.creation.cone(1.0, 1.0, sections=200)
    positions, tris = np.asarray(cone.vertices), np.asarray(cone.faces, dtype=np.intp)
    apex = np.argmax(positions[:, 2])
    at_apex = tris == apex
    smooth = corner_normals(positions, tris, "crease", 30.0)[at_apex]
    np.testing.assert_allclose(smooth, np.tile([0.0, 0.0, 1.0], (smooth.shape[0], 1)), atol=1e-9)
    sharp = corner_normals(positions, tris, "crease", 1.0)[at_apex]
    own = face_normals(positions, tris)[np.nonzero(at_apex)[0]]
    np.testing.assert_allclose(sharp, own, atol=1e-12)


def write_fan(path: Path, n: int) -> Path:
    """A binary PLY fan: ``n`` triangles around one centre vertex (three quarters of a disc)."""
    angle = np.linspace(0.0, 1.5 * np.pi, n + 1)
    rim = np.c_[np.cos(angle), np.sin(angle), np.zeros(n + 1)]
    faces = np.c_[np.zeros(n, dtype=np.int64), np.arange(1, n + 1), np.arange(2, n + 2)]
    trimesh.Trimesh(np.r_[[[0.0, 0.0, 0.0]], rim], faces, process=False).export(path)
    return path


def write_repeated(path: Path, n: int) -> Path:
    """An OBJ that lists one triangle ``n`` times (its vertices too)."""
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n" * n)
    return path


def write_cone(path: Path, n: int) -> Path:
    """A cone of ``n`` sides: ``n`` faces meet at its apex (the ring walk, tier 3)."""
    trimesh.creation.cone(1.0, 1.0, sections=n).export(path)
    return path


def write_chain(path: Path, n: int) -> Path:
    """A glTF whose ``n`` nodes are nested, each moved 1 along x from its parent, each with a triangle."""
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32).tobytes()
    import base64

    nodes = [{"translation": [1.0, 0.0, 0.0], "mesh": 0, **({"children": [i + 1]} if i + 1 < n else {})}
             for i in range(n)]
    gltf = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": nodes,
            "buffers": [{"byteLength": 36,
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(positions).decode()}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]}
    path.write_text(json.dumps(gltf))
    return path


ANGLES = itertools.count()


def load_seconds(path: Path) -> float:
    """The least CPU time of three loads (another crease angle each time: the cache is bypassed)."""
    best = math.inf
    for _ in range(3):
        angle = 20.0 + 0.01 * next(ANGLES)
        start = time.process_time()
        load_model(path, crease_angle=angle)
        best = min(best, time.process_time() - start)
    return best


@pytest.mark.parametrize("make, small, suffix", [(write_fan, 20_000, ".ply"), (write_repeated, 20_000, ".obj"),
                                                 (write_cone, 4_000, ".ply"), (write_chain, 300, ".gltf")])
def test_loading_grows_linearly_with_the_size(tmp_path: Path, make: Callable[[Path, int], Path], small: int,
                                              suffix: str) -> None:
    # Four times the size: linear work takes about 4x, square work 16x (a fan of 32,000 triangles took
    # 39 s, 5,000 nested glTF nodes 760 s). The bound, 9x, leaves room for a noisy machine.
    a = make(tmp_path / f"small{suffix}", small)
    b = make(tmp_path / f"large{suffix}", 4 * small)
    load_seconds(a)  # warm: imports and first-call costs out of the ratio
    ratio = load_seconds(b) / max(load_seconds(a), 1e-4)
    assert ratio < 9.0, f"{make.__name__}: 4x the size took {ratio:.1f}x the time"


def test_a_repeated_triangle_is_one_triangle_of_vertices(tmp_path: Path) -> None:
    model = load_model(write_repeated(tmp_path / "rep.obj", 50_000))
    assert model.triangles == 50_000 and model.mesh.vertex_count == 3


def test_nested_glTF_nodes_add_up_their_transforms(tmp_path: Path) -> None:
    mesh = load_model(write_chain(tmp_path / "chain.gltf", 400)).mesh
    corners = np.asarray(mesh.positions)[np.asarray(mesh.indices)].reshape(-1, 3, 3)
    # The node at depth d (1..400) is moved d along x: its triangle's first corner is at x = d.
    np.testing.assert_array_equal(np.sort(corners[:, :, 0].min(axis=1)), np.arange(1, 401))


def test_a_model_bigger_than_the_memory_limit_is_refused_before_loading(tmp_path: Path, monkeypatch) -> None:
    path = write_fan(tmp_path / "fan.ply", 10_000)
    monkeypatch.setenv(MEMORY_ENV, "1M")
    with pytest.raises(SandboxError) as caught:
        load_model(path)
    text = str(caught.value)
    need = 10_000 * BYTES_PER_TRIANGLE
    assert "\n" not in text and "10,000 triangles" in text and f"{need / 1e6:.1f} MB" in text
    assert f"{MEMORY_ENV}=" in text and str(path) in text
    monkeypatch.setenv(MEMORY_ENV, "1G")  # raised: it loads
    assert load_model(path).triangles == 10_000


def test_an_obj_is_refused_by_what_its_text_needs(tmp_path: Path, monkeypatch) -> None:
    # 10,000 triangles need 2.56 MB by their count; trimesh's parse of the 360 kB text of one triangle
    # repeated (vertices too), 40,000 short lines, needs more: that is the figure checked and given.
    path = write_repeated(tmp_path / "repeated.obj", 10_000)
    data = path.read_bytes()
    need = needed_bytes(10_000, "obj", data)
    assert need == len(data) * OBJ_BYTES_PER_FILE_BYTE + (data.count(b"\n") + 1) * OBJ_BYTES_PER_LINE
    assert need > 10_000 * BYTES_PER_TRIANGLE
    monkeypatch.setenv(MEMORY_ENV, str((need + 10_000 * BYTES_PER_TRIANGLE) // 2))
    with pytest.raises(SandboxError) as caught:
        load_model(path)
    text = str(caught.value)
    assert "\n" not in text and "10,000 triangles" in text and f"{need / 1e6:.1f} MB" in text
    monkeypatch.setenv(MEMORY_ENV, str(need))  # just enough: it loads
    assert load_model(path).triangles == 10_000


@pytest.mark.parametrize("kind", ["repeated", "normals"])
def test_the_obj_memory_estimate_covers_what_trimesh_parses(tmp_path: Path, kind: str) -> None:
    # The estimate of an OBJ's need (by its bytes and lines) against the traced peak of loading it:
    # the text's parse is trimesh's, so a reader that grew would show here.
    if kind == "repeated":
        path, triangles = write_repeated(tmp_path / "repeated.obj", 20_000), 20_000
    else:
        path, triangles = write_sphere_obj(tmp_path / "sphere.obj"), 20_480
    load_model(path, crease_angle=31.0)  # the reader's imports, once
    peak = traced_peak(lambda: load_model(path))
    need = needed_bytes(triangles, "obj", path.read_bytes())
    assert peak <= need, f"{peak / triangles:.0f} bytes per triangle at the peak, {need / triangles:.0f} estimated"


def test_an_obj_load_peaks_at_what_trimesh_alone_needs_to_parse_it(tmp_path: Path) -> None:
    # The text is trimesh's to parse: no copy of the file is kept beside it, and glsandbox's own
    # arrays after it (normals, vertices) peak lower than the parse. A copy kept (69 bytes per
    # triangle here, 12% of the parse) would show.
    path = write_sphere_obj(tmp_path / "sphere.obj")
    load_model(path, crease_angle=31.0)
    ours = traced_peak(lambda: load_model(path))
    alone = traced_peak(lambda: trimesh.load_scene(str(path), process=False))
    assert ours <= 1.04 * alone, f"{ours / 20_480:.0f} bytes per triangle, trimesh alone {alone / 20_480:.0f}"


def write_sphere_obj(path: Path) -> Path:
    """A 20,480-triangle sphere as an OBJ with normals, ``f a//a b//b c//c`` (as the bunny is written)."""
    sphere = trimesh.creation.icosphere(5)
    normals = sphere.vertices / np.linalg.norm(sphere.vertices, axis=1, keepdims=True)
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in sphere.vertices]
    lines += [f"vn {x:.6f} {y:.6f} {z:.6f}" for x, y, z in normals]
    lines += [f"f {a}//{a} {b}//{b} {c}//{c}" for a, b, c in sphere.faces + 1]
    path.write_text("\n".join(lines) + "\n")
    return path


def traced_peak(load: Callable[[], object]) -> int:
    """The peak of Python's and numpy's allocations while ``load`` runs (tracemalloc)."""
    import tracemalloc

    tracemalloc.start()
    try:
        load()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_the_memory_refusal_is_one_error_line_and_exit_2(tmp_path: Path) -> None:
    path = write_fan(tmp_path / "fan.ply", 10_000)
    out = tmp_path / "out" / "model.png"
    out.parent.mkdir()
    run = run_cli("render", "model", "--set", f"mesh={path}", "--out", str(out), "--size", "32x32",
                  env={MEMORY_ENV: "100K"}, unchanged=out.parent)
    assert_user_error(run, "10,000 triangles need about", f"{MEMORY_ENV}=")


def test_a_bad_memory_setting_is_an_error(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv(MEMORY_ENV, "lots")
    with pytest.raises(SandboxError, match=f"{MEMORY_ENV}='lots': expected a number of bytes"):
        load_model(write_fan(tmp_path / "fan.ply", 10))


def test_the_peak_memory_of_a_load_stays_near_its_budget(tmp_path: Path) -> None:
    # tracemalloc sees numpy's arrays: the peak while a 200,000-triangle fan (a vertex per triangle,
    # the worst case for the per-vertex arrays) becomes a drawable mesh, over its triangles.
    import tracemalloc

    path = write_fan(tmp_path / "fan.ply", 200_000)
    tracemalloc.start()
    try:
        load_model(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak / 200_000 <= BYTES_PER_TRIANGLE + 32, f"{peak / 200_000:.0f} bytes per triangle"


def _gltf_with_nodes(path: Path, nodes: list[dict]) -> Path:
    """A one-triangle glTF (buffer inline) whose scene starts at node 0 with ``nodes``."""
    import base64
    import json
    import struct

    data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    path.write_text(json.dumps({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}]}))
    return path


@pytest.mark.parametrize("nodes, node", [
    ([{"name": "loop", "mesh": 0, "children": [0]}], "loop"),  # its own child
    ([{"name": "a", "mesh": 0, "children": [1]}, {"name": "b", "mesh": 0, "children": [0]}], "a"),  # each other's
], ids=["self", "pair"])
def test_a_gltf_whose_nodes_form_a_cycle_is_refused_naming_the_file_and_the_node(tmp_path: Path, nodes, node) -> None:
    from glsandbox.mesh.load import load_model

    path = _gltf_with_nodes(tmp_path / "cycle.gltf", nodes)
    with pytest.raises(SandboxError) as caught:
        load_model(path)
    message = str(caught.value)
    assert str(path) in message and repr(node) in message and "cycle" in message and "\n" not in message
    ok = _gltf_with_nodes(tmp_path / "tree.gltf", [{"name": "a", "mesh": 0, "children": [1]}, {"name": "b", "mesh": 0}])
    assert sum(len(part.mesh.triangle_indices()) for part in load_model(ok).parts) == 2


def test_a_groups_position_ids_are_renumbered_in_their_order() -> None:
    # Each material's mesh numbers its positions 0.. in the file's order: its arrays are sized by
    # its own positions, not the whole file's (a glTF of many nodes was quadratic), with the same result.
    import inspect

    _compact_ids = inspect.getmodule(load_model)._compact_ids  # (the loader's own module)

    ids = np.array([7, 3, 7, 12, 3, 40], dtype=np.intp)
    assert _compact_ids(ids).tolist() == [1, 0, 1, 2, 0, 3]
    assert _compact_ids(np.zeros(0, dtype=np.intp)).size == 0
