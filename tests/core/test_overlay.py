"""Screen overlays as scene data (glsandbox/overlay.py): an image checked and kept read-only; its
scale with the region (1:1 up to the reference size, whole texels above, capped to a share of the
region); where it lands, negative positions counting from the far edges; scaling by whole texels
or a box filter without dark fringes; text panels drawn once per set of rows. No GL."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.overlay import (MAX_AREA_SHARE, PANEL_COLOR, REFERENCE_SIZE, Overlay, overlay_scale, scaled_image,
                               text_image)


def solid(w: int, h: int, rgba=(255, 0, 0, 255)) -> np.ndarray:
    return np.tile(np.array(rgba, dtype=np.uint8), (h, w, 1))


@pytest.mark.parametrize("image", [np.zeros((4, 4, 3), np.uint8), np.zeros((4, 4, 4), np.float32),
                                   np.zeros((0, 4, 4), np.uint8)])
def test_an_image_that_is_not_a_non_empty_rgba8_array_is_refused_naming_the_overlay(image) -> None:
    with pytest.raises(SandboxError, match="overlay 'label': expected a non-empty"):
        Overlay("label", image)


def test_the_overlay_keeps_its_image_read_only() -> None:
    image = solid(2, 2)
    Overlay("label", image)
    assert not image.flags.writeable


def test_the_scale_is_one_up_to_the_reference_size_then_whole_numbers_under_the_caps() -> None:
    assert overlay_scale(REFERENCE_SIZE, REFERENCE_SIZE, 10, 10) == 1.0
    assert overlay_scale(3 * REFERENCE_SIZE + 10, 3 * REFERENCE_SIZE, 10, 10) == 3.0
    big = overlay_scale(200, 200, 150, 20)  # wider than 60% of the region: shrunk to fit
    assert big < 1.0 and 150 * big == pytest.approx(0.6 * 200)
    area = overlay_scale(2000, 2000, 400, 400)
    assert (400 * area) ** 2 <= MAX_AREA_SHARE * 2000 * 2000 * (1 + 1e-9)


def test_negative_positions_count_from_the_right_and_bottom_edges() -> None:
    region = (10, 20, 100, 80)  # x, y from the bottom left, w, h
    top_left = Overlay("a", solid(8, 4), position=(4, 4)).placement(region)
    bottom_right = Overlay("b", solid(8, 4), position=(-1, -1)).placement(region)
    assert top_left == (14, 20 + 80 - 4 - 4, 8, 4)
    assert bottom_right == (10 + 100 - 8, 20, 8, 4)  # flush with the far corner


def test_an_unscaled_overlay_lands_texel_for_pixel_in_any_region() -> None:
    image = solid(300, 10)
    assert Overlay("traced", image, scalable=False).drawn_image((0, 0, 64, 64)) is image


def test_whole_number_growth_repeats_texels_and_a_box_filter_keeps_colour_at_the_edges() -> None:
    image = np.zeros((2, 2, 4), np.uint8)
    image[0, 0] = (255, 0, 0, 255)
    image.setflags(write=False)
    grown = scaled_image(image, 2.0)
    assert grown.shape == (4, 4, 4) and (grown[:2, :2] == (255, 0, 0, 255)).all() and (grown[2:, 2:] == 0).all()
    assert scaled_image(image, 2.0) is grown and scaled_image(image, 1.0) is image
    edge = np.zeros((4, 4, 4), np.uint8)
    edge[:, :2] = (255, 0, 0, 128)  # half-transparent red beside clear black
    shrunk = scaled_image(edge, 0.75)
    covered = shrunk[..., 3] > 0
    assert covered.any() and (shrunk[covered][:, :3] == (255, 0, 0)).all()  # no dark fringe where they mix


def test_a_text_panel_is_drawn_once_per_rows_and_grows_with_them() -> None:
    one = text_image(["x = 1"])
    assert text_image(["x = 1"]) is one and not one.flags.writeable
    assert tuple(one[0, 0]) == PANEL_COLOR  # the padding is the panel colour
    two = text_image(["x = 1", "y = 2"])
    assert two.shape[0] > one.shape[0] and two.shape[1] == one.shape[1]
