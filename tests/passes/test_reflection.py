"""The ``reflection`` pass (glsandbox/passes/reflection.py): the mirror's reflected nodes where the
stencil holds the mirror bit, blended ones after the opaque ones farthest first as the eye's mirror
image sees them; a reflected name that is no node is refused by name (course "The stencil Test")."""

from __future__ import annotations

import pytest

from glsandbox import geometry, transforms
from glsandbox.errors import SandboxError
from glsandbox.passes.planar_effects import REFLECTION_STENCIL
from glsandbox.passes.reflection import describe, reflection_pass
from glsandbox.planar import Mirror
from glsandbox.scene import Camera, Material, Node, Scene

GLASS = Material(color=(1.0, 1.0, 1.0, 0.5), alpha_mode="blend")
# The mirror is the plane z = 0 and the eye at z = 10: its mirror image is at z = -10, so of two
# blended nodes the one at z = 5 is the farther in the mirror.
EYE = Camera(eye=(0.0, 0.0, 10.0), target=(0.0, 0.0, 0.0))


def scene_with(reflected: tuple[str, ...], stencil: bool = True) -> Scene:
    nodes = (Node("mirror", geometry.plane(1.0)),
             Node("near_glass", geometry.cube(), transforms.translate(0.0, 0.0, 5.0), GLASS),
             Node("cube", geometry.cube(), transforms.translate(0.0, 0.0, 3.0)),
             Node("far_glass", geometry.cube(), transforms.translate(0.0, 0.0, 1.0), GLASS))
    return Scene("s", nodes=nodes, camera=EYE, mirror=Mirror("mirror", (0.0, 0.0, 1.0, 0.0), reflected, stencil=stencil))


def by_name(scene: Scene) -> dict[str, Node]:
    return {node.name: node for node in scene.nodes}


def test_opaque_reflections_first_then_blended_ones_farthest_first_in_the_mirror() -> None:
    scene = scene_with(("far_glass", "cube", "near_glass"))
    step = reflection_pass(scene, 0, by_name(scene), set())
    assert [d.node for d in step.draws] == ["cube", "near_glass", "far_glass"]
    assert step.stencil is REFLECTION_STENCIL and step.depth_test


def test_without_the_stencil_the_reflection_has_no_stencil_test() -> None:
    scene = scene_with(("cube",), stencil=False)
    step = reflection_pass(scene, 0, by_name(scene), set())
    assert step.stencil is None
    assert describe(step) == ("reflection viewport 0 (depth test, no stencil, front faces clockwise, lights reflected): "
                              "cube with basic[SOLID_COLOR]")


def test_a_reflected_name_that_is_no_node_is_refused_by_name() -> None:
    scene = scene_with(("cube", "ghost"))
    with pytest.raises(SandboxError, match="mirror reflects 'ghost', which is not a node of the scene"):
        reflection_pass(scene, 0, by_name(scene), set())
