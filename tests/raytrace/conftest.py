"""Fixtures of the ray tracer's tests: ``engine_path``, every path a render can take
(tests/conftest.py's ``engine`` is the two engines; this splits each into scan and BVH),
and ``strict_floats``."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator

import numpy as np
import pytest

#: The paths a render takes: the numpy engine's per-node scan (``bvh=False``) and
#: its BVH, the gpu engine's scan (meshes of at most gpu.BVH_TRIANGLES triangles)
#: and its BVH program (forced here by setting that bound to 0).
ENGINE_PATHS = ("numpy-scan", "numpy-bvh", "gpu-scan", "gpu-bvh")


@pytest.fixture(params=ENGINE_PATHS)
def engine_path(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> Callable[..., np.ndarray]:
    """``engine_path(scene, size, **options)``: the scene rendered through one engine path
    (the fixture's id names it); gpu paths need a GL backend (skip without one)."""
    from glsandbox.raytrace import render

    path = request.param
    if path.startswith("gpu"):
        from glsandbox.raytrace import gpu as gpu_engine

        ctx = request.getfixturevalue("gl").host.ctx
        tracer = gpu_engine.gpu_tracer(ctx)
        tracer.forget_scenes()  # an upload decides scan or BVH once: none kept from another path
        request.addfinalizer(tracer.forget_scenes)
        monkeypatch.setattr(gpu_engine, "BVH_TRIANGLES", 0 if path == "gpu-bvh" else 1 << 30)

        def trace(scene, size, **options):
            return render(scene, size, "gpu", ctx=ctx, **options)
    else:
        def trace(scene, size, **options):
            return render(scene, size, bvh=path == "numpy-bvh", **options)
    trace.path = path  # type: ignore[attr-defined]
    return trace


@pytest.fixture
def strict_floats() -> Iterator[None]:
    """Any floating-point warning (a 0/0, an overflow) fails the test instead of passing silently."""
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        yield
