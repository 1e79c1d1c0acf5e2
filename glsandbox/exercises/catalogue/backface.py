"""Hızlandırma: back-face culling, the notes' rule for a triangle that faces away."""

from __future__ import annotations

import math

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import grid
from glsandbox.exercises.plain import dot

DOC = """Arka yüz (back-face culling), course section "Hızlandırma: backface culling, AABB".

A triangle's normal is N = (V1 - V0) x (V2 - V0): its winding (the order of
V0, V1, V2) says which side is its front. Seen along the ray direction Rd,
the triangle shows its back when its normal points away from the viewer:

    N·Rd > 0   ->  a back face (skip it: it cannot be seen on a closed shape)
    N·Rd < 0   ->  a front face

Return True for a back face, False otherwise.

Worked example: the notes' triangle V0 = (30, -40, 60), V1 = (60, -120, 0),
V2 = (0, -120, 0) has N = (0, 0.6, -0.8); seen along Rd = (0, 0, 1),
N·Rd = -0.8 < 0: a front face (False). Swap V1 and V2 and it is a back face.
"""


def reference(v0, v1, v2, direction):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's own culling: a ray along ``direction`` through the triangle's centre is
    hit by :meth:`Triangle.intersect` but not with ``cull_backfaces=True``."""
    from glsandbox.raytrace.ray import Ray
    from glsandbox.raytrace.triangle import Triangle

    triangle = Triangle(v0, v1, v2)
    centre = (triangle.v0 + triangle.v1 + triangle.v2) / 3.0
    ray = Ray(centre - Ray(centre, direction).direction, direction)  # reaches the centre at t = 1
    seen = triangle.intersect(ray) is not None
    return seen and triangle.intersect(ray, cull_backfaces=True) is None


def _normal(v0, v1, v2):  # noqa: ANN001, ANN202
    a = [y - x for x, y in zip(v0, v1, strict=True)]
    b = [y - x for x, y in zip(v0, v2, strict=True)]
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]




def sign_flipped(v0, v1, v2, direction):  # noqa: ANN001, ANN201
    return dot(_normal(v0, v1, v2), direction) < 0


def view_axis(v0, v1, v2, direction):  # noqa: ANN001, ANN201
    return _normal(v0, v1, v2)[2] > 0


def from_the_origin(v0, v1, v2, direction):  # noqa: ANN001, ANN201
    return dot(_normal(v0, v1, v2), v0) > 0


MISTAKES = (
    Mistake("sign_flipped", "your rule is the wrong way round: N·Rd > 0 means the normal points away from the "
            "viewer, a back face.", sign_flipped),
    Mistake("view_axis", "compare the normal with the ray's direction Rd, not with the z axis: a ray that does "
            "not look along +z sees the triangle from another side.", view_axis),
    Mistake("from_the_origin", "use the ray's direction: N·V0 is the view from the world's origin, not from "
            "this ray's origin.", from_the_origin),
)

V0, V1, V2 = (30.0, -40.0, 60.0), (60.0, -120.0, 0.0), (0.0, -120.0, 0.0)
Z = (0.0, 0.0, 1.0)
# The notes' cube (DirectX Tutorial 04): its top face, indices 3, 1, 0.
CUBE_TOP = ((-1.0, 1.0, 1.0), (1.0, 1.0, -1.0), (-1.0, 1.0, -1.0))

VISIBLE = (
    Case("the notes' triangle seen along +z: front", (V0, V1, V2, Z), False),
    Case("the same, V1 and V2 swapped: back", (V0, V2, V1, Z), True),
    Case("the cube's top face (indices 3, 1, 0) from above: front", (*CUBE_TOP, (0.0, -1.0, 0.0)), False),
    Case("the cube's top face from below: back", (*CUBE_TOP, (0.0, 1.0, 0.0)), True),
)


def hidden() -> list[Case]:
    """Rays not along z, a ray from behind the world's origin, edge-on (either), far and tiny."""
    far = 1e5
    return [
        Case("seen along -z: back", (V0, V1, V2, (0.0, 0.0, -1.0)), True, group="directions"),
        Case("seen along its normal (0, 0.6, -0.8): back", (V0, V1, V2, (0.0, 0.6, -0.8)), True,
             group="directions"),
        Case("seen against its normal, along (0, -0.6, 0.8): front", (V0, V1, V2, (0.0, -0.6, 0.8)), False,
             group="directions"),
        Case("a triangle behind the world's origin, seen along -z: front",
             ((30.0, -40.0, -60.0), (0.0, -120.0, 0.0), (60.0, -120.0, 0.0), (0.0, 0.0, -1.0)), False,
             group="directions"),
        Case("edge-on: N·Rd = 0", (V0, V1, V2, (1.0, 0.0, 0.0)), False, also=(True,),
             margin="N·Rd = 0 exactly: the triangle is seen edge-on, neither side", group="edge"),
        Case("the cube's top face far away (1e5), from below", (*[tuple(x + far for x in v) for v in CUBE_TOP],
                                                                 (0.0, 1.0, 0.0)), True, group="scale"),
        Case("a tiny triangle (1e-4), along +z", (*[tuple(x * 1e-4 for x in v) for v in (V0, V1, V2)], Z), False,
             group="scale"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """The notes' triangle turned about the y axis by 180°·u, seen along (v, 0, 1)."""
    out = []
    for u, v in grid(n, -1.0, 1.0).tolist():
        c, s = math.cos(math.pi * u), math.sin(math.pi * u)
        turned = [(c * x + s * z, y, -s * x + c * z) for x, y, z in (V0, V1, V2)]
        out.append((*turned, (float(v), 0.0, 1.0)))
    return out


EXERCISE = Exercise(
    name="backface", function="is_backface", params=("v0", "v1", "v2", "direction"),
    section="Hızlandırma: backface culling, AABB", term="arka yüz ayıklama",
    summary="whether a triangle shows its back along a ray's direction (N·Rd > 0)",
    doc=DOC, example="is_backface((30, -40, 60), (60, -120, 0), (0, -120, 0), (0, 0, 1)) is False",
    returns="bool", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("the notes' triangle turned about y by -180°..180° (across), seen along (v, 0, 1) (down)",
                _probe_inputs, resolution=64),
    mistakes=MISTAKES, order=90,
)
