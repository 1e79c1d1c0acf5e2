"""Mesh vertices far from the origin: refused beyond the model matrices' bound (one line
naming the mesh), and within it drawn right by every engine: a quad at the origin beside one
stray triangle 9e5 away, in the same mesh or in a node of its own, has the pixels it has alone
(the gpu engine's float32 anchor is a median, which the stray triangle does not move)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox import Camera, Material, Mesh, Node, Scene
from glsandbox.errors import SandboxError

#: Corners on no float32 grid of a far anchor (0.77 is no multiple of 2⁻⁵, the spacing at 5e5).
QUAD = 0.77 * np.array([(-1.0, -1.0, 0.0), (1.0, -1.0, 0.0), (1.0, 1.0, 0.0), (-1.0, -1.0, 0.0), (1.0, 1.0, 0.0),
                        (-1.0, 1.0, 0.0)]) + (0.013, 0.0, 0.0)
SIZE = (160, 120)


def stray(at: float) -> np.ndarray:
    """One triangle ``at`` along +x, off to the side of the camera's view (its far corner, row 1, is the largest)."""
    return np.array([(at, 0.0, 0.0), (at + 1.0, 0.0, 0.0), (at, 1.0, 0.0)])


def scene(parts: dict[str, np.ndarray]) -> Scene:
    material = Material(color=(0.9, 0.4, 0.2, 1.0))
    nodes = tuple(Node(name, Mesh(name, positions), np.eye(4), material) for name, positions in parts.items())
    return Scene("stray", nodes=nodes, camera=Camera(eye=(0.0, 0.0, 2.5), target=(0.0, 0.0, 0.0)),
                 clear_color=(0.0, 0.0, 0.0, 1.0))


def test_a_vertex_beyond_the_bound_is_refused_naming_the_mesh() -> None:
    with pytest.raises(SandboxError) as caught:
        Mesh("with_stray", np.concatenate([QUAD, stray(1e8)]))
    message = str(caught.value)
    assert "\n" not in message and "'with_stray'" in message and "positions[7]" in message and "1e+06" in message
    Mesh("within", np.concatenate([QUAD, stray(9.3e5)]))  # the bound itself is allowed


LAYOUTS = {
    "same_mesh": {"quad": np.concatenate([QUAD, stray(9.3e5)])},
    "own_node": {"quad": QUAD, "stray": stray(9.3e5)},
}


@pytest.mark.parametrize("layout", LAYOUTS)
def test_a_stray_vertex_leaves_the_quad_drawn_right_by_each_ray_engine(engine, layout) -> None:
    alone = engine.render(scene({"quad": QUAD}), SIZE)
    image = engine.render(scene(LAYOUTS[layout]), SIZE)
    lit = np.count_nonzero(alone[..., :3].max(axis=-1))
    assert lit > 150  # the quad
    differ = np.count_nonzero(np.abs(image.astype(int) - alone.astype(int)).max(axis=-1) > 2)
    assert differ == 0, f"{engine.name}, {layout}: {differ} of the quad's {lit} pixels changed"


@pytest.mark.parametrize("layout", LAYOUTS)
def test_a_stray_vertex_leaves_the_quad_drawn_right_by_the_rasterizer(gl, layout) -> None:
    alone = gl.render_scene(scene({"quad": QUAD}), SIZE).image
    image = gl.render_scene(scene(LAYOUTS[layout]), SIZE).image
    assert np.count_nonzero(alone[..., :3].max(axis=-1)) > 150
    assert np.array_equal(image, alone)
