"""The ``mirror_surface`` pass: the mirror's glass blended over its reflection (course
"The stencil Test": the glass's alpha is the share of its own colour)."""

from __future__ import annotations

from glsandbox.passes.plan_parts import Draw, Pass
from glsandbox.passes.planar_effects import describe_planar


def mirror_surface_pass(index: int, glass: Draw) -> Pass:
    """Viewport ``index``'s glass, drawn as ``glass`` and blended."""
    return Pass("mirror_surface", index, draws=(glass,), depth_test=True, detail="blended")


def describe(step: Pass) -> str:
    return describe_planar(step, "mirror surface")
