"""The ``draw`` pass: the nodes a viewport shows, each with its program variant.

Opaque nodes first in scene order, then the blended ones farthest first
(:func:`glsandbox.passes.order.farthest_first`), with depth writes off.
"""

from __future__ import annotations

from glsandbox.passes.order import farthest_first
from glsandbox.passes.plan_parts import Draw, Pass, ProgramVariant, describe_draws
from glsandbox.plan_variants import program_for
from glsandbox.scene import Scene


def draw_pass(scene: Scene, index: int, depth_test: bool, programs: set[ProgramVariant],
              shadow_light: int | None, shadow_pcf: int) -> Pass | None:
    """Viewport ``index``'s draw pass (None when it shows nothing), adding its variants to ``programs``.
    A raster viewport's receivers look light ``shadow_light``'s shadow map up, ``shadow_pcf`` texels wide."""
    viewport = scene.viewports[index]
    draws, blended = [], []
    for node in scene.nodes:
        if not node.shown_in(index):
            continue
        if scene.mirror is not None and node.name == scene.mirror.node:
            continue  # the mirror's glass is drawn by the mirror passes
        receives = shadow_light if node.receives_shadow and viewport.renderer == "raster" else None
        variant = program_for(node, len(scene.lights), receives, shadow_pcf)
        programs.add(variant)
        texture = node.material.texture
        blend = node.material.alpha_mode == "blend"
        (blended if blend else draws).append(
            (node, Draw(node.name, variant.key, node.cull_back_faces,
                        texture=texture.describe() if texture is not None else None, blend=blend,
                        shadow_map=receives if "SHADOW_LIGHT" in dict(variant.defines) else None)))
    camera = viewport.camera or scene.camera
    ordered = [d for _, d in draws] + [d for _, d in farthest_first(blended, camera)]
    return Pass("draw", index, draws=tuple(ordered), depth_test=depth_test) if ordered else None


def describe(step: Pass) -> str:
    depth = "depth test" if step.depth_test else "no depth test"
    return f"draw viewport {step.viewport} ({depth}): {describe_draws(step)}"
