"""Mesh vertices far from the origin: refused beyond the model matrices' bound (one line
naming the mesh), and within it drawn right by every engine: a quad at the origin beside one
stray triangle 9e5 away, in the same mesh or in a node of its own, has the pixels it has alone
(the gpu engine's float32 anchor is a median, which the stray triangle does not move). The
rasterizer and the gpu engine on both headless backends (EGL and OSMesa: support.on_backend)."""

from __future__ import annotations

import numpy as np
import pytest
from support import gpu_image, on_backend, raster_image, stray_scene

from glsandbox import Mesh
from glsandbox.errors import SandboxError

#: Corners on no float32 grid of a far anchor (0.77 is no multiple of 2⁻⁵, the spacing at 5e5).
QUAD = 0.77 * np.array([(-1.0, -1.0, 0.0), (1.0, -1.0, 0.0), (1.0, 1.0, 0.0), (-1.0, -1.0, 0.0), (1.0, 1.0, 0.0),
                        (-1.0, 1.0, 0.0)]) + (0.013, 0.0, 0.0)
SIZE = (160, 120)


def stray(at: float) -> np.ndarray:
    """One triangle ``at`` along +x, off to the side of the camera's view (its far corner, row 1, is the largest)."""
    return np.array([(at, 0.0, 0.0), (at + 1.0, 0.0, 0.0), (at, 1.0, 0.0)])


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


def changed_pixels(image: np.ndarray, alone: np.ndarray) -> int:
    return int(np.count_nonzero(np.abs(image.astype(int) - alone.astype(int)).max(axis=-1) > 2))


@pytest.mark.parametrize("layout", LAYOUTS)
def test_a_stray_vertex_leaves_the_quad_drawn_right_by_the_numpy_engine(layout) -> None:
    from glsandbox.raytrace import render

    alone = render(stray_scene({"quad": QUAD}), SIZE)
    assert np.count_nonzero(alone[..., :3].max(axis=-1)) > 150  # the quad
    assert changed_pixels(render(stray_scene(LAYOUTS[layout]), SIZE), alone) == 0


@pytest.fixture(scope="module")
def drawn(backend, gl_renderer) -> dict[tuple[str, str], np.ndarray]:
    """The quad alone and each layout, by (renderer, layout), rasterized and gpu-traced on
    ``backend`` (one subprocess for the other backend)."""
    layouts = {"alone": {"quad": QUAD}, **LAYOUTS}
    keys = [(draw, name) for draw in ("raster", "gpu") for name in layouts]
    images = on_backend(backend, gl_renderer, [
        (raster_image if draw == "raster" else gpu_image, (SIZE, stray_scene, layouts[name])) for draw, name in keys])
    return dict(zip(keys, images))


@pytest.mark.parametrize("layout", LAYOUTS)
def test_a_stray_vertex_leaves_the_quad_drawn_right_by_the_rasterizer_and_the_gpu_engine(drawn, backend,
                                                                                         layout) -> None:
    for draw in ("raster", "gpu"):
        assert np.count_nonzero(drawn[draw, "alone"][..., :3].max(axis=-1)) > 150  # the quad
    assert np.array_equal(drawn["raster", layout], drawn["raster", "alone"]), f"{backend}, {layout}: the rasterizer"
    lost = changed_pixels(drawn["gpu", layout], drawn["gpu", "alone"])
    assert lost == 0, f"{backend}, {layout}: {lost} of the gpu engine's quad pixels changed"
