"""The ``trace`` pass: a ray-traced viewport (``renderer = "ray"`` or ``"ray_numpy"``).

It is run before the rasterizer (:func:`glsandbox.frame.trace_viewports`); the
traced picture is then an overlay of its viewport (:func:`traced_scene`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from glsandbox.overlay import Overlay
from glsandbox.passes.plan_parts import Draw, Pass
from glsandbox.scene import Node, Scene


#: The options every ray-traced viewport is traced with (:func:`glsandbox.frame.trace_viewports`
#: passes them to :func:`glsandbox.raytrace.render.render`; the plan's trace passes say them).
TRACE_OPTIONS: dict[str, Any] = {"max_depth": 2, "shadows": True}

#: Who traces a viewport of each ray renderer.
TRACERS = {"ray": "GLSL ray tracer, float32", "ray_numpy": "numpy ray tracer, float64"}

#: Shadings the ray tracer gives another name: Gouraud is a raster approximation
#: (the ray tracer shades every pixel with the Phong formula).
TRACED_SHADING = {"gouraud": "phong"}


def traced_scene(scene: Scene, images: dict[int, Overlay]) -> Scene:
    """The scene the rasterizer draws once the ray-traced viewports are traced.

    Each viewport in ``images`` (by index) is traced: it keeps its clear, loses
    its nodes, and shows its traced image as its first overlay (so the
    scene's own overlays still land on top); its renderer becomes ``raster``.
    Viewports without an image (a ray viewport too small to hold a pixel)
    keep their nodes away too. A pure function: :func:`plan` uses it with
    placeholder images to print the frame that will be drawn.
    """
    ray = {i for i, vp in enumerate(scene.viewports) if vp.renderer != "raster"}
    everywhere = tuple(range(len(scene.viewports)))
    nodes = []
    for node in scene.nodes:
        shown = tuple(v for v in (node.viewports if node.viewports is not None else everywhere) if v not in ray)
        if shown:
            nodes.append(node if shown == node.viewports or (node.viewports is None and shown == everywhere)
                         else replace(node, viewports=shown))
    viewports = tuple(replace(vp, renderer="raster") for vp in scene.viewports)
    traced = tuple(images[i] for i in sorted(images))
    return replace(scene, nodes=tuple(nodes), viewports=viewports, overlays=(*traced, *scene.overlays))


def traced_image_name(viewport: int) -> str:
    """The overlay name of a viewport's traced image."""
    return f"raytrace/{viewport}"




def traced_reflectivity(scene: Scene, node: Node) -> float:
    """The share of a node's colour the ray tracer takes from the reflected ray: its
    ``material.reflectivity``; for the glass of the scene's stencil mirror
    (:class:`glsandbox.planar.Mirror`) at least ``1 - alpha``, the share of the
    reflection the rasterizer blends under the glass. The ray tracer reflects
    everything in front of the glass, not only the mirror's ``reflected`` nodes:
    the answer the stencil approximation aims at."""
    value = float(node.material.reflectivity)
    if scene.mirror is not None and node.name == scene.mirror.node:
        value = max(value, 1.0 - float(node.material.color[3]))
    return value


def trace_pass(scene: Scene, index: int) -> Pass:
    """What tracing viewport ``index`` does: the tracer, its options, and each node as it is shaded."""
    viewport = scene.viewports[index]
    lights = len(scene.lights)
    draws = []
    for node in scene.nodes:
        if not node.shown_in(index):
            continue
        material = node.material
        shading = TRACED_SHADING.get(material.shading, material.shading)
        reflects = traced_reflectivity(scene, node)
        texture = material.texture
        draws.append(Draw(node.name, shading + (f", reflects {reflects:g}" if reflects > 0 else ""),
                          node.cull_back_faces, texture=texture.describe() if texture is not None else None))
    how = [TRACERS[viewport.renderer], "1 primary ray per pixel"]
    if lights:
        how.append(f"shadow rays to {lights} light{'s' if lights != 1 else ''}" if TRACE_OPTIONS["shadows"]
                   else "no shadow rays")
    if any(", reflects" in d.program for d in draws):
        how.append(f"reflections up to {TRACE_OPTIONS['max_depth']} bounces")
    if any(d.texture for d in draws):
        how.append("textures sampled bilinearly in their base level")
    how.append(f"shown as overlay {traced_image_name(index)}")
    return Pass("trace", index, draws=tuple(draws), detail=", ".join(how))



def describe(step: Pass) -> str:
    nodes = "; ".join(f"{d.node} ({d.program}" + (f", texture {d.texture}" if d.texture else "") + ")"
                      for d in step.draws) or "nothing"
    return f"trace viewport {step.viewport} ({step.detail}): {nodes}"
