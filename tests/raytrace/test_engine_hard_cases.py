"""Every engine path (numpy and gpu, scan and BVH) in the regimes that break ray
tracers: rays aimed exactly at the vertices and edges of closed meshes, a whole
view from inside a closed mesh, with the scene at the origin and moved to 1e3,
1e5 and 1e6. A watertight test traced in coordinates that do not lose their
bits far from the origin never misses; Möller–Trumbore in float32 world
coordinates (the gpu scan's old way) missed 0.5-17% of these rays."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from glsandbox import Camera, Material, Node, Scene, geometry, meshgen, transforms
from glsandbox.measure.knobs._far import DIRECTION

OFFSETS = (0.0, 1e3, 1e5, 1e6)
RED = (1.0, 0.0, 0.0, 1.0)


def closed_meshes():
    return {"cube": geometry.cube(), "icosahedron": meshgen.icosphere(0), "icosphere1": meshgen.icosphere(1)}


def features(mesh, model):
    """World-space ``(point, outward direction)`` pairs: every vertex (along the mean
    of its faces' normals) and three points on every edge (along the mean of its two
    faces' normals). A ray from ``point + 3·direction`` to ``point`` enters the solid."""
    positions = transforms.transform_points(model, np.asarray(mesh.positions, dtype=np.float64))
    tris = np.asarray(mesh.indices, dtype=np.intp).reshape(-1, 3)
    keys = {tuple(p): i for i, p in enumerate(np.round(positions, 9).tolist())}  # one id per position
    canon = np.array([keys[tuple(p)] for p in np.round(positions, 9).tolist()])
    tris = canon[tris]
    face = np.cross(positions[tris[:, 1]] - positions[tris[:, 0]], positions[tris[:, 2]] - positions[tris[:, 0]])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    vertex_normal: dict[int, np.ndarray] = {}
    edge_normal: dict[tuple[int, int], np.ndarray] = {}
    for tri, n in zip(tris, face):
        for k in range(3):
            vertex_normal[tri[k]] = vertex_normal.get(tri[k], 0.0) + n
            edge = tuple(sorted((int(tri[k]), int(tri[(k + 1) % 3]))))
            edge_normal[edge] = edge_normal.get(edge, 0.0) + n
    found = [(positions[v], n / np.linalg.norm(n)) for v, n in vertex_normal.items()]
    for (a, b), n in edge_normal.items():
        for f in (0.3, 0.5, 0.71):
            found.append((positions[a] + f * (positions[b] - positions[a]), n / np.linalg.norm(n)))
    return found


def aimed_scenes(name: str, offset: float):
    """One scene per feature ray: the closed mesh (unlit red, both faces) under a black
    background, moved by ``offset``, the camera aimed exactly at the feature (a 1x1
    image's one ray runs from the eye through the target)."""
    model = transforms.translate(*(offset * DIRECTION)) @ transforms.rotate_y(0.3)
    node = Node(name, closed_meshes()[name], model, Material(color=RED), cull_back_faces=False)
    base = Scene(name, nodes=(node,), clear_color=(0.0, 0.0, 0.0, 1.0))
    rng = np.random.default_rng(7)
    scenes = []
    for point, outward in features(node.mesh, model):
        for tilt in range(2):  # straight in, and tilted a little within the solid's cone
            direction = outward + (0.12 * rng.standard_normal(3) if tilt else 0.0)
            up = (0.0, 1.0, 0.0) if abs(direction[1]) < 0.9 * np.linalg.norm(direction) else (1.0, 0.0, 0.0)
            camera = Camera(eye=tuple(point + 3.0 * direction / np.linalg.norm(direction)), target=tuple(point),
                            up=up, near=0.01, far=100.0)
            scenes.append(dataclasses.replace(base, camera=camera))
    return scenes


@pytest.mark.parametrize("offset", OFFSETS, ids=lambda o: f"at{o:g}")
@pytest.mark.parametrize("name", ["cube", "icosahedron", "icosphere1"])
def test_rays_aimed_at_vertices_and_edges_never_miss(engine_path, name, offset) -> None:
    scenes = aimed_scenes(name, offset)
    assert len(scenes) >= 2 * (8 + 18)
    missed = [i for i, scene in enumerate(scenes)
              if not engine_path(scene, (1, 1), shadows=False, max_depth=0)[0, 0, :3].any()]
    assert missed == [], f"{engine_path.path}: {len(missed)} of {len(scenes)} rays through vertices and edges missed"


@pytest.mark.parametrize("offset", OFFSETS, ids=lambda o: f"at{o:g}")
def test_a_view_from_inside_a_closed_mesh_has_no_hole(engine_path, offset) -> None:
    # Every primary ray from inside a closed mesh crosses it: a background pixel is a
    # ray that slipped between two triangles (the gpu scan had 30-45 at 1e3 before).
    centre = offset * DIRECTION
    model = transforms.translate(*centre) @ transforms.scale(3.0, 2.0, 2.5)
    node = Node("shell", meshgen.icosphere(2), model, Material(color=RED), cull_back_faces=False)
    camera = Camera(eye=tuple(centre + (0.31, 0.17, 0.4)), target=tuple(centre + (-1.0, -0.3, -2.0)),
                    fov_y=100.0, near=0.01, far=100.0)
    scene = Scene("inside", nodes=(node,), camera=camera, clear_color=(0.0, 0.0, 0.0, 1.0))
    image = engine_path(scene, (121, 91), shadows=False, max_depth=0)
    holes = int(np.count_nonzero(~image[..., :3].any(axis=-1)))
    assert holes == 0, f"{engine_path.path}: {holes} holes at offset {offset:g}"
