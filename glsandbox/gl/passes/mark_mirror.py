"""The ``mark_mirror`` pass's runner (:func:`glsandbox.gl.planar_state.mark_mirror`): it sets the
stencil and both write masks, and leaves them changed."""

from __future__ import annotations

from glsandbox.gl.passes import Runner, stencil_set
from glsandbox.gl.planar_state import mark_mirror
from glsandbox.passes.plan_parts import Pass


def habits(step: Pass) -> tuple[frozenset[str], frozenset[str]]:
    return stencil_set(step) | {"masks"}, frozenset({"stencil", "masks"})


RUNNER = Runner("mark_mirror", mark_mirror, habits, moved=True)
