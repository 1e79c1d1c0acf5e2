"""Vektörel işlemler: the unit normal of a triangle, from the cross product of two edges."""

from __future__ import annotations

import math

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import grid
from glsandbox.exercises.plain import unit

DOC = """Üçgenin normali (a triangle's normal), course section "Vektörel işlemler (normalize, dot, cross)".

With the edges R1 = V1 - V0 and R2 = V2 - V0, the normal is their cross
product, normalized:

    R1 x R2 = (R1y·R2z - R1z·R2y,  R1z·R2x - R1x·R2z,  R1x·R2y - R1y·R2x)
    N = (R1 x R2) / |R1 x R2|

Return N as three numbers, or None for a degenerate triangle (zero area,
|R1 x R2| = 0: it has no normal).

Worked example (the notes' #1): V0 = (30, -40, 60), V1 = (60, -120, 0),
V2 = (0, -120, 0): R1 = (30, -80, -60), R2 = (-30, -80, -60),
R1 x R2 = (0, 3600, -4800), |R1 x R2| = 6000, N = (0, 0.6, -0.8).
"""


def reference(v0, v1, v2):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :attr:`Triangle.normal` (None where the engine calls it degenerate)."""
    from glsandbox.raytrace.triangle import Triangle

    triangle = Triangle(v0, v1, v2)
    return None if triangle.is_degenerate else triangle.normal


def _normalized(n):  # noqa: ANN001, ANN202
    u = unit(n)
    return None if u is None else tuple(u)


def _edges(v0, v1, v2):  # noqa: ANN001, ANN202
    return [b - a for a, b in zip(v0, v1, strict=True)], [c - a for a, c in zip(v0, v2, strict=True)]




def unnormalized(v0, v1, v2):  # noqa: ANN001, ANN201
    a, b = _edges(v0, v1, v2)
    n = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    return None if not any(n) else n


def reversed_order(v0, v1, v2):  # noqa: ANN001, ANN201
    b, a = _edges(v0, v1, v2)
    return _normalized((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))


def cross_y_sign(v0, v1, v2):  # noqa: ANN001, ANN201
    a, b = _edges(v0, v1, v2)
    return _normalized((a[1] * b[2] - a[2] * b[1], a[0] * b[2] - a[2] * b[0], a[0] * b[1] - a[1] * b[0]))


def vertices_not_edges(v0, v1, v2):  # noqa: ANN001, ANN201
    a, b = v1, v2
    return _normalized((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))


MISTAKES = (
    Mistake("unnormalized", "your normal is R1 x R2 itself: divide it by its length |R1 x R2| so that it is a "
            "unit vector.", unnormalized),
    Mistake("reversed_order", "your normal points the other way: the notes take R1 x R2 with R1 = V1 - V0 and "
            "R2 = V2 - V0; R2 x R1 is its opposite.", reversed_order),
    Mistake("cross_y_sign", "the cross product's middle component is R1z·R2x - R1x·R2z; yours has the opposite "
            "sign.", cross_y_sign),
    Mistake("vertices_not_edges", "the cross product is of the edges R1 = V1 - V0 and R2 = V2 - V0, not of the "
            "vertices V1 and V2 themselves.", vertices_not_edges),
)

V0, V1, V2 = (30.0, -40.0, 60.0), (60.0, -120.0, 0.0), (0.0, -120.0, 0.0)

VISIBLE = (
    Case("the notes' #1: N = (0, 0.6, -0.8)", (V0, V1, V2), (0.0, 0.6, -0.8)),
    Case("the same triangle, V1 and V2 swapped: the opposite normal", (V0, V2, V1), (0.0, -0.6, 0.8)),
)


def hidden() -> list[Case]:
    """Degenerate triangles, a non-unit right angle, far and tiny triangles."""
    far = 1e5
    return [
        Case("three points on a line: no normal", ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (2.0, 2.0, 2.0)), None,
             group="degenerate"),
        Case("two equal vertices: no normal", ((1.0, 2.0, 3.0), (1.0, 2.0, 3.0), (4.0, 5.0, 7.0)), None,
             group="degenerate"),
        Case("the floor, counter-clockwise from above", ((0.0, 0.0, 0.0), (0.0, 0.0, 5.0), (5.0, 0.0, 0.0)),
             (0.0, 1.0, 0.0), group="axes"),
        Case("a slanted triangle", ((1.0, 0.0, 0.0), (0.0, 2.0, 0.0), (0.0, 0.0, 2.0)),
             (2.0 / math.sqrt(6.0), 1.0 / math.sqrt(6.0), 1.0 / math.sqrt(6.0)), group="axes"),
        Case("the notes' triangle moved 1e5 away", (tuple(v + far for v in V0), tuple(v + far for v in V1),
                                                    tuple(v + far for v in V2)), (0.0, 0.6, -0.8), rel=1e-9,
             abs=1e-9, group="scale"),
        Case("the notes' triangle shrunk 1e-4", (tuple(v * 1e-4 for v in V0), tuple(v * 1e-4 for v in V1),
                                                 tuple(v * 1e-4 for v in V2)), (0.0, 0.6, -0.8), group="scale"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """V0 = (0.3, 0.2, 0.5), V1 = V0 + (1, u, 0), V2 = V0 + (0, 1, v)."""
    return [((0.3, 0.2, 0.5), (1.3, 0.2 + float(u), 0.5), (0.3, 1.2, 0.5 + float(v)))
            for u, v in grid(n, -2.0, 2.0).tolist()]


EXERCISE = Exercise(
    name="triangle_normal", function="triangle_normal", params=("v0", "v1", "v2"),
    section="Vektörel işlemler (normalize, dot, cross)", term="normal vektör, vektörel çarpım",
    summary="the unit normal (V1 - V0) x (V2 - V0) / |...| of a triangle, None when degenerate",
    doc=DOC, example="tuple(triangle_normal((30, -40, 60), (60, -120, 0), (0, -120, 0))) == (0.0, 0.6, -0.8)",
    returns="vec3_or_none", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("triangles V0, V0 + (1, u, 0), V0 + (0, 1, v) for u, v in [-2, 2]", _probe_inputs,
                shade=lambda n: 0.5 + 0.25 * n[0] + 0.25 * n[1]),
    mistakes=MISTAKES, order=20,
)
