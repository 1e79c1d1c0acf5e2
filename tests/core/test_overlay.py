"""Screen overlays as scene data (glsandbox/overlay.py): an image checked and kept read-only; its
scale with the region (1:1 up to the reference size, whole texels above, capped to a share of the
region); where it lands, negative positions counting from the far edges; scaling by whole texels
or a box filter without dark fringes; text panels drawn once per set of rows. No GL.

Also the figures in the world (:class:`WorldLines`): projected through the camera
that draws the frame, clipped where the eye cannot see, drawn as the region's own image."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.overlay import (MAX_AREA_SHARE, MIN_LABELLED_SIZE, PANEL_COLOR, REFERENCE_SIZE, Overlay, WorldLine,
                               WorldLines, WorldMark, overlay_scale, project_segment, scaled_image, text_image)
from glsandbox.scene import Camera


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


CAMERA = Camera(eye=(0.0, 0.0, 10.0), target=(0.0, 0.0, 0.0), fov_y=90.0)
SIZE = (200, 100)


def clip(camera: Camera = CAMERA, size: tuple[int, int] = SIZE) -> np.ndarray:
    return camera.projection(size[0] / size[1]) @ camera.view()


def test_a_point_in_front_of_the_eye_lands_where_the_perspective_divide_puts_it() -> None:
    # fov 90: at distance 10 the frame's half height is 10 world units, its half width 20.
    (a, b) = project_segment(clip(), (0.0, 0.0, 0.0), (10.0, 5.0, 0.0), SIZE)
    assert a == pytest.approx((100.0, 50.0))
    assert b == pytest.approx((100.0 + 0.5 * 100.0, 50.0 - 0.5 * 50.0))


def test_a_segment_through_the_eye_plane_is_cut_where_it_leaves_the_view() -> None:
    # From in front of the eye to behind it: only the part in front is kept, and its end is
    # on the frame's edge (never the mirrored point a divide by a negative w would give).
    ends = project_segment(clip(), (0.0, 0.0, 0.0), (0.0, 5.0, 20.0), SIZE)
    assert ends is not None
    (x0, y0), (x1, y1) = ends
    assert (x0, y0) == pytest.approx((100.0, 50.0))
    assert x1 == pytest.approx(100.0) and y1 == pytest.approx(0.0, abs=1e-6)  # the top edge
    assert project_segment(clip(), (0.0, 0.0, 11.0), (3.0, 1.0, 30.0), SIZE) is None  # all behind the eye
    assert project_segment(clip(), (50.0, 0.0, 0.0), (60.0, 0.0, 0.0), SIZE) is None  # beside the view


def test_world_lines_are_drawn_through_the_camera_that_sees_them() -> None:
    yellow = (255, 220, 0, 255)
    figure = WorldLines("rays", lines=(WorldLine((-10.0, 0.0, 0.0), (10.0, 0.0, 0.0), yellow),),
                        marks=(WorldMark((0.0, 5.0, 0.0), "top", (0, 255, 255, 255)),))
    drawn = figure.seen_by(CAMERA, (0, 0, *SIZE))
    assert isinstance(drawn, Overlay) and not isinstance(drawn, WorldLines)
    assert drawn.image.shape == (SIZE[1], SIZE[0], 4) and drawn.placement((0, 0, *SIZE)) == (0, 0, *SIZE)
    image = drawn.image
    assert tuple(image[50, 100]) == yellow and tuple(image[50, 60]) == yellow  # the line, x from 50 to 150
    assert image[50, 20, 3] == 0 and image[50, 180, 3] == 0 and image[80, 100, 3] == 0  # nothing past its ends
    assert tuple(image[25, 100]) == (0, 255, 255, 255)  # the mark's dot at (0, 5, 0)
    # Moved camera, moved figure: looking from the side, the line's middle is elsewhere.
    side = Camera(eye=(0.0, 10.0, 10.0), target=(0.0, 0.0, 0.0), fov_y=90.0)
    assert not np.array_equal(figure.seen_by(side, (0, 0, *SIZE)).image, image)
    # The same camera and region: the same array (no new texture upload).
    assert figure.seen_by(CAMERA, (0, 0, *SIZE)).image is image


def test_labels_show_only_where_the_frame_has_room_for_them() -> None:
    mark = WorldMark((0.0, 0.0, 0.0), "a long label that would cover the picture", (255, 255, 255, 255))
    small = (MIN_LABELLED_SIZE - 40, MIN_LABELLED_SIZE - 60)
    big = (2 * MIN_LABELLED_SIZE, MIN_LABELLED_SIZE)
    for size, labelled in ((small, False), (big, True)):
        image = WorldLines("m", marks=(mark,)).seen_by(CAMERA, (0, 0, *size)).image
        dot = 4 * 2 + 2  # the dot's diameter and its edge
        assert (int((image[..., 3] > 0).sum()) > 3 * dot * dot) == labelled, size


def test_a_figure_refuses_points_that_are_not_three_finite_numbers() -> None:
    with pytest.raises(SandboxError, match="WorldLine start: expected three finite numbers"):
        WorldLine((0.0, 1.0), (0.0, 0.0, 0.0), (255, 0, 0, 255))
    with pytest.raises(SandboxError, match="WorldMark point"):
        WorldMark((0.0, float("nan"), 0.0), "x", (255, 0, 0, 255))
    with pytest.raises(SandboxError, match="color: expected four numbers 0-255"):
        WorldLine((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (300, 0, 0, 255))
    line = WorldLine(np.array([0, 0, 0]), np.array([1.0, 2.0, 3.0]), (1, 2, 3, 4))
    assert line.end == (1.0, 2.0, 3.0) and hash(line) == hash(WorldLine((0, 0, 0), (1, 2, 3), (1, 2, 3, 4)))
