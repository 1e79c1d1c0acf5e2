"""The ``trace`` pass (glsandbox/passes/trace.py): what tracing a ray viewport does, as the plan
prints it; the scene the rasterizer draws once the ray viewports are traced; the reflectivity the
ray tracer gives the stencil mirror's glass."""

from __future__ import annotations

import numpy as np

from glsandbox import geometry
from glsandbox.overlay import Overlay
from glsandbox.passes.trace import describe, trace_pass, traced_image_name, traced_reflectivity, traced_scene
from glsandbox.planar import Mirror
from glsandbox.scene import Light, Material, Node, Scene, Viewport

HALVES = (Viewport((0.0, 0.0, 0.5, 1.0)), Viewport((0.5, 0.0, 0.5, 1.0), renderer="ray_numpy"))


def test_the_line_names_the_tracer_each_nodes_shading_and_the_overlay_it_becomes() -> None:
    scene = Scene("s", viewports=HALVES, lights=(Light((0.0, 5.0, 0.0)),),
                  nodes=(Node("ball", geometry.cube(), material=Material(shading="gouraud", reflectivity=0.25)),
                         Node("left_only", geometry.cube(), viewports=(0,))))
    step = trace_pass(scene, 1)
    assert [d.node for d in step.draws] == ["ball"]
    assert describe(step) == (
        "trace viewport 1 (numpy ray tracer, float64, 1 primary ray per pixel, shadow rays to 1 light, "
        "reflections up to 2 bounces, shown as overlay raytrace/1): ball (phong, reflects 0.25)")


def test_the_traced_scene_keeps_each_nodes_raster_viewports_and_shows_the_image_first() -> None:
    scene = Scene("s", viewports=HALVES, overlays=(Overlay("label", np.zeros((1, 1, 4), np.uint8)),),
                  nodes=(Node("both", geometry.cube()), Node("ray_only", geometry.cube(), viewports=(1,))))
    image = Overlay(traced_image_name(1), np.zeros((2, 2, 4), np.uint8), viewport=1)
    traced = traced_scene(scene, {1: image})
    assert [(n.name, n.viewports) for n in traced.nodes] == [("both", (0,))]
    assert [vp.renderer for vp in traced.viewports] == ["raster", "raster"]
    assert [o.name for o in traced.overlays] == ["raytrace/1", "label"]


def test_the_stencil_mirrors_glass_reflects_at_least_what_the_rasterizer_blends_under_it() -> None:
    glass = Node("glass", geometry.plane(1.0), material=Material(color=(1.0, 1.0, 1.0, 0.25), reflectivity=0.5))
    other = Node("other", geometry.cube(), material=Material(reflectivity=0.5))
    scene = Scene("s", nodes=(glass, other), mirror=Mirror("glass", (0.0, 0.0, 1.0, 0.0), ("other",)))
    assert traced_reflectivity(scene, glass) == 0.75 and traced_reflectivity(scene, other) == 0.5
    assert traced_reflectivity(Scene("no_mirror", nodes=(glass,)), glass) == 0.5
