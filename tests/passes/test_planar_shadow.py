"""The ``planar_shadow`` pass (glsandbox/passes/planar_shadow.py): the casters flattened onto the
receiver's plane with one flat program, a blended caster casting nothing, the stencil only when
the shadow asks for it (course "The stencil Test", ``XMMatrixShadow``)."""

from __future__ import annotations

from glsandbox import geometry, transforms
from glsandbox.passes.plan_parts import ProgramVariant
from glsandbox.passes.planar_effects import PLANAR_SHADOW_PROGRAM, PLANAR_SHADOW_STENCIL
from glsandbox.passes.planar_shadow import describe, planar_shadow_pass
from glsandbox.planar import PlanarShadow
from glsandbox.scene import Material, Node, Scene

UP = (0.0, 1.0, 0.0, 0.0)
LIGHT = (0.0, 10.0, 0.0, 1.0)


def scene_with(stencil: bool) -> Scene:
    nodes = (Node("floor", geometry.plane(5.0)),
             Node("cube", geometry.cube(), transforms.translate(0.0, 1.0, 0.0)),
             Node("glass", geometry.cube(), transforms.translate(2.0, 1.0, 0.0), Material(alpha_mode="blend")))
    return Scene("s", nodes=nodes, planar_shadow=PlanarShadow("floor", UP, LIGHT, ("cube", "glass"), stencil=stencil))


def by_name(scene: Scene) -> dict[str, Node]:
    return {node.name: node for node in scene.nodes}


def test_opaque_casters_are_drawn_flat_and_a_blended_one_casts_nothing() -> None:
    scene = scene_with(stencil=True)
    programs: set[ProgramVariant] = set()
    step = planar_shadow_pass(scene, 0, by_name(scene), programs)
    assert [(d.node, d.program, d.cull_back_faces) for d in step.draws] == [("cube", PLANAR_SHADOW_PROGRAM.key, False)]
    assert programs == {PLANAR_SHADOW_PROGRAM}
    assert step.stencil is PLANAR_SHADOW_STENCIL and step.depth_test


def test_without_the_stencil_the_pass_has_none_and_the_line_says_so() -> None:
    scene = scene_with(stencil=False)
    step = planar_shadow_pass(scene, 0, by_name(scene), set())
    assert step.stencil is None
    assert describe(step) == ("planar shadow viewport 0 (depth test, no stencil, lift 0.005, polygon offset, "
                              "blended, no depth writes): cube with basic[SOLID_COLOR] (no culling)")
