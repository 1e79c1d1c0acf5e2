"""The ``reflection`` pass's runner (:func:`glsandbox.gl.planar.reflection`): it sets the
stencil where it has a stencil state, and leaves it so."""

from __future__ import annotations

from glsandbox.gl.passes import Runner, stencil_set
from glsandbox.gl.planar import reflection
from glsandbox.passes.base import Pass


def habits(step: Pass) -> tuple[frozenset[str], frozenset[str]]:
    return stencil_set(step), stencil_set(step)


RUNNER = Runner("reflection", reflection, habits, moved=True)
