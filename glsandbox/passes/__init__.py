"""The pass kinds: one module per kind, ``glsandbox/passes/<kind>.py``.

Each kind's module holds what the plan knows of it: ``describe(step)``, the
line ``glsandbox plan`` prints for a pass of that kind, and the planner that
makes its passes (called by :func:`glsandbox.plan.plan`). Its runner, the GL
side, is ``glsandbox/gl/passes/<kind>.py`` (:mod:`glsandbox.gl.passes`).

A new kind: its name in :data:`PASS_KINDS` (frame order), its module here,
its runner module there, and its test; ``tests/gl/test_passes.py`` fails
naming the kind and the part it lacks.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Callable
from types import ModuleType
from typing import Any

from glsandbox.errors import SandboxError

#: Every pass kind, in frame order: a kind's module is ``glsandbox.passes.<kind>``.
PASS_KINDS = ("trace", "shadow_map", "clear", "draw", "mark_mirror", "reflection", "mirror_surface",
              "planar_shadow", "overlay")


@functools.cache
def kind_module(kind: str) -> ModuleType:
    """The module of pass kind ``kind``; a :class:`SandboxError` naming it for a kind not in :data:`PASS_KINDS`."""
    if kind not in PASS_KINDS:
        raise SandboxError(f"pass kind {kind!r} has no describer (it is not in glsandbox.passes.PASS_KINDS)")
    return importlib.import_module(f"{__name__}.{kind}")


def describer(kind: str) -> Callable[[Any], str]:
    """``describe(step)`` of pass kind ``kind`` (its module's)."""
    describe = getattr(kind_module(kind), "describe", None)
    if describe is None:
        raise SandboxError(f"pass kind {kind!r} has no describer (glsandbox/passes/{kind}.py defines no describe)")
    return describe
