"""The indexed_cube lesson (course "Küp: vertex + index buffer; World, View, Projection"):
culling on a closed cube, a flipped front face, time, and MSAA."""

from __future__ import annotations

import numpy as np
from support import COURSE_BLUE_RGBA8, check_lesson_golden, lesson_image


def test_indexed_cube_golden_and_culling_changes_nothing_on_a_closed_cube(gl, golden) -> None:
    image = check_lesson_golden(gl, golden, "indexed_cube")
    np.testing.assert_array_equal(image, lesson_image(gl, "indexed_cube", "cull=off"))
    # The front face (towards the camera, +z in OpenGL) and top face are visible.
    centre = image[128, 128]
    assert tuple(centre) != COURSE_BLUE_RGBA8


def test_flipping_the_front_face_winding_opens_a_hole(gl, golden) -> None:
    image = check_lesson_golden(gl, golden, "indexed_cube", "flip=front")
    # Through the hole: the inner sides are back faces too, so the background shows.
    assert tuple(image[135, 128]) == COURSE_BLUE_RGBA8
    # Without culling the inside of the far faces is drawn instead.
    assert tuple(lesson_image(gl, "indexed_cube", "flip=front", "cull=off")[135, 128]) != COURSE_BLUE_RGBA8


def test_time_renders_that_moment_exactly(gl) -> None:
    a = lesson_image(gl, "indexed_cube", "time=0.8")
    b = lesson_image(gl, "indexed_cube", "time=0.8")
    c = lesson_image(gl, "indexed_cube", "time=0.9")
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    # A full turn (2π at speed 1) is the same picture as time 0, up to rounding.
    start, turn = lesson_image(gl, "indexed_cube"), lesson_image(gl, "indexed_cube", f"time={2 * np.pi}")
    assert np.abs(start.astype(int) - turn.astype(int)).max() <= 1


def test_msaa_smooths_edges_but_keeps_the_picture(gl) -> None:
    plain = lesson_image(gl, "indexed_cube", "time=0.5")
    smooth = lesson_image(gl, "indexed_cube", "time=0.5", samples=4)
    diff = np.abs(plain.astype(int) - smooth.astype(int)).max(axis=-1)
    assert 0 < np.count_nonzero(diff) < 0.05 * diff.size  # only edge pixels change
