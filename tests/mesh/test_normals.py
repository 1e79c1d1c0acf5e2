"""The flat-shading trap: a lit node whose mesh has no normals (``mesh = "cube"``, ``shading = "phong"``).

The ray tracer shades such a mesh with each triangle's face normal; the
rasterizer used to refuse it ("mesh 'cube' has no normal data"). Now it
draws the mesh un-indexed with the same face normals
(:func:`glsandbox.geometry.with_face_normals`), so the two agree.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from glsandbox import Camera, Light, Material, Node, Scene, Viewport, geometry, transforms
from glsandbox.lesson import scene_file_lesson
from glsandbox.mesh.normals import normal_groups, row_ids


def test_meshes_without_normals_get_face_normals_once() -> None:
    cube = geometry.cube()
    flat = geometry.with_face_normals(cube)
    assert geometry.with_face_normals(cube) is flat and flat.indices is None
    assert flat.vertex_count == 36 and flat.colors.shape == (36, 3)
    tri = flat.positions.reshape(-1, 3, 3)
    np.testing.assert_array_equal(tri, cube.triangles())  # the same triangles, in order
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    np.testing.assert_allclose(flat.normals.reshape(-1, 3, 3), np.repeat(face[:, None], 3, axis=1))
    np.testing.assert_allclose(np.abs(flat.normals).max(axis=1), 1.0)  # the cube's six axis directions
    assert geometry.with_face_normals(geometry.cube24()) is geometry.cube24()  # has normals: unchanged
    strip = geometry.with_face_normals(geometry.quad_strip())
    np.testing.assert_allclose(strip.normals, np.tile([0.0, 0.0, 1.0], (6, 1)))  # both strip triangles face +z


def lit_cube(shading: str, renderer: str) -> Scene:
    model = transforms.rotate_y(0.6) @ transforms.rotate_x(0.3)
    node = Node("cube", geometry.cube(), model, Material(color=(0.8, 0.3, 0.2, 1.0), shading=shading))
    lights = (Light((2.0, 4.0, 3.0)), Light((-3.0, 2.0, 2.0), (1.0, 1.0, 0.0)))
    return Scene("lit cube", nodes=(node,), camera=Camera(eye=(0.0, 2.0, 6.0)), lights=lights,
                 viewports=(Viewport(renderer=renderer),))


@pytest.mark.parametrize("shading", ["phong", "blinn_phong"])
def test_raster_and_ray_shade_a_normal_less_cube_alike(gl, shading: str) -> None:
    raster = gl.render_scene(lit_cube(shading, "raster"), (128, 128)).image.astype(int)
    ray = gl.render_scene(lit_cube(shading, "ray"), (128, 128)).image.astype(int)
    background = np.all(raster == raster[0, 0], axis=2)
    assert 0.15 < 1.0 - background.mean() < 0.6  # the cube covers a good part of the frame
    # Three faces visible, each lit differently: flat shading, not one colour.
    shades = {tuple(raster[y, x, :3] // 24) for y, x in zip(*np.nonzero(~background))}
    assert len(shades) >= 3
    differ = np.abs(raster - ray).max(axis=2) > 8
    assert differ.mean() < 0.005, f"{differ.mean():.2%} of pixels differ by more than 8 levels"


def test_a_scene_file_lit_cube_renders_in_every_lit_shading(gl, tmp_path: Path) -> None:
    for shading in ("phong", "gouraud", "blinn_phong"):
        path = tmp_path / f"{shading}.toml"
        path.write_text(f'[[lights]]\nposition = [2, 4, 3]\n\n[[nodes]]\nmesh = "cube"\nshading = "{shading}"\n'
                        'rotate = [20, 35, 0]\ncolor = [0.2, 0.5, 0.9]\n')
        image = gl.render(scene_file_lesson(path)(), (64, 64)).image
        assert image[32, 32, 2] > image[32, 32, 0]  # the blue cube, lit, in the middle


@pytest.mark.parametrize("mode", ["flat", "smooth", "crease"])
def test_corners_at_one_position_share_a_group_exactly_when_their_normals_are_bit_identical(mode: str) -> None:
    # A box split per face (24 vertices, 8 positions), a cone apex of 80 faces (the ring walk) and a
    # fan of coplanar faces: groups are what tells a position's vertices apart, with no hash of normals.
    box = trimesh.creation.box()
    cone = trimesh.creation.cone(1.0, 1.0, sections=80)
    for vertices, faces in ((np.asarray(box.vertices)[np.asarray(box.faces).reshape(-1)], np.arange(36).reshape(-1, 3)),
                            (np.asarray(cone.vertices), np.asarray(cone.faces))):
        tris = faces.astype(np.intp)
        group, normals = normal_groups(vertices, tris, mode, 30.0)
        position = row_ids(vertices)[0][tris.reshape(-1)]
        bits = normals[group].view(np.uint64)
        for p in np.unique(position):
            here = np.flatnonzero(position == p)
            same_group = group[here][:, None] == group[here][None, :]
            same_normal = (bits[here][:, None, :] == bits[here][None, :, :]).all(axis=-1)
            assert (same_group == same_normal).all()
