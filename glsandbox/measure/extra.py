"""The ``measure`` extra: flip-evaluator and matplotlib, needed by ``glsandbox tradeoffs`` only.

They are optional dependencies (``pip install 'glsandbox[measure]'``; in the
repository ``uv run --extra measure ...``; the tests' ``dev`` group has them).
Every import of them goes through :func:`require`, so a missing one is one
``error: ...`` line (exit status 2) instead of a traceback. FLIP alone may be
missing (``flip-evaluator`` has no wheel for some systems and Pythons): then
:func:`has_flip` is false, and ``tradeoffs`` says in one line that it leaves
the FLIP column and error maps out, and measures the rest.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from glsandbox.errors import SandboxError

__all__ = ["FLIP_MISSING", "MISSING", "MODULES", "has_flip", "require", "require_all"]

#: The message when the extra is not installed.
MISSING = ("glsandbox tradeoffs needs matplotlib (the 'measure' extra, with flip-evaluator): "
           "uv run --extra measure glsandbox tradeoffs")
#: The extra's top-level modules.
MODULES = ("flip_evaluator", "matplotlib")
#: What ``tradeoffs`` says, once, when flip-evaluator alone is missing.
FLIP_MISSING = ("tradeoffs: flip-evaluator is not installed: the FLIP column and the error maps are left out, "
                "the rest is measured (pip install flip-evaluator, or uv run --extra measure glsandbox tradeoffs)")


def require(name: str) -> ModuleType:
    """Import ``name``, a module of the extra (or one inside it, e.g. ``matplotlib.pyplot``).

    Raises:
        SandboxError: it cannot be imported (:data:`MISSING`).
    """
    try:
        return importlib.import_module(name)
    except ImportError:
        raise SandboxError(MISSING) from None


def has_flip() -> bool:
    """Whether flip-evaluator imports (FLIP is the one part of the extra ``tradeoffs`` can do without)."""
    try:
        importlib.import_module("flip_evaluator")
    except ImportError:
        return False
    return True


def require_all() -> None:
    """Check that every module the measuring cannot do without imports (matplotlib, for the
    plot), before any work is done; FLIP is optional (:func:`has_flip`)."""
    for name in MODULES:
        if name != "flip_evaluator":
            require(name)
