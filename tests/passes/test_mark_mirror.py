"""The ``mark_mirror`` pass (glsandbox/passes/mark_mirror.py): the glass drawn into the stencil
only, depth-tested (course "The stencil Test", ``MarkMirrorDSS``)."""

from __future__ import annotations

from glsandbox.passes.mark_mirror import describe, mark_mirror_pass
from glsandbox.passes.plan_parts import Draw
from glsandbox.passes.planar_effects import MARK_MIRROR_STENCIL

GLASS = Draw("glass", "basic", True)


def test_the_glass_replaces_the_mirror_bit_with_the_depth_test_on() -> None:
    step = mark_mirror_pass(2, GLASS)
    assert (step.kind, step.viewport, step.draws, step.depth_test) == ("mark_mirror", 2, (GLASS,), True)
    assert step.stencil is MARK_MIRROR_STENCIL
    assert (step.stencil.test, step.stencil.on_pass, step.stencil.write_mask) == ("always", "replace", step.stencil.ref)


def test_the_line_says_no_colour_or_depth_writes_and_the_stencil() -> None:
    assert describe(mark_mirror_pass(0, GLASS)) == (
        "mark mirror viewport 0 (depth test, no colour or depth writes, stencil always, replace 1): glass with basic")
