"""The ``trace`` pass's runner: a ray-traced viewport is traced before the executor runs
(:func:`glsandbox.frame.trace_viewports`), its picture an overlay by then."""

from __future__ import annotations

from typing import Any

from glsandbox.gl.passes import FrameState, Runner, touches_nothing
from glsandbox.passes.plan_parts import Pass


def run(executor: Any, frame: FrameState, step: Pass, camera: Any) -> None:
    """Refused: the executor draws raster viewports only."""
    raise ValueError(f"trace viewport {step.viewport}: trace it first (glsandbox.frame.trace_viewports)")


RUNNER = Runner("trace", run, touches_nothing, moved=False)
