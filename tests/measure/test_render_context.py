"""What a knob's setting renders with: the box filter, supersampling at a factor, the shared renderer."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from glsandbox.errors import SandboxError
from glsandbox.measure.render_context import RenderContext, downsample, render_supersampled
from glsandbox.scene import Scene


def test_downsample_averages_each_block_and_rounds_to_8_bits() -> None:
    image = np.zeros((4, 4, 4), dtype=np.uint8)
    image[:2, :2] = 255  # one white block
    image[2:, 2:, 0] = (1, 2)  # a block averaging 1.5: rounds to even 2
    small = downsample(image, 2)
    assert small.shape == (2, 2, 4) and small.dtype == np.uint8
    assert tuple(small[0, 0]) == (255,) * 4 and tuple(small[0, 1]) == (0,) * 4 and small[1, 1, 0] == 2
    flipped = image[::-1]  # a strided view: factor 1 hands back its pixels, contiguous
    assert np.array_equal(downsample(flipped, 1), flipped) and downsample(flipped, 1).flags.c_contiguous


def test_render_supersampled_renders_factor_times_larger_then_filters() -> None:
    @dataclass
    class Frame:
        image: np.ndarray

    asked: list[tuple[int, int]] = []

    class Renderer:
        def render_scene(self, scene: Scene, size: tuple[int, int]) -> Frame:
            asked.append(size)
            return Frame(np.full((size[1], size[0], 4), 10, dtype=np.uint8))

    image = render_supersampled(Renderer(), Scene("s"), (8, 6), 3)
    assert asked == [(24, 18)] and image.shape == (6, 8, 4) and (image == 10).all()
    with pytest.raises(SandboxError, match="supersampling factor must be 1 or more, got 0"):
        render_supersampled(Renderer(), Scene("s"), (8, 6), 0)


def test_a_render_context_opens_no_gl_until_it_draws() -> None:
    context = RenderContext((32, 24))
    assert context.size == (32, 24)
    context.close()  # never opened: nothing to close, no error
