"""The watertight test on many (ray, triangle) pairs (glsandbox/raytrace/watertight.py): the same
float64 arithmetic as the scalar test, so the same ``t`` bit for bit; no ray slips between two
triangles that share an edge; back faces skipped with culling; triangles without area never hit
(Woop, Benthin & Wald 2013; the course's "Işın-Üçgen kesim testi")."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings, strategies as st

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
