"""The ``draw`` pass's runner: each node with its program, through the viewport's camera
(its blended draws put blending and depth writes back themselves)."""

from __future__ import annotations

from typing import Any

from glsandbox.gl.passes import FrameState, Runner, touches_nothing
from glsandbox.passes.plan_parts import Pass


def run(executor: Any, frame: FrameState, step: Pass, camera: Any) -> None:
    """Draw each node at the frame's model matrix for it (its own where the frame moves none)."""
    assert camera is not None
    nodes, models = frame.nodes, frame.models
    for draw in step.draws:
        executor.draw_node(nodes[draw.node], draw, camera, model=models.get(draw.node))


RUNNER = Runner("draw", run, touches_nothing, moved=True)
