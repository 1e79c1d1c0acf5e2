"""Işın-Düzlem kesim testi: where a ray meets the plane N·P + d = 0."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import grid
from glsandbox.exercises.plain import dot

DOC = """Işın-Düzlem kesimi (ray-plane intersection), course section "Işın-Üçgen kesim testi" (its first step).

The plane is the set of points P with N·P + d = 0 (so d = -(N·V0) for a
point V0 on it). Putting the ray R0 + t·Rd into it:

    N·(R0 + t·Rd) + d = 0   =>   t = -(N·R0 + d) / (N·Rd)

N·Rd = 0: the ray runs parallel to the plane (yüzeye paralel): no hit.
t <= 0: the plane is behind the ray's origin: no hit.
Return the t > 0, or None.

Worked example (the notes' #2): N = (0, 0.6, -0.8), d = 72, R0 = (0, 0, 0),
Rd = (0, 0, 1): t = -(0 + 72)/(-0.8) = 90, the point (0, 0, 90).
"""


def reference(origin, direction, normal, d):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :meth:`Plane.intersect`."""
    from glsandbox.raytrace.plane import Plane
    from glsandbox.raytrace.ray import Ray

    return Plane(normal, d).intersect(Ray(origin, direction))


def _reference_many(inputs: list[tuple]) -> list:
    from glsandbox.raytrace.plane import Plane

    (_, _, normal, d) = inputs[0]
    assert all(tuple(i[2]) == tuple(normal) and i[3] == d for i in inputs)  # one plane in the probe
    o = np.array([i[0] for i in inputs], dtype=np.float64)
    rd = np.array([i[1] for i in inputs], dtype=np.float64)
    t = Plane(normal, d).intersect_many(o, rd).tolist()
    return [v if math.isfinite(v) else None for v in t]




def _t(origin, direction, normal, d, sign_d=1.0, sign_t=1.0, positive=True):  # noqa: ANN001, ANN202
    den = dot(normal, direction)
    if den == 0:
        return None
    t = sign_t * -(dot(normal, origin) + sign_d * d) / den
    return t if (t > 0 or not positive) else None


def d_sign_flipped(origin, direction, normal, d):  # noqa: ANN001, ANN201
    return _t(origin, direction, normal, d, sign_d=-1.0)


def minus_dropped(origin, direction, normal, d):  # noqa: ANN001, ANN201
    return _t(origin, direction, normal, d, sign_t=-1.0)


def behind_accepted(origin, direction, normal, d):  # noqa: ANN001, ANN201
    t = _t(origin, direction, normal, d, positive=False)
    return None if t == 0 else t


MISTAKES = (
    Mistake("d_sign_flipped", "your plane is N·P - d = 0: the notes write N·P + d = 0, so t = -(N·R0 + d)/(N·Rd) "
            "(with N = (0, 0.6, -0.8), d = 72 the plane passes through (30, -40, 60)).", d_sign_flipped),
    Mistake("minus_dropped", "t = -(N·R0 + d)/(N·Rd): your t has the opposite sign (the minus is missing), so "
            "planes in front are missed and planes behind are hit.", minus_dropped),
    Mistake("behind_accepted", "a plane behind the ray's origin gives t < 0: that is no hit, return None; only "
            "t > 0 is in front of the origin.", behind_accepted),
)

ORIGIN = (0.0, 0.0, 0.0)
N, D = (0.0, 0.6, -0.8), 72.0

VISIBLE = (
    Case("the notes' #2: N (0,0.6,-0.8), d 72, Rd (0,0,1)", (ORIGIN, (0.0, 0.0, 1.0), N, D), 90.0),
    Case("the notes' #6: the reflected ray meets the plane y = 255",
         ((0.0, 21.0, 28.0), (0.0, 0.936, -0.352), (0.0, -1.0, 0.0), 255.0), 250.0),
    Case("2012 exam #10: the shadow ray meets the plane at t = 40",
         ((0.0, -8.0, -5.0), (0.0, 0.6, -0.8), (0.0, -0.6, 0.8), 39.2), 40.0),
)


def hidden() -> list[Case]:
    """Parallel rays, planes behind, an origin on the plane, a non-unit normal, far and tiny."""
    far = 1e5
    return [
        Case("parallel to the plane, beside it", ((0.0, 10.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.0), None,
             group="parallel"),
        Case("along the plane, inside it", (ORIGIN, (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.0), None,
             group="parallel"),
        Case("the plane behind the origin", (ORIGIN, (0.0, 0.0, -1.0), N, D), None, group="behind"),
        Case("from the other side of the plane", ((0.0, 0.0, 100.0), (0.0, 0.0, 1.0), N, D), None,
             group="behind"),
        Case("looking back at it from the other side", ((0.0, 0.0, 100.0), (0.0, 0.0, -1.0), N, D), 10.0,
             group="behind"),
        Case("the origin on the plane: t = 0 is no hit", ((0.0, 0.0, 90.0), (0.0, 0.0, 1.0), N, D), None,
             abs=1e-9, also=(0.0,), margin="the origin is on the plane: t = 0 up to rounding, or none",
             group="surface"),
        Case("a normal of length 2 (d scaled too)", (ORIGIN, (0.0, 0.0, 1.0), (0.0, 1.2, -1.6), 144.0), 90.0,
             group="scale"),
        Case("far from the world's origin (1e5)", ((far, far, far), (0.0, 0.0, 1.0), N,
                                                   D - 0.6 * far + 0.8 * far), 90.0, rel=1e-9, group="scale"),
        Case("a tiny scene (1e-4)", (ORIGIN, (0.0, 0.0, 1.0), N, D * 1e-4), 90.0e-4, abs=1e-15, group="scale"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """Rays along (0, 0.6, 0.8) from each point (0, y, z) of a 400 x 400 square around the plane."""
    return [((0.0, float(y), float(z)), (0.0, 0.6, 0.8), N, D) for z, y in grid(n, -200.0, 200.0).tolist()]


EXERCISE = Exercise(
    name="ray_plane", function="intersect_plane", params=("origin", "direction", "normal", "d"),
    section="Işın-Üçgen kesim testi", term="ışın-düzlem kesimi",
    summary="nearest t > 0 where a ray meets the plane N·P + d = 0, or None",
    doc=DOC, example="intersect_plane((0, 0, 0), (0, 0, 1), (0, 0.6, -0.8), 72) == 90.0",
    returns="t", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("rays along (0, 0.6, 0.8) from each point of the square x = 0, |y|, |z| <= 200; the plane "
                "N = (0, 0.6, -0.8), d = 72", _probe_inputs, _reference_many, shade=lambda t: 1.0 - t / 600.0),
    mistakes=MISTAKES, order=30,
)
