"""The ``mirror_surface`` pass (glsandbox/passes/mirror_surface.py): the glass blended over its
reflection, depth-tested, with no stencil of its own (course "The stencil Test")."""

from __future__ import annotations

from glsandbox.passes.mirror_surface import describe, mirror_surface_pass
from glsandbox.passes.plan_parts import Draw

GLASS = Draw("glass", "phong[NUM_LIGHTS=1]", True, blend=True)


def test_the_glass_is_drawn_blended_without_a_stencil_test() -> None:
    step = mirror_surface_pass(1, GLASS)
    assert (step.kind, step.viewport, step.draws, step.depth_test, step.stencil) == (
        "mirror_surface", 1, (GLASS,), True, None)


def test_the_line_says_blended_and_no_stencil_mention() -> None:
    assert describe(mirror_surface_pass(0, GLASS)) == (
        "mirror surface viewport 0 (depth test, blended): glass with phong[NUM_LIGHTS=1] (blended, no depth writes)")
