"""The X-ray's primitive-id picture against a CPU rasterisation of the same triangles (top-left rule)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.geometry import Mesh
from glsandbox.scene import Camera, Material, Node, Scene
from glsandbox.story.coverage import rasterize_ids, window_positions
from glsandbox.story.xray import xray

SIZE = (40, 30)
CAMERA = Camera(eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), fov_y=50.0)

#: GL window positions (x right, y up from the bottom row, pixels) of each node's triangles:
#: edges along pixel centres (x or y = k + ½), shared edges, diagonals through centres, both windings.
FANS = {
    "fan": [[(4.5, 4.5), (20.5, 4.5), (12.5, 12.5)], [(4.5, 4.5), (12.5, 12.5), (4.5, 20.5)],
            [(12.5, 12.5), (20.5, 4.5), (20.5, 20.5)], [(4.5, 20.5), (12.5, 12.5), (20.5, 20.5)]],
    "strip": [[(22.5, 3.0), (36.0, 3.5), (22.5, 14.5)], [(36.0, 3.5), (36.0, 14.5), (22.5, 14.5)],
              [(22.5, 16.5), (29.25, 27.75), (36.5, 16.5)]],
}


def world_of(window: np.ndarray, depth: float = 0.5) -> np.ndarray:
    """The world points that the camera puts at these window positions (NDC z = ``depth``)."""
    width, height = SIZE
    ndc = np.stack([window[:, 0] / width * 2.0 - 1.0, window[:, 1] / height * 2.0 - 1.0,
                    np.full(len(window), depth), np.ones(len(window))], axis=1)
    inverse = np.linalg.inv(CAMERA.projection(width / height) @ CAMERA.view())
    world = ndc @ inverse.T
    return world[:, :3] / world[:, 3:4]


def test_primitive_ids_are_the_cpu_rasterisation(gl) -> None:
    nodes = []
    for name, triangles in FANS.items():
        window = np.array(triangles, dtype=np.float64).reshape(-1, 2)
        mesh = Mesh(name, world_of(window), np.arange(len(window), dtype=np.uint32))
        nodes.append(Node(name, mesh, np.eye(4), Material(color=(0.9, 0.5, 0.2, 1.0)), cull_back_faces=False))
    scene = Scene("ids", nodes=tuple(nodes), camera=CAMERA, clear_color=(0.0, 0.0, 0.0, 1.0))
    x = xray(gl, scene, SIZE)
    ids = x.passes[-1].ids
    assert ids is not None
    for number, (name, triangles) in enumerate(FANS.items(), start=1):
        # The window positions the GPU's float32 transform gives back, snapped by the CPU rule.
        clip = np.c_[nodes[number - 1].mesh.positions, np.ones(len(nodes[number - 1].mesh.positions))] @ \
            (CAMERA.projection(SIZE[0] / SIZE[1]) @ CAMERA.view()).T
        cpu = rasterize_ids(window_positions(clip, SIZE).reshape(-1, 3, 2), SIZE)
        gpu = np.where(ids[..., 0] == number, ids[..., 1].astype(np.int64), -1)
        assert (cpu >= 0).sum() > 50
        assert np.array_equal(gpu, cpu), (name, np.argwhere(gpu != cpu)[:10])
    # No pixel of a shared edge is missed: the fan covers its square's centres (4.5 .. 19.5 each way,
    # the top edge at GL y = 20.5 out, the bottom one at 4.5 in: rows 30 - 20 .. 30 - 5 as shown).
    fan = ids[..., 0] == 1
    assert fan[10:26, 4:20].all() and not fan[9, 4:20].any() and not fan[26, 4:20].any()


@pytest.mark.parametrize("flip", [False, True])
def test_cpu_rule_shares_every_edge(flip: bool) -> None:
    """Two triangles sharing an edge through pixel centres: every centre of the square is drawn once."""
    a, b, c, d = (2.5, 2.5), (10.5, 2.5), (10.5, 10.5), (2.5, 10.5)
    tris = [[a, b, c], [a, c, d]] if not flip else [[a, c, b], [a, d, c]]
    ids = rasterize_ids(np.array(tris), (14, 14))
    # GL's rows as stored (y up): the centres 2.5 .. 9.5 each way are in (the edge on the first rows,
    # y = 2.5, and the left one count; the one at y = 10.5 and the right one do not).
    shown = ids[::-1]  # back to GL's rows, row 0 at the bottom
    assert (shown[2:10, 2:10] >= 0).all() and (shown[:2] == -1).all() and (shown[10:] == -1).all()
    assert (shown[:, :2] == -1).all() and (shown[:, 10:] == -1).all()
    # The shared diagonal's centres (x = y) belong to one triangle only: the one right of it (b's side).
    assert {int(shown[k, k]) for k in range(2, 10)} == {0}
