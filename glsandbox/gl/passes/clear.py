"""The ``clear`` pass's runner: the viewport's colour (opaque), depth and stencil."""

from __future__ import annotations

from typing import Any

from glsandbox.gl.passes import FrameState, Runner, touches_nothing
from glsandbox.gl.target import clear_opaque
from glsandbox.passes.plan_parts import Pass


def run(executor: Any, frame: FrameState, step: Pass, camera: Any) -> None:
    """Clear the viewport's rectangle: depth to the frame's clear value (0 with reverse-Z)."""
    rect = executor.pass_rect or frame.scene.viewports[step.viewport].pixels(*frame.size)
    r, g, b, _ = step.clear_color or (0.0, 0.0, 0.0, 0.0)
    # Frames are opaque whatever the clear colour's alpha (glsandbox.gl.target).
    clear_opaque(frame.framebuffer, (r, g, b), executor.clear_depth, rect)
    if step.clear_stencil:  # moderngl's clear leaves the stencil alone
        executor.raw.clear_stencil(rect)


RUNNER = Runner("clear", run, touches_nothing, moved=True)
