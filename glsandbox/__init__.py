"""glsandbox: a graphics course as runnable, tested ModernGL lessons.

The public pieces are a :class:`~glsandbox.scene.Scene` (plain data), its
:func:`~glsandbox.plan.plan` (only the passes the scene needs), and renderers
that run a plan: the raster executor in :mod:`glsandbox.gl` and, for the
course's first half, the ray tracer in :mod:`glsandbox.raytrace`.
"""

from glsandbox.errors import SandboxError

__version__ = "0.1.0"
__all__ = ["SandboxError", "__version__"]
