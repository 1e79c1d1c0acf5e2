"""The watertight scan's probe (:func:`glsandbox.raytrace.aimed_rays`): rays aimed exactly at the
vertices and edges of a closed mesh from inside it, which every crack-free test must hit, and
the two vectorised scans the report and ``ray_triangle`` time (:func:`nearest_by`)."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import aimed_rays, nearest_by


def test_every_aimed_ray_hits_the_closed_mesh_at_the_point_it_aims_at() -> None:
    tris, origins, directions = aimed_rays((32, 24))
    assert origins.shape == directions.shape == (32 * 24, 3) and tris[0].shape == (80, 3)
    t = nearest_by("watertight", tris, origins, directions)
    assert np.all(np.isfinite(t))  # from inside a closed mesh no ray escapes
    # The point aimed at is on the surface, so the nearest hit is there (t = 1), never beyond it.
    assert np.all(t <= 1.0 + 1e-9) and np.median(t) == pytest.approx(1.0, abs=1e-9)
    # Moller-Trumbore finds the same hits wherever it finds one.
    mt = nearest_by("mt64", tris, origins, directions)
    found = np.isfinite(mt)
    assert found.mean() > 0.9 and np.allclose(mt[found], t[found], rtol=0, atol=1e-9)


def test_the_probe_moves_with_the_mesh_and_unknown_tests_are_refused() -> None:
    (a, _, _), origins, _ = aimed_rays((16, 12))
    (b, _, _), moved, _ = aimed_rays((16, 12), 1e3)
    assert np.allclose(b - a, 1e3 * np.array([0.99, 0.7, -0.4])) and np.allclose(moved - origins, b[0] - a[0])
    with pytest.raises(ValueError, match="unknown triangle test 'mt32'"):
        nearest_by("mt32", *aimed_rays((4, 3)))
