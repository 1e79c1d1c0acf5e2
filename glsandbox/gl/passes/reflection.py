"""The ``reflection`` pass's runner (:func:`glsandbox.gl.planar_state.reflection`): it sets the
stencil where it has a stencil state, and leaves it so (and the depth mask, where it turns
depth writes off)."""

from __future__ import annotations

from glsandbox.gl.passes import Runner, stencil_set
from glsandbox.gl.planar_state import reflection
from glsandbox.passes.plan_parts import Pass


def habits(step: Pass) -> tuple[frozenset[str], frozenset[str]]:
    # A state table without depth writes in this pass turns them off: the masks are restored after.
    parts = stencil_set(step) | ({"masks"} if step.depth_write is False else frozenset())
    return parts, parts


RUNNER = Runner("reflection", reflection, habits, moved=True)
