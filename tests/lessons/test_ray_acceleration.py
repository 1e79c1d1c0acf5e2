"""The ray_acceleration lesson (course "Hızlandırma: AABB"): fewer tests with AABBs and the BVH, and its golden."""

from __future__ import annotations

import numpy as np
import pytest
from support import check_lesson_golden, variant_name


def test_acceleration_counts_fewer_tests_with_aabb():
    from glsandbox.lessons.ray_acceleration import table

    rows = table("ray_acceleration", False)
    counts = {row[0]: int(row[1].replace(",", "")) for row in rows[2:]}
    assert counts["AABB"] < counts["none"] / 5 and counts["both"] == counts["AABB"]
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
