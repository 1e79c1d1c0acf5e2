"""The frame's depth mode (:data:`glsandbox.scene.DEPTH_MODES`): standard or reverse-Z.

``standard`` is OpenGL's default: clip depth -1..1, clear depth 1, test LESS.
``reverse_z`` remaps the projection (:func:`glsandbox.transforms.reverse_z`),
keeps clip depth 0..1 as it is (``glClipControl``), clears depth to 0 and
tests GREATER. The mode belongs to a whole frame: the executor begins it
before the first pass and ends it after the last, back at OpenGL's defaults.
"""

from __future__ import annotations

import moderngl
import numpy as np

from glsandbox import transforms
from glsandbox.gl import rawgl
from glsandbox.scene import Scene


def clear_depth_value(scene: Scene) -> float:
    """What "far" is in the depth buffer: 1 normally, 0 with reverse-Z."""
    return 0.0 if scene.depth_mode == "reverse_z" else 1.0


def projection_for(scene: Scene, projection: np.ndarray) -> np.ndarray:
    """The camera's projection, remapped for reverse-Z when the scene asks for it."""
    return transforms.reverse_z(projection) if scene.depth_mode == "reverse_z" else projection


def begin_depth_mode(ctx: moderngl.Context, raw: rawgl.RawGL, scene: Scene) -> None:
    """Reverse-Z: clip depth 0..1 kept as is (``glClipControl``), test GREATER."""
    if scene.depth_mode == "reverse_z":
        raw.glClipControl(rawgl.GL_LOWER_LEFT, rawgl.GL_ZERO_TO_ONE)
        ctx.depth_func = ">"


def end_depth_mode(ctx: moderngl.Context, raw: rawgl.RawGL, scene: Scene) -> None:
    """Back to OpenGL's defaults: clip depth -1..1, test LESS, clear depth 1."""
    if scene.depth_mode == "reverse_z":
        raw.glClipControl(rawgl.GL_LOWER_LEFT, rawgl.GL_NEGATIVE_ONE_TO_ONE)
        raw.glClearDepth(1.0)
        ctx.depth_func = "<"
