"""The frame's depth mode: standard, or reverse-Z (far at depth 0, a GREATER test, clip depth 0..1)."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np

from glsandbox import transforms
from glsandbox.gl import rawgl
from glsandbox.gl.depth import begin_depth_mode, clear_depth_value, end_depth_mode, projection_for
from glsandbox.scene import Scene

STANDARD = Scene("s")
REVERSED = replace(STANDARD, depth_mode="reverse_z")
PROJECTION = transforms.perspective(45.0, 4 / 3, 0.01, 100.0)


def test_far_is_1_normally_and_0_with_reverse_z() -> None:
    assert (clear_depth_value(STANDARD), clear_depth_value(REVERSED)) == (1.0, 0.0)


def test_reverse_z_maps_near_to_1_and_far_to_0() -> None:
    assert projection_for(STANDARD, PROJECTION) is PROJECTION
    reversed_proj = projection_for(REVERSED, PROJECTION)
    depths = []
    for distance in (0.01, 100.0):  # points on the near and far planes, in front of the camera (-z)
        clip = reversed_proj @ np.array([0.0, 0.0, -distance, 1.0])
        depths.append(clip[2] / clip[3])
    np.testing.assert_allclose(depths, [1.0, 0.0], atol=1e-9)


class Recorder:
    """A stand-in for moderngl's context and the raw GL calls: what the mode sets, in order."""

    def __init__(self) -> None:
        self.calls: list[tuple] = []
        self.ctx = SimpleNamespace(depth_func="<")
        self.raw = SimpleNamespace(glClipControl=lambda *a: self.calls.append(("clip", *a)),
                                   glClearDepth=lambda *a: self.calls.append(("clear depth", *a)))


def test_a_standard_frame_leaves_opengls_defaults_alone() -> None:
    gl = Recorder()
    begin_depth_mode(gl.ctx, gl.raw, STANDARD)
    end_depth_mode(gl.ctx, gl.raw, STANDARD)
    assert gl.calls == [] and gl.ctx.depth_func == "<"


def test_a_reverse_z_frame_begins_at_0_to_1_greater_and_ends_back_at_the_defaults() -> None:
    gl = Recorder()
    begin_depth_mode(gl.ctx, gl.raw, REVERSED)
    assert gl.calls == [("clip", rawgl.GL_LOWER_LEFT, rawgl.GL_ZERO_TO_ONE)] and gl.ctx.depth_func == ">"
    end_depth_mode(gl.ctx, gl.raw, REVERSED)
    assert gl.calls[1:] == [("clip", rawgl.GL_LOWER_LEFT, rawgl.GL_NEGATIVE_ONE_TO_ONE), ("clear depth", 1.0)]
    assert gl.ctx.depth_func == "<"
