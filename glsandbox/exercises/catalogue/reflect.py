"""Yansıma vektörü: a direction reflected about a surface normal."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import hemisphere

DOC = """Yansıma vektörü (the reflection vector), course section "Yansıma vektörü".

A ray arriving along `direction` Rd at a surface with normal N leaves along

    R = Rd - 2(Rd·N)N

where N is a unit vector: normalize `normal` first (it may be of any
length). Rd keeps its length. Return R as three numbers.

Worked example (the notes' #5): Rd = (0, 0.6, 0.8) on the sphere's normal
N = (0, 0.28, -0.96): Rd·N = 0.168 - 0.768 = -0.6, R = (0, 0.936, -0.352).
"""


def reference(direction, normal):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.raytrace.shading.reflect`."""
    from glsandbox.raytrace.shading import reflect

    return reflect(direction, normal)


def _reference_many(inputs: list[tuple]) -> list:
    from glsandbox.raytrace.shading import reflect

    d = np.array([i[0] for i in inputs], dtype=np.float64)
    n = np.array([i[1] for i in inputs], dtype=np.float64)
    return list(reflect(d, n))


def _reflect(d, n, k=2.0, unit=True):  # noqa: ANN001, ANN202
    if unit:
        size = math.sqrt(sum(x * x for x in n))
        n = [x / size for x in n]
    dn = sum(a * b for a, b in zip(d, n, strict=True))
    return tuple(a - k * dn * b for a, b in zip(d, n, strict=True))


def plus_sign(direction, normal):  # noqa: ANN001, ANN201
    return _reflect(direction, normal, k=-2.0)


def factor_two_missing(direction, normal):  # noqa: ANN001, ANN201
    return _reflect(direction, normal, k=1.0)


def normal_not_normalized(direction, normal):  # noqa: ANN001, ANN201
    return _reflect(direction, normal, unit=False)


def direction_normalized(direction, normal):  # noqa: ANN001, ANN201
    size = math.sqrt(sum(x * x for x in direction))
    return _reflect([x / size for x in direction], normal)


MISTAKES = (
    Mistake("plus_sign", "R = Rd - 2(Rd·N)N: with a plus the ray goes on through the surface instead of "
            "bouncing off it.", plus_sign),
    Mistake("factor_two_missing", "R = Rd - 2(Rd·N)N: without the 2 you remove the normal part of Rd instead of "
            "reversing it, and the ray slides along the surface.", factor_two_missing),
    Mistake("normal_not_normalized", "the formula needs a unit normal: divide N by its length first (here the "
            "normals are not unit vectors).", normal_not_normalized),
    Mistake("direction_normalized", "Rd keeps its length in R = Rd - 2(Rd·N)N: only the normal is normalized, "
            "not the direction.", direction_normalized),
)

VISIBLE = (
    Case("the notes' #5: Rd (0,0.6,0.8) on N (0,0.28,-0.96)", ((0.0, 0.6, 0.8), (0.0, 0.28, -0.96)),
         (0.0, 0.936, -0.352)),
    Case("2013 exam #8: Rd (0.96,0.28,0) on the red sphere's N (-0.8,0.6,0)",
         ((0.96, 0.28, 0.0), (-0.8, 0.6, 0.0)), (0.0, 1.0, 0.0)),
)


def hidden() -> list[Case]:
    """A normal of any length, head on, grazing, a normal facing away, a long direction, tiny."""
    return [
        Case("a normal of length 10", ((0.0, 0.6, 0.8), (0.0, 2.8, -9.6)), (0.0, 0.936, -0.352), group="normal"),
        Case("a normal facing away (the same reflection)", ((0.0, 0.6, 0.8), (0.0, -0.28, 0.96)),
             (0.0, 0.936, -0.352), group="normal"),
        Case("head on: straight back", ((0.0, 0.0, -1.0), (0.0, 0.0, 1.0)), (0.0, 0.0, 1.0), group="angles"),
        Case("grazing: unchanged", ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)), (1.0, 0.0, 0.0), group="angles"),
        Case("a direction of length 5 keeps it", ((0.0, 3.0, 4.0), (0.0, 0.28, -0.96)), (0.0, 4.68, -1.76),
             group="length"),
        Case("a tiny direction (1e-4)", ((0.0, 0.6e-4, 0.8e-4), (0.0, 0.28, -0.96)), (0.0, 0.936e-4, -0.352e-4),
             abs=1e-16, group="length"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """The direction (1.2, 0, -1.6) (length 2) on a hemisphere of normals, each scaled to length 2."""
    return [((1.2, 0.0, -1.6), tuple(2.0 * float(x) for x in normal)) for normal in hemisphere(n)]


EXERCISE = Exercise(
    name="reflect", function="reflect", params=("direction", "normal"),
    section="Yansıma vektörü", term="yansıma vektörü",
    summary="the direction Rd - 2(Rd·N)N of a reflected ray",
    doc=DOC, example="[round(x, 9) for x in reflect((0, 0.6, 0.8), (0, 0.28, -0.96))] == [0.0, 0.936, -0.352]",
    returns="vec3", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("the direction (1.2, 0, -1.6) on a hemisphere of normals of length 2 (seen from above)",
                _probe_inputs, _reference_many, shade=lambda r: 0.5 + 0.25 * r[2]),
    mistakes=MISTAKES, order=60,
)
