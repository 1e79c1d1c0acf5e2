"""A ray R = R0 + t·Rd: its points, and the directions it refuses."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import Ray, RayTraceError


def test_at_walks_the_unnormalized_direction() -> None:
    ray = Ray((1, 2, 3), (0, 0, -2))
    np.testing.assert_array_equal(ray.at(0.0), (1, 2, 3))
    np.testing.assert_array_equal(ray.at(1.5), (1, 2, 0))  # t counts whole directions, not units
    assert repr(ray) == "Ray(origin=[1.0, 2.0, 3.0], direction=[0.0, 0.0, -2.0])"


def test_the_ray_keeps_copies_of_what_it_was_given() -> None:
    origin = np.array([0.0, 0.0, 0.0])
    ray = Ray(origin, (1, 0, 0))
    origin[0] = 5.0
    assert ray.origin[0] == 0.0


@pytest.mark.parametrize(("origin", "direction", "message"), [
    ((0, 0, 0), (0, 0, 0), "zero vector"),
    ((0, 0, 0), (0, np.nan, 1), "ray direction must be finite"),
    ((0, 0), (0, 0, 1), r"ray origin must have shape \(3,\)"),
])
def test_bad_rays_are_refused(origin, direction, message: str) -> None:
    with pytest.raises(RayTraceError, match=message):
        Ray(origin, direction)
