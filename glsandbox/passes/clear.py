"""The ``clear`` pass: a viewport's colour, and its depth and stencil where the frame has them."""

from __future__ import annotations

from glsandbox.passes.plan_parts import Pass
from glsandbox.scene import Scene


def clear_pass(scene: Scene, index: int, depth: bool, stencil: bool) -> Pass:
    """Viewport ``index``'s clear: its own clear colour (else the scene's), the depth buffer with
    ``depth``, the stencil with ``stencil``."""
    viewport = scene.viewports[index]
    color = viewport.clear_color if viewport.clear_color is not None else scene.clear_color
    return Pass("clear", index, clear_color=color, clear_depth=depth, clear_stencil=stencil, camera=None)


def describe(step: Pass) -> str:
    what = []
    if step.clear_color is not None:
        what.append("colour (" + ", ".join(f"{c:g}" for c in step.clear_color) + ")")
    if step.clear_depth:
        what.append("depth")
    if step.clear_stencil:
        what.append("stencil")
    return f"clear viewport {step.viewport}: " + " + ".join(what)
