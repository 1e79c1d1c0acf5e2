"""The ``mirror_surface`` pass's runner (:func:`glsandbox.gl.planar_state.mirror_surface`): it sets
its blending and leaves it on."""

from __future__ import annotations

from glsandbox.gl.passes import Runner
from glsandbox.gl.planar_state import mirror_surface
from glsandbox.passes.plan_parts import Pass

_BLEND = frozenset({"blend"})


def habits(step: Pass) -> tuple[frozenset[str], frozenset[str]]:
    return _BLEND, _BLEND


RUNNER = Runner("mirror_surface", mirror_surface, habits, moved=True)
