"""Correct ways of writing an exercise pass it: the four inside tests and Möller-Trumbore for the
triangle, the geometric and the quadratic roots for the sphere, written as a student would and
compared with the reference on generated rays (hypothesis)."""

from __future__ import annotations

import math

from hypothesis import assume, given, settings
from hypothesis import strategies as st

from glsandbox.exercises import get
from glsandbox.exercises.check import PASS, check_function
from glsandbox.exercises.compare import judge
from glsandbox.exercises.definition import Case


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def length(a):
    return math.sqrt(dot(a, a))


def area(a, b, c):
    return length(cross(sub(b, a), sub(c, a))) / 2


def plane_then(inside):
    def intersect_triangle(origin, direction, v0, v1, v2):
        n = cross(sub(v1, v0), sub(v2, v0))
        den = dot(n, direction)
        if length(n) == 0 or abs(den) < 1e-12 * length(n) * length(direction):  # degenerate, or parallel
            return None
        t = dot(n, sub(v0, origin)) / den
        if t <= 0:
            return None
        p = [o + t * d for o, d in zip(origin, direction)]
        return t if inside(p, v0, v1, v2, n) else None

    return intersect_triangle


def area_sum(p, v0, v1, v2, n):  # I: S1 + S2 + S3 = S
    s = area(v0, v1, v2)
    return area(p, v1, v2) + area(v0, p, v2) + area(v0, v1, p) <= s * (1 + 1e-9)


def edge_sides(p, v0, v1, v2, n):  # II: on the inner side of each edge
    return all(dot(cross(sub(b, a), sub(p, a)), n) >= 0 for a, b in ((v0, v1), (v1, v2), (v2, v0)))


def dot_barycentric(p, v0, v1, v2, n):  # III: R = V0 + u·e0 + v·e1 from dot products
    e0, e1, r = sub(v1, v0), sub(v2, v0), sub(p, v0)
    d00, d01, d11, d20, d21 = dot(e0, e0), dot(e0, e1), dot(e1, e1), dot(r, e0), dot(r, e1)
    den = d00 * d11 - d01 * d01
    u, v = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
    return u >= 0 and v >= 0 and u + v <= 1


def area_ratio(p, v0, v1, v2, n):  # IV: u = S1/S, v = S2/S with signs from the normal
    s = dot(cross(sub(v1, v0), sub(v2, v0)), n)
    u = dot(cross(sub(p, v0), sub(v2, v0)), n) / s
    v = dot(cross(sub(v1, v0), sub(p, v0)), n) / s
    return u >= 0 and v >= 0 and u + v <= 1


def moller_trumbore(origin, direction, v0, v1, v2):
    e1, e2 = sub(v1, v0), sub(v2, v0)
    p = cross(direction, e2)
    det = dot(e1, p)
    if det == 0 or abs(det) < 1e-12 * length(e1) * length(e2) * length(direction):
        return None
    s = sub(origin, v0)
    u = dot(s, p) / det
    q = cross(s, e1)
    v = dot(direction, q) / det
    if u < 0 or v < 0 or u + v > 1:
        return None
    t = dot(e2, q) / det
    return t if t > 0 else None


TRIANGLE_VARIANTS = {"area_sum": plane_then(area_sum), "edge_sides": plane_then(edge_sides),
                     "dot_barycentric": plane_then(dot_barycentric), "area_ratio": plane_then(area_ratio),
                     "moller_trumbore": moller_trumbore}


def geometric(origin, direction, center, radius):
    l = sub(center, origin)  # noqa: E741
    s, l2, r2 = dot(l, direction), dot(l, l), radius * radius
    m2 = l2 - s * s
    if m2 > r2:
        return None
    q = math.sqrt(r2 - m2)
    if l2 > r2:
        return None if s < 0 else s - q
    t = s + q
    return t if t > 0 else None


def quadratic(origin, direction, center, radius):
    oc = sub(origin, center)
    b = dot(oc, direction)
    c = dot(oc, oc) - radius * radius
    disc = b * b - c
    if disc < 0:
        return None
    for t in (-b - math.sqrt(disc), -b + math.sqrt(disc)):
        if t > 0:
            return t
    return None


def test_each_triangle_variant_passes_every_case_and_agrees_on_the_probe() -> None:
    exercise = get("ray_triangle")
    for name, function in TRIANGLE_VARIANTS.items():
        result = check_function(exercise, function, hidden=True, probe_size=64)
        assert all(c.status == PASS for c in result.cases), (name, [c for c in result.cases if not c.passed])
        assert result.probe.agrees and not result.mistakes, name


def test_each_sphere_variant_passes_every_case_and_agrees_on_the_probe() -> None:
    exercise = get("ray_sphere")
    for function in (geometric, quadratic):
        result = check_function(exercise, function, hidden=True, probe_size=64)
        assert all(c.status == PASS for c in result.cases), [c for c in result.cases if not c.passed]
        assert result.probe.agrees and not result.mistakes


coordinate = st.floats(-50, 50, allow_nan=False)
point = st.tuples(coordinate, coordinate, coordinate)


def barycentric_margin(origin, direction, v0, v1, v2) -> float:
    """How far inside (> 0) or outside (< 0) the triangle the ray's plane hit lies, in barycentric units."""
    n = cross(sub(v1, v0), sub(v2, v0))
    t = dot(n, sub(v0, origin)) / dot(n, direction)
    p = [o + t * d for o, d in zip(origin, direction)]
    s = dot(n, n)
    u = dot(cross(sub(p, v0), sub(v2, v0)), n) / s
    v = dot(cross(sub(v1, v0), sub(p, v0)), n) / s
    return min(u, v, 1 - u - v)


@settings(max_examples=150, deadline=None)
@given(v0=point, v1=point, v2=point, origin=point, aim=st.tuples(st.floats(-0.3, 1.3), st.floats(-0.3, 1.3)))
def test_the_triangle_variants_agree_with_the_reference_away_from_edges(v0, v1, v2, origin, aim) -> None:
    n = cross(sub(v1, v0), sub(v2, v0))
    assume(length(n) > 1.0 and min(length(sub(v1, v0)), length(sub(v2, v0)), length(sub(v2, v1))) > 0.5)
    target = [a + aim[0] * (b - a) + aim[1] * (c - a) for a, b, c in zip(v0, v1, v2)]
    direction = sub(target, origin)
    assume(length(direction) > 1.0 and abs(dot(n, direction)) > 1e-3 * length(n) * length(direction))
    assume(abs(barycentric_margin(origin, direction, v0, v1, v2)) > 1e-6)
    reference = get("ray_triangle").reference(origin, direction, v0, v1, v2)
    case = Case("generated", (), None if reference is None else float(reference), rel=1e-7, abs=1e-9)
    for name, function in TRIANGLE_VARIANTS.items():
        assert judge(case, function(origin, direction, v0, v1, v2), "t")[0], name


@settings(max_examples=150, deadline=None)
@given(center=point, radius=st.floats(0.5, 30), origin=point, aim=point)
def test_the_sphere_roots_agree_with_the_reference(center, radius, origin, aim) -> None:
    direction = sub(aim, origin)
    assume(length(direction) > 1e-3)
    direction = [x / length(direction) for x in direction]
    l = sub(center, origin)  # noqa: E741
    m2 = dot(l, l) - dot(l, direction) ** 2
    assume(abs(m2 - radius * radius) > 1e-6 * radius * radius)  # not tangent
    assume(abs(length(l) - radius) > 1e-6 * radius)  # not on the surface
    reference = get("ray_sphere").reference(origin, direction, center, radius)
    case = Case("generated", (), None if reference is None else float(reference), rel=1e-6, abs=1e-6)
    for function in (geometric, quadratic):
        assert judge(case, function(origin, direction, center, radius), "t")[0], function.__name__
