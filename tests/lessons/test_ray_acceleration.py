"""The ray_acceleration lesson (course "Hızlandırma: AABB"): fewer tests with AABBs and the BVH, and its golden."""

from __future__ import annotations

import numpy as np
from support import check_lesson_golden


def test_acceleration_counts_fewer_tests_with_aabb():
    from lessons.ray_acceleration import table

    rows = table("ray_acceleration", False)
    counts = {row[0]: int(row[1].replace(",", "")) for row in rows[2:]}
    assert counts["AABB"] < counts["none"] / 5 and counts["both"] == counts["AABB"]
    assert counts["BVH"] < counts["AABB"] / 5 and counts["BVH+backface"] <= counts["BVH"]


def test_acceleration_times_the_bvh_on_a_rock():
    from lessons.ray_acceleration import rock_rows

    rows = rock_rows()
    assert "5,120 triangles" in rows[0] and rows[2].startswith("BVH ") and "x faster" in rows[2]
    tests = [int(row.split(" ms, ")[1].split(" shape")[0].replace(",", "")) for row in rows[1:]]
    assert tests[1] < tests[0] / 100  # the BVH tests a tiny share of the rock's triangles


def test_golden(gl, golden):
    # The rock line shows times (they change every run): the golden turns it off.
    image = check_lesson_golden(gl, golden, "ray_acceleration", "rock=off")
    assert np.unique(image.reshape(-1, 4), axis=0).shape[0] > 50  # a real picture, not a clear
