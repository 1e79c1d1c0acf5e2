"""Textures held in memory (``Texture(image=...)``, a model file's base colour texture): both renderers
sample them, and they are told apart by their pixels."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from glsandbox import Camera, Material, Node, Scene, Texture, Viewport, geometry, transforms
from glsandbox.errors import SandboxError
from glsandbox.images import texture_levels

#: Red top-left, green top-right, blue bottom-left, yellow bottom-right; 16x16 pixels, so that
#: the ray tracer's bilinear sampling (base level only) reads pure colours inside each quadrant.
QUADRANTS = np.repeat(np.repeat(np.array([[[255, 0, 0, 255], [0, 255, 0, 255]], [[0, 0, 255, 255], [255, 255, 0, 255]]],
                                         dtype=np.uint8), 8, axis=0), 8, axis=1)


def test_an_image_texture_is_checked_hashed_and_read_only() -> None:
    texture = Texture("memory#quadrants", image=QUADRANTS)
    assert not texture.is_file and texture.digest and not texture.image.flags.writeable
    assert texture_levels(texture) == [texture.image]
    same = Texture("memory#quadrants", image=QUADRANTS.copy())
    other = Texture("memory#quadrants", image=QUADRANTS[::-1].copy())
    assert same == texture and hash(same) == hash(texture) and other != texture
    assert replace(texture, filter="nearest").digest == texture.digest
    with pytest.raises(SandboxError, match="expected a non-empty \\(H, W, 4\\) uint8 image"):
        Texture("memory#bad", image=np.zeros((2, 2, 3), dtype=np.uint8))


def facing_quad(renderer: str) -> Scene:
    """The plane turned to face the camera: uv (0, 0) at the top-left corner, as the course's uv."""
    model = transforms.rotate_x(np.pi / 2) @ transforms.scale(2.0, 2.0, 2.0)
    texture = Texture("memory#quadrants", filter="nearest", image=QUADRANTS)
    node = Node("quad", geometry.plane(), model, Material(texture=texture))
    return Scene("quad", nodes=(node,), camera=Camera(eye=(0.0, 0.0, 3.0)), clear_color=(0.0, 0.0, 0.0, 1.0),
                 viewports=(Viewport(renderer=renderer),))


@pytest.mark.parametrize("renderer", ["raster", "ray", "ray_numpy"])
def test_both_renderers_sample_an_image_texture(gl, renderer: str) -> None:
    image = gl.render_scene(facing_quad(renderer), (64, 64)).image
    corners = {(20, 20): (255, 0, 0), (20, 44): (0, 255, 0), (44, 20): (0, 0, 255), (44, 44): (255, 255, 0)}
    for (y, x), rgb in corners.items():
        np.testing.assert_allclose(image[y, x, :3], rgb, atol=2, err_msg=f"{renderer} at row {y}, column {x}")
