"""``intersect_many``: many rays at once, ``inf`` for misses, the same numbers as one ray at a time."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from glsandbox.raytrace import (
    AABB,
    Plane,
    Ray,
    Shape,
    Sphere,
    Triangle,
    TriangleBatch,
    moller_trumbore_many,
    nearest_hit,
    nearest_hit_many,
)

# The course's image plane: pixel (x, y) of 800x450 -> (16x/799 − 8, 4.5 − 9y/449, 10);
# a coarse grid of it is enough here.
XS, YS = np.meshgrid(np.arange(0, 800, 20), np.arange(0, 450, 20))
PIXELS = np.stack([16 * XS.ravel() / 799 - 8, 4.5 - 9 * YS.ravel() / 449, np.full(XS.size, 10.0)], axis=1)
EYE = np.zeros(3)

CUBE_VERTS = np.array(
    [(-1, 1, -1), (1, 1, -1), (1, 1, 1), (-1, 1, 1), (-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1)], dtype=float
) * 3 + (0, 0, 20)
CUBE_IDX = [3, 1, 0, 2, 1, 3, 0, 5, 4, 1, 5, 0, 3, 4, 7, 0, 4, 3, 1, 6, 5, 2, 6, 1, 2, 7, 6, 3, 7, 2, 6, 4, 5, 7, 4, 6]


def scalar(shape: Shape, **kwargs: str) -> np.ndarray:
    out = []
    for d in PIXELS:
        t = shape.intersect(Ray(EYE, d), **kwargs)
        out.append(np.inf if t is None else t)
    return np.array(out)


@pytest.mark.parametrize(
    "shape",
    [
        Sphere((1, -0.5, 30), 4),
        Sphere((0, 0, 0.5), 3),  # the eye is inside: exits
        Plane((0, 1, 0), 2),  # floor y = −2
        Plane((0, 0.6, -0.8), 72),
        AABB((-3, -2, 20), (2, 1, 25)),
        Triangle((30, -40, 60), (60, -120, 0), (0, -120, 0)),
        Triangle((-5, -3, 20), (5, -3, 20), (0, 4, 25)),
    ],
    ids=repr,
)
def test_intersect_many_equals_the_scalar_test_bit_for_bit(shape: Shape) -> None:
    t_many = shape.intersect_many(EYE, PIXELS)
    assert t_many.shape == (len(PIXELS),) and t_many.dtype == np.float64
    kwargs = {"method": "moller_trumbore"} if isinstance(shape, Triangle) else {}
    np.testing.assert_array_equal(t_many, scalar(shape, **kwargs))


def test_some_rays_hit_and_some_miss() -> None:
    t = Sphere((1, -0.5, 30), 4).intersect_many(EYE, PIXELS)
    assert np.isfinite(t).sum() > 10 and np.isinf(t).sum() > 10
    assert np.all(t[np.isfinite(t)] > 0)


def test_triangle_batch_is_a_rays_by_triangles_matrix_and_nearest_matches_the_loop() -> None:
    batch = TriangleBatch.from_indexed(CUBE_VERTS, CUBE_IDX)
    assert len(batch) == 12
    t = batch.intersect_many(EYE, PIXELS)
    assert t.shape == (len(PIXELS), 12)
    triangles = [Triangle(batch.v0[i], batch.v1[i], batch.v2[i], method="moller_trumbore") for i in range(12)]
    for k, d in list(enumerate(PIXELS))[::3]:
        row = [tri.intersect(Ray(EYE, d)) for tri in triangles]
        np.testing.assert_array_equal(t[k], [np.inf if x is None else x for x in row])
    best_t, best_i = batch.nearest_many(EYE, PIXELS, chunk_elements=5 * len(PIXELS))  # three chunks
    loop = [nearest_hit(Ray(EYE, d), triangles) for d in PIXELS[::2]]
    np.testing.assert_array_equal(best_t[::2], [x[0] for x in loop])
    np.testing.assert_array_equal(best_i[::2], [x[1] for x in loop])
    assert (best_i >= 0).sum() > 20 and (best_i == -1).sum() > 20


def test_cube_culling_keeps_the_nearest_face() -> None:
    batch = TriangleBatch.from_indexed(CUBE_VERTS, CUBE_IDX)
    t_all, _ = batch.nearest_many(EYE, PIXELS)
    t_front, _ = batch.nearest_many(EYE, PIXELS, cull_backfaces=True)
    # Whatever winding the index list has, culling one side keeps exactly one
    # face per ray: the near one (front) or the far one (back).
    t_back, _ = TriangleBatch(batch.v0, batch.v2, batch.v1).nearest_many(EYE, PIXELS, cull_backfaces=True)
    hit = np.isfinite(t_all)
    assert np.array_equal(np.isfinite(t_front), hit) and np.array_equal(np.isfinite(t_back), hit)
    near = np.minimum(t_front, t_back)
    np.testing.assert_array_equal(near[hit], t_all[hit])
    assert np.all(np.maximum(t_front, t_back)[hit] > t_all[hit])


def test_nearest_hit_many_over_mixed_shapes_matches_the_course_loop() -> None:
    shapes: list[Shape] = [
        Plane((0, 1, 0), 2),
        Sphere((1, -0.5, 30), 4),
        AABB((-3, -2, 20), (2, 1, 25)),
        Triangle((-5, -3, 18), (5, -3, 18), (0, 4, 26), method="moller_trumbore"),
    ]
    t, idx = nearest_hit_many(EYE, PIXELS, shapes)
    loop = [nearest_hit(Ray(EYE, d), shapes) for d in PIXELS]
    np.testing.assert_array_equal(t, [x[0] for x in loop])
    np.testing.assert_array_equal(idx, [x[1] for x in loop])
    assert set(np.unique(idx)) == {-1, 0, 1, 2, 3}


def test_vectorized_kernels_never_warn_and_broadcast() -> None:
    origins = np.array([[0, 0, 0], [0, 0, 0], [0.25, 0.25, 1], [1, 1, 1]], dtype=float)
    directions = np.array([[0, 0, 0], [1, 0, 0], [0, 0, -1], [-1, -1, -1]], dtype=float)  # zero, parallel, hits
    tris = TriangleBatch(
        [[0, 0, 0], [0, 0, 0], [0, 0, 0]], [[1, 0, 0], [1, 1, 1], [0, 0, 0]], [[0, 1, 0], [2, 2, 2], [0, 0, 0]]
    )
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        t = tris.intersect_many(origins, directions)
        for shape in (Sphere((0, 0, 0), 1), Plane((0, 0, 1), 0), AABB((0, 0, 0), (1, 1, 1))):
            assert shape.intersect_many(origins, directions).shape == (4,)
        one_origin = moller_trumbore_many((0.2, 0.2, 1), directions[1:], tris.v0, tris.v1, tris.v2)
    assert t.shape == (4, 3)
    assert t[2, 0] == 1.0 and np.isinf(t[:, 1:]).all() and np.isinf(t[:2]).all()
    assert one_origin.shape == (3, 3)


def test_mismatched_ray_counts_are_an_error() -> None:
    with pytest.raises(ValueError, match="same length"):
        Sphere((0, 0, 0), 1).intersect_many(np.zeros((3, 3)), np.ones((2, 3)))
    with pytest.raises(ValueError, match="shape"):
        Sphere((0, 0, 0), 1).intersect_many(np.zeros((3, 2)), np.ones((3, 2)))
