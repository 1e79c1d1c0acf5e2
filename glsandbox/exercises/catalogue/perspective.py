"""World, View, Projection: the Projection matrix, XMMatrixPerspectiveFovLH."""

from __future__ import annotations

import math

import numpy as np

from glsandbox.exercises.definition import Case, Exercise, Mistake, Probe
from glsandbox.exercises.dxmath import camera, cube_segments, edge_probe, look_at_lh, perspective_fov_lh, row

CONVENTION = ("the course's DirectX row vectors (p_clip = p_view·Projection, w = z in the last column), "
              "left-handed, depth 0..1; OpenGL's column form (the transpose) is not accepted")

DOC = """The Projection matrix (izdüşüm matrisi), course section "Vertex/pixel shader; World, View, Projection".

XMMatrixPerspectiveFovLH(FovAngleY, AspectRatio, NearZ, FarZ), FovAngleY in
radians, AspectRatio = width / height. With

    yScale = 1 / tan(FovAngleY / 2),   xScale = yScale / AspectRatio

and, for row vectors (p_clip = p_view·Projection):

    Projection = | xScale    0                0               0 |
                 |   0     yScale             0               0 |
                 |   0       0       Far/(Far-Near)           1 |
                 |   0       0     -Near·Far/(Far-Near)       0 |

so w = z (the view distance) and, after the divide, depth z/w runs from 0 at
the near plane to 1 at the far plane (DirectX's range; OpenGL's is -1..1).

Worked example (the notes' projection): FovAngleY = π/4, 800 x 600, Near 0.01,
Far 100: yScale = 1/tan(π/8) = 2.414214, xScale = 1.810660,
Far/(Far-Near) = 1.000100, -Near·Far/(Far-Near) = -0.010001.
"""


def reference(fov_y, aspect, near, far):  # noqa: ANN001, ANN201 - the student's plain signature
    """The engine's :func:`glsandbox.transforms.perspective` converted to the course's form
    (:func:`glsandbox.exercises.dxmath.perspective_fov_lh`: mirrored view, depth 0..1, transposed)."""
    return perspective_fov_lh(fov_y, aspect, near, far)


def _projection(fov_y, aspect, near, far, *, half=True, divide=True, gl_depth=False):  # noqa: ANN001, ANN202
    y = 1.0 / math.tan(fov_y / 2.0 if half else fov_y)
    x = y / aspect if divide else y * aspect
    m = np.zeros((4, 4))
    m[0, 0], m[1, 1], m[2, 3] = x, y, 1.0
    if gl_depth:
        m[2, 2], m[3, 2] = (far + near) / (far - near), -2.0 * far * near / (far - near)
    else:
        m[2, 2], m[3, 2] = far / (far - near), -near * far / (far - near)
    return m


def column_vectors(fov_y, aspect, near, far):  # noqa: ANN001, ANN201
    return row(_projection(fov_y, aspect, near, far).T)


def full_angle(fov_y, aspect, near, far):  # noqa: ANN001, ANN201
    return row(_projection(fov_y, aspect, near, far, half=False))


def aspect_multiplied(fov_y, aspect, near, far):  # noqa: ANN001, ANN201
    return row(_projection(fov_y, aspect, near, far, divide=False))


def opengl_depth(fov_y, aspect, near, far):  # noqa: ANN001, ANN201
    return row(_projection(fov_y, aspect, near, far, gl_depth=True))


MISTAKES = (
    Mistake("column_vectors", "that is the column-vector form, the transpose: with p·Projection the 1 that "
            "copies z into w sits in row 2, column 3.", column_vectors),
    Mistake("full_angle", "FovAngleY is the whole vertical angle: yScale = 1/tan(FovAngleY/2), half of it.",
            full_angle),
    Mistake("aspect_multiplied", "a wide picture squeezes x: xScale = yScale / AspectRatio, not times it.",
            aspect_multiplied),
    Mistake("opengl_depth", "that is OpenGL's depth range -1..1: DirectX maps Near to 0 and Far to 1, "
            "Far/(Far-Near) and -Near·Far/(Far-Near).", opengl_depth),
)

VISIBLE = (
    Case("the notes' projection: π/4, 800/600, 0.01, 100", (math.pi / 4, 800 / 600, 0.01, 100.0),
         row(reference(math.pi / 4, 800 / 600, 0.01, 100.0))),
)


def _case(name, args, group, **tolerance):  # noqa: ANN001, ANN202
    return Case(name, args, row(reference(*args)), group=group, **tolerance)


def hidden() -> list[Case]:
    """Other angles and aspects (tall, square), near planes far from 0, a far plane close to the near."""
    return [
        _case("a square picture, 60°", (math.pi / 3, 1.0, 0.1, 50.0), "frusta"),
        _case("a tall picture (450 x 800), 90°", (math.pi / 2, 450 / 800, 1.0, 10.0), "frusta"),
        _case("a narrow lens, 10°", (math.radians(10.0), 16 / 9, 2.0, 3000.0), "frusta"),
        _case("near 5, far 6: a thin slab of depth", (math.pi / 4, 1.5, 5.0, 6.0), "depth"),
        _case("near 1e-4, far 1e5", (math.pi / 4, 4 / 3, 1e-4, 1e5), "depth", rel=1e-9, abs=1e-12),
    ]


_PROBE_INPUTS = [(math.pi / 4, 1.0, 0.01, 100.0), (math.pi / 2, 2.0, 0.5, 50.0),
                 (math.pi / 6, 0.5, 1.0, 20.0), (math.pi / 4, 1.0, 9.2, 12.0)]
_WORLD_VIEW = look_at_lh((2.0, 3.0, -9.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))


def _segments(projection: np.ndarray, i: int) -> np.ndarray:
    return cube_segments(_WORLD_VIEW @ projection)


EXERCISE = Exercise(
    name="perspective", function="perspective_fov_lh", params=("fov_y", "aspect", "near", "far"),
    section="Vertex/pixel shader; World, View, Projection", term="izdüşüm matrisi (Projection), "
    "XMMatrixPerspectiveFovLH",
    summary="XMMatrixPerspectiveFovLH(FovAngleY, AspectRatio, NearZ, FarZ), the course's row form",
    doc=DOC, example="[round(x, 6) for x in perspective_fov_lh(3.141592653589793 / 4, 800 / 600, 0.01, 100)[0]]"
                     " == [1.81066, 0.0, 0.0, 0.0]",
    returns="matrix4", reference=reference, visible=VISIBLE, hidden=hidden,
    probe=Probe("the course's cube through a fixed View and Projection (π/4 square; π/2 wide; π/6 tall; "
                "near 9.2 cutting the cube, depth clipped to 0..1)", lambda n: list(_PROBE_INPUTS),
                draw=edge_probe(_segments)),
    mistakes=MISTAKES, convention=CONVENTION, order=140,
)
