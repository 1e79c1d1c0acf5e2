"""glsandbox.frame's headless renderer: offscreen targets with the buffers asked for, odd sizes,
and two renderers in one process."""

from __future__ import annotations

import numpy as np
import pytest
from support import lesson_image, need

from glsandbox.lesson import find_lesson
from glsandbox.plan import Buffers


def test_offscreen_targets_have_the_depth_and_stencil_bits_asked_for(gl) -> None:
    assert gl.target((64, 64), Buffers(depth=True, stencil=True, samples=0)).bits() == (24, 8)
    assert gl.target((64, 64), Buffers(depth=True, stencil=False, samples=0)).bits() == (24, 0)
    assert gl.target((64, 64), Buffers(depth=False, stencil=False, samples=0)).bits() == (0, 0)


@pytest.mark.parametrize("size", [(1, 1), (333, 77)])
def test_odd_sizes_render(gl, size) -> None:
    image = lesson_image(gl, "clear_and_swap", "split=off", size=size)
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
