"""Property tests (hypothesis): exact power-of-two scaling, double reflection, agreement of the tests."""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from glsandbox.raytrace import (
    AABB,
    INSIDE_TESTS,
    POINT_IN_TRIANGLE,
    Plane,
    Ray,
    Sphere,
    Triangle,
    reflect,
)

# Coordinates: finite, |x| <= 100, and either 0 or |x| >= 1e-3, so scaling by
# 2^±40 never reaches subnormal numbers (where power-of-two scaling stops
# being exact) or overflow.
coord = st.floats(-100, 100, allow_nan=False, allow_infinity=False, allow_subnormal=False).map(
    lambda x: 0.0 if abs(x) < 1e-3 else x
)
vec3 = st.tuples(coord, coord, coord).map(lambda v: np.array(v, dtype=np.float64))
nonzero_vec3 = vec3.filter(lambda v: bool(np.any(v)))
power = st.integers(-40, 40)
#: Where a ray aims across a triangle's edges: the coordinates' rule, so that no direction
#: component is tiny enough to meet subnormal numbers once a product is scaled by 2^-40.
edge_fraction = st.floats(-0.2, 1.2, allow_subnormal=False).map(lambda x: 0.0 if abs(x) < 1e-3 else x)
unit_interval = st.floats(0, 1, allow_nan=False)


def scaled_t(t: float | None, k: int) -> float | None:
    return None if t is None else t * 2.0**k


@settings(max_examples=150, deadline=None)
@given(center=vec3, radius=st.floats(0.01, 50), origin=vec3, aim=vec3, k=power)
def test_scaling_a_sphere_scene_by_a_power_of_two_scales_t_exactly(
    center: np.ndarray, radius: float, origin: np.ndarray, aim: np.ndarray, k: int
) -> None:
    direction = center + aim * (radius / 100) - origin  # aimed near the sphere: plenty of hits
    assume(np.any(direction))
    s = 2.0**k
    ray, ray_scaled = Ray(origin, direction), Ray(origin * s, direction)
    sphere, sphere_scaled = Sphere(center, radius), Sphere(center * s, radius * s)
    for method in ("stable", "geometric"):
        assert sphere_scaled.intersect(ray_scaled, method=method) == scaled_t(sphere.intersect(ray, method=method), k)


@settings(max_examples=150, deadline=None)
@given(normal=nonzero_vec3, point=vec3, origin=vec3, direction=nonzero_vec3, k=power)
def test_scaling_a_plane_scene_by_a_power_of_two_scales_t_exactly(
    normal: np.ndarray, point: np.ndarray, origin: np.ndarray, direction: np.ndarray, k: int
) -> None:
    s = 2.0**k
    plane = Plane.through(normal, point)
    scaled = Plane.through(normal, point * s)
    assert scaled.d == plane.d * s
    assert scaled.intersect(Ray(origin * s, direction)) == scaled_t(plane.intersect(Ray(origin, direction)), k)


@settings(max_examples=150, deadline=None)
@given(
    v=st.tuples(vec3, vec3, vec3),
    origin=vec3,
    u=edge_fraction,
    w=edge_fraction,
    cull=st.booleans(),
    k=power,
)
def test_scaling_a_triangle_scene_by_a_power_of_two_scales_t_exactly_for_all_six_tests(
    v: tuple[np.ndarray, np.ndarray, np.ndarray], origin: np.ndarray, u: float, w: float, cull: bool, k: int
) -> None:
    v0, v1, v2 = v
    direction = v0 + u * (v1 - v0) + w * (v2 - v0) - origin  # aimed at (or just off) the triangle
    assume(np.any(direction))
    s = 2.0**k
    tri, tri_scaled = Triangle(v0, v1, v2), Triangle(v0 * s, v1 * s, v2 * s)
    ray, ray_scaled = Ray(origin, direction), Ray(origin * s, direction)
    for method in INSIDE_TESTS:
        t = tri.intersect(ray, method=method, cull_backfaces=cull)
        assert tri_scaled.intersect(ray_scaled, method=method, cull_backfaces=cull) == scaled_t(t, k), method
    t_many = tri.intersect_many(ray.origin, ray.direction, cull_backfaces=cull)
    t_many_scaled = tri_scaled.intersect_many(ray_scaled.origin, ray_scaled.direction, cull_backfaces=cull)
    assert np.array_equal(t_many_scaled, t_many * s)


@settings(max_examples=150, deadline=None)
@given(a=vec3, b=vec3, origin=vec3, direction=nonzero_vec3, k=power)
def test_scaling_a_box_scene_by_a_power_of_two_scales_t_exactly(
    a: np.ndarray, b: np.ndarray, origin: np.ndarray, direction: np.ndarray, k: int
) -> None:
    s = 2.0**k
    box = AABB(np.minimum(a, b), np.maximum(a, b))
    scaled = AABB(box.min * s, box.max * s)
    assert scaled.intersect(Ray(origin * s, direction)) == scaled_t(box.intersect(Ray(origin, direction)), k)


@settings(max_examples=200, deadline=None)
@given(direction=vec3, normal=nonzero_vec3)
def test_reflecting_twice_returns_the_direction(direction: np.ndarray, normal: np.ndarray) -> None:
    once = reflect(direction, normal)
    twice = reflect(once, normal)
    size = float(np.linalg.norm(direction))
    np.testing.assert_allclose(twice, direction, rtol=0, atol=1e-13 * max(size, 1e-300))
    assert abs(float(np.linalg.norm(once)) - size) <= 1e-13 * size  # a mirror keeps lengths


MARGIN = 0.02


@st.composite
def triangle_and_ray(draw: st.DrawFn) -> tuple[Triangle, Ray, bool]:
    """A well-shaped triangle, a ray aimed at a point with barycentrics >= MARGIN
    (inside) or with one barycentric <= −MARGIN (outside), never grazing."""
    v0, v1, v2 = draw(vec3), draw(vec3), draw(vec3)
    tri = Triangle(v0, v1, v2)
    edges = [v1 - v0, v2 - v1, v0 - v2]
    l_max2 = max(float(e @ e) for e in edges)
    assume(l_max2 > 1e-2 and tri.area >= 0.05 * l_max2)  # no needles here: they have their own tests
    inside = draw(st.booleans())
    if inside:
        b1 = draw(st.floats(MARGIN, 1 - 2 * MARGIN))
        b2 = draw(st.floats(MARGIN, 1 - MARGIN - b1))
        assume(1 - b1 - b2 >= MARGIN)
    else:
        b1 = draw(st.floats(-1.5, 2.5))
        b2 = draw(st.floats(-1.5, 2.5))
        assume(min(b1, b2, 1 - b1 - b2) <= -MARGIN)
    target = v0 + b1 * (v1 - v0) + b2 * (v2 - v0)
    n = tri.normal
    side = draw(st.sampled_from([1.0, -1.0]))
    jitter = draw(vec3) / 100.0
    offset = side * n + jitter - (jitter @ n) * n  # at most ~60° from the normal: never grazing
    distance = draw(st.floats(0.5, 1e3))
    origin = target + offset / np.linalg.norm(offset) * distance
    return tri, Ray(origin, target - origin), inside


@settings(max_examples=200, deadline=None)
@given(case=triangle_and_ray(), cull=st.booleans())
def test_all_six_tests_agree_away_from_the_edges(case: tuple[Triangle, Ray, bool], cull: bool) -> None:
    tri, ray, inside = case
    front = float(tri.n @ ray.direction) < 0
    expect_hit = inside and (front or not cull)
    results = {m: tri.intersect(ray, method=m, cull_backfaces=cull) for m in INSIDE_TESTS}
    for method, t in results.items():
        if expect_hit:
            assert t is not None and abs(t - 1.0) <= 1e-9, (method, t)  # the target sits at t = 1
        else:
            assert t is None, (method, t)
    t_many = tri.intersect_many(ray.origin, ray.direction, cull_backfaces=cull)[0]
    assert bool(t_many == np.inf) is (not expect_hit)
    point = ray.at(1.0)
    assert {m: tri.contains(point, m) for m in POINT_IN_TRIANGLE} == dict.fromkeys(POINT_IN_TRIANGLE, inside)
