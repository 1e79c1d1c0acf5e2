"""The Stanford bunny that pymeshlab ships inside its wheel (the ``bench`` group): never downloaded."""

from __future__ import annotations

from pathlib import Path


def bunny_path() -> Path | None:
    """pymeshlab's copy of the Stanford bunny (56,172 triangles), or None when pymeshlab is not installed."""
    try:
        import pymeshlab
    except ImportError:
        return None
    path = Path(pymeshlab.__file__).parent / "tests" / "sample_meshes" / "bunny.obj"
    return path if path.is_file() else None
