"""The ``measure`` extra: flip-evaluator and matplotlib, needed by ``glsandbox tradeoffs`` only.

They are optional dependencies (``pip install 'glsandbox[measure]'``; in the
repository ``uv run --extra measure ...``; the tests' ``dev`` group has them).
Every import of them goes through :func:`require`, so a missing one is one
``error: ...`` line (exit status 2) instead of a traceback.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from glsandbox.errors import SandboxError

__all__ = ["MISSING", "MODULES", "require", "require_all"]

#: The message when the extra is not installed.
MISSING = ("glsandbox tradeoffs needs flip-evaluator and matplotlib (the 'measure' extra): "
           "uv run --extra measure glsandbox tradeoffs")
#: The extra's top-level modules.
MODULES = ("flip_evaluator", "matplotlib")


def require(name: str) -> ModuleType:
    """Import ``name``, a module of the extra (or one inside it, e.g. ``matplotlib.pyplot``).

    Raises:
        SandboxError: it cannot be imported (:data:`MISSING`).
    """
    try:
        return importlib.import_module(name)
    except ImportError:
        raise SandboxError(MISSING) from None


def require_all() -> None:
    """Check that every module of the extra imports, before any work is done."""
    for name in MODULES:
        require(name)
