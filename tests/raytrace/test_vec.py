"""The course's vector algebra (Vektörler): dot, cross, length, normalize, and their input checks."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.raytrace import RayTraceError
from glsandbox.raytrace.vec import as_vec3, as_vec3_batch, cross, dot, length, moved_off, normalize


def test_dot_is_the_cosine_form_and_broadcasts() -> None:
    assert dot((1, 2, 3), (4, -5, 6)) == 12.0
    a, b = np.array([2.0, 0, 0]), np.array([3.0, 3.0, 0])
    assert dot(a, b) == pytest.approx(length(a) * length(b) * np.cos(np.pi / 4))
    np.testing.assert_array_equal(dot([[1, 0, 0], [0, 2, 0]], (1, 1, 1)), [1.0, 2.0])


def test_cross_is_right_handed_perpendicular_with_the_sine_length() -> None:
    np.testing.assert_array_equal(cross((1, 0, 0), (0, 1, 0)), (0, 0, 1))  # x × y = z
    np.testing.assert_array_equal(cross((0, 1, 0), (1, 0, 0)), (0, 0, -1))
    a, b = np.array([1.0, 2.0, 3.0]), np.array([-2.0, 0.5, 4.0])
    c = cross(a, b)
    assert dot(c, a) == pytest.approx(0) and dot(c, b) == pytest.approx(0)
    sine = np.sqrt(1 - (dot(a, b) / (length(a) * length(b))) ** 2)
    assert length(c) == pytest.approx(length(a) * length(b) * sine)


def test_normalize_gives_unit_vectors_and_refuses_zero_or_non_finite() -> None:
    np.testing.assert_allclose(normalize((3, 0, 4)), (0.6, 0, 0.8))
    np.testing.assert_allclose(length(normalize([[1, 1, 1], [0, 0, -2]])), [1.0, 1.0])
    for bad in ((0, 0, 0), (np.inf, 0, 0), [[1, 0, 0], [0, 0, 0]]):
        with pytest.raises(RayTraceError, match="cannot normalize"):
            normalize(bad)


def test_as_vec3_copies_and_names_the_value_it_refuses() -> None:
    source = np.array([1.0, 2.0, 3.0])
    vec = as_vec3(source, "eye")
    vec[0] = 9.0
    assert source[0] == 1.0  # a copy
    with pytest.raises(RayTraceError, match=r"^eye must have shape \(3,\), got shape \(2,\)"):
        as_vec3((1, 2), "eye")
    with pytest.raises(RayTraceError, match=r"^eye must be finite"):
        as_vec3((1, np.nan, 2), "eye")
    with pytest.raises(RayTraceError, match=r"^eye must be 3 numbers"):
        as_vec3(("a", 1, 2), "eye")


def test_as_vec3_batch_lifts_one_vector_and_refuses_other_shapes() -> None:
    assert as_vec3_batch((1, 2, 3)).shape == (1, 3)
    assert as_vec3_batch(np.zeros((5, 3))).shape == (5, 3)
    with pytest.raises(RayTraceError, match=r"shape \(N, 3\), got shape \(2, 2\)"):
        as_vec3_batch(np.zeros((2, 2)))


def test_moved_off_rounds_one_float_further_along_the_step() -> None:
    point = np.array([1.0, 1.0, 1.0])
    step = np.array([1e-17, -1e-17, 0.0])  # below half an ulp of 1: the plain sum would not move
    moved = moved_off(point, step)
    assert moved[0] == np.nextafter(1.0, 2.0) and moved[1] == np.nextafter(1.0, 0.0) and moved[2] == 1.0
