"""The AABB slab test: the course's centre and half-size form, ±0 directions, origins on faces."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from glsandbox.raytrace import AABB, Ray

BOX = AABB((0, 0, 0), (1, 1, 1))




def test_course_center_and_half_size_form() -> None:
    box = AABB.from_center((-25, -20, 70), (15, 20, 30))  # the notes' AABB(-25, -20, 70, 15, 20, 30)
    np.testing.assert_array_equal(box.min, (-40, -40, 40))
    np.testing.assert_array_equal(box.max, (-10, 0, 100))
    t = box.intersect(Ray((0, 0, 0), (-25, -20, 70)))  # towards the centre (t = 1)
    assert t is not None and 0 < t < 1
    with pytest.raises(ValueError):
        AABB((1, 0, 0), (0, 1, 1))


@pytest.mark.parametrize("zero", [0.0, -0.0])
def test_zero_and_negative_zero_direction_components(zero: float, strict_floats: None) -> None:
    assert BOX.intersect(Ray((-1, 0.5, 0.5), (1, zero, zero))) == 1.0
    assert BOX.intersect(Ray((2, 0.5, 0.5), (-1, zero, zero))) == 1.0
    assert BOX.intersect(Ray((-1, 1.5, 0.5), (1, zero, zero))) is None  # parallel, outside the y slab
    assert BOX.intersect(Ray((-1, -0.5, 0.5), (1, zero, zero))) is None
    assert BOX.intersect(Ray((0.5, 0.5, -3), (zero, zero, 1))) == 3.0


@pytest.mark.parametrize("zero", [0.0, -0.0])
def test_origin_on_a_face_with_a_zero_component_is_not_nan(zero: float, strict_floats: None) -> None:
    # O on the plane x = 0 (or x = 1) and d_x = ±0: (0 − 0)·(±inf) = NaN. The ray
    # runs inside the face's plane, which belongs to the box.
    assert BOX.intersect(Ray((0, 0.5, 0.5), (zero, 1, 0))) == 0.5
    assert BOX.intersect(Ray((1, 0.5, 0.5), (zero, 0, 1))) == 0.5
    assert BOX.intersect(Ray((0, -1, 0.5), (zero, 1, 0))) == 1.0  # along the face from outside
    assert BOX.intersect(Ray((0, 0, -1), (zero, zero, 1))) == 1.0  # along an edge
    assert BOX.intersect(Ray((0, 2, 0.5), (zero, 1, 0))) is None  # in the plane, moving away


def test_origin_on_a_face_heading_in_or_out() -> None:
    assert BOX.intersect(Ray((0, 0.5, 0.5), (1, 0, 0))) == 1.0  # enters at t = 0: the exit is next
    assert BOX.intersect(Ray((0, 0.5, 0.5), (-1, 0, 0))) is None
    assert BOX.intersect(Ray((0.5, 0.5, 0.5), (0, 0, -2))) == 0.25  # inside: the exit, in units of d
    assert BOX.intersect(Ray((-1, 0, 0), (1, 1, 1))) == 1.0  # touches only the corner (0, 1, 1): inclusive


def slab_reference(box: AABB, o: np.ndarray, d: np.ndarray) -> float:
    """A branchy reference: every zero handled by hand, boundaries inclusive."""
    lo, hi = -np.inf, np.inf
    for i in range(3):
        if d[i] == 0:
            if not box.min[i] <= o[i] <= box.max[i]:
                return np.inf
            continue
        a, b = (box.min[i] - o[i]) / d[i], (box.max[i] - o[i]) / d[i]
        lo, hi = max(lo, min(a, b)), min(hi, max(a, b))
    if lo > hi:
        return np.inf
    t = lo if lo > 0 else hi
    return t if t > 0 else np.inf


def test_vectorized_slab_test_matches_a_branchy_reference_on_every_special_case(strict_floats: None) -> None:
    box = AABB((-1, 0, 2), (1, 3, 4))
    coords = {0: [-2.0, -1.0, 0.0, 1.0, 2.0], 1: [-1.0, 0.0, 1.5, 3.0, 4.0], 2: [1.0, 2.0, 3.0, 4.0, 5.0]}
    comps = [-1.0, -0.5, -0.0, 0.0, 0.5, 1.0]
    origins, directions = [], []
    for o in itertools.product(*coords.values()):
        for d in itertools.product(comps, repeat=3):
            if any(d):
                origins.append(o)
                directions.append(d)
    o_arr, d_arr = np.array(origins), np.array(directions)
    t = box.intersect_many(o_arr, d_arr)
    expected = np.array([slab_reference(box, o, d) for o, d in zip(o_arr, d_arr, strict=True)])
    np.testing.assert_array_equal(t, expected)
    assert np.isfinite(t).sum() > 1000 and (~np.isfinite(t)).sum() > 1000


def test_box_normals() -> None:
    np.testing.assert_array_equal(BOX.normal_at((0, 0.5, 0.5)), (-1, 0, 0))
    np.testing.assert_array_equal(BOX.normal_at((0.5, 1, 0.5)), (0, 1, 0))
    np.testing.assert_array_equal(BOX.normal_at((0.5, 0.4, 1)), (0, 0, 1))
    assert BOX.contains((1, 1, 1)) and not BOX.contains((1, 1, 1.0000001))
