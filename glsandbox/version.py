"""glsandbox's version, in one place: the package metadata (pyproject's dynamic version) and ``glsandbox --version`` read it."""

__version__ = "0.1.0"
