"""W A S D camera: rotateLeft / rotateRight, a point turned 15° about the camera."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import grid

COS15, SIN15 = math.cos(math.radians(15.0)), math.sin(math.radians(15.0))

DOC = f"""rotateLeft / rotateRight, course section "W A S D, Z X camera; rotateLeft/Right 15° about the camera".

In the notes the A and D keys turn every point of the scene by 15° about
the camera, in the xz plane (y stays): with q = P - camera and an angle
a = 15°·steps (steps = 1 for rotateLeft, -1 for rotateRight, any whole
number for several presses):

    x' = q.x·cos a - q.z·sin a
    z' = q.x·sin a + q.z·cos a
    P' = camera + (x', q.y, z')

Return P' as three numbers. The notes write cos 15° = 0.9666 and
sin 15° = 0.259: those are wrong (cos 15° = {COS15:.6f}, sin 15° = {SIN15:.6f};
0.9666² + 0.259² = 1.0014, so every press grows the scene by 0.07%), and
their rotateRight (P.Z = tmpX·0.259 - P.Z·0.9666) is a mirror, not the
inverse turn. Use math.cos and math.sin of the angle in radians; a right
turn must undo a left one exactly.

Worked example: P = (0, 0, 10), camera (0, 0, 0), one left turn:
(-10·sin 15°, 0, 10·cos 15°) = (-2.588190, 0, 9.659258).
"""


def reference(point, camera, steps):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.transforms.rotate_y` by -15°·steps about the camera (the
    notes' rotateLeft turns x towards -z... their matrix is R_y(-a))."""
    from glsandbox.transforms import rotate_y

    c = np.asarray(camera, dtype=np.float64)
    q = np.append(np.asarray(point, dtype=np.float64) - c, 1.0)
    return (rotate_y(-math.radians(15.0 * steps)) @ q)[:3] + c


def _turn(point, camera, steps, cos=None, sin=None):  # noqa: ANN001, ANN202
    a = math.radians(15.0 * steps)
    c, s = (math.cos(a) if cos is None else cos), (math.sin(a) if sin is None else sin)
    q = [p - k for p, k in zip(point, camera, strict=True)]
    return (camera[0] + q[0] * c - q[2] * s, camera[1] + q[1], camera[2] + q[0] * s + q[2] * c)


def notes_constants(point, camera, steps):  # noqa: ANN001, ANN201
    p = tuple(point)
    for _ in range(abs(int(steps))):
        p = _turn(p, camera, 0, cos=0.9666, sin=0.259 if steps > 0 else -0.259)
    return p


def notes_right_mirror(point, camera, steps):  # noqa: ANN001, ANN201
    if steps >= 0:
        return _turn(point, camera, steps)
    p = tuple(point)
    for _ in range(-int(steps)):
        q = [a - k for a, k in zip(p, camera, strict=True)]
        p = (camera[0] + q[0] * COS15 + q[2] * SIN15, p[1], camera[2] + q[0] * SIN15 - q[2] * COS15)
    return p


def degrees_as_radians(point, camera, steps):  # noqa: ANN001, ANN201
    a = 15.0 * steps
    return _turn(point, camera, 0, cos=math.cos(a), sin=math.sin(a))


def about_the_origin(point, camera, steps):  # noqa: ANN001, ANN201
    return _turn(point, (0.0, 0.0, 0.0), steps)


MISTAKES = (
    Mistake("notes_constants", f"0.9666 and 0.259 are not cos 15° and sin 15° ({COS15:.6f}, {SIN15:.6f}): each "
            "press then grows the scene by 0.07%; use math.cos and math.sin.", notes_constants),
    Mistake("notes_right_mirror", "the notes' rotateRight (P.Z = x·0.259 - z·0.9666) is a mirror: a right turn is "
            "the same rotation with the angle -15°, and undoes a left one.", notes_right_mirror),
    Mistake("degrees_as_radians", "math.cos and math.sin take radians: 15° is math.radians(15) = 0.2618, not 15.",
            degrees_as_radians),
    Mistake("about_the_origin", "turn about the camera, not the world's origin: subtract the camera before "
            "rotating and add it back after.", about_the_origin),
)

VISIBLE = (
    Case("(0, 0, 10) one left turn about the origin", ((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), 1),
         (-10.0 * SIN15, 0.0, 10.0 * COS15)),
    Case("(0, 0, 10) one right turn about the origin", ((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), -1),
         (10.0 * SIN15, 0.0, 10.0 * COS15)),
    Case("a point 10 away turned by a camera at (5, 2, -3)", ((5.0, 7.0, 7.0), (5.0, 2.0, -3.0), 1),
         (5.0 - 10.0 * SIN15, 7.0, -3.0 + 10.0 * COS15)),
)


def hidden() -> list[Case]:
    """Whole circles (no drift), right undoing left, many presses, far cameras, tiny scenes."""
    left = (-10.0 * SIN15, 0.0, 10.0 * COS15)
    return [
        Case("24 presses: a full circle, back where it was", ((3.0, 1.0, 10.0), (0.0, 0.0, 0.0), 24),
             (3.0, 1.0, 10.0), abs=1e-12, group="circles"),
        Case("one right turn after a left: back to (0, 0, 10)", (left, (0.0, 0.0, 0.0), -1), (0.0, 0.0, 10.0),
             abs=1e-12, group="circles"),
        Case("six left presses: a quarter turn", ((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), 6), (-10.0, 0.0, 0.0),
             abs=1e-12, group="circles"),
        Case("three right presses from (10, 0, 0)", ((10.0, 0.0, 0.0), (0.0, 0.0, 0.0), -3),
             (10.0 * math.cos(math.radians(-45.0)), 0.0, 10.0 * math.sin(math.radians(-45.0))), group="circles"),
        Case("a camera far away (1e5)", ((1e5, 0.0, 1e5 + 10.0), (1e5, 0.0, 1e5), 1),
             (1e5 - 10.0 * SIN15, 0.0, 1e5 + 10.0 * COS15), rel=1e-9, group="scale"),
        Case("a tiny scene (1e-4)", ((0.0, 0.0, 1e-4), (0.0, 0.0, 0.0), -1), (1e-4 * SIN15, 0.0, 1e-4 * COS15),
             abs=1e-16, group="scale"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    """Points of the floor [-10, 10]² about a camera at (1, 0, 2): the top half one left press,
    the bottom half one right press."""
    camera = (1.0, 0.0, 2.0)
    return [((10.0 * float(u), 0.0, 10.0 * float(v)), camera, 1 if v > 0 else -1)
            for u, v in grid(n, -1.0, 1.0).tolist()]


EXERCISE = Exercise(
    name="camera_turn", function="turn", params=("point", "camera", "steps"),
    section="W A S D, Z X camera; rotateLeft/Right 15° about the camera", term="kamera dönüşü (rotateLeft/Right)",
    summary="a point turned by steps × 15° about the camera in the xz plane (rotateLeft = +1)",
    doc=DOC, example="[round(x, 6) for x in turn((0, 0, 10), (0, 0, 0), 1)] == [-2.58819, 0.0, 9.659258]",
    returns="vec3", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("the floor about a camera at (1, 0, 2): the top half turned left, the bottom half right",
                _probe_inputs, shade=lambda p: 0.5 + 0.04 * (p[0] - p[2]), resolution=128),
    mistakes=MISTAKES, order=110,
)
