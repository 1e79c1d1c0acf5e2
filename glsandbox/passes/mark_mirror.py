"""The ``mark_mirror`` pass: the mirror's glass drawn into the stencil only (course "The
stencil Test", ``MarkMirrorDSS``): colour and depth writes off, depth test on, so what
stands in front of the glass keeps its pixels unmarked."""

from __future__ import annotations

from glsandbox.passes.plan_parts import Draw, Pass
from glsandbox.passes.planar_effects import MARK_MIRROR_STENCIL, describe_planar


def mark_mirror_pass(index: int, glass: Draw) -> Pass:
    """Viewport ``index``'s marking of the glass drawn as ``glass``."""
    return Pass("mark_mirror", index, draws=(glass,), depth_test=True, stencil=MARK_MIRROR_STENCIL)


def describe(step: Pass) -> str:
    return describe_planar(step, "mark mirror")
