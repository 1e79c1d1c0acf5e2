"""Gölge testi: is anything between a point and the light?"""

from __future__ import annotations

import math

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import grid
from glsandbox.exercises.plain import cross, dot, sub

DOC = """Gölge testi (the shadow test), course section "Gölge testi".

From the surface point P, send the shadow ray towards the light L:

    Rd = (L - P) / |L - P|,   distance = |L - P|

P is in shadow when some triangle is hit at 0 < t < distance: between the
point and the light. A hit beyond the light (t > distance) does not shadow.
The point's own triangle is hit at t ≈ 0 by rounding: start the ray a little
off the surface (R0 = P + ε·Rd, ε about 1e-6 times the scene's size) or ask
for t > ε. `triangles` is a list of (v0, v1, v2). Return True (in shadow) or
False (lit).

Worked examples: the 2013 exam (#9): P = (72, 21, 0), L = (100, 117, 0),
distance 100, Rd = (0.28, 0.96, 0); the blue sphere is hit at t = 75 < 100:
in shadow. The 2012 exam (#10): P = (0, -8, -5), L = (0, 10, -29),
distance 30; the plane is crossed at t = 40 > 30, beyond the light: lit
(the notes say "in shadow" there: that is the erratum; their own 2013 rule
gives lit).
"""


def reference(point, light, triangles):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.raytrace.trace.in_shadow` over :class:`Triangle` shapes."""
    from glsandbox.raytrace.trace import in_shadow
    from glsandbox.raytrace.triangle import Triangle

    return in_shadow(point, light, [Triangle(*t) for t in triangles])


def _reference_many(inputs: list[tuple]) -> list[bool]:
    """:func:`reference` over a field whose inputs share one list of triangles: its
    :class:`Triangle` objects made once."""
    from glsandbox.raytrace.trace import in_shadow
    from glsandbox.raytrace.triangle import Triangle

    made: dict[int, list] = {}
    out = []
    for point, light, triangles in inputs:
        shapes = made.get(id(triangles))
        if shapes is None:
            shapes = made[id(triangles)] = [Triangle(*t) for t in triangles]
        out.append(in_shadow(point, light, shapes))
    return out








def _hit(origin, direction, v0, v1, v2):  # noqa: ANN001, ANN202
    """Plane then the edge test; t (any sign) or None."""
    n = cross(sub(v1, v0), sub(v2, v0))
    den = dot(n, direction)
    if den == 0:
        return None
    t = dot(n, sub(v0, origin)) / den
    p = [o + t * d for o, d in zip(origin, direction, strict=True)]
    vs = (v0, v1, v2)
    if any(dot(cross(sub(vs[(i + 1) % 3], vs[i]), sub(p, vs[i])), n) < 0 for i in range(3)):
        return None
    return t


def _shadow(point, light, triangles, *, beyond=False, offset=1e-6, reverse=False):  # noqa: ANN001, ANN202
    to_light = sub(light, point)
    distance = math.sqrt(dot(to_light, to_light))
    d = [x / distance for x in to_light]
    if reverse:
        d = [-x for x in d]
    scale = max(1.0, *(abs(x) for x in point))
    origin = [p + offset * scale * x for p, x in zip(point, d, strict=True)]
    for tri in triangles:
        t = _hit(origin, d, *tri)
        if t is not None and t > 0 and (beyond or t < distance):
            return True
    return False


def the_notes_erratum(point, light, triangles):  # noqa: ANN001, ANN201
    return _shadow(point, light, triangles, beyond=True)


def no_offset(point, light, triangles):  # noqa: ANN001, ANN201
    to_light = sub(light, point)
    distance = math.sqrt(dot(to_light, to_light))
    d = [x / distance for x in to_light]
    return any((t := _hit(point, d, *tri)) is not None and -1e-9 <= t < distance for tri in triangles)


def towards_the_point(point, light, triangles):  # noqa: ANN001, ANN201
    return _shadow(point, light, triangles, reverse=True)


MISTAKES = (
    Mistake("the_notes_erratum", "a triangle beyond the light (t > distance to the light) does not shadow: in "
            "shadow only when 0 < t < |L - P|, the 2012 exam's erratum.", the_notes_erratum),
    Mistake("no_offset", "your shadow ray hits the point's own surface at t ≈ 0: start it a little off the "
            "surface, or count only t > ε.", no_offset),
    Mistake("towards_the_point", "the shadow ray goes from the point towards the light, Rd = (L - P)/|L - P|; "
            "yours runs away from the light.", towards_the_point),
)

# The 2012 exam's plane, as a large triangle of it around where the shadow ray crosses it (0, 16, -37).
PLANE_2012 = ((-100.0, -64.0, -97.0), (100.0, -64.0, -97.0), (0.0, 176.0, 83.0))
# The 2013 exam's blue sphere, as its tangent triangle where the shadow ray enters it, (93, 93, 0).
BLUE_2013 = ((85.0, 87.0, -10.0), (101.0, 99.0, -10.0), (93.0, 93.0, 20.0))

VISIBLE = (
    Case("2013 exam #9: the blue sphere (its tangent triangle) at t = 75 < 100: in shadow",
         ((72.0, 21.0, 0.0), (100.0, 117.0, 0.0), [BLUE_2013]), True),
    Case("2012 exam #10: the plane at t = 40, beyond the light at 30: lit (the notes' erratum)",
         ((0.0, -8.0, -5.0), (0.0, 10.0, -29.0), [PLANE_2012]), False),
)

FLOOR = [((-10.0, 0.0, -10.0), (-10.0, 0.0, 10.0), (10.0, 0.0, 10.0)),
         ((-10.0, 0.0, -10.0), (10.0, 0.0, 10.0), (10.0, 0.0, -10.0))]
BLOCK = ((-1.0, 2.0, -1.0), (1.0, 2.0, -1.0), (0.0, 2.0, 1.5))


def _scaled(tris: list, by: float = 0.0, times: float = 1.0) -> list:
    return [tuple(tuple(x * times + by for x in v) for v in t) for t in tris]


def hidden() -> list[Case]:
    """The light before the occluder, the occluder behind the point, the point's own surface,
    an occluder at the light's distance (either answer), far and tiny scenes."""
    p, light = (0.0, 0.0, 0.0), (0.0, 5.0, 0.0)
    return [
        Case("the occluder between: in shadow", (p, light, [BLOCK]), True, group="between"),
        Case("the occluder beyond the light: lit", (p, (0.0, 1.0, 0.0), [BLOCK]), False, group="beyond"),
        Case("the occluder behind the point: lit", (p, (0.0, -5.0, 0.0), [BLOCK]), False, group="beyond"),
        Case("on the floor, under an open sky: lit", (p, light, FLOOR), False, group="own surface"),
        Case("on the floor, an occluder above: in shadow", (p, light, [*FLOOR, BLOCK]), True, group="own surface"),
        Case("the light below the floor: the floor itself is between", ((0.0, 0.0, 0.0), (0.0, -3.0, 0.5),
                                                                        [*FLOOR, _scaled([BLOCK], -4.0)[0]]),
             False, group="own surface"),
        Case("the occluder exactly at the light", (p, (0.0, 2.0, 0.0), [BLOCK]), False, also=(True,),
             margin="the occluder is at t = distance: the decision t < distance is within rounding", group="edge"),
        Case("far from the world's origin (1e5)", ((1e5, 1e5, 1e5), (1e5, 1e5 + 5.0, 1e5),
                                                   _scaled([*FLOOR, BLOCK], 1e5)), True, group="scale"),
        Case("a tiny scene (1e-4)", (p, (0.0, 5e-4, 0.0), _scaled([*FLOOR, BLOCK], times=1e-4)), True,
             group="scale"),
    ]


#: The probe's scene: the floor, a small triangle above it (between), one above the light (beyond).
PROBE_TRIANGLES = [*_scaled(FLOOR, times=0.25), ((-1.2, 1.2, -0.8), (0.8, 1.2, -0.9), (0.2, 1.2, 1.2)),
                   ((0.3, 3.5, -0.5), (1.9, 3.5, -0.5), (1.1, 3.5, 1.5)),
                   ((-1.9, -1.0, -1.9), (-0.2, -1.0, -1.9), (-1.0, -1.0, -0.1))]
PROBE_LIGHT = (0.0, 3.0, 0.0)


def _probe_inputs(n: int) -> list[tuple]:
    """Points of the floor y = 0, seen from above."""
    return [((float(u), 0.0, float(-v)), PROBE_LIGHT, PROBE_TRIANGLES) for u, v in grid(n, -2.4, 2.4).tolist()]


EXERCISE = Exercise(
    name="shadow", function="in_shadow", params=("point", "light", "triangles"),
    section="Gölge testi", term="gölge ışını",
    summary="whether a triangle lies between a point and the light (0 < t < distance)",
    doc=DOC, example="in_shadow((72, 21, 0), (100, 117, 0), [((85, 87, -10), (101, 99, -10), (93, 93, 20))]) is True",
    returns="bool", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("points of a floor (seen from above) under a light at height 3: a triangle between (its "
                "shadow), one above the light, one under the floor", _probe_inputs, _reference_many, resolution=64),
    mistakes=MISTAKES, order=80,
)
