"""The ray tracer's error type.

glsandbox has one user-facing error type (:class:`glsandbox.errors.SandboxError`);
numpy-style code expects :class:`ValueError` for bad arguments. ``RayTraceError``
is both, so ``except SandboxError`` (the CLI) and ``except ValueError`` (library
users, tests) catch it alike.
"""

from __future__ import annotations

from glsandbox.errors import SandboxError


class RayTraceError(SandboxError, ValueError):
    """A bad argument to the ray tracer (zero vector, wrong shape, bad coefficients...)."""
