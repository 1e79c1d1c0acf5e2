"""Işın-Üçgen kesim testi: the ray against the triangle's plane, then an inside test."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, LessonView, Mistake, Probe
from glsandbox.exercises.fields import grid
from glsandbox.exercises.plain import cross, dot, sub

DOC = """Işın-Üçgen kesimi (ray-triangle intersection), course section "Işın-Üçgen kesim testi".

Two steps, as the notes do it:
1. the plane of the triangle: N = (V1 - V0) x (V2 - V0), d = -(N·V0),
   t = -(N·R0 + d)/(N·Rd); no hit when N·Rd = 0 (parallel) or t <= 0;
2. is the point R = R0 + t·Rd inside the triangle? Any of the notes' four
   tests is right: (I) the three sub-triangles' areas add up to the
   triangle's, (II) R is on the inner side of each edge, (III) R = V0 + u·e0
   + v·e1 with u, v >= 0 and u + v <= 1 from dot products, (IV) the same u, v
   as ratios of areas. (Möller-Trumbore, the two steps in one, is right too.)
Return the t > 0 of the hit, or None. Both sides of the triangle count.

Worked example (the notes' #3): the triangle V0 = (30, -40, 60),
V1 = (60, -120, 0), V2 = (0, -120, 0) and the ray R0 = (0, 0, 0),
Rd = (0, 0, 1): the plane is hit at t = 90, the point (0, 0, 90), which is
outside the triangle: None.
"""


def reference(origin, direction, v0, v1, v2):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :meth:`Triangle.intersect` (the watertight test; both sides)."""
    from glsandbox.raytrace.ray import Ray
    from glsandbox.raytrace.triangle import Triangle

    return Triangle(v0, v1, v2).intersect(Ray(origin, direction))


def _engine(method: str):  # noqa: ANN202
    def intersect_triangle(origin, direction, v0, v1, v2):  # noqa: ANN001, ANN202
        from glsandbox.raytrace.ray import Ray
        from glsandbox.raytrace.triangle import Triangle

        return Triangle(v0, v1, v2).intersect(Ray(origin, direction), method=method)

    return intersect_triangle


def _reference_many(inputs: list[tuple]) -> list:
    from glsandbox.raytrace.triangle import Triangle

    (_, _, v0, v1, v2) = inputs[0]
    o = np.array([i[0] for i in inputs], dtype=np.float64)
    d = np.array([i[1] for i in inputs], dtype=np.float64)
    t = Triangle(v0, v1, v2).intersect_many(o, d).tolist()
    return [v if math.isfinite(v) else None for v in t]


# --- the named mistakes: the plane, then a same-side test with one thing wrong ------------------








def _plane_then(origin, direction, v0, v1, v2, *, inside=True, behind=False, cull=False,  # noqa: ANN001, ANN202
                edges=((0, 1), (1, 2), (2, 0))):
    n = cross(sub(v1, v0), sub(v2, v0))
    den = dot(n, direction)
    if den == 0 or (cull and den > 0):
        return None
    t = dot(n, sub(v0, origin)) / den
    if t <= 0 and not behind:
        return None
    p = [o + t * d for o, d in zip(origin, direction, strict=True)]
    vs = (v0, v1, v2)
    if inside and any(dot(cross(sub(vs[j], vs[i]), sub(p, vs[i])), n) < 0 for i, j in edges):
        return None
    return t if t != 0 else None


def plane_only(origin, direction, v0, v1, v2):  # noqa: ANN001, ANN201
    return _plane_then(origin, direction, v0, v1, v2, inside=False)


def behind_accepted(origin, direction, v0, v1, v2):  # noqa: ANN001, ANN201
    return _plane_then(origin, direction, v0, v1, v2, behind=True)


def one_sided(origin, direction, v0, v1, v2):  # noqa: ANN001, ANN201
    return _plane_then(origin, direction, v0, v1, v2, cull=True)


def edge_reversed(origin, direction, v0, v1, v2):  # noqa: ANN001, ANN201
    return _plane_then(origin, direction, v0, v1, v2, edges=((0, 1), (2, 1), (2, 0)))


MISTAKES = (
    Mistake("plane_only", "your function returns the plane's t even when the point is outside the triangle: "
            "after the plane, test whether R0 + t·Rd is inside (any of the notes' four tests).", plane_only),
    Mistake("behind_accepted", "your function hits triangles behind the ray's origin: the plane's t must be "
            "> 0 before the inside test counts.", behind_accepted),
    Mistake("one_sided", "your function misses triangles seen from their back: a ray hits both sides here "
            "(back-face culling is a separate step, only for closed shapes).", one_sided),
    Mistake("edge_reversed", "one of your edges runs the wrong way round: the inside test walks V0 -> V1 -> V2 "
            "-> V0, each edge from its start to its end.", edge_reversed),
)

V0, V1, V2 = (30.0, -40.0, 60.0), (60.0, -120.0, 0.0), (0.0, -120.0, 0.0)
CENTROID = tuple((a + b + c) / 3.0 for a, b, c in zip(V0, V1, V2, strict=True))
ORIGIN = (0.0, 0.0, 0.0)

VISIBLE = (
    Case("the notes' #3: the plane at t = 90, outside the triangle", (ORIGIN, (0.0, 0.0, 1.0), V0, V1, V2), None),
    Case("the ray through the notes' triangle's centre (Rd = the centre): t = 1",
         (ORIGIN, CENTROID, V0, V1, V2), 1.0),
)


def _moved(points: tuple, by: float = 0.0, times: float = 1.0) -> tuple:
    return tuple(tuple(x * times + by for x in p) for p in points)


def hidden() -> list[Case]:
    """Edges and vertices (either answer), degenerate and parallel, behind, the back side, far, tiny."""
    far = 1e5
    edge_middle = tuple((b + c) / 2.0 for b, c in zip(V1, V2, strict=True))
    on = "exactly on the triangle's boundary: the reference is within its rounding of the decision"
    back = tuple(2.0 * c for c in CENTROID)
    return [
        Case("through the middle of the edge V1-V2", (ORIGIN, edge_middle, V0, V1, V2), 1.0, also=(None,),
             margin=on, group="boundary"),
        Case("through the vertex V0", (ORIGIN, V0, V0, V1, V2), 1.0, also=(None,), margin=on, group="boundary"),
        Case("just inside the edge V1-V2", (ORIGIN, tuple(0.999 * m + 0.001 * c for m, c in
                                                          zip(edge_middle, CENTROID, strict=True)), V0, V1, V2),
             1.0, rel=1e-9, group="boundary"),
        Case("just outside the edge V1-V2", (ORIGIN, tuple(1.001 * m - 0.001 * c for m, c in
                                                           zip(edge_middle, CENTROID, strict=True)), V0, V1, V2),
             None, group="boundary"),
        Case("a degenerate triangle (three points on a line)", (ORIGIN, (0.0, 0.0, 1.0), (0.0, 0.0, 5.0),
                                                                 (1.0, 1.0, 5.0), (2.0, 2.0, 5.0)), None,
             group="degenerate"),
        Case("a ray in the triangle's plane", (V0, tuple(b - a for a, b in zip(V0, V1, strict=True)), V0, V1, V2),
             None, group="degenerate"),
        Case("the triangle behind the origin", (ORIGIN, tuple(-c for c in CENTROID), V0, V1, V2), None,
             group="behind"),
        Case("from the back side", (back, tuple(-c for c in CENTROID), V0, V1, V2), 1.0, rel=1e-9,
             group="back"),
        Case("far from the world's origin (1e5)", (*_moved((ORIGIN,), far), CENTROID, *_moved((V0, V1, V2), far)),
             1.0, rel=1e-9, group="scale"),
        Case("a tiny scene (1e-4)", (ORIGIN, *_moved((CENTROID, V0, V1, V2), times=1e-4)), 1.0, rel=1e-9,
             group="scale"),
    ]


#: The probe's triangle: tilted (its plane is z = x/2), seen from its back along +z.
PROBE_TRIANGLE = ((-1.5, -1.23, -0.75), (1.5, -1.23, 0.75), (0.13, 1.47, 0.065))


def _probe_inputs(n: int) -> list[tuple]:
    return [((float(u), float(v), 0.0), (0.0, 0.0, 1.0), *PROBE_TRIANGLE) for u, v in grid(n, -2.0, 2.0).tolist()]


def _lesson_scene():  # noqa: ANN202
    from glsandbox.exercises.lesson_view import triangle_scene

    return triangle_scene()


EXERCISE = Exercise(
    name="ray_triangle", function="intersect_triangle", params=("origin", "direction", "v0", "v1", "v2"),
    section="Işın-Üçgen kesim testi", term="ışın-üçgen kesimi, içerde mi testi",
    summary="nearest t > 0 where a ray meets a triangle (either side), or None",
    doc=DOC, example="intersect_triangle((0, 0, 0), (0, 0, 1), (30, -40, 60), (60, -120, 0), (0, -120, 0)) is None",
    returns="t", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("rays along +z from each point of the plane z = 0 towards a triangle tilted through it "
                "(its left half behind the rays' origins, its back facing them)", _probe_inputs,
                _reference_many, shade=lambda t: 0.5 + t),
    mistakes=MISTAKES,
    lesson=LessonView("the course's cube, its triangles traced by your function", _lesson_scene, "triangles"),
    extra={"variants": {name: _engine(name) for name in
                        ("area_sum", "edge_distance", "dot_barycentric", "area_ratio", "moller_trumbore")}},
    order=40,
)
