"""What a knob's setting renders with: the frame size, one GL renderer, supersampling.

:class:`RenderContext` holds the size the tradeoffs run measures at and a
:class:`~glsandbox.frame.LazyRenderer` (one context, opened on first use),
and draws a scene rasterised (with MSAA, or supersampled and box-filtered
down by :func:`downsample`) or ray-traced at that size.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from glsandbox.errors import SandboxError
from glsandbox.frame import HeadlessRenderer, LazyRenderer
from glsandbox.scene import Scene

__all__ = ["REFERENCE_FACTOR", "RenderContext", "downsample", "render_supersampled"]

#: The supersampling factor of the references (8x8 samples per pixel).
REFERENCE_FACTOR = 8


def downsample(image: np.ndarray, factor: int) -> np.ndarray:
    """Average each ``factor`` x ``factor`` block of an (H*f, W*f, C) ``uint8``
    image into one pixel: a box filter, the simplest reconstruction of the
    pixel's area from ``factor**2`` evenly spaced samples. The average is
    taken on the stored 8-bit values (display space, as MSAA's resolve does
    on this driver) and rounded back to ``uint8``."""
    if factor == 1:
        return np.ascontiguousarray(image)
    height, width = image.shape[0] // factor, image.shape[1] // factor
    blocks = image.reshape(height, factor, width, factor, image.shape[2]).astype(np.float32)
    return np.rint(blocks.mean(axis=(1, 3))).astype(np.uint8)


def render_supersampled(renderer: HeadlessRenderer, scene: Scene, size: tuple[int, int],
                        factor: int) -> np.ndarray:
    """Supersampling: render ``scene`` at ``factor`` times the width and
    height, then :func:`downsample` to ``size``. Returns (H, W, 4) ``uint8``."""
    if factor < 1:
        raise SandboxError(f"supersampling factor must be 1 or more, got {factor}")
    big = (size[0] * factor, size[1] * factor)
    return downsample(renderer.render_scene(scene, big).image, factor)


class RenderContext:
    """The frame size of a tradeoffs run and its one GL renderer (opened on first use, see :meth:`close`)."""

    def __init__(self, size: tuple[int, int], backend: str | None = None) -> None:
        self.size = size
        self.gl = LazyRenderer(backend)

    @property
    def renderer(self) -> HeadlessRenderer:
        """The shared :class:`~glsandbox.frame.HeadlessRenderer`."""
        return self.gl.renderer

    def raster(self, scene: Scene, factor: int = 1, samples: int = 0) -> np.ndarray:
        """The scene rasterised at this size, with MSAA ``samples`` and supersampling ``factor``."""
        return render_supersampled(self.renderer, replace(scene, samples=samples), self.size, factor)

    def ray(self, scene: Scene, engine: str = "numpy", **options: Any) -> np.ndarray:
        """The scene ray-traced at this size (:func:`glsandbox.raytrace.render.render`); ``gpu`` runs on the renderer's context."""
        from glsandbox.raytrace.render import render

        ctx = self.renderer.host.ctx if engine == "gpu" else None
        return render(scene, self.size, engine, ctx=ctx, **options)

    def close(self) -> None:
        """Close the renderer, if it was opened."""
        self.gl.close()
