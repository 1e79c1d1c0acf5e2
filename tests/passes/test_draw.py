"""The ``draw`` pass (glsandbox/passes/draw.py): the nodes a viewport shows, opaque ones in scene
order and blended ones after them farthest first, each with its program variant; the mirror's
glass left to the mirror passes; a receiver's draw naming the shadow map it reads."""

from __future__ import annotations

from glsandbox import geometry, transforms
from glsandbox.passes.draw import describe, draw_pass
from glsandbox.passes.plan_parts import ProgramVariant
from glsandbox.planar import Mirror
from glsandbox.scene import Camera, Light, Material, Node, Scene, ShadowMap, Viewport

GLASS = Material(color=(1.0, 1.0, 1.0, 0.5), alpha_mode="blend")
EYE = Camera(eye=(0.0, 0.0, 10.0), target=(0.0, 0.0, 0.0))


def blended_at(name: str, z: float) -> Node:
    return Node(name, geometry.cube(), transforms.translate(0.0, 0.0, z), GLASS)


def test_opaque_nodes_come_first_in_scene_order_then_blended_ones_farthest_first() -> None:
    scene = Scene("s", camera=EYE, nodes=(blended_at("near", 5.0), Node("a", geometry.cube()),
                                          blended_at("far", -5.0), Node("b", geometry.cube())))
    programs: set[ProgramVariant] = set()
    step = draw_pass(scene, 0, True, programs, None, 1)
    assert [d.node for d in step.draws] == ["a", "b", "far", "near"]
    assert [d.blend for d in step.draws] == [False, False, True, True]
    assert {d.program for d in step.draws} == {v.key for v in programs}


def test_a_viewport_that_shows_nothing_has_no_draw_pass() -> None:
    scene = Scene("s", nodes=(Node("only_in_1", geometry.cube(), viewports=(1,)),),
                  viewports=(Viewport((0.0, 0.0, 0.5, 1.0)), Viewport((0.5, 0.0, 0.5, 1.0))))
    assert draw_pass(scene, 0, True, set(), None, 1) is None
    assert [d.node for d in draw_pass(scene, 1, True, set(), None, 1).draws] == ["only_in_1"]


def test_the_mirrors_glass_is_left_to_the_mirror_passes() -> None:
    scene = Scene("s", nodes=(Node("glass", geometry.plane(1.0)), Node("cube", geometry.cube())),
                  mirror=Mirror("glass", (0.0, 0.0, 1.0, 0.0), ("cube",)))
    assert [d.node for d in draw_pass(scene, 0, True, set(), None, 1).draws] == ["cube"]


def test_a_lit_receiver_reads_the_shadow_map_and_the_line_says_so() -> None:
    lit = Material(shading="phong")
    scene = Scene("s", lights=(Light((0.0, 5.0, 0.0), shadow=ShadowMap()),),
                  nodes=(Node("floor", geometry.plane(1.0), material=lit),
                         Node("away", geometry.cube(), material=lit, receives_shadow=False)))
    step = draw_pass(scene, 0, False, set(), 0, 3)
    assert [d.shadow_map for d in step.draws] == [0, None]
    line = describe(step)
    assert line.startswith("draw viewport 0 (no depth test): floor with phong[")
    assert "texture unit 1: shadow map 0" in line and line.count("shadow map") == 1
