"""What every shape offers, and the plumbing the vectorized tests share: broadcasting rays,
recognising one shared origin, and the inf-for-a-miss convention."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import AABB, Plane, RayTraceError, Sphere, Triangle
from glsandbox.raytrace.shape_protocol import Shape, broadcast_rays, finite_positive_or_none, shared_origin


def test_the_course_shapes_offer_the_shape_interface() -> None:
    shapes = (Plane((0, 1, 0), 0), Sphere((0, 0, 0), 1), Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0)),
              AABB((0, 0, 0), (1, 1, 1)))
    assert all(isinstance(shape, Shape) for shape in shapes)
    assert not isinstance(object(), Shape)


def test_one_origin_is_shared_by_many_directions_and_recognised_as_one() -> None:
    origins, directions = broadcast_rays((0, 0, 5), np.eye(3))
    assert origins.shape == directions.shape == (3, 3)
    np.testing.assert_array_equal(shared_origin(origins), (0, 0, 5))  # a stride-0 view: one row
    many = np.array([[0, 0, 5], [0, 0, 5.0]])
    assert shared_origin(many) is many  # equal rows, but separate: not recognised
    o, d = broadcast_rays(np.zeros((2, 3)), (0, 0, -1))
    assert d.shape == (2, 3) and (d[:, 2] == -1).all()


def test_rays_of_different_counts_are_refused() -> None:
    with pytest.raises(RayTraceError, match="same length, got 2 and 3"):
        broadcast_rays(np.zeros((2, 3)), np.ones((3, 3)))


@pytest.mark.parametrize(("t", "value"), [(2.5, 2.5), (np.array([0.5]), 0.5), (np.inf, None), (0.0, None),
                                          (-1.0, None), (np.nan, None)])
def test_a_miss_is_none_and_a_hit_a_positive_t(t, value) -> None:
    assert finite_positive_or_none(t) == value
