"""Every lesson's overlays (text panels, figures, labels) keep clear of its 3D picture
at every size, and ``overlay=off`` removes them.

"Scene pixels" are those of the ``overlay=off`` render that differ from the scene's
clear colour: what the lesson drew in 3D (the traced or rasterised picture). A scene
pixel is *covered* when the ``overlay=on`` render changes it. The share measured is
covered scene pixels over all scene pixels, so a panel over empty background costs
nothing and one over the spheres costs what a student loses.
"""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.lesson import all_lessons, find_lesson
from glsandbox.overlay import Overlay, overlay_scale, text_image

SIZES = [(160, 120), (1280, 720)]
#: The most of a lesson's scene pixels its overlays may cover, at any size.
MAX_COVERED = 0.15


def covered_share(gl, cls, size: tuple[int, int]) -> tuple[float, int]:
    """(covered scene pixels / scene pixels, scene pixels) for ``cls`` at ``size``."""
    on = gl.render(cls(), size).image[..., :3].astype(np.int16)
    off = gl.render(cls.from_settings(["overlay=off"]), size).image[..., :3].astype(np.int16)
    clear = np.rint(np.asarray(cls().scene().clear_color[:3]) * 255).astype(np.int16)
    scene = np.abs(off - clear).max(axis=2) > 2
    covered = scene & (np.abs(on - off).max(axis=2) > 0)
    return float(covered.sum()) / max(int(scene.sum()), 1), int(scene.sum())


@pytest.mark.slow
@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
def test_every_lessons_overlay_keeps_clear_of_its_scene(gl, size) -> None:
    shares = {}
    for cls in all_lessons():
        share, scene_pixels = covered_share(gl, cls, size)
        assert scene_pixels > 0, f"{cls.name}: nothing drawn at {size}"
        shares[cls.name] = share
    worst = max(shares, key=shares.get)
    assert shares[worst] <= MAX_COVERED, {k: round(v, 3) for k, v in shares.items()}


def test_overlay_off_drops_every_overlay_of_every_lesson() -> None:
    with_overlays = [cls for cls in all_lessons() if cls().scene().overlays]
    assert len(with_overlays) >= 6
    for cls in with_overlays:
        assert cls.from_settings(["overlay=off"]).scene().overlays == (), cls.name


def test_a_panel_scales_with_its_region_and_stays_a_bounded_part_of_it() -> None:
    image = text_image([f"row {i}: figures" for i in range(4)])
    h, w = image.shape[:2]
    assert w * h <= 0.16 * 256 * 256
    assert overlay_scale(256, 256, w, h) == 1.0  # the golden size: drawn 1:1
    assert overlay_scale(1280, 720, w, h) == 2.0  # grown by whole texels
    assert overlay_scale(160, 120, w, h) < 1.0  # shrunk by the caps only
    for region in [(160, 120), (256, 256), (640, 480), (1280, 720), (4000, 300)]:
        s = overlay_scale(*region, w, h)
        assert w * s * h * s <= 0.16 * region[0] * region[1] + 1e-6
    overlay = Overlay("t", image)
    big = overlay.drawn_image((0, 0, 1280, 720))
    assert big.shape == (2 * h, 2 * w, 4) and np.array_equal(big[::2, ::2], image)
    assert overlay.placement((0, 0, 1280, 720)) == (8, 720 - 8 - 2 * h, 2 * w, 2 * h)
    small = overlay.drawn_image((0, 0, 160, 120))
    assert small.shape[0] < h and small.shape[1] < w
    label = text_image(["1: STR"])  # a short label in a small tile stays 1:1, readable
    assert overlay_scale(85, 128, label.shape[1], label.shape[0]) == 1.0
    traced = Overlay("traced", image, scalable=False)
    assert traced.drawn_image((0, 0, 1280, 720)) is image


def test_the_ray_spheres_panel_no_longer_hides_the_spheres_at_160x120(gl) -> None:
    share, _ = covered_share(gl, find_lesson("ray_spheres"), (160, 120))
    assert share <= MAX_COVERED
