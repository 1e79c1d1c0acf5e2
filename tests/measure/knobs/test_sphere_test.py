"""The sphere-test knob (glsandbox/measure/knobs/sphere_test.py): the course's geometric test frays
at 1e8, the stable one holds."""

from __future__ import annotations

import numpy as np
from support import knob_counts

from glsandbox.measure.knobs import sphere_test


def test_sphere_test_geometric_fails_far_away_and_stable_holds() -> None:
    size = (48, 36)
    counts = knob_counts(sphere_test.KNOB, size)
    assert counts["geometric, at 100"].pixels == 0 and counts["geometric, at 10000"].pixels == 0
    assert counts["geometric, at 1e+08"].share > 0.2  # the silhouette and the hit distances are gone
    assert counts["geometric, at 1e+06"].pixels > counts["geometric, at 10000"].pixels
    assert counts["stable, at 1e+08"].pixels == 0 and counts["stable, at 100"].pixels == 0
    sphere, directions = sphere_test.view(size, 1e8)
    exact = sphere_test.exact_t(size, 1e8)
    hit = np.isfinite(exact)
    assert 0.2 < hit.mean() < 0.6  # the sphere fills the same part of the frame at every distance
    geometric = sphere_test.geometric_many(sphere, directions)
    stable = sphere_test.stable_many(sphere, directions)
    both = hit & np.isfinite(geometric)
    assert np.abs(geometric[both] - exact[both]).max() > 0.1 * sphere_test.RADIUS
    assert np.array_equal(np.isfinite(stable), hit)
    assert np.abs(stable[hit] - exact[hit]).max() < 1e-6 * sphere_test.RADIUS


def test_sphere_test_geometric_is_the_courses_test_and_exact_is_exact() -> None:
    from glsandbox.raytrace.ray import Ray

    sphere, directions = sphere_test.view((24, 18), 1e6)
    vectorized = sphere_test.geometric_many(sphere, directions)
    scalar = np.array([sphere.intersect(Ray(np.zeros(3), d), method="geometric") or np.inf for d in directions])
    assert np.array_equal(vectorized, scalar)  # the course's steps, bit for bit
    near, dirs = sphere_test.view((24, 18), 100.0)
    exact = sphere_test.exact_t((24, 18), 100.0)
    stable = sphere_test.stable_many(near, dirs)
    assert np.array_equal(np.isfinite(exact), np.isfinite(stable))
    assert np.allclose(stable, exact, rtol=1e-13, atol=0.0, equal_nan=False)
