"""Işın-Üçgen kesim testi: the six tests, shared edges, tiny, needle and degenerate triangles."""

from __future__ import annotations

import warnings
from collections.abc import Iterator

import numpy as np
import pytest

from glsandbox.raytrace import (
    INSIDE_TESTS,
    POINT_IN_TRIANGLE,
    Ray,
    RayTraceError,
    Triangle,
    TriangleBatch,
    nearest_hit,
)

METHODS = sorted(INSIDE_TESTS)


@pytest.fixture
def strict_floats() -> Iterator[None]:
    """Any numpy floating-point problem or any warning becomes an error."""
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def test_registry_names_are_the_course_four_plus_two() -> None:
    assert set(INSIDE_TESTS) == {
        "area_sum",
        "edge_distance",
        "dot_barycentric",
        "area_ratio",
        "moller_trumbore",
        "watertight",
    }
    assert set(POINT_IN_TRIANGLE) == {"area_sum", "edge_distance", "dot_barycentric", "area_ratio"}


def test_unknown_method_is_a_value_error_naming_it() -> None:
    tri = Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0))
    with pytest.raises(ValueError, match="barycentrik"):
        tri.intersect(Ray((0, 0, 1), (0, 0, -1)), method="barycentrik")
    with pytest.raises(RayTraceError):
        Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0), method="nope")


@pytest.mark.parametrize("method", METHODS)
def test_simple_hit_and_miss(method: str) -> None:
    tri = Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0))
    assert tri.intersect(Ray((0.25, 0.25, 2), (0, 0, -1)), method=method) == pytest.approx(2.0, abs=1e-12)
    assert tri.intersect(Ray((0.25, 0.25, 2), (0, 0, -0.5)), method=method) == pytest.approx(4.0, abs=1e-12)
    assert tri.intersect(Ray((0.75, 0.75, 2), (0, 0, -1)), method=method) is None  # beyond the hypotenuse
    assert tri.intersect(Ray((-0.1, 0.25, 2), (0, 0, -1)), method=method) is None
    assert tri.intersect(Ray((0.25, 0.25, 2), (0, 0, 1)), method=method) is None  # behind
    assert tri.intersect(Ray((0.25, 0.25, 2), (1, 0, 0)), method=method) is None  # parallel to the plane


# --- backface culling ---------------------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_backface_culling(method: str) -> None:
    tri = Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0))  # N = (0, 0, 1)
    towards_front = Ray((0.2, 0.3, 5), (0.01, 0.02, -1))  # N·Rd < 0: front face
    towards_back = Ray((0.2, 0.3, -5), (0.01, 0.02, 1))  # N·Rd > 0: back face
    assert tri.intersect(towards_front, method=method, cull_backfaces=True) is not None
    assert tri.intersect(towards_back, method=method, cull_backfaces=False) is not None
    assert tri.intersect(towards_back, method=method, cull_backfaces=True) is None
    swapped = Triangle(tri.v0, tri.v2, tri.v1)  # bir köşeyi değiştir: the winding flips
    assert swapped.intersect(towards_front, method=method, cull_backfaces=True) is None
    assert swapped.intersect(towards_back, method=method, cull_backfaces=True) is not None


def test_culling_as_a_triangle_default_is_honoured_by_nearest_hit() -> None:
    culled = Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0), cull_backfaces=True)
    behind = Triangle((0, 0, -1), (1, 0, -1), (0, 1, -1))
    ray = Ray((0.2, 0.3, -5), (0, 0, 1))
    t, index = nearest_hit(ray, [culled, behind])
    assert index == 1 and t == pytest.approx(4.0)
    assert culled.intersect_many(ray.origin, ray.direction)[0] == np.inf
    assert culled.intersect_many(ray.origin, ray.direction, cull_backfaces=False)[0] == pytest.approx(5.0)


# --- barycentric uv and texture coordinates ------------------------------------------


def test_barycentric_roundtrip_t_of_u_v() -> None:
    tri = Triangle((1, 2, 3), (4, -1, 2), (0, 5, -2))
    for u, v in [(0.2, 0.3), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (0.5, 0.5), (-0.5, 2.0)]:
        p = tri.v0 + u * (tri.v1 - tri.v0) + v * (tri.v2 - tri.v0)  # t(u,v) = V0 + u(V1−V0) + v(V2−V0)
        assert tri.barycentric(p) == pytest.approx((u, v), abs=1e-12)


def test_texture_coordinates_are_interpolated_with_the_barycentrics() -> None:
    uvs = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
    tri = Triangle((1, 2, 3), (4, -1, 2), (0, 5, -2), uvs=uvs)
    p = tri.v0 + 0.25 * tri.e1 + 0.5 * tri.e2
    np.testing.assert_allclose(tri.uv_at(p), (0.25, 0.5), atol=1e-12)
    mapped = Triangle(tri.v0, tri.v1, tri.v2, uvs=[(0.5, 0.5), (0.9, 0.1), (0.1, 0.7)])
    for vertex, uv in zip((mapped.v0, mapped.v1, mapped.v2), mapped.uvs, strict=True):  # type: ignore[arg-type]
        np.testing.assert_allclose(mapped.uv_at(vertex), uv, atol=1e-12)
    np.testing.assert_allclose(mapped.uv_at((mapped.v0 + mapped.v1 + mapped.v2) / 3), (0.5, 0.4333333333333333))
    with pytest.raises(ValueError, match="uvs"):
        Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0)).uv_at((0.1, 0.1, 0))


def test_hit_point_barycentrics_via_a_ray() -> None:
    tri = Triangle((0, 0, 0), (2, 0, 0), (0, 4, 0), uvs=[(0, 0), (1, 0), (0, 1)])
    ray = Ray((0.5, 1.0, 3.0), (0, 0, -1))
    t = tri.intersect(ray)
    assert t is not None
    np.testing.assert_allclose(tri.uv_at(ray.at(t)), (0.25, 0.25), atol=1e-12)


# --- degenerate triangles: rejected, silently -----------------------------------------

DEGENERATE = [
    ((0, 0, 0), (1, 1, 1), (2, 2, 2)),  # collinear
    ((1, 2, 3), (1, 2, 3), (4, 5, 6)),  # two equal vertices
    ((1, 2, 3), (1, 2, 3), (1, 2, 3)),  # a point
    ((0, 0, 0), (0.1, 0.2, 0.3), (0.3, 0.6, 0.9)),  # collinear up to rounding
]


@pytest.mark.parametrize("vertices", DEGENERATE)
@pytest.mark.parametrize("method", METHODS)
def test_degenerate_triangles_are_rejected_without_warnings(
    vertices: tuple[tuple[float, ...], ...], method: str, strict_floats: None
) -> None:
    tri = Triangle(*vertices)
    assert tri.is_degenerate
    mid = np.mean(np.asarray(vertices, dtype=float), axis=0)
    for origin in [(5.0, -3.0, 1.0), (0.0, 0.0, -7.0), tuple(mid + (0, 0, 1))]:
        ray = Ray(origin, mid - np.asarray(origin))
        assert tri.intersect(ray, method=method) is None
        assert tri.intersect(ray, method=method, cull_backfaces=True) is None
    along_line = Ray(np.asarray(vertices[0]) - (1, 1, 1), (1, 1, 1))
    assert tri.intersect(along_line, method=method) is None


def test_degenerate_triangles_vectorized_and_point_tests_without_warnings(strict_floats: None) -> None:
    good = Triangle((0, 0, 0), (1, 0, 0), (0, 1, 0))
    batch = TriangleBatch.from_triangles([Triangle(*v) for v in DEGENERATE] + [good])
    origins = np.array([[0.2, 0.2, 1.0], [5.0, 5.0, 5.0], [1.0, 2.0, 10.0]])
    directions = np.array([[0.0, 0.0, -1.0], [-1.0, -1.0, -1.0], [0.0, 0.0, -1.0]])
    t = batch.intersect_many(origins, directions)
    assert t.shape == (3, 5)
    assert np.all(t[:, :4] == np.inf)
    assert t[0, 4] == pytest.approx(1.0)
    for vertices in DEGENERATE:
        tri = Triangle(*vertices)
        assert not any(tri.contains(vertices[0], m) for m in POINT_IN_TRIANGLE)
        with pytest.raises(ValueError):
            tri.barycentric(vertices[0])


# --- tiny and needle triangles ------------------------------------------------------------


@pytest.mark.parametrize("base", [(1.0, 2.0, 3.0), (1e3, -2e3, 5e2), (-3e4, 1e4, 2e4)])
@pytest.mark.parametrize("method", METHODS)
def test_tiny_triangles_1e_6_are_hit_inside_and_missed_outside(base: tuple[float, float, float], method: str) -> None:
    rng = np.random.default_rng(11)
    a = np.asarray(base)
    tri = Triangle(a, a + rng.normal(size=3) * 1e-6, a + rng.normal(size=3) * 1e-6)
    assert not tri.is_degenerate
    origin = np.zeros(3)
    for u, v in [(0.3, 0.3), (0.1, 0.8), (0.8, 0.1), (0.05, 0.05)]:
        p = tri.v0 + u * tri.e1 + v * tri.e2
        t = tri.intersect(Ray(origin, p), method=method)  # the target sits at t = 1
        assert t == pytest.approx(1.0, rel=1e-12)
    for u, v in [(-0.1, 0.3), (0.3, -0.1), (0.6, 0.6), (2.0, 2.0)]:
        p = tri.v0 + u * tri.e1 + v * tri.e2
        assert tri.intersect(Ray(origin, p), method=method) is None


@pytest.mark.parametrize("aspect", [1e-4, 1e-7])
@pytest.mark.parametrize("method", METHODS)
def test_needle_triangles(aspect: float, method: str) -> None:
    tri = Triangle((0, 0, 0), (1, 0, 0), (0.5, aspect, 0))
    for u, v in [(0.3, 0.3), (0.1, 0.8), (0.6, 0.2)]:
        p = tri.v0 + u * tri.e1 + v * tri.e2
        origin = p + np.array([0.1, 0.2, 1.0])
        assert tri.intersect(Ray(origin, p - origin), method=method) == pytest.approx(1.0, rel=1e-12)
    outside = np.array([0.5, -aspect, 0.0])  # just below the long edge, at the needle's width
    assert tri.intersect(Ray(outside + (0, 0, 1), (0, 0, -1)), method=method) is None


@pytest.mark.parametrize("method", ["area_sum", "edge_distance", "area_ratio", "moller_trumbore", "watertight"])
def test_extreme_needle_1e_12_is_still_hit_by_the_cross_product_tests(method: str) -> None:
    # Yöntem III (dot-product barycentrics) divides by d00·d11 − d01², which
    # cancels to noise for a needle this thin; the cross-product forms do not.
    tri = Triangle((0, 0, 0), (1, 0, 0), (0.5, 1e-12, 0))
    assert not tri.is_degenerate
    p = tri.v0 + 0.3 * tri.e1 + 0.3 * tri.e2
    assert tri.intersect(Ray(p + (0, 0, 1), (0, 0, -1)), method=method) == pytest.approx(1.0)


# --- watertightness: shared edges and shared vertices from far away --------------------


def _shared_edge_rays(seed: int, count: int) -> Iterator[tuple[Triangle, Triangle, Ray]]:
    """Random hinges A-B with C, D on either side, rays aimed at a point of A-B.

    Origins are 1e3..1e5 from the world origin. Only rays that see both
    triangles from the same side (both front or both back, not grazing) are
    kept: for those the edge is inside the projected quad, so a correct test
    must hit at least one of the two triangles.
    """
    rng = np.random.default_rng(seed)
    made = 0
    while made < count:
        a, b, c, d = rng.uniform(-10, 10, size=(4, 3))
        t1, t2 = Triangle(a, b, c), Triangle(b, a, d)  # consistent winding across A-B
        p = a + rng.uniform() * (b - a)
        direction = rng.normal(size=3)
        origin = p - direction / np.linalg.norm(direction) * 10 ** rng.uniform(3, 5)
        ray = Ray(origin, p - origin)
        unit = ray.direction / np.linalg.norm(ray.direction)
        c1, c2 = float(t1.normal @ unit), float(t2.normal @ unit)
        if c1 * c2 <= 0 or min(abs(c1), abs(c2)) < 0.05:
            continue
        made += 1
        yield t1, t2, ray


def test_watertight_never_misses_both_triangles_of_a_shared_edge() -> None:
    misses = [
        ray
        for t1, t2, ray in _shared_edge_rays(seed=1, count=2000)
        if t1.intersect(ray, method="watertight") is None and t2.intersect(ray, method="watertight") is None
    ]
    assert misses == []


def test_watertight_shared_edge_with_culling_keeps_the_front_pair() -> None:
    misses = 0
    for t1, t2, ray in _shared_edge_rays(seed=2, count=500):
        if float(t1.n @ ray.direction) >= 0:  # back-facing pair: both culled, nothing to check
            continue
        h1 = t1.intersect(ray, method="watertight", cull_backfaces=True)
        h2 = t2.intersect(ray, method="watertight", cull_backfaces=True)
        misses += h1 is None and h2 is None
    assert misses == 0


def test_the_shared_edge_sample_is_hard_enough_to_catch_moller_trumbore() -> None:
    # Control for the test above: plain Möller-Trumbore (no epsilon) lets
    # some of the very same rays slip between the two triangles.
    misses = sum(
        t1.intersect(ray, method="moller_trumbore") is None and t2.intersect(ray, method="moller_trumbore") is None
        for t1, t2, ray in _shared_edge_rays(seed=1, count=600)
    )
    assert misses > 0


def test_watertight_fan_around_a_shared_vertex() -> None:
    # Eight triangles around a centre vertex (a slightly bumpy disc); rays from
    # far away, within about 45° of the disc's normal, aimed exactly at the
    # vertex or at points of the spokes, must hit at least one.
    rng = np.random.default_rng(5)
    for _ in range(60):
        centre = rng.uniform(-5, 5, size=3)
        frame = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        angles = (np.arange(8) + rng.uniform(-0.4, 0.4, 8)) * (2 * np.pi / 8)  # gaps well below π
        rim = [centre + frame @ np.array([np.cos(a), np.sin(a), rng.uniform(-0.1, 0.1)]) * 3 for a in angles]
        fan = [Triangle(centre, rim[i], rim[(i + 1) % 8]) for i in range(8)]
        normal = frame[:, 2]
        for target in [centre] + [centre + rng.uniform() * (r - centre) for r in rim]:
            side = 1 if rng.uniform() < 0.5 else -1
            offset = normal * side + rng.normal(size=3) * 0.3  # never near edge-on
            origin = target + offset / np.linalg.norm(offset) * 10 ** rng.uniform(3, 5)
            ray = Ray(origin, target - origin)
            assert any(tri.intersect(ray, method="watertight") is not None for tri in fan)


def test_watertight_edge_function_rounding_to_zero_is_decided_exactly() -> None:
    # Seen along +z from (0, 0, −1), the shared edge B-C passes ε²/(2√2) from
    # the ray (ε = 2⁻⁵²). In float64 its edge function C.x·B.y − C.y·B.x rounds
    # to exactly 0 (−(1 + 2ε + ε²) becomes −(1 + 2ε)); the exact value is −ε².
    # With zeros counted inside, both triangles would report a hit; the exact
    # fall-back puts the ray on D's side only, and never on neither side.
    eps = 2.0**-52
    b, c = (-1.0, -1.0 - eps, 0.0), (1.0 + eps, 1.0 + 2 * eps, 0.0)
    assert c[0] * b[1] - c[1] * b[0] == 0.0
    a, d = (1.0, -1.0, 0.0), (-1.0, 1.0, 0.0)
    t1, t2 = Triangle(b, c, a), Triangle(c, b, d)
    assert not t1.is_degenerate and not t2.is_degenerate
    ray = Ray((0.0, 0.0, -1.0), (0.0, 0.0, 1.0))
    assert t1.intersect(ray, method="watertight") is None
    assert t2.intersect(ray, method="watertight") == 1.0
    # and a ray exactly through a shared edge (exact zero) hits both: not a crack
    quad_a, quad_b = Triangle((0, 0, 0), (1, 0, 0), (1, 1, 0)), Triangle((0, 0, 0), (1, 1, 0), (0, 1, 0))
    diagonal = Ray((0.5, 0.5, 1.0), (0.0, 0.0, -1.0))
    assert quad_a.intersect(diagonal, method="watertight") == quad_b.intersect(diagonal, method="watertight") == 1.0


def test_watertight_t_matches_moller_trumbore_off_the_edges() -> None:
    rng = np.random.default_rng(9)
    for _ in range(200):
        a, b, c = rng.uniform(-10, 10, size=(3, 3))
        tri = Triangle(a, b, c)
        p = a + 0.3 * (b - a) + 0.3 * (c - a)
        origin = p + rng.normal(size=3) * 20
        ray = Ray(origin, p - origin)
        tw = tri.intersect(ray, method="watertight")
        tm = tri.intersect(ray, method="moller_trumbore")
        assert tw is not None and tm is not None
        assert tw == pytest.approx(tm, rel=1e-9) and tw == pytest.approx(1.0, rel=1e-9)
