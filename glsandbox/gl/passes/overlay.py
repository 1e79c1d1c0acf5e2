"""The ``overlay`` pass's runner: labels and figures blended over the frame
(:mod:`glsandbox.gl.overlay_drawer`, which puts blending and the scissor back itself)."""

from __future__ import annotations

from typing import Any

from glsandbox.gl.passes import FrameState, Runner, touches_nothing
from glsandbox.passes.plan_parts import Pass


def run(executor: Any, frame: FrameState, step: Pass, camera: Any) -> None:
    """Draw the pass's overlays with its program; the drawer switches culling off."""
    executor.unbind_texture()
    executor.overlay_drawer().draw(frame.scene, step, frame.framebuffer, frame.size,
                                   executor.compiled(step.draws[0].program))
    executor.culling_switched_off()


RUNNER = Runner("overlay", run, touches_nothing, moved=True)
