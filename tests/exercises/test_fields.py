"""Probe pictures' inputs (glsandbox/exercises/fields.py): the pixel grid read like a plot, the
hemisphere of normals seen from above, and arrays as the plain floats a student's function gets."""

from __future__ import annotations

import numpy as np

from glsandbox.exercises.fields import grid, hemisphere, plain, unit


def test_the_grid_is_the_pixel_centres_row_by_row_from_the_top() -> None:
    points = grid(2, 0.0, 4.0)
    assert points.tolist() == [[1.0, 3.0], [3.0, 3.0], [1.0, 1.0], [3.0, 1.0]]  # u to the right, v upwards
    assert grid(5, -1.0, 1.0).shape == (25, 2)


def test_the_hemisphere_is_unit_normals_facing_up_and_the_horizon_outside_the_disc() -> None:
    n = 9
    normals = hemisphere(n)
    assert normals.shape == (n * n, 3)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0) and (normals[:, 2] >= 0).all()
    centre = normals[(n // 2) * n + n // 2]
    assert np.allclose(centre, [0.0, 0.0, 1.0])  # the middle pixel looks straight up
    corner = normals[0]  # top left: outside the disc, on the horizon towards (-1, 1)
    assert corner[2] == 0.0 and np.allclose(corner[:2], [-np.sqrt(0.5), np.sqrt(0.5)])


def test_plain_values_are_python_floats() -> None:
    rows = plain(np.array([[1, 2], [3, 4]], dtype=np.float32))
    assert rows == [(1.0, 2.0), (3.0, 4.0)] and all(type(x) is float for row in rows for x in row)
    assert plain(np.array([0.5, 2.0])) == [0.5, 2.0]
    assert unit((3.0, 0.0, 4.0)) == (0.6, 0.0, 0.8)
