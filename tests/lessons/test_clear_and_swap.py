"""The clear_and_swap lesson (course "DirectX 11: device, context, swap chain; Viewport"): the course blue exactly, and a split screen."""

from __future__ import annotations

from support import COURSE_BLUE_RGBA8, check_lesson_golden, count_color, lesson_image

SIZE = (256, 256)


def test_clear_colour_is_the_course_blue_exactly(gl) -> None:
    image = lesson_image(gl, "clear_and_swap", "split=off", size=SIZE)
    assert count_color(image, COURSE_BLUE_RGBA8) == SIZE[0] * SIZE[1]


def test_split_screen_clears_each_half_to_its_own_colour(gl, golden) -> None:
    image = check_lesson_golden(gl, golden, "clear_and_swap", size=SIZE)
    assert count_color(image[:, :128], COURSE_BLUE_RGBA8) == 128 * 256
    assert count_color(image[:, 128:], (153, 32, 0, 255)) == 128 * 256
