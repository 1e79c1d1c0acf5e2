"""The ``planar_shadow`` pass's runner (:func:`glsandbox.gl.planar_state.planar_shadow`): it sets the
stencil (where it has a stencil state) and its blending, and leaves depth writes off and the
polygon offset set."""

from __future__ import annotations

from glsandbox.gl.passes import Runner, stencil_set
from glsandbox.gl.planar_state import planar_shadow
from glsandbox.passes.plan_parts import Pass


def habits(step: Pass) -> tuple[frozenset[str], frozenset[str]]:
    return stencil_set(step) | {"blend"}, frozenset({"stencil", "masks", "blend", "offset"})


RUNNER = Runner("planar_shadow", planar_shadow, habits, moved=True)
