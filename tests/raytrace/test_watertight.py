"""The watertight test on many (ray, triangle) pairs (glsandbox/raytrace/watertight.py): the same
float64 arithmetic as the scalar test, so the same ``t`` bit for bit; no ray slips between two
triangles that share an edge; back faces skipped with culling; triangles without area never hit
(Woop, Benthin & Wald 2013; the course's "Işın-Üçgen kesim testi").

Also the scan's probe (:func:`glsandbox.raytrace.aimed_rays`): rays aimed at the vertices and edges of
a closed mesh from inside it, and the two vectorised scans the report and ``ray_triangle`` time."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from glsandbox.raytrace import aimed_rays, nearest_by
from glsandbox.raytrace.ray import Ray
from glsandbox.raytrace.triangle import Triangle
from glsandbox.raytrace.watertight import nearest_watertight, nondegenerate


# A unit quad in the plane z = 0 as two triangles sharing the diagonal (0,0)-(1,1), both facing +z.
QUAD = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
                 [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]])
V0, V1, V2 = QUAD[:, 0], QUAD[:, 1], QUAD[:, 2]


def test_a_ray_straight_down_onto_the_quad_meets_it_at_its_distance() -> None:
    t, index = nearest_watertight(V0, V1, V2, [[0.75, 0.25, 5.0], [0.25, 0.75, 2.0]], [[0.0, 0.0, -1.0]] * 2)
    assert t.tolist() == [5.0, 2.0] and index.tolist() == [0, 1]


def test_rays_through_the_shared_diagonal_never_slip_between_the_two_triangles() -> None:
    # Each ray aimed exactly at a point p = (s, s, 0) of the diagonal, slanted so that the edge
    # functions round (origin = p - 3 d).
    s = np.linspace(0.0, 1.0, 257)[1:-1]
    d = np.array([0.1, 0.3, -1.0])
    p = np.stack([s, s, np.zeros_like(s)], axis=1)
    t, index = nearest_watertight(V0, V1, V2, p - 3.0 * d, np.tile(d, (s.size, 1)))
    assert (index >= 0).all(), f"{(index < 0).sum()} rays slipped through the shared edge"
    assert np.allclose(t, 3.0)


def test_with_culling_a_back_face_is_skipped_and_a_front_face_is_not() -> None:
    up, down = [[0.5, 0.25, -2.0]], [[0.0, 0.0, 1.0]]  # from below: the quad's back
    assert nearest_watertight(V0, V1, V2, up, down)[1].tolist() == [0]
    t, index = nearest_watertight(V0, V1, V2, up, down, cull_backfaces=True)
    assert index.tolist() == [-1] and np.isinf(t).all()


def test_a_triangle_without_area_is_never_hit_and_the_nearer_triangle_wins() -> None:
    flat = np.array([[[0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [2.0, 2.0, 1.0]]])  # three points on a line
    assert nondegenerate(flat[:, 0], flat[:, 1], flat[:, 2]).tolist() == [False]
    assert nondegenerate(V0, V1, V2).tolist() == [True, True]
    raised = QUAD + np.array([0.0, 0.0, 1.0])
    both = np.concatenate([QUAD, raised, flat])
    t, index = nearest_watertight(both[:, 0], both[:, 1], both[:, 2], [[0.75, 0.25, 5.0]], [[0.0, 0.0, -1.0]])
    assert index.tolist() == [2] and t.tolist() == [4.0]  # the raised copy, nearer than the quad


coordinate = st.floats(-10.0, 10.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.lists(coordinate, min_size=15, max_size=15))
def test_each_pairs_t_is_the_scalar_tests_bit_for_bit(values: list[float]) -> None:
    a, b, c, origin, direction = (np.array(values[i:i + 3]) for i in range(0, 15, 3))
    if not np.any(direction):
        direction = np.array([0.0, 0.0, -1.0])
    scalar = Triangle(a, b, c).intersect(Ray(origin, direction), method="watertight")
    t, index = nearest_watertight(a[None], b[None], c[None], origin[None], direction[None])
    if not nondegenerate(a[None], b[None], c[None])[0] or scalar is None:
        assert index.tolist() == [-1] or scalar is not None
        return
    assert index.tolist() == [0] and t[0] == scalar


def test_every_aimed_ray_hits_the_closed_mesh_at_the_point_it_aims_at() -> None:
    tris, origins, directions = aimed_rays((32, 24))
    assert origins.shape == directions.shape == (32 * 24, 3) and tris[0].shape == (80, 3)
    t = nearest_by("watertight", tris, origins, directions)
    assert np.all(np.isfinite(t))  # from inside a closed mesh no ray escapes
    # The point aimed at is on the surface, so the nearest hit is there (t = 1), never beyond it.
    assert np.all(t <= 1.0 + 1e-9) and np.median(t) == pytest.approx(1.0, abs=1e-9)
    # Moller-Trumbore finds the same hits wherever it finds one.
    mt = nearest_by("mt64", tris, origins, directions)
    found = np.isfinite(mt)
    assert found.mean() > 0.9 and np.allclose(mt[found], t[found], rtol=0, atol=1e-9)


def test_the_probe_moves_with_the_mesh_and_unknown_tests_are_refused() -> None:
    (a, _, _), origins, _ = aimed_rays((16, 12))
    (b, _, _), moved, _ = aimed_rays((16, 12), 1e3)
    assert np.allclose(b - a, 1e3 * np.array([0.99, 0.7, -0.4])) and np.allclose(moved - origins, b[0] - a[0])
    with pytest.raises(ValueError, match="unknown triangle test 'mt32'"):
        nearest_by("mt32", *aimed_rays((4, 3)))
