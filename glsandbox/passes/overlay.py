"""The ``overlay`` pass: labels and figures over the frame, one pass per region."""

from __future__ import annotations

from glsandbox.passes.plan_parts import Draw, Pass, ProgramVariant
from glsandbox.scene import Scene


#: The program that draws overlay images texel for pixel (``shaders/overlay.glsl``).
OVERLAY_PROGRAM = ProgramVariant("overlay")


def overlay_passes(scene: Scene) -> list[Pass]:
    """One ``overlay`` pass per region that has overlays, after every 3D pass.

    The pass lists the overlays by name as draws of the overlay program; its
    viewport is the region they are clipped to (-1: the whole frame). A scene
    without overlays gets no pass and no overlay program.
    """
    if not scene.overlays:
        return []
    regions: dict[int, list[Draw]] = {}
    for overlay in scene.overlays:
        region = -1 if overlay.viewport is None else overlay.viewport
        regions.setdefault(region, []).append(Draw(overlay.name, OVERLAY_PROGRAM.key, False))
    # Viewport regions in order, then the frame-wide ones, which may lie across several viewports.
    order = sorted(regions, key=lambda region: (region < 0, region))
    return [Pass("overlay", region, draws=tuple(regions[region]), camera=None) for region in order]


def describe(step: Pass) -> str:
    where = "frame" if step.viewport < 0 else f"viewport {step.viewport}"
    return f"overlay {where} (blended, no depth test): " + ", ".join(d.node for d in step.draws)

