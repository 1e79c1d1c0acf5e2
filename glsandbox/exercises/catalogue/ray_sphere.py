"""Işın-Küre kesim testi: where a ray first meets a sphere.

The template of an exercise module: the student's docstring, the reference
(the engine's :class:`~glsandbox.raytrace.sphere.Sphere`, wrapped), the notes'
worked examples, the hard cases, the probe and the named mistakes.
"""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, LessonView, Mistake, Probe
from glsandbox.exercises.fields import grid

DOC = """Işın-Küre kesim testi (ray-sphere intersection), course section "Işın-Küre kesim testi".

The ray starts at `origin` and runs along the unit vector `direction`; the
sphere has `center` C and `radius` r. Return the nearest t > 0 where the ray
meets the sphere, or None when it does not. The notes' geometric test:

    l  = C - R0             (from the ray's origin to the centre)
    s  = l·Rd               (how far along the ray the centre lies)
    m² = l·l - s²           (squared distance from C to the ray)
    m² > r²                 -> no hit
    q  = sqrt(r² - m²)
    outside (l·l > r²):  s < 0 -> no hit (the sphere is behind); else t = s - q
    inside  (l·l <= r²): t = s + q (the ray leaves through the far side)

Solving the quadratic |R0 + t·Rd - C|² = r² for its smallest positive root
is right too.

Worked example (the notes' #4): C = (0, 0, 100), r = 75, R0 = (0, 0, 0),
Rd = (0, 0.6, 0.8): s = 80, m² = 3600, q = 45, t = 35, at the point (0, 21, 28).
"""


def reference(origin, direction, center, radius):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's own test (:meth:`Sphere.intersect`, the numerically stable form)."""
    from glsandbox.raytrace.ray import Ray
    from glsandbox.raytrace.sphere import Sphere

    return Sphere(center, radius).intersect(Ray(origin, direction))


def _reference_many(inputs: list[tuple]) -> list[float | None]:
    """The engine's batch test (:meth:`Sphere.intersect_many`) over a field of one sphere."""
    from glsandbox.raytrace.sphere import Sphere

    origins, directions, centers, radii = zip(*inputs, strict=True)
    if centers.count(centers[0]) != len(centers) or radii.count(radii[0]) != len(radii):
        return [reference(*args) for args in inputs]
    t = Sphere(centers[0], radii[0]).intersect_many(np.array(origins), np.array(directions))
    return [value if math.isfinite(value) else None for value in t.tolist()]


# --- the named mistakes: the course's test with one step wrong -----------------------------


def _parts(origin, direction, center, radius):  # noqa: ANN001, ANN202
    l = [c - o for c, o in zip(center, origin, strict=True)]  # noqa: E741 (the notes' l)
    s = sum(a * b for a, b in zip(l, direction, strict=True))
    l2 = sum(a * a for a in l)
    return l, s, l2, l2 - s * s, radius * radius


def far_root(origin, direction, center, radius):  # noqa: ANN001, ANN201
    """Takes s + q from outside too."""
    _, s, l2, m2, r2 = _parts(origin, direction, center, radius)
    if m2 > r2 or (l2 > r2 and s < 0):
        return None
    t = s + math.sqrt(r2 - m2)
    return t if t > 0 else None


def behind_accepted(origin, direction, center, radius):  # noqa: ANN001, ANN201
    """No s < 0 test and no t > 0 test: spheres behind the origin are hit at a negative t."""
    _, s, l2, m2, r2 = _parts(origin, direction, center, radius)
    if m2 > r2:
        return None
    q = math.sqrt(r2 - m2)
    return s - q if l2 > r2 else s + q


def no_inside(origin, direction, center, radius):  # noqa: ANN001, ANN201
    """Always s - q, even from inside (where it is behind the origin): misses from inside."""
    _, s, _, m2, r2 = _parts(origin, direction, center, radius)
    if m2 > r2 or s < 0:
        return None
    t = s - math.sqrt(r2 - m2)
    return t if t > 0 else None


def l_reversed(origin, direction, center, radius):  # noqa: ANN001, ANN201
    """l = R0 - C: s changes sign."""
    return _with_l(origin, direction, center, radius, -1.0)


def _with_l(origin, direction, center, radius, sign):  # noqa: ANN001, ANN202
    l = [sign * (c - o) for c, o in zip(center, origin, strict=True)]  # noqa: E741
    s = sum(a * b for a, b in zip(l, direction, strict=True))
    l2 = sum(a * a for a in l)
    m2, r2 = l2 - s * s, radius * radius
    if m2 > r2:
        return None
    q = math.sqrt(r2 - m2)
    if l2 > r2:
        if s < 0:
            return None
        t = s - q
    else:
        t = s + q
    return t if t > 0 else None


def reference_geometric(origin, direction, center, radius):  # noqa: ANN001, ANN201
    """The notes' geometric test, step by step (a correct variant the tests pass through)."""
    return _with_l(origin, direction, center, radius, 1.0)


MISTAKES = (
    Mistake("far_root", "your function returns the far intersection: the notes take s - q when the origin is "
            "outside the sphere (l·l > r²), and s + q only from inside.", far_root),
    Mistake("behind_accepted", "your function reports spheres behind the ray's origin: from outside, s < 0 means "
            "the sphere is behind (no hit), and only t > 0 is a hit.", behind_accepted),
    Mistake("no_inside", "your function finds no hit from inside the sphere: when l·l <= r² the ray leaves "
            "through the far side, t = s + q.", no_inside),
    Mistake("l_reversed", "your l points the wrong way: l = C - R0 (from the origin to the centre); with "
            "R0 - C the sign of s flips, so spheres in front are missed and those behind are hit.", l_reversed),
)


# --- the cases ----------------------------------------------------------------------------

ORIGIN = (0.0, 0.0, 0.0)

VISIBLE = (
    Case("the notes' #4: C (0,0,100), r 75, Rd (0,0.6,0.8)", (ORIGIN, (0.0, 0.6, 0.8), (0.0, 0.0, 100.0), 75.0),
         35.0),
    Case("2013 exam #8: the red sphere, Rd (0.96,0.28,0)", (ORIGIN, (0.96, 0.28, 0.0), (80.0, 15.0, 0.0), 10.0),
         75.0),
    Case("2013 exam #8: the reflected ray meets the blue sphere", ((72.0, 21.0, 0.0), (0.0, 1.0, 0.0),
                                                                   (72.0, 121.0, 0.0), 35.0), 65.0),
    Case("2013 exam #9: the shadow ray meets the blue sphere", ((72.0, 21.0, 0.0), (0.28, 0.96, 0.0),
                                                                (72.0, 121.0, 0.0), 35.0), 75.0),
)


def hidden() -> list[Case]:
    """The hard cases: from inside, behind, tangent, on the surface, far away and tiny."""
    c, r = (0.0, 0.0, 100.0), 75.0
    d = (0.0, 0.6, 0.8)
    far = 1e5
    return [
        Case("from the centre: t = r", (c, d, c, r), 75.0, group="inside"),
        Case("from inside, off centre: the far side", ((0.0, 0.0, 90.0), (0.0, 0.0, 1.0), c, r), 85.0,
             group="inside"),
        Case("the sphere behind the origin", (ORIGIN, (0.0, 0.0, -1.0), c, r), None, group="behind"),
        Case("past the sphere, looking away", ((0.0, 0.0, 200.0), (0.0, 0.0, 1.0), c, r), None, group="behind"),
        Case("a clear miss beside it", (ORIGIN, (0.0, 1.0, 0.0), c, r), None, group="behind"),
        Case("tangent: m² = r²", ((75.0, 0.0, 0.0), (0.0, 0.0, 1.0), c, r), 100.0, also=(None,),
             margin="a tangent ray is on the decision m² = r²: a hit at t = 100 or none are both right",
             group="edge"),
        Case("on the surface, going in: the chord", ((0.0, 21.0, 28.0), (0.0, -0.28, 0.96), c, r), 150.0,
             rel=1e-9, group="surface"),
        Case("on the surface, going out: no hit (or t ≈ 0)", ((0.0, 21.0, 28.0), (0.0, 0.28, -0.96), c, r), None,
             abs=1e-9, also=(0.0,), margin="the origin is on the sphere: t = 0 up to rounding, or none",
             group="surface"),
        Case("far from the world's origin (1e5)", ((far, far, far), d, (far, far, far + 100.0), r), 35.0,
             rel=1e-9, group="scale"),
        Case("a tiny scene (1e-4)", (ORIGIN, d, (0.0, 0.0, 1e-2), 7.5e-3), 3.5e-3, rel=1e-9, abs=1e-15,
             group="scale"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """Rays to the right (+x) from every point of the plane z = 0 around the unit sphere."""
    return [((float(u), float(v), 0.0), (1.0, 0.0, 0.0), ORIGIN, 1.0) for u, v in grid(n, -2.0, 2.0).tolist()]


def _lesson_scene():  # noqa: ANN202
    from glsandbox.exercises.lesson_view import sphere_scene

    return sphere_scene()


EXERCISE = Exercise(
    name="ray_sphere", function="intersect_sphere", params=("origin", "direction", "center", "radius"),
    section="Işın-Küre kesim testi", term="ışın-küre kesimi",
    summary="nearest t > 0 where a ray meets a sphere, or None",
    doc=DOC, example="intersect_sphere((0, 0, 0), (0, 0.6, 0.8), (0, 0, 100), 75) == 35.0",
    returns="t", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("rays along +x from each point of the plane z = 0, unit sphere at the centre", _probe_inputs,
                _reference_many, shade=lambda t: 1.0 - t / 4.0),
    mistakes=MISTAKES,
    lesson=LessonView("the course's sphere scene, the sphere traced by your function", _lesson_scene, "sphere"),
    extra={"variants": {"geometric": reference_geometric}},
)
