"""Bakış noktası, görüntü düzlemi GD(x, y): a pixel's point on the ray tracer's image plane."""

from __future__ import annotations

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.fields import grid

DOC = """Görüntü düzlemi (the image plane), course section "Bakış noktası, görüntü düzlemi GD(x,y)".

The eye sits at (0, 0, 0) looking along +z; the image plane is z = 10,
16 units wide and 9 high. Pixel (x, y) of an 800x450 picture (x to the right,
y down, (0, 0) the top-left pixel) is the point

    GD(x, y) = (16x/799 - 8,  4.5 - 9y/449,  10)

so (0, 0) is the top-left corner (-8, 4.5, 10) and (799, 449) the
bottom-right (8, -4.5, 10). Return the point as three numbers.

Worked example: GD(0, 0) = (-8, 4.5, 10).
"""


def reference(x, y):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`~glsandbox.raytrace.world.course_image_plane`."""
    from glsandbox.raytrace.world import course_image_plane

    return course_image_plane(x, y)


def _reference_many(inputs: list[tuple]) -> list:
    import numpy as np

    from glsandbox.raytrace.world import course_image_plane

    xy = np.array(inputs, dtype=np.float64)
    return list(course_image_plane(xy[:, 0], xy[:, 1]))


def width_not_minus_one(x, y):  # noqa: ANN001, ANN201
    return (16 * x / 800 - 8, 4.5 - 9 * y / 450, 10.0)


def y_not_flipped(x, y):  # noqa: ANN001, ANN201
    return (16 * x / 799 - 8, 9 * y / 449 - 4.5, 10.0)


def x_and_y_swapped(x, y):  # noqa: ANN001, ANN201
    return (16 * y / 799 - 8, 4.5 - 9 * x / 449, 10.0)


def not_centred(x, y):  # noqa: ANN001, ANN201
    return (16 * x / 799, 9 - 9 * y / 449, 10.0)


MISTAKES = (
    Mistake("width_not_minus_one", "divide by W - 1 = 799 and H - 1 = 449, not 800 and 450: the last pixel, "
            "x = 799, must land on the plane's right edge, 8.", width_not_minus_one),
    Mistake("y_not_flipped", "pixel rows count down but the plane's y goes up: 4.5 - 9y/449, so row 0 is the top "
            "(y = 4.5).", y_not_flipped),
    Mistake("x_and_y_swapped", "x is the column (0..799, across 16 units) and y the row (0..449, across 9): "
            "they are swapped in your function.", x_and_y_swapped),
    Mistake("not_centred", "the plane is centred on the view axis: subtract 8 from x and start y at 4.5, so "
            "the middle pixel looks straight ahead.", not_centred),
)

VISIBLE = (
    Case("top-left pixel (0, 0)", (0, 0), (-8.0, 4.5, 10.0)),
    Case("bottom-right pixel (799, 449)", (799, 449), (8.0, -4.5, 10.0)),
    Case("pixel (400, 225), beside the centre", (400, 225), (16 * 400 / 799 - 8, 4.5 - 9 * 225 / 449, 10.0)),
)


def hidden() -> list[Case]:
    """The other corners, and points between pixels."""
    return [
        Case("top-right pixel (799, 0)", (799, 0), (8.0, 4.5, 10.0), group="corners"),
        Case("bottom-left pixel (0, 449)", (0, 449), (-8.0, -4.5, 10.0), group="corners"),
        Case("the plane's centre, x = 399.5, y = 224.5", (399.5, 224.5), (0.0, 0.0, 10.0), abs=1e-12,
             group="between"),
        Case("a sample inside a pixel (10.25, 300.75)", (10.25, 300.75),
             (16 * 10.25 / 799 - 8, 4.5 - 9 * 300.75 / 449, 10.0), group="between"),
    ]


def _probe_inputs(n: int) -> list[tuple]:
    return [(float(u), float(449.0 - v)) for u, v in (grid(n, 0.0, 799.0) * [1.0, 449.0 / 799.0]).tolist()]


EXERCISE = Exercise(
    name="image_plane", function="image_plane", params=("x", "y"),
    section="Bakış noktası, görüntü düzlemi GD(x,y)", term="görüntü düzlemi",
    summary="the point of the image plane that pixel (x, y) of 800x450 looks through",
    doc=DOC, example="tuple(image_plane(0, 0)) == (-8.0, 4.5, 10.0)",
    returns="vec3", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("every pixel position of the 800x450 picture (squeezed into a square)", _probe_inputs,
                _reference_many, shade=lambda p: (p[0] + 8.0) / 32.0 + (p[1] + 4.5) / 18.0),
    mistakes=MISTAKES, order=10,
)
