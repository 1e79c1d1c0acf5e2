"""The ``reflection`` pass: the reflected nodes drawn with R @ model where the stencil holds
the mirror bit (course "The stencil Test", ``DrawReflectionDSS``, ``XMMatrixReflect``), with
the front-face rule flipped (det R = -1, ``CullClockwise``) and the lights reflected too.
Without the stencil the reflection has no stencil test and leaks outside the glass."""

from __future__ import annotations

from glsandbox.errors import SandboxError
from glsandbox.passes.order import farthest_first, mirrored_eye
from glsandbox.passes.plan_parts import Draw, Pass, ProgramVariant
from glsandbox.passes.planar_effects import REFLECTION_STENCIL, describe_planar
from glsandbox.plan_variants import program_for
from glsandbox.scene import Node, Scene


def reflection_pass(scene: Scene, index: int, nodes: dict[str, Node], programs: set[ProgramVariant]) -> Pass:
    """Viewport ``index``'s reflection of the mirror's ``reflected`` nodes (``nodes``: the scene's
    by name), adding their variants to ``programs``."""
    mirror = scene.mirror
    assert mirror is not None
    reflected, blended = [], []
    for name in mirror.reflected:
        if name not in nodes:
            raise SandboxError(f"mirror reflects {name!r}, which is not a node of the scene")
        node = nodes[name]
        if node.shown_in(index):
            variant = program_for(node, len(scene.lights))  # a cut-out's ALPHA_MASK too, as in the main pass
            programs.add(variant)
            blend = node.material.alpha_mode == "blend"
            (blended if blend else reflected).append((node, Draw(name, variant.key, node.cull_back_faces,
                                                                 blend=blend)))
    # Blended parts after the opaque ones, farthest first as seen in the mirror: from the eye's
    # mirror image (the reflection is an isometry, so its distances are the reflected ones).
    eye = mirrored_eye(mirror, scene.viewports[index].camera or scene.camera)
    draws = [d for _, d in reflected] + [d for _, d in farthest_first(blended, eye)]
    return Pass("reflection", index, draws=tuple(draws), depth_test=True,
                stencil=REFLECTION_STENCIL if mirror.stencil else None,
                detail="front faces clockwise, lights reflected")


def describe(step: Pass) -> str:
    return describe_planar(step, "reflection")
