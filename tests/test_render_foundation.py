"""Rendered pixels of the first three lessons, headless."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import need

from glsandbox.lesson import find_lesson
from glsandbox.plan import Buffers

SIZE = (256, 256)
COURSE_BLUE_RGBA8 = (0, 32, 153, 255)  # round(255 * (0, 0.125, 0.6))
ORANGE_RGBA8 = (255, 140, 26, 255)


def render(gl, name: str, *settings: str, size=SIZE, samples: int = 0) -> np.ndarray:
    return gl.render(find_lesson(name).from_settings(settings), size, samples).image


def count(image: np.ndarray, rgba) -> int:
    return int(np.all(image == np.array(rgba, dtype=np.uint8), axis=-1).sum())


def test_clear_colour_is_the_course_blue_exactly(gl) -> None:
    image = render(gl, "clear_and_swap", "split=off")
    assert count(image, COURSE_BLUE_RGBA8) == SIZE[0] * SIZE[1]


def test_split_screen_clears_each_half_to_its_own_colour(gl, golden) -> None:
    image = render(gl, "clear_and_swap")
    assert count(image[:, :128], COURSE_BLUE_RGBA8) == 128 * 256
    assert count(image[:, 128:], (153, 32, 0, 255)) == 128 * 256
    golden(image, "clear_and_swap")


def test_strip_and_list_give_identical_pixels(gl, golden) -> None:
    strip = render(gl, "triangle", "topology=strip")
    quad_list = render(gl, "triangle", "topology=list")
    assert count(strip, ORANGE_RGBA8) > 5000
    np.testing.assert_array_equal(strip, quad_list)
    both = render(gl, "triangle")
    np.testing.assert_array_equal(both[:, :128], both[:, 128:])
    golden(both, "triangle")


def test_swapped_winding_is_culled_as_a_back_face(gl) -> None:
    full = count(render(gl, "triangle", "topology=list"), ORANGE_RGBA8)
    half = count(render(gl, "triangle", "topology=list", "winding=swapped"), ORANGE_RGBA8)
    unculled = count(render(gl, "triangle", "topology=list", "winding=swapped", "cull=off"), ORANGE_RGBA8)
    # One of the two triangles is gone: about half the quad (the shared diagonal
    # belongs to one triangle only, so allow a diagonal's worth of pixels).
    assert abs(half - full / 2) <= 0.01 * full + 256
    assert unculled == full


def test_indexed_cube_golden_and_culling_changes_nothing_on_a_closed_cube(gl, golden) -> None:
    image = render(gl, "indexed_cube")
    golden(image, "indexed_cube")
    np.testing.assert_array_equal(image, render(gl, "indexed_cube", "cull=off"))
    # The front face (towards the camera, +z in OpenGL) and top face are visible.
    centre = image[128, 128]
    assert tuple(centre) != COURSE_BLUE_RGBA8


def test_flipping_the_front_face_winding_opens_a_hole(gl, golden) -> None:
    image = render(gl, "indexed_cube", "flip=front")
    # Through the hole: the inner sides are back faces too, so the background shows.
    assert tuple(image[135, 128]) == COURSE_BLUE_RGBA8
    golden(image, "indexed_cube_flip_front")
    # Without culling the inside of the far faces is drawn instead.
    assert tuple(render(gl, "indexed_cube", "flip=front", "cull=off")[135, 128]) != COURSE_BLUE_RGBA8


def test_time_renders_that_moment_exactly(gl) -> None:
    a = render(gl, "indexed_cube", "time=0.8")
    b = render(gl, "indexed_cube", "time=0.8")
    c = render(gl, "indexed_cube", "time=0.9")
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    # A full turn (2π at speed 1) is the same picture as time 0, up to rounding.
    start, turn = render(gl, "indexed_cube"), render(gl, "indexed_cube", f"time={2 * np.pi}")
    assert np.abs(start.astype(int) - turn.astype(int)).max() <= 1


def test_msaa_smooths_edges_but_keeps_the_picture(gl) -> None:
    plain = render(gl, "indexed_cube", "time=0.5")
    smooth = render(gl, "indexed_cube", "time=0.5", samples=4)
    diff = np.abs(plain.astype(int) - smooth.astype(int)).max(axis=-1)
    assert 0 < np.count_nonzero(diff) < 0.05 * diff.size  # only edge pixels change


def test_offscreen_targets_have_the_depth_and_stencil_bits_asked_for(gl) -> None:
    assert gl.target((64, 64), Buffers(depth=True, stencil=True, samples=0)).bits() == (24, 8)
    assert gl.target((64, 64), Buffers(depth=True, stencil=False, samples=0)).bits() == (24, 0)
    assert gl.target((64, 64), Buffers(depth=False, stencil=False, samples=0)).bits() == (0, 0)


@pytest.mark.parametrize("size", [(1, 1), (333, 77)])
def test_odd_sizes_render(gl, size) -> None:
    image = render(gl, "clear_and_swap", "split=off", size=size)
    assert image.shape == (size[1], size[0], 4)


def test_a_second_renderer_in_the_process_leaves_the_first_intact(gl) -> None:
    from glsandbox.frame import HeadlessRenderer

    lesson = find_lesson("indexed_cube")(time=0.5)
    before = np.array(gl.render(lesson, (64, 64)).image)
    if gl.host.backend != "egl":
        need("EGL", f"the session renderer runs on {gl.host.backend}; two contexts of one backend "
                    "are checked on EGL (OSMesa and EGL must not be mixed in one process)")
    other = HeadlessRenderer("egl")  # opening it makes it current
    try:
        np.testing.assert_array_equal(np.array(other.render(lesson, (64, 64)).image), before)
        np.testing.assert_array_equal(np.array(gl.render(lesson, (64, 64)).image), before)
    finally:
        other.close()  # its deletes must not reach the first context's objects
    np.testing.assert_array_equal(np.array(gl.render(lesson, (64, 64)).image), before)
