"""The triangle-test knob (glsandbox/measure/knobs/triangle_test.py): Möller–Trumbore leaks at
shared vertices and edges, the watertight test never does."""

from __future__ import annotations

import numpy as np
from support import knob_counts

from glsandbox.measure.knobs import triangle_test
from glsandbox.measure.knobs._far import DIRECTION


def test_triangle_test_moller_trumbore_leaks_and_watertight_does_not() -> None:
    size = (64, 48)
    counts = knob_counts(triangle_test.KNOB, size)
    assert all(count.of == size[0] * size[1] for count in counts.values())
    watertight = {label: count for label, count in counts.items() if label.startswith("watertight")}
    assert len(watertight) >= 4 and all(count.pixels == 0 for count in watertight.values())
    # Möller–Trumbore aimed at shared vertices and edges misses some, float64 and float32 alike.
    assert counts["Möller–Trumbore float64, at 0"].share > 0.01
    assert counts["Möller–Trumbore float32, at 0"].share > 0.01
    assert counts["Möller–Trumbore float64, at 100000"].pixels > 0


def test_triangle_test_rays_are_aimed_at_the_mesh_and_its_frame_shows_the_leaks() -> None:
    size = (40, 30)
    tris, origins, directions = triangle_test.aimed_rays(size, 1e3)
    centre = 1e3 * DIRECTION
    assert np.abs(origins - centre).max() <= 0.4 + 1e-9  # every eye is inside the mesh (radius 2)
    targets = origins + directions  # t = 1 is the point aimed at: a vertex or an edge point
    corners = np.concatenate(tris)
    on_vertex = np.isclose(np.linalg.norm(corners[None] - targets[:, None], axis=-1), 0.0, atol=1e-9).any(axis=1)
    assert on_vertex.any() and not on_vertex.all()
    assert np.allclose(np.linalg.norm(targets - centre, axis=1), 2.0, atol=0.25)  # on the surface, not beyond
    frame = triangle_test.frame("mt64", 0.0, size)
    leaked = ~np.isfinite(triangle_test.nearest_t("mt64", *triangle_test.aimed_rays(size, 0.0)))
    assert frame.shape == (30, 40, 4) and np.count_nonzero(frame[..., 1] == 0) == np.count_nonzero(leaked) > 0


def test_float32_moller_trumbore_hits_where_float64_does_away_from_the_edges() -> None:
    tris, origins, _ = triangle_test.aimed_rays((40, 30), 0.0)
    centroids = (tris[0] + tris[1] + tris[2]) / 3.0
    origin = np.repeat(origins[:1], len(centroids), axis=0)
    t32 = triangle_test.moller_trumbore_float32(tris, origin, centroids - origin)
    t64 = triangle_test.nearest_t("mt64", tris, origin, centroids - origin)
    assert np.isfinite(t32).all() and np.allclose(t32, t64, rtol=1e-5) and np.allclose(t64, 1.0)
