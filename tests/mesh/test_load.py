"""Model files (glsandbox.mesh.load): every format through trimesh, normals, uvs, textures, fit, the cache,
degenerate faces, and flat normals for lit meshes that have none."""

from __future__ import annotations

import logging
import os
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh

import glsandbox
from support import CUBE_OBJ, quadrant_image, textured_quad_glb

from glsandbox import geometry
from glsandbox.errors import SandboxError
from glsandbox.mesh.load import fit_mesh, is_model_path, load_mesh, load_model

def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


# --- formats ------------------------------------------------------------------


def test_an_obj_without_normals_gets_crease_normals(tmp_path: Path) -> None:
    model = load_model(write(tmp_path / "cube.obj", CUBE_OBJ))
    mesh = model.mesh
    assert model.triangles == 12 and model.dropped_faces == 0 and model.normals == "crease 30°"
    assert mesh.mode == "triangles" and mesh.indices is not None and len(mesh.indices) == 36
    # A cube's edges are 90°, sharper than 30°: each face keeps its own four vertices and normal.
    assert mesh.vertex_count == 24
    np.testing.assert_allclose(np.abs(mesh.normals).max(axis=1), 1.0)
    tri = mesh.positions[np.asarray(mesh.indices).reshape(-1, 3)]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    corner_normals = mesh.normals[np.asarray(mesh.indices).reshape(-1, 3)]
    assert (np.einsum("fj,fkj->fk", face, corner_normals) > 0).all()  # normals agree with the winding
    assert mesh.uvs is None and mesh.colors is None and model.texture is None
    assert mesh.name == "cube.obj" and "normals crease 30°" in mesh.notes


@pytest.mark.parametrize("mode, vertices", [("smooth", 8), ("flat", 24), ("crease", 24)])
def test_normals_can_be_asked_for(tmp_path: Path, mode: str, vertices: int) -> None:
    model = load_model(write(tmp_path / "cube.obj", CUBE_OBJ), normals=mode)
    assert model.mesh.vertex_count == vertices
    if mode == "smooth":  # one normal per corner: the diagonal, as the faces' angles weigh equally
        np.testing.assert_allclose(model.mesh.normals, model.mesh.positions / np.sqrt(3.0), atol=1e-12)


def test_a_crease_angle_above_the_cube_edges_smooths_them(tmp_path: Path) -> None:
    assert load_model(write(tmp_path / "cube.obj", CUBE_OBJ), crease_angle=95).mesh.vertex_count == 8


def test_an_obj_with_normals_and_uvs_keeps_them_with_v_flipped(tmp_path: Path) -> None:
    # Normals tilted on purpose, so they can only have come from the file.
    path = write(tmp_path / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                       "vn 0 0.6 0.8\nvn 0.6 0 0.8\nvn 0 0 2\nf 1/1/1 2/2/2 3/3/3\n")
    model = load_model(path)
    mesh = model.mesh
    assert model.normals == "file" and "normals from the file" in mesh.notes
    order = np.lexsort(mesh.positions.T[::-1])
    np.testing.assert_allclose(mesh.positions[order], [[0, 0, 0], [0, 1, 0], [1, 0, 0]])
    np.testing.assert_allclose(mesh.normals[order], [[0, 0.6, 0.8], [0, 0, 1], [0.6, 0, 0.8]])  # unit length
    # OBJ's vt has v up; the course's textures have v down (row 0 at the top).
    np.testing.assert_allclose(mesh.uvs[order], [[0, 1], [0, 0], [1, 1]])
    with pytest.raises(SandboxError, match=r"cube.obj has no vertex normals \(normals = \"file\"\)"):
        load_model(write(tmp_path / "cube.obj", CUBE_OBJ), normals="file")


def test_a_ply_with_normals_and_colours(tmp_path: Path) -> None:
    sphere = trimesh.creation.icosphere(subdivisions=1)
    normals = np.asarray(sphere.vertices) * np.array([1.0, 2.0, 1.0])  # not the geometric normals
    colors = np.tile([255, 128, 0, 255], (len(sphere.vertices), 1)).astype(np.uint8)
    mesh = trimesh.Trimesh(sphere.vertices, sphere.faces, vertex_normals=normals, vertex_colors=colors,
                           process=False)
    path = tmp_path / "ball.ply"
    path.write_bytes(trimesh.exchange.ply.export_ply(mesh, encoding="binary", vertex_normal=True))
    loaded = load_model(path)
    assert loaded.normals == "file" and loaded.triangles == 80
    got = loaded.mesh
    want = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    lookup = {tuple(np.round(p, 6)): n for p, n in zip(np.asarray(sphere.vertices), want)}
    for p, n in zip(got.positions, got.normals):
        np.testing.assert_allclose(n, lookup[tuple(np.round(p, 6))], atol=1e-6)
    np.testing.assert_allclose(got.colors, np.tile([1.0, 128 / 255, 0.0], (got.vertex_count, 1)))


def test_stl_and_off_load_the_same_box(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(2, 4, 6))
    box.export(tmp_path / "box.stl")
    box.export(tmp_path / "box.off")
    for name in ("box.stl", "box.off"):
        model = load_model(tmp_path / name)
        assert model.triangles == 12 and model.normals == "crease 30°", name
        np.testing.assert_allclose(model.mesh.positions.min(axis=0), (-1, -2, -3))
        np.testing.assert_allclose(model.mesh.positions.max(axis=0), (1, 2, 3))
        assert model.mesh.vertex_count == 24, name  # STL's 36 unshared corners welded back


def test_a_glb_brings_its_base_colour_texture(tmp_path: Path) -> None:
    model = load_model(textured_quad_glb(tmp_path / "quad.glb"))
    assert model.triangles == 2 and model.color == (1.0, 1.0, 1.0, 1.0)
    texture = model.texture
    assert texture is not None and not texture.is_file and texture.digest
    np.testing.assert_array_equal(texture.image[..., :3], np.asarray(quadrant_image()))
    mesh = model.mesh
    # The quad's top-left corner (-1, 1) samples the image's top-left texel: uv (0, 0), v down.
    corner = int(np.flatnonzero((mesh.positions[:, :2] == (-1, 1)).all(axis=1))[0])
    np.testing.assert_allclose(mesh.uvs[corner], (0, 0))
    node_material = model.material(shading="phong")
    assert node_material.texture is texture and node_material.color == (1.0, 1.0, 1.0, 1.0)


def test_gltf_node_transforms_are_applied(tmp_path: Path) -> None:
    scene = trimesh.Scene()
    box = trimesh.creation.box(extents=(1, 1, 1))
    scene.add_geometry(box, transform=trimesh.transformations.translation_matrix((5, 0, 0)))
    scene.add_geometry(box, transform=trimesh.transformations.translation_matrix((-5, 0, 0)))
    scene.export(tmp_path / "two.glb")
    model = load_model(tmp_path / "two.glb")
    assert model.triangles == 24
    np.testing.assert_allclose(model.mesh.positions[:, 0].min(), -5.5)
    np.testing.assert_allclose(model.mesh.positions[:, 0].max(), 5.5)


# --- fit, the cache ------------------------------------------------------------


def test_fit_centres_and_scales_into_the_box_of_the_built_in_cube(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(8, 4, 2), transform=trimesh.transformations.translation_matrix((10, 5, 0)))
    box.export(tmp_path / "box.off")
    mesh = load_mesh(tmp_path / "box.off", fit=True)
    np.testing.assert_allclose(mesh.positions.min(axis=0), (-1, -0.5, -0.25))
    np.testing.assert_allclose(mesh.positions.max(axis=0), (1, 0.5, 0.25))
    assert "fitted into -1..1" in mesh.notes
    raw = load_mesh(tmp_path / "box.off")
    np.testing.assert_allclose(raw.positions.min(axis=0), (6, 3, -1))
    np.testing.assert_allclose(fit_mesh(raw).positions, mesh.positions)
    np.testing.assert_array_equal(raw.normals, mesh.normals)  # a uniform scale keeps directions


def test_loads_are_cached_by_path_time_size_and_options(tmp_path: Path) -> None:
    path = write(tmp_path / "cube.obj", CUBE_OBJ)
    first = load_model(path)
    assert load_model(str(path)) is first and load_mesh(path) is first.mesh
    assert load_model(path, fit=True) is not first and load_model(path, normals="flat") is not first
    write(path, CUBE_OBJ + "f 1 2 3\n")  # a different size
    os.utime(path, ns=(1, 1))
    again = load_model(path)
    assert again is not first and again.triangles == 13


# --- degenerate faces, bad data -------------------------------------------------


def test_degenerate_faces_are_dropped_and_counted(tmp_path: Path) -> None:
    text = CUBE_OBJ + "v 0 5 0\nv 1 5 0\nv 2 5 0\nf 9 10 11\nf 1 1 2\nf 9 9 9\n"  # collinear, repeated, a point
    model = load_model(write(tmp_path / "cube.obj", text))
    assert model.dropped_faces == 3 and model.triangles == 12
    assert "3 degenerate faces dropped (zero area or a repeated vertex)" in model.mesh.notes
    assert model.mesh.positions[:, 1].max() == 1.0  # the dropped faces' vertices are gone too


@pytest.mark.parametrize("name, text, message", [
    ("flat.obj", "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 1 1 3\n",
     r"flat.obj has no faces: all 2 are degenerate"),
    ("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", r"points.obj has no faces"),
    ("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", r"nan.obj: 1 vertex with NaN or infinite coordinates"),
    ("inf.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", r"inf.off: 1 vertex with NaN or infinite"),
    ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", r"range.obj: not a readable OBJ file: a face index is out"),
    ("range.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
     r"range.ply: face 0 refers to vertex 7, but the file has 3 vertices"),
    ("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -4\n", r"range.off"),
    ("model.xyz", "1 2 3\n", r"model.xyz: unknown format \(extension '.xyz'\); use one of .obj"),
    ("empty.stl", "", r"empty.stl is empty"),
])
def test_bad_files_are_one_line_naming_the_file(tmp_path: Path, name: str, text: str, message: str) -> None:
    with pytest.raises(SandboxError, match=message) as info:
        load_model(write(tmp_path / name, text))
    assert "\n" not in str(info.value) and str(tmp_path / name) in str(info.value)


def test_truncated_and_garbage_binaries_are_refused(tmp_path: Path) -> None:
    box = trimesh.creation.box()
    rng = np.random.default_rng(7)
    for ext in ("ply", "stl", "glb"):
        whole = box.export(file_type=ext) if ext != "ply" else trimesh.exchange.ply.export_ply(box, encoding="binary")
        (tmp_path / f"half.{ext}").write_bytes(whole[: len(whole) // 2])
        (tmp_path / f"noise.{ext}").write_bytes(rng.integers(0, 256, 600, dtype=np.uint8).tobytes())
        for stem in ("half", "noise"):
            with pytest.raises(SandboxError) as info:
                load_model(tmp_path / f"{stem}.{ext}")
            assert f"model file {tmp_path / f'{stem}.{ext}'}" in str(info.value) and "\n" not in str(info.value)


def test_folders_fifos_and_missing_files_are_refused_before_opening(tmp_path: Path) -> None:
    (tmp_path / "dir.obj").mkdir()
    os.mkfifo(tmp_path / "pipe.obj")  # opening it for reading would wait for a writer forever
    for name, message in (("dir.obj", "is a folder"), ("pipe.obj", "is a named pipe (FIFO)"),
                          ("none.obj", "not found")):
        with pytest.raises(SandboxError, match=re.escape(f"model file {tmp_path / name} {message}")):
            load_model(tmp_path / name)


def test_bad_options_are_refused(tmp_path: Path) -> None:
    path = write(tmp_path / "cube.obj", CUBE_OBJ)
    with pytest.raises(SandboxError, match="unknown normals 'bent'"):
        load_model(path, normals="bent")
    with pytest.raises(SandboxError, match="crease angle must be"):
        load_model(path, crease_angle=200)


def test_trimesh_says_nothing_on_stderr(tmp_path: Path, capfd) -> None:
    logger = logging.getLogger("trimesh")
    level = logger.level
    (tmp_path / "noise.stl").write_bytes(bytes(range(256)) * 3)
    # trimesh logs a warning with a traceback when a PLY's texture file is missing.
    ply = write(tmp_path / "texref.ply", "ply\nformat ascii 1.0\ncomment TextureFile missing.png\n"
                "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    assert load_model(ply).triangles == 1
    load_model(write(tmp_path / "cube.obj", CUBE_OBJ))
    load_model(textured_quad_glb(tmp_path / "quad.glb"))
    with pytest.raises(SandboxError):
        load_model(tmp_path / "noise.stl")
    captured = capfd.readouterr()
    assert captured.err == "" and captured.out == ""
    assert logger.level == level  # put back as it was


def test_model_paths_and_built_in_names_are_told_apart() -> None:
    assert not any(is_model_path(name) for name in geometry.BUILTIN_MESHES)
    assert all(is_model_path(name) for name in ("bunny.obj", "models/bunny", "x.PLY", "cbe.ob"))
    assert not is_model_path("cbe")  # a misspelt built-in name stays "unknown mesh"


def test_the_public_face_loads_models(tmp_path: Path) -> None:
    path = write(tmp_path / "cube.obj", CUBE_OBJ)
    assert glsandbox.load_mesh(path) is glsandbox.load_model(path).mesh
    assert isinstance(glsandbox.load_model(path), glsandbox.Model)
    assert glsandbox.meshgen.rock(1).triangle_indices().shape == (80, 3)


def test_the_plan_lists_what_loading_did_for_each_node(tmp_path: Path) -> None:
    from glsandbox import Node, Scene
    from glsandbox.plan import plan

    mesh = load_mesh(write(tmp_path / "cube.obj", CUBE_OBJ + "f 1 1 2\n"), fit=True)
    described = plan(Scene("s", nodes=(Node("box", mesh), Node("plain", geometry.cube())))).describe()
    assert described.endswith("meshes:\n  box: cube.obj: 12 triangles (OBJ), 1 degenerate face dropped "
                              "(zero area or a repeated vertex), normals crease 30°, fitted into -1..1")
    assert "meshes:" not in plan(Scene("s", nodes=(Node("plain", geometry.cube()),))).describe()
