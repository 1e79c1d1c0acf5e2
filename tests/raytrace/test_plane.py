"""Işın-Düzlem (ray-plane): parallel rays, planes behind the ray, the sign convention, bad planes."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import Plane, Ray


def test_ray_parallel_to_a_plane_returns_none(strict_floats: None) -> None:
    plane = Plane((0, 0.6, -0.8), 72)
    assert plane.intersect(Ray((0, 0, 0), (1, 0, 0))) is None  # N·Rd = 0
    assert plane.intersect(Ray((0, 0, 0), (0, 0.8, 0.6))) is None
    in_plane = Ray((0, 0, 90), (0, 0.8, 0.6))  # inside the plane and parallel to it
    assert plane.intersect(in_plane) is None
    t = plane.intersect_many(np.array([[0, 0, 0], [0, 0, 90.0]]), np.array([[1, 0, 0], [0, 0.8, 0.6]]))
    assert np.all(t == np.inf)


def test_plane_behind_the_ray_and_origin_on_the_plane() -> None:
    plane = Plane((0, 0, 1), -5)  # z = 5
    assert plane.intersect(Ray((0, 0, 0), (0, 0, -1))) is None
    assert plane.intersect(Ray((0, 0, 0), (0, 0, 1))) == 5.0
    assert plane.intersect(Ray((0, 0, 5), (0, 0, 1))) is None  # t = 0 is not > 0


def test_plane_sign_convention_and_non_unit_normal() -> None:
    assert Plane.through((0, 0, 1), (7, -3, 5)).d == -5.0  # N·P + D = 0
    plane = Plane((0, 0, 2), -10)  # 2z − 10 = 0: z = 5
    np.testing.assert_allclose(plane.normal_at((1, 2, 5)), (0, 0, 1))
    assert plane.intersect(Ray((0, 0, 0), (0, 0, 1))) == 5.0
    assert plane.signed_distance((0, 0, 8)) == pytest.approx(3.0)
    assert Plane((0, 0.6, -0.8), 72).signed_distance((0, 0, 0)) == pytest.approx(72.0)  # D: origin's distance


def test_bad_planes() -> None:
    with pytest.raises(ValueError):
        Plane((0, 0, 0), 1)
    with pytest.raises(ValueError):
        Plane((0, 0, 1), float("nan"))
    with pytest.raises(ValueError):
        Ray((0, 0, 0), (0, 0, 0))
