"""The ray_acceleration lesson (course "Hızlandırma: AABB"): fewer tests with AABBs and the BVH, and its golden."""

from __future__ import annotations

import numpy as np
import pytest
from support import check_lesson_golden, variant_name


def test_acceleration_counts_fewer_tests_with_aabb():
    from glsandbox.lessons.ray_acceleration import table

    rows = table("ray_acceleration", False)
    counts = {row[0]: int(row[1].replace(",", "")) for row in rows[2:]}
    assert counts["AABB"] < counts["none"] / 5
    # Backface culling skips the tests of the faces turned away (about half of a closed mesh's).
    assert counts["backface"] < 0.6 * counts["none"] and counts["both"] < 0.6 * counts["AABB"]
    assert counts["BVH"] < counts["AABB"] / 5 and counts["BVH+backface"] <= counts["BVH"]


def test_acceleration_times_the_bvh_on_a_rock_with_timing_on():
    from glsandbox.lessons.ray_acceleration import rock_rows

    rows = rock_rows(True)
    assert "5,120 triangles" in rows[0] and rows[2].startswith("BVH ") and "x faster" in rows[2]
    tests = [int(row.split(" ms, ")[1].split(" shape")[0].replace(",", "")) for row in rows[1:]]
    assert tests[1] < tests[0] / 100  # the BVH tests a tiny share of the rock's triangles


def test_the_default_rock_line_counts_tests_and_shows_no_time():
    """Times change every run: the default picture holds counts only (tests/gl/test_context.py
    requires every lesson's picture to be the same in two runs and on both backends)."""
    from glsandbox.lessons.ray_acceleration import RayAcceleration, rock_rows

    rows = rock_rows(False)
    assert rows[1].startswith("AABB: ") and rows[2].startswith("BVH: ") and rows[2].endswith("x fewer")
    assert not any(" ms" in row or "faster" in row for row in rows)
    tests = [int(row.split()[1].replace(",", "")) for row in rows[1:]]
    assert tests[1] < tests[0] / 100
    assert RayAcceleration().values["timing"] is False and RayAcceleration().values["rock"] is True


@pytest.mark.parametrize("settings", [(), ("rock=off",)], ids=variant_name)
def test_golden(gl, golden, settings):
    image = check_lesson_golden(gl, golden, "ray_acceleration", *settings)
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear


def test_backface_culling_skips_tests_and_keeps_the_picture() -> None:
    """Culling drops the triangles facing away before any test: the count falls (the
    spheres are closed, so about half their pairs face away) and the picture is the
    same as without it (a back face is never the first visible hit of a closed mesh). Neither
    depends on the size: the picture is the lesson's at half its measuring size (a quarter of
    the rays, every ray still tested against every triangle)."""
    from glsandbox.raytrace.numpy_engine import RenderStats
    from glsandbox.raytrace.render import render as trace
    from lessons.ray_acceleration import MEASURE_SIZE, scene

    base, size = scene("ray_acceleration"), (MEASURE_SIZE[0] // 2, MEASURE_SIZE[1] // 2)
    counts, images = {}, {}
    for cull in (False, True):
        stats = RenderStats()
        images[cull] = trace(base, size, cull_backfaces=cull, aabb=False, bvh=False, stats=stats)
        counts[cull] = stats.tests
    assert counts[True] < 0.6 * counts[False], counts
    assert np.array_equal(images[True], images[False])


def test_the_watertight_scan_with_culling_tests_only_the_front_faces() -> None:
    from glsandbox import geometry
    from glsandbox.raytrace.watertight import nearest_watertight

    mesh = geometry.sphere()
    p, f = np.asarray(mesh.positions, dtype=np.float64), mesh.triangle_indices()
    v0, v1, v2 = p[f[:, 0]], p[f[:, 1]], p[f[:, 2]]
    rng = np.random.default_rng(3)
    d = np.c_[rng.normal(size=(200, 2)) * 0.2, -np.ones(200)]
    for origins in (np.array([0.0, 0.0, 5.0]), np.c_[rng.normal(size=(200, 2)) * 0.1, np.full(200, 5.0)]):
        both, one = [], []
        t2, i2 = nearest_watertight(v0, v1, v2, origins, d, tested=both)
        t1, i1 = nearest_watertight(v0, v1, v2, origins, d, cull_backfaces=True, tested=one)
        assert np.array_equal(t1, t2) and np.array_equal(i1, i2)  # from outside, the front face is nearest
        assert one[0] < 0.6 * both[0], (one, both)
