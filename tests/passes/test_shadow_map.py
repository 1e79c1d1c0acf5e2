"""The ``shadow_map`` pass (glsandbox/passes/shadow_map.py): the casting light's depth-only pass
before every viewport, drawn only when some lit node receives it; its casters with the depth
program, a blended caster left out; the line names the light, the target and the map's size."""

from __future__ import annotations

from glsandbox import geometry, transforms
from glsandbox.passes.plan_parts import ProgramVariant
from glsandbox.passes.shadow_map import DEPTH_PROGRAM, describe, shadow_map_passes
from glsandbox.scene import Light, Material, Node, Scene, ShadowMap

LIT = Material(shading="phong")


def scene_with(*nodes: Node, shadow: ShadowMap | None = ShadowMap(size=512, fov=60.0)) -> Scene:
    return Scene("s", nodes=nodes, lights=(Light((0.0, 5.0, 0.0)), Light((0.0, 5.0, 1.0), shadow=shadow)))


def test_the_casting_lights_pass_draws_its_casters_with_the_depth_program() -> None:
    scene = scene_with(Node("floor", geometry.plane(5.0), material=LIT, casts_shadow=False),
                       Node("cube", geometry.cube(), transforms.translate(0.0, 1.0, 0.0), LIT),
                       Node("glass", geometry.cube(), material=Material(alpha_mode="blend")))
    programs: set[ProgramVariant] = set()
    steps, light = shadow_map_passes(scene, programs)
    assert light == 1 and programs == {DEPTH_PROGRAM}
    (step,) = steps
    assert (step.target, step.camera, step.viewport, step.clear_depth) == ("shadow map 1", "light 1", -1, True)
    assert [d.node for d in step.draws] == ["cube"]
    assert describe(step) == ("shadow map from light 1 into shadow map 1 (512x512 depth 24, perspective 60°, "
                              "cleared, depth test, no colour): cube with basic[SOLID_COLOR]")


def test_no_pass_without_a_shadow_map_or_without_a_lit_receiver() -> None:
    cube = Node("cube", geometry.cube(), material=LIT)
    assert shadow_map_passes(scene_with(cube, shadow=None), set()) == ([], None)
    unlit = Node("cube", geometry.cube())  # basic shading: it cannot receive
    programs: set[ProgramVariant] = set()
    assert shadow_map_passes(scene_with(unlit), programs) == ([], None) and programs == set()
