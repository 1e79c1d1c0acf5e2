"""The triangle lesson (course "Triangle; vertex buffer; TRIANGLESTRIP vs TRIANGLELIST"):
strip and list draw the same quad, and a swapped winding is culled."""

from __future__ import annotations

import numpy as np
from support import check_lesson_golden, count_color, lesson_image

ORANGE_RGBA8 = (255, 140, 26, 255)


def test_strip_and_list_give_identical_pixels(gl, golden) -> None:
    strip = lesson_image(gl, "triangle", "topology=strip")
    quad_list = lesson_image(gl, "triangle", "topology=list")
    assert count_color(strip, ORANGE_RGBA8) > 5000
    np.testing.assert_array_equal(strip, quad_list)
    both = check_lesson_golden(gl, golden, "triangle")
    np.testing.assert_array_equal(both[:, :128], both[:, 128:])


def test_swapped_winding_is_culled_as_a_back_face(gl) -> None:
    full = count_color(lesson_image(gl, "triangle", "topology=list"), ORANGE_RGBA8)
    half = count_color(lesson_image(gl, "triangle", "topology=list", "winding=swapped"), ORANGE_RGBA8)
    unculled = count_color(lesson_image(gl, "triangle", "topology=list", "winding=swapped", "cull=off"), ORANGE_RGBA8)
    # One of the two triangles is gone: about half the quad (the shared diagonal
    # belongs to one triangle only, so allow a diagonal's worth of pixels).
    assert abs(half - full / 2) <= 0.01 * full + 256
    assert unculled == full
